"""Numerical stability: dead points, change points, scale, extreme rates and many turns.

The error bounds below are the measured worst cases (docs/dead_point_accuracy.py, table in
docs/kinematics.md) times a safety factor of about 3. δ is the exact distance of the float α
from the dead point; S = |sin μ| is the sine of the transmission angle.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from mpmath import mpf
from reference import reference_singular_angles, reference_state, state_errors

from linkage_kinematics.drive import DriveLaw
from linkage_kinematics import kinematics
from linkage_kinematics.geometry import PRESETS, FourBar, UnreachableError
from linkage_kinematics.kinematics import (
    SINGULAR_SINE,
    DeadPointError,
    LinkageState,
    solve,
    solve_many,
    solve_pose,
)

# Near a dead point (measured worst: 5.7e-16/√δ, 4.7e-16/δ, 1.4e-15/δ).
DEAD_POINT_ANGLE = 2e-15  # rad·√δ
DEAD_POINT_RATE = 1.5e-15  # relative·δ, angular rates and pin velocities
DEAD_POINT_ACCELERATION = 5e-15  # relative·δ, angular and pin accelerations
# Near a change point, in terms of S (measured worst: 1.2e-15/S, 1.2e-15/S², 3e-15/S³).
CHANGE_POINT_ANGLE = 4e-15  # rad·S
CHANGE_POINT_RATE = 4e-15  # relative·S²
CHANGE_POINT_ACCELERATION = 1e-14  # relative·S³

PAPER = PRESETS["paper"].geometry
CONSTANT = DriveLaw(2.0)
VARIABLE = DriveLaw(0.10, 2.3)
PARALLELOGRAM = FourBar(0.3, 1.3, 0.3, 1.3, 0.0)
KITE = FourBar(0.4, 0.4, 1.0, 1.0, 0.0)
FOLDING_KITE = FourBar(1.0, 0.4, 0.4, 1.0, 0.0)


def branch_side(linkage: FourBar, state: LinkageState) -> float:
    """+1 if B is left of the directed line A→C, −1 if right."""
    to_c = (linkage.ground_x - state.pin_a_x, linkage.ground_y - state.pin_a_y)
    to_b = (state.pin_b_x - state.pin_a_x, state.pin_b_y - state.pin_a_y)
    return math.copysign(1.0, to_c[0] * to_b[1] - to_c[1] * to_b[0])


def assert_finite(state: LinkageState) -> None:
    for field_name in LinkageState.__dataclass_fields__:
        assert math.isfinite(getattr(state, field_name)), field_name


def paper_dead_points() -> list[tuple[mpf, int]]:
    """The paper mechanism's two dead points, each with the direction of its reachable side."""
    points = reference_singular_angles(PAPER)

    def nearest(end: float) -> mpf:
        return min(points, key=lambda point: abs(math.remainder(float(point) - end, 2 * math.pi)))

    low, high = PAPER.reachability.intervals[0]
    return [(nearest(low), 1), (nearest(high), -1)]


def test_paper_dead_point_is_where_the_seed_starts_from() -> None:
    (dead, _), _ = paper_dead_points()
    assert round(math.degrees(float(dead)), 3) == -1.941


@pytest.mark.parametrize("offset", [1e-3, 1e-6, 1e-9, 1e-12, 1e-13, 1e-14, 1e-15])
@pytest.mark.parametrize("drive", [CONSTANT, VARIABLE], ids=["constant", "variable"])
@pytest.mark.parametrize("branch", [1, -1])
def test_approaching_the_paper_dead_point(offset: float, drive: DriveLaw, branch: int) -> None:
    for dead, side in paper_dead_points():
        alpha = float(dead + side * offset)
        delta = abs(float(mpf(alpha) - dead))
        try:
            state = solve(PAPER, alpha, drive, branch)
        except DeadPointError:
            # Only where the transmission sine has fallen below SINGULAR_SINE (S² ≈ 2.5·δ here).
            assert delta < (2 * SINGULAR_SINE) ** 2
            continue
        assert delta > (SINGULAR_SINE / 2) ** 2
        assert_finite(state)
        assert branch_side(PAPER, state) == branch
        errors = state_errors(state, reference_state(PAPER, alpha, drive, branch))
        assert errors["angle"] <= DEAD_POINT_ANGLE / math.sqrt(delta), errors
        if offset >= 1e-6:
            assert errors["angle"] <= 1e-12, errors
        assert errors["angular_rate"] <= DEAD_POINT_RATE / delta, errors
        assert errors["velocity"] <= DEAD_POINT_RATE / delta, errors
        assert errors["angular_acceleration"] <= DEAD_POINT_ACCELERATION / delta, errors
        assert errors["acceleration"] <= DEAD_POINT_ACCELERATION / delta, errors


