# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The follower's efforts through the loops (loops.robot_transmission, loops.follower).

With ``loops.output_joints`` a message whose actuators carry efforts gives each published joint
its effort: an output joint τ_o = Mᵀ·τ_m, the very value ``Transmission.output_efforts`` gives at
the pose the follower solved (whose accuracy test/test_transmission.py checks against the 50-digit
references), every other published joint 0, in the order the joints are published (a planar
group's loops' order, not its structure's); the power balance τ_mᵀ·ṁ = τ_oᵀ·q̇_o holds on the
sample's own velocities. Without output joints, without efforts in the message, or with a NaN
among the actuators' efforts (joint_state_broadcaster's value for a missing interface), the
sample has none. A group whose joints are not named keeps 0 on every joint. At the knee's toggle
the efforts are withheld, naming the group, and the positions are still published. The output
joints are checked when the plan is made: one line naming every problem. The diagnostics give
each group with output joints a status: its actuators and outputs, its mechanical advantage at
the last sample, what became of that sample's efforts and how many were withheld. The command
direction's examples in docs/following_loops.md (the excavator's boom trajectory, the ankle's
torques) are what the command direction gives with the node's transmissions.
"""

from __future__ import annotations

import math
from pathlib import Path
import re
import sys

from linkage_kinematics.loops.command import CommandGroup, CommandRefused, JointPoint
from linkage_kinematics.loops.follower import LoopSample, RobotLoopsFollower
from linkage_kinematics.loops.plan import read_loops
from linkage_kinematics.loops.robot_command import RobotCommand
from linkage_kinematics.loops.robot_transmission import plan_transmissions
from linkage_kinematics.loops.transmission import (
    actuator_efforts,
    MechanicalAdvantage,
    TransmissionError,
)
from linkage_kinematics.model.urdf_reader import read_urdf
from linkage_kinematics.run.configuration import build_configuration
from linkage_kinematics.run.control import RunState
from linkage_kinematics.run.diagnostics import Level, Status, StatusInputs
from linkage_kinematics.run.loop_diagnostics import loop_statuses, LoopsHealth, LoopsView
from linkage_kinematics.run.parameter_specs import parameter_specs
import loop_robots
import pytest
import yaml

REPOSITORY = Path(__file__).resolve().parent.parent
EPSILON = sys.float_info.epsilon
ANKLE = (REPOSITORY / 'urdf' / 'humanoid_ankle.urdf').read_text(encoding='utf-8')
KNEE = (REPOSITORY / 'urdf' / 'lab_knee.urdf').read_text(encoding='utf-8')
CYLINDERS = ('boom_cylinder', 'stick_cylinder', 'bucket_cylinder')
BOOM_STICK_BUCKET = ('boom_joint', 'stick_joint', 'bucket_joint')
# robot → URDF, measured joints, output joints, and per measured joint (amplitude, effort)
ROBOTS = {
    'excavator': (loop_robots.excavator(), CYLINDERS, BOOM_STICK_BUCKET,
                  ((0.14, 2e5), (0.19, -1e5), (0.14, 5e4))),
    'ankle': (ANKLE, ('motor_left', 'motor_right'), ('ankle_pitch', 'ankle_roll'),
              ((0.4, 2.0), (0.3, -1.5))),
    'knee': (KNEE, ('knee_motor',), ('knee_output',), ((3.0, 4.0),)),
}


def follower(name: str, outputs: tuple[str, ...] | None = None) -> RobotLoopsFollower:
    urdf, measured, default, _ = ROBOTS[name]
    return RobotLoopsFollower(read_loops(read_urdf(urdf)), measured, {}, math.pi,
                              outputs=default if outputs is None else outputs)


def motion(name: str, count: int) -> list[tuple[list[float], list[float], list[float]]]:
    """Return the measured joints' positions, velocities and efforts at ``count`` samples."""
    _, measured, _, amplitudes = ROBOTS[name]
    samples = []
    for index in range(count):
        phase = [2.0 * math.pi * index / count + k for k in range(len(measured))]
        samples.append(([a * math.sin(p) for (a, _), p in zip(amplitudes, phase)],
                        [a * math.cos(p) for (a, _), p in zip(amplitudes, phase)],
                        [effort * (1.0 + 0.5 * math.cos(p))
                         for (_, effort), p in zip(amplitudes, phase)]))
    return samples


