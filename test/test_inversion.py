# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The four-bar driven by its rocker (``inversion``), against the independent reference.

``reference.reference_rocker_driven`` solves the crank side from the rocker angle with its own
equation (an asin form) and differentiates it numerically in 50 digits; the library solves the
mechanism seen from C with its crank-driven closed form. They must agree as the crank-driven
solve agrees with its reference: angles and pins to 1e-12, rates and accelerations to 1e-9
relative, also 1e-6 rad from the rocker-driven chain's dead points (crank and coupler
collinear), whose positions must match the reference's to 1e-12; the parallelogram driven by
its rocker goes through its change points and stays a parallelogram.
"""

from __future__ import annotations

import math

from linkage_kinematics.kinematics.geometry import FourBar, preset, TWO_PI
from linkage_kinematics.kinematics.inversion import seen_from_rocker, solve_from_rocker
from linkage_kinematics.kinematics.solver import continued_branch, CrankRates, DeadPointError
from mpmath import mp, mpf
import numpy as np
import pytest
from reference import reference_rocker_driven

PAPER = preset('paper').geometry
LINKAGES = {
    'paper': PAPER,
    'grashof_crank_rocker': preset('grashof_crank_rocker').geometry,
    'tilted non-Grashof': FourBar(0.5, 1.1, 0.8, 1.2, 0.3),
}
RATES = (CrankRates(-1.7, 0.0), CrankRates(0.4, 3.1))


def rocker_dead_points(linkage: FourBar) -> list[float]:
    """θ_BC where crank and coupler are collinear (|B − O| = AB ± OA), from the reference."""
    with mp.workdps(50):
        c = mpf(linkage.rocker_length)
        x_c, y_c = mpf(linkage.ground_x), mpf(linkage.ground_y)
        angles = []
        for reach in (mpf(linkage.coupler_length) + mpf(linkage.crank_length),
                      abs(mpf(linkage.coupler_length) - mpf(linkage.crank_length))):
            # |C + BC·e(θ)|² = reach²: x_C·cos θ + y_C·sin θ = (reach² − OC² − BC²)/(2·BC)
            ground = mp.sqrt(x_c**2 + y_c**2)
            ratio = (reach**2 - ground**2 - c**2) / (2 * c * ground)
            if abs(ratio) <= 1:
                heading = mp.atan2(y_c, x_c)
                angles += [float(heading + mp.acos(ratio)), float(heading - mp.acos(ratio))]
        return angles


def compare(linkage: FourBar, theta: float, rates: CrankRates, side: int) -> None:
    state = solve_from_rocker(linkage, seen_from_rocker(linkage), theta, rates, side)
    reference = reference_rocker_driven(linkage, theta, rates, side)
    for name in ('alpha', 'beta', 'gamma'):
        assert abs(math.remainder(getattr(state, name) - float(reference[name]), TWO_PI)) < 1e-12
    for name in ('pin_a_x', 'pin_a_y', 'pin_b_x', 'pin_b_y'):
        assert getattr(state, name) == pytest.approx(float(reference[name]), abs=1e-12)
    rate_scale = max(abs(float(reference[name])) for name in ('omega', 'omega_ab', 'omega_bc'))
    for name in ('omega', 'omega_ab', 'omega_bc'):
        assert getattr(state, name) == pytest.approx(float(reference[name]),
                                                     abs=1e-9 * rate_scale)
    acceleration_scale = max(
        [abs(float(reference[name])) for name in ('omega_dot', 'omega_dot_ab', 'omega_dot_bc')]
        + [rate_scale**2])
    for name in ('omega_dot', 'omega_dot_ab', 'omega_dot_bc'):
        assert getattr(state, name) == pytest.approx(float(reference[name]),
                                                     abs=1e-9 * acceleration_scale)


@pytest.mark.parametrize('name', LINKAGES)
@pytest.mark.parametrize('side', [1, -1])
@pytest.mark.parametrize('rates', RATES, ids=['constant', 'accelerating'])
def test_rocker_driven_states_match_the_reference(name: str, side: int,
                                                  rates: CrankRates) -> None:
    linkage = LINKAGES[name]
    inverted = seen_from_rocker(linkage)
    for low, high in inverted.reachability.intervals:
        for theta in np.linspace(low + 1e-6, high - 1e-6, 9) if low != high - TWO_PI else (
                np.linspace(low, high, 9, endpoint=False)):
            compare(linkage, float(theta), rates, side)


@pytest.mark.parametrize('name', LINKAGES)
def test_the_rocker_driven_dead_points_are_where_crank_and_coupler_are_collinear(name: str):
    linkage = LINKAGES[name]
    dead_points = seen_from_rocker(linkage).reachability.dead_points
    expected = rocker_dead_points(linkage)
    assert len(dead_points) == len(expected)
    for point in dead_points:
        assert min(abs(math.remainder(point - other, TWO_PI)) for other in expected) < 1e-12
        # The rates are undefined there: the solve refuses it.
        with pytest.raises(DeadPointError):
            solve_from_rocker(linkage, seen_from_rocker(linkage), point, RATES[0], 1)


def test_the_seed_rocker_over_beta_0_to_86_degrees_and_near_its_dead_points():
    inverted = seen_from_rocker(PAPER)
    for beta in np.radians(np.arange(0.0, 86.5, 0.5)):
        compare(PAPER, math.pi - float(beta), RATES[1], 1)
    for point in inverted.reachability.dead_points:
        (low, high), = [interval for interval in inverted.reachability.intervals
                        if min(abs(point - end) for end in interval) < 1e-9]
        inside = point + 1e-6 if point == low else point - 1e-6
        for side in (1, -1):
            compare(PAPER, inside, RATES[1], side)


def test_a_parallelogram_driven_by_its_rocker_goes_through_its_change_points():
    """
    OA = BC, AB = OC: the crank stays parallel to the rocker, α = θ + π/2, γ = 0.

    Two turns of the rocker from θ = 10° in 0.5° steps, which land on the change points (θ = 0°
    and 180°, where all four pins are collinear), the assembly continued through them.
    """
    parallelogram = FourBar(0.3, 1.0, 0.3, 1.0, 0.0)
    inverted = seen_from_rocker(parallelogram)
    assert len(inverted.reachability.change_points) == 2
    start = math.radians(10.0)
    rates = CrankRates(2.0, 0.5)
    (start_side,) = [side for side in (1, -1) if abs(math.remainder(solve_from_rocker(
        parallelogram, inverted, start, rates, side).gamma, TWO_PI)) < 1e-12]
    for degrees in np.arange(10.0, 730.5, 0.5):
        theta = math.radians(float(degrees))
        wrapped = math.remainder(theta, TWO_PI)
        side = continued_branch(inverted, start, start_side, wrapped,
                                turns=round((theta - wrapped) / TWO_PI))
        state = solve_from_rocker(parallelogram, inverted, wrapped, rates, side)
        assert abs(math.remainder(state.alpha - (theta + math.pi / 2.0), TWO_PI)) < 4e-15
        assert abs(math.remainder(state.gamma, TWO_PI)) < 4e-15
        assert state.omega == pytest.approx(2.0, abs=4e-15)
        assert state.omega_ab == pytest.approx(0.0, abs=4e-15)
        assert state.omega_dot == pytest.approx(0.5, abs=4e-15)
