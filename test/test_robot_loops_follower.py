# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
loops.follower and run.loop_diagnostics: a robot's loops followed message by message, no ROS.

The follower's answers are checked against test/loop_reference.py (mpmath, sharing nothing with
the package); its refusals, one by one, name the loops they concern; the statuses say so.
"""

from __future__ import annotations

import math
from typing import Any

from linkage_kinematics.loops.description import LoopError
from linkage_kinematics.loops.follower import (
    LoopDrop,
    LoopSample,
    RobotLoopsFollower,
)
from linkage_kinematics.loops.intake import DropReason, Estimate
from linkage_kinematics.loops.plan import read_loops
from linkage_kinematics.model.urdf_reader import read_urdf
from linkage_kinematics.run.configuration import build_configuration
from linkage_kinematics.run.control import RunState
from linkage_kinematics.run.diagnostics import Level, StatusInputs
from linkage_kinematics.run.loop_diagnostics import loop_statuses, LoopsHealth, LoopsView
from linkage_kinematics.run.measured import MeasuredFollower
from linkage_kinematics.run.parameter_specs import parameter_specs
from linkage_kinematics.run.parameter_values import ConfigurationError
import loop_reference
from loop_robots import ROBOTS
import pytest

TOLERANCE = 1e-12
PERIOD_NS = 10_000_000
KNEE = ROBOTS['four_bar_knee'].urdf()
EXCAVATOR = ROBOTS['excavator'].urdf()
CYLINDERS = list(ROBOTS['excavator'].measured_joints)


def follower(urdf: str, measured: tuple[str, ...] = (), max_jump: float = math.pi / 2,
             branches: dict[str, int] | None = None) -> RobotLoopsFollower:
    return RobotLoopsFollower(read_loops(read_urdf(urdf)), measured, branches or {}, max_jump)


def test_the_knee_without_velocities_is_estimated_and_matches_the_reference() -> None:
    """Backward difference over the stamps (0 at first); positions and rates to 1e-12."""
    knee = follower(KNEE)
    guess: dict[str, Any] = {}
    previous = None
    for index in range(7):
        angle = -0.3 + 0.1 * index
        sample = knee.follow(index * PERIOD_NS, ['knee_front', 'other'], [angle, 4.0], [])
        assert isinstance(sample, LoopSample)
        rate = 0.0 if previous is None else (angle - previous) / (PERIOD_NS * 1e-9)
        assert sample.estimates == {'knee_front': (
            Estimate.FIRST_SAMPLE if previous is None else Estimate.BACKWARD_DIFFERENCE)}
        exact = loop_reference.solve(KNEE, {'knee_front': angle}, guess)
        exact_rates = loop_reference.velocities(KNEE, {'knee_front': angle, **exact},
                                                {'knee_front': rate})
        assert sorted(sample.names) == ['knee_rear', 'knee_shank']
        for name, position, velocity in zip(sample.names, sample.positions, sample.velocities):
            assert abs(position - float(exact[name])) < TOLERANCE
            assert abs(velocity - float(exact_rates[name])) < TOLERANCE * max(1.0, abs(rate))
        guess, previous = exact, angle


def test_a_wrapping_encoder_is_unwrapped() -> None:
    """The measured joint read 2π further is the same pose, and no jump."""
    plain, wrapped = follower(KNEE), follower(KNEE)
    for index, angle in enumerate((0.1, 0.2, 0.25)):
        turned = angle + (2.0 * math.pi if index else 0.0)
        first = plain.follow(index + 1, ['knee_front'], [angle], [1.0])
        second = wrapped.follow(index + 1, ['knee_front'], [turned], [1.0])
        assert isinstance(second, LoopSample)
        assert second.positions == pytest.approx(first.positions, abs=TOLERANCE)


def test_bad_samples_are_dropped_naming_their_loops_and_leave_the_motion_as_it_was() -> None:
    excavator = follower(EXCAVATOR, tuple(CYLINDERS))
    good = excavator.follow(1, CYLINDERS, [0.0, 0.0, 0.0], [0.1, 0.0, 0.0])
    assert isinstance(good, LoopSample)
    drops = [
        (excavator.follow(2, CYLINDERS[:2], [0.0, 0.0], []), DropReason.NO_JOINT,
         ('bucket_cylinder_pin',)),
        (excavator.follow(2, CYLINDERS, [0.0, math.inf, 0.0], []), DropReason.NON_FINITE,
         ('stick_cylinder_pin',)),
        (excavator.follow(2, CYLINDERS, [0.0, 0.0, 0.0], [math.nan, 0.0, 0.0]),
         DropReason.NON_FINITE, ('boom_cylinder_pin',)),
        (excavator.follow(1, CYLINDERS, [0.0, 0.0, 0.0], []), DropReason.STAMP_NOT_NEWER, ()),
        (excavator.follow(2, CYLINDERS, [5.0, 0.0, 0.0], []), DropReason.JOINTS_UNREACHABLE,
         ('boom_cylinder_pin',)),
    ]
    for drop, reason, constraints in drops:
        assert isinstance(drop, LoopDrop)
        assert (drop.reason, drop.constraints) == (reason, constraints)
    # Nothing of a dropped sample was kept: the next one is estimated from the good one.
    after = excavator.follow(3, CYLINDERS, [0.01, 0.0, 0.0], [])
    fresh = follower(EXCAVATOR, tuple(CYLINDERS))
    fresh.follow(1, CYLINDERS, [0.0, 0.0, 0.0], [0.1, 0.0, 0.0])
    assert after == fresh.follow(3, CYLINDERS, [0.01, 0.0, 0.0], [])
    assert after.estimates['boom_cylinder'] is Estimate.BACKWARD_DIFFERENCE
    # a revolute measured joint's jump
    knee = follower(KNEE, max_jump=0.5)
    knee.follow(1, ['knee_front'], [0.0], [])
    jump = knee.follow(2, ['knee_front'], [0.6], [])
    assert (jump.reason, jump.constraints) == (DropReason.JUMP, ('knee_rear_pin',))


def test_measured_joints_come_from_the_first_message_and_own_output_is_ignored() -> None:
    excavator = follower(EXCAVATOR)
    assert excavator.plan is None
    assert excavator.follow(1, ['track_left'], [0.3], []) is None  # no loop joint: not planned
    assert excavator.plan is None
    assert isinstance(excavator.follow(2, ['track_left', *CYLINDERS], [0.3, 0.0, 0.0, 0.0], []),
                      LoopSample)
    assert excavator.plan.measured == tuple(CYLINDERS)
    # its own output: passive loop joints only
    assert excavator.follow(3, ['boom_joint', 'stick_joint'], [0.0, 0.0], []) is None
    # two joints of one loop measured: refused, naming the constraint
    with pytest.raises(LoopError, match='boom_cylinder_pin'):
        follower(EXCAVATOR).follow(1, ['boom_cylinder', 'boom_joint', *CYLINDERS[1:]],
                                   [0.0] * 4, [])
    with pytest.raises(LoopError, match="measured joint 'nothing' is not a joint"):
        follower(KNEE, ('nothing',))


def test_a_joint_named_twice_counts_at_its_first_place_in_both_modes() -> None:
    """As robot_state_publisher reads a joint state: its map keeps a name's first position."""
    twice, once = follower(KNEE, ('knee_front',)), follower(KNEE, ('knee_front',))
    sample = twice.follow(1, ['knee_front', 'knee_front'], [0.1, 0.3], [0.5, 0.7])
    assert sample == once.follow(1, ['knee_front'], [0.1], [0.5])
    crank = build_configuration({**{spec.name: spec.default for spec in parameter_specs('paper')},
                                 'source': 'measured', 'log.enabled': False})
    followed = MeasuredFollower(crank).follow(1, ['crank_joint', 'crank_joint'], [0.1, 0.3], [])
    assert followed.joints == MeasuredFollower(crank).follow(1, ['crank_joint'], [0.1], []).joints


