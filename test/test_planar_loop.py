# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Planar loops of four joints solved from one known joint (``kinematics.planar_loop``).

Four-bars (all revolute) are checked against a direct evaluation of the loop closure, central
differences of the solved coordinates, and the existing four-bar solve they are mapped onto.
"""

from __future__ import annotations

import math
import struct

from hypothesis import assume, given, HealthCheck, settings
from hypothesis import strategies as st
from linkage_kinematics.kinematics import singular_points
from linkage_kinematics.kinematics.closed_form import CrankRates
from linkage_kinematics.kinematics.geometry import FourBar, GeometryError, UnreachableError
from linkage_kinematics.kinematics.planar_loop import (
    branch_of,
    continued_branch_of,
    joint_points,
    JointKind,
    known_joint_range,
    PlanarLoop,
    solve_loop,
)
from linkage_kinematics.kinematics.singular_points import RATE_ACCURACY
from linkage_kinematics.kinematics.solver import DeadPointError, solve
from prismatic_reference import errors, input_floor, reference_dead_point, reference_state
import pytest

REVOLUTE = JointKind.REVOLUTE
PRISMATIC = JointKind.PRISMATIC
STEP = 1e-6  # central-difference step (rad or m)


def loop_from_points(points: list[tuple[float, float]], kinds=(REVOLUTE,) * 4,
                     slide=None) -> PlanarLoop:
    """Return the loop whose joints are at ``points`` in its zero pose (all frames aligned)."""
    links = tuple((points[(k + 1) % 4][0] - points[k][0], points[(k + 1) % 4][1] - points[k][1])
                  for k in range(4))
    return PlanarLoop(tuple(kinds), links, slide)


def closure_residual(loop: PlanarLoop, coordinates: tuple[float, ...]) -> float:
    """Return the distance (m) from joint 0 to the end of the chain 0 → 1 → 2 → 3 → 0."""
    points, angles = joint_points(loop, coordinates)
    theta = angles[3]
    link_x, link_y = loop.links[3]
    end_x = points[3][0] + math.cos(theta) * link_x - math.sin(theta) * link_y
    end_y = points[3][1] + math.sin(theta) * link_x + math.cos(theta) * link_y
    return math.hypot(end_x, end_y)


def angle_sum_residual(loop: PlanarLoop, coordinates: tuple[float, ...]) -> float:
    """Return |Σ φ_k| modulo 2π: the cut pin closes the turn."""
    total = sum(value for value, kind in zip(coordinates, loop.kinds) if kind is REVOLUTE)
    return abs(math.remainder(total, 2.0 * math.pi))


def coordinate_gap(loop: PlanarLoop, first: float, second: float, joint: int) -> float:
    """Return the difference of two values of one coordinate (wrapped for a revolute joint)."""
    if loop.kinds[joint] is REVOLUTE:
        return math.remainder(first - second, 2.0 * math.pi)
    return first - second


def assert_state_consistent(loop: PlanarLoop, known: int, value: float, branch: int,
                            rate: float = 1.7) -> None:
    """Check closure, the known coordinate, and the rates against central differences."""
    state = solve_loop(loop, known, value, rate, branch)
    assert state.coordinates[known] == value
    assert state.rates[known] == rate
    assert all(math.isfinite(x) for x in state.coordinates + state.rates)
    assert closure_residual(loop, state.coordinates) <= 1e-13
    assert angle_sum_residual(loop, state.coordinates) <= 1e-13
    assert branch_of(loop, known, state.coordinates) == branch
    after = solve_loop(loop, known, value + STEP, rate, branch)
    before = solve_loop(loop, known, value - STEP, rate, branch)
    scale = max(abs(x) for x in state.rates)
    for joint in range(4):
        difference = coordinate_gap(loop, after.coordinates[joint], before.coordinates[joint],
                                    joint) / (2.0 * STEP) * rate
        assert abs(difference - state.rates[joint]) <= 1e-6 * scale, (joint, state)


# A crank-rocker (joint 1 turns fully), a double-rocker and a parallelogram, in zero poses.
CRANK_ROCKER = loop_from_points([(0.0, 0.0), (0.3, 0.05), (1.1, 0.65), (0.9, -0.3)])
DOUBLE_ROCKER = loop_from_points([(0.0, 0.0), (1.0, 0.0), (1.2, 0.5), (0.3, 0.9)])
PARALLELOGRAM = loop_from_points([(0.0, 0.0), (1.0, 0.0), (1.3, 0.4), (0.3, 0.4)])
FOUR_BARS = {'crank_rocker': CRANK_ROCKER, 'double_rocker': DOUBLE_ROCKER,
             'parallelogram': PARALLELOGRAM}


def sample_values(loop: PlanarLoop, known: int, count: int = 9) -> list[float]:
    """Return values spread over the known joint's reachable intervals, ends excluded."""
    reach = known_joint_range(loop, known)
    values = []
    for low, high in reach.intervals:
        margin = 0.02 * (high - low)  # central differences lose accuracy near dead points
        values += [low + margin + (high - low - 2 * margin) * i / (count - 1)
                   for i in range(count)]
    return [value for value in values if reach.change_point_distance(value) is None
            or reach.change_point_distance(value) > 1e-4]


