# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A single-degree-of-freedom planar loop of four joints, solved in closed form from one joint.

Conventions (in the loop's plane, counterclockwise about its normal; metres and radians):

* Joints 0..3 in cyclic order; body k joins joint k to joint k + 1 (indices mod 4); body 0 is
  the reference (angle 0). Joint 0 is the cut pin: revolute, never the known joint.
* Revolute joint k has φ_k = θ_k − θ_{k−1}, the angle of body k relative to body k − 1. The
  prismatic joint p has δ_p: the point of joint p on body p is the point of joint p on body p − 1
  plus δ_p·ŝ, ŝ = ``slide``/|``slide``| in body p − 1's frame (θ_p = θ_{p−1}).
* ``links[k]`` is the vector from joint k's point to joint k + 1's point, in body k's frame. All
  frames are aligned where every coordinate is 0 (the URDF's zero pose, so Σ links ≈ 0).

A loop of four revolute joints is the four-bar, solved by the existing closed form
(``kinematics.solver.solve``) after mapping: known joint k → ground = body k − 1, crank = body k
about joint k (crank angle α = φ_k exactly, the FourBar's frame turned so that φ_k = 0 puts pin
A at its lowest position), coupler = body k + 1, rocker = body k + 2; C is joint k − 1. Its branch
is the FourBar's: +1 where joint k + 2 lies left of the directed line joint k + 1 → joint k − 1.
A loop with one prismatic joint has its own closed forms (``prismatic_loop``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from decimal import Decimal, localcontext
from enum import StrEnum
from functools import lru_cache
import math
import operator

from linkage_kinematics.kinematics.continuation import check_branch, continued_branch
from linkage_kinematics.kinematics.decimal_arithmetic import DIGITS
from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import (
    FourBar,
    from_exact,
    GeometryError,
    Reachability,
    UnreachableError,
    wrap_angle,
)
from linkage_kinematics.kinematics.prismatic_loop import PrismaticLoop
from linkage_kinematics.kinematics.solver import DeadPointError, solve_at_rates, solve_many
import numpy as np

__all__ = [
    'branch_of', 'continued_branch_of', 'driven_loop', 'DrivenLoop', 'joint_points', 'JointKind',
    'known_joint_range', 'LoopState', 'PlanarLoop', 'solve_loop',
]

# |slide| must be 1 to this relative tolerance (a unit vector written as floats).
SLIDE_NORM_TOLERANCE = 1e-9
_CACHE_SIZE = 256


class JointKind(StrEnum):
    """What a joint of the loop lets its two bodies do relative to each other."""

    REVOLUTE = 'revolute'
    PRISMATIC = 'prismatic'


@dataclass(frozen=True)
class PlanarLoop:
    """A single-degree-of-freedom planar loop of four joints in cyclic order (module docstring)."""

    kinds: tuple[JointKind, JointKind, JointKind, JointKind]
    links: tuple[tuple[float, float], ...]
    slide: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        # Normalised to JointKind members and tuples of floats, so that loops compare and hash by
        # value whatever sequences they were given as.
        try:
            kinds = tuple(JointKind(kind) for kind in self.kinds)
        except (TypeError, ValueError):
            kinds = ()
        if len(kinds) != 4:
            raise GeometryError(f'kinds must be four JointKind values, got {self.kinds!r}')
        object.__setattr__(self, 'kinds', kinds)
        links = _vectors(self.links)
        if links is None or len(links) != 4:
            raise GeometryError(f'links must be four finite 2-vectors (m), got {self.links!r}')
        object.__setattr__(self, 'links', links)
        if self.kinds[0] is not JointKind.REVOLUTE:
            raise GeometryError('joint 0 (the cut pin) must be revolute')
        if self.kinds.count(JointKind.PRISMATIC) > 1:
            raise GeometryError('a loop of four joints with one degree of freedom has at most one '
                                f'prismatic joint, got kinds {[str(k) for k in self.kinds]}')
        if self.prismatic is None:
            if self.slide is not None:
                raise GeometryError('slide is given but no joint is prismatic')
            return
        slide = None if self.slide is None else _vectors((self.slide,))
        if slide is None:
            raise GeometryError(f'the prismatic joint needs a finite slide vector, got '
                                f'{self.slide!r}')
        object.__setattr__(self, 'slide', slide[0])
        if abs(math.hypot(*self.slide) - 1.0) > SLIDE_NORM_TOLERANCE:
            raise GeometryError(f'slide must be a unit vector, got {self.slide!r}')

    @property
    def prismatic(self) -> int | None:
        """Index of the prismatic joint, None for a four-bar."""
        return self.kinds.index(JointKind.PRISMATIC) if JointKind.PRISMATIC in self.kinds else None

    @property
    def closure_gap(self) -> float:
        """|Σ links| (m): how far the all-zero pose is from closing (the exporter's rounding)."""
        # Added in order, not with sum(): Python 3.12's sum() of floats compensates, and the
        # gap is all rounding, so it would read differently on the 3.11 and 3.12 this runs on.
        x = y = 0.0
        for link_x, link_y in self.links:
            x += link_x
            y += link_y
        return math.hypot(x, y)


def _vectors(values: object) -> tuple[tuple[float, float], ...] | None:
    """Return ``values`` as a tuple of finite 2-vectors of floats, None if they are not."""
    try:
        vectors = tuple(tuple(values[i]) for i in range(len(values)))
    except (TypeError, KeyError):
        return None
    for vector in vectors:
        if len(vector) != 2 or not all(
                isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)
                for x in vector):
            return None
    return tuple((float(vector[0]), float(vector[1])) for vector in vectors)


@dataclass(slots=True)
class LoopState:
    """
    The loop's coordinates (φ in rad, δ in m) of joints 0..3 and their time derivatives.

    ``branch`` is the assembly the state lies on (+1 or −1, see ``branch_of``). A value, not
    frozen because a frozen dataclass sets each field through ``object.__setattr__``: a loop
    sample made three times slower to build than this (``LinkageState`` says the same).
    """

    coordinates: tuple[float, float, float, float]
    rates: tuple[float, float, float, float]
    branch: int


def _check_known(loop: PlanarLoop, known: int) -> None:
    if known not in (1, 2, 3):
        raise ValueError(f'the known joint must be 1, 2 or 3 (joint 0 is the cut pin), got '
                         f'{known!r}')


def _angle(vector: tuple[float, float]) -> float:
    return math.atan2(vector[1], vector[0])


@lru_cache(maxsize=_CACHE_SIZE)
def _four_bar(loop: PlanarLoop, known: int) -> FourBar:
    """
    Return the four-bar seen from body known − 1 (module docstring), crank angle α = φ_known.

    C = joint known − 1 relative to O = joint known is c = −links[known − 1]; in the FourBar's
    frame, where the crank vector links[known] points straight down, it is (u × c, −u·c) with u
    the crank's unit vector. The dimensions are exact (60-digit decimals), and the FourBar's
    singular points are theirs (``geometry.from_exact``).
    """
    crank = loop.links[known]
    ground = loop.links[known - 1]
    try:
        with localcontext() as context:
            context.prec = DIGITS
            crank_x, crank_y = Decimal(crank[0]), Decimal(crank[1])
            to_c_x, to_c_y = -Decimal(ground[0]), -Decimal(ground[1])
            length = _length(crank)
            if length == 0:
                raise GeometryError(f'joint {known + 1} coincides with joint {known}: the crank '
                                    'has no length')
            dimensions = (length, _length(loop.links[(known + 1) % 4]),
                          _length(loop.links[(known + 2) % 4]),
                          (crank_x * to_c_y - crank_y * to_c_x) / length,
                          -(crank_x * to_c_x + crank_y * to_c_y) / length)
            return from_exact(dimensions)
    except GeometryError as error:
        raise GeometryError(f'the four-bar loop driven at joint {known}: {error}') from None


def _length(vector: tuple[float, float]) -> Decimal:
    return (Decimal(vector[0]) ** 2 + Decimal(vector[1]) ** 2).sqrt()


@lru_cache(maxsize=_CACHE_SIZE)
def _prismatic(loop: PlanarLoop, known: int) -> PrismaticLoop:
    return PrismaticLoop(loop.links, loop.slide, loop.prismatic, known)


class DrivenLoop:
    """
    A loop driven at one known joint, its constants resolved once (``driven_loop``).

    ``solve`` and ``continued_branch`` are ``solve_loop``'s and ``continued_branch_of``'s
    work for that joint: a caller that solves the same loop sample after sample (``LoopSolver``)
    keeps one, instead of looking the loop's four-bar or prismatic closed form up by the
    loop's hash at every call.
    """

    def __init__(self, loop: PlanarLoop, known: int) -> None:
        _check_known(loop, known)
        self.known = known
        self._prismatic = None if loop.prismatic is None else _prismatic(loop, known)
        if self._prismatic is None:
            self._linkage = _four_bar(loop, known)
            links = loop.links
            # The FourBar's frame is body known − 1's turned by arg(links[known]) + π/2.
            self._turn = _angle(links[known]) + 0.5 * math.pi
            self._coupler_angle = _angle(links[(known + 1) % 4])
            self._rocker_angle = _angle(links[(known + 2) % 4])
            # joints 0..3 from (known, known + 1, known + 2, known + 3), each mod 4
            self._in_joint_order = operator.itemgetter(*((index - known) % 4
                                                         for index in range(4)))

    def solve(self, value: float, rate: float, branch: int) -> LoopState:
        """Return the loop's state as ``solve_loop`` does, for this loop and known joint."""
        known = self.known
        if branch != 1 and branch != -1:
            check_branch(branch)
        if not math.isfinite(value) or not math.isfinite(rate):
            raise UnreachableError(f'joint {known}: value and rate must be finite, got '
                                   f'{value!r}, {rate!r}')
        if self._prismatic is not None:
            coordinates, rates = self._prismatic.solve(value, rate, branch)
            return LoopState(coordinates, rates, branch)
        try:
            state = solve_at_rates(self._linkage, value, rate, 0.0, branch)
        except (DeadPointError, UnreachableError) as error:
            raise type(error)(f'joint {known}: {error}') from None
        turn = self._turn
        coupler = state.gamma + turn - self._coupler_angle  # θ_{k+1} − θ_{k−1}
        rocker = -state.beta + turn - self._rocker_angle  # θ_{k+2} − θ_{k−1}
        omega_ab, omega_bc = state.omega_ab, state.omega_bc
        in_joint_order = self._in_joint_order
        return LoopState(
            in_joint_order((value, wrap_angle(coupler - value), wrap_angle(rocker - coupler),
                            wrap_angle(-rocker))),
            in_joint_order((rate, omega_ab - rate, omega_bc - omega_ab, -omega_bc)), branch)

    def positions_many(self, values: np.ndarray, branch: int) -> tuple[np.ndarray, ...] | None:
        """
        Return ``solve``'s coordinates at many values of the known joint, a motion's points.

        ``branch``: the branch at ``values[0]``; each point's by ``continued_branch`` from
        there (a motion's branch depends on where it is, not on how it got there). The same
        closed form over arrays (``solver.solve_many``), so the same angles to a few ulps.
        None where any point is refused (out of reach, at a dead point) or the loop is
        prismatic: the caller then solves point by point, which names the refusal.
        """
        if self._prismatic is not None:
            return None
        branches = np.asarray(continued_branch(self._linkage, float(values[0]), branch, values))
        try:
            state = solve_many(self._linkage, values, DriveLaw(0.0), branches)
        except (DeadPointError, UnreachableError):
            return None
        turn = self._turn
        coupler = state.gamma + turn - self._coupler_angle
        rocker = -state.beta + turn - self._rocker_angle
        return self._in_joint_order((values, _wrap_many(coupler - values),
                                     _wrap_many(rocker - coupler), _wrap_many(-rocker)))

    def continued_branch(self, value_from: float, branch: int, value_to: float) -> int:
        """Return the branch at ``value_to`` as ``continued_branch_of`` does for this loop."""
        if self._prismatic is not None:
            return self._prismatic.continued_branch(value_from, branch, value_to)
        return int(continued_branch(self._linkage, value_from, branch, value_to))


def _wrap_many(angles: np.ndarray) -> np.ndarray:
    """Return ``wrap_angle`` of each angle: to (−π, π]."""
    turn = 2.0 * math.pi
    wrapped = angles - turn * np.round(angles / turn)
    return np.where(wrapped <= -math.pi, wrapped + turn, wrapped)


@lru_cache(maxsize=_CACHE_SIZE)
def driven_loop(loop: PlanarLoop, known: int) -> DrivenLoop:
    """Return ``loop`` driven at joint ``known`` (1, 2 or 3), its constants resolved."""
    return DrivenLoop(loop, known)


def solve_loop(loop: PlanarLoop, known: int, value: float, rate: float,
               branch: int) -> LoopState:
    """
    Return the loop's coordinates and rates with joint ``known`` at ``value`` moving at ``rate``.

    ``branch`` names the assembly at ``value`` (``branch_of``). Raises DeadPointError at a dead
    point of the known joint (where a one-ulp change of ``value`` would move the exact
    accelerations by more than ``singular_points.RATE_ACCURACY``) and UnreachableError where the
    loop does not close at ``value``. Never returns NaN.
    """
    return driven_loop(loop, known).solve(value, rate, branch)


def joint_points(loop: PlanarLoop, coordinates: tuple[float, ...]
                 ) -> tuple[tuple[tuple[float, float], ...], tuple[float, ...]]:
    """
    Return the joints' points (joint k's on body k) and the bodies' angles θ_k, in body 0's frame.

    The forward kinematics of the open chain joint 0 → 1 → 2 → 3; joint 0 is at the origin. The
    loop closes where the chain's end, joint 3's point plus body 3's link, is back at the origin.
    """
    points = [(0.0, 0.0)]
    angles = [0.0]
    if loop.prismatic is not None:
        norm = math.hypot(*loop.slide)
        slide = (loop.slide[0] / norm, loop.slide[1] / norm)  # ŝ, as the closed forms take it
    for joint in (1, 2, 3):
        theta = angles[-1]
        cosine, sine = math.cos(theta), math.sin(theta)
        link_x, link_y = loop.links[joint - 1]
        if loop.kinds[joint] is JointKind.PRISMATIC:
            link_x += coordinates[joint] * slide[0]
            link_y += coordinates[joint] * slide[1]
        else:
            theta += coordinates[joint]
        previous_x, previous_y = points[-1]
        points.append((previous_x + cosine * link_x - sine * link_y,
                       previous_y + sine * link_x + cosine * link_y))
        angles.append(theta)
    return tuple(points), tuple(angles)


def branch_of(loop: PlanarLoop, known: int, coordinates: tuple[float, ...]) -> int:
    """
    Return the assembly branch (+1 or −1) that ``coordinates`` lie on, joint ``known`` driving.

    Four-bar: +1 where joint known + 2 lies left of the directed line joint known + 1 → joint
    known − 1. Loops with a prismatic joint: ``prismatic_loop.PrismaticLoop.side``. Where the two
    assemblies meet (a dead or change point: the side is zero) the result is +1.
    """
    _check_known(loop, known)
    points, angles = joint_points(loop, coordinates)
    if loop.prismatic is not None:
        side = _prismatic(loop, known).side(points, angles)
    else:
        origin = points[(known + 1) % 4]
        to_line = _difference(points[(known + 3) % 4], origin)
        to_pin = _difference(points[(known + 2) % 4], origin)
        side = to_line[0] * to_pin[1] - to_line[1] * to_pin[0]
    return -1 if side < 0.0 else 1


def _difference(point: tuple[float, float], origin: tuple[float, float]) -> tuple[float, float]:
    return point[0] - origin[0], point[1] - origin[1]


def continued_branch_of(loop: PlanarLoop, known: int, value_from: float, branch: int,
                        value_to: float) -> int:
    """
    Return the branch at ``value_to`` of a smooth motion of joint ``known`` from ``value_from``.

    The motion has ``branch`` at ``value_from``; it continues through change points on the smooth
    branch, so the branch flips at each change point passed (``kinematics.continued_branch``).
    """
    return driven_loop(loop, known).continued_branch(value_from, branch, value_to)


def known_joint_range(loop: PlanarLoop, known: int) -> Reachability:
    """Return where joint ``known`` can go when it drives the loop, its dead and change points."""
    _check_known(loop, known)
    if loop.prismatic is not None:
        return _prismatic(loop, known).range
    reachability = _four_bar(loop, known).reachability
    return replace(reachability, joint=known)