@pytest.mark.parametrize("offset", [1e-9, 1e-10, 1e-11, 1e-12, 1e-13])
def test_closed_form_below_the_cut_off_degrades_as_documented(
    offset: float, monkeypatch: pytest.MonkeyPatch
) -> None:
    """With the SINGULAR_SINE cut-off lifted, the closed form still follows the documented
    bounds: the cut-off is a choice about useful accuracy, not a hiding place for a bug."""
    monkeypatch.setattr(kinematics, "SINGULAR_SINE", 0.0)
    for dead, side in paper_dead_points():
        alpha = float(dead + side * offset)
        delta = abs(float(mpf(alpha) - dead))
        state = solve(PAPER, alpha, VARIABLE)
        assert_finite(state)
        assert branch_side(PAPER, state) == 1
        errors = state_errors(state, reference_state(PAPER, alpha, VARIABLE))
        assert errors["angle"] <= DEAD_POINT_ANGLE / math.sqrt(delta), errors
        assert errors["angular_rate"] <= DEAD_POINT_RATE / delta, errors
        assert errors["angular_acceleration"] <= DEAD_POINT_ACCELERATION / delta, errors


def test_at_and_past_the_paper_dead_point() -> None:
    (dead, side), _ = paper_dead_points()
    with pytest.raises(DeadPointError, match="-1.940963885°"):
        solve(PAPER, float(dead), CONSTANT)
    with pytest.raises(DeadPointError):
        solve_many(PAPER, np.array([0.0, float(dead)]), CONSTANT)
    for past in (1e-12, 1e-9, 1e-6, 1e-3):
        with pytest.raises(UnreachableError, match=r"\[-1\.941°, 181\.941°\]"):
            solve(PAPER, float(dead - side * past), CONSTANT)


def change_points(linkage: FourBar) -> list[float]:
    return sorted(linkage.reachability.change_points)


@pytest.mark.parametrize("linkage", [PARALLELOGRAM, KITE, FOLDING_KITE],
                         ids=["parallelogram", "kite", "folding_kite"])
def test_change_points_are_reported(linkage: FourBar) -> None:
    singular = [float(angle) for angle in reference_singular_angles(linkage)]
    for point in change_points(linkage):
        assert min(abs(math.remainder(point - angle, 2 * math.pi)) for angle in singular) < 1e-15
    assert len(change_points(linkage)) + len(linkage.reachability.dead_points) == len(singular)


@pytest.mark.parametrize("linkage", [PARALLELOGRAM, KITE, FOLDING_KITE],
                         ids=["parallelogram", "kite", "folding_kite"])
@pytest.mark.parametrize("branch", [1, -1])
def test_through_a_change_point(linkage: FourBar, branch: int) -> None:
    """The branch sign is kept on both sides of the meeting point; at it the rates are singular;
    near it they match the reference to a bound that grows as S shrinks."""
    for point in change_points(linkage):
        with pytest.raises(DeadPointError):
            solve(linkage, point, VARIABLE, branch)
        for offset in (1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-8):
            for side in (1, -1):
                alpha = point + side * offset
                try:
                    state = solve(linkage, alpha, CONSTANT, branch)
                except DeadPointError:
                    assert offset < 1e-3
                    continue
                assert_finite(state)
                assert branch_side(linkage, state) == branch
                sine = math.sin(state.transmission_angle)
                assert sine >= SINGULAR_SINE
                errors = state_errors(state, reference_state(linkage, alpha, CONSTANT, branch))
                assert errors["angle"] <= CHANGE_POINT_ANGLE / sine, (offset, errors)
                assert errors["angular_rate"] <= CHANGE_POINT_RATE / sine**2, (offset, errors)
                assert errors["velocity"] <= CHANGE_POINT_RATE / sine**2, (offset, errors)
                assert errors["angular_acceleration"] <= CHANGE_POINT_ACCELERATION / sine**3, (
                    offset, errors)
                assert errors["acceleration"] <= CHANGE_POINT_ACCELERATION / sine**3, (
                    offset, errors)