@pytest.mark.parametrize('name', list(ROBOTS))
def test_each_output_joint_gets_its_transmissions_effort_and_the_power_balances(name):
    followed = follower(name)
    _, measured, outputs, _ = ROBOTS[name]
    efforts_of = followed.output_efforts
    for index, (positions, velocities, efforts) in enumerate(motion(name, 40)):
        sample = followed.follow(index + 1, list(measured), positions, velocities, efforts)
        assert isinstance(sample, LoopSample) and sample.withheld is None
        assert len(sample.efforts) == len(sample.names)
        by_name = dict(zip(sample.names, sample.efforts))
        # every published joint but the outputs: the effort of an unactuated joint
        assert all(by_name[joint] == 0.0 for joint in sample.names if joint not in outputs)
        for found in efforts_of.groups:
            transmission = found.transmission
            known = [sample.joints[a] for a in transmission.actuators]
            given = [efforts[measured.index(a)] for a in transmission.actuators]
            solved = [sample.joints[joint] for joint in transmission.solved]
            expected = transmission.output_efforts(known, solved, given)
            for output in transmission.outputs:
                assert by_name[output] == expected[transmission.solved.index(output)]
        rates = dict(zip(sample.names, sample.velocities))
        actuator_power = math.fsum(t * v for t, v in zip(efforts, velocities))
        output_power = math.fsum(by_name[joint] * rates[joint] for joint in outputs)
        scale = math.fsum(abs(t * v) for t, v in zip(efforts, velocities))
        assert abs(actuator_power - output_power) <= 1e3 * EPSILON * scale


def test_the_efforts_follow_the_published_order_of_a_chain_of_planar_loops():
    """The bucket's two loops publish in their solve order, not the group structure's."""
    followed = follower('excavator')
    (positions, velocities, efforts), = motion('excavator', 1)
    sample = followed.follow(1, list(CYLINDERS), positions, velocities, efforts)
    bucket = next(found for found in followed.output_efforts.groups
                  if 'bucket_joint' in found.transmission.outputs)
    assert list(bucket.transmission.solved) != [
        joint for joint in sample.names if joint in bucket.transmission.solved]
    by_name = dict(zip(sample.names, sample.efforts))
    assert [joint for joint in sample.names if by_name[joint] != 0.0] == list(BOOM_STICK_BUCKET)


def test_without_output_joints_or_measured_efforts_the_sample_has_none():
    (positions, velocities, efforts), = motion('ankle', 1)
    plain = follower('ankle', ())
    assert plain.output_efforts is None
    assert plain.follow(1, ['motor_left', 'motor_right'], positions, velocities,
                        efforts).efforts == ()
    followed = follower('ankle')
    names = ['motor_left', 'motor_right', 'hip']
    for stamp, given in enumerate(([], [1.0], [math.nan, 2.0, 3.0], [1.0, math.inf]), 1):
        sample = followed.follow(stamp, names, positions + [0.0], velocities + [0.0], given)
        assert sample.efforts == () and sample.withheld is None
    # a NaN of a joint outside the loops does not matter
    sample = followed.follow(9, names, positions + [0.0], velocities + [0.0],
                             efforts + [math.nan])
    assert len(sample.efforts) == 6 and sample.efforts[2:] == (0.0,) * 4


