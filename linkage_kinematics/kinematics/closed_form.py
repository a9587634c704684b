# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The closed form: exact positions, rates and accelerations of the four-bar at given crank angles.

Positions come from loop closure: B is where the circle of radius AB about A meets the circle of
radius BC about C. With d = |C − A|, u the unit vector A→C and u⊥ it turned by +90°,

    B − A = x·u + σ·h·u⊥,   B − C = (x − d)·u + σ·h·u⊥,
    x = (AB² − BC² + d²)/(2d),  4·d²·h² = ((AB + BC)² − d²)·(d² − (AB − BC)²)

(σ the branch). Heron's two factors come from d where both are far from zero, and otherwise
from ``singular_points``, exact to rounding at float64's limit.

Rates solve the differentiated loop A + AB·e_AB = C + BC·e_BC. Writing e⊥ for a unit vector
turned by +90° and S = e_AB × e_BC (= σ·h·d/(AB·BC), the sine of the transmission angle):

    ω_AB = −(v_A·e_BC)/(AB·S),      ω_BC = −(v_A·e_AB)/(BC·S)
    ω̇_AB = −(w·e_BC)/(AB·S),       ω̇_BC = −(w·e_AB)/(BC·S)
    w = a_A − AB·ω_AB²·e_AB + BC·ω_BC²·e_BC

which is Cramer's rule on the 2×2 velocity and acceleration systems. For a change-point linkage
the system is singular at its change points while the motion is smooth; there the rates come
from an analytic form with the common factor of numerator and S taken out
(``_smooth_rates``), finite and exact at the change point itself.

