# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Independent high-precision reference for planar loops of four joints (mpmath, 50 digits).

Why it is independent of ``kinematics.planar_loop`` and ``kinematics.prismatic_loop``:

* Positions. The library has one closed form per case (Heron's triangle, a circle meeting a
  line, the distance of two pivots) with factored discriminants. Here the loop is an open chain
  joint 0 → 1 → 2 → 3 → back to joint 0, and its closure (the chain's end at the origin, two
  equations) is solved for the two unknown coordinates by Newton's method at 50 digits, from a
  nearby guess (the library's float answer), with the chain's own Jacobian: turning revolute
  joint j moves the end by (end − J_j)⊥, sliding prismatic joint j by its slide direction.
  No case distinction, no discriminant.
* Rates. The same Jacobian: J_u·u̇ = −J_k·k̇ (u the unknown coordinates, k the known one), a
  2×2 linear solve at 50 digits; the cut pin's rate closes the sum of the angle rates.
* Dead points. Roots of a scalar distance condition of the case, written from the geometry
  (|J_c − J_b| = L_a ± L_c, the far pivot's distance from the slide line = its circle's radius,
  the distance of the pivots next to the slide = the slide line's offset), found by
  ``mpmath.findroot`` from the library's float as a guess.
* The input floor (``input_floor``) is the change of the exact answer between the float value
  and its neighbouring floats: what a one-ulp change of the input alone does.

The slide direction is taken as exactly ``slide``/|``slide``| (the library's convention), and
every other input is the exact float the library receives.
"""

from __future__ import annotations

import math

from linkage_kinematics.kinematics.planar_loop import JointKind, PlanarLoop
from mpmath import mp, mpf

DIGITS = 50


def _rotate(angle: mpf, vector: tuple[mpf, mpf]) -> tuple[mpf, mpf]:
    cosine, sine = mp.cos(angle), mp.sin(angle)
    return cosine * vector[0] - sine * vector[1], sine * vector[0] + cosine * vector[1]


def _slide(loop: PlanarLoop) -> tuple[mpf, mpf]:
    norm = mp.sqrt(mpf(loop.slide[0]) ** 2 + mpf(loop.slide[1]) ** 2)
    return mpf(loop.slide[0]) / norm, mpf(loop.slide[1]) / norm


def chain(loop: PlanarLoop, coordinates: list[mpf]) -> tuple[list, list, list]:
    """Return the joints' points, the open chain's end and d(end)/d(coordinate j), j = 1..3."""
    points = [(mpf(0), mpf(0))]
    angles = [mpf(0)]
    directions = {}
    for joint in (1, 2, 3):
        link = tuple(mpf(x) for x in loop.links[joint - 1])
        step = _rotate(angles[-1], link)
        theta = angles[-1]
        if loop.kinds[joint] is JointKind.PRISMATIC:
            direction = _rotate(theta, _slide(loop))
            directions[joint] = direction
            step = (step[0] + coordinates[joint] * direction[0],
                    step[1] + coordinates[joint] * direction[1])
        else:
            theta = theta + coordinates[joint]
        points.append((points[-1][0] + step[0], points[-1][1] + step[1]))
        angles.append(theta)
    last = _rotate(angles[3], tuple(mpf(x) for x in loop.links[3]))
    end = (points[3][0] + last[0], points[3][1] + last[1])
    columns = []
    for joint in (1, 2, 3):
        if joint in directions:
            columns.append(directions[joint])
        else:
            columns.append((-(end[1] - points[joint][1]), end[0] - points[joint][0]))
    return points, end, columns


def _solve_2x2(first: tuple[mpf, mpf], second: tuple[mpf, mpf],
               right: tuple[mpf, mpf]) -> tuple[mpf, mpf]:
    """Solve [first second]·x = right (columns) by Cramer's rule at the working precision."""
    determinant = first[0] * second[1] - first[1] * second[0]
    return ((right[0] * second[1] - right[1] * second[0]) / determinant,
            (first[0] * right[1] - first[1] * right[0]) / determinant)


def reference_state(loop: PlanarLoop, known: int, value: float, rate: float,
                    guess: tuple[float, ...]) -> tuple[list[mpf], list[mpf]]:
    """
    Return the exact coordinates and rates of joints 0..3 (mpf) with joint ``known`` at ``value``.

    Newton's method from ``guess`` (coordinates of joints 0..3) on the chain's closure.
    """
    with mp.workdps(DIGITS):
        unknown = [joint for joint in (1, 2, 3) if joint != known]
        coordinates = [mpf(x) for x in guess]
        coordinates[known] = mpf(value)
        for _ in range(100):
            _, end, columns = chain(loop, coordinates)
            step = _solve_2x2(columns[unknown[0] - 1], columns[unknown[1] - 1],
                              (-end[0], -end[1]))
            coordinates[unknown[0]] += step[0]
            coordinates[unknown[1]] += step[1]
            # Near a change point the Jacobian is nearly singular and the last steps are the
            # 50-digit rounding divided by its determinant: 1e-35 leaves 1e-19 of room there.
            if max(abs(step[0]), abs(step[1])) < mpf(10) ** -35:
                break
        else:
            raise ValueError('reference: Newton did not converge')
        _, end, columns = chain(loop, coordinates)
        assert max(abs(end[0]), abs(end[1])) < mpf(10) ** (10 - DIGITS)
        known_column = columns[known - 1]
        unknown_rates = _solve_2x2(columns[unknown[0] - 1], columns[unknown[1] - 1],
                                   (-known_column[0] * rate, -known_column[1] * rate))
        rates = [mpf(0)] * 4
        rates[known] = mpf(rate)
        rates[unknown[0]], rates[unknown[1]] = unknown_rates
        revolute = [joint for joint in (1, 2, 3) if loop.kinds[joint] is JointKind.REVOLUTE]
        coordinates[0] = -sum(coordinates[joint] for joint in revolute)
        rates[0] = -sum(rates[joint] for joint in revolute)
        return coordinates, rates


def errors(loop: PlanarLoop, coordinates: tuple[float, ...], rates: tuple[float, ...],
           reference: tuple[list[mpf], list[mpf]]) -> tuple[float, float]:
    """
    Return the coordinates' error (rad or m, the worst joint) and the rates' normwise one.

    Angles are compared modulo 2π; rates relative to the largest reference rate.
    """
    with mp.workdps(DIGITS):
        exact_coordinates, exact_rates = reference
        worst = mpf(0)
        for joint in range(4):
            gap = mpf(coordinates[joint]) - exact_coordinates[joint]
            if loop.kinds[joint] is JointKind.REVOLUTE:
                gap -= 2 * mp.pi * mp.nint(gap / (2 * mp.pi))
            worst = max(worst, abs(gap))
        scale = max(abs(x) for x in exact_rates)
        rate_error = max(abs(mpf(rates[j]) - exact_rates[j]) for j in range(4)) / scale
        return float(worst), float(rate_error)


def input_floor(loop: PlanarLoop, known: int, value: float, rate: float,
                guess: tuple[float, ...]) -> tuple[float, float]:
    """Return how far the exact answer moves between ``value`` and its neighbouring floats."""
    exact = reference_state(loop, known, value, rate, guess)
    floors = []
    for neighbour in (math.nextafter(value, -math.inf), math.nextafter(value, math.inf)):
        try:
            moved = reference_state(loop, known, neighbour, rate, guess)
        except (ValueError, ZeroDivisionError, AssertionError):
            continue  # past a dead point: the neighbour has no answer
        floors.append(_exact_gap(moved, exact))
    return tuple(max(floor[i] for floor in floors) for i in (0, 1))


def _exact_gap(moved: tuple[list, list], exact: tuple[list, list]) -> tuple[float, float]:
    """Return the difference of two exact answers' coordinates and rates, as ``errors`` does."""
    with mp.workdps(DIGITS):
        worst = max(abs(moved[0][j] - exact[0][j]) for j in range(4))
        scale = max(abs(x) for x in exact[1])
        return float(worst), float(max(abs(moved[1][j] - exact[1][j]) for j in range(4)) / scale)


def reference_dead_point(loop: PlanarLoop, known: int, guess: float) -> mpf:
    """
    Return the exact dead point of joint ``known`` nearest ``guess``.

    A four-bar: joints known + 1 and known − 1 are L_{k+1} ± L_{k+2} apart (the two far links
    collinear). With a slide, the known joint is the slide: |J_c − J_b| = L_a ± L_c. Next to it:
    the far pivot's circle touches the slide line (its centre's distance from the line = the
    radius). Opposite: |J_c − J_b| equals the slide line's distance from J_b.
    """
    if JointKind.PRISMATIC not in loop.kinds:
        return _four_bar_dead_point(loop, known, guess)
    p = loop.kinds.index(JointKind.PRISMATIC)
    with mp.workdps(DIGITS):
        slide = _slide(loop)
        links = [tuple(mpf(x) for x in link) for link in loop.links]
        m = (links[(p - 1) % 4][0] + links[p][0], links[(p - 1) % 4][1] + links[p][1])
        link_a, link_c = links[(p - 2) % 4], links[(p + 1) % 4]
        length_a, length_c = mp.hypot(*link_a), mp.hypot(*link_c)
        offset = m[0] * slide[1] - m[1] * slide[0]

        def cross(vector: tuple[mpf, mpf]) -> mpf:
            return vector[0] * slide[1] - vector[1] * slide[0]

        if known == p:
            def distance(delta: mpf) -> mpf:
                return mp.hypot(m[0] + delta * slide[0], m[1] + delta * slide[1])

            # the triangle stretched or folded flat, whichever the guess is nearer
            reach = min((length_a + length_c, abs(length_a - length_c)),
                        key=lambda length: abs(distance(mpf(guess)) - length))

            def condition(delta: mpf) -> mpf:
                return distance(delta) - reach
        elif (known - p) % 4 == 2:
            def condition(angle: mpf) -> mpf:
                rotated = _rotate(angle, link_a)
                return mp.hypot(link_c[0] + rotated[0], link_c[1] + rotated[1]) - abs(offset)
        else:
            sense, near, radius = ((1, link_c, length_a) if (known - p) % 4 == 1
                                   else (-1, link_a, length_c))

            def condition(angle: mpf) -> mpf:
                distance = abs(offset + cross(_rotate(sense * angle, near)))
                return distance - radius
        return mp.findroot(condition, mpf(guess), tol=mpf(10) ** (6 - 2 * DIGITS))


def _four_bar_dead_point(loop: PlanarLoop, known: int, guess: float) -> mpf:
    with mp.workdps(DIGITS):
        links = [tuple(mpf(x) for x in link) for link in loop.links]
        far = (mp.hypot(*links[(known + 1) % 4]), mp.hypot(*links[(known + 2) % 4]))

        def distance(angle: mpf) -> mpf:
            # joint known + 1 relative to joint known − 1, in body known − 1's frame
            crank = _rotate(angle, links[known])
            return mp.hypot(links[known - 1][0] + crank[0], links[known - 1][1] + crank[1])

        reach = min((far[0] + far[1], abs(far[0] - far[1])),
                    key=lambda length: abs(distance(mpf(guess)) - length))
        return mp.findroot(lambda angle: distance(angle) - reach, mpf(guess),
                           tol=mpf(10) ** (6 - 2 * DIGITS))
