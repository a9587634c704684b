# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Closed forms of the planar loop with one prismatic joint (RRRP): slider-cranks, cylinders.

Names (indices mod 4, p the prismatic joint): J_b = joint p − 1, J_c = joint p + 1 and
J_a = joint p + 2 are the three revolute pivots. Bodies p − 1 and p never turn relative to each
other, and everything is written in body p − 1's frame with J_b at the origin:

* w = J_c − J_b = m + δ·ŝ, m = links[p − 1] + links[p]. Along and across the slide:
  w = t·ŝ − e·ŝ⊥ with t = δ + m·ŝ and e = m × ŝ (the slide line's signed offset from J_b).
* a = J_b − J_a = R(ψ_a)·links[p − 2], c = J_a − J_c = R(ψ_c)·links[p + 1], ψ the angles of
  bodies p − 2 and p + 1 relative to body p − 1; L_a = |links[p − 2]|, L_c = |links[p + 1]|.
  Closure w + c + a = 0, and the coordinates are δ_p = δ, φ_{p+1} = ψ_c,
  φ_{p+2} = ψ_a − ψ_c, φ_{p−1} = −ψ_a.

The cases, by the known joint:

* ``SLIDE`` (δ known): the triangle J_b J_c J_a has all sides known (|w|, L_a, L_c): J_a by
  Heron's formula, 4·|w|²·h² = P₊·P₋, P₊ = (L_a + L_c)² − |w|², P₋ = |w|² − (L_a − L_c)².
  Each is a quadratic in δ, written as ∓(δ − δ₁)·(δ − δ₂) with its roots (the dead points, where
  the triangle is flat) held as double-doubles, so that δ − δᵢ is exact however close.
  ``branch`` = the side of J_a relative to the directed line J_b → J_c.
* ``NEXT`` (φ_{p+1} or φ_{p−1} known): the known body's link v = R(±φ)·l is known, and the far
  pivot lies on a circle of radius L (L_a or L_c) about a point q = m + v, moving along the
  slide line: |q + δ·ŝ| = L, so t = σ·√((L − e)(L + e)) with e = q × ŝ. Each factor is a
  sinusoid in φ, A − B·cos(±φ − x₀), written as 2B·sin(½(φ − ρ₁))·sin(½(φ − ρ₂)) with its
  roots ρ (dead points: the line tangent to the circle, crank and coupler collinear) held as
  double-doubles. ``branch`` = the sign of t (the far pivot ahead of or behind the foot of the
  perpendicular from the circle's centre to the slide line).
* ``OPPOSITE`` (φ_{p+2} known): D = |J_c − J_b| = |links[p + 1] + R(φ)·links[p − 2]| is known,
  and t = σ·√(D² − e²), one sinusoid factor in φ (dead points where D = |e|). ``branch`` = the
  sign of t.

A factor that only touches zero (a double root: the two assemblies cross, e.g. a slider-crank
with crank = coupler and zero offset, whose slider passes through the crank pivot) is
gap + 2B·sin²(½(φ − ρ)) (or (δ − ρ)² + gap), and its square root continues analytically through
the change point; the rates there come from forms with the vanishing factor divided out.
"""

from __future__ import annotations

from decimal import Decimal, localcontext
from enum import Enum
import math
import operator

from linkage_kinematics.kinematics.continuation import check_branch, turns_past
from linkage_kinematics.kinematics.decimal_arithmetic import atan2, DIGITS, PI, split
from linkage_kinematics.kinematics.geometry import (
    Factor,
    FactorForm,
    GeometryError,
    Reachability,
    TOUCH_TOLERANCE,
    TWO_PI,
    wrap_angle,
)
from linkage_kinematics.kinematics.singular_points import (
    factor_unit,
    factor_value,
    offset_from,
    PIVOT_PASSAGE,
    too_close,
)
from linkage_kinematics.kinematics.solver import DeadPointError

Vector = tuple[float, float]


class KnownCase(Enum):
    """Which joint of the RRRP loop is known, relative to the prismatic one."""

    SLIDE = 'the prismatic joint'
    NEXT = 'a revolute joint next to the prismatic one'
    OPPOSITE = 'the revolute joint opposite the prismatic one'


def _sinusoid(constant: Decimal, amplitude: Decimal, phase: Decimal, sense: int,
              what: str) -> Factor:
    """
    Return the factor A − B·cos(sense·φ − x₀): A ``constant``, B ``amplitude``, x₀ ``phase``.

    Its roots are sense·x₀ ∓ ξ with cos ξ = A/B: A − B·cos y = 2B·sin(½(φ − ρ₁))·sin(½(φ − ρ₂)).
    """
    centre = sense * phase
    tolerance = Decimal(TOUCH_TOLERANCE)
    if constant - amplitude >= -tolerance * amplitude:
        gap = constant - amplitude
        return Factor(FactorForm.TOUCH, float(2 * amplitude), split(centre),
                      gap=float(gap) if gap > tolerance * amplitude else 0.0)
    if constant + amplitude <= tolerance * amplitude:
        raise GeometryError(f'the loop cannot close at any angle: {what}')
    ratio = constant / amplitude
    half_width = atan2((1 - ratio * ratio).sqrt(), ratio)
    return Factor(FactorForm.ROOTS, float(2 * amplitude), split(centre - half_width),
                  split(centre + half_width))


def _quadratic(centre: Decimal, radius_squared: Decimal, orientation: int, size: Decimal,
               what: str) -> Factor:
    """
    Return the factor orientation·((δ − centre)² − radius²) with its roots as double-doubles.

    ``size`` is the squared length the touching test is relative to.
    """
    tolerance = Decimal(TOUCH_TOLERANCE)
    if abs(radius_squared) <= tolerance * size or radius_squared < 0:
        if orientation < 0:
            raise GeometryError(f'the loop cannot close at any displacement: {what}')
        gap = -radius_squared if radius_squared < -tolerance * size else Decimal(0)
        return Factor(FactorForm.TOUCH, 1.0, split(centre), gap=float(gap), periodic=False)
    radius = radius_squared.sqrt()
    return Factor(FactorForm.ROOTS, 1.0, split(centre - radius), split(centre + radius),
                  orientation=float(orientation), periodic=False)


def _angle(vector: Vector) -> float:
    return math.atan2(vector[1], vector[0])


def _decimal_angle(vector: tuple[Decimal, Decimal]) -> Decimal:
    return atan2(vector[1], vector[0])


def _arcs(factors: tuple[Factor, ...]) -> list[tuple[float, float]]:
    """Return the arcs of angles where every factor is ≥ 0 (a factor with roots: [ρ₂, ρ₁ + 2π])."""
    arcs = [(-math.pi, math.pi)]
    for factor in factors:
        if factor.touching:
            continue
        low, high = factor.second[0], factor.first[0] + TWO_PI
        if arcs == [(-math.pi, math.pi)]:
            arcs = [(low, high)]
            continue
        pieces = []
        for start, end in arcs:
            for turns in range(-2, 3):
                shift = TWO_PI * turns
                piece = (max(start, low + shift), min(end, high + shift))
                if piece[1] > piece[0]:
                    pieces.append(piece)
        arcs = pieces
    return arcs


def _centred(interval: tuple[float, float]) -> tuple[float, float]:
    """Return the interval shifted by whole turns so that its centre lies in (−π, π]."""
    middle = 0.5 * (interval[0] + interval[1])
    shift = TWO_PI * round((wrap_angle(middle) - middle) / TWO_PI)
    return interval[0] + shift, interval[1] + shift


class PrismaticLoop:
    """
    One RRRP loop driven at one joint: its constants, computed once, and its closed form.

    ``links``, ``slide`` and ``prismatic`` as in ``planar_loop.PlanarLoop``; ``known`` is the
    driving joint (1, 2 or 3).
    """

    def __init__(self, links: tuple[Vector, ...], slide: Vector, prismatic: int,
                 known: int) -> None:
        self.prismatic = prismatic
        self.known = known
        self.case = {0: KnownCase.SLIDE, 2: KnownCase.OPPOSITE}.get(
            (known - prismatic) % 4, KnownCase.NEXT)
        # +1: the known joint is p + 1 (its body p + 1 turns by +φ relative to body p − 1);
        # −1: it is p − 1 (body p − 2 turns by −φ).
        self.sense = 1 if (known - prismatic) % 4 == 1 else -1
        # joints 0..3 from (p, p + 1, p + 2, p + 3, the known joint): the known one its own
        self._in_joint_order = operator.itemgetter(*(
            4 if index == known else (index - prismatic) % 4 for index in range(4)))
        self.link_a = links[(prismatic - 2) % 4]
        self.link_c = links[(prismatic + 1) % 4]
        self.angle_a = _angle(self.link_a)
        self.angle_c = _angle(self.link_c)
        with localcontext() as context:
            context.prec = DIGITS
            _constants(self, links, slide)
        self.factors = _factors(self)
        self.range = _range(self)

    def _discriminant(self, value: float) -> tuple[float, ...]:
        """
        Return the factors at ``value``; raise where the loop does not close or a dead point is.

        Past a root (a factor < 0): UnreachableError. On a root, or so close that a one-ulp
        change of ``value`` moves the exact accelerations by more than RATE_ACCURACY (the
        four-bar's rule, ``singular_points.too_close``): DeadPointError.
        """
        values = []
        for factor in self.factors:
            result, nearest = factor_value(factor, value)
            if result < 0.0:
                raise self.range.unreachable(value)
            if result == 0.0 and not factor.touching or too_close(value, nearest):
                raise DeadPointError(
                    f'joint {self.known} at {value!r} is at a dead point of the loop: the rates '
                    'are unbounded there (closer than a one-ulp change of the value moving the '
                    'accelerations by 0.1%)')
            values.append(result)
        return tuple(values)

    def _analytic_sign(self, branch: int, factor: Factor, value: float) -> float:
        """
        Return σ_a, the sign that continues the root of a change factor through its point.

        The root is σ_a·√(2B)·m·√(other factor), m = sin(½(φ − ρ)) or δ − ρ: its sign is the
        side named by ``branch`` at ``value``, so σ_a = branch·sign(m); at m = 0 itself, where
        the sides meet, the side just past it (the sign of m's derivative).
        """
        unit = factor_unit(factor, value, factor.first)
        if unit != 0.0:
            return branch * math.copysign(1.0, unit)
        if factor.periodic:
            return branch * math.copysign(1.0, math.cos(0.5 * (value - factor.first[0])))
        return float(branch)

    def solve(self, value: float, rate: float, branch: int
              ) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """Return the coordinates and rates of joints 0..3 (``planar_loop.solve_loop``)."""
        values = self._discriminant(value)
        if self.case is KnownCase.SLIDE:
            delta, angle_a, angle_c, delta_rate, rate_a, rate_c = self._solve_slide(
                value, rate, branch, values)
        elif self.case is KnownCase.OPPOSITE:
            delta, angle_a, angle_c, delta_rate, rate_a, rate_c = self._solve_opposite(
                value, rate, branch, values[0])
        else:
            delta, angle_a, angle_c, delta_rate, rate_a, rate_c = self._solve_next(
                value, rate, branch, values)
        in_joint_order = self._in_joint_order
        return (in_joint_order((delta, wrap_angle(angle_c), wrap_angle(angle_a - angle_c),
                                wrap_angle(-angle_a), value)),
                in_joint_order((delta_rate, rate_c, rate_a - rate_c, -rate_a, rate)))

    def _solve_slide(self, delta: float, speed: float, branch: int,
                     values: tuple[float, ...]) -> tuple[float, ...]:
        """Return δ, ψ_a, ψ_c and their rates, δ known: the triangle J_b J_c J_a (Heron)."""
        stretched, folded = values
        along = offset_from(delta, self.centre)  # t = δ + m·ŝ, exact near the change point
        across = self.offset
        slide_x, slide_y = self.slide
        w_x = along * slide_x + across * slide_y
        w_y = along * slide_y - across * slide_x
        squared = along * along + across * across
        length = math.sqrt(squared)
        self._check_pivot_passage(length)
        x = (self.squares + squared) / (2.0 * length)
        height = branch * math.sqrt(stretched * folded) / (2.0 * length)
        u_x = w_x / length
        u_y = w_y / length
        pin_x = x * u_x - height * u_y
        pin_y = x * u_y + height * u_x
        angle_a = math.atan2(-pin_y, -pin_x) - self.angle_a
        angle_c = math.atan2(pin_y - w_y, pin_x - w_x) - self.angle_c
        folded_factor = self.factors[1]
        if folded_factor.is_change:
            # σh = H·t: the vanishing t divided out of numerators and denominators alike.
            sign = self._analytic_sign(branch, folded_factor, delta)
            ratio = sign * math.sqrt(stretched) / (2.0 * length)
            lead = x + ratio * across
            rate_c = speed * lead / (ratio * squared)
            rate_a = speed * (lead / length - 1.0) / (ratio * length)
        else:
            # ω_c = −v·(ŝ·a)/(c × a), ω_a = v·(ŝ·c)/(c × a), c × a = σh·|w|
            lead = x * along + height * across
            rate_c = speed * lead / (height * squared)
            rate_a = speed * (lead / length - along) / (height * length)
        return delta, angle_a, angle_c, speed, rate_a, rate_c

    def _solve_next(self, angle: float, rate: float, branch: int,
                    values: tuple[float, ...]) -> tuple[float, ...]:
        """Return δ, ψ_a, ψ_c and their rates, a revolute joint next to the slide known."""
        lower, upper = values  # L − e, L + e
        near = self.link_c if self.sense > 0 else self.link_a
        cosine = math.cos(self.sense * angle)
        sine = math.sin(self.sense * angle)
        v_x = cosine * near[0] - sine * near[1]
        v_y = sine * near[0] + cosine * near[1]
        slide_x, slide_y = self.slide
        cross = v_x * slide_y - v_y * slide_x
        across = self.offset + cross  # e = q × ŝ
        along = branch * math.sqrt(lower * upper)  # t
        first, second = self.factors
        first_unit = abs(factor_unit(first, angle, first.first)) if first.is_change else math.inf
        second_unit = (abs(factor_unit(second, angle, second.first)) if second.is_change
                       else math.inf)
        # Q = e'/t, finite through a change point where e' and t vanish together
        if first_unit <= second_unit and first.is_change:
            sign = self._analytic_sign(branch, first, angle)
            half_cosine = math.cos(0.5 * (angle - first.first[0]))
            ratio = -math.sqrt(first.scale) * half_cosine / (sign * math.sqrt(upper))
        elif second.is_change:
            sign = self._analytic_sign(branch, second, angle)
            half_cosine = math.cos(0.5 * (angle - second.first[0]))
            ratio = math.sqrt(second.scale) * half_cosine / (sign * math.sqrt(lower))
        else:
            ratio = -self.sense * (v_x * slide_x + v_y * slide_y) / along
        delta = along - (self.along + v_x * slide_x + v_y * slide_y)
        delta_slope = -across * ratio - self.sense * cross
        # −(t·ŝ − e·ŝ⊥): the vector a (sense +1) or c (sense −1)
        far_angle = math.atan2(-(along * slide_y - across * slide_x),
                               -(along * slide_x + across * slide_y))
        if self.sense > 0:
            return (delta, far_angle - self.angle_a, angle, rate * delta_slope, -rate * ratio,
                    rate)
        return (delta, -angle, far_angle - self.angle_c, rate * delta_slope, -rate,
                -rate * ratio)

    def _solve_opposite(self, angle: float, rate: float, branch: int,
                        value: float) -> tuple[float, ...]:
        """Return δ, ψ_a, ψ_c and their rates, the revolute joint opposite the slide known."""
        factor = self.factors[0]
        cosine, sine = math.cos(angle), math.sin(angle)
        link_a, link_c = self.link_a, self.link_c
        v_x = cosine * link_a[0] - sine * link_a[1]
        v_y = sine * link_a[0] + cosine * link_a[1]
        along = branch * math.sqrt(value)  # t
        if factor.is_change:
            sign = self._analytic_sign(branch, factor, angle)
            slope = sign * math.sqrt(factor.scale) * math.cos(0.5 * (angle - factor.first[0]))
            slope *= 0.5
        else:
            slope = (v_x * link_c[1] - v_y * link_c[0]) / along  # dt/dφ = (v × l_c)/t
        across = self.offset
        slide_x, slide_y = self.slide
        w_x = along * slide_x + across * slide_y
        w_y = along * slide_y - across * slide_x
        squared = along * along + across * across
        self._check_pivot_passage(math.sqrt(squared))
        angle_c = (math.atan2(-w_y, -w_x)
                   - math.atan2(link_c[1] + v_y, link_c[0] + v_x))
        # dψ_c/dφ = (e·t' − l_c·v − L_a²)/D²
        rate_c = rate * (across * slope - (link_c[0] * v_x + link_c[1] * v_y)
                         - self.squares_a) / squared
        return (along - self.along, angle_c + angle, angle_c, rate * slope, rate + rate_c,
                rate_c)

    def _check_pivot_passage(self, length: float) -> None:
        if length < PIVOT_PASSAGE * self.scale:
            raise DeadPointError(
                f'joint {self.known}: joints {(self.prismatic - 1) % 4} and '
                f'{(self.prismatic + 1) % 4} meet (equal links, zero slide offset): the links '
                'between them can turn together, so the motion is undetermined there')

    def side(self, points: tuple[Vector, ...], angles: tuple[float, ...]) -> float:
        """
        Return the signed quantity whose sign is the branch, from the joints' points.

        SLIDE: (J_c − J_b) × (J_a − J_b); NEXT: t = (J_a − J_b)·ŝ (known p + 1) or
        (J_c − J_a)·ŝ (known p − 1); OPPOSITE: t = (J_c − J_b)·ŝ; ŝ turned with body p − 1.
        """
        p = self.prismatic
        theta = angles[(p - 1) % 4]
        slide = (math.cos(theta) * self.slide[0] - math.sin(theta) * self.slide[1],
                 math.sin(theta) * self.slide[0] + math.cos(theta) * self.slide[1])
        pivot_b, pivot_c, pivot_a = points[(p - 1) % 4], points[(p + 1) % 4], points[(p + 2) % 4]
        if self.case is KnownCase.SLIDE:
            w = _minus(pivot_c, pivot_b)
            to_a = _minus(pivot_a, pivot_b)
            return w[0] * to_a[1] - w[1] * to_a[0]
        if self.case is KnownCase.OPPOSITE:
            chord = _minus(pivot_c, pivot_b)
        else:
            chord = _minus(pivot_a, pivot_b) if self.sense > 0 else _minus(pivot_c, pivot_a)
        return chord[0] * slide[0] + chord[1] * slide[1]

    def continued_branch(self, value_from: float, branch: int, value_to: float) -> int:
        """Return the branch at ``value_to`` of a smooth motion with ``branch`` at value_from."""
        check_branch(branch)
        flips = 0
        for factor in self.factors:
            if not factor.is_change:
                continue
            if factor.periodic:
                flips += abs(turns_past(value_to, factor.first)
                             - turns_past(value_from, factor.first))
            else:
                flips += ((offset_from(value_to, factor.first) >= 0.0)
                          != (offset_from(value_from, factor.first) >= 0.0))
        return branch if flips % 2 == 0 else -branch


def _constants(loop: PrismaticLoop, links: tuple[Vector, ...], slide: Vector) -> None:
    """Compute, in 60-digit decimal arithmetic, what the closed form needs."""
    p = loop.prismatic
    norm = (Decimal(slide[0]) ** 2 + Decimal(slide[1]) ** 2).sqrt()
    loop._slide = (Decimal(slide[0]) / norm, Decimal(slide[1]) / norm)
    loop._m = (Decimal(links[(p - 1) % 4][0]) + Decimal(links[p][0]),
               Decimal(links[(p - 1) % 4][1]) + Decimal(links[p][1]))
    loop._offset = loop._m[0] * loop._slide[1] - loop._m[1] * loop._slide[0]  # e = m × ŝ
    loop._along = loop._m[0] * loop._slide[0] + loop._m[1] * loop._slide[1]  # m·ŝ
    loop._length_a = (Decimal(loop.link_a[0]) ** 2 + Decimal(loop.link_a[1]) ** 2).sqrt()
    loop._length_c = (Decimal(loop.link_c[0]) ** 2 + Decimal(loop.link_c[1]) ** 2).sqrt()
    if loop._length_a == 0 or loop._length_c == 0:
        raise GeometryError(f'joint {(p + 2) % 4} coincides with a neighbouring revolute '
                            'joint: a link of the loop has no length')
    loop.slide = (float(loop._slide[0]), float(loop._slide[1]))
    loop.m = (float(loop._m[0]), float(loop._m[1]))
    loop.offset = float(loop._offset)
    loop.along = float(loop._along)
    loop.centre = split(-loop._along)
    loop.squares_a = float(loop._length_a ** 2)
    loop.squares = float(loop._length_a ** 2 - loop._length_c ** 2)
    loop.scale = float(max(loop._length_a, loop._length_c, abs(loop._m[0]),
                           abs(loop._m[1])))


def _factors(loop: PrismaticLoop) -> tuple[Factor, ...]:
    """Return the discriminant's factors for this case (module docstring)."""
    with localcontext() as context:
        context.prec = DIGITS
        length_a, length_c, offset = loop._length_a, loop._length_c, loop._offset
        if loop.case is KnownCase.SLIDE:
            centre = -loop._along
            stretched = (length_a + length_c) ** 2
            folded = (length_a - length_c) ** 2
            what = (f'the slide line passes {float(abs(offset)):.6g} m from joint '
                    f'{(loop.prismatic - 1) % 4} but the links reach '
                    f'{float(length_a + length_c):.6g} m')
            return (_quadratic(centre, stretched - offset ** 2, -1, stretched, what),
                    _quadratic(centre, folded - offset ** 2, 1, stretched, what))
        if loop.case is KnownCase.OPPOSITE:
            # D² − e² = L_a² + L_c² − e² + 2·L_a·L_c·cos(φ + λ), λ = arg l_a − arg l_c
            turn = (_decimal_angle(_decimal(loop.link_a))
                    - _decimal_angle(_decimal(loop.link_c)))
            what = (f'the pivots next to the slide are never {float(abs(offset)):.6g} m '
                    "apart (the slide line's offset)")
            return (_sinusoid(length_a ** 2 + length_c ** 2 - offset ** 2,
                              2 * length_a * length_c, PI - turn, 1, what),)
        near, radius = ((loop.link_c, length_a) if loop.sense > 0
                        else (loop.link_a, length_c))
        near_length = (Decimal(near[0]) ** 2 + Decimal(near[1]) ** 2).sqrt()
        # e(φ) = e₀ + |v|·sin(κ − sense·φ), κ = arg ŝ − arg v
        kappa = _decimal_angle(loop._slide) - _decimal_angle(_decimal(near))
        what = (f'the circle of radius {float(radius):.6g} m never meets the slide line')
        return (_sinusoid(radius - offset, near_length, kappa - PI / 2, loop.sense, what),
                _sinusoid(radius + offset, near_length, kappa + PI / 2, loop.sense, what))


def _range(loop: PrismaticLoop) -> Reachability:
    change_points = tuple(factor.first[0] for factor in loop.factors if factor.is_change)
    if loop.case is KnownCase.SLIDE:
        stretched, folded = loop.factors
        low, high = stretched.first[0], stretched.second[0]
        intervals = (((low, folded.first[0]), (folded.second[0], high))
                     if not folded.touching else ((low, high),))
        return Reachability(intervals, tuple(end for piece in intervals for end in piece),
                            change_points, periodic=False, joint=loop.known)
    arcs = _arcs(loop.factors)
    if not arcs:
        raise GeometryError(f'the loop cannot close at any angle of joint {loop.known}')
    full = arcs == [(-math.pi, math.pi)]
    intervals = tuple(_centred(arc) for arc in arcs)
    return Reachability(
        intervals, () if full else tuple(end for piece in intervals for end in piece),
        tuple(wrap_angle(point) for point in change_points), joint=loop.known)


def _minus(point: Vector, origin: Vector) -> Vector:
    return point[0] - origin[0], point[1] - origin[1]


def _decimal(vector: Vector) -> tuple[Decimal, Decimal]:
    return Decimal(vector[0]), Decimal(vector[1])
