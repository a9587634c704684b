# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A robot's closures through the one pipeline: read, grouped, planned, followed, reported.

Without ROS: the plan (planar loops and closure groups in one ``LoopPlan``), the measured joints
(given, else the closure file's ``name_mot``, else the first message's), the refusals at start
(one line naming the group, its joints, degrees of freedom and known joints; a group that does
not assemble), ``loops.assemblies`` picking another assembly, joints a closure file overrides
(solved, not published, warned about by name), a group's refusals as drop reasons counted for
it, its status, the new parameters and the source's logged lines. Over DDS:
test_robot_closures_node.py.
"""

from __future__ import annotations

import math
from pathlib import Path
import re
from typing import Any

import closure_robots
import example_parallel_robots as models
from linkage_kinematics.loops.closures import ClosureError
from linkage_kinematics.loops.description import LoopError
from linkage_kinematics.loops.follower import (
    LoopDrop,
    LoopSample,
    REFUSAL_DROPS,
    RobotLoopsFollower,
)
from linkage_kinematics.loops.intake import DropReason, LOOPS_DROPS
from linkage_kinematics.loops.plan import find_loops, read_loops
from linkage_kinematics.loops.refusals import Refusal
from linkage_kinematics.loops.solver import LoopSolver
from linkage_kinematics.loops.structure import GroupKind
from linkage_kinematics.model.urdf_reader import read_urdf
from linkage_kinematics.ros.loop_source import assembly_line, ClosedRobot, group_plan_line
from linkage_kinematics.run.configuration import build_configuration
from linkage_kinematics.run.control import RunState
from linkage_kinematics.run.diagnostics import Level, StatusInputs
from linkage_kinematics.run.loop_diagnostics import loop_statuses, LoopsHealth, LoopsView
from linkage_kinematics.run.parameter_specs import parameter_specs
from linkage_kinematics.run.parameter_values import ConfigurationError
from loop_robots import ROBOTS
import pytest
from test_closure_assembly import mirrored_distal_angles

REPOSITORY = Path(__file__).resolve().parent.parent
ANKLE = (REPOSITORY / 'urdf' / 'humanoid_ankle.urdf').read_text(encoding='utf-8')
LAB_KNEE = (REPOSITORY / 'urdf' / 'lab_knee.urdf').read_text(encoding='utf-8')
MOTORS = ('motor_left', 'motor_right')
ANKLE_SOLVED = ('ankle_pitch', 'ankle_roll', 'rod_left_u1', 'rod_left_u2', 'rod_right_u1',
                'rod_right_u2')
PIN = ('<constraint name="tip" type="revolute"><parent link="distal1"/>'
       '<parent_origin xyz="0.25 0 0"/><parent_axis xyz="0 0 1"/><child link="distal2"/>'
       '<child_origin xyz="0.25 0 0"/><child_axis xyz="0 0 1"/></constraint>')
FIVE_BAR = closure_robots.five_bar().urdf.replace('</robot>', PIN + '</robot>')


def knee_and_ankle() -> str:
    """
    Return the lab knee with the humanoid ankle hung below its foot: two kinds of group.

    The ankle's shank and foot renamed (the knee has links of those names), its materials left
    out (the knee defines some of the same names).
    """
    start = ANKLE.index('<robot name="humanoid_ankle">') + len('<robot name="humanoid_ankle">')
    body = re.sub(r'<material[^>]*?(/>|>.*?</material>)', '', ANKLE[start:ANKLE.index('</robot>')],
                  flags=re.DOTALL)
    for link in ('shank', 'foot'):
        body = body.replace(f'<link name="{link}"', f'<link name="ankle_{link}"').replace(
            f'link="{link}"', f'link="ankle_{link}"')
    below = ('<joint name="ankle_mount" type="fixed"><parent link="foot"/>'
             '<child link="ankle_shank"/><origin xyz="0.6 0 0" rpy="0 0 0"/></joint>')
    return LAB_KNEE.replace('</robot>', body + below + '</robot>')


def follow(follower: RobotLoopsFollower, stamp: int, values: dict[str, float]) -> Any:
    return follower.follow(stamp, list(values), list(values.values()), [0.0] * len(values))


# --- the plan ----------------------------------------------------------------------------------

def test_a_planar_knee_and_a_spatial_ankle_are_one_plan_in_solve_order() -> None:
    """
    The knee's loop solved as alone, bit for bit; the ankle's group after it.

    The ankle's closures are written in the frame of the knee's foot there (its loops' base),
    through the fixed joint that mounts it: as alone up to the rounding of that offset.
    """
    loops = read_loops(read_urdf(knee_and_ankle()))
    plan = loops.plan(('knee_motor', *MOTORS))
    assert [(group.name, group.kind) for group in plan.groups] == [
        ('knee_output_pin', GroupKind.PLANAR_LOOPS), ('ball_left+ball_right', GroupKind.NEWTON)]
    assert [planned.loop.constraint for planned in plan.loops] == ['knee_output_pin']
    assert plan.passive == ('knee_link', 'knee_output', *ANKLE_SOLVED)
    assert [group.known for group in plan.groups] == [('knee_motor',), MOTORS]
    both = LoopSolver(plan)
    alone = LoopSolver(read_loops(read_urdf(LAB_KNEE)).plan(('knee_motor',)))
    ankle = LoopSolver(read_loops(read_urdf(ANKLE)).plan(MOTORS))
    for step in range(20):
        measured = {'knee_motor': 0.3 * step, 'motor_left': 0.02 * step,
                    'motor_right': -0.015 * step}
        rates = {'knee_motor': 1.0, 'motor_left': 0.1, 'motor_right': -0.2}
        positions, velocities = both.solve(measured, rates)
        knee = alone.solve({'knee_motor': measured['knee_motor']}, {'knee_motor': 1.0})
        foot = ankle.solve({name: measured[name] for name in MOTORS},
                           {name: rates[name] for name in MOTORS})
        assert [positions[name].hex() for name in knee[0]] == [
            value.hex() for value in knee[0].values()]
        assert [velocities[name].hex() for name in knee[1]] == [
            value.hex() for value in knee[1].values()]
        assert {name: positions[name] for name in foot[0]} == pytest.approx(foot[0], abs=1e-14)
        assert {name: velocities[name] for name in foot[1]} == pytest.approx(foot[1], abs=1e-13)


def test_the_measured_joints_are_given_else_the_closure_files_else_the_first_messages() -> None:
    name = 'cassie_like'
    loops = read_loops(read_urdf(models.urdf(name)), models.closure_file(name))
    assert loops.actuated == tuple(models.closure_file_content(name)['name_mot'])
    assert RobotLoopsFollower(loops, (), {}, 1.0).plan.measured == loops.actuated
    given = ('motor_knee', 'motor_ankle')
    assert RobotLoopsFollower(loops, given, {}, 1.0).plan.measured == given
    # the ankle has no closure file: the motors the first message carries
    follower = RobotLoopsFollower(read_loops(read_urdf(ANKLE)), (), {}, 1.0)
    assert follower.plan is None
    assert follow(follower, 1, {'other': 0.1}) is None
    assert isinstance(follow(follower, 2, {'motor_left': 0.0, 'motor_right': 0.0}), LoopSample)
    assert follower.plan.measured == MOTORS


def test_groups_the_measured_joints_do_not_determine_are_refused_at_start_in_one_line() -> None:
    name = 'disney_like'
    loops = read_loops(read_urdf(models.urdf(name)), models.closure_file(name))
    with pytest.raises(LoopError) as refused:
        RobotLoopsFollower(loops, (), {}, 1.0)
    (line,) = str(refused.value).split('\n')
    assert line.startswith('group closedloop1_BCclosedloop1_A+closedloop2_ACclosedloop2_B+'
                           "closedloop3_ACclosedloop3_B (joints ['motor_4barlink1', ")
    assert ("8 degrees of freedom (0 idle), known ['motor_4barlink1', 'motor_4barlink3', "
            "'motor_hip_x', 'motor_4barlink2', 'motor_4barlink4']: under-determined, a free "
            'motion moves') in line
    assert line.endswith('; 8 known joints are needed')
    # the ankle with a third known joint: over-determined
    with pytest.raises(LoopError, match=r'^group ball_left\+ball_right \(joints \[.*\]\): 2 '
                                        r"degrees of freedom \(0 idle\), known \['ankle_pitch', "
                                        r"'motor_left', 'motor_right'\]: over-determined, 3 known "
                                        r'joints for 2 determining freedoms$'):
        read_loops(read_urdf(ANKLE)).plan(('motor_left', 'motor_right', 'ankle_pitch'))


def test_a_group_that_does_not_assemble_is_refused_at_start_by_its_gaps() -> None:
    """kangaroo_like's closures stay centimetres open: no pose closes them as given."""
    name = 'kangaroo_like'
    loops = read_loops(read_urdf(models.urdf(name)), models.closure_file(name))
    with pytest.raises(LoopError) as refused:
        loops.plan(loops.actuated)
    (line,) = str(refused.value).split('\n')
    assert line.startswith('group closedloop0_BCclosedloop0_A+closedloop2_ACclosedloop2_B+')
    assert (': no assembled pose found from the start (open by closedloop0_BCclosedloop0_A '
            '0.536 m and 2.54 rad, ') in line
    assert line.endswith(' in 25 tries: it cannot be assembled as given')


def test_an_assembly_seed_picks_the_other_assembly_and_the_node_keeps_it() -> None:
    """The five-bar's elbow mirrored by a seed of its distal joints: the other orientation."""
    loops = read_loops(read_urdf(FIVE_BAR))
    drawn = RobotLoopsFollower(loops, ('j1', 'j3'), {}, 1.0)
    j2, j4 = mirrored_distal_angles()
    seeded = RobotLoopsFollower(loops, ('j1', 'j3'), {}, 1.0, {'j2': j2 + 0.1, 'j4': j4 - 0.1})
    assert [group.kind for group in seeded.plan.groups] == [GroupKind.FIVE_BAR]
    assert seeded.plan.groups[0].seed == {'j2': j2 + 0.1, 'j4': j4 - 0.1}
    for stamp in range(1, 12):
        values = {'j1': 0.01 * stamp, 'j3': -0.01 * stamp}
        first, second = follow(drawn, stamp, values), follow(seeded, stamp, values)
        (step,), (other,) = drawn.solver.groups, seeded.solver.groups
        assert other.solver.orientation == -step.solver.orientation
        assert abs(first.positions[0] - second.positions[0]) > 0.5
    with pytest.raises(LoopError, match=r"^loops.assemblies: 'j1' is not a joint a closure "
                                        'group solves by the general closure'):
        RobotLoopsFollower(loops, ('j1', 'j3'), {}, 1.0, {'j1': 0.2})


def test_overridden_joints_are_solved_not_published_and_warned_about_by_name() -> None:
    name = 'battobot_6d'
    loops = read_loops(read_urdf(models.urdf(name)), models.closure_file(name))
    plan = RobotLoopsFollower(loops, (), {}, 1.0).plan
    knee = plan.groups[0]
    assert knee.hidden == ('free_knee_left_Y', 'free_knee_left_Z', 'transmission_knee_left_X',
                           'transmission_knee_left_Y', 'transmission_knee_left_Z')
    assert knee.published == ('knee_left',)
    assert plan.passive == ('knee_left', 'knee_right', 'anklex_right', 'ankley_right',
                            'anklex_left', 'ankley_left')
    assert len(plan.warnings) == len(loops.overrides) == 12
    assert plan.warnings[0] == (
        "joint 'left_spherical_ankle_1' is read as UJOINT_ZY by the closure file: its "
        'coordinates left_spherical_ankle_1_Z, left_spherical_ankle_1_Y are solved but not '
        'published (they are no URDF joints), so robot_state_publisher cannot pose link '
        "'long_axis_assembly_6d_4' and the links below it; model it in the URDF as 2 revolute "
        'joints to publish them')


# --- following ---------------------------------------------------------------------------------

def test_a_groups_refusal_is_its_own_drop_reason_counted_for_the_group() -> None:
    assert set(REFUSAL_DROPS) == set(Refusal)
    assert set(REFUSAL_DROPS.values()) <= set(LOOPS_DROPS)
    follower = RobotLoopsFollower(read_loops(read_urdf(FIVE_BAR)), ('j1', 'j3'), {}, math.pi)
    assert isinstance(follow(follower, 1, {'j1': 0.0, 'j3': 0.0}), LoopSample)
    before = follower.solver.groups[0].state.positions
    # the cranks spread so far apart that the distal links cannot meet
    dropped = follow(follower, 2, {'j1': 1.2, 'j3': -1.2})
    assert isinstance(dropped, LoopDrop)
    assert (dropped.reason, dropped.constraints) == (DropReason.NO_ASSEMBLY, ('tip',))
    assert dropped.detail == ('group tip: no assembly reaches the known joints (the circles do '
                              'not meet)')
    assert follower.solver.groups[0].state.positions == before
    health = LoopsHealth(0)
    health.drop(dropped.reason, dropped.constraints)
    health.accept(1, follow(follower, 3, {'j1': 0.05, 'j3': -0.05}))
    _, group = statuses(follower, health)
    assert (group.task, group.level) == ('group tip', Level.WARN)
    assert group.message == ('dropped 1 message at joint values no assembly of a closure group '
                             'reaches')
    assert group.values['dropped at joint values no assembly of a closure group reaches'] == '1'
    assert group.values['dropped samples'] == '1'


def statuses(follower: RobotLoopsFollower, health: LoopsHealth) -> Any:
    values = {spec.name: spec.default for spec in parameter_specs('paper')}
    config = build_configuration({**values, 'log.enabled': False, 'source': 'measured',
                                  'loops': 'robot_description'})
    inputs = StatusInputs(config=config, run_state=RunState.RUNNING, state=None,
                          activity='following', achieved_rate=None, missed_deadlines=0,
                          log_file=None, log_size=None, now_ns=0)
    return loop_statuses(inputs, LoopsView(robot_name='r', description_from='topic',
                                           plan=follower.plan, health=health,
                                           groups=follower.solver.groups))


def test_a_groups_status_says_what_it_is_how_it_is_solved_and_how_near_a_singularity() -> None:
    follower = RobotLoopsFollower(read_loops(read_urdf(ANKLE)), MOTORS, {}, 1.0)
    health = LoopsHealth(0)
    node, group = statuses(follower, health)
    assert node.values['closure groups'] == 'ball_left+ball_right (general closure)'
    assert node.values['passive joints'] == ', '.join(ANKLE_SOLVED)
    assert (group.task, group.level, group.message) == (
        'group ball_left+ball_right', Level.OK, 'waiting for motor_left, motor_right')
    assert group.values['conditioning'] == 'not followed yet'
    sample = follower.follow(1, list(MOTORS), [0.1, -0.05], [])
    health.accept(1, sample)
    node, group = statuses(follower, health)
    assert (group.level, group.message) == (Level.OK, 'closed from motor_left, motor_right')
    values = group.values
    assert {key: values[key] for key in (
        'kind', 'closures', 'degrees of freedom', 'known joints', 'solves', 'solved by',
        'idle freedoms', 'not published', 'assembly', 'estimated')} == {
        'kind': 'closure group of 2 balls',
        'closures': 'ball_left (ball, <constraint>), ball_right (ball, <constraint>)',
        'degrees of freedom': '2 (0 idle)',
        'known joints': 'motor_left, motor_right (measured)',
        'solves': ', '.join(ANKLE_SOLVED),
        'solved by': 'Newton on the closure equations with their exact Jacobian, to rounding',
        'idle freedoms': 'none',
        'not published': 'none',
        'assembly': f'orientation {follower.solver.groups[0].solver.orientation:+d} (the sign '
                    'of det A), assembled at the first sample',
        'estimated': 'velocities of ' + ', '.join(ANKLE_SOLVED)
                     + ' (from an estimated velocity of motor_left, motor_right)'}
    assert 1.0 < float(values['conditioning']) < 100.0
    distance = float(values['singular configuration distance'].split()[0])
    assert distance == pytest.approx(
        follower.solver.groups[0].solver.derivatives.singular_distance([0.0, 0.0]), rel=1e-5)
    assert values['Newton iterations'] in {'1', '2', '3', '4'}


def test_the_source_logs_how_each_group_is_solved_and_which_assembly_it_took() -> None:
    follower = RobotLoopsFollower(read_loops(read_urdf(ANKLE)), MOTORS, {}, 1.0)
    (group,) = follower.plan.general
    # drawn assembled: its balls open by the rounding of their written numbers
    gaps = [gap.position for gap in group.zero.assembly.start_gaps]
    assert max(gaps) < 1e-16
    assert group_plan_line(group) == (
        'group ball_left+ball_right: 2 degrees of freedom (0 idle), known motor_left, '
        'motor_right, solving ' + ', '.join(ANKLE_SOLVED) + ' by Newton on the closure '
        f'equations; the zero pose is open by ball_left {gaps[0]:.3g} m, ball_right '
        f'{gaps[1]:.3g} m; it is assembled at the first sample, nearest its zero-pose assembly '
        '(loops.assemblies picks another)')
    follower.follow(1, list(MOTORS), [0.0, 0.0], [])
    (step,) = follower.solver.groups
    line = assembly_line(step)
    assert line.startswith('group ball_left+ball_right: assembled at the first sample '
                           '(motor_left = 0, motor_right = 0): ankle_pitch = ')
    assert (f', orientation {step.solver.orientation:+d} (the sign of det A), closed to '
            'ball_left ') in line


# --- parameters --------------------------------------------------------------------------------

def configuration(**overrides: Any) -> Any:
    values = {spec.name: spec.default for spec in parameter_specs('paper')}
    return build_configuration({**values, 'log.enabled': False, 'source': 'measured',
                                'loops': 'robot_description', **overrides})


def test_the_assemblies_and_the_closure_file_parameters_are_validated_naming_them() -> None:
    text = models.closure_file('cassie_like')
    config = configuration(**{'loops.assemblies': ['rod_left_u1=0.25', 'x=-1e-3'],
                              'robot_description_closures': text})
    assert config.loops.assemblies == (('rod_left_u1', 0.25), ('x', -1e-3))
    assert config.loops.robot_description_closures == text
    for value, message in (
            (['j2'], "entry 'j2' is not JOINT=VALUE"),
            (['j2=nan'], "entry 'j2=nan' is not JOINT=VALUE"),
            (['=1'], "entry '=1' is not JOINT=VALUE"),
            (['a=1', 'a=2'], 'gives a joint more than one value')):
        with pytest.raises(ConfigurationError, match=f'^loops.assemblies: {message}'):
            configuration(**{'loops.assemblies': value})
    for name, value in (('loops.assemblies', ['a=1']), ('loops.output_joints', ['a']),
                        ('robot_description_closures', text)):
        with pytest.raises(ConfigurationError, match=f'^{name}: is used only with loops '
                                                     'robot_description'):
            configuration(loops='parameters', **{name: value})


def test_the_node_reads_the_closure_file_parameter_with_every_description() -> None:
    name = 'cassie_like'
    config = configuration(**{'robot_description_closures': models.closure_file(name)})
    robot = ClosedRobot(models.urdf(name), config)
    assert robot.follower.plan.measured == robot.follower.loops.actuated
    assert robot.closures == models.closure_file(name)
    with pytest.raises(ClosureError, match='^the closure file is not YAML'):
        ClosedRobot(models.urdf(name), configuration(
            **{'robot_description_closures': 'closed_loop: [a'}))


def test_the_planar_robots_plans_have_no_general_group() -> None:
    """Every planar test robot: its groups are planar loops only, as the plan always was."""
    for robot in ROBOTS.values():
        plan = find_loops(read_urdf(robot.urdf())).plan(robot.measured_joints)
        assert plan.general == ()
        assert {group.kind for group in plan.groups} == {GroupKind.PLANAR_LOOPS}
        assert sorted(joint for group in plan.groups for joint in group.solved) == sorted(
            plan.passive)