@pytest.mark.parametrize('name', sorted(FOUR_BARS))
@pytest.mark.parametrize('known', (1, 2, 3))
@pytest.mark.parametrize('branch', (1, -1))
def test_four_bar_closes_and_rates_match_differences(name: str, known: int, branch: int) -> None:
    loop = FOUR_BARS[name]
    for value in sample_values(loop, known):
        assert_state_consistent(loop, known, value, branch)


@pytest.mark.parametrize('name', sorted(FOUR_BARS))
@pytest.mark.parametrize('known', (1, 2, 3))
def test_the_zero_pose_is_solved_on_its_own_branch(name: str, known: int) -> None:
    loop = FOUR_BARS[name]
    branch = branch_of(loop, known, (0.0, 0.0, 0.0, 0.0))
    state = solve_loop(loop, known, 0.0, 1.0, branch)
    assert max(abs(x) for x in state.coordinates) <= 1e-14


def test_four_bar_known_one_is_the_existing_solve_mapped() -> None:
    linkage = FourBar(0.3, math.sqrt(1.09), 0.3, 1.3, 0.0)
    zero = solve(linkage, 0.0, CrankRates(0.0, 0.0), 1)
    # Joint 0 = C, 1 = O, 2 = A, 3 = B, body 0's frame the FourBar's.
    loop = loop_from_points([(1.3, 0.0), (0.0, 0.0), (zero.pin_a_x, zero.pin_a_y),
                             (zero.pin_b_x, zero.pin_b_y)])
    assert branch_of(loop, 1, (0.0,) * 4) == 1
    for alpha in (-0.02, 0.0, 0.4, 1.5, 3.0):
        state = solve(linkage, alpha, CrankRates(2.0, 0.0), 1)
        mapped = solve_loop(loop, 1, alpha, 2.0, 1)
        coupler = state.gamma - zero.gamma
        rocker = -(state.beta - zero.beta)
        expected = (-rocker, alpha, coupler - alpha, rocker - coupler)
        for got, want in zip(mapped.coordinates, expected):
            assert abs(math.remainder(got - want, 2 * math.pi)) <= 4e-15
        # The loop's link lengths come from differences of the pins: equal to rounding.
        assert mapped.rates == pytest.approx((-state.omega_bc, 2.0, state.omega_ab - 2.0,
                                              state.omega_bc - state.omega_ab), rel=1e-13)


def test_four_bar_range_and_refusals() -> None:
    loop = DOUBLE_ROCKER
    reach = known_joint_range(loop, 3)
    assert len(reach.dead_points) == 4 and not reach.full_rotation
    dead = reach.dead_points[0]
    assert reach.dead_point_distance(dead) == 0.0
    branch = 1
    with pytest.raises(DeadPointError, match='joint 3'):
        solve_loop(loop, 3, dead, 1.0, branch)
    outside = dead - 1e-3 if reach.contains(dead + 1e-3) else dead + 1e-3
    with pytest.raises(UnreachableError, match='joint 3'):
        solve_loop(loop, 3, outside, 1.0, branch)
    assert known_joint_range(CRANK_ROCKER, 1).full_rotation


