# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""Exact four-bar kinematics checked against the independent mpmath reference (reference.py)."""

from __future__ import annotations

import math

from hypothesis import assume, given, HealthCheck, settings
from hypothesis import strategies as st
import linkage_kinematics.kinematics as library
from linkage_kinematics.kinematics import geometry, solver
from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import (
    FourBar,
    GeometryError,
    PRESETS,
    UnreachableError,
)
from linkage_kinematics.kinematics.solver import (
    DeadPointError,
    LinkageState,
    loop_closure_residual,
    reachable_mask,
    solve,
    solve_many,
)
import numpy as np
import pytest
from reference import reference_singular_angles, reference_state, state_errors

ANGLE_TOLERANCE = 1e-12  # rad
RATE_TOLERANCE = 1e-9  # normwise relative, see reference.state_errors
CONSTANT = DriveLaw(2.0)
VARIABLE = DriveLaw(0.10, 2.3)

GEOMETRIES = {
    **{name: preset.geometry for name, preset in PRESETS.items()},
    'non_grashof_tilted': FourBar(0.5, 2.0, 1.8, 0.3, -0.2),
    'drag_link': FourBar(1.0, 1.2, 0.9, 0.3, 0.0),
    'crank_rocker_tilted': FourBar(0.25, 1.0, 0.7, 0.8, -0.35),
    'rocker_rocker_raised': FourBar(0.5, 1.1, 0.8, 0.6, 0.4),
}


def sample_angles(linkage: FourBar, count: int) -> list[float]:
    """
    Evenly spread crank angles over each reachable interval.

    Plus two within 1e-3 rad of each dead point (on its reachable side).
    """
    angles = []
    for low, high in linkage.reachability.intervals:
        angles.extend(np.linspace(low, high, count + 2)[1:-1])
        if not linkage.reachability.full_rotation:
            angles.extend((low + 1e-3, low + 3e-4, high - 1e-3, high - 3e-4))
    return [float(angle) for angle in angles]


def assert_matches_reference(state: LinkageState, linkage: FourBar, drive: DriveLaw,
                             branch: int) -> None:
    errors = state_errors(state, reference_state(linkage, state.alpha, drive, branch))
    assert errors['angle'] <= ANGLE_TOLERANCE, errors
    assert errors['pin'] <= ANGLE_TOLERANCE, errors
    for kind in ('angular_rate', 'angular_acceleration', 'velocity', 'acceleration'):
        assert errors[kind] <= RATE_TOLERANCE, (kind, errors)


def branch_side(linkage: FourBar, state: LinkageState) -> float:
    """+1 if B is left of the directed line A→C, −1 if right."""
    to_c = (linkage.ground_x - state.pin_a_x, linkage.ground_y - state.pin_a_y)
    to_b = (state.pin_b_x - state.pin_a_x, state.pin_b_y - state.pin_a_y)
    return math.copysign(1.0, to_c[0] * to_b[1] - to_c[1] * to_b[0])


@pytest.mark.parametrize('name', sorted(GEOMETRIES))
@pytest.mark.parametrize('branch', [1, -1])
@pytest.mark.parametrize('drive', [CONSTANT, VARIABLE], ids=['constant', 'variable'])
def test_solve_matches_reference(name: str, branch: int, drive: DriveLaw) -> None:
    linkage = GEOMETRIES[name]
    for alpha in sample_angles(linkage, 12):
        state = solve(linkage, alpha, drive, branch)
        assert branch_side(linkage, state) == branch
        assert_matches_reference(state, linkage, drive, branch)


@pytest.mark.parametrize('name', sorted(GEOMETRIES))
@pytest.mark.parametrize('branch', [1, -1])
def test_solve_many_equals_solve_and_closes_the_loop(name: str, branch: int) -> None:
    linkage = GEOMETRIES[name]
    angles = np.array(sample_angles(linkage, 200))
    states = solve_many(linkage, angles, VARIABLE, branch)
    assert np.max(loop_closure_residual(linkage, states)) <= 1e-12
    for index in range(0, angles.size, 37):
        row = states.at(index)
        single = solve(linkage, float(angles[index]), VARIABLE, branch)
        for field_name in LinkageState.__dataclass_fields__:
            assert getattr(row, field_name) == pytest.approx(
                getattr(single, field_name), rel=1e-13, abs=1e-13
            ), field_name
    for field_name in LinkageState.__dataclass_fields__:
        assert np.all(np.isfinite(getattr(states, field_name))), field_name


