# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Change points: Grashof linkages with s + l = p + q turn through them on the smooth branch.

The library follows the smooth (analytic) branch by rule: B crosses to the other side of A→C at
every change point (``continued_branch``). The reference follows the motion itself in small
steps of 30-digit arithmetic (``reference.continued_sides``); the two must agree at every angle,
and the states must match the 50-digit reference on that branch, at the change points too.
"""

from __future__ import annotations

import math

from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import FourBar
from linkage_kinematics.kinematics.solver import (
    continued_branch,
    DeadPointError,
    LinkageState,
    solve,
    solve_many,
)
import numpy as np
import pytest
from reference import continued_sides, reference_singular_angles, reference_state, state_errors

CONSTANT = DriveLaw(2.0)
VARIABLE = DriveLaw(0.10, 2.3)
DRIVES = (CONSTANT, VARIABLE)
PARALLELOGRAM = FourBar(0.3, 1.0, 0.3, 1.0, 0.0)
KITE = FourBar(0.4, 0.4, 1.0, 1.0, 0.0)
# One change point per turn (|AB − BC| = OC − OA): its smooth motion repeats every two turns.
GENERAL = FourBar(0.25, 0.75, 0.5, 0.5, 0.0)
LINKAGES = {'parallelogram': PARALLELOGRAM, 'kite': KITE, 'general': GENERAL}
# Every 0.5° from 0 to ±720°: the grid lands on the change points at ±90° and ±270°.
STEP_DEG = 0.5
TURN_STEPS = 1440
# Rounding of results of order one (rad, or relative) for the parallelogram's identities.
ROUNDING = 4e-15
REFERENCE_TOLERANCE = 1e-12


def grid(direction: int) -> np.ndarray:
    return np.radians(direction * STEP_DEG * np.arange(1, TURN_STEPS + 1))


def reference_indices(alphas: np.ndarray, linkage: FourBar) -> list[int]:
    """
    Where to compare with the 50-digit reference.

    On every change point and the grid points next to it, and every 37th grid point elsewhere (the
    reference is slow).
    """
    points = linkage.reachability.change_points
    near = {
        index for index, alpha in enumerate(alphas)
        if min(abs(math.remainder(alpha - point, 2 * math.pi)) for point in points)
        < math.radians(STEP_DEG) * 1.5
    }
    return sorted(near | set(range(0, alphas.size, 37)))


def side_of_b(linkage: FourBar, states: LinkageState) -> np.ndarray:
    to_c_x = linkage.ground_x - states.pin_a_x
    to_c_y = linkage.ground_y - states.pin_a_y
    cross = to_c_x * (states.pin_b_y - states.pin_a_y) - to_c_y * (states.pin_b_x - states.pin_a_x)
    return np.sign(cross)


@pytest.mark.parametrize('name', sorted(LINKAGES))
def test_change_points_are_the_reference_s_double_roots(name: str) -> None:
    linkage = LINKAGES[name]
    singular = [float(angle) for angle in reference_singular_angles(linkage)]
    assert linkage.reachability.full_rotation
    assert len(linkage.reachability.change_points) == len(singular)
    for point in linkage.reachability.change_points:
        assert min(abs(math.remainder(point - angle, 2 * math.pi)) for angle in singular) < 1e-15


@pytest.mark.parametrize('name', sorted(LINKAGES))
@pytest.mark.parametrize('branch', [1, -1])
@pytest.mark.parametrize('direction', [1, -1], ids=['counterclockwise', 'clockwise'])
def test_smooth_motion_through_two_turns(name: str, branch: int, direction: int) -> None:
    """
    Both assemblies, both directions, two full turns.

    The library's branch rule picks the root the reference's step-by-step continuation picks, at
    every 0.5°; and there (the change points included) every quantity matches the reference to
    1e-12, under both drive laws.
    """
    linkage = LINKAGES[name]
    alphas = grid(direction)
    branches = continued_branch(linkage, 0.0, branch, alphas)
    expected = continued_sides(linkage, 0.0, branch, [float(a) for a in alphas])
    assert branches.tolist() == expected
    for drive_index, drive in enumerate(DRIVES):
        states = solve_many(linkage, alphas, drive, branches)
        for field_name in LinkageState.__dataclass_fields__:
            assert np.all(np.isfinite(getattr(states, field_name))), field_name
        # B is on the side the branch names, except exactly at a change point (h = 0)
        sides = side_of_b(linkage, states)
        assert np.all((sides == branches) | (sides == 0) | (np.abs(np.sin(
            states.transmission_angle)) < 1e-15))
        for index in reference_indices(alphas, linkage)[drive_index::2]:
            alpha = float(alphas[index])
            state = states.at(index)
            single = solve(linkage, alpha, drive, int(branches[index]))
            for field_name in LinkageState.__dataclass_fields__:
                assert getattr(single, field_name) == pytest.approx(
                    getattr(state, field_name), rel=1e-13, abs=1e-13), field_name
            errors = state_errors(state, reference_state(linkage, alpha, drive,
                                                         int(branches[index])))
            for kind, error in errors.items():
                assert error <= REFERENCE_TOLERANCE, (alpha, kind, errors)


@pytest.mark.parametrize('drive', DRIVES, ids=['constant', 'variable'])
@pytest.mark.parametrize('direction', [1, -1], ids=['counterclockwise', 'clockwise'])
def test_parallelogram_stays_a_parallelogram(drive: DriveLaw, direction: int) -> None:
    """
    Started as a parallelogram (B = A + C, branch −1 at α = 0).

    It stays one through ±720°, change points included: γ = 0, ω_AB = 0, ω_BC = ω, ω̇_AB = 0, ω̇_BC
    = ω̇ to rounding.
    """
    alphas = grid(direction)
    states = solve_many(PARALLELOGRAM, alphas, drive,
                        continued_branch(PARALLELOGRAM, 0.0, -1, alphas))
    omega = states.omega
    # accelerations relative to their group's size, as reference.state_errors judges them
    acceleration_scale = np.maximum(omega**2, np.abs(states.omega_dot))
    assert np.max(np.abs(states.gamma)) <= ROUNDING
    assert np.max(np.abs(states.pin_b_x - states.pin_a_x - 1.0)) <= ROUNDING
    assert np.max(np.abs(states.omega_ab / omega)) <= ROUNDING
    assert np.max(np.abs(states.omega_bc / omega - 1.0)) <= ROUNDING
    assert np.max(np.abs(states.omega_dot_ab) / acceleration_scale) <= ROUNDING
    assert np.max(np.abs(states.omega_dot_bc - states.omega_dot) / acceleration_scale) <= ROUNDING


@pytest.mark.parametrize('drive', DRIVES, ids=['constant', 'variable'])
def test_kite_keeps_its_folded_assembly(drive: DriveLaw) -> None:
    """
    Return the kite OA = AB = 0.4.

    BC = OC = 1 has an assembly with B on O (branch +1 at α = 0): the rocker stands still and the
    coupler turns with the crank, through both change points.
    """
    alphas = grid(1)
    states = solve_many(KITE, alphas, drive, continued_branch(KITE, 0.0, 1, alphas))
    assert np.max(np.hypot(states.pin_b_x, states.pin_b_y)) <= ROUNDING
    assert np.max(np.abs(states.omega_bc / states.omega)) <= ROUNDING
    assert np.max(np.abs(states.omega_ab / states.omega - 1.0)) <= ROUNDING


def test_one_change_point_per_turn_repeats_every_two_turns() -> None:
    """
    With one change point per turn, a whole turn brings the other assembly.

    Solving at α with the branch for ``turns`` later turns gives the state at α + 2π·turns.
    """
    alpha = 0.3
    for turns in (1, 2, 3, -1, 1000, -1001):
        branch = continued_branch(GENERAL, 0.0, 1, alpha, turns=turns)
        assert branch == (1 if turns % 2 == 0 else -1)
        assert branch == continued_branch(GENERAL, 0.0, 1, alpha + 2 * math.pi * turns)
        far = solve(GENERAL, alpha + 2 * math.pi * turns, CONSTANT, branch)
        near = solve(GENERAL, alpha, CONSTANT, branch)
        assert math.remainder(far.beta - near.beta, 2 * math.pi) == pytest.approx(0, abs=1e-9)
        assert far.omega_bc == pytest.approx(near.omega_bc, rel=1e-9)
    for turns in (1, 7, -3):
        assert continued_branch(PARALLELOGRAM, 0.0, -1, alpha, turns=turns) == -1
        assert continued_branch(KITE, 0.0, 1, alpha, turns=turns) == 1


def test_branch_flips_exactly_at_the_change_point() -> None:
    """
    Return the change point at π/2 lies between the floats around it.

    Continued_branch decides which side each float is on from the change point held to twice double
    precision. At a change point itself a branch names the side just counterclockwise of it.
    """
    change = math.pi / 2  # the float below π/2
    above = math.nextafter(change, math.inf)
    assert continued_branch(GENERAL, 0.0, 1, change) == 1
    assert continued_branch(GENERAL, 0.0, 1, above) == -1
    assert continued_branch(GENERAL, 3.0, 1, above) == 1
    assert continued_branch(GENERAL, above, 1, change) == -1
    # C straight below O puts a change point on α = 0 exactly, a float
    exact = FourBar(0.25, 0.75, 0.5, 0.0, -0.5)
    assert 0.0 in exact.reachability.change_points
    assert continued_branch(exact, -0.5, 1, 0.0) == -1
    assert continued_branch(exact, 0.0, 1, 0.5) == 1
    assert continued_branch(exact, 0.0, 1, -0.5) == -1
    state = solve(exact, 0.0, CONSTANT, 1)
    below = solve(exact, -1e-9, CONSTANT, -1)
    above_state = solve(exact, 1e-9, CONSTANT, 1)
    assert state.omega_bc == pytest.approx(above_state.omega_bc, rel=1e-8)
    assert state.omega_bc == pytest.approx(below.omega_bc, rel=1e-8)


def test_pin_passing_through_the_pivot_is_refused() -> None:
    """
    OA = OC and AB = BC.

    Pin A passes through C, where coupler and rocker lie on each other and can turn together about
    it; solve refuses within PIVOT_PASSAGE of it, not beyond.
    """
    folding = FourBar(1.0, 0.4, 0.4, 1.0, 0.0)
    assert folding.reachability.change_points == pytest.approx((math.pi / 2,), abs=1e-15)
    with pytest.raises(DeadPointError, match='on the pivot C'):
        solve(folding, math.pi / 2, CONSTANT)
    with pytest.raises(DeadPointError, match='on the pivot C'):
        solve_many(folding, np.array([1.0, math.pi / 2 + 1e-8]), CONSTANT)
    for alpha in (math.pi / 2 + 0.2, math.pi / 2 - 0.3):
        state = solve(folding, alpha, CONSTANT)
        errors = state_errors(state, reference_state(folding, alpha, CONSTANT))
        assert max(errors.values()) <= 1e-12, errors


@pytest.mark.parametrize('branch', [1, -1])
def test_a_change_point_on_a_float_names_the_side_just_counterclockwise_on_any_turn(branch):
    """
    C straight above O puts a change point of the parallelogram on the float 0 (held as 2π).

    At α = 0.0 itself a branch names the side just counterclockwise of it, as everywhere: the
    state there is the limit of that side's states from α > 0. (Seen from C, the parallelogram
    with C level with O is this linkage, so a measured rocker at θ = 0 lands here.)
    """
    linkage = FourBar(0.3, 1.0, 0.3, 0.0, 1.0)
    assert linkage.reachability.change_points[1] == 0.0
    at = solve(linkage, 0.0, CONSTANT, branch)
    after = solve(linkage, 1e-9, CONSTANT, branch)
    assert (at.omega_ab, at.omega_bc) == pytest.approx((after.omega_ab, after.omega_bc), abs=1e-8)
    assert (at.omega_dot_ab, at.omega_dot_bc) == pytest.approx(
        (after.omega_dot_ab, after.omega_dot_bc), abs=1e-7)
