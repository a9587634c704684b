# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""The drive law ω = ω0 + k·α and its exact flow α(t), checked against mpmath's closed form."""

from __future__ import annotations

import math

from hypothesis import assume, given, settings
from hypothesis import strategies as st
from linkage_kinematics.kinematics.drive import DriveError, DriveLaw
from mpmath import mp, mpf
import pytest


def exact_alpha(drive: DriveLaw, alpha_start: float, elapsed: float) -> float:
    """α(t) = α_s + ω_s·(e^{k t} − 1)/k in 50 digits, from the float inputs."""
    with mp.workdps(50):
        k = mpf(drive.k)
        omega_start = mpf(drive.omega0) + k * mpf(alpha_start)
        if k == 0:
            return float(mpf(alpha_start) + omega_start * mpf(elapsed))
        return float(mpf(alpha_start) + omega_start * mp.expm1(k * mpf(elapsed)) / k)


def exact_time(drive: DriveLaw, alpha_start: float, alpha: float) -> float:
    """T = ln(1 + k·(α − α_s)/ω_s)/k in 50 digits."""
    with mp.workdps(50):
        k = mpf(drive.k)
        omega_start = mpf(drive.omega0) + k * mpf(alpha_start)
        travel = mpf(alpha) - mpf(alpha_start)
        if k == 0:
            return float(travel / omega_start)
        return float(mp.log1p(k * travel / omega_start) / k)


def test_seed_variable_law() -> None:
    drive = DriveLaw(0.10, 2.3)
    assert drive.angular_velocity(0.0) == 0.10
    assert drive.angular_acceleration(0.0) == pytest.approx(0.23, rel=1e-15)
    assert round(drive.angular_velocity(math.pi / 2), 3) == 3.713
    # α(t) = (0.10/2.3)(e^{2.3 t} − 1): the 90° turn takes ln(1 + 2.3·(π/2)/0.10)/2.3 s
    seconds = drive.time_to(0.0, math.pi / 2)
    assert seconds == pytest.approx(math.log1p(23.0 * math.pi / 2) / 2.3, rel=1e-15)
    assert drive.alpha_at(0.0, seconds) == pytest.approx(math.pi / 2, rel=1e-15)


omega0s = st.floats(-20.0, 20.0)
ks = st.floats(-5.0, 5.0)
angles = st.floats(-10.0, 10.0)


@settings(max_examples=200, deadline=None)
@given(omega0=omega0s, k=ks, alpha=angles)
def test_angular_acceleration_is_k_omega_exactly(omega0, k, alpha) -> None:
    drive = DriveLaw(omega0, k)
    assert drive.angular_acceleration(alpha) == k * drive.angular_velocity(alpha)
    assert drive.angular_velocity(alpha) == omega0 + k * alpha


@settings(max_examples=200, deadline=None)
@given(omega0=omega0s, k=ks, alpha_start=angles, elapsed=st.floats(0.0, 5.0))
def test_flow_matches_closed_form_and_inverts(omega0, k, alpha_start, elapsed) -> None:
    drive = DriveLaw(omega0, k)
    assume(abs(drive.angular_velocity(alpha_start)) > 1e-6)
    assume(abs(k * elapsed) < 30.0)
    alpha = drive.alpha_at(alpha_start, elapsed)
    expected = exact_alpha(drive, alpha_start, elapsed)
    # ω_s = ω0 + k·α_s is rounded to float once, and the flow carries that rounding along
    stretch = math.expm1(k * elapsed) / k if k else elapsed
    omega_rounding = 4 * 2.2e-16 * (abs(omega0) + abs(k * alpha_start)) * abs(stretch)
    assert alpha == pytest.approx(
        expected, rel=1e-14, abs=1e-14 * (1.0 + abs(alpha_start)) + omega_rounding
    )
    assume(abs(alpha - alpha_start) > 1e-9 * (1.0 + abs(alpha_start)))
    back = drive.time_to(alpha_start, alpha)
    # The inverse is as well conditioned as |dt/dα| = 1/|ω(α)| allows, and carries the rounding
    # of ω_s too: ∂t/∂ω_s = −(α − α_s)/(ω_s·ω(α)), large where ω_s is small by cancellation
    # (ω0 = 3, k = 3, α_s = −0.99999: ω_s = 3e-5, relative rounding 1.5e-11).
    spacing = math.ulp(max(abs(alpha), abs(alpha_start), 1.0))
    omega_rounding_relative = (4 * 2.2e-16 * (abs(omega0) + abs(k * alpha_start))
                               / abs(drive.angular_velocity(alpha_start)))
    condition = (4.0 * spacing + omega_rounding_relative * abs(alpha - alpha_start)) / abs(
        drive.angular_velocity(alpha))
    assert back == pytest.approx(exact_time(drive, alpha_start, alpha), rel=1e-13, abs=condition)
    assert back == pytest.approx(elapsed, rel=1e-9, abs=condition + 1e-12)


def test_continuity_as_k_goes_to_zero() -> None:
    constant = DriveLaw(2.0, 0.0)
    for k in (1e-6, 1e-9, 1e-12, 1e-15, -1e-15, -1e-9, 1e-300, 2.2e-313, -5e-324):
        drive = DriveLaw(2.0, k)
        for elapsed in (0.0, 0.1, 1.0, 10.0):
            assert drive.alpha_at(0.5, elapsed) == pytest.approx(
                constant.alpha_at(0.5, elapsed), rel=10 * abs(k) * (1 + elapsed) + 1e-15
            )
            assert drive.alpha_at(0.5, elapsed) == pytest.approx(
                exact_alpha(drive, 0.5, elapsed), rel=1e-15, abs=1e-15
            )
        assert drive.time_to(0.5, 3.0) == pytest.approx(
            constant.time_to(0.5, 3.0), rel=10 * abs(k) + 1e-15
        )


def test_time_to_same_angle_is_zero() -> None:
    assert DriveLaw(0.0, 0.0).time_to(1.0, 1.0) == 0.0


def test_errors() -> None:
    with pytest.raises(DriveError, match='at rest'):
        DriveLaw(0.0, 0.0).time_to(0.0, 1.0)
    with pytest.raises(DriveError, match='at rest'):
        DriveLaw(-2.3, 2.3).time_to(1.0, 2.0)  # ω(1) = 0
    with pytest.raises(DriveError, match='never reaches'):
        DriveLaw(2.0).time_to(1.0, 0.5)  # turning counterclockwise, asked to go back
    with pytest.raises(DriveError, match=r'only approaches α\*'):
        DriveLaw(1.0, -1.0).time_to(0.0, 2.0)  # ω → 0 as α → 1 rad, never beyond
    with pytest.raises(DriveError, match='overflows'):
        DriveLaw(0.1, 2.3).alpha_at(0.0, 1e4)
    with pytest.raises(DriveError, match='overflows'):
        DriveLaw(1e300, 1.0).alpha_at(0.0, 700.0)
    for bad in (math.nan, math.inf, -math.inf):
        with pytest.raises(DriveError, match='finite'):
            DriveLaw(bad, 0.0)
        with pytest.raises(DriveError, match='finite'):
            DriveLaw(1.0, bad)


def test_approach_to_rest_point_is_finite() -> None:
    """With k·ω < 0 the crank creeps toward α* = −ω0/k for ever but never reaches it."""
    drive = DriveLaw(1.0, -1.0)
    for elapsed in (1.0, 10.0, 100.0, 1e6):
        alpha = drive.alpha_at(0.0, elapsed)
        assert 0.0 <= alpha <= 1.0
    assert drive.alpha_at(0.0, 1e6) == 1.0