@pytest.mark.parametrize('name', ['paper', 'drag_link', 'rocker_rocker_raised'])
def test_finite_differences_of_positions_give_the_rates(name: str) -> None:
    """
    Central differences in α of solve_many's positions, times ω (and α̈ = k·ω).

    Reproduce the closed-form velocities and accelerations.
    """
    linkage = GEOMETRIES[name]
    step = 1e-4
    # Away from dead points, where the truncation error h²·β'''/6 stays small.
    low, high = linkage.reachability.intervals[0]
    margin = 0.1 * (high - low)
    centres = np.linspace(low + margin, high - margin, 30)
    stencil = solve_many(
        linkage, np.concatenate([centres - step, centres, centres + step]), VARIABLE
    )

    def around(values: np.ndarray, angle: bool) -> tuple[np.ndarray, np.ndarray]:
        """(value after − centre, centre − value before), wrapped for angles."""
        size = centres.size
        before, centre, after = values[:size], values[size:2 * size], values[2 * size:]
        forward, backward = after - centre, centre - before
        if angle:
            forward, backward = (np.remainder(d + np.pi, 2 * np.pi) - np.pi
                                 for d in (forward, backward))
        return forward, backward

    middle = solve_many(linkage, centres, VARIABLE)
    omega = middle.omega
    for position, rate, acceleration in (
        ('beta', -middle.omega_bc, -middle.omega_dot_bc),
        ('gamma', middle.omega_ab, middle.omega_dot_ab),
        ('pin_b_x', middle.velocity_b_x, middle.acceleration_b_x),
        ('pin_b_y', middle.velocity_b_y, middle.acceleration_b_y),
        ('pin_a_y', middle.velocity_a_y, middle.acceleration_a_y),
    ):
        forward, backward = around(getattr(stencil, position), position in ('beta', 'gamma'))
        first = (forward + backward) / (2.0 * step)
        second = (forward - backward) / step**2
        rate_scale = np.max(np.abs(rate))
        assert np.max(np.abs(first * omega - rate)) <= 1e-7 * rate_scale, position
        predicted = second * omega**2 + first * middle.omega_dot
        acceleration_scale = np.max(np.abs(acceleration))
        assert np.max(np.abs(predicted - acceleration)) <= 1e-5 * acceleration_scale, position


# Lengths between 0.1 and 2 m and a ground pivot anywhere within 2 m: Grashof and non-Grashof
# linkages of every type, with both branches.
lengths = st.floats(0.1, 2.0)
coordinates = st.floats(-2.0, 2.0)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(
    crank=lengths, coupler=lengths, rocker=lengths, ground_x=coordinates, ground_y=coordinates,
    branch=st.sampled_from([1, -1]), which=st.integers(0, 1), where=st.floats(0.01, 0.99),
    omega0=st.floats(-5.0, 5.0), k=st.floats(-3.0, 3.0),
)
def test_random_linkages_match_reference(crank, coupler, rocker, ground_x, ground_y, branch,
                                         which, where, omega0, k) -> None:
    try:
        linkage = FourBar(crank, coupler, rocker, ground_x, ground_y)
    except GeometryError:
        assume(False)
    assume(linkage.ground_length > 0.05)
    intervals = linkage.reachability.intervals
    low, high = intervals[which % len(intervals)]
    alpha = low + (high - low) * where
    drive = DriveLaw(omega0, k)
    assume(abs(drive.angular_velocity(alpha)) > 1e-3)
    reference = reference_state(linkage, alpha, drive, branch)
    # Well away from collinearity only: near it the error grows as measured in test_hard_cases.
    assume(math.sin(float(reference['transmission_angle'])) > 1e-2)
    state = solve(linkage, alpha, drive, branch)
    errors = state_errors(state, reference)
    assert errors['angle'] <= ANGLE_TOLERANCE, errors
    for kind in ('angular_rate', 'angular_acceleration', 'velocity', 'acceleration'):
        assert errors[kind] <= RATE_TOLERANCE, (kind, errors)
    assert loop_closure_residual(linkage, state) <= 1e-12