def test_a_group_without_output_joints_keeps_its_joints_at_zero():
    followed = follower('excavator', ('stick_joint',))
    assert [found.group.name for found in followed.output_efforts.groups] == [
        'stick_cylinder_pin']
    (positions, velocities, efforts), = motion('excavator', 1)
    sample = followed.follow(1, list(CYLINDERS), positions, velocities, efforts)
    by_name = dict(zip(sample.names, sample.efforts))
    assert [joint for joint, effort in by_name.items() if effort != 0.0] == ['stick_joint']
    # the stick cylinder's effort alone makes the stick joint's
    again = follower('excavator', ('stick_joint',)).follow(
        1, list(CYLINDERS), positions, velocities, [math.nan, efforts[1], math.nan])
    assert again.efforts == sample.efforts


def toggle_angle(followed: RobotLoopsFollower) -> float:
    """Return a motor angle where the knee's rocker turns back (d(output)/d(motor) = 0)."""

    def output_rate(motor: float) -> float:
        followed.restart()
        sample = followed.follow(1, ['knee_motor'], [motor], [1.0])
        return dict(zip(sample.names, sample.velocities))['knee_output']

    low = 0.0
    while output_rate(low + 0.05) * output_rate(low) > 0.0:
        low += 0.05
    high = low + 0.05
    for _ in range(50):
        middle = 0.5 * (low + high)
        low, high = ((middle, high) if output_rate(middle) * output_rate(low) > 0.0
                     else (low, middle))
    return low


def test_at_the_knees_toggle_the_efforts_are_withheld_and_the_positions_published():
    """At a rocker's end the crank and coupler are in line: dm/do has no bound there."""
    followed = follower('knee')
    low = toggle_angle(followed)
    followed.restart()
    sample = followed.follow(1, ['knee_motor'], [low], [1.0], [1.0])
    assert sample.efforts == () and sample.withheld == 'knee_output_pin'
    assert len(sample.positions) == 2
    (advantage,) = followed.output_efforts.advantages(sample.joints, followed.solver.groups)
    assert str(advantage).startswith('group knee_output_pin: the output joints are too near')
    followed.restart()
    sample = followed.follow(1, ['knee_motor'], [0.7], [1.0], [1.0])
    (advantage,) = followed.output_efforts.advantages(sample.joints, followed.solver.groups)
    assert isinstance(advantage, MechanicalAdvantage)
    assert advantage.ratio[0][0] == dict(zip(sample.names, sample.efforts))['knee_output']


def test_output_joints_that_cannot_be_the_groups_are_refused_in_one_line():
    loops = read_loops(read_urdf(ROBOTS['excavator'][0]))
    with pytest.raises(TransmissionError) as refused:
        RobotLoopsFollower(loops, CYLINDERS, {}, math.pi, outputs=(
            'boom_cylinder', 'tooth', 'stick_joint', 'stick_joint', 'bucket_joint',
            'bucket_link_joint'))
    assert str(refused.value) == (
        "output joint 'tooth' is not a joint of the robot; output joint 'stick_joint' is named "
        "twice; group boom_cylinder_pin: output joints ['boom_cylinder']: ['boom_cylinder'] "
        "are measured; an output joint is one the actuators ['boom_cylinder'] move; group "
        "bucket_cylinder_pin+bucket_pin: output joints ['bucket_joint', 'bucket_link_joint']: 2 "
        'joints for 1 degrees of freedom that move it (as many as its actuators '
        "['bucket_cylinder'])")
    # planned at the first message when the measured joints are not given: refused there
    later = RobotLoopsFollower(loops, (), {}, math.pi, outputs=('boom_cylinder',))
    with pytest.raises(TransmissionError, match='group boom_cylinder_pin: output joints'):
        later.follow(1, list(CYLINDERS), [0.0] * 3, [0.0] * 3)
    plan = loops.plan(CYLINDERS)
    assert [found.group.name for found in plan_transmissions(plan, ('bucket_joint',))] == [
        'bucket_cylinder_pin+bucket_pin']