def test_parallelogram_keeps_its_branch_through_a_sweep() -> None:
    """On branch +1 the parallelogram turns as a parallelogram (ω_AB = 0, ω_BC = ω) on one side
    of each change point and as the crossed linkage on the other, never flipping sides of A→C."""
    angles = np.linspace(-math.pi / 2 + 0.01, math.pi / 2 - 0.01, 501)
    states = solve_many(PARALLELOGRAM, angles, CONSTANT, 1)
    cross = ((PARALLELOGRAM.ground_x - states.pin_a_x) * (states.pin_b_y - states.pin_a_y)
             - (PARALLELOGRAM.ground_y - states.pin_a_y) * (states.pin_b_x - states.pin_a_x))
    assert np.all(cross > 0)
    other = solve_many(PARALLELOGRAM, angles + math.pi, CONSTANT, 1)
    moving_as_parallelogram = [
        np.allclose(s.omega_ab, 0.0, atol=1e-9) and np.allclose(s.omega_bc, 2.0, rtol=1e-9)
        for s in (states, other)
    ]
    assert sorted(moving_as_parallelogram) == [False, True]


@pytest.mark.parametrize("factor", [1e-6, 1e3])
def test_scale_invariance(factor: float) -> None:
    scaled = PAPER.scaled(factor)
    for alpha in np.linspace(0.0, math.pi / 2, 7):
        for drive in (CONSTANT, VARIABLE):
            base = solve(PAPER, float(alpha), drive)
            other = solve(scaled, float(alpha), drive)
            for name in ("beta", "gamma", "transmission_angle"):
                assert getattr(other, name) == pytest.approx(getattr(base, name), abs=1e-12)
            for name in ("omega", "omega_dot", "omega_ab", "omega_bc", "omega_dot_ab",
                         "omega_dot_bc"):
                assert getattr(other, name) == pytest.approx(getattr(base, name), rel=1e-12)
            for name in ("pin_b_x", "pin_b_y", "velocity_a_x", "velocity_a_y", "velocity_b_x",
                         "velocity_b_y", "acceleration_a_x", "acceleration_a_y",
                         "acceleration_b_x", "acceleration_b_y"):
                magnitude = max(abs(getattr(base, n)) for n in (name[:-1] + "x", name[:-1] + "y"))
                assert getattr(other, name) == pytest.approx(
                    factor * getattr(base, name), abs=1e-12 * factor * magnitude
                ), name


@pytest.mark.parametrize("omega0", [1e-6, -1e-6, 1e-3, 1.0, -7.5, 1e4, -1e4])
@pytest.mark.parametrize("k", [0.0, 10.0, -10.0, 0.37])
def test_extreme_drive_rates(omega0: float, k: float) -> None:
    """Angular rates are ω times a geometric ratio; accelerations follow α̈ = k·ω; all match the
    reference from 1e-6 to 1e4 rad/s."""
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
        for kind in ("angle", "angular_rate", "angular_acceleration", "velocity", "acceleration"):
            assert errors[kind] <= 1e-12, (kind, errors)