@settings(max_examples=40, deadline=None)
@given(crank=st.floats(0.1, 0.5), extra=st.lists(st.floats(0.2, 2.0), min_size=3, max_size=3),
       tilt=st.floats(-math.pi, math.pi))
def test_grashof_crank_rocker_turns_fully(crank, extra, tilt) -> None:
    """
    Return the crank as the strictly shortest link of a Grashof linkage turns fully.

    And the reference agrees at every sampled angle.
    """
    coupler, rocker, ground = (crank + length for length in extra)
    ordered = sorted((crank, coupler, rocker, ground))
    assume(ordered[0] + ordered[3] < 0.99 * (ordered[1] + ordered[2]))
    linkage = FourBar(crank, coupler, rocker, ground * math.cos(tilt), ground * math.sin(tilt))
    assert linkage.is_grashof
    assert linkage.reachability.full_rotation
    assert reference_singular_angles(linkage) == []
    for alpha in np.linspace(-math.pi, math.pi, 5):
        state = solve(linkage, float(alpha), CONSTANT)
        errors = state_errors(state, reference_state(linkage, float(alpha), CONSTANT))
        assert errors['angle'] <= ANGLE_TOLERANCE and errors['angular_rate'] <= RATE_TOLERANCE


def _row(state: LinkageState) -> dict[str, float]:
    """Return the seed's table columns (degrees, m/s, rad/s, rad/s²)."""
    return {
        'beta': math.degrees(state.beta),
        'gamma': math.degrees(state.gamma),
        'v_a': float(state.v_a),
        'v_b': float(state.v_b),
        'omega': state.omega,
        'omega_ab': state.omega_ab,
        'omega_bc': state.omega_bc,
        'omega_dot_ab': state.omega_dot_ab,
        'omega_dot_bc': state.omega_dot_bc,
    }


# The seed's Tables 1 and 2 (constant ω = 2 rad/s), value and the decimals it prints. Its
# "−6.7" for ω_BC at α = 0 is −6.667 (−20/3), and its Table 2 prints −57.8 and 192.6.
SEED_TABLES_1_AND_2 = {
    0.0: {'beta': (0, 0), 'gamma': (16.7, 1), 'v_a': (0.6, 1), 'v_b': (2, 0), 'omega': (2, 0),
          'omega_ab': (2, 0), 'omega_bc': (-6.7, 1), 'omega_dot_ab': (-57.8, 1),
          'omega_dot_bc': (192.6, 1)},
    90.0: {'beta': (90, 0), 'gamma': (16.7, 1), 'v_a': (0.6, 1), 'v_b': (0.18, 2),
           'omega': (2, 0), 'omega_ab': (-0.6, 1), 'omega_bc': (-0.6, 1),
           'omega_dot_ab': (0.0, 1), 'omega_dot_bc': (5.2, 1)},
}


@pytest.mark.parametrize('alpha_degrees', sorted(SEED_TABLES_1_AND_2))
def test_seed_tables_1_and_2(alpha_degrees: float) -> None:
    row = _row(solve(PRESETS['paper'].geometry, math.radians(alpha_degrees), CONSTANT))
    for column, (printed, decimals) in SEED_TABLES_1_AND_2[alpha_degrees].items():
        assert round(row[column], decimals) == printed, (column, row[column])