def transmission_statuses(followed: RobotLoopsFollower, health: LoopsHealth) -> list[Status]:
    """Return the statuses of the follower's transmissions, as the node would publish them."""
    values = {spec.name: spec.default for spec in parameter_specs('paper')}
    config = build_configuration({**values, 'log.enabled': False, 'source': 'measured',
                                  'loops': 'robot_description'})
    inputs = StatusInputs(config=config, run_state=RunState.RUNNING, state=None,
                          activity='following', achieved_rate=None, missed_deadlines=0,
                          log_file=None, log_size=None, now_ns=0)
    view = LoopsView(robot_name='r', description_from='topic', plan=followed.plan,
                     health=health, groups=followed.solver.groups,
                     transmissions=followed.output_efforts)
    return [status for status in loop_statuses(inputs, view)
            if status.task.startswith('transmission ')]


def test_each_groups_transmission_has_a_status_with_its_advantage_now():
    followed = follower('ankle')
    health = LoopsHealth(0)
    (status,) = transmission_statuses(followed, health)
    assert (status.task, status.level, status.message) == (
        'transmission ball_left+ball_right', Level.OK, 'waiting for motor_left, motor_right')
    assert status.values == {
        'actuators': 'motor_left, motor_right', 'output joints': 'ankle_pitch, ankle_roll',
        'efforts': 'not followed yet', 'efforts withheld (samples)': '0',
        'mechanical advantage': 'not followed yet', 'd(actuators)/d(outputs)': 'not followed yet'}
    sample = followed.follow(1, ['motor_left', 'motor_right'], [0.2, -0.2], [0.0, 0.0], [1.0, 2.0])
    health.accept(1, sample)
    (status,) = transmission_statuses(followed, health)
    (found,) = followed.output_efforts.groups
    advantage = found.transmission.advantage(
        [0.2, -0.2], [sample.joints[joint] for joint in found.transmission.solved])
    assert (status.level, status.message) == (
        Level.OK, 'ankle_pitch, ankle_roll from motor_left, motor_right')
    assert status.values['mechanical advantage'] == advantage.describe()
    assert status.values['mechanical advantage'].startswith(
        'singular values of d(actuators)/d(outputs) ')
    (left, right) = advantage.ratio
    assert status.values['d(actuators)/d(outputs)'] == (
        f'motor_left: {left[0]:.6g}, {left[1]:.6g}; motor_right: {right[0]:.6g}, {right[1]:.6g}')
    assert status.values['efforts'] == (
        "published: each output joint Mᵀ·(the actuators' measured efforts), every other "
        'published joint 0')
    health.accept(2, followed.follow(2, ['motor_left', 'motor_right'], [0.2, -0.2], [0.0, 0.0]))
    (status,) = transmission_statuses(followed, health)
    assert status.values['efforts'] == (
        'not published: the input does not carry a finite effort of each of motor_left, '
        'motor_right')


def test_the_knees_status_warns_at_its_toggle_and_counts_the_samples_withheld():
    followed = follower('knee')
    health = LoopsHealth(0)
    health.accept(1, followed.follow(1, ['knee_motor'], [0.7], [1.0], [1.0]))
    (status,) = transmission_statuses(followed, health)
    assert status.values['mechanical advantage'].startswith('d(knee_motor)/d(knee_output) = ')
    # the rocker's end (test above): the crank in line with the coupler
    toggle = toggle_angle(followed)
    followed.restart()
    health.accept(2, followed.follow(2, ['knee_motor'], [toggle], [1.0], [1.0]))
    (status,) = transmission_statuses(followed, health)
    assert status.level is Level.WARN
    assert status.message.startswith('group knee_output_pin: the output joints are too near a '
                                     'singular configuration of the transmission')
    assert status.values['efforts'] == (
        'withheld: the transmission is too near a singular configuration')
    assert status.values['efforts withheld (samples)'] == '1'
    assert status.values['mechanical advantage'] == 'none: ' + status.message