def test_descriptions_that_cannot_be_closed_are_refused_in_one_line() -> None:
    broken = KNEE.replace('<constraint name="knee_rear_pin" type="revolute">',
                          '<constraint name="knee_rear_pin" type="prismatic">')
    with pytest.raises(LoopError, match='knee_rear_pin') as refusal:
        read_loops(read_urdf(broken))
    assert '\n' not in str(refusal.value)
    with pytest.raises(LoopError, match="robot 'plain' has no <constraint> loop to close"):
        read_loops(read_urdf('<robot name="plain"><link name="a"/></robot>'))


def test_a_branch_override_picks_the_other_assembly() -> None:
    default = follower(KNEE, ('knee_front',)).follow(1, ['knee_front'], [0.0], [0.0])
    other = follower(KNEE, ('knee_front',), branches={'knee_rear_pin': -default_branch()})
    flipped = other.follow(1, ['knee_front'], [0.0], [0.0])
    assert max(abs(a - b) for a, b in zip(default.positions, flipped.positions)) > 0.1
    gaps = loop_reference.closure_residuals(KNEE, {'knee_front': 0.0, **flipped.joints})
    assert max(gaps.values()) < TOLERANCE


def default_branch() -> int:
    return follower(KNEE, ('knee_front',)).plan.loops[0].branch