def test_parallelogram_continues_through_its_change_points() -> None:
    loop = PARALLELOGRAM
    reach = known_joint_range(loop, 1)
    assert len(reach.change_points) == 2
    branch = branch_of(loop, 1, (0.0,) * 4)
    # Over a whole turn the smooth branch keeps the parallelogram: φ2 = −φ1, φ3 = φ1, φ0 = −φ1.
    for step in range(-360, 361, 5):
        value = math.radians(step)
        state = solve_loop(loop, 1, value, 1.0,
                           continued_branch_of(loop, 1, 0.0, branch, value))
        for got, want in zip(state.coordinates, (-value, value, -value, value)):
            assert abs(math.remainder(got - want, 2 * math.pi)) <= 1e-13
        assert state.rates == pytest.approx((-1.0, 1.0, -1.0, 1.0), abs=1e-13)


@pytest.mark.parametrize('kinds, links, slide, problem', [
    ((PRISMATIC,) + (REVOLUTE,) * 3, ((1.0, 0.0),) * 4, (1.0, 0.0), 'cut pin'),
    ((REVOLUTE, PRISMATIC, PRISMATIC, REVOLUTE), ((1.0, 0.0),) * 4, (1.0, 0.0), 'at most one'),
    ((REVOLUTE,) * 4, ((1.0, 0.0),) * 3, None, 'four finite'),
    ((REVOLUTE,) * 4, ((1.0, 0.0),) * 3 + ((math.nan, 0.0),), None, 'four finite'),
    ((REVOLUTE, PRISMATIC, REVOLUTE, REVOLUTE), ((1.0, 0.0),) * 4, None, 'slide'),
    ((REVOLUTE, PRISMATIC, REVOLUTE, REVOLUTE), ((1.0, 0.0),) * 4, (2.0, 0.0), 'unit'),
    ((REVOLUTE,) * 4, ((1.0, 0.0),) * 4, (1.0, 0.0), 'no joint is prismatic'),
])
def test_invalid_loops_are_refused(kinds, links, slide, problem) -> None:
    with pytest.raises(GeometryError, match=problem):
        PlanarLoop(kinds, links, slide)


def test_known_joint_must_not_be_the_cut_pin() -> None:
    with pytest.raises(ValueError, match='known joint'):
        solve_loop(CRANK_ROCKER, 0, 0.0, 1.0, 1)


# --- loops with one prismatic joint (RRRP) ------------------------------------------------------

def rotated_loop(points: list[tuple[float, float]], kinds: list[JointKind], slide,
                 shift: int) -> PlanarLoop:
    """Return the loop with its joints renumbered from ``shift`` (joint 0 must stay revolute)."""
    return loop_from_points(points[shift:] + points[:shift], kinds[shift:] + kinds[:shift],
                            slide)


def slider_crank(crank: float, coupler: float, offset: float, shift: int,
                 crank_angle: float = 1.0) -> PlanarLoop:
    """
    Return a slider-crank: crank pin, wrist pin, slider point (prismatic), crank pivot.

    The slide is horizontal at height ``offset`` above the crank pivot; renumbered by ``shift``.
    """
    pin = (crank * math.cos(crank_angle), crank * math.sin(crank_angle))
    wrist = (pin[0] + math.sqrt(coupler ** 2 - (offset - pin[1]) ** 2), offset)
    return rotated_loop([pin, wrist, (wrist[0] + 0.2, offset), (0.0, 0.0)],
                        [REVOLUTE, REVOLUTE, PRISMATIC, REVOLUTE], (1.0, 0.0), shift)


