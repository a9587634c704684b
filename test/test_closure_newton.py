# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
loops.newton: each group closed per sample, against the 50-digit reference.

Positions within 1e-12 (rad or m) and velocities within 1e-12 relative along motions of every
mechanism of test/closure_robots.py, in both directions (measured actuators in; the ankle's
foot and the five-bar's first chain known, actuators out); approaching the five-bar's stretched
configuration within a few times κ·ε (positions) and κ²·ε (velocities), and refused just where
κ²·ε passes 1e-3; the refusals by reason; idle freedoms held over 100 000 samples; the
accelerations against differences of the reference's velocities.
"""

from __future__ import annotations

import math
import sys

from closure_reference import Reference
import closure_robots
from linkage_kinematics.loops.newton import plan_group
from linkage_kinematics.loops.refusals import CONDITION_LIMIT, Refusal, SampleRefused
from linkage_kinematics.loops.structure import GroupKind
from mpmath import mp, mpf
import pytest

EPSILON = sys.float_info.epsilon

# mechanism, known joints, group, amplitude and period (samples) of each known joint's
# motion about its value at the start (0, or the third element of ``CENTERS``)
MOTIONS = {
    'ankle': ('ankle', None, 0, (0.3, 0.25), (400, 270)),
    'ankle leg, foot known': ('ankle', ('ankle_pitch', 'ankle_roll'), 0, (0.4, 0.2), (400, 300)),
    'ankle right leg': ('ankle', ('ankle_pitch', 'ankle_roll'), 1, (0.4, 0.2), (400, 300)),
    'five-bar': ('five_bar', None, 0, (0.3, 0.3), (400, 330)),
    # the drawing's second chain is nearly stretched: a small motion keeps it in reach
    'five-bar inverse': ('five_bar', ('j1', 'j2'), 0, (0.05, 0.1), (400, 330)),
    'planar weld, a full turn': ('planar_weld', None, 0, None, (400,)),
    'rod with two balls': ('rod_two_balls', None, 0, (0.35,), (400,)),
    'collinear pins, a full turn': ('collinear_pins', None, 0, None, (400,)),
    'delta-like': ('delta_like', None, 0, (0.3, 0.3, 0.3), (400, 290, 350)),
}
# the rod's crank has a dead point 0.043 rad below its drawing: its motion is about 0.4 rad
CENTERS = {'rod with two balls': {'crank': 0.4}}


def known_at(case: str, step: int) -> tuple[list[float], list[float]]:
    """Return the known joints' values and rates (per sample) at ``step``."""
    _, known, _, amplitudes, periods = MOTIONS[case]
    centers = list(CENTERS.get(case, {}).values()) or [0.0] * len(periods)
    values, rates = [], []
    for k, (period, center) in enumerate(zip(periods, centers)):
        phase = 2.0 * math.pi * step / period
        if amplitudes is None:  # a crank turning at one turn per period
            values.append(phase)
            rates.append(2.0 * math.pi / period)
        else:
            values.append(center + amplitudes[k] * math.sin(phase + k))
            rates.append(amplitudes[k] * 2.0 * math.pi / period * math.cos(phase + k))
    return values, rates


def planned_for(case: str):
    name, known, place, _, _ = MOTIONS[case]
    start = dict(CENTERS.get(case, {}))
    if start:  # assembled at the motion's start
        start |= dict(zip((known or getattr(closure_robots, name)().measured),
                          known_at(case, 0)[0]))
    return closure_robots.plan(getattr(closure_robots, name)(), known, place=place, start=start)


def errors(planned, known, rates, state) -> tuple[float, float]:
    """Return the worst position error and the velocities' normwise relative error."""
    positions, velocities = closure_robots.reference_state(planned, known, rates,
                                                           state.positions)
    names = planned.structure.solved
    position_error = max(abs(float(positions[n]) - x) for n, x in zip(names, state.positions))
    size = max(abs(float(v)) for v in velocities.values())
    velocity_error = max(abs(float(velocities[n]) - v)
                         for n, v in zip(names, state.velocities)) / size
    return position_error, velocity_error


@pytest.mark.parametrize('case', list(MOTIONS))
def test_a_motion_is_closed_within_1e_12_of_the_reference(case):
    planned = planned_for(case)
    checked = 0
    for step in range(401):
        known, rates = known_at(case, step)
        state = planned.solver.solve(known, rates)
        assert all(map(math.isfinite, state.positions + state.velocities))
        if step % 100 == 50:
            position_error, velocity_error = errors(planned, known, rates, state)
            assert position_error <= 1e-12 and velocity_error <= 1e-12, (step, state)
            checked += 1
    assert checked == 4


@pytest.mark.parametrize('case', ['ankle', 'delta-like'])
def test_a_smooth_motion_is_predicted_to_second_order(case):
    """
    From the third sample on, the prediction has its second-order term: two iterations.

    (S − S_last) along the last change: Newton's first correction is some 1e-7 rad, not 1e-5,
    and the step after it is at rounding level, so most samples take two iterations (with the
    first-order prediction: three or more in at least 390 of these 399 samples).
    """
    planned = planned_for(case)
    iterations = [planned.solver.solve(*known_at(case, step)).iterations for step in range(401)]
    assert sum(count > 2 for count in iterations[2:]) <= 80


def stretched():
    """Return s (50 digits) where cranks at s and −s put their ends 0.5 m apart."""
    with mp.workdps(50):
        first, second = mp.radians(100), mp.radians(80)
        return mp.findroot(lambda s: mp.hypot(
            0.2 * mp.cos(first + s) - 0.15 - 0.2 * mp.cos(second - s),
            0.2 * mp.sin(first + s) - 0.2 * mp.sin(second - s)) - mpf('0.5'), 0.9)


def five_bar_near_stretched(kind: GroupKind) -> closure_robots.Planned:
    """Return the five-bar moved (cranks s, −s) to 1e-3 of its stretched configuration."""
    planned = closure_robots.plan(closure_robots.five_bar(), kind=kind)
    end = float(stretched()) - 1e-3
    for step in range(301):
        s = step / 300 * end
        planned.solver.solve([s, -s], [1.0, -1.0])
    return planned


@pytest.mark.parametrize('kind', [GroupKind.FIVE_BAR, GroupKind.NEWTON])
def test_near_a_singular_configuration_the_error_is_the_float_floor_until_refused(kind):
    planned = five_bar_near_stretched(kind)
    edge = stretched()
    for decade in range(4, 17):
        with mp.workdps(50):
            s = float(edge - mpf(10) ** -decade)
        try:
            state = planned.solver.solve([s, -s], [1.0, -1.0])
        except SampleRefused as refusal:
            assert refusal.reason is Refusal.SINGULAR
            assert decade >= 13  # κ ≈ 3.6e6 at 1e-13: κ²·ε > 1e-3
            continue
        assert decade <= 12 and state.conditioning <= CONDITION_LIMIT
        position_error, velocity_error = errors(planned, [s, -s], [1.0, -1.0], state)
        floor = state.conditioning * EPSILON
        assert position_error <= 1e-14 + 4.0 * floor
        assert velocity_error <= 1e-14 + 4.0 * floor * state.conditioning
        # a fold: det A vanishes as the square root of the distance, which the estimate uses
        true_distance = math.sqrt(2.0) * 10.0 ** -decade
        assert planned.solver.derivatives.singular_distance([1.0, -1.0]) == pytest.approx(
            true_distance, rel=0.02)


def test_a_sample_no_assembly_reaches_is_refused_and_the_state_kept():
    planned = five_bar_near_stretched(GroupKind.FIVE_BAR)
    fresh = five_bar_near_stretched(GroupKind.FIVE_BAR)
    for known in ([1.2, -1.2], [math.nan, 0.0], [0.5, math.inf]):
        with pytest.raises(SampleRefused) as refused:
            planned.solver.solve(known, [1.0, -1.0])
        assert refused.value.reason is Refusal.UNREACHABLE
        assert str(refused.value).startswith('group tip: no assembly reaches the known joints (')
    assert planned.solver.solve([0.8, -0.8], [1.0, -1.0]) == fresh.solver.solve(
        [0.8, -0.8], [1.0, -1.0])
    newton = five_bar_near_stretched(GroupKind.NEWTON)
    with pytest.raises(SampleRefused, match='no assembly reaches') as refused:
        newton.solver.solve([1.2, -1.2], [1.0, -1.0])


def test_a_long_step_is_followed_on_its_assembly_where_newton_would_jump_to_the_mirror():
    # Newton from the drawing straight to these cranks (0.65 and 0.77 rad away) lands on the
    # mirror assembly; the continuation follows the change in substeps and stays on the
    # drawing's, where the closed form keeps its branch
    newton = closure_robots.plan(closure_robots.five_bar(), kind=GroupKind.NEWTON)
    closed = closure_robots.plan(closure_robots.five_bar())
    known = [-0.6544864668008885, 0.7674126124716718]
    state = newton.solver.solve(known, [0.3, 0.1])
    assert state.iterations > 10 and newton.solver.orientation == 1
    expected = closed.solver.solve(known, [0.3, 0.1])
    position_error, velocity_error = errors(newton, known, [0.3, 0.1], state)
    assert position_error <= 1e-14 and velocity_error <= 1e-14
    # the same pose; the continuation turned the second joint the long way round, as the
    # motion from the drawing to these cranks does, the closed form the short way
    assert [math.remainder(a - b, 2.0 * math.pi) for a, b in
            zip(state.positions, expected.positions)] == pytest.approx([0.0, 0.0], abs=1e-14)
    assert state.velocities == pytest.approx(expected.velocities, abs=1e-14)


def test_idle_freedoms_stay_put_over_100_000_samples_of_a_periodic_motion():
    planned = closure_robots.plan(closure_robots.collinear_pins())
    solver, period = planned.solver, 1000
    (idle,) = planned.structure.idle
    reference = planned.assembly.values[1:]
    first_period = []
    for step in range(100 * period + 1):
        phase = 2.0 * math.pi * step / period
        state = solver.solve([1.2 * math.sin(phase)], [1.2 * math.cos(phase)])
        if step < period:
            first_period.append(state.positions)
        elif step % 997 == 0 or step % period == 0:
            # the same crank angle gives the same joints, period after period
            assert state.positions == pytest.approx(first_period[step % period], abs=1e-13)
        held = math.fsum(d * (q - r) for d, q, r in zip(idle.direction, state.positions,
                                                        reference))
        assert abs(held) <= 1e-15
    assert state.positions == pytest.approx(first_period[0], abs=1e-13)


def test_an_idle_link_keeps_its_equation_while_the_crank_turns_whole_turns():
    # A crank–rocker's coupler turns once backwards about the crank per crank turn; the two
    # collinear pins share that turn, each by half, and their idle difference stays.
    planned = closure_robots.plan(closure_robots.collinear_pins())
    start = planned.assembly.values[1:3]
    for step in range(3 * 400 + 1):
        state = planned.solver.solve([2.0 * math.pi * (step % 400) / 400], [0.0])
    # (each joint now near −3π: its rounding is 4.4e-16)
    assert state.positions[0] - state.positions[1] == pytest.approx(start[0] - start[1],
                                                                    abs=4e-15)
    assert state.positions[0] + state.positions[1] == pytest.approx(
        start[0] + start[1] - 3 * 2.0 * math.pi, abs=1e-13)


@pytest.mark.parametrize('case', ['ankle', 'ankle leg, foot known', 'five-bar', 'delta-like'])
def test_accelerations_are_the_rate_of_the_references_velocities(case):
    planned = planned_for(case)
    for step in range(61):
        known, rates = known_at(case, step)
        state = planned.solver.solve(known, rates)
    accelerations = [0.7 * (k + 1) for k in range(len(known))]
    result = planned.solver.derivatives.accelerations(rates, accelerations)
    mechanism = planned.mechanism
    structure = planned.structure
    reference = Reference(mechanism.urdf, planned.group.closures,
                          mechanism.reference_overrides)
    unknown = list(structure.solved)
    anchor = dict(zip(planned.tree.names, planned.assembly.values))
    basis = reference.idle_basis(anchor, unknown)
    h = mpf('1e-12')
    with mp.workdps(50):
        velocities = []
        for sign in (1, -1):
            moved = {name: mpf(k) + sign * h * v + h * h / 2 * a for name, k, v, a in
                     zip(structure.known, known, rates, accelerations)}
            moved_rates = {name: mpf(v) + sign * h * a for name, v, a in
                           zip(structure.known, rates, accelerations)}
            positions = reference.solve(moved, dict(zip(unknown, state.positions)), unknown,
                                        (basis, anchor))
            at = {**moved, **positions}
            velocities.append(reference.velocities(at, moved_rates, unknown, basis))
        exact = [(velocities[0][n] - velocities[1][n]) / (2 * h) for n in unknown]
    size = max(abs(float(x)) for x in exact)
    assert max(abs(float(x) - y) for x, y in zip(exact, result)) <= 1e-12 * size


def test_plan_group_builds_the_solver_at_the_first_sample_or_says_why_not():
    mechanism = closure_robots.ankle()
    tree = closure_robots.KinematicTree(closure_robots.read_urdf(mechanism.urdf))
    (group,) = closure_robots.closure_groups(tree, mechanism.closures, mechanism.measured)
    start = [0.0] * len(tree.names)
    start[tree.index['motor_left']], start[tree.index['motor_right']] = 0.2, -0.1
    planned = plan_group(tree, group, start)
    assert planned.problem is None and planned.kind is GroupKind.NEWTON
    assert [planned.assembly.values[tree.index[n]] for n in ('motor_left', 'motor_right')] == [
        0.2, -0.1]
    state = planned.solver.solve([0.2, -0.1], [0.0, 0.0])
    assert state.positions == pytest.approx(
        [planned.assembly.values[tree.index[n]] for n in planned.structure.solved], abs=1e-15)
    five_bar = closure_robots.five_bar()
    tree = closure_robots.KinematicTree(closure_robots.read_urdf(five_bar.urdf))
    (group,) = closure_robots.closure_groups(tree, five_bar.closures, ['j1'])
    refused = plan_group(tree, group, [0.0] * 4, hold_known=False)
    assert refused.solver is None and 'under-determined' in refused.problem


def test_the_sensitivity_maps_known_velocities_to_solved_ones_and_efforts_back():
    planned = closure_robots.plan(closure_robots.ankle(), ('ankle_pitch', 'ankle_roll'))
    state = planned.solver.solve([0.2, -0.1], [0.7, -0.4])
    sensitivity = planned.solver.derivatives.sensitivity()
    assert [sum(s * v for s, v in zip(row, [0.7, -0.4])) for row in sensitivity] == \
        pytest.approx(state.velocities, abs=1e-15)
    # power balance: a motor torque τ_m does the work τ_m·ṁ = (Sᵀ·τ_m)·(pitch, roll rates)
    torque = 3.0
    efforts = [torque * row for row in sensitivity[0]]
    assert efforts[0] * 0.7 + efforts[1] * -0.4 == pytest.approx(torque * state.velocities[0],
                                                                 rel=1e-15)