# --- the command direction the document shows ---------------------------------------------------

def documented_section(title: str) -> str:
    """Return a section of docs/following_loops.md, from its heading to the next one."""
    text = (REPOSITORY / 'docs' / 'following_loops.md').read_text(encoding='utf-8')
    start = text.index(f'### {title}\n')
    return text[start:text.index('\n##', start + 4)]


def robot_command(urdf: str, measured: tuple[str, ...],
                  outputs: tuple[str, ...]) -> RobotCommand:
    """Return the robot's command direction, its groups those of the node's transmissions."""
    loops = read_loops(read_urdf(urdf))
    plan = loops.plan(measured)
    return RobotCommand([CommandGroup(plan.tree, found.transmission, found.values, loops.loops)
                         for found in plan_transmissions(plan, outputs)], loops.joint_names)


def test_the_documented_boom_trajectory_is_what_the_command_direction_gives():
    """The boom joint's three points in, the boom cylinder's out (positions, velocities)."""
    section = documented_section('The excavator: cylinder forces and a boom trajectory')
    sent = yaml.safe_load(re.search(r'JointTrajectory \\\n  "(\{.*?\})"', section).group(1))
    relayed = yaml.safe_load(re.findall(r'```text\n(.*?)```', section, re.DOTALL)[1])
    command = robot_command((REPOSITORY / 'urdf' / 'excavator.urdf').read_text(encoding='utf-8'),
                            CYLINDERS, BOOM_STICK_BUCKET)
    names = sent['joint_names']
    points = command.trajectory(names, [JointPoint(tuple(point['positions']),
                                                   tuple(point['velocities']))
                                        for point in sent['points']])
    assert list(command.names(names)) == relayed['joint_names'] == ['boom_cylinder']
    assert len(points) == len(relayed['points'])
    for point, given, shown in zip(points, sent['points'], relayed['points']):
        assert list(point.positions) == pytest.approx(shown['positions'], rel=1e-12, abs=1e-15)
        assert list(point.velocities) == pytest.approx(shown['velocities'], rel=1e-12,
                                                       abs=1e-15)
        assert shown['time_from_start'] == given['time_from_start']
    # beyond the stroke: the boom at −1.0 rad needs more than the cylinder's 0.5 m
    with pytest.raises(CommandRefused, match=r"actuator 'boom_cylinder' at 0\.5\d+ outside"):
        command.trajectory(names, [JointPoint((-0.4,)), JointPoint((-1.0,))])


def test_the_documented_ankle_torques_are_what_the_command_direction_gives():
    """Pitch and roll torques in, at the pose the motors measure, the motors' out."""
    section = documented_section("The humanoid ankle's torques")
    sent = yaml.safe_load(re.search(r'Float64MultiArray \\\n  "(\{.*?\})"', section).group(1))
    relayed = yaml.safe_load(re.findall(r'```text\n(.*?)```', section, re.DOTALL)[1])
    # the pose the motors measure in the document's sample, closed as the node closes it
    followed = follower('ankle')
    sample = followed.follow(1, ['motor_left', 'motor_right'], [0.2, -0.2], [0.5, 0.5])
    (found,) = followed.output_efforts.groups
    transmission = found.transmission
    ratio = transmission.ratio(transmission.local(
        [0.2, -0.2], [sample.joints[joint] for joint in transmission.solved]))
    motors = actuator_efforts(ratio, sent['data'])
    assert list(motors) == pytest.approx(relayed['data'], rel=1e-12)
    command = robot_command(ANKLE, ('motor_left', 'motor_right'), ('ankle_pitch', 'ankle_roll'))
    point = command.convert(['ankle_pitch', 'ankle_roll'], JointPoint(
        (sample.joints['ankle_pitch'], sample.joints['ankle_roll']), (), (),
        tuple(sent['data'])))
    assert list(point.efforts) == pytest.approx(relayed['data'], rel=1e-12)
