# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The loop test robots and the independent loop reference, checked against each other and urchin.

The robots (loop_robots.py) must close at their drawn zero pose and over their measured ranges;
the reference (loop_reference.py) must close every constraint there, to 1e-40 m in its own
50-digit arithmetic and to 1e-12 m in urchin's float64 forward kinematics, and its velocities
must be the derivatives of its positions. Nothing here imports the package, so the reference
stays independent of the closed forms it will judge.
"""

from __future__ import annotations

import functools
import itertools
import math

from loop_reference import (
    closure_residuals,
    CONVERGED,
    link_poses,
    loop_joints,
    NotClosed,
    parse,
    planar_residuals,
    solve,
    velocities,
)
from loop_robots import (
    excavator,
    four_bar_knee,
    parallelogram,
    parallelogram_mimic,
    ROBOTS,
    slider_crank,
)
from mpmath import mp, mpf
import numpy as np
import pytest

# What float64 forward kinematics of metre-sized robots can show: a few 1e-16 m of rounding.
FLOAT_CLOSURE = 1e-12
# Samples along each robot's measured range: half walk from the zero pose to the top of the
# range, half to the bottom, each answer the next guess (the zero pose's assembly branch).
SWEEP_SAMPLES = 25
# A walk of 12 steps over at most 0.6 rad or 0.2 m moves no passive joint by more than this
# on its branch (measured: 0.04); a jump to another branch moves some joint by far more.
LARGEST_STEP = 0.1
# Central differences in 50 digits: step 1e-12 leaves a truncation error of about 1e-24 and
# a rounding error of about CONVERGED/1e-12 = 1e-28.
DIFFERENCE_STEP = mpf('1e-12')
DIFFERENCE_ACCURACY = 1e-18
# Two solves of the same closed loops agree to their residual times the condition (≲ 1e3).
SAME_ROOT = 1e-35


def measured_at(name: str, fraction: float) -> dict[str, float]:
    """Return the measured joints ``fraction`` of the way from 0 to the top (>0) or bottom (<0)."""
    return {joint: (high if fraction > 0 else -low) * fraction
            for joint, (low, high) in ROBOTS[name].measured_ranges.items()}


@functools.lru_cache(maxsize=None)
def sweep(name: str) -> list[tuple[dict[str, float], dict[str, mpf]]]:
    """Walk the reference along the measured range from the zero pose: (measured, passive)."""
    urdf = ROBOTS[name].urdf()
    half = SWEEP_SAMPLES // 2
    samples = []
    for direction in (1, -1):
        guess: dict[str, mpf] = {}
        for step in range(1 if direction == -1 else 0, half + 1):
            measured = measured_at(name, direction * step / half)
            guess = solve(urdf, measured, guess)
            samples.append((measured, guess))
    assert len(samples) == SWEEP_SAMPLES
    return samples


@pytest.mark.parametrize('name', ROBOTS)
def test_robot_closes_at_its_drawn_zero_pose(name: str) -> None:
    robot = ROBOTS[name]
    urdf = robot.urdf()
    gaps = closure_residuals(urdf, {})
    assert set(gaps) == set(robot.loops)
    assert max(gaps.values()) < FLOAT_CLOSURE
    # The zero pose is the answer at measured = 0: the drawing closes there, not nearby.
    at_zero = solve(urdf, {joint: 0.0 for joint in robot.measured_joints}, {})
    assert set(at_zero) == set(robot.passive_joints)
    assert max(abs(value) for value in at_zero.values()) < FLOAT_CLOSURE


@pytest.mark.parametrize('name', ROBOTS)
def test_each_loop_is_three_tree_joints_with_at_most_one_slider(name: str) -> None:
    robot = ROBOTS[name]
    urdf = robot.urdf()
    joints = parse(urdf).joints
    assert set(parse(urdf).constraints) == set(robot.loops)
    for constraint, documented in robot.loops.items():
        path = loop_joints(urdf, constraint)
        assert len(path) == 3 and set(path) == documented, constraint
        kinds = sorted(joints[joint].kind for joint in path)
        assert kinds in (['revolute'] * 3, ['prismatic', 'revolute', 'revolute']), constraint
    in_loops = set().union(*robot.loops.values())
    assert in_loops == set(robot.measured_joints) | set(robot.passive_joints)
    assert not set(robot.measured_joints) & set(robot.passive_joints)


def test_frames_must_be_derived_not_read_off() -> None:
    knee = parse(four_bar_knee()).joints.values()
    assert any(joint.axis == (0.0, 0.0, -1.0) for joint in knee)
    assert len({joint.origin.rpy[2] for joint in knee}) == len(knee)  # yaws all differ
    assert any(joint.origin.xyz[2] != 0.0 for joint in knee)          # stacked in depth
    digger = parse(excavator())
    for joint in digger.joints.values():
        assert joint.origin.rpy != (0.0, 0.0, 0.0), joint.name
    assert any(joint.origin.rpy[0] != 0.0 for joint in digger.joints.values())  # tilted frame
    assert any(joint.axis[1] == -1.0 for joint in digger.joints.values())


@pytest.mark.parametrize('name', ROBOTS)
def test_reference_closes_every_constraint_along_the_measured_range(name: str) -> None:
    urdf = ROBOTS[name].urdf()
    samples = sweep(name)
    for index, (measured, passive) in enumerate(samples):
        values = {**measured, **passive}
        assert max(planar_residuals(urdf, values).values()) <= CONVERGED
        assert max(closure_residuals(urdf, values).values()) < FLOAT_CLOSURE
        if index > 0:
            # The walk down starts again from the zero pose, the first sample.
            _, before = samples[0 if index == SWEEP_SAMPLES // 2 + 1 else index - 1]
            assert max(abs(passive[joint] - before[joint]) for joint in passive) < LARGEST_STEP


@pytest.mark.parametrize('name', ROBOTS)
def test_velocities_are_the_derivatives_of_the_positions(name: str) -> None:
    urdf = ROBOTS[name].urdf()
    samples = sweep(name)
    for measured, passive in (samples[3], samples[SWEEP_SAMPLES // 2], samples[-2]):
        # Different rates per measured joint, so a swapped column would show.
        rates = {joint: 0.3 + 0.5 * index for index, joint in enumerate(measured)}
        computed = velocities(urdf, {**measured, **passive}, rates)
        with mp.workdps(50):
            ahead, behind = (
                solve(urdf, {joint: mpf(value) + sign * DIFFERENCE_STEP * rates[joint]
                             for joint, value in measured.items()}, passive)
                for sign in (1, -1))
            for joint, rate in computed.items():
                difference = (ahead[joint] - behind[joint]) / (2 * DIFFERENCE_STEP)
                assert abs(difference - rate) <= DIFFERENCE_ACCURACY * max(1, abs(rate)), joint
        assert any(abs(rate) > 0.01 for rate in computed.values())


def test_parallelogram_is_exactly_its_linear_mimic() -> None:
    exact_urdf, mimic_urdf = parallelogram(), parallelogram_mimic()
    mimics = {joint.name: joint.mimic for joint in parse(mimic_urdf).joints.values()
              if joint.mimic is not None}
    assert set(mimics) == set(ROBOTS['parallelogram'].passive_joints)
    assert not parse(mimic_urdf).constraints
    for measured, passive in sweep('parallelogram'):
        for joint, (driver, multiplier, offset) in mimics.items():
            assert abs(passive[joint] - (multiplier * measured[driver] + offset)) < FLOAT_CLOSURE
        # urchin moves the mimic robot's links, from the crank alone, where the loop puts them.
        exact = link_poses(exact_urdf, {**measured, **passive})
        faked = link_poses(mimic_urdf, measured)
        for link, pose in faked.items():
            np.testing.assert_allclose(pose, exact[link], rtol=0, atol=FLOAT_CLOSURE)


def test_excavator_loops_solve_one_at_a_time_in_the_documented_order() -> None:
    urdf = excavator()
    measured, all_at_once = sweep('excavator')[SWEEP_SAMPLES // 4]
    known: dict[str, float | mpf] = dict(measured)
    for constraint, joints in ROBOTS['excavator'].loops.items():
        assert len(joints - set(known)) == 2, constraint  # one known joint, two to find
        known.update(solve(urdf, known, {}, constraints=[constraint]))
    for joint, value in all_at_once.items():
        assert abs(known[joint] - value) < SAME_ROOT, joint
    # The bucket's four-bar cannot come first: with the cylinders alone it has three unknowns.
    with pytest.raises(ValueError, match='exactly one known joint'):
        solve(urdf, measured, {}, constraints=['bucket_pin'])


@pytest.mark.parametrize('name', ROBOTS)
def test_any_one_tree_joint_of_a_loop_may_be_the_known_one(name: str) -> None:
    urdf = ROBOTS[name].urdf()
    (_, before), (measured, passive) = sweep(name)[-2:]
    closed = {**measured, **passive}
    for constraint, joints in ROBOTS[name].loops.items():
        for known_joint in joints:
            others = joints - {known_joint}
            known = {joint: value for joint, value in closed.items() if joint not in others}
            # From the walk's previous sample: with a middle joint known there are two
            # assembly branches, and the zero pose may be nearer the other one.
            found = solve(urdf, known, {**measured, **before}, constraints=[constraint])
            assert set(found) == others
            for joint, value in found.items():
                assert abs(value - closed[joint]) < SAME_ROOT, (constraint, known_joint, joint)


def test_reference_refuses_a_loop_that_cannot_close() -> None:
    # A slider 1 m along its line is out of reach of a 5 cm crank and a 13 cm coupler.
    with pytest.raises(NotClosed):
        solve(slider_crank(), {'slider_joint': 1.0}, {})


def test_excavator_closes_at_the_corners_of_its_measured_box() -> None:
    # The sweep moves the three cylinders together to two corners; the box's six others,
    # reached from the zero pose in two steps, close too.
    urdf = excavator()
    ranges = ROBOTS['excavator'].measured_ranges
    for corner in itertools.product(*ranges.values()):
        if corner in (tuple(low for low, _ in ranges.values()),
                      tuple(high for _, high in ranges.values())):
            continue
        guess: dict[str, mpf] = {}
        for fraction in (0.5, 1.0):
            measured = {joint: fraction * value for joint, value in zip(ranges, corner)}
            guess = solve(urdf, measured, guess)
        assert max(closure_residuals(urdf, {**measured, **guess}).values()) < FLOAT_CLOSURE
        assert all(math.isfinite(float(value)) for value in guess.values())
