# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
loops.closed_forms: each closed form against the same geometry solved at 50 digits.

Three spheres (a delta's forward kinematics), the circles of a planar triangle near tangency,
a crank or a slide onto a sphere (a crank–rod–ball leg's inverse), a universal joint's angles
that point its rod and a ball of three turns' angles that make a rotation, each with both
branches.
"""

from __future__ import annotations

import math

from linkage_kinematics.loops.closed_forms import (
    circle_intersection,
    crank_to_sphere,
    OutOfReach,
    slide_to_sphere,
    three_spheres,
    turn_to,
    TurnChain,
)
from linkage_kinematics.loops.spatial import add, apply, axis_rotation, norm, scale, subtract
from mpmath import mp, mpf
import pytest


def distance_50(a, b) -> float:
    with mp.workdps(50):
        return float(mp.sqrt(sum((mpf(x) - mpf(y)) ** 2 for x, y in zip(a, b))))


def test_three_spheres_meet_where_a_deltas_platform_is():
    # a delta's three elbows (arms of 0.1 m at 0.1 m from the centre, raised by 0.2, 0.1 and
    # −0.1 rad), its rods 0.25 m, the platform's attachments at 0.03 m shifted in
    centers = []
    for leg, lift in enumerate((0.2, 0.1, -0.1)):
        heading = 2.0 * math.pi * leg / 3.0
        reach = 0.1 + 0.1 * math.cos(lift) - 0.03
        centers.append((reach * math.cos(heading), reach * math.sin(heading),
                        0.1 * math.sin(lift)))
    for branch in (1, -1):
        point = three_spheres(tuple(centers), (0.25, 0.25, 0.25), branch)
        assert [distance_50(point, c) for c in centers] == pytest.approx([0.25] * 3, abs=1e-16)
        # the centres turn counterclockwise seen from above: +1 is above them, −1 the
        # platform hanging below
        assert (point[2] > 0.0) == (branch == 1)
    with pytest.raises(OutOfReach, match='the three spheres do not meet'):
        three_spheres(tuple(centers), (0.05, 0.05, 0.05), 1)


@pytest.mark.parametrize('gap', [1e-2, 1e-8, 1e-14, 0.0])
def test_circles_near_tangency_lose_no_more_than_their_conditioning(gap):
    p, q = (0.1, 0.2, 0.0), (0.4, -0.1, 0.0)
    distance = math.dist(p, q)
    radius_p = 0.25
    radius_q = distance - radius_p + gap
    for branch in (1, -1):
        point = circle_intersection(p, q, radius_p, radius_q, (0.0, 0.0, 1.0), branch)
        # the height (√gap) carries the rounding of the lengths magnified by 1/√gap, but along
        # the circles: the distances stay exact to rounding
        assert distance_50(point, p) == pytest.approx(radius_p, abs=4e-16)
        assert distance_50(point, q) == pytest.approx(radius_q, abs=4e-16)
    with pytest.raises(OutOfReach, match='the circles do not meet'):
        circle_intersection(p, q, radius_p, distance - radius_p - 1e-6, (0.0, 0.0, 1.0), 1)


def test_a_crank_and_a_slide_put_a_point_on_a_sphere_on_either_branch():
    origin, axis = (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)
    point, center = (-0.045, 0.035, 0.0), (-0.05, 0.04, -0.22)
    for branch in (1, -1):
        turn = crank_to_sphere(origin, axis, point, center, 0.23, branch)
        moved = apply(axis_rotation(axis, turn), point)
        assert distance_50(moved, center) == pytest.approx(0.23, abs=1e-16)
        travel = slide_to_sphere(point, (0.0, 0.0, -1.0), center, 0.23, branch)
        assert distance_50(add(point, scale(travel, (0.0, 0.0, -1.0))), center) == \
            pytest.approx(0.23, abs=1e-16)
    first, second = (crank_to_sphere(origin, axis, point, center, 0.23, b) for b in (1, -1))
    assert first != second
    with pytest.raises(OutOfReach):
        crank_to_sphere(origin, axis, point, center, 0.5, 1)


def test_turn_to_carries_a_point_onto_its_target_about_an_axis():
    axis, origin = (0.0, 0.0, 1.0), (0.1, 0.2, 0.3)
    point = (0.4, 0.2, 0.5)
    target = add(origin, apply(axis_rotation(axis, 2.5), subtract(point, origin)))
    assert turn_to(axis, origin, point, target) == pytest.approx(2.5, abs=1e-15)
    assert norm(subtract(target, origin)) == pytest.approx(norm(subtract(point, origin)))


def rotation_50(origins, axes, angles):
    """Return O₁·R(a₁, θ₁)·O₂·R(a₂, θ₂)·… at 50 digits (Rodrigues), as an mp matrix."""
    with mp.workdps(50):
        result = mp.eye(3)
        for origin, axis, angle in zip(origins, axes, angles):
            x, y, z = (mpf(v) for v in axis)
            k = mp.matrix([[0, -z, y], [z, 0, -x], [-y, x, 0]])
            turn = mp.eye(3) + mp.sin(mpf(angle)) * k + (1 - mp.cos(mpf(angle))) * k * k
            result = result * mp.matrix([[mpf(origin[3 * i + j]) for j in range(3)]
                                         for i in range(3)]) * turn
        return result


def test_a_ball_of_three_turns_makes_a_rotation_with_either_angle_triple():
    # Battobot's ball (x, y, z about its joint frame, turned in its link), and a ball whose
    # axes are not perpendicular: both triples make the rotation to rounding, one of them
    # with the angles it was made with
    tilted = axis_rotation((0.6, 0.0, 0.8), 0.4)
    identity = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
    for origins, axes in (((tilted, identity, identity),
                           ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))),
                          ((identity, tilted, identity),
                           ((0.0, 0.0, 1.0), (0.6, 0.8, 0.0), (1.0, 0.0, 0.0)))):
        for angles in ((0.3, -1.2, 2.5), (-2.0, 0.7, -0.1), (1.0, 1.5, 0.2)):
            target = rotation_50(origins, axes, angles)
            rotation = tuple(float(target[i, j]) for i in range(3) for j in range(3))
            ball = TurnChain(origins, axes)
            images = apply(rotation, axes[2]), apply(rotation, ball.across)
            triples = [ball.ball(*images, branch) for branch in (1, -1)]
            for found in triples:
                made = rotation_50(origins, axes, found)
                assert max(abs(float(made[i, j] - target[i, j])) for i in range(3)
                           for j in range(3)) <= 2e-15
            apart = [max(abs(math.remainder(a - b, 2.0 * math.pi))
                         for a, b in zip(found, angles)) for found in triples]
            # (1.5 rad is near the gimbal lock: the angles carry some 14 times the rounding)
            assert min(apart) <= 2e-14 and max(apart) > 0.1
