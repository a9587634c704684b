# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
loops.command_batch: a trajectory converted at once equals its points converted one by one.

Along test_command.py's motions of the humanoid ankle, the lab knee, the excavator and the
five-bar, and the relay bench's biped swing: positions, velocities and efforts from the batch
within 1e-14 (relative; absolute below 1) of the per-point path's (each point alone, continuing
from the last), the batch taken (not declined) for every group, and the state after it the
per-point path's (the next command gives the same). A trajectory the per-point path refuses is
refused whole with the same reason, point number and detail, the state as before: ramps out of
reach, past a singular configuration, past an actuator's limit, with NaN or a short array late
in the trajectory. Under it, the batched closure Jacobian and transmission (orientations,
conditionings, M) are the per-sample ones within 1e-14 at poses around each robot's assembly.
The 50-digit checks stay test_command.py's (the batch's answers are the per-point path's to
1e-14).
"""

from __future__ import annotations

import math
from pathlib import Path
import sys

from linkage_kinematics.loops.command import CommandRefusal, CommandRefused, JointPoint
from linkage_kinematics.loops.command_batch import convert_many
import numpy as np
import pytest
from test_command import EFFORTS, motion, MOTIONS
import transmission_robots

# the bench's biped and its swing, as bench/run.py imports them
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / 'bench'))

import relay_bench  # noqa: E402, I100

TOLERANCE = 1e-14
SAMPLES = 400


def _points(robot: str, velocities: bool, efforts: bool) -> list[JointPoint]:
    points = []
    for sample in range(SAMPLES):
        found = motion(robot, sample)
        points.append(JointPoint(
            tuple(value for value, _, _ in found.values()),
            tuple(rate for _, rate, _ in found.values()) if velocities else (), (),
            tuple(0.5 * math.sin(0.01 * sample + place) * effort
                  for place, effort in enumerate(EFFORTS[robot])) if efforts else ()))
    return points


def _one_by_one(command, names, points) -> tuple[JointPoint, ...]:
    return tuple(command.trajectory(names, [point])[0] for point in points)


def _assert_close(found, expected) -> None:
    assert len(found) == len(expected)
    for point, reference in zip(found, expected):
        for array, wanted in zip(point, reference):
            assert len(array) == len(wanted)
            for value, exact in zip(array, wanted):
                assert abs(value - exact) <= TOLERANCE * max(abs(exact), 1.0), (value, exact)


@pytest.mark.parametrize('robot', list(MOTIONS))
@pytest.mark.parametrize(('velocities', 'efforts'), [(False, False), (True, False),
                                                     (True, True)])
def test_a_trajectory_at_once_is_its_points_one_by_one(robot, velocities, efforts):
    batched, single = transmission_robots.build(robot), transmission_robots.build(robot)
    names = tuple(MOTIONS[robot])
    points = _points(robot, velocities, efforts)
    _assert_close(batched.robot.trajectory(names, points),
                  _one_by_one(single.robot, names, points))
    following = _points(robot, velocities, efforts)[:1]
    _assert_close(batched.robot.trajectory(names, following),
                  single.robot.trajectory(names, following))


@pytest.mark.parametrize('robot', list(MOTIONS))
def test_every_group_takes_the_batch(robot):
    built = transmission_robots.build(robot)
    points = np.array([[motion(robot, sample)[name][0] for name in MOTIONS[robot]]
                       for sample in range(SAMPLES)])
    for command in built.commands:
        places = [list(MOTIONS[robot]).index(name) for name in command.outputs]
        assert convert_many(command, points[:, places], points[:, places] * 0.1,
                            None) is not None


@pytest.mark.parametrize('rates', [False, True])
def test_the_biped_s_swing_at_once_is_its_points_one_by_one(rates):
    batched = relay_bench.relay_for_biped().command
    single = relay_bench.relay_for_biped().command
    names, given = relay_bench.trajectory_points(rates, False)
    points = [JointPoint(point.positions, point.velocities) for point in given]
    _assert_close(batched.trajectory(names, points), _one_by_one(single, names, points))


def _refusal(call) -> tuple[CommandRefusal, str]:
    with pytest.raises(CommandRefused) as refused:
        call()
    return refused.value.reason, refused.value.detail


def _per_point_refusal(command, names, points) -> tuple[CommandRefusal, str]:
    for number, point in enumerate(points):
        try:
            command.trajectory(names, [point])
        except CommandRefused as refusal:
            return refusal.reason, f'point {number}: ' + refusal.detail.removeprefix('point 0: ')
    raise AssertionError('the per-point path refused nothing')


def _ramp(start: tuple[float, ...], end: tuple[float, ...], count: int) -> list[JointPoint]:
    return [JointPoint(tuple(a + (b - a) * k / (count - 1) for a, b in zip(start, end)))
            for k in range(count)]


@pytest.mark.parametrize(('robot', 'points', 'reason'), [
    ('knee', _ramp((0.2,), (1.5,), 200), CommandRefusal.UNREACHABLE),
    ('knee_reversed', _ramp((0.0,), (2.5,), 200), CommandRefusal.SINGULAR),
    ('excavator', _ramp((0.0, 0.0, 0.3), (1.0, 0.0, 0.3), 200), CommandRefusal.LIMIT),
    ('ankle', _ramp((0.0, 0.0), (0.3, 0.2), 50)
     + [JointPoint((0.3, math.nan))], CommandRefusal.NOT_FINITE),
    ('ankle', _ramp((0.0, 0.0), (0.3, 0.2), 50) + [JointPoint((0.3,))],
     CommandRefusal.JOINTS),
])
def test_a_refused_trajectory_is_refused_as_point_by_point(robot, points, reason):
    batched, single = transmission_robots.build(robot), transmission_robots.build(robot)
    names = transmission_robots.build(robot).robot.groups[0].outputs if robot != 'excavator' \
        else tuple(MOTIONS['excavator'])
    before = [command.state() for command in batched.commands]
    found = _refusal(lambda: batched.robot.trajectory(names, points))
    if reason in (CommandRefusal.NOT_FINITE, CommandRefusal.JOINTS):
        # checked before any point is converted, the same for both paths
        assert found[0] is reason and found[1].startswith(f'point {len(points) - 1}: ')
    else:
        assert found == _per_point_refusal(single.robot, names, points)
        assert found[0] is reason
    assert [command.state() for command in batched.commands] == before


@pytest.mark.parametrize('robot', list(MOTIONS))
def test_the_batched_jacobian_and_transmission_are_the_per_sample_ones(robot):
    rng = np.random.default_rng(30)
    for command in transmission_robots.build(robot).commands:
        transmission = command.transmission
        equations = transmission.equations
        start = np.array([command.state().values[i] for i in equations.coordinates])
        poses = start + 0.05 * rng.standard_normal((40, len(start)))
        batch = transmission.batch
        assert batch.supports
        jacobians = batch.jacobian(batch.evaluate(poses))
        many = transmission.linearize_many(poses)
        for row, pose in enumerate(poses.tolist()):
            exact = np.array(equations.jacobian(equations.evaluate(pose)))
            assert np.max(np.abs(jacobians[row] - exact)) <= TOLERANCE * np.max(np.abs(exact))
            one = transmission.linearize(pose)
            assert (one.measured_orientation, one.command_orientation) == (
                many.measured_orientation[row], many.command_orientation[row])
            for found, exact_value in ((many.measured_conditioning[row],
                                        one.measured_conditioning),
                                       (many.command_conditioning[row],
                                        one.command_conditioning)):
                assert abs(found - exact_value) <= TOLERANCE * exact_value
            ratio = np.array(one.ratio)
            assert np.max(np.abs(many.ratio[row] - ratio)) <= TOLERANCE * np.max(np.abs(ratio))