def test_seed_values_at_alpha_zero_to_more_digits() -> None:
    """The seed's figures at α = 0, more digits: ω_BC = −20/3, ω̇_AB = −57.78, ω̇_BC = 192.59."""
    state = solve(PRESETS['paper'].geometry, 0.0, CONSTANT)
    assert state.omega_bc == pytest.approx(-20.0 / 3.0, rel=1e-12)
    assert round(state.omega_dot_ab, 2) == -57.78
    assert round(state.omega_dot_bc, 2) == 192.59
    assert state.beta == pytest.approx(0.0, abs=1e-15)


def test_reachability_of_the_presets() -> None:
    paper = PRESETS['paper'].geometry.reachability
    assert round(math.degrees(paper.dead_points[0]), 3) == -1.941
    assert not paper.full_rotation
    full_turn = PRESETS['paper_full_turn'].geometry.reachability
    assert not full_turn.full_rotation
    ((low, high),) = full_turn.intervals
    assert (round(math.degrees(low), 1), round(math.degrees(high), 1)) == (-211.3, 31.3)
    assert PRESETS['grashof_crank_rocker'].geometry.reachability.full_rotation


@pytest.mark.parametrize('name', sorted(GEOMETRIES))
def test_dead_points_match_reference(name: str) -> None:
    linkage = GEOMETRIES[name]
    reachability = linkage.reachability
    expected = [float(angle) for angle in reference_singular_angles(linkage)]
    found = sorted(math.remainder(angle, 2 * math.pi)
                   for angle in reachability.dead_points + reachability.change_points)
    assert found == pytest.approx(expected, abs=1e-13)


def test_unreachable_angle_names_the_interval() -> None:
    linkage = PRESETS['paper_full_turn'].geometry
    with pytest.raises(UnreachableError, match=r'\[-211\.\d+°, 31\.\d+°\]'):
        solve(linkage, math.radians(90.0), CONSTANT)
    with pytest.raises(UnreachableError, match='-1.941'):
        solve(PRESETS['paper'].geometry, math.radians(-10.0), CONSTANT)
    with pytest.raises(UnreachableError, match=r'\[-211'):
        solve_many(linkage, np.array([0.0, math.radians(90.0)]), CONSTANT)
    for bad in (math.nan, math.inf, -math.inf):
        with pytest.raises(UnreachableError, match='finite'):
            solve(linkage, bad, CONSTANT)
    with pytest.raises(UnreachableError, match='finite'):
        solve_many(linkage, np.array([0.0, math.nan]), CONSTANT)
    with pytest.raises(ValueError, match='branch'):
        solve(linkage, 0.0, CONSTANT, branch=0)


@pytest.mark.parametrize('name', sorted(GEOMETRIES))
def test_dense_sweep_is_finite_and_reachable_mask_agrees(name: str) -> None:
    """Solve never returns NaN or inf: it answers or raises, at every angle of a dense sweep."""
    linkage = GEOMETRIES[name]
    angles = np.linspace(-math.pi, math.pi, 2001)
    mask = reachable_mask(linkage, angles)
    for alpha, reachable in zip(angles[::20], mask[::20]):
        try:
            state = solve(linkage, float(alpha), VARIABLE)
        except UnreachableError:
            assert not reachable
            continue
        except DeadPointError:
            continue
        assert reachable
        for field_name in LinkageState.__dataclass_fields__:
            assert math.isfinite(getattr(state, field_name)), field_name


def test_the_librarys_public_names_keep_their_import_path():
    """``linkage_kinematics.kinematics`` was one module; its public names are still there."""
    for name in ('solve', 'solve_many', 'solve_pose', 'continued_branch', 'DeadPointError',
                 'loop_closure_residual', 'unwrap_near', 'reachable_mask'):
        assert getattr(library, name) is getattr(solver, name)
    for name in ('FourBar', 'preset', 'PRESETS', 'UnreachableError', 'GeometryError', 'TWO_PI'):
        assert getattr(library, name) is getattr(geometry, name)
    assert library.DriveLaw is DriveLaw
    assert set(library.__all__) <= set(dir(library))
    state = library.solve(library.preset('paper').geometry, 0.0, library.DriveLaw(2.0))
    assert state.omega_bc == pytest.approx(-6.667, abs=5e-4)  # the paper's Table 1, α = 0
