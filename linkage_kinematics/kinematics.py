# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Exact positions, rates and accelerations of the four-bar, for one α or for arrays of α.

Positions come from loop closure: B is where the circle of radius AB about A meets the circle of
radius BC about C. With d = |C − A|, u the unit vector A→C and u⊥ it turned by +90°,

    B − A = x·u + σ·h·u⊥,   B − C = (x − d)·u + σ·h·u⊥,
    x = (AB² − BC² + d²)/(2d),  4·d²·h² = ((AB + BC)² − d²)·(d² − (AB − BC)²)

(σ the branch). Near a dead point a each factor is evaluated from α − a (a held to twice double
precision, ``geometry.LoopClosure``), so h is exact to rounding however close α is; at a change
point (a double zero) as 4·OA·OC·sin²(½(α − a)), whose root continues analytically.

Rates solve the differentiated loop A + AB·e_AB = C + BC·e_BC. Writing e⊥ for a unit vector
turned by +90° and S = e_AB × e_BC (= σ·h·d/(AB·BC), the sine of the transmission angle):

    ω_AB = −(v_A·e_BC)/(AB·S),      ω_BC = −(v_A·e_AB)/(BC·S)
    ω̇_AB = −(w·e_BC)/(AB·S),       ω̇_BC = −(w·e_AB)/(BC·S)
    w = a_A − AB·ω_AB²·e_AB + BC·ω_BC²·e_BC

which is Cramer's rule on the 2×2 velocity and acceleration systems. For a change-point linkage
the system is singular at its change points while the motion is smooth; there the rates come
from an analytic form with the common factor of numerator and S taken out
(``_smooth_rate_terms``), finite and exact at the change point itself.

Branches. ``branch`` is the side of B relative to the directed line A→C at the α solved for
(+1 left, −1 right; at a change point itself, the side just counterclockwise of it). A real
mechanism driven through a change point continues on the smooth branch, on which B crosses
that line: ``continued_branch(linkage, alpha_start, branch, alpha, turns)`` gives the side at α
of the motion that has ``branch`` at ``alpha_start``. With an odd number of change points per
turn the smooth motion repeats only every two turns; ``turns`` lets a caller that keeps α within
one pass (the node) get the branch of any later turn.

Refusal. ``solve`` raises DeadPointError only where a one-ulp change of the float α moves the
exact accelerations by more than RATE_ACCURACY (δ < 1500·ulp(α) from a dead point), and where
pin A meets C in a linkage with OA = OC and AB = BC.

