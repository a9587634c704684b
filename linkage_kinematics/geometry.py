"""Geometry of a planar four-bar linkage: validation, presets and reachability.

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
  A branch can only change where AB and BC are collinear (a dead point or a change point), so a
  fixed branch is a continuous motion everywhere else.

All lengths are in metres and all angles in radians; degrees appear only in messages for people.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

TWO_PI = 2.0 * math.pi
# Cosine bounds within this distance of ±1 are treated as touching: the linkage then has a
# change point (both branches meet) instead of a vanishingly small gap in its reachable set.
_TOUCH_TOLERANCE = 1e-12
# A crank angle this close outside a computed interval end is still taken as the end itself.
ANGLE_TOLERANCE = 1e-14
# Lengths and coordinates are kept within these magnitudes so that the products of four lengths
# in the closed form (Heron's formula) neither overflow nor underflow in double precision.
MAX_LENGTH = 1e60
MIN_LENGTH = 1e-60


class GeometryError(ValueError):
    """The link lengths or pivot positions do not describe a mechanism that can move."""


class UnreachableError(ValueError):
    """The loop cannot close at the requested crank angle."""


def _is_real(value: object) -> bool:
    """An int or float, but not a bool (which Python counts as an int)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def wrap_angle(angle: float) -> float:
    """Return ``angle`` wrapped to (−π, π]."""
    wrapped = math.remainder(angle, TWO_PI)
    return math.pi if wrapped == -math.pi else wrapped


def format_interval(interval: tuple[float, float]) -> str:
    """``[lo°, hi°]`` for an error message."""
    return f"[{math.degrees(interval[0]):.3f}°, {math.degrees(interval[1]):.3f}°]"


@dataclass(frozen=True)
class Reachability:
    """Where the crank of a mechanism can go.

    ``intervals`` are the closed crank-angle intervals (rad) where the loop closes, each written
    with its centre in (−π, π] and repeating every 2π. ``dead_points`` are the interval ends,
    where coupler and rocker are collinear and the crank cannot drive further. ``change_points``
    are crank angles inside an interval where both branches meet (Grashof equality linkages).
    """

    intervals: tuple[tuple[float, float], ...]
    dead_points: tuple[float, ...]
    change_points: tuple[float, ...]

    @property
    def full_rotation(self) -> bool:
        """True when the crank can turn all the way round."""
        return not self.dead_points

    def interval_containing(self, alpha: float) -> tuple[float, float] | None:
        """The interval that holds ``alpha`` (modulo 2π), or None."""
        for low, high in self.intervals:
            past_low = (alpha - low) % TWO_PI
            if past_low <= high - low + ANGLE_TOLERANCE or past_low >= TWO_PI - ANGLE_TOLERANCE:
                return (low, high)
        return None

    def describe(self) -> str:
        """The reachable set in degrees, for messages."""
        if self.full_rotation:
            return "all crank angles (full rotation)"
        return " and ".join(format_interval(interval) for interval in self.intervals)

    def require(self, alpha: float) -> tuple[float, float]:
        """Return the interval holding ``alpha`` or raise UnreachableError naming the reachable set."""
        interval = self.interval_containing(alpha)
        if interval is None:
            raise UnreachableError(
                f"crank angle α = {math.degrees(alpha):.6f}° is not reachable: the loop closes "
                f"only for α in {self.describe()} (mod 360°)"
            )
        return interval

    def dead_point_distance(self, alpha: float) -> float | None:
        """Crank-angle distance (rad) from ``alpha`` to the nearest dead or change point.

        None when the mechanism has neither (a crank that turns fully with no branch meeting).
        """
        singular = self.dead_points + self.change_points
        if not singular:
            return None
        return min(abs(wrap_angle(alpha - point)) for point in singular)


@dataclass(frozen=True)
class FourBar:
    """A planar four-bar linkage; construction validates it and computes its reachability."""

    crank_length: float
    coupler_length: float
    rocker_length: float
    ground_x: float
    ground_y: float = 0.0
    reachability: Reachability = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        for name in ("crank_length", "coupler_length", "rocker_length"):
            value = getattr(self, name)
            if not _is_real(value) or not MIN_LENGTH <= value <= MAX_LENGTH:
                raise GeometryError(
                    f"{name} must be a length from {MIN_LENGTH:g} to {MAX_LENGTH:g} m, "
                    f"got {value!r}"
                )
        for name in ("ground_x", "ground_y"):
            value = getattr(self, name)
            if not _is_real(value) or not abs(value) <= MAX_LENGTH:
                raise GeometryError(
                    f"{name} must be a coordinate from {-MAX_LENGTH:g} to {MAX_LENGTH:g} m, "
                    f"got {value!r}"
                )
        object.__setattr__(self, "reachability", _reachability(self))

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
        return lengths[0] + lengths[3] <= (lengths[1] + lengths[2]) * (1.0 + _TOUCH_TOLERANCE)

    def scaled(self, factor: float) -> FourBar:
        """The same mechanism with every length multiplied by ``factor``."""
        return FourBar(
            self.crank_length * factor,
            self.coupler_length * factor,
            self.rocker_length * factor,
            self.ground_x * factor,
            self.ground_y * factor,
        )


