# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
loops.robot_command.plan_command: a robot's command direction built from its description.

As the command relay builds it (the description read once, the loops planned as the loops node
plans them): along a motion of the humanoid ankle, the lab knee and the excavator, the actuators
within 1e-12 of the 50-digit references (test/closure_reference.py, test/loop_reference.py) and,
fed to the loops node's own follower, the output joints back within 1e-12; a planar loop's
``loops.branches`` honoured in both directions; output joints that cannot be the groups' refused
in one line naming each problem.
"""

from __future__ import annotations

import math

from linkage_kinematics.loops.command import JointPoint
from linkage_kinematics.loops.follower import LoopSample, RobotLoopsFollower
from linkage_kinematics.loops.plan import read_loops
from linkage_kinematics.loops.robot_command import plan_command
from linkage_kinematics.loops.transmission import TransmissionError
from linkage_kinematics.model.urdf_reader import read_urdf
import pytest
from test_command import motion
import transmission_robots
from transmission_robots import reference_pose

TOLERANCE = 1e-12


@pytest.mark.parametrize('name', ['ankle', 'knee', 'excavator'])
def test_the_description_s_command_direction_is_the_reference_s_and_returns(name):
    robot = transmission_robots.build(name)
    loops = read_loops(read_urdf(robot.urdf))
    command = plan_command(loops, robot.measured, robot.outputs)
    follower = RobotLoopsFollower(loops, robot.measured, {}, math.pi)
    names = command.names(robot.outputs)
    assert set(names) == set(robot.measured)
    for sample in range(0, 400, 10):
        wanted = {output: value for output, (value, _, _) in motion(name, sample).items()}
        found = command.convert(robot.outputs,
                                JointPoint(tuple(wanted[n] for n in robot.outputs)))
        actuators = dict(zip(names, found.positions))
        returned = follower.follow(1_000_000_000 + sample, names, found.positions,
                                   (0.0,) * len(names))
        assert isinstance(returned, LoopSample), returned
        assert max(abs(returned.joints[n] - wanted[n]) for n in robot.outputs) <= TOLERANCE
        if sample % 100 == 0:
            guess = {n: group.position(n) for group in command.groups
                     for n in (*group.actuators, *group.passive)}
            exact = reference_pose(robot, wanted, guess)
            assert max(abs(actuators[n] - float(exact[n])) for n in names) <= TOLERANCE


def test_a_planar_loop_s_branch_is_the_one_the_loops_node_is_given():
    robot = transmission_robots.build('knee')
    loops = read_loops(read_urdf(robot.urdf))
    zero_branch = loops.plan(robot.measured).loops[0].branch
    answers = {}
    for branches in ({}, {'knee_output_pin': -zero_branch}):
        command = plan_command(loops, robot.measured, robot.outputs, branches)
        follower = RobotLoopsFollower(loops, robot.measured, branches, math.pi)
        assembled = command.groups[0].position('knee_output')
        for step, change in enumerate((0.05, 0.1, -0.1)):
            found = command.convert(['knee_output'], JointPoint((assembled + change,)))
            returned = follower.follow(1_000_000_000 + step, ['knee_motor'], found.positions,
                                       (0.0,))
            assert abs(returned.joints['knee_output'] - (assembled + change)) <= TOLERANCE
        answers[bool(branches)] = (assembled, found.positions[0])
    # the other assembly: the rocker elsewhere at the crank's zero, the crank elsewhere after
    assert abs(answers[True][0] - answers[False][0]) > 1.0
    assert abs(answers[True][1] - answers[False][1]) > 0.1


@pytest.mark.parametrize(('outputs', 'problem'), [
    ([], 'group knee_output_pin: output joints []: 0 joints for 1 degrees of freedom that move '
         "it (as many as its actuators ['knee_motor'])"),
    (['knee_motor'], "group knee_output_pin: output joints ['knee_motor']: ['knee_motor'] are "
                     "measured; an output joint is one the actuators ['knee_motor'] move"),
    (['nope', 'knee_output'], "output joint 'nope' is not a joint of the robot"),
    (['knee_output', 'knee_link'], "group knee_output_pin: output joints ['knee_output', "
                                   "'knee_link']: 2 joints for 1 degrees of freedom that move it "
                                   "(as many as its actuators ['knee_motor'])"),
])
def test_output_joints_that_cannot_be_the_groups_are_refused_in_one_line(outputs, problem):
    loops = read_loops(read_urdf(transmission_robots.KNEE))
    with pytest.raises(TransmissionError) as refused:
        plan_command(loops, ['knee_motor'], outputs)
    assert str(refused.value) == problem