@pytest.mark.parametrize("turns", [1, 10, 100, 1000, 10_000, -10_000])
def test_many_turns_of_a_grashof_crank(turns: int) -> None:
    linkage = PRESETS["grashof_crank_rocker"].geometry
    for alpha in (0.3, 2.0, -1.1):
        far = alpha + 2 * math.pi * turns
        base = solve(linkage, alpha, CONSTANT)
        state = solve(linkage, far, CONSTANT)
        # Only far's float spacing (ulp(6.3e4) = 7e-12 rad) separates it from alpha + 2πn.
        assert abs(math.remainder(state.beta - base.beta, 2 * math.pi)) <= 1e-10
        assert abs(math.remainder(state.gamma - base.gamma, 2 * math.pi)) <= 1e-10
        # ... and at that exact float the library is as exact as anywhere.
        errors = state_errors(state, reference_state(linkage, far, CONSTANT))
        assert errors["angle"] <= 1e-12 and errors["angular_rate"] <= 1e-9, errors


def test_unwrapped_sweep_is_continuous() -> None:
    linkage = PRESETS["grashof_crank_rocker"].geometry
    angles = np.linspace(-2 * math.pi * 20, 2 * math.pi * 20, 160_001)
    states = solve_many(linkage, angles, CONSTANT)
    step = angles[1] - angles[0]
    for name, rate in (("beta", -states.omega_bc), ("gamma", states.omega_ab)):
        jumps = np.abs(np.remainder(np.diff(getattr(states, name)) + np.pi, 2 * np.pi) - np.pi)
        largest_slope = np.max(np.abs(rate / states.omega))
        assert np.max(jumps) <= 1.01 * largest_slope * step, name
    # β of a crank-rocker stays inside its swing: no wrap, so no jump at all
    assert np.max(np.abs(np.diff(states.beta))) <= 1.01 * np.max(np.abs(states.omega_bc / 2)) * step


POSE_FIELDS = ("alpha", "beta", "gamma", "pin_a_x", "pin_a_y", "pin_b_x", "pin_b_y",
               "transmission_angle")


@pytest.mark.parametrize("alpha", [0.0, 0.3, 1.0, math.pi / 2, 3.0])
@pytest.mark.parametrize("branch", [1, -1])
def test_pose_is_the_full_state_s_positions(alpha: float, branch: int) -> None:
    pose = solve_pose(PAPER, alpha, branch)
    state = solve(PAPER, alpha, CONSTANT, branch)
    for name in POSE_FIELDS:
        assert getattr(pose, name) == getattr(state, name), name


@pytest.mark.parametrize("offset", [0.0, 1e-15, 1e-12, 1e-9])
def test_positions_stay_exact_where_the_rates_are_singular(offset: float) -> None:
    """Where solve() reports a dead point, solve_pose() still places the links: the loop
    closes, the branch is kept, and the angles meet the documented 1/√δ bound."""
    for dead, side in paper_dead_points():
        alpha = float(dead + side * offset)
        with pytest.raises(DeadPointError):
            solve(PAPER, alpha, CONSTANT)
        pose = solve_pose(PAPER, alpha)
        for name in POSE_FIELDS:
            assert math.isfinite(getattr(pose, name)), name
        assert kinematics.loop_closure_residual(PAPER, pose) <= 1e-12
        delta = abs(float(mpf(alpha) - dead))
        # Coupler and rocker collinear: μ is 0 (folded) or π (stretched) up to ~√(2.5·δ), plus
        # what rounding leaves at δ ≈ 0 (S ≈ 1e-8 from a 2e-16 error in |C − A|).
        deviation = min(pose.transmission_angle, math.pi - pose.transmission_angle)
        assert deviation <= 2.0 * math.sqrt(delta) + 1e-7, deviation
        if offset >= 1e-12:
            # Closer, the branches coincide to rounding, B's side is not defined, and the float
            # α may lie a hair past the true dead point, where solve_pose takes the dead point.
            assert branch_side(PAPER, pose) == 1
            reference = reference_state(PAPER, alpha, CONSTANT)
            for name in ("beta", "gamma"):
                error = abs(math.remainder(getattr(pose, name) - float(reference[name]),
                                           2 * math.pi))
                assert error <= DEAD_POINT_ANGLE / math.sqrt(delta), (name, error)


def test_pose_outside_the_reachable_set_names_the_interval() -> None:
    with pytest.raises(UnreachableError, match=r"\[-1\.941°, 181\.941°\]"):
        solve_pose(PAPER, math.radians(-5.0))