def configuration(**overrides: Any) -> Any:
    values = {spec.name: spec.default for spec in parameter_specs('paper')}
    return build_configuration({**values, 'log.enabled': False, 'source': 'measured',
                                'loops': 'robot_description', **overrides})


def test_the_loop_parameters_are_validated_naming_them() -> None:
    config = configuration(**{'loops.branches': ['knee_rear_pin=-1', 'b=+1'],
                              'loops.measured_joints': ['knee_front']})
    assert config.loops.branches == (('knee_rear_pin', -1), ('b', 1))
    assert config.loops.measured_joints == ('knee_front',)
    for name, value, message in (
            ('loops.branches', ['pin=2'], "entry 'pin=2' is not CONSTRAINT=1 or CONSTRAINT=-1"),
            ('loops.branches', ['a=1', 'a=-1'], 'gives a constraint more than one branch'),
            ('loops.measured_joints', ['a', 'a'], "names \\['a'\\] more than once"),
            ('loops.measured_joints', 'a', 'must be a list of strings'),
            ('loops', 'urdf', 'must be one of parameters, robot_description')):
        with pytest.raises(ConfigurationError, match=f'^{name}: {message}'):
            configuration(**{name: value})
    with pytest.raises(ConfigurationError, match='^loops: robot_description .* needs source '
                                                 'measured, got source drive_law'):
        configuration(source='drive_law')
    with pytest.raises(ConfigurationError, match=r'^loops.measured_joints: is used only with '
                                                 r'loops robot_description \(and source '
                                                 r'measured\), got loops parameters$'):
        configuration(loops='parameters', **{'loops.measured_joints': ['a']})


def statuses(health: LoopsHealth, plan: Any, now_ns: int = 0, timeout: float = 1.0) -> Any:
    inputs = StatusInputs(config=configuration(**{'measured.timeout': timeout}),
                          run_state=RunState.RUNNING, state=None, activity='following',
                          achieved_rate=None, missed_deadlines=0, log_file=None, log_size=None,
                          now_ns=now_ns)
    return loop_statuses(inputs, LoopsView(robot_name='excavator', description_from='topic',
                                           plan=plan, health=health))


def test_the_statuses_say_what_each_loop_does_and_what_was_dropped() -> None:
    excavator = follower(EXCAVATOR, tuple(CYLINDERS))
    health = LoopsHealth(0)
    health.accept(0, excavator.follow(1, CYLINDERS, [0.0, 0.0, 0.0], [0.1, 0.2, 0.3]))
    drop = excavator.follow(2, CYLINDERS, [5.0, 0.0, 0.0], [])
    health.drop(drop.reason, drop.constraints)
    node, *loops = statuses(health, excavator.plan)
    assert [status.task for status in loops] == [
        f'loop {planned.loop.constraint}' for planned in excavator.plan.loops]
    assert (node.level, node.message) == (
        Level.WARN, 'dropped 1 message at joint values a loop cannot reach (or at a dead point)')
    by_task = {status.task: status for status in loops}
    boom = by_task['loop boom_cylinder_pin']
    assert boom.level is Level.WARN
    assert boom.values['dropped samples'] == '1'
    assert boom.values['estimated'] == 'none'
    assert by_task['loop bucket_pin'].level is Level.OK
    assert by_task['loop bucket_pin'].values['known joint'] == (
        'bucket_link_joint (solved by loop bucket_cylinder_pin)')
    # the window starts anew; the totals stay
    node, *loops = statuses(health, excavator.plan)
    assert node.level is Level.OK and node.values['dropped samples'] == '1'
    # stale: ERROR
    node, *_ = statuses(health, excavator.plan, now_ns=2_000_000_000)
    assert node.level is Level.ERROR
    assert node.message.startswith('no valid measured sample for 2.000 s')