One function serves the scalar path (``math`` on floats, the node's hot path) and the
vectorised path (``numpy`` on arrays, sweeps and benchmarks; long arrays go through it in
cache-sized pieces).
"""

from __future__ import annotations

from dataclasses import dataclass, fields
import math
from typing import Callable, Union

from linkage_kinematics.drive import DriveLaw
from linkage_kinematics.geometry import (
    _PLAIN,
    _TOUCH,
    ANGLE_TOLERANCE,
    FourBar,
    LoopClosure,
    TWO_PI,
    UnreachableError,
)
import numpy as np

FloatOrArray = Union[float, np.ndarray]

# solve refuses a crank angle so close to a dead point that a one-ulp change of α would move the
# exact accelerations by more than this (relative): no float64 answer could be that accurate.
RATE_ACCURACY = 1e-3


class DeadPointError(ValueError):
    """Coupler and rocker are collinear: the crank cannot drive the rates there."""


@dataclass(frozen=True, slots=True)
class CrankRates:
    """
    The crank's angular velocity ω (rad/s) and acceleration ω̇ (rad/s²) at the α solved for.

    Given instead of a drive law where the crank's motion is measured, not commanded: ``solve``
    then takes its rates as they are.
    """

    omega: float
    omega_dot: float


@dataclass(frozen=True, slots=True)
class LinkageState:
    """
    Everything the seed tabulates and plots, for one configuration or an array of them.

    Angles in rad (seed conventions, see ``geometry``), angular rates counterclockwise-positive
    in rad/s and rad/s², pin coordinates in m, velocities in m/s, accelerations in m/s², all in
    the frame with O at the origin.
    """

    alpha: FloatOrArray
    beta: FloatOrArray
    gamma: FloatOrArray
    omega: FloatOrArray
    omega_dot: FloatOrArray
    omega_ab: FloatOrArray
    omega_bc: FloatOrArray
    omega_dot_ab: FloatOrArray
    omega_dot_bc: FloatOrArray
    pin_a_x: FloatOrArray
    pin_a_y: FloatOrArray
    pin_b_x: FloatOrArray
    pin_b_y: FloatOrArray
    velocity_a_x: FloatOrArray
    velocity_a_y: FloatOrArray
    velocity_b_x: FloatOrArray
    velocity_b_y: FloatOrArray
    acceleration_a_x: FloatOrArray
    acceleration_a_y: FloatOrArray
    acceleration_b_x: FloatOrArray
    acceleration_b_y: FloatOrArray
    transmission_angle: FloatOrArray

    @property
    def v_a(self) -> FloatOrArray:
        """Speed of pin A (m/s)."""
        return np.hypot(self.velocity_a_x, self.velocity_a_y)

    @property
    def v_b(self) -> FloatOrArray:
        """Speed of pin B (m/s)."""
        return np.hypot(self.velocity_b_x, self.velocity_b_y)

    def at(self, index: int) -> LinkageState:
        """Return the configuration at ``index`` of an array state, as a state of floats."""
        return LinkageState(*(float(getattr(self, f.name)[index]) for f in fields(self)))


class _StateBuilder:
    """
    Storage laid out like LinkageState, filled by plain slot stores, then turned into one.

    A frozen dataclass sets each field through object.__setattr__, which for 22 fields costs
    more than the closed form's arithmetic; ``solve`` builds its result this way instead.
    """

    __slots__ = LinkageState.__slots__


MathFunctions = tuple[Callable, Callable, Callable, Callable, Callable]
_SCALAR_MATH: MathFunctions = (math.sin, math.cos, math.sqrt, math.atan2, abs)
_ARRAY_MATH: MathFunctions = (np.sin, np.cos, np.sqrt, np.arctan2, np.abs)
# Arrays longer than this are solved in pieces of this many angles, so that the closed form's
# temporaries stay in cache instead of streaming whole arrays through memory.
_CHUNK = 8192


# Where AB + BC − d and d − |AB − BC| both exceed this fraction of d, the factors are taken
# from d (their relative error is then at most a few roundings) instead of from α's offsets to
# the singular angles: the scalar path's shortcut for ordinary angles.
_FAR = 0.0625
# |sin(½(α − a))| below which α is checked against the refusal rule: ½δ for the refusal zone's
# widest δ ≈ 1500·ulp(α) at |α| up to ~3e6 rad.
_NEAR_DEAD = 1e-6
# Below this |sin(½(α − a))| the half-angle sine is recomputed from α − a less whole turns
# held exactly (``_half_sine``); above it, the rounding of α − a is harmless beside it.
_NEAR_HALF_SINE = 0.25


def _corrected_half_sine(alpha: FloatOrArray, point: tuple[float, float], difference: FloatOrArray,
                         value: FloatOrArray, sin: Callable) -> FloatOrArray:
    """
    sin(½(α − a)) for a singular angle a (a double-double).

    Given ``value`` = sin(½((α − a_high) − a_low)) and ``difference`` = α − a_high: to rounding of
    the result even where it vanishes. Within half a turn of a, ``value`` carries only the rounding
    of the result; near another turn's image of a, α − a − 2π·k is taken exactly instead (Dekker's
    product for 2π·k), so that the sine keeps its sign and relative accuracy next to the zero after
    many turns too. Call it for a float only where -π ≤ difference ≤ π fails and |value| <
    _NEAR_HALF_SINE.
    """
    if isinstance(value, np.ndarray):
        near = (np.abs(value) < _NEAR_HALF_SINE) & (np.abs(difference) > math.pi)
        if not np.any(near):
            return value
        turns = np.round(difference / TWO_PI)
        exact = sin(0.5 * _offset(alpha, point, turns)) * (1.0 - 2.0 * (turns % 2.0))
        return np.where(near, exact, value)
    turns = float(round(difference / TWO_PI))
    exact = sin(0.5 * _offset(alpha, point, turns))
    return -exact if turns % 2.0 else exact


def _half_sine(alpha: FloatOrArray, point: tuple[float, float], sin: Callable) -> FloatOrArray:
    """sin(½(α − a)) for a singular angle a, as ``_corrected_half_sine`` describes."""
    high, low = point
    difference = alpha - high
    value = sin(0.5 * (difference - low))
    if isinstance(value, np.ndarray) or not (
            -math.pi <= difference <= math.pi or abs(value) >= _NEAR_HALF_SINE):
        return _corrected_half_sine(alpha, point, difference, value, sin)
    return value


def _exact_factors(
    closure: LoopClosure, alpha: FloatOrArray, distance: FloatOrArray, xp: MathFunctions
) -> tuple[FloatOrArray, FloatOrArray, FloatOrArray, FloatOrArray | None]:
    """
    Heron's two factors (AB + BC)² − d² and d² − (AB − BC)².

    Each in the form geometry.LoopFactor names: from d; from the offsets to its two dead points a₁,
    a₂ as ∓4·OA·OC·sin(½(α − a₁))·sin(½(α − a₂)); or touching zero as gap + 4·OA·OC·sin²(½(α − a)).

    Also whether the loop closes (a touching factor is ≥ 0 by construction, 0 at a change point,
    where the loop closes) and the least |sin(½(α − a))| over the dead points a (for a float,
    only if below _NEAR_DEAD; None if there is none).
    """
    sin = xp[0]
    scale = closure.scale
    nearest_dead = None
    closes = True
    factors = []
    for part, orientation in ((closure.stretched, -1.0), (closure.folded, 1.0)):
        kind = part.kind
        if kind == _PLAIN:
            length = part.length
            value = orientation * (distance - length) * (distance + length)
            closes = closes & (value > 0.0)
            factors.append(value)
            continue
        high, low = part.first
        difference = alpha - high
        first = sin(0.5 * (difference - low))
        if (xp is _ARRAY_MATH or not (-math.pi <= difference <= math.pi
                                      or abs(first) >= _NEAR_HALF_SINE)):
            first = _corrected_half_sine(alpha, part.first, difference, first, sin)
        if kind == _TOUCH:
            factors.append(part.gap + scale * first * first)
            continue
        high, low = part.second
        difference = alpha - high
        second = sin(0.5 * (difference - low))
        if (xp is _ARRAY_MATH or not (-math.pi <= difference <= math.pi
                                      or abs(second) >= _NEAR_HALF_SINE)):
            second = _corrected_half_sine(alpha, part.second, difference, second, sin)
        value = orientation * scale * first * second
        closes = closes & (value > 0.0)
        first = abs(first)
        second = abs(second)
        if xp is _ARRAY_MATH:
            near = np.minimum(first, second)
            nearest_dead = near if nearest_dead is None else np.minimum(nearest_dead, near)
        else:
            # only a float within the refusal check's reach is reported
            near = first if first < second else second
            if near < _NEAR_DEAD and (nearest_dead is None or near < nearest_dead):
                nearest_dead = near
        factors.append(value)
    stretched, folded = factors
    if closure.passes_through_pivot:
        closes = closes & (distance >= PIVOT_PASSAGE * closure.ground)
    # Where the loop does not close, B is placed on the dead point (h = 0): solve refuses
    # there, and solve_pose gives the interval end for an α within its tolerance.
    return stretched * (stretched > 0.0), folded * (folded > 0.0), closes, nearest_dead


def _smooth_rate_terms(
    linkage: FourBar, branch: int | np.ndarray, alpha: FloatOrArray, stretched: FloatOrArray,
    folded: FloatOrArray, distance_squared: FloatOrArray, distance: FloatOrArray,
    xp: MathFunctions,
) -> tuple[FloatOrArray, ...]:
    """
    P − OA, q, Q = q/h and dQ/dα of a change-point linkage.

    Analytic through its change points.

    With p = C·â and q = C·â⊥ (â = A/OA, â⊥ its derivative in α), the rates are
    dγ/dα = −OA·((p − OA) + (x − d)·Q)/d² with Q = q/h (``_closed_form``). At a change point
    q and h vanish together; here both are written with their common factor m (the sine of half
    the crank's offset from the change point, or the product of two) taken out:
    q = n·m and h = σ_a·m·R with R > 0, so Q = σ_a·n/R stays finite and smooth. σ_a is the
    analytic branch: the requested side of B times the sign of m (at m = 0, the side just
    counterclockwise of the change point).
    """
    sin, cos, sqrt, _, _ = xp
    closure = linkage.closure
    crank = linkage.crank_length
    ground = closure.ground
    half_scale = 0.25 * closure.scale  # OA·OC
    # sin and cos of ½φ, φ = α − α₀, each from the crank's offset to the angle where it vanishes
    sin_half = _half_sine(alpha, closure.direction, sin)
    cos_half = -_half_sine(alpha, closure.opposite, sin)
    # p = OC·cos φ, q = −OC·sin φ
    p_minus_crank = ground * (cos_half - sin_half) * (cos_half + sin_half) - crank
    q = -2.0 * ground * sin_half * cos_half
    if closure.folded.is_change and closure.stretched.is_change:
        # m = sin(½φ)·sin(½(φ − π)), q = 2·OC·m, R = 2·OA·OC/d
        vanishing = -sin_half * cos_half
        # at m = 0, the sign just counterclockwise is the other factor's
        other = (np.where(sin_half == 0.0, -cos_half, sin_half) if isinstance(sin_half, np.ndarray)
                 else -cos_half if sin_half == 0.0 else sin_half)
        numerator = 2.0 * ground
        numerator_rate = 0.0
        radius = 2.0 * half_scale / distance
        radius_rate = 0.0
    elif closure.folded.is_change:
        # m = sin(½φ), n = −2·OC·cos(½φ), R = √(OA·OC·stretched)/d
        vanishing = sin_half
        other = 1.0
        numerator = -2.0 * ground * cos_half
        numerator_rate = ground * sin_half
        radius = sqrt(half_scale * stretched) / distance
        radius_rate = crank * q / stretched
    else:
        # m = sin(½(φ − π)) = −cos(½φ), n = 2·OC·sin(½φ), R = √(OA·OC·folded)/d
        vanishing = -cos_half
        other = 1.0
        numerator = 2.0 * ground * sin_half
        numerator_rate = ground * cos_half
        radius = sqrt(half_scale * folded) / distance
        radius_rate = -crank * q / folded
    # R'/R = radius_rate + OA·q/d²
    radius_log_rate = radius_rate + crank * q / distance_squared
    if isinstance(vanishing, np.ndarray):
        analytic = branch * np.where(vanishing == 0.0, np.sign(other), np.sign(vanishing))
    else:
        analytic = branch * math.copysign(1.0, other if vanishing == 0.0 else vanishing)
    ratio = analytic * numerator / radius
    ratio_rate = analytic * (numerator_rate - numerator * radius_log_rate) / radius
    return p_minus_crank, q, ratio, ratio_rate


def _closed_form(
    linkage: FourBar, branch: int | np.ndarray, alpha: FloatOrArray,
    drive: DriveLaw | CrankRates | None,
    xp: MathFunctions,
) -> tuple[FloatOrArray, ...]:
    """
    Evaluate the closed form.

    The 22 LinkageState fields in order, then S = sin μ (signed), whether the loop closes (both
    factors > 0, or a change factor ≥ 0), and the smallest |sin(½(α − a))| over the dead points a
    (None without dead points or far from them).

    With ``drive`` None, only the positions: α, β, γ, pin A, pin B, μ, then the same three.
    ``xp`` is (sin, cos, sqrt, atan2, abs) from ``math`` or ``numpy``.
    """
    sin, cos, sqrt, atan2, _ = xp
    closure = linkage.closure
    (crank, coupler, rocker, ground_x, ground_y, reach, difference, squares,
     plain_where_far) = closure.constants
    sin_alpha = sin(alpha)
    cos_alpha = cos(alpha)
    pin_a_x = crank * sin_alpha
    pin_a_y = -crank * cos_alpha
    to_c_x = ground_x - pin_a_x
    to_c_y = ground_y - pin_a_y
    distance_squared = to_c_x * to_c_x + to_c_y * to_c_y
    distance = sqrt(distance_squared)
    stretched = reach - distance
    folded = distance - difference
    if xp is _SCALAR_MATH and plain_where_far:
        if stretched >= _FAR * distance and folded >= _FAR * distance:
            # Far from every zero of the factors, d's own rounding is harmless beside them: the
            # cheaper product from d, with the loop surely closed and no dead point near.
            stretched *= reach + distance
            folded *= distance + difference
            closes = True
            nearest_dead = None
        else:
            stretched, folded, closes, nearest_dead = _exact_factors(closure, alpha, distance, xp)
    elif plain_where_far:
        # The same choice for each element of an array.
        near = (stretched < _FAR * distance) | (folded < _FAR * distance)
        stretched = stretched * (reach + distance)
        folded = folded * (distance + difference)
        closes = np.ones(alpha.shape, dtype=bool)
        nearest_dead = None
        if np.any(near):
            (stretched[near], folded[near], closes[near], nearest) = _exact_factors(
                closure, alpha[near], distance[near], xp)
            if nearest is not None:
                nearest_dead = np.full(alpha.shape, np.inf)
                nearest_dead[near] = nearest
    else:
        stretched, folded, closes, nearest_dead = _exact_factors(closure, alpha, distance, xp)
    heron = stretched * folded
    two_distance = 2.0 * distance
    u_x = to_c_x / distance
    u_y = to_c_y / distance
    along = (squares + distance_squared) / two_distance
    height = branch * sqrt(heron) / two_distance
    rocker_along = along - distance
    coupler_x = along * u_x - height * u_y
    coupler_y = along * u_y + height * u_x
    rocker_x = rocker_along * u_x - height * u_y
    rocker_y = rocker_along * u_y + height * u_x
    sine = height * distance / (coupler * rocker)
    e_ab_x = coupler_x / coupler
    e_ab_y = coupler_y / coupler
    e_bc_x = rocker_x / rocker
    e_bc_y = rocker_y / rocker
    cosine = e_ab_x * e_bc_x + e_ab_y * e_bc_y
    if drive is None:
        return (alpha, atan2(rocker_y, -rocker_x), atan2(coupler_y, coupler_x), pin_a_x,
                pin_a_y, ground_x + rocker_x, ground_y + rocker_y, atan2(abs(sine), cosine),
                sine, closes, nearest_dead)

    if type(drive) is CrankRates:
        omega = drive.omega
        omega_dot = drive.omega_dot
    else:
        omega = drive.omega0 + drive.k * alpha
        omega_dot = drive.k * omega
    # v_A = OA·ω·(cos α, sin α); a_A = OA·ω̇·(cos α, sin α) − OA·ω²·(sin α, −cos α)
    crank_omega = crank * omega
    omega_squared = omega * omega
    velocity_a_x = crank_omega * cos_alpha
    velocity_a_y = crank_omega * sin_alpha
    acceleration_a_x = crank * (omega_dot * cos_alpha - omega_squared * sin_alpha)
    acceleration_a_y = crank * (omega_dot * sin_alpha + omega_squared * cos_alpha)

    if not closure.change_points:
        # Cramer's rule on the differentiated loop (module docstring).
        coupler_sine = coupler * sine
        rocker_sine = rocker * sine
        omega_ab = -(velocity_a_x * e_bc_x + velocity_a_y * e_bc_y) / coupler_sine
        omega_bc = -(velocity_a_x * e_ab_x + velocity_a_y * e_ab_y) / rocker_sine
        coupler_centripetal = coupler * omega_ab * omega_ab
        rocker_centripetal = rocker * omega_bc * omega_bc
        w_x = acceleration_a_x - coupler_centripetal * e_ab_x + rocker_centripetal * e_bc_x
        w_y = acceleration_a_y - coupler_centripetal * e_ab_y + rocker_centripetal * e_bc_y
        omega_dot_ab = -(w_x * e_bc_x + w_y * e_bc_y) / coupler_sine
        omega_dot_bc = -(w_x * e_ab_x + w_y * e_ab_y) / rocker_sine
    else:
        # The analytic rates of a change-point linkage (_smooth_rate_terms): with x = along
        # A→C and G = dγ/dα, G_BC = d(angle of C→B)/dα,
        #   G = −OA·((p − OA) + (x − d)·Q)/d²,  G_BC = −OA·((p − OA) + x·Q)/d²
        # and their α-derivatives, from p' = q, q' = −p, (d²)' = −2·OA·q, x' = OA·q·(x − d)/d².
        p_minus_crank, q, ratio, ratio_rate = _smooth_rate_terms(
            linkage, branch, alpha, stretched, folded, distance_squared, distance, xp)
        scale = -crank / distance_squared
        drift = crank * q / distance_squared
        coupler_rate = scale * (p_minus_crank + rocker_along * ratio)
        rocker_rate = scale * (p_minus_crank + along * ratio)
        coupler_curvature = scale * (
            q + rocker_along * ratio_rate
            + drift * (along * ratio + 2.0 * p_minus_crank + 2.0 * rocker_along * ratio))
        rocker_curvature = scale * (
            q + along * ratio_rate
            + drift * (rocker_along * ratio + 2.0 * p_minus_crank + 2.0 * along * ratio))
        omega_ab = omega * coupler_rate
        omega_bc = omega * rocker_rate
        omega_dot_ab = omega_dot * coupler_rate + omega_squared * coupler_curvature
        omega_dot_bc = omega_dot * rocker_rate + omega_squared * rocker_curvature
        rocker_centripetal = rocker * omega_bc * omega_bc

    rocker_tangential = rocker * omega_dot_bc
    return (
        alpha,
        atan2(rocker_y, -rocker_x),
        atan2(coupler_y, coupler_x),
        omega,
        omega_dot,
        omega_ab,
        omega_bc,
        omega_dot_ab,
        omega_dot_bc,
        pin_a_x,
        pin_a_y,
        ground_x + rocker_x,
        ground_y + rocker_y,
        velocity_a_x,
        velocity_a_y,
        -omega_bc * rocker_y,
        omega_bc * rocker_x,
        acceleration_a_x,
        acceleration_a_y,
        -rocker_tangential * e_bc_y - rocker_centripetal * e_bc_x,
        rocker_tangential * e_bc_x - rocker_centripetal * e_bc_y,
        atan2(abs(sine), cosine),
        sine,
        closes,
        nearest_dead,
    )


def _check_branch(branch: int) -> None:
    if branch not in (1, -1):
        raise ValueError(f'branch must be +1 or -1, got {branch!r}')


def _too_close(alpha: float, nearest_dead: float | None) -> bool:
    """
    Tell whether α is too close to a dead point for float64.

    It is when a one-ulp change of α moves the exact accelerations by more than RATE_ACCURACY
    (they grow as δ^(−3/2): by 1.5·ulp(α)/δ).
    """
    # nearest_dead = |sin(½δ)| ≈ ½δ
    return nearest_dead is not None and 1.5 * math.ulp(alpha) > RATE_ACCURACY * 2.0 * nearest_dead


def _dead_point_message(alpha: float) -> str:
    return (
        f'crank angle α = {math.degrees(alpha):.9f}° is at a dead point: coupler and rocker are '
        'collinear, so the rates are undefined (closer than a one-ulp change of α moving the '
        f'accelerations by {RATE_ACCURACY:.1%})'
    )


# A linkage whose pin A passes through C (OA = OC, AB = BC) is refused this close to it,
# relative to OC: there coupler and rocker lie on each other and can turn together about the
# joined pins, so the motion is undetermined at the point, and on the way to it the direction
# A→C, taken from C − A, carries its rounding divided by |C − A|: the accelerations lose
# accuracy as ~2e-16·(OC/|C − A|)³ (2.4e-4 relative at this distance, docs/kinematics.md).
PIVOT_PASSAGE = 1e-4


def _check_pivot_passage(linkage: FourBar, alpha: FloatOrArray) -> None:
    distance = np.hypot(linkage.ground_x - linkage.crank_length * np.sin(alpha),
                        linkage.ground_y + linkage.crank_length * np.cos(alpha))
    close = distance < PIVOT_PASSAGE * linkage.closure.ground
    if np.any(close):
        angle = float(np.asarray(alpha).reshape(-1)[int(np.argmax(np.reshape(close, -1)))])
        raise DeadPointError(
            f'crank angle α = {math.degrees(angle):.9f}° puts pin A on the pivot C (OA = OC, '
            'AB = BC): coupler and rocker lie on each other and can turn together about it, so '
            'the motion is undetermined there'
        )


def _check_closure(linkage: FourBar, alpha: float, closes: bool,
                   nearest_dead: float | None) -> None:
    """Raise as ``solve`` does where the loop does not close or α is too close to a dead point."""
    if not closes:
        raise _refuse(linkage, alpha)
    if nearest_dead is not None and nearest_dead < _NEAR_DEAD and _too_close(alpha, nearest_dead):
        raise DeadPointError(_dead_point_message(alpha))


def _refuse(linkage: FourBar, alpha: float) -> ValueError:
    """
    Return the error for an α where the loop does not close.

    UnreachableError for a non-finite α or outside the reachable set (with its tolerance),
    DeadPointError at an interval end or with pin A on the pivot C.
    """
    if not math.isfinite(alpha):
        return UnreachableError(f'crank angle α must be finite, got {alpha!r}')
    if linkage.closure.passes_through_pivot:
        try:
            _check_pivot_passage(linkage, alpha)
        except DeadPointError as error:
            return error
    try:
        linkage.reachability.require(alpha)
    except UnreachableError as error:
        return error
    return DeadPointError(_dead_point_message(alpha))


def solve(
    linkage: FourBar, alpha: float, drive: DriveLaw | CrankRates, branch: int = 1
) -> LinkageState:
    """
    Return the exact state at one crank angle (the node's hot path).

    The crank's rates come from ``drive``: a drive law's ω = ω0 + k·α and ω̇ = k·ω at α, or
    ``CrankRates`` given as they are (a measured crank).

    ``branch`` is the side of B relative to the line A→C at this α (+1 left, −1 right); at a
    change point itself, where the sides meet, the side just counterclockwise of it. To follow a
    motion through change points, take the branch from ``continued_branch``.

    Raises UnreachableError outside the reachable set and DeadPointError at a dead point: within
    the distance where a one-ulp change of α moves the exact accelerations by more than
    RATE_ACCURACY (``solve_pose`` still gives the positions there). The state returned never
    holds NaN or inf.
    """
    if branch != 1 and branch != -1:
        _check_branch(branch)
    try:
        values = _closed_form(linkage, branch, alpha, drive, _SCALAR_MATH)
    except ZeroDivisionError:
        # S = 0: past or on a dead point (the loop does not close), or pin A on the pivot C.
        raise _refuse(linkage, alpha) from None
    except ValueError:
        # math.sin of ±inf, or rounding NaN to whole turns
        raise _refuse(linkage, alpha) from None
    if values[23] is not True or values[24] is not None:
        _check_closure(linkage, alpha, values[23], values[24])
    state = _StateBuilder()
    (
        state.alpha,
        state.beta,
        state.gamma,
        state.omega,
        state.omega_dot,
        state.omega_ab,
        state.omega_bc,
        state.omega_dot_ab,
        state.omega_dot_bc,
        state.pin_a_x,
        state.pin_a_y,
        state.pin_b_x,
        state.pin_b_y,
        state.velocity_a_x,
        state.velocity_a_y,
        state.velocity_b_x,
        state.velocity_b_y,
        state.acceleration_a_x,
        state.acceleration_a_y,
        state.acceleration_b_x,
        state.acceleration_b_y,
        state.transmission_angle,
        _,
        _,
        _,
    ) = values
    state.__class__ = LinkageState
    return state


@dataclass(frozen=True, slots=True)
class LinkagePose:
    """Where the links are at one crank angle: what is still defined at a dead point."""

    alpha: float
    beta: float
    gamma: float
    pin_a_x: float
    pin_a_y: float
    pin_b_x: float
    pin_b_y: float
    transmission_angle: float


def solve_pose(linkage: FourBar, alpha: float, branch: int = 1) -> LinkagePose:
    """
    Return the positions alone at one crank angle, at a dead point too (where ``solve`` raises).

    ``branch`` as in ``solve``. Raises UnreachableError outside the reachable set.
    """
    if not math.isfinite(alpha):
        raise UnreachableError(f'crank angle α must be finite, got {alpha!r}')
    _check_branch(branch)
    if linkage.closure.passes_through_pivot:
        _check_pivot_passage(linkage, alpha)
    *pose, _, closes, _ = _closed_form(linkage, branch, alpha, None, _SCALAR_MATH)
    if not closes:
        # On the interval end (within its tolerance) the positions are the dead point's.
        linkage.reachability.require(alpha)
    return LinkagePose(*pose)


def solve_many(
    linkage: FourBar, alpha: np.ndarray, drive: DriveLaw, branch: int | np.ndarray = 1
) -> LinkageState:
    """
    Return the exact states at an array of crank angles, as a LinkageState of arrays.

    ``branch`` is one side for all angles or an array of sides, one per angle (as
    ``continued_branch`` gives for a motion through change points). Raises, naming the first
    offending α, if any α is unreachable or at a dead point (as ``solve``).
    """
    alpha = np.asarray(alpha, dtype=float)
    if not np.all(np.isfinite(alpha)):
        raise UnreachableError('crank angles must be finite')
    if isinstance(branch, np.ndarray):
        if branch.shape != alpha.shape or not np.all(np.abs(branch) == 1):
            raise ValueError('branch must be +1 or -1, or an array of them shaped like alpha')
        branch = branch.astype(float)
    else:
        _check_branch(branch)
    with np.errstate(divide='ignore', invalid='ignore'):
        flat_alpha = alpha.reshape(-1)
        flat_branch = branch.reshape(-1) if isinstance(branch, np.ndarray) else branch
        columns = [np.empty(flat_alpha.size) for _ in range(len(fields(LinkageState)) - 1)]
        for start in range(0, flat_alpha.size, _CHUNK):
            piece = slice(start, start + _CHUNK)
            piece_branch = flat_branch[piece] if isinstance(branch, np.ndarray) else branch
            _, *values, _, closes, nearest_dead = _closed_form(
                linkage, piece_branch, flat_alpha[piece], drive, _ARRAY_MATH)
            _raise_at_first_refusal(linkage, flat_alpha[piece], closes, nearest_dead)
            for column, value in zip(columns, values):
                column[piece] = value
    return LinkageState(alpha, *(column.reshape(alpha.shape) for column in columns))


def _raise_at_first_refusal(
    linkage: FourBar, alpha: np.ndarray, closes: np.ndarray, nearest_dead: np.ndarray | None
) -> None:
    """Return the error ``solve`` would raise at the first α it refuses, if any."""
    closes = np.broadcast_to(closes, alpha.shape)
    refused = ~closes
    if nearest_dead is not None:
        close = nearest_dead < _NEAR_DEAD
        if np.any(close):
            ulp = np.spacing(np.abs(alpha))
            refused |= close & (1.5 * ulp > RATE_ACCURACY * 2.0 * nearest_dead)
    if np.any(refused):
        first = int(np.argmax(refused.reshape(-1)))
        angle = float(alpha.reshape(-1)[first])
        if not bool(closes.reshape(-1)[first]):
            raise _refuse(linkage, angle)
        raise DeadPointError(_dead_point_message(angle))


def reachable_mask(linkage: FourBar, alpha: np.ndarray) -> np.ndarray:
    """Which crank angles of an array the loop closes at."""
    alpha = np.asarray(alpha, dtype=float)
    mask = np.zeros(alpha.shape, dtype=bool)
    for low, high in linkage.reachability.intervals:
        past_low = np.mod(alpha - low, TWO_PI)
        mask |= (past_low <= high - low + ANGLE_TOLERANCE) | (past_low >= TWO_PI - ANGLE_TOLERANCE)
    return mask


def continued_branch(
    linkage: FourBar, alpha_from: float, branch: int, alpha_to: FloatOrArray, turns: int = 0
) -> int | np.ndarray:
    """
    Return the branch at ``alpha_to`` + 2π·``turns`` of a smooth motion.

    The motion has ``branch`` at ``alpha_from`` and turns the crank smoothly from there.

    Away from change points B stays on its side of the line A→C; through a change point the
    mechanism continues on the analytic branch (a parallelogram stays a parallelogram), and
    there B crosses to the other side, so the branch flips at every change point passed.
    Branches follow ``solve``'s convention: at a change point itself, the side just
    counterclockwise of it. ``alpha_to`` may be a float or an array (then so is the result);
    ``turns`` counts whole turns to add, so that a caller that keeps α within one pass (as the
    node does) gets the branch of any later turn without losing α's precision. For a linkage
    with an odd number of change points per turn the branch flips with every turn: its smooth
    motion repeats only every two turns.
    """
    _check_branch(branch)
    points = linkage.closure.change_points
    if not points:
        return np.full(np.shape(alpha_to), branch) if isinstance(alpha_to, np.ndarray) else branch
    flips = abs(turns) * len(points)
    for point in points:
        flips = flips + np.abs(_turns_past(alpha_to, point) - _turns_past(alpha_from, point))
    if isinstance(alpha_to, np.ndarray):
        return np.where(flips % 2 == 0, branch, -branch)
    return branch if flips % 2 == 0 else -branch


_TWO_PI_LOW = 2.4492935982947064e-16  # 2π − TWO_PI
_SPLITTER = 134217729.0  # 2^27 + 1, Veltkamp's splitting constant for doubles


def _two_sum(a: FloatOrArray, b: FloatOrArray) -> tuple[FloatOrArray, FloatOrArray]:
    """Return a + b as a double-double (Knuth): the rounded sum and its exact rounding error."""
    total = a + b
    b_part = total - a
    return total, (a - (total - b_part)) + (b - b_part)


def _two_product(a: FloatOrArray, b: float) -> tuple[FloatOrArray, FloatOrArray]:
    """a·b as a double-double (Dekker, with Veltkamp's split; no fused multiply-add needed)."""
    product = a * b
    a_scaled = _SPLITTER * a
    a_high = a_scaled - (a_scaled - a)
    a_low = a - a_high
    b_scaled = _SPLITTER * b
    b_high = b_scaled - (b_scaled - b)
    b_low = b - b_high
    error = ((a_high * b_high - product) + a_high * b_low + a_low * b_high) + a_low * b_low
    return product, error


def _offset(alpha: FloatOrArray, point: tuple[float, float], turns: FloatOrArray) -> FloatOrArray:
    """α − (point + 2π·turns), exact to rounding of the result however close α is to it."""
    high, low = point
    turn_high, turn_low = _two_product(turns, TWO_PI)
    first, first_error = _two_sum(alpha, -high)
    second, second_error = _two_sum(first, -turn_high)
    return second + (first_error + second_error - low - turn_low - turns * _TWO_PI_LOW)


def _turns_past(alpha: FloatOrArray, point: tuple[float, float]) -> FloatOrArray:
    """
    Return the largest k with point + 2π·k ≤ α.

    How many images of the point lie at or below α, up to a constant. Exact near the images, where
    a rounded (α − point)/2π could be off by one.
    """
    turns = np.floor((alpha - point[0]) / TWO_PI)
    if isinstance(alpha, np.ndarray):
        turns = turns + (_offset(alpha, point, turns + 1.0) >= 0.0)
        return turns - (_offset(alpha, point, turns) < 0.0)
    turns = float(turns)
    if _offset(alpha, point, turns + 1.0) >= 0.0:
        turns += 1.0
    elif _offset(alpha, point, turns) < 0.0:
        turns -= 1.0
    return int(turns)


def loop_closure_residual(linkage: FourBar, state: LinkageState) -> FloatOrArray:
    """Largest error of |AB| and |BC| from the state's pins, relative to the longest link."""
    coupler_error = np.abs(
        np.hypot(state.pin_b_x - state.pin_a_x, state.pin_b_y - state.pin_a_y)
        - linkage.coupler_length
    )
    rocker_error = np.abs(
        np.hypot(state.pin_b_x - linkage.ground_x, state.pin_b_y - linkage.ground_y)
        - linkage.rocker_length
    )
    scale = max(linkage.crank_length, linkage.coupler_length, linkage.rocker_length,
                linkage.ground_length)
    return np.maximum(coupler_error, rocker_error) / scale


def unwrap_near(angle: float, reference: float) -> float:
    """``angle`` shifted by whole turns to lie within π of ``reference``."""
    return angle + 2.0 * math.pi * round((reference - angle) / (2.0 * math.pi))