def cylinder(shift: int) -> PlanarLoop:
    """Return a hydraulic cylinder between two pivots, lifting a boom hinged on the ground."""
    slide = (math.cos(0.7), math.sin(0.7))
    base = (0.2, -0.1)
    rod_end = (base[0] + 0.6 * slide[0], base[1] + 0.6 * slide[1])
    return rotated_loop([(0.0, 0.0), rod_end, (base[0] + 0.3 * slide[0], base[1] + 0.3 * slide[1]),
                         base], [REVOLUTE, REVOLUTE, PRISMATIC, REVOLUTE], slide, shift)


RRRP_LOOPS = {
    **{f'offset_slider_crank_{shift}': slider_crank(0.1, 0.3, 0.02, shift) for shift in (0, 1, 3)},
    **{f'cylinder_{shift}': cylinder(shift) for shift in (0, 1, 3)},
}


@pytest.mark.parametrize('name', sorted(RRRP_LOOPS))
@pytest.mark.parametrize('known', (1, 2, 3))
@pytest.mark.parametrize('branch', (1, -1))
def test_rrrp_closes_and_rates_match_differences(name: str, known: int, branch: int) -> None:
    loop = RRRP_LOOPS[name]
    for value in sample_values(loop, known, 7):
        assert_state_consistent(loop, known, value, branch)


@pytest.mark.parametrize('name', sorted(RRRP_LOOPS))
@pytest.mark.parametrize('known', (1, 2, 3))
def test_rrrp_zero_pose_is_solved_on_its_own_branch(name: str, known: int) -> None:
    loop = RRRP_LOOPS[name]
    branch = branch_of(loop, known, (0.0, 0.0, 0.0, 0.0))
    state = solve_loop(loop, known, 0.0, 1.0, branch)
    assert max(abs(x) for x in state.coordinates) <= 1e-14


# --- RRRP against the independent 50-digit reference --------------------------------------------

# The results' own rounding (rad, m or relative) allowed on top of 3× the input floor.
ROUNDING = 2e-15
# The two numberings that between them make every case: slide p = 2 (known 1 and 3 next to it,
# 2 the slide) and p = 1 (known 1 the slide, 2 next to it, 3 opposite it).
REFERENCE_LOOPS = {
    'slider_crank': (slider_crank(0.1, 0.3, 0.02, 0), slider_crank(0.1, 0.3, 0.02, 1)),
    'cylinder': (cylinder(0), cylinder(1)),
    # crank + offset > coupler and offset > crank − coupler: its crank and the angle between crank
    # and coupler have dead points too (the others' turn fully)
    'rocking_slider_crank': (slider_crank(0.3, 0.25, 0.1, 0), slider_crank(0.3, 0.25, 0.1, 1)),
}


def assert_as_accurate_as_the_input(loop: PlanarLoop, known: int, value: float,
                                    branch: int) -> None:
    """Check a solved state against the reference: within 3× the input floor plus rounding."""
    state = solve_loop(loop, known, value, 1.3, branch)
    exact = reference_state(loop, known, value, 1.3, state.coordinates)
    coordinate_error, rate_error = errors(loop, state.coordinates, state.rates, exact)
    coordinate_floor, rate_floor = input_floor(loop, known, value, 1.3, state.coordinates)
    assert coordinate_error <= 3.0 * coordinate_floor + ROUNDING * max(1.0, abs(value)), value
    assert rate_error <= 3.0 * rate_floor + ROUNDING, value
    assert reference_side(loop, known, exact[0]) == branch


def reference_side(loop: PlanarLoop, known: int, coordinates: list) -> int:
    """Return the branch the library's branch_of gives for the reference's (rounded) answer."""
    return branch_of(loop, known, tuple(float(x) for x in coordinates))