def _snap_cosine(value: float) -> tuple[float, bool]:
    """Snap a cosine bound that touches ±1 onto it, saying whether it touched."""
    for bound in (-1.0, 1.0):
        if abs(value - bound) <= _TOUCH_TOLERANCE:
            return bound, True
    return value, False


def _reachability(linkage: FourBar) -> Reachability:
    """Crank intervals where |C − A| lies within [|AB − BC|, AB + BC]."""
    r = linkage.crank_length
    b = linkage.coupler_length
    c = linkage.rocker_length
    g = linkage.ground_length
    if g == 0.0:
        # O and C coincide: |C − A| = OA for every α, so the loop closes everywhere or nowhere.
        if abs(b - c) < r < b + c:
            return Reachability(intervals=((-math.pi, math.pi),), dead_points=(), change_points=())
        raise GeometryError(
            "with O and C coincident the loop needs |AB − BC| < OA < AB + BC, "
            f"got OA = {r} m, AB = {b} m, BC = {c} m"
        )
    # |C − A|² = g² + r² − 2gr·cos φ with φ the angle between OA and OC; the loop closes where
    # cos φ lies in [lowest_cosine, highest_cosine].
    lowest_cosine, touches_low = _snap_cosine((g * g + r * r - (b + c) ** 2) / (2.0 * g * r))
    highest_cosine, touches_high = _snap_cosine((g * g + r * r - (b - c) ** 2) / (2.0 * g * r))
    if lowest_cosine >= 1.0 or highest_cosine <= -1.0:
        raise GeometryError(
            f"the loop cannot close at any crank angle: |C − A| spans [{abs(g - r):.6g}, "
            f"{g + r:.6g}] m but AB and BC reach only [{abs(b - c):.6g}, {b + c:.6g}] m"
        )
    # φ = α − π/2 − ψ, where ψ is the direction of OC.
    offset = math.pi / 2.0 + math.atan2(linkage.ground_y, linkage.ground_x)
    phi_intervals: list[tuple[float, float]]
    change_phis: list[float] = []
    if lowest_cosine <= -1.0 and highest_cosine >= 1.0:
        phi_intervals = [(-math.pi, math.pi)]
    elif highest_cosine >= 1.0:
        limit = math.acos(lowest_cosine)
        phi_intervals = [(-limit, limit)]
    elif lowest_cosine <= -1.0:
        limit = math.acos(highest_cosine)
        phi_intervals = [(limit, TWO_PI - limit)]
    else:
        inner = math.acos(highest_cosine)
        outer = math.acos(lowest_cosine)
        phi_intervals = [(inner, outer), (-outer, -inner)]
    if touches_high:
        change_phis.append(0.0)
    if touches_low:
        change_phis.append(math.pi)
    full_turn = phi_intervals == [(-math.pi, math.pi)]
    intervals = []
    dead_points = []
    for low, high in phi_intervals:
        centre = wrap_angle(0.5 * (low + high) + offset)
        half = 0.5 * (high - low)
        intervals.append((centre - half, centre + half))
        if not full_turn:
            dead_points.extend((centre - half, centre + half))
    return Reachability(
        intervals=tuple(intervals),
        dead_points=tuple(dead_points),
        change_points=tuple(wrap_angle(phi + offset) for phi in change_phis),
    )


@dataclass(frozen=True)
class Preset:
    """A named mechanism and the sign of its usual drive."""

    geometry: FourBar
    drive_sign: float
    description: str


_SEED_COUPLER = math.sqrt(1.09)

PRESETS: dict[str, Preset] = {
    "paper": Preset(
        FourBar(0.3, _SEED_COUPLER, 0.3, 1.3, 0.0),
        1.0,
        "the seed's mechanism: OA = BC = 0.3 m, OC = 1.3 m, AB = √1.09 m, C level with O",
    ),
    "paper_full_turn": Preset(
        FourBar(0.3, _SEED_COUPLER, 0.3, math.sqrt(1.09 - 0.6**2), 0.0),
        -1.0,
        "the seed's 'full revolution' redesign, driven clockwise; it cannot turn fully: the loop "
        "closes only for α in about [−211.3°, 31.3°]",
    ),
    "grashof_crank_rocker": Preset(
        FourBar(0.3, _SEED_COUPLER, 0.6, 1.0, 0.0),
        1.0,
        "a Grashof crank-rocker with the seed's coupler (OA = 0.3, BC = 0.6, OC = 1.0 m): the "
        "crank is the shortest link and turns fully",
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
