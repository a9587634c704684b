# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
loops.command: commands in the output joints turned into the actuators', checked independently.

Along a motion of every robot of test/transmission_robots.py (the humanoid ankle, the lab knee's
four-bar, an excavator's three cylinders, a planar five-bar), against the 50-digit references
(test/closure_reference.py, test/loop_reference.py), not the package's own equations:
actuator and passive positions within 1e-12 (rad or m); velocities within 1e-12 relative;
accelerations against central differences of the reference's velocities at 50 digits within
1e-12 relative; actuator efforts against M⁻ᵀ·τ_o with the reference's M within 1e-12 relative,
and the power balance to rounding; the round trip (the commanded actuators fed to the measured
direction's own solver) returns the output joints within 1e-12. Then the refusals, each by
reason, the state kept; continuation over far points; ``RobotCommand``'s names and arrays;
idle freedoms and redundant rows (test/closure_robots.py's rod with two balls, collinear pins,
planar weld, delta-like) held in both directions: the round trip within 1e-14.
"""

from __future__ import annotations

import math
import sys

import closure_robots
from linkage_kinematics.loops.command import (
    CommandGroup,
    CommandRefusal,
    CommandRefused,
    JointPoint,
)
from linkage_kinematics.loops.robot_command import RobotCommand
from linkage_kinematics.loops.structure import GroupKind
from linkage_kinematics.loops.transmission import Transmission
from mpmath import mp, mpf
import pytest
import transmission_robots
from transmission_robots import (
    reference_pose,
    reference_ratio,
    reference_velocities,
    relative,
)

EPSILON = sys.float_info.epsilon
# robot → per output joint (centre, amplitude, period in samples); a motion of 400 samples
MOTIONS = {
    'ankle': {'ankle_pitch': (0.0, 0.3, 400), 'ankle_roll': (0.0, 0.2, 300)},
    'knee': {'knee_output': (0.15, 0.4, 400)},
    'excavator': {'boom_joint': (0.0, 0.5, 400), 'stick_joint': (0.0, 0.5, 300),
                  'bucket_joint': (0.3, 0.5, 350)},
    # near its drawing the second chain is nearly stretched: j4 reaches only some 0.05 rad up
    'five_bar': {'j2': (0.05, 0.05, 400), 'j4': (-0.05, 0.06, 300)},
}
# how each robot's command groups are solved
KINDS = {'ankle': [GroupKind.LEG_INVERSE, GroupKind.LEG_INVERSE],
         'knee': [GroupKind.PLANAR_LOOPS],
         'excavator': [GroupKind.PLANAR_LOOPS] * 3,
         'five_bar': [GroupKind.NEWTON]}
SECONDS = 0.01  # between samples
# N·m or N at the output joints (the five-bar's actuators have an effort limit of 1 N·m)
EFFORTS = {'ankle': (3.0, -2.0), 'knee': (3.0,), 'excavator': (3e4, -2e4, 1.5e4),
           'five_bar': (0.3, -0.2)}
STEP = mpf('1e-12')  # the reference's central differences, in seconds


def motion(robot: str, sample: float) -> dict[str, tuple[float, float, float]]:
    """Return each output joint's position, velocity and acceleration at ``sample``."""
    found = {}
    for place, (name, (centre, amplitude, period)) in enumerate(MOTIONS[robot].items()):
        w = 2.0 * math.pi / (period * SECONDS)
        phase = w * sample * SECONDS + place
        found[name] = (centre + amplitude * math.sin(phase), amplitude * w * math.cos(phase),
                       -amplitude * w * w * math.sin(phase))
    return found


def exact_motion(robot: str, sample: int, offset: mpf) -> dict[str, tuple[mpf, mpf]]:
    """
    Return each output's position and velocity ``offset`` s after ``sample`` (50 digits).

    The motion through the floats given at the sample with their acceleration held: its
    acceleration there is exactly the one the package was given.
    """
    found = {}
    for name, (position, rate, acceleration) in motion(robot, sample).items():
        found[name] = (mpf(position) + mpf(rate) * offset + mpf(acceleration) * offset ** 2 / 2,
                       mpf(rate) + mpf(acceleration) * offset)
    return found


def commanded(robot, sample: int) -> JointPoint:
    """Return the robot's output joints' point at ``sample``, in ``robot.outputs`` order."""
    found = motion(robot.name, sample)
    return JointPoint(tuple(found[name][0] for name in robot.outputs),
                      tuple(found[name][1] for name in robot.outputs),
                      tuple(found[name][2] for name in robot.outputs),
                      EFFORTS[robot.name])


@pytest.mark.parametrize('name', list(MOTIONS))
def test_a_motion_is_commanded_within_1e_12_of_the_reference_and_returns(name):
    robot = transmission_robots.build(name)
    returned = transmission_robots.build(name)  # the measured direction, on its own
    assert [kind for command in robot.commands for kind in command.kinds] == KINDS[name]
    names = robot.robot.names(robot.outputs)
    assert names == tuple(a for t in robot.transmissions for a in t.actuators)
    checked = 0
    for sample in range(401):
        point = commanded(robot, sample)
        actuators = robot.robot.convert(robot.outputs, point)
        results = {}
        for place, command in enumerate(robot.commands):
            # the last point each group accepted, with its passive joints
            results.update({n: command.position(n) for n in (*command.actuators,
                                                             *command.passive)})
            found = returned.planned[place].solver.solve(
                [actuators.positions[names.index(a)] for a in command.actuators],
                [actuators.velocities[names.index(a)] for a in command.actuators])
            solved = returned.planned[place].structure.solved
            for output in command.outputs:
                given = point.positions[robot.outputs.index(output)]
                rate = point.velocities[robot.outputs.index(output)]
                # the round trip: the measured direction gives the commanded outputs back
                assert abs(found.positions[solved.index(output)] - given) <= 1e-12
                assert abs(found.velocities[solved.index(output)] - rate) <= 1e-12 * max(
                    1.0, abs(rate))
        if sample % 200 == 100:
            check_against_reference(robot, sample, point, actuators, results, names)
            checked += 1
    assert checked == 2


def check_against_reference(robot, sample, point, actuators, results, names):
    """Check one point: positions, velocities, accelerations, efforts, power balance."""
    outputs = {name: point.positions[k] for k, name in enumerate(robot.outputs)}
    rates = {name: point.velocities[k] for k, name in enumerate(robot.outputs)}
    ours, solved = {}, {}
    for command in robot.commands:  # the full path at the same point: every passive joint
        found = command.solve([outputs[n] for n in command.outputs],
                              [rates[n] for n in command.outputs],
                              [point.accelerations[robot.outputs.index(n)]
                               for n in command.outputs])
        # the lean path's answer to rounding (a leg's crank from another start)
        lean = [results[n] for n in command.actuators]
        assert max(abs(x - y) for x, y in zip(found.actuators.positions, lean)) <= 4 * EPSILON
        for joints, side in ((command.actuators, found.actuators),
                             (command.passive, found.passive)):
            solved.update(zip(joints, side.positions))
            ours.update(zip(joints, zip(side.velocities, side.accelerations)))
    exact = reference_pose(robot, outputs, solved)
    loop_joints = robot.loop_joints()
    assert max(abs(solved[n] - float(exact[n])) for n in loop_joints) <= 1e-12
    velocities = reference_velocities(robot, {**outputs, **exact}, rates)
    assert relative([ours[n][0] for n in loop_joints],
                    [velocities[n] for n in loop_joints]) <= 1e-12
    # accelerations: central differences of the reference's velocities along the motion
    with mp.workdps(50):
        sides = []
        for offset in (STEP, -STEP):
            moved = {n: value for n, (value, _) in exact_motion(robot.name, sample,
                                                                offset).items()}
            moved_rates = {n: rate for n, (_, rate) in exact_motion(robot.name, sample,
                                                                    offset).items()}
            pose = reference_pose(robot, moved, results)
            sides.append(reference_velocities(robot, {**moved, **pose}, moved_rates))
        accelerations = {n: (sides[0][n] - sides[1][n]) / (2 * STEP) for n in loop_joints}
    assert relative([ours[n][1] for n in loop_joints],
                    [accelerations[n] for n in loop_joints]) <= 1e-12
    # efforts: τ_m = M⁻ᵀ·τ_o with the reference's M; the power balance
    for place, command in enumerate(robot.commands):
        efforts = [EFFORTS[robot.name][robot.outputs.index(n)] for n in command.outputs]
        with mp.workdps(50):
            ratio = reference_ratio(robot, place, {**outputs, **exact})
            expected = mp.lu_solve(ratio.T, mp.matrix([mpf(e) for e in efforts]))
        found = actuators.efforts
        mine = [found[names.index(a)] for a in command.actuators]
        assert relative(mine, list(expected)) <= 1e-12
        speeds = [actuators.velocities[names.index(a)] for a in command.actuators]
        output_rates = [rates[n] for n in command.outputs]
        actuator_power = math.fsum(t * v for t, v in zip(mine, speeds))
        output_power = math.fsum(t * v for t, v in zip(efforts, output_rates))
        scale = math.fsum(abs(t * v) for t, v in zip(efforts, output_rates))
        assert abs(actuator_power - output_power) <= 16 * EPSILON * scale


def test_a_refused_point_leaves_every_group_as_it_was():
    robot = transmission_robots.build('ankle')
    command = robot.robot
    names = robot.outputs
    command.convert(names, JointPoint((0.1, 0.05)))
    before = command.convert(names, JointPoint((0.12, 0.06)))
    command.convert(names, JointPoint((0.1, 0.05)))
    for bad, reason in (((0.1, math.nan), CommandRefusal.NOT_FINITE),
                        ((0.1, math.inf), CommandRefusal.NOT_FINITE),
                        ((2.0, 0.0), CommandRefusal.LIMIT),  # pitch 2 rad: motors past ±1.2
                        ((0.1, 0.05, 0.0), CommandRefusal.JOINTS)):
        with pytest.raises(CommandRefused) as refused:
            command.convert(names, JointPoint(bad))
        assert refused.value.reason is reason
    assert command.convert(names, JointPoint((0.12, 0.06))) == before


def test_names_and_arrays_that_do_not_fit_are_refused_and_other_joints_pass_through():
    robot = transmission_robots.build('ankle')
    command = RobotCommand(robot.commands, [joint.name for joint in
                                            robot.tree.joint_above.values()] + ['toe'])
    names = ('toe', 'ankle_roll', 'ankle_pitch')
    assert command.names(names) == ('toe', 'motor_left', 'motor_right')
    point = command.convert(names, JointPoint((0.7, 0.05, 0.1), (1.5, 0.0, 0.0), (),
                                              (2.0, 0.0, 0.0)))
    alone = transmission_robots.build('ankle').commands[0].solve((0.1, 0.05), (0.0, 0.0), (),
                                                                 (0.0, 0.0))
    assert point == JointPoint((0.7, *alone.actuators.positions),
                               (1.5, *alone.actuators.velocities), (),
                               (2.0, *alone.actuators.efforts))
    # the toe alone: nothing of the loops is solved
    assert command.convert(('toe',), JointPoint((0.3,))) == JointPoint((0.3,))
    for names, point, detail in (
            (('toe', 'nope'), JointPoint((0.0, 0.0)), "joint 'nope' is not a joint of the robot"),
            (('motor_left',), JointPoint((0.0,)),
             "joint 'motor_left' is solved by group ball_left+ball_right: command its output "
             'joints'),
            (('rod_left_u1',), JointPoint((0.0,)),
             "joint 'rod_left_u1' is solved by group ball_left+ball_right: command its output "
             'joints'),
            (('ankle_pitch',), JointPoint((0.0,)),
             "group ball_left+ball_right needs all its output joints ['ankle_pitch', "
             "'ankle_roll']; ['ankle_roll'] missing"),
            (('toe', 'toe'), JointPoint((0.0, 0.0)), "joints named twice: ['toe']"),
            (('ankle_pitch', 'ankle_roll'), JointPoint((0.0,)),
             '1 positions for 2 joints'),
            (('ankle_pitch', 'ankle_roll'), JointPoint((0.0, 0.0), (), (0.0, 0.0)),
             'accelerations without velocities'),
            (('ankle_pitch', 'ankle_roll'), JointPoint((), (0.0, 0.0)),
             "the loops' output joints need positions")):
        with pytest.raises(CommandRefused) as refused:
            command.convert(names, point)
        assert refused.value.reason is CommandRefusal.JOINTS
        assert refused.value.detail == detail
    with pytest.raises(CommandRefused) as refused:
        command.convert(('toe', 'ankle_pitch', 'ankle_roll'),
                        JointPoint((0.0, 0.1, 0.1), (math.nan, 0.0, 0.0)))
    assert refused.value.reason is CommandRefusal.NOT_FINITE
    assert str(refused.value) == "a value is not finite: joint 'toe': velocities nan"


def test_a_trajectory_is_refused_whole_and_leaves_the_state_as_it_was():
    robot = transmission_robots.build('knee')
    fresh = transmission_robots.build('knee')
    names = ('knee_output',)
    points = [JointPoint((value,)) for value in (0.2, 0.4, 0.6, 0.8, 0.5)]
    with pytest.raises(CommandRefused) as refused:
        robot.robot.trajectory(names, points)
    assert refused.value.reason is CommandRefusal.UNREACHABLE
    assert refused.value.detail.startswith('point 3: group knee_output_pin: no assembly '
                                           'reaches the known joints')
    assert robot.commands[0].position('knee_motor') == fresh.commands[0].position('knee_motor')
    assert (robot.robot.trajectory(names, points[:3] + points[4:])
            == fresh.robot.trajectory(names, points[:3] + points[4:]))


def test_far_points_are_reached_by_continuation_and_a_crossing_is_refused():
    # one step of 0.6 rad: the motor as after sixty small ones
    far, near = transmission_robots.build('knee'), transmission_robots.build('knee')
    jump = far.commands[0].solve((0.6,)).actuators.positions[0]
    for step in range(1, 61):
        walked = near.commands[0].solve((0.01 * step,)).actuators.positions[0]
    assert abs(jump - walked) <= 1e-13
    # the crank as the output: past the rocker's end the actuator would turn back, and the
    # node's measured direction would have to change assemblies
    reversed_knee = transmission_robots.build('knee_reversed')
    command = reversed_knee.commands[0]
    good, bad, start = 0.0, 2.5, command.position('knee_output')
    with pytest.raises(CommandRefused) as refused:
        command.solve((bad,))
    assert refused.value.reason is CommandRefusal.SINGULAR
    assert command.position('knee_output') == start
    for _ in range(60):  # to the rocker's end: the measured direction is too near it
        middle = 0.5 * (good + bad)
        try:
            command.solve((middle,))
            good = middle
        except CommandRefused as error:
            bad, refused_at = middle, error
    assert refused_at.reason is CommandRefusal.SINGULAR
    assert "the measured direction's conditioning" in refused_at.detail


def test_an_actuator_leaving_its_urdf_limit_refuses_the_point():
    excavator = transmission_robots.build('excavator')
    boom = excavator.commands[0]
    assert boom.actuators == ('boom_cylinder',)
    before = boom.position('boom_cylinder')
    for given, start in (
            (((1.0,), (), (), ()), "group boom_cylinder_pin: actuator 'boom_cylinder' at "),
            (((0.1,), (3.0,), (), ()),
             "group boom_cylinder_pin: actuator 'boom_cylinder' velocity "),
            (((0.1,), (0.0,), (), (1e6,)),
             "group boom_cylinder_pin: actuator 'boom_cylinder' effort ")):
        with pytest.raises(CommandRefused) as refused:
            boom.solve(*given)
        assert refused.value.reason is CommandRefusal.LIMIT
        assert refused.value.detail.startswith(start)
        assert boom.position('boom_cylinder') == before


@pytest.mark.parametrize('mechanism, outputs, start', [
    ('rod_two_balls', ('rocker',), {'crank': 0.4}),  # the rod spins idle both ways
    ('collinear_pins', ('p3',), None),  # the short link turns idle both ways
    ('planar_weld', ('k4',), None),  # six rows of rank three
    ('delta_like', ('elbow0_Y', 'elbow1_Y', 'elbow2_Y'), None),  # three idle spins
])
def test_idle_freedoms_and_redundant_rows_are_held_both_ways(mechanism, outputs, start):
    """The round trip within 1e-14 and the power balance to rounding, M without idle motion."""
    built = getattr(closure_robots, mechanism)()
    planned = closure_robots.plan(built, start=start)
    transmission = Transmission(planned.tree, planned.group, planned.structure, outputs,
                                planned.assembly.values)
    command = CommandGroup(planned.tree, transmission, planned.assembly.values)
    measured = closure_robots.plan(built, start=start)
    solved = measured.structure.solved
    base = [command.position(name) for name in outputs]
    for step in range(1, 101):
        target = [b + 0.05 * math.sin(0.05 * step + k) for k, b in enumerate(base)]
        rates = [0.01 * (k + 1) for k in range(len(outputs))]
        efforts = [0.1] * len(outputs)
        found = command.solve(target, rates, (), efforts).actuators
        state = measured.solver.solve(list(found.positions), list(found.velocities))
        for name, value, rate in zip(outputs, target, rates):
            assert abs(state.positions[solved.index(name)] - value) <= 1e-14
            assert abs(state.velocities[solved.index(name)] - rate) <= 1e-14
        actuator_power = math.fsum(t * v for t, v in zip(found.efforts, found.velocities))
        output_power = math.fsum(t * v for t, v in zip(efforts, rates))
        assert abs(actuator_power - output_power) <= 8 * EPSILON * abs(output_power)