def assert_dead_points_at_float64s_limit(loop: PlanarLoop, known: int) -> None:
    """Approach every dead point of joint ``known`` from its reachable side, both branches."""
    reach = known_joint_range(loop, known)
    for dead in reach.dead_points:
        exact = reference_dead_point(loop, known, dead)
        assert abs(float(exact) - dead) <= 1e-15 * max(1.0, abs(dead))
        inward = 1.0 if reach.contains(dead + 1e-6 * max(1.0, abs(dead))) else -1.0
        for branch in (1, -1):
            for relative in (1e-3, 1e-6, 1e-9, 1e-12, 1e-13, 1e-14, 1e-15):
                distance = relative * max(1.0, abs(dead))
                value = float(exact + inward * distance)
                # the four-bar's rule: refuse where 1.5·ulp(value) > RATE_ACCURACY·distance
                ratio = 1.5 * math.ulp(value) / (RATE_ACCURACY * distance)
                if ratio > 2.0:
                    with pytest.raises(DeadPointError):
                        solve_loop(loop, known, value, 1.3, branch)
                elif ratio < 0.5:
                    assert_as_accurate_as_the_input(loop, known, value, branch)
            with pytest.raises(UnreachableError):
                solve_loop(loop, known, float(exact - inward * 1e-9 * max(1.0, abs(dead))),
                           1.3, branch)
        # the float nearest the dead point: on it (refused) or just past it (unreachable)
        with pytest.raises((DeadPointError, UnreachableError)):
            solve_loop(loop, known, dead, 1.3, 1)


@pytest.mark.parametrize('name', sorted(REFERENCE_LOOPS))
@pytest.mark.parametrize('numbering', (0, 1))
@pytest.mark.parametrize('known', (1, 2, 3))
def test_rrrp_dead_points_at_float64s_limit(name: str, numbering: int, known: int) -> None:
    assert_dead_points_at_float64s_limit(REFERENCE_LOOPS[name][numbering], known)


# A four-bar whose pivots are at no special angles: its link lengths are no floats.
TILTED = loop_from_points([(0.0, 0.0), (0.93, 0.21), (1.17, 0.77), (0.31, 0.83)])


@pytest.mark.parametrize('loop, known', [(CRANK_ROCKER, 2), (CRANK_ROCKER, 3),
                                         (DOUBLE_ROCKER, 3), (TILTED, 3)])
def test_four_bar_dead_points_at_float64s_limit(loop: PlanarLoop, known: int) -> None:
    # The FourBar's singular points are the loop's exact ones (geometry.from_exact), not those
    # of its float lengths: without that, the error was up to 7× the input floor here.
    assert_dead_points_at_float64s_limit(loop, known)


@pytest.mark.parametrize('name', sorted(REFERENCE_LOOPS))
@pytest.mark.parametrize('numbering', (0, 1))
@pytest.mark.parametrize('known', (1, 2, 3))
def test_rrrp_over_the_reachable_range(name: str, numbering: int, known: int) -> None:
    loop = REFERENCE_LOOPS[name][numbering]
    for value in sample_values(loop, known, 5):
        for branch in (1, -1):
            assert_as_accurate_as_the_input(loop, known, value, branch)


# --- change points: the two assemblies cross, the motion continues on the smooth branch ---------

# Exact in binary: L_a = 0.625, L_c = 0.3125 and the slide line 0.3125 from J_b (= L_a − L_c),
# so every case has a change point (slide known: the triangle folds flat with J_c straight below
# J_b; opposite: the pivots next to the slide at their least distance; next: the far circle
# touches the slide line).
CHANGE_LOOP = loop_from_points([(0.0, 0.0), (0.2, 0.3125), (0.625, 0.3125), (0.375, 0.5)],
                               [REVOLUTE, PRISMATIC, REVOLUTE, REVOLUTE], (1.0, 0.0))
# Crank = coupler = 0.3125 and zero offset, exact in binary: the slider passes through the crank
# pivot. Joint 0 the crank pin, 1 the wrist pin, 2 the slide, 3 the crank pivot.
CRANK_ANGLE = math.atan2(0.25, 0.1875)
ISOSCELES = loop_from_points([(0.1875, 0.25), (0.375, 0.0), (0.625, 0.0), (0.0, 0.0)],
                             [REVOLUTE, REVOLUTE, PRISMATIC, REVOLUTE], (1.0, 0.0))
