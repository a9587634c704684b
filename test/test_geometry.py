# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""Geometry validation, presets and reachability."""

from __future__ import annotations

import math

from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import (
    format_interval,
    FourBar,
    GeometryError,
    preset,
    PRESETS,
    Reachability,
    UnreachableError,
    wrap_angle,
)
from linkage_kinematics.kinematics.solver import solve
import pytest
from reference import reference_singular_angles


@pytest.mark.parametrize('name', ['crank_length', 'coupler_length', 'rocker_length'])
@pytest.mark.parametrize(
    'bad', [0.0, -0.3, math.nan, math.inf, -math.inf, '0.3', None, True, 1e308, 1e-300]
)
def test_bad_lengths_are_rejected_by_name(name: str, bad) -> None:
    lengths = {'crank_length': 0.3, 'coupler_length': 1.0, 'rocker_length': 0.3}
    lengths[name] = bad
    with pytest.raises(GeometryError, match=name):
        FourBar(**lengths, ground_x=1.3)


@pytest.mark.parametrize('name', ['ground_x', 'ground_y'])
@pytest.mark.parametrize('bad', [math.nan, math.inf, -math.inf, '1.3', True, 1e308, -1e308])
def test_bad_ground_pivot_is_rejected_by_name(name: str, bad) -> None:
    pivot = {'ground_x': 1.3, 'ground_y': 0.0}
    pivot[name] = bad
    with pytest.raises(GeometryError, match=name):
        FourBar(0.3, 1.0, 0.3, **pivot)


def test_a_loop_that_never_closes_is_rejected() -> None:
    # |C − A| ∈ [2.7, 3.3] m but AB + BC = 1.3 m
    with pytest.raises(GeometryError, match='cannot close at any crank angle'):
        FourBar(0.3, 1.0, 0.3, 3.0, 0.0)
    # |C − A| ∈ [0.7, 1.3] m but |AB − BC| = 2.0 m
    with pytest.raises(GeometryError, match='cannot close at any crank angle'):
        FourBar(0.3, 2.5, 0.5, 1.0, 0.0)


def test_coincident_pivots() -> None:
    """With O = C, |C − A| = OA always: the loop closes everywhere or nowhere."""
    turning = FourBar(0.5, 1.0, 0.8, 0.0, 0.0)
    assert turning.reachability.full_rotation
    assert turning.reachability.change_points == ()
    state = solve(turning, 1.0, DriveLaw(2.0))
    # B keeps its distance from O = C: the whole linkage turns rigidly with the crank
    assert state.omega_ab == pytest.approx(2.0, rel=1e-12)
    assert state.omega_bc == pytest.approx(2.0, rel=1e-12)
    for lengths in ((0.5, 1.0, 0.3), (0.5, 0.2, 0.3), (0.5, 0.3, 0.8)):
        with pytest.raises(GeometryError, match='O and C coincident'):
            FourBar(*lengths, 0.0, 0.0)


def test_presets() -> None:
    paper = preset('paper')
    assert paper.geometry == FourBar(0.3, math.sqrt(1.09), 0.3, 1.3, 0.0)
    assert paper.drive_sign == 1.0
    assert not paper.geometry.is_grashof
    assert preset('paper_full_turn').drive_sign == -1.0
    assert preset('paper_full_turn').geometry.ground_x == pytest.approx(math.sqrt(0.73))
    assert preset('grashof_crank_rocker').geometry.is_grashof
    with pytest.raises(GeometryError, match='known presets: grashof_crank_rocker, paper, '):
        preset('nope')


@pytest.mark.parametrize('name', sorted(PRESETS))
def test_preset_singular_angles_match_reference(name: str) -> None:
    reachability = PRESETS[name].geometry.reachability
    found = sorted(wrap_angle(angle) for angle in reachability.dead_points)
    expected = [float(angle) for angle in reference_singular_angles(PRESETS[name].geometry)]
    assert found == pytest.approx(expected, abs=1e-14)


def test_reachability_messages() -> None:
    paper = PRESETS['paper'].geometry.reachability
    assert paper.describe() == '[-1.941°, 181.941°]'
    assert PRESETS['grashof_crank_rocker'].geometry.reachability.describe() == (
        'all crank angles (full rotation)'
    )
    assert format_interval((-math.pi / 2, math.pi)) == '[-90.000°, 180.000°]'
    with pytest.raises(UnreachableError, match=r'α = -10\.000000° is not reachable.*'
                                               r'\[-1\.941°, 181\.941°\] \(mod 360°\)'):
        paper.require(math.radians(-10.0))
    # the same angle a whole number of turns away is treated alike
    assert paper.require(math.radians(45.0 + 720.0)) == paper.intervals[0]
    assert paper.interval_containing(math.radians(185.0)) is None


def test_dead_point_distance() -> None:
    paper = PRESETS['paper'].geometry.reachability
    assert paper.dead_point_distance(0.0) == pytest.approx(-paper.dead_points[0], rel=1e-15)
    assert paper.dead_point_distance(paper.dead_points[1]) == 0.0
    assert paper.change_point_distance(0.0) is None
    assert PRESETS['grashof_crank_rocker'].geometry.reachability.dead_point_distance(1.0) is None


