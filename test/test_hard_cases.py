# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Numerical stability: dead points at float64's limit, scale, extreme rates and many turns.

Near a dead point the exact answer is ill-conditioned: a one-ulp change of the float α alone
moves it by what ``reference.input_floor`` computes (the "input floor"). The library must stay
within 3× that floor, plus a few roundings of the result itself where the floor is smaller
still (far from the dead point). Change points are in test_change_points.py.
"""

from __future__ import annotations

import math

from linkage_kinematics import kinematics
from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import FourBar, PRESETS, UnreachableError
from linkage_kinematics.kinematics.solver import (
    DeadPointError,
    LinkageState,
    RATE_ACCURACY,
    solve,
    solve_many,
    solve_pose,
)
from mpmath import mpf
import numpy as np
import pytest
from reference import input_floor, reference_singular_angles, reference_state, state_errors

# The result's own rounding (relative, or rad for angles) allowed on top of 3× the input floor.
ROUNDING = 2e-15
KINDS = ('angle', 'angular_rate', 'angular_acceleration', 'velocity', 'acceleration')

PAPER = PRESETS['paper'].geometry
CONSTANT = DriveLaw(2.0)
VARIABLE = DriveLaw(0.10, 2.3)


def branch_side(linkage: FourBar, state: LinkageState) -> float:
    """+1 if B is left of the directed line A→C, −1 if right."""
    to_c = (linkage.ground_x - state.pin_a_x, linkage.ground_y - state.pin_a_y)
    to_b = (state.pin_b_x - state.pin_a_x, state.pin_b_y - state.pin_a_y)
    return math.copysign(1.0, to_c[0] * to_b[1] - to_c[1] * to_b[0])


def assert_finite(state: LinkageState) -> None:
    for field_name in LinkageState.__dataclass_fields__:
        assert math.isfinite(getattr(state, field_name)), field_name


def paper_dead_points() -> list[tuple[mpf, int]]:
    """
    Return the paper mechanism's two dead points.

    Each with the direction of its reachable side.
    """
    points = reference_singular_angles(PAPER)

    def nearest(end: float) -> mpf:
        return min(points, key=lambda point: abs(math.remainder(float(point) - end, 2 * math.pi)))

    low, high = PAPER.reachability.intervals[0]
    return [(nearest(low), 1), (nearest(high), -1)]


def refused_by_rule(alpha: float, dead: mpf) -> bool:
    """
    Where solve must refuse.

    A one-ulp change of α moves the exact accelerations (which grow as δ^(−3/2)) by more than
    RATE_ACCURACY.
    """
    delta = abs(float(mpf(alpha) - dead))
    return 1.5 * math.ulp(alpha) / delta > RATE_ACCURACY if delta else True


def test_paper_dead_point_is_where_the_seed_starts_from() -> None:
    (dead, _), _ = paper_dead_points()
    assert round(math.degrees(float(dead)), 3) == -1.941


@pytest.mark.parametrize('offset', [1e-3, 1e-6, 1e-9, 1e-10, 1e-12])
@pytest.mark.parametrize('drive', [CONSTANT, VARIABLE], ids=['constant', 'variable'])
@pytest.mark.parametrize('branch', [1, -1])
def test_approaching_the_paper_dead_points(offset: float, drive: DriveLaw, branch: int) -> None:
    """
    Both dead points (−1.94° and 181.94°), from their reachable sides.

    Every quantity within 3× what a one-ulp change of α does to the exact answer; solve_many agrees
    with solve.
    """
    for dead, side in paper_dead_points():
        alpha = float(dead + side * offset)
        state = solve(PAPER, alpha, drive, branch)
        assert_finite(state)
        assert branch_side(PAPER, state) == branch
        errors = state_errors(state, reference_state(PAPER, alpha, drive, branch))
        floor = input_floor(PAPER, alpha, drive, branch)
        for kind in KINDS:
            assert errors[kind] <= 3.0 * floor[kind] + ROUNDING, (kind, errors, floor)
        many = solve_many(PAPER, np.array([alpha, 0.5]), drive, branch).at(0)
        for name in LinkageState.__dataclass_fields__:
            assert getattr(many, name) == pytest.approx(getattr(state, name), rel=1e-14), name


@pytest.mark.parametrize('exponent', np.arange(-16.5, -10.9, 0.5))
def test_refusal_zone_is_where_float64_cannot_follow(exponent: float) -> None:
    """
    Refuse with DeadPointError exactly where float64 cannot follow, in solve and solve_many.

    That is where a one-ulp change of α moves the exact accelerations by more than
    RATE_ACCURACY (about 1e-14 rad from the −1.94° dead point, 7e-13 rad from the 181.94° one).
    """
    for dead, side in paper_dead_points():
        alpha = float(dead + side * mpf(10) ** mpf(float(exponent)))
        delta = abs(float(mpf(alpha) - dead))
        limit = 1.5 * math.ulp(alpha) / RATE_ACCURACY
        if 0.97 * limit < delta < 1.03 * limit:
            continue  # the rule's own approximation (δ ≈ 2·sin ½δ) may tip either way
        expect_refusal = refused_by_rule(alpha, dead)
        with_many = solve_many(PAPER, np.array([alpha]), VARIABLE) if not expect_refusal else None
        try:
            solve(PAPER, alpha, VARIABLE)
        except DeadPointError as error:
            assert expect_refusal, (alpha, delta)
            assert 'is at a dead point' in str(error)
            with pytest.raises(DeadPointError):
                solve_many(PAPER, np.array([0.5, alpha]), VARIABLE)
            continue
        assert not expect_refusal, (alpha, delta)
        assert with_many is not None and np.all(np.isfinite(with_many.omega_dot_bc))


def test_at_and_past_the_paper_dead_point() -> None:
    (dead, side), _ = paper_dead_points()
    with pytest.raises(DeadPointError, match='-1.940963885°'):
        solve(PAPER, float(dead), CONSTANT)
    with pytest.raises(DeadPointError):
        solve_many(PAPER, np.array([0.0, float(dead)]), CONSTANT)
    for past in (1e-12, 1e-9, 1e-6, 1e-3):
        with pytest.raises(UnreachableError, match=r'\[-1\.941°, 181\.941°\]'):
            solve(PAPER, float(dead - side * past), CONSTANT)
        with pytest.raises(UnreachableError, match=r'\[-1\.941°, 181\.941°\]'):
            solve_many(PAPER, np.array([0.0, float(dead - side * past)]), CONSTANT)


@pytest.mark.parametrize('factor', [1e-6, 1e3])
def test_scale_invariance(factor: float) -> None:
    scaled = PAPER.scaled(factor)
    for alpha in np.linspace(0.0, math.pi / 2, 7):
        for drive in (CONSTANT, VARIABLE):
            base = solve(PAPER, float(alpha), drive)
            other = solve(scaled, float(alpha), drive)
            for name in ('beta', 'gamma', 'transmission_angle'):
                assert getattr(other, name) == pytest.approx(getattr(base, name), abs=1e-12)
            for name in ('omega', 'omega_dot', 'omega_ab', 'omega_bc', 'omega_dot_ab',
                         'omega_dot_bc'):
                assert getattr(other, name) == pytest.approx(getattr(base, name), rel=1e-12)
            for name in ('pin_b_x', 'pin_b_y', 'velocity_a_x', 'velocity_a_y', 'velocity_b_x',
                         'velocity_b_y', 'acceleration_a_x', 'acceleration_a_y',
                         'acceleration_b_x', 'acceleration_b_y'):
                magnitude = max(abs(getattr(base, n)) for n in (name[:-1] + 'x', name[:-1] + 'y'))
                assert getattr(other, name) == pytest.approx(
                    factor * getattr(base, name), abs=1e-12 * factor * magnitude
                ), name


@pytest.mark.parametrize('omega0', [1e-6, -1e-6, 1e-3, 1.0, -7.5, 1e4, -1e4])
@pytest.mark.parametrize('k', [0.0, 10.0, -10.0, 0.37])
def test_extreme_drive_rates(omega0: float, k: float) -> None:
    """
    Angular rates are ω times a geometric ratio; accelerations follow α̈ = k·ω.

    All match the reference from 1e-6 to 1e4 rad/s.
    """
    for alpha in (0.05, 0.8, 2.0):
        drive = DriveLaw(omega0, k)
        omega = drive.angular_velocity(alpha)
        if abs(omega) < 1e-9:
            continue
        state = solve(PAPER, alpha, drive)
        unit = solve(PAPER, alpha, DriveLaw(1.0))
        assert state.omega_ab == pytest.approx(omega * unit.omega_ab, rel=1e-13)
        assert state.omega_bc == pytest.approx(omega * unit.omega_bc, rel=1e-13)
        assert state.velocity_b_y == pytest.approx(omega * unit.velocity_b_y, rel=1e-13)
        assert state.omega_dot == k * omega
        errors = state_errors(state, reference_state(PAPER, alpha, drive))
        for kind in ('angle', 'angular_rate', 'angular_acceleration', 'velocity', 'acceleration'):
            assert errors[kind] <= 1e-12, (kind, errors)


@pytest.mark.parametrize('turns', [1, 10, 100, 1000, 10_000, -10_000])
def test_many_turns_of_a_grashof_crank(turns: int) -> None:
    linkage = PRESETS['grashof_crank_rocker'].geometry
    for alpha in (0.3, 2.0, -1.1):
        far = alpha + 2 * math.pi * turns
        base = solve(linkage, alpha, CONSTANT)
        state = solve(linkage, far, CONSTANT)
        # Only far's float spacing (ulp(6.3e4) = 7e-12 rad) separates it from alpha + 2πn.
        assert abs(math.remainder(state.beta - base.beta, 2 * math.pi)) <= 1e-10
        assert abs(math.remainder(state.gamma - base.gamma, 2 * math.pi)) <= 1e-10
        # ... and at that exact float the library is as exact as anywhere.
        errors = state_errors(state, reference_state(linkage, far, CONSTANT))
        assert errors['angle'] <= 1e-12 and errors['angular_rate'] <= 1e-9, errors


def test_unwrapped_sweep_is_continuous() -> None:
    linkage = PRESETS['grashof_crank_rocker'].geometry
    angles = np.linspace(-2 * math.pi * 20, 2 * math.pi * 20, 160_001)
    states = solve_many(linkage, angles, CONSTANT)
    step = angles[1] - angles[0]
    for name, rate in (('beta', -states.omega_bc), ('gamma', states.omega_ab)):
        jumps = np.abs(np.remainder(np.diff(getattr(states, name)) + np.pi, 2 * np.pi) - np.pi)
        largest_slope = np.max(np.abs(rate / states.omega))
        assert np.max(jumps) <= 1.01 * largest_slope * step, name
    # β of a crank-rocker stays inside its swing: no wrap, so no jump at all
    largest_step = np.max(np.abs(np.diff(states.beta)))
    assert largest_step <= 1.01 * np.max(np.abs(states.omega_bc / 2)) * step


POSE_FIELDS = ('alpha', 'beta', 'gamma', 'pin_a_x', 'pin_a_y', 'pin_b_x', 'pin_b_y',
               'transmission_angle')


@pytest.mark.parametrize('alpha', [0.0, 0.3, 1.0, math.pi / 2, 3.0])
@pytest.mark.parametrize('branch', [1, -1])
def test_pose_is_the_full_state_s_positions(alpha: float, branch: int) -> None:
    pose = solve_pose(PAPER, alpha, branch)
    state = solve(PAPER, alpha, CONSTANT, branch)
    for name in POSE_FIELDS:
        assert getattr(pose, name) == getattr(state, name), name


@pytest.mark.parametrize('offset', [0.0, 1e-16, 1e-15, 1e-12, 1e-9])
def test_positions_stay_exact_where_the_rates_are_singular(offset: float) -> None:
    """
    Where solve() refuses (at and within ~1e-14 rad of the dead point).

    Solve_pose() still places the links; at every offset its angles are within 3× the input floor.
    """
    for dead, side in paper_dead_points():
        alpha = float(dead + side * offset)
        if refused_by_rule(alpha, dead):
            with pytest.raises(DeadPointError):
                solve(PAPER, alpha, CONSTANT)
        pose = solve_pose(PAPER, alpha)
        for name in POSE_FIELDS:
            assert math.isfinite(getattr(pose, name)), name
        assert kinematics.loop_closure_residual(PAPER, pose) <= 1e-15
        delta = abs(float(mpf(alpha) - dead))
        # Coupler and rocker collinear: μ is 0 (folded) or π (stretched) up to ~√(2.5·δ).
        deviation = min(pose.transmission_angle, math.pi - pose.transmission_angle)
        assert deviation <= 2.0 * math.sqrt(delta) + 1e-15, deviation
        if delta > 0.0 and mpf(alpha) * side > dead * side:  # on the reachable side
            assert branch_side(PAPER, pose) == 1
            reference = reference_state(PAPER, alpha, CONSTANT)
            floor = input_floor(PAPER, alpha, CONSTANT)['angle']
            for name in ('beta', 'gamma'):
                error = abs(math.remainder(getattr(pose, name) - float(reference[name]),
                                           2 * math.pi))
                assert error <= 3.0 * floor + ROUNDING, (name, error, floor)


def test_pose_outside_the_reachable_set_names_the_interval() -> None:
    with pytest.raises(UnreachableError, match=r'\[-1\.941°, 181\.941°\]'):
        solve_pose(PAPER, math.radians(-5.0))