OFFSETS = (1e-2, 1e-6, 1e-10, 1e-13, 1e-15)


@pytest.mark.parametrize('loop, known', [(CHANGE_LOOP, 1), (CHANGE_LOOP, 2), (CHANGE_LOOP, 3),
                                         (ISOSCELES, 1), (ISOSCELES, 3)])
@pytest.mark.parametrize('branch', (1, -1))
def test_rrrp_through_change_points(loop: PlanarLoop, known: int, branch: int) -> None:
    reach = known_joint_range(loop, known)
    assert reach.change_points
    for point in reach.change_points:
        start = point - 0.05
        assert continued_branch_of(loop, known, start, branch, point + 0.05) == -branch
        for value in [point + sign * offset for offset in OFFSETS for sign in (1, -1)]:
            assert_as_accurate_as_the_input(
                loop, known, value, continued_branch_of(loop, known, start, branch, value))
        # at the change point itself the smooth branch's rates, as on either side of it
        state = solve_loop(loop, known, point, 1.3,
                           continued_branch_of(loop, known, start, branch, point))
        for offset in (1e-15, -1e-15):
            near = solve_loop(loop, known, point + offset, 1.3,
                              continued_branch_of(loop, known, start, branch, point + offset))
            assert near.rates == pytest.approx(state.rates, rel=1e-12, abs=1e-12)


def test_isosceles_slider_crank_over_four_turns() -> None:
    # The smooth motion from the zero pose mirrors the crank: the slider at 2r·cos θ; the other
    # smooth motion keeps the wrist pin on the crank pivot, at rest. δ moves the ground (body 2)
    # relative to the slider (body 1): δ = 2r·(cos θ₀ − cos θ), and 2r·cos θ₀ = 0.375 at rest.
    branch = branch_of(ISOSCELES, 3, (0.0,) * 4)
    change = known_joint_range(ISOSCELES, 3).change_points[0]
    for step in range(-160, 161):
        value = change + step * math.pi / 40  # lands on the change points every 20 steps
        mirror = solve_loop(ISOSCELES, 3, value, 1.3,
                            continued_branch_of(ISOSCELES, 3, 0.0, branch, value))
        crank = CRANK_ANGLE + value
        assert abs(mirror.coordinates[2] - 0.625 * (0.6 - math.cos(crank))) <= 1e-15
        assert abs(mirror.rates[2] - 0.625 * math.sin(crank) * 1.3) <= 1e-15
        assert abs(math.remainder(mirror.coordinates[0] + 2.0 * value, 2 * math.pi)) <= 1e-14
        still = solve_loop(ISOSCELES, 3, value, 1.3,
                           continued_branch_of(ISOSCELES, 3, 0.0, -branch, value))
        assert abs(still.coordinates[2] - 0.375) <= 1e-15
        assert abs(still.rates[2]) <= 1e-15


def test_pin_through_the_pivot_is_refused() -> None:
    # Slide known on the isosceles slider-crank: the wrist pin meets the crank pivot at δ = 0.375
    # where coupler and crank can turn together: refused, as the four-bar's pin A through C.
    with pytest.raises(DeadPointError, match='meet'):
        solve_loop(ISOSCELES, 2, 0.375, 1.0, 1)
    assert_state_consistent(ISOSCELES, 2, 0.2, 1)


# --- random loops -------------------------------------------------------------------------------

coordinate = st.floats(-1.0, 1.0, allow_nan=False)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(points=st.lists(st.tuples(coordinate, coordinate), min_size=4, max_size=4),
       slide_angle=st.floats(-math.pi, math.pi), prismatic=st.sampled_from((1, 2, 3)),
       known=st.sampled_from((1, 2, 3)), where=st.floats(0.05, 0.95),
       branch=st.sampled_from((1, -1)))