One function (``evaluate``) serves the scalar path (``math`` on floats, the node's hot path) and
the vectorised path (``numpy`` on arrays); it neither checks its inputs nor refuses anything:
``solver`` does, from the LoopCheck it returns.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
import math
from typing import Callable

from linkage_kinematics.kinematics.geometry import FourBar, LoopClosure
from linkage_kinematics.kinematics.singular_points import (
    array_factors,
    exact_factors,
    FAR,
    FloatOrArray,
    half_sine,
    LoopCheck,
)
import numpy as np


@dataclass(frozen=True, slots=True)
class CrankRates:
    """
    The crank's angular velocity ω (rad/s) and acceleration ω̇ (rad/s²) at the α solved for.

    Given instead of a drive law where the crank's motion is measured, not commanded: the
    state then takes its rates as they are.
    """

    omega: float
    omega_dot: float


@dataclass(slots=True)
class LinkageState:
    """
    Everything the seed tabulates and plots, for one configuration or an array of them.

    Angles in rad (seed conventions, see ``geometry``), angular rates counterclockwise-positive
    in rad/s and rad/s², pin coordinates in m, velocities in m/s, accelerations in m/s², all in
    the frame with O at the origin.

    A value: change a field with ``dataclasses.replace``. It is not frozen because a frozen
    dataclass sets each of its 22 fields through ``object.__setattr__``, which costs more than
    the closed form's arithmetic (docs/benchmarks.md); ``evaluate`` fills a new state field by
    field instead.
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
        return LinkageState(**{name: float(getattr(self, name)[index]) for name in STATE_FIELDS})


STATE_FIELDS = tuple(field.name for field in fields(LinkageState))


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


MathFunctions = tuple[Callable, Callable, Callable, Callable]
SCALAR_MATH: MathFunctions = (math.sin, math.cos, math.sqrt, math.atan2)
ARRAY_MATH: MathFunctions = (np.sin, np.cos, np.sqrt, np.arctan2)


def evaluate(
    linkage: FourBar, branch: int | np.ndarray, alpha: FloatOrArray,
    omega: FloatOrArray | None, omega_dot: FloatOrArray | None, xp: MathFunctions,
) -> tuple[LinkageState | LinkagePose, LoopCheck | None]:
    """
    Return the state at ``alpha`` (crank rates ``omega``, ``omega_dot``) and its LoopCheck.

    A LinkagePose if ``omega`` is None. The callers take the crank's rates from their drive.
    """
    sin, cos, sqrt, atan2 = xp
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
    if (plain_where_far and xp is SCALAR_MATH
            and stretched >= FAR * distance and folded >= FAR * distance):
        # Far from the factors' zeros d's rounding is harmless: the cheaper product from d.
        # (Tested here, not in singular_points: a call costs the hot path more than the test.)
        stretched *= reach + distance
        folded *= distance + difference
        check = None
    else:
        stretched, folded, check = _factors_near_zeros(
            closure, alpha, distance, stretched, folded, xp)
    two_distance = 2.0 * distance
    u_x = to_c_x / distance
    u_y = to_c_y / distance
    along = (squares + distance_squared) / two_distance
    height = branch * sqrt(stretched * folded) / two_distance
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
    transmission_angle = atan2(abs(sine), e_ab_x * e_bc_x + e_ab_y * e_bc_y)
    if omega is None:
        return _pose(linkage, alpha, pin_a_x, pin_a_y, coupler_x, coupler_y, rocker_x, rocker_y,
                     transmission_angle, atan2), check
    # Filled by name, field by field (LinkageState says why not through its __init__).
    state = object.__new__(LinkageState)
    state.alpha = alpha
    state.omega = omega
    state.omega_dot = omega_dot
    # v_A = OA·ω·(cos α, sin α); a_A = OA·ω̇·(cos α, sin α) − OA·ω²·(sin α, −cos α)
    crank_omega = crank * omega
    omega_squared = omega * omega
    state.velocity_a_x = velocity_a_x = crank_omega * cos_alpha
    state.velocity_a_y = velocity_a_y = crank_omega * sin_alpha
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
        omega_ab, omega_bc, omega_dot_ab, omega_dot_bc = _smooth_rates(
            linkage, branch, alpha, stretched, folded, distance_squared, distance, along,
            omega, omega_dot, xp)
        rocker_centripetal = rocker * omega_bc * omega_bc
    rocker_tangential = rocker * omega_dot_bc
    state.beta = atan2(rocker_y, -rocker_x)
    state.gamma = atan2(coupler_y, coupler_x)
    state.omega_ab = omega_ab
    state.omega_bc = omega_bc
    state.omega_dot_ab = omega_dot_ab
    state.omega_dot_bc = omega_dot_bc
    state.pin_a_x = pin_a_x
    state.pin_a_y = pin_a_y
    state.pin_b_x = ground_x + rocker_x
    state.pin_b_y = ground_y + rocker_y
    state.velocity_b_x = -omega_bc * rocker_y
    state.velocity_b_y = omega_bc * rocker_x
    state.acceleration_a_x = acceleration_a_x
    state.acceleration_a_y = acceleration_a_y
    state.acceleration_b_x = -rocker_tangential * e_bc_y - rocker_centripetal * e_bc_x
    state.acceleration_b_y = rocker_tangential * e_bc_x - rocker_centripetal * e_bc_y
    state.transmission_angle = transmission_angle
    return state, check


def _factors_near_zeros(
    closure: LoopClosure, alpha: FloatOrArray, distance: FloatOrArray, stretched: FloatOrArray,
    folded: FloatOrArray, xp: MathFunctions,
) -> tuple[FloatOrArray, FloatOrArray, LoopCheck | None]:
    """
    Return Heron's two factors and the LoopCheck where the cheap product from d may not do.

    Arrays of a linkage without change points keep that product where it is far from the
    factors' zeros (``array_factors``); floats near them, and any linkage with change points,
    take the exact factors (``exact_factors``).
    """
    if xp is ARRAY_MATH and not closure.change_points:
        return array_factors(closure, alpha, distance, stretched, folded)
    return exact_factors(closure, alpha, distance, xp[0])


def _pose(
    linkage: FourBar, alpha: float, pin_a_x: float, pin_a_y: float, coupler_x: float,
    coupler_y: float, rocker_x: float, rocker_y: float, transmission_angle: float,
    atan2: Callable,
) -> LinkagePose:
    """Return the pose from pin A and the links' vectors B − A and B − C."""
    return LinkagePose(
        alpha=alpha, beta=atan2(rocker_y, -rocker_x), gamma=atan2(coupler_y, coupler_x),
        pin_a_x=pin_a_x, pin_a_y=pin_a_y, pin_b_x=linkage.ground_x + rocker_x,
        pin_b_y=linkage.ground_y + rocker_y, transmission_angle=transmission_angle)


def _smooth_rate_terms(
    linkage: FourBar, branch: int | np.ndarray, alpha: FloatOrArray, stretched: FloatOrArray,
    folded: FloatOrArray, distance_squared: FloatOrArray, distance: FloatOrArray,
    xp: MathFunctions,
) -> tuple[FloatOrArray, FloatOrArray, FloatOrArray, FloatOrArray]:
    """
    Return p − OA, q, Q = q/h and dQ/dα of a change-point linkage.

    Analytic through its change points.

    With p = C·â and q = C·â⊥ (â = A/OA, â⊥ its derivative in α), the rates are
    dγ/dα = −OA·((p − OA) + (x − d)·Q)/d² with Q = q/h (``_smooth_rates``). At a change point
    q and h vanish together; here both are written with their common factor m (the sine of half
    the crank's offset from the change point, or the product of two) taken out:
    q = n·m and h = σ_a·m·R with R > 0, so Q = σ_a·n/R stays finite and smooth. σ_a is the
    analytic branch: the requested side of B times the sign of m (at m = 0, the side just
    counterclockwise of the change point).
    """
    sin, _, sqrt, _ = xp
    closure = linkage.closure
    crank = linkage.crank_length
    ground = closure.ground
    half_scale = 0.25 * closure.scale  # OA·OC
    # sin and cos of ½φ, φ = α − α₀, each from the crank's offset to the angle where it vanishes
    sin_half = half_sine(alpha, closure.direction, sin)
    cos_half = -half_sine(alpha, closure.opposite, sin)
    # p = OC·cos φ, q = −OC·sin φ
    p_minus_crank = ground * (cos_half - sin_half) * (cos_half + sin_half) - crank
    q = -2.0 * ground * sin_half * cos_half
    if closure.folded.is_change and closure.stretched.is_change:
        # m = sin(½φ)·sin(½(φ − π)), q = 2·OC·m, R = 2·OA·OC/d
        vanishing = -sin_half * cos_half
        # m = −½·sin φ: at m = 0 its sign just counterclockwise is that of −cos φ (whichever
        # factor vanishes, and on every turn of φ, which the half-angle factors tell apart)
        other = (sin_half - cos_half) * (cos_half + sin_half)
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


def _smooth_rates(
    linkage: FourBar, branch: int | np.ndarray, alpha: FloatOrArray, stretched: FloatOrArray,
    folded: FloatOrArray, distance_squared: FloatOrArray, distance: FloatOrArray,
    along: FloatOrArray, omega: FloatOrArray, omega_dot: FloatOrArray, xp: MathFunctions,
) -> tuple[FloatOrArray, FloatOrArray, FloatOrArray, FloatOrArray]:
    """
    Return ω_AB, ω_BC, ω̇_AB and ω̇_BC of a change-point linkage, smooth through its change points.

    With x = ``along`` A→C, G = dγ/dα and G_BC = d(angle of C→B)/dα,
    G = −OA·((p − OA) + (x − d)·Q)/d² and G_BC = −OA·((p − OA) + x·Q)/d², and their
    α-derivatives from p' = q, q' = −p, (d²)' = −2·OA·q, x' = OA·q·(x − d)/d²
    (``_smooth_rate_terms``); ω = ω0 + k·α and ω̇ = k·ω turn them into rates and accelerations.
    """
    p_minus_crank, q, ratio, ratio_rate = _smooth_rate_terms(
        linkage, branch, alpha, stretched, folded, distance_squared, distance, xp)
    crank = linkage.crank_length
    rocker_along = along - distance
    scale = -crank / distance_squared
    drift = crank * q / distance_squared
    coupler_slope = scale * (p_minus_crank + rocker_along * ratio)
    rocker_slope = scale * (p_minus_crank + along * ratio)
    coupler_curvature = scale * (
        q + rocker_along * ratio_rate
        + drift * (along * ratio + 2.0 * p_minus_crank + 2.0 * rocker_along * ratio))
    rocker_curvature = scale * (
        q + along * ratio_rate
        + drift * (rocker_along * ratio + 2.0 * p_minus_crank + 2.0 * along * ratio))
    omega_squared = omega * omega
    return (omega * coupler_slope, omega * rocker_slope,
            omega_dot * coupler_slope + omega_squared * coupler_curvature,
            omega_dot * rocker_slope + omega_squared * rocker_curvature)
