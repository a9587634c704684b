# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Geometry of a planar four-bar linkage: validation, presets and reachability.

Conventions (the seed paper's, used everywhere in this package):

* The disk centre O is the origin; x points right, y up, z out of the plane. Angles and angular
  velocities are counterclockwise-positive about z.
* The crank (disk radius) OA has length ``crank_length``. The crank angle α is measured from the
  lowest position of pin A, counterclockwise: ``A = OA·(sin α, −cos α)``.
* The second ground pivot C sits at ``(ground_x, ground_y)`` relative to O.
* The coupler AB has length ``coupler_length``; γ is the angle of the vector A→B above the
  horizontal: ``B = A + AB·(cos γ, sin γ)``.
* The rocker (output bar) BC has length ``rocker_length``; β follows the seed's Eq. (8d):
  ``B = C + BC·(−cos β, sin β)``. The rocker's counterclockwise angular velocity is
  therefore ``ω_BC = −dβ/dt``, and the coupler's is ``ω_AB = dγ/dt``.
* For one α the loop closes in two ways (assembly branches). ``branch = +1`` puts B to the left
  of the directed line A→C, ``branch = −1`` to its right. The seed's mechanism is on ``+1``.
  B can only change sides where AB and BC are collinear. At a dead point the crank cannot go
  on; at a change point (Grashof's s + l = p + q, where both assemblies meet) a mechanism
  driven through continues on the smooth branch, on which B does cross the line A→C
  (``kinematics.continued_branch``). A fixed branch is a continuous motion everywhere else.

All lengths are in metres and all angles in radians; degrees appear only in messages for people.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from decimal import Decimal, localcontext
from enum import Enum
import math

from linkage_kinematics.kinematics.decimal_arithmetic import atan2, DIGITS, PI, split

TWO_PI = 2.0 * math.pi
# Cosine bounds k± (computed exactly from the float lengths) within this distance of ±1 are
# treated as touching: the linkage is solved as the exact change-point linkage (s + l = p + q)
# instead of one with a vanishingly small gap in its reachable set or a near-miss of its
# branches. It covers lengths typed as decimals whose Grashof sums differ only by the rounding
# of those decimals to floats (~1e-16); near its change points such a linkage moves as the
# exact one, which may differ from its float lengths' own motion by up to √(2·tolerance)
# relative there (and by tolerance/S² at a transmission sine S).
TOUCH_TOLERANCE = 1e-14
# A crank angle this close outside a computed interval end is still taken as the end itself.
ANGLE_TOLERANCE = 1e-14
# Lengths and coordinates are kept within these magnitudes so that the products of four lengths
# in the closed form (Heron's formula) neither overflow nor underflow in double precision.
MAX_SOLVABLE_LENGTH = 1e60
MIN_SOLVABLE_LENGTH = 1e-60
# The dimensions that make a FourBar, in its constructor's order: its link lengths and the
# coordinates of the pivot C. The node's geometry parameters and linkage-sweep's geometry options
# carry these names.
LINK_LENGTHS = ('crank_length', 'coupler_length', 'rocker_length')
GROUND_COORDINATES = ('ground_x', 'ground_y')
DIMENSIONS = LINK_LENGTHS + GROUND_COORDINATES


class GeometryError(ValueError):
    """The link lengths or pivot positions do not describe a mechanism that can move."""


class UnreachableError(ValueError):
    """The loop cannot close at the requested crank angle."""


def _is_real(value: object) -> bool:
    """Return an int or float, but not a bool (which Python counts as an int)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def wrap_angle(angle: float) -> float:
    """Return ``angle`` wrapped to (−π, π]."""
    wrapped = math.remainder(angle, TWO_PI)
    return math.pi if wrapped == -math.pi else wrapped


def format_interval(interval: tuple[float, float]) -> str:
    """``[lo°, hi°]`` for an error message."""
    return f'[{math.degrees(interval[0]):.3f}°, {math.degrees(interval[1]):.3f}°]'


@dataclass(frozen=True)
class Reachability:
    """
    Where the coordinate that drives a loop can go: a four-bar's crank, or a loop's known joint.

    ``intervals`` are the closed intervals where the loop closes. An angle's (``periodic``: a
    crank or a revolute joint, rad) are each written with its centre in (−π, π] and repeat every
    2π; a displacement's (a prismatic joint, m) are plain. ``dead_points`` are the interval ends,
    where the loop folds flat and the coordinate cannot drive further (none where an angle turns
    fully). ``change_points`` lie inside an interval, where both assemblies meet (Grashof
    equality linkages). ``joint`` is the loop joint that drives (``planar_loop``), None for a
    four-bar's crank α; messages name it.
    """

    intervals: tuple[tuple[float, float], ...]
    dead_points: tuple[float, ...]
    change_points: tuple[float, ...]
    periodic: bool = True
    joint: int | None = None

    @property
    def full_rotation(self) -> bool:
        """Return True when the crank (or revolute joint) can turn all the way round."""
        return self.periodic and not self.dead_points

    def interval_containing(self, value: float) -> tuple[float, float] | None:
        """Return the interval that holds ``value`` (modulo 2π for an angle), or None."""
        for low, high in self.intervals:
            if self.periodic:
                past_low = (value - low) % TWO_PI
                if (past_low <= high - low + ANGLE_TOLERANCE
                        or past_low >= TWO_PI - ANGLE_TOLERANCE):
                    return (low, high)
            elif low <= value <= high:
                return (low, high)
        return None

    def contains(self, value: float) -> bool:
        """Return True when the loop closes at ``value`` (modulo 2π for an angle)."""
        return math.isfinite(value) and self.interval_containing(value) is not None

    def describe(self) -> str:
        """Return the reachable set for messages: degrees for an angle, metres otherwise."""
        if self.joint is None:
            if self.full_rotation:
                return 'all crank angles (full rotation)'
            return ' and '.join(format_interval(interval) for interval in self.intervals)
        if self.full_rotation:
            return 'all angles (full rotation)'
        if self.periodic:
            return ' and '.join(
                f'[{math.degrees(low):.6f}°, {math.degrees(high):.6f}°]'
                for low, high in self.intervals) + ' (mod 360°)'
        return ' and '.join(f'[{low:.9g} m, {high:.9g} m]' for low, high in self.intervals)

    def unreachable(self, value: float) -> UnreachableError:
        """Return the error for a ``value`` at which the loop does not close."""
        if self.joint is None:
            return UnreachableError(
                f'crank angle α = {math.degrees(value):.6f}° is not reachable: the loop closes '
                f'only for α in {self.describe()} (mod 360°)'
            )
        shown = f'{math.degrees(value):.9f}°' if self.periodic else f'{value!r} m'
        return UnreachableError(
            f'joint {self.joint} at {shown} is not reachable: the loop closes only for '
            f'{self.describe()}'
        )

    def require(self, value: float) -> tuple[float, float]:
        """
        Return the interval holding ``value``.

        Raise UnreachableError naming the reachable set where none does.
        """
        interval = self.interval_containing(value)
        if interval is None:
            raise self.unreachable(value)
        return interval

    def dead_point_distance(self, value: float) -> float | None:
        """
        Distance (rad or m) from ``value`` to the nearest dead point (mod 2π for an angle).

        None where there is none (an angle that turns fully).
        """
        return self._nearest(self.dead_points, value)

    def change_point_distance(self, value: float) -> float | None:
        """
        Distance (rad or m) from ``value`` to the nearest change point (mod 2π for an angle).

        Where the two assemblies meet and the motion continues smoothly; None if there is none.
        """
        return self._nearest(self.change_points, value)

    def first_dead_point(self, value_from: float, value_to: float) -> float | None:
        """
        Return the first dead point met on the way from ``value_from`` to ``value_to``.

        ``value_to`` is included; for an angle the dead point is unwrapped (on the way's turn),
        None if the way is clear.

        Change points do not stop the motion (it continues through them on its smooth branch,
        see ``kinematics.continued_branch``), so they are not counted here.
        """
        direction = 1.0 if value_to > value_from else -1.0
        reach = abs(value_to - value_from) + (ANGLE_TOLERANCE if self.periodic else 0.0)
        nearest = None
        for point in self.dead_points:
            distance = direction * (point - value_from)
            if self.periodic:
                distance %= TWO_PI
            elif distance < 0.0:
                continue  # behind the way
            if distance <= reach and (nearest is None or distance < nearest):
                nearest = distance
        return None if nearest is None else value_from + direction * nearest

    def _nearest(self, points: tuple[float, ...], value: float) -> float | None:
        if not points:
            return None
        if self.periodic:
            return min(abs(wrap_angle(value - point)) for point in points)
        return min(abs(value - point) for point in points)


@dataclass(frozen=True)
class FourBar:
    """A planar four-bar linkage; construction validates it and computes its reachability."""

    crank_length: float
    coupler_length: float
    rocker_length: float
    ground_x: float
    ground_y: float = 0.0
    reachability: Reachability = field(init=False, repr=False, compare=False)
    closure: LoopClosure = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        for name in LINK_LENGTHS:
            value = getattr(self, name)
            if not _is_real(value) or not MIN_SOLVABLE_LENGTH <= value <= MAX_SOLVABLE_LENGTH:
                raise GeometryError(
                    f'{name} must be a length from {MIN_SOLVABLE_LENGTH:g} to '
                    f'{MAX_SOLVABLE_LENGTH:g} m, got {value!r}'
                )
        for name in GROUND_COORDINATES:
            value = getattr(self, name)
            if not _is_real(value) or not abs(value) <= MAX_SOLVABLE_LENGTH:
                raise GeometryError(
                    f'{name} must be a coordinate from {-MAX_SOLVABLE_LENGTH:g} to '
                    f'{MAX_SOLVABLE_LENGTH:g} m, got {value!r}'
                )
        closure, reachability = _loop_closure(self)
        object.__setattr__(self, 'closure', _closure_constants(self, closure))
        object.__setattr__(self, 'reachability', reachability)

    @property
    def ground_length(self) -> float:
        """Distance OC between the fixed pivots."""
        return math.hypot(self.ground_x, self.ground_y)

    @property
    def is_grashof(self) -> bool:
        """Grashof's condition s + l ≤ p + q: some link can turn fully relative to the others."""
        lengths = sorted(
            (self.crank_length, self.coupler_length, self.rocker_length, self.ground_length)
        )
        return lengths[0] + lengths[3] <= (lengths[1] + lengths[2]) * (1.0 + TOUCH_TOLERANCE)

    def scaled(self, factor: float) -> FourBar:
        """Return the same mechanism with every length multiplied by ``factor``."""
        return FourBar(
            self.crank_length * factor,
            self.coupler_length * factor,
            self.rocker_length * factor,
            self.ground_x * factor,
            self.ground_y * factor,
        )


# --- the exact zeros of the loop closure, computed once per linkage ---------------------------
#
# With φ = α − α₀ the angle from OC to OA (α₀ = π/2 + atan2(y_C, x_C)) and d = |C − A|,
# d² = OC² + OA² − 2·OA·OC·cos φ, and Heron's product 4·d²·h² is the product of two factors:
#
#   stretched  (AB + BC)² − d² = 2·OA·OC·(cos φ − k₊),  k₊ = (OC² + OA² − (AB + BC)²)/(2·OA·OC)
#   folded     d² − (AB − BC)² = 2·OA·OC·(k₋ − cos φ),  k₋ = (OC² + OA² − (AB − BC)²)/(2·OA·OC)
#
# A factor whose k lies inside (−1, 1) vanishes at two dead points α₀ ± acos k, and is written as
# 4·OA·OC·sin(½(α − a₁))·sin(½(α − a₂)) (up to sign) with a₁, a₂ those crank angles held to twice
# double precision: α − a is then exact to rounding however close α is to a, where the
# difference of the pin distance d from AB + BC would lose everything but the rounding of d.
# A factor with k = ∓1 (Grashof's s + l = p + q) has a double zero, a change point, and is
# written as 4·OA·OC·sin²(½(α − a)), whose square root continues analytically through it.
# A factor that stays away from zero is taken from d directly (the cheapest form).

DoubleDouble = tuple[float, float]


class FactorForm(Enum):
    """How a factor of a loop's discriminant is evaluated (``Factor``)."""

    PLAIN = 'from the pin distance'
    ROOTS = 'two roots'
    TOUCH = 'touching zero'


@dataclass(frozen=True)
class Factor:
    """
    One factor of a loop's discriminant, in the form that is exact near its zeros.

    The four-bar's two factors of Heron's product (see the comment above) and those of a loop
    with a prismatic joint (``prismatic_loop``). With u(x, a) = sin(½(x − a)) for an angle
    (``periodic``) or x − a for a displacement, each root a held as a double-double
    (``singular_points`` evaluates them), the ``form`` is ``ROOTS``:
    ``orientation``·``scale``·u(x, ``first``)·u(x, ``second``), two dead points; ``TOUCH``:
    ``gap`` + ``scale``·u(x, ``first``)², a change point where ``gap`` = 0; or, for a four-bar's
    factor far from zero everywhere, ``PLAIN``: taken from the pin distance d and ``length``. A
    four-bar's ``length`` is AB + BC or |AB − BC| in every form.
    """

    form: FactorForm
    scale: float
    first: DoubleDouble = (0.0, 0.0)
    second: DoubleDouble = (0.0, 0.0)
    gap: float = 0.0
    orientation: float = 1.0
    periodic: bool = True
    length: float = 0.0

    @property
    def touching(self) -> bool:
        """Return True for the TOUCH form: the factor touches zero or stays above it."""
        return self.form is FactorForm.TOUCH

    @property
    def is_change(self) -> bool:
        """Return True where the factor touches zero: a change point."""
        return self.form is FactorForm.TOUCH and self.gap == 0.0


@dataclass(frozen=True)
class LoopClosure:
    """
    Constants of the loop-closure evaluation of one linkage, computed once.

    ``stretched`` and ``folded`` are the two factors; ``scale`` = 4·OA·OC; ``ground`` = OC;
    ``squares`` = AB² − BC²; ``direction`` is α₀ and ``opposite`` α₀ + π (double-doubles), the
    crank angles at which OA points along OC and against it. ``dead_points`` and
    ``change_points`` are the singular crank angles as double-doubles, unwrapped as the factors
    use them.
    """

    stretched: Factor
    folded: Factor
    scale: float
    ground: float
    squares: float
    direction: tuple[float, float]
    opposite: tuple[float, float]
    dead_points: tuple[tuple[float, float], ...]
    change_points: tuple[tuple[float, float], ...]
    # True where OA = OC and AB = BC: pin A passes through C, where the dyad ABC is undetermined.
    passes_through_pivot: bool
    # What the closed form reads first, in one tuple (one attribute load on the hot path):
    # OA, AB, BC, x_C, y_C, AB + BC, |AB − BC|, AB² − BC², and whether the factors may come
    # from d where both are far from zero (not for change-point linkages, whose rates always
    # take the analytic form).
    constants: tuple = ()


def _closure_constants(linkage: FourBar, closure: LoopClosure) -> LoopClosure:
    constants = (linkage.crank_length, linkage.coupler_length, linkage.rocker_length,
                 linkage.ground_x, linkage.ground_y, closure.stretched.length,
                 closure.folded.length, closure.squares, not closure.change_points)
    return replace(closure, constants=constants)


def _loop_closure(linkage: FourBar, exact: tuple[Decimal, ...] | None = None
                  ) -> tuple[LoopClosure, Reachability]:
    """
    Return the factors of the loop closure and the reachable crank angles.

    Both come from exact arithmetic: on the float dimensions, or on ``exact`` (OA, AB, BC, x_C,
    y_C), the dimensions the floats are roundings of where those are known (``from_exact``).
    """
    with localcontext() as context:
        context.prec = DIGITS
        r, b, c, x_c, y_c = exact if exact is not None else (
            Decimal(linkage.crank_length), Decimal(linkage.coupler_length),
            Decimal(linkage.rocker_length), Decimal(linkage.ground_x),
            Decimal(linkage.ground_y))
        ground_squared = x_c * x_c + y_c * y_c
        if ground_squared == 0:
            # O and C coincide: |C − A| = OA for every α, so the loop closes everywhere or nowhere.
            crank, coupler, rocker = (linkage.crank_length, linkage.coupler_length,
                                      linkage.rocker_length)
            if not abs(coupler - rocker) < crank < coupler + rocker:
                raise GeometryError(
                    'with O and C coincident the loop needs |AB − BC| < OA < AB + BC, '
                    f'got OA = {crank} m, AB = {coupler} m, BC = {rocker} m'
                )
            closure = LoopClosure(
                Factor(FactorForm.PLAIN, 0.0, orientation=-1.0, length=coupler + rocker),
                Factor(FactorForm.PLAIN, 0.0, length=abs(coupler - rocker)),
                0.0, 0.0, float(b * b - c * c), (0.0, 0.0), (0.0, 0.0), (), (), False,
            )
            return closure, Reachability(((-math.pi, math.pi),), (), ())
        ground = ground_squared.sqrt()
        product = 2 * r * ground
        lowest_cosine = (ground_squared + r * r - (b + c) ** 2) / product
        highest_cosine = (ground_squared + r * r - (b - c) ** 2) / product
        if lowest_cosine >= 1 - TOUCH_TOLERANCE or highest_cosine <= -1 + TOUCH_TOLERANCE:
            raise GeometryError(
                f'the loop cannot close at any crank angle: |C − A| spans '
                f'[{float(abs(ground - r)):.6g}, {float(ground + r):.6g}] m but AB and BC reach '
                f'only [{float(abs(b - c)):.6g}, {float(b + c):.6g}] m'
            )
        direction = PI / 2 + atan2(y_c, x_c)
        opposite = direction + PI
        scale = float(2 * product)

        def factor(cosine: Decimal, bound: int, touch_at: Decimal, length: Decimal
                   ) -> Factor:
            """
            Return the factor that vanishes where cos φ = ``cosine``.

            Its extreme over a turn is at cos φ = ``bound``. The factor is
            ``bound``·2·OA·OC·(``cosine`` − cos φ), so ``bound`` is its orientation.
            """
            orientation = float(bound)
            if abs(cosine - bound) <= TOUCH_TOLERANCE:
                return Factor(FactorForm.TOUCH, scale, split(touch_at), orientation=orientation,
                              length=float(length))
            gap = product * (cosine - bound) * bound  # the factor's least value over a turn
            if gap > 0:
                # Far from zero everywhere, d's own rounding is small beside the factor.
                plain = gap >= Decimal('0.25') * (ground + r) ** 2
                return Factor(FactorForm.PLAIN if plain else FactorForm.TOUCH, scale,
                              split(touch_at), gap=float(gap), orientation=orientation,
                              length=float(length))
            half_width = atan2((1 - cosine * cosine).sqrt(), cosine)
            return Factor(FactorForm.ROOTS, scale, split(direction - half_width),
                          split(direction + half_width), orientation=orientation,
                          length=float(length))

        stretched = factor(lowest_cosine, -1, opposite, b + c)
        folded = factor(highest_cosine, 1, direction, abs(b - c))
        # (within the touching tolerance: exact lengths from a loop's link vectors that are equal
        # in the typed decimals differ by their roundings)
        passes_through_pivot = (folded.is_change
                                and abs(b - c) <= Decimal(TOUCH_TOLERANCE) * (b + c))
    dead_points = tuple(
        angle for part in (stretched, folded) if part.form is FactorForm.ROOTS
        for angle in (part.first, part.second)
    )
    change_points = tuple(part.first for part in (folded, stretched) if part.is_change)
    closure = LoopClosure(stretched, folded, scale, linkage.ground_length, float(b * b - c * c),
                          split(direction), split(opposite), dead_points, change_points,
                          passes_through_pivot)
    return closure, _reachability(closure)


def from_exact(dimensions: tuple[Decimal, Decimal, Decimal, Decimal, Decimal]) -> FourBar:
    """
    Return the FourBar nearest the exact ``dimensions`` (OA, AB, BC, x_C, y_C; 60-digit decimals).

    Its singular points (dead points, change points, reachability) are those of the exact
    dimensions, not of their float roundings: a four-bar mapped from a loop's link vectors (whose
    lengths no float holds) then meets its dead points where the loop does, to rounding of the
    crank angle, instead of up to a few ulp of the geometry away.
    """
    linkage = FourBar(*(float(value) for value in dimensions))
    closure, reachability = _loop_closure(linkage, dimensions)
    # The same frozen value, its derived constants taken from the exact dimensions.
    object.__setattr__(linkage, 'closure', _closure_constants(linkage, closure))
    object.__setattr__(linkage, 'reachability', reachability)
    return linkage


def _reachability(closure: LoopClosure) -> Reachability:
    """Crank intervals where both factors are ≥ 0, ending at the dead points (φ₋ ≤ |φ| ≤ φ₊)."""
    stretched, folded = closure.stretched, closure.folded
    if stretched.form is not FactorForm.ROOTS and folded.form is not FactorForm.ROOTS:
        ends = [(closure.direction[0] - math.pi, closure.direction[0] + math.pi)]
    elif folded.form is not FactorForm.ROOTS:
        ends = [(stretched.first[0], stretched.second[0])]
    elif stretched.form is not FactorForm.ROOTS:
        ends = [(folded.second[0], folded.first[0] + TWO_PI)]
    else:
        ends = [(folded.second[0], stretched.second[0]), (stretched.first[0], folded.first[0])]
    intervals = []
    for low, high in ends:
        # Each interval is written with its centre in (−π, π].
        shift = wrap_angle(0.5 * (low + high)) - 0.5 * (low + high)
        shift = TWO_PI * round(shift / TWO_PI)
        intervals.append((low + shift, high + shift))
    full_turn = not closure.dead_points
    return Reachability(
        intervals=tuple(intervals),
        dead_points=() if full_turn else tuple(end for interval in intervals for end in interval),
        change_points=tuple(wrap_angle(high) for high, _ in closure.change_points),
    )


@dataclass(frozen=True)
class Preset:
    """A named mechanism and the sign of its usual drive."""

    geometry: FourBar
    drive_sign: float
    description: str


_SEED_COUPLER = math.sqrt(1.09)

PRESETS: dict[str, Preset] = {
    'paper': Preset(
        FourBar(0.3, _SEED_COUPLER, 0.3, 1.3, 0.0),
        1.0,
        "the seed's mechanism: OA = BC = 0.3 m, OC = 1.3 m, AB = √1.09 m, C level with O",
    ),
    'paper_full_turn': Preset(
        FourBar(0.3, _SEED_COUPLER, 0.3, math.sqrt(1.09 - 0.6**2), 0.0),
        -1.0,
        "the seed's 'full revolution' redesign, driven clockwise; it cannot turn fully: the loop "
        'closes only for α in about [−211.3°, 31.3°]',
    ),
    'grashof_crank_rocker': Preset(
        FourBar(0.3, _SEED_COUPLER, 0.6, 1.0, 0.0),
        1.0,
        "a Grashof crank-rocker with the seed's coupler (OA = 0.3, BC = 0.6, OC = 1.0 m): the "
        'crank is the shortest link and turns fully',
    ),
}


def preset(name: str) -> Preset:
    """Look up a preset by name, with an error that lists the known names."""
    try:
        return PRESETS[name]
    except KeyError:
        raise GeometryError(
            f"unknown preset {name!r}; known presets: {', '.join(sorted(PRESETS))}"
        ) from None