def test_random_rrrp_loops_against_the_reference(points, slide_angle, prismatic, known, where,
                                                 branch) -> None:
    kinds = [REVOLUTE] * 4
    kinds[prismatic] = PRISMATIC
    pivots = [points[(prismatic + k) % 4] for k in (-1, 1, 2)]
    assume(min(math.dist(pivots[i], pivots[j]) for i, j in ((0, 1), (1, 2), (0, 2))) > 0.05)
    try:
        loop = loop_from_points(points, kinds, (math.cos(slide_angle), math.sin(slide_angle)))
        reach = known_joint_range(loop, known)
    except GeometryError:
        assume(False)
    low, high = max(reach.intervals, key=lambda interval: interval[1] - interval[0])
    assume(high - low > 1e-3)
    value = low + where * (high - low)
    assume(reach.change_point_distance(value) is None or reach.change_point_distance(value) > 0.01)
    state = solve_loop(loop, known, value, 1.3, branch)
    assert closure_residual(loop, state.coordinates) <= 1e-13
    assert angle_sum_residual(loop, state.coordinates) <= 1e-13
    assert branch_of(loop, known, state.coordinates) == branch
    exact = reference_state(loop, known, value, 1.3, state.coordinates)
    coordinate_error, rate_error = errors(loop, state.coordinates, state.rates, exact)
    coordinate_floor, rate_floor = input_floor(loop, known, value, 1.3, state.coordinates)
    # A few more roundings than the chosen geometries: the links here are up to 2.8 m long and
    # meet at any angle.
    assert coordinate_error <= 3.0 * coordinate_floor + 1e-14
    assert rate_error <= 3.0 * rate_floor + 1e-13


def test_loops_compare_by_value_whatever_sequences_they_are_given_as() -> None:
    loop = PlanarLoop(['revolute', 'revolute', 'prismatic', 'revolute'],
                      [[0.1, 0.2], (0.3, -0.1), [-0.2, 0.0], (-0.2, -0.1)], [1, 0])
    same = PlanarLoop((REVOLUTE, REVOLUTE, PRISMATIC, REVOLUTE),
                      ((0.1, 0.2), (0.3, -0.1), (-0.2, 0.0), (-0.2, -0.1)), (1.0, 0.0))
    assert loop == same and hash(loop) == hash(same)
    assert loop.prismatic == 2
    with pytest.raises(GeometryError, match='kinds'):
        PlanarLoop(('revolute', 'ball', 'revolute', 'revolute'), same.links)


@settings(max_examples=2000, deadline=None)
@given(st.floats(allow_nan=True, allow_infinity=True), st.floats(allow_nan=False),
       st.floats(allow_nan=False, min_value=-1e-8, max_value=1e-8))
def test_offset_from_is_offset_of_no_turns_bit_for_bit(alpha: float, high: float,
                                                       low: float) -> None:
    """The slider loops' ``offset_from`` gives ``offset(…, 0.0)``'s bits, -0.0 and NaN too."""
    expected = singular_points.offset(alpha, (high, low), 0.0)
    got = singular_points.offset_from(alpha, (high, low))
    assert struct.pack('<d', got) == struct.pack('<d', expected) or (
        math.isnan(got) and math.isnan(expected))


@pytest.mark.parametrize('alpha', [0.0, -0.0, 1.0, -1.0, 5e-324, -5e-324, 1e308, -1e308,
                                   math.inf, -math.inf, 0.1 + 0.2, 1.0 + 2**-52])
@pytest.mark.parametrize('point', [(0.0, 0.0), (-0.0, 0.0), (0.0, -0.0), (1.0, 0.0),
                                   (0.3, 5.551115123125783e-17), (-1.0, -1e-17), (1e308, 0.0)])
def test_offset_from_at_signed_zeros_and_limits(alpha: float, point: tuple[float, float]
                                                ) -> None:
    """The cases a random draw rarely meets: signed zeros, subnormals, overflow, infinities."""
    expected = singular_points.offset(alpha, point, 0.0)
    got = singular_points.offset_from(alpha, point)
    assert struct.pack('<d', got) == struct.pack('<d', expected) or (
        math.isnan(got) and math.isnan(expected))