def test_change_points_are_not_dead_points() -> None:
    """
    Return a parallelogram has change points and no dead points.

    Distances and the first dead point on the way say so, which is what lets a motion run through
    its change points.
    """
    parallelogram = FourBar(0.3, 1.0, 0.3, 1.0, 0.0).reachability
    assert parallelogram.dead_point_distance(1.5) is None
    assert parallelogram.change_point_distance(1.5) == pytest.approx(math.pi / 2 - 1.5, abs=1e-15)
    assert parallelogram.change_point_distance(1.5 + 2 * math.pi * 3) == pytest.approx(
        math.pi / 2 - 1.5, abs=1e-13)
    assert parallelogram.first_dead_point(0.0, 2 * math.pi * 1000) is None


def test_a_loop_joints_reachability_names_the_joint() -> None:
    """The same class holds a loop's known joint: an angle (rad) or a displacement (m)."""
    revolute = Reachability(((-1.0, 2.0),), (-1.0, 2.0), (), joint=3)
    assert revolute.describe() == '[-57.295780°, 114.591559°] (mod 360°)'
    with pytest.raises(UnreachableError, match=r'^joint 3 at 143\.239448783° is not reachable: '
                                               r'the loop closes only for \[-57\.295780°, '
                                               r'114\.591559°\] \(mod 360°\)$'):
        revolute.require(2.5)
    assert revolute.contains(2.0 + 4 * math.pi) and not revolute.contains(math.inf)
    assert Reachability(((-math.pi, math.pi),), (), (), joint=1).describe() == (
        'all angles (full rotation)')


def test_a_displacements_reachability_does_not_wrap() -> None:
    slide = Reachability(((-0.5, -0.1), (0.1, 0.5)), (-0.5, -0.1, 0.1, 0.5), (), periodic=False,
                         joint=2)
    assert not slide.full_rotation
    assert slide.describe() == '[-0.5 m, -0.1 m] and [0.1 m, 0.5 m]'
    with pytest.raises(UnreachableError, match=r'^joint 2 at 0\.0 m is not reachable: the loop '
                                               r'closes only for \[-0\.5 m, -0\.1 m\] and '
                                               r'\[0\.1 m, 0\.5 m\]$'):
        slide.require(0.0)
    assert slide.require(0.3) == (0.1, 0.5)
    assert slide.interval_containing(0.3 + 2 * math.pi) is None
    assert slide.contains(-0.5) and not slide.contains(0.0) and not slide.contains(math.nan)
    assert slide.dead_point_distance(0.0) == pytest.approx(0.1, abs=1e-17)
    assert slide.dead_point_distance(0.3 + 2 * math.pi) == pytest.approx(2 * math.pi - 0.2)
    # the dead points ahead on the way, none behind it and none a turn later
    assert slide.first_dead_point(0.0, 0.4) == pytest.approx(0.1, abs=1e-17)
    assert slide.first_dead_point(0.2, -0.2) == pytest.approx(0.1, abs=1e-17)
    assert slide.first_dead_point(0.2, 0.5) == pytest.approx(0.5, abs=1e-17)
    assert slide.first_dead_point(0.2, 0.4) is None
    assert slide.first_dead_point(0.2, 0.4 + 2 * math.pi) == pytest.approx(0.5, abs=1e-17)


def test_first_dead_point_on_the_way() -> None:
    paper = PRESETS['paper'].geometry.reachability
    low, high = paper.dead_points
    # counterclockwise from 0 the crank meets the 181.94° dead point, clockwise the −1.94° one
    assert paper.first_dead_point(0.0, math.radians(200.0)) == pytest.approx(high, abs=1e-15)
    assert paper.first_dead_point(0.0, math.radians(-10.0)) == pytest.approx(low, abs=1e-15)
    assert paper.first_dead_point(0.0, math.radians(90.0)) is None
    assert paper.first_dead_point(0.0, high) == pytest.approx(high, abs=1e-15)
    # unwrapped: from 720° on, the same dead point two turns later
    assert paper.first_dead_point(4 * math.pi, 4 * math.pi + math.radians(200.0)) == pytest.approx(
        high + 4 * math.pi, abs=1e-13)


def test_change_points_of_equality_linkages() -> None:
    parallelogram = FourBar(0.3, 1.3, 0.3, 1.3, 0.0)
    assert parallelogram.is_grashof
    assert parallelogram.reachability.full_rotation
    assert sorted(parallelogram.reachability.change_points) == pytest.approx(
        [-math.pi / 2, math.pi / 2], abs=1e-15
    )
    kite = FourBar(0.4, 0.4, 1.0, 1.0, 0.0)
    assert sorted(kite.reachability.change_points) == pytest.approx(
        [-math.pi / 2, math.pi / 2], abs=1e-15
    )
    # a folding kite: the crank rocks between two dead points and passes one change point
    folding = FourBar(1.0, 0.4, 0.4, 1.0, 0.0)
    assert len(folding.reachability.dead_points) == 2
    assert folding.reachability.change_points == pytest.approx((math.pi / 2,), abs=1e-15)


def test_scaled() -> None:
    paper = PRESETS['paper'].geometry
    small = paper.scaled(1e-6)
    assert small.coupler_length == paper.coupler_length * 1e-6
    assert small.reachability.intervals[0] == pytest.approx(
        paper.reachability.intervals[0], abs=1e-15
    )


def test_wrap_angle() -> None:
    assert wrap_angle(math.pi) == math.pi
    assert wrap_angle(-math.pi) == math.pi
    assert wrap_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)
    assert wrap_angle(0.25 + 2 * math.pi * 1000) == pytest.approx(0.25, abs=1e-12)
