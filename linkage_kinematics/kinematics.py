"""Exact positions, rates and accelerations of the four-bar, for one α or for arrays of α.

Positions come from loop closure: B is where the circle of radius AB about A meets the circle of
radius BC about C. With d = |C − A|, u the unit vector A→C and u⊥ it turned by +90°,

    B − A = x·u + σ·h·u⊥,   B − C = (x − d)·u + σ·h·u⊥,
    x = (AB² − BC² + d²)/(2d),  h² = (AB+BC−d)(BC+d−AB)(AB+d−BC)(AB+BC+d)/(4d²)

(σ the branch). Heron's factored form keeps h accurate near the dead points where h → 0, and
the link vectors never come from subtracting nearly equal pin coordinates.

Rates solve the differentiated loop A + AB·e_AB = C + BC·e_BC. Writing e⊥ for a unit vector
turned by +90° and S = e_AB × e_BC (= σ·h·d/(AB·BC), the sine of the transmission angle):

    ω_AB = −(v_A·e_BC)/(AB·S),      ω_BC = −(v_A·e_AB)/(BC·S)
    ω̇_AB = −(w·e_BC)/(AB·S),       ω̇_BC = −(w·e_AB)/(BC·S)
    w = a_A − AB·ω_AB²·e_AB + BC·ω_BC²·e_BC

which is Cramer's rule on the 2×2 velocity and acceleration systems. One function serves the
scalar path (``math`` on floats, the node's hot path) and the vectorised path (``numpy`` on
arrays, sweeps and benchmarks; long arrays go through it in cache-sized pieces).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Callable, Union

import numpy as np

from linkage_kinematics.drive import DriveLaw
from linkage_kinematics.geometry import ANGLE_TOLERANCE, TWO_PI, FourBar, UnreachableError

FloatOrArray = Union[float, np.ndarray]

# Below this |sin μ| (μ the transmission angle) the results are reported as a dead point: the
# measured errors (docs/kinematics.md) are ≤ 1e-15/sin²μ for rates and, near a change point,
# up to 3e-15/sin³μ for accelerations, so they stay below ~1e-7 and ~3e-3 above it.
SINGULAR_SINE = 1e-4


class DeadPointError(ValueError):
    """Coupler and rocker are collinear: the crank cannot drive the rates there."""


@dataclass(frozen=True, slots=True)
class LinkageState:
    """Everything the seed tabulates and plots, for one configuration or an array of them.

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
        """The configuration at ``index`` of an array state, as a state of floats."""
        return LinkageState(*(float(getattr(self, f.name)[index]) for f in fields(self)))


class _StateBuilder:
    """Storage laid out like LinkageState, filled by plain slot stores, then turned into one.

    A frozen dataclass sets each field through object.__setattr__, which for 22 fields costs
    more than the closed form's arithmetic; ``solve`` builds its result this way instead.
    """

    __slots__ = LinkageState.__slots__


MathFunctions = tuple[Callable, Callable, Callable, Callable]
_SCALAR_MATH: MathFunctions = (math.sin, math.cos, math.sqrt, math.atan2)
_ARRAY_MATH: MathFunctions = (np.sin, np.cos, np.sqrt, np.arctan2)
# Arrays longer than this are solved in pieces of this many angles, so that the closed form's
# temporaries stay in cache instead of streaming whole arrays through memory.
_CHUNK = 8192


def _loop_closure(
    linkage: FourBar, branch: int, alpha: FloatOrArray, xp: MathFunctions
) -> tuple[FloatOrArray, ...]:
    """Positions by loop closure: sin α, cos α, pin A, the vectors A→B and C→B, and S.

    ``xp`` is (sin, cos, sqrt, atan2) from ``math`` or ``numpy``. The caller has checked that
    every α is reachable; h² is clamped at 0 so that an α on an interval end (rounding may put
    it a hair outside) lands exactly on the dead point.
    """
    sin, cos, sqrt, _ = xp
    crank = linkage.crank_length
    coupler = linkage.coupler_length
    rocker = linkage.rocker_length
    sin_alpha = sin(alpha)
    cos_alpha = cos(alpha)
    pin_a_x = crank * sin_alpha
    pin_a_y = -crank * cos_alpha
    to_c_x = linkage.ground_x - pin_a_x
    to_c_y = linkage.ground_y - pin_a_y
    distance = sqrt(to_c_x * to_c_x + to_c_y * to_c_y)
    u_x = to_c_x / distance
    u_y = to_c_y / distance
    two_distance = 2.0 * distance
    along = (coupler * coupler - rocker * rocker + distance * distance) / two_distance
    reach = coupler + rocker
    heron = (
        (reach - distance)
        * (rocker + distance - coupler)
        * (coupler + distance - rocker)
        * (reach + distance)
    )
    height = branch * sqrt(heron * (heron > 0.0)) / two_distance
    rocker_along = along - distance
    coupler_x = along * u_x - height * u_y
    coupler_y = along * u_y + height * u_x
    rocker_x = rocker_along * u_x - height * u_y
    rocker_y = rocker_along * u_y + height * u_x
    sine = height * distance / (coupler * rocker)
    return sin_alpha, cos_alpha, pin_a_x, pin_a_y, coupler_x, coupler_y, rocker_x, rocker_y, sine


def _closed_form(
    linkage: FourBar, branch: int, alpha: FloatOrArray, drive: DriveLaw, xp: MathFunctions
) -> tuple[FloatOrArray, ...]:
    """Evaluate the closed form: the 22 LinkageState fields in order, then the signed sine S."""
    atan2 = xp[3]
    crank = linkage.crank_length
    coupler = linkage.coupler_length
    rocker = linkage.rocker_length
    (
        sin_alpha, cos_alpha, pin_a_x, pin_a_y, coupler_x, coupler_y, rocker_x, rocker_y, sine
    ) = _loop_closure(linkage, branch, alpha, xp)
    e_ab_x = coupler_x / coupler
    e_ab_y = coupler_y / coupler
    e_bc_x = rocker_x / rocker
    e_bc_y = rocker_y / rocker
    cosine = e_ab_x * e_bc_x + e_ab_y * e_bc_y

    omega = drive.omega0 + drive.k * alpha
    omega_dot = drive.k * omega
    # v_A = OA·ω·(cos α, sin α); a_A = OA·ω̇·(cos α, sin α) − OA·ω²·(sin α, −cos α)
    crank_omega = crank * omega
    omega_squared = omega * omega
    velocity_a_x = crank_omega * cos_alpha
    velocity_a_y = crank_omega * sin_alpha
    acceleration_a_x = crank * (omega_dot * cos_alpha - omega_squared * sin_alpha)
    acceleration_a_y = crank * (omega_dot * sin_alpha + omega_squared * cos_alpha)

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
        linkage.ground_x + rocker_x,
        linkage.ground_y + rocker_y,
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
    )


def _check_branch(branch: int) -> None:
    if branch not in (1, -1):
        raise ValueError(f"branch must be +1 or -1, got {branch!r}")


def _dead_point_message(alpha: float, sine: float) -> str:
    return (
        f"crank angle α = {math.degrees(alpha):.9f}° is at a dead point: coupler and rocker are "
        f"collinear (|sin μ| = {abs(sine):.3g} < {SINGULAR_SINE:g}), so the rates are undefined"
    )


def solve(linkage: FourBar, alpha: float, drive: DriveLaw, branch: int = 1) -> LinkageState:
    """The exact state at one crank angle (the node's hot path).

    Raises UnreachableError outside the reachable set and DeadPointError at a dead point (where
    ``solve_pose`` still gives the positions); the state returned never holds NaN or inf.
    """
    if not math.isfinite(alpha):
        raise UnreachableError(f"crank angle α must be finite, got {alpha!r}")
    _check_branch(branch)
    linkage.reachability.require(alpha)
    try:
        values = _closed_form(linkage, branch, alpha, drive, _SCALAR_MATH)
    except ZeroDivisionError:
        # Exactly on a dead or change point S rounds to 0 and the rates divide by it.
        raise DeadPointError(_dead_point_message(alpha, 0.0)) from None
    sine = values[-1]
    if abs(sine) < SINGULAR_SINE:
        raise DeadPointError(_dead_point_message(alpha, sine))
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
    ) = values
    object.__setattr__(state, "__class__", LinkageState)
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
    """The positions alone at one crank angle, at a dead point too (where ``solve`` raises).

    Raises UnreachableError outside the reachable set. Near a dead point the angles keep the
    accuracy docs/kinematics.md gives (their error grows as 1/√δ, δ the distance from it).
    """
    if not math.isfinite(alpha):
        raise UnreachableError(f"crank angle α must be finite, got {alpha!r}")
    _check_branch(branch)
    linkage.reachability.require(alpha)
    (
        _, _, pin_a_x, pin_a_y, coupler_x, coupler_y, rocker_x, rocker_y, sine
    ) = _loop_closure(linkage, branch, alpha, _SCALAR_MATH)
    coupler = linkage.coupler_length
    rocker = linkage.rocker_length
    cosine = (
        (coupler_x / coupler) * (rocker_x / rocker) + (coupler_y / coupler) * (rocker_y / rocker)
    )
    return LinkagePose(
        alpha=alpha,
        beta=math.atan2(rocker_y, -rocker_x),
        gamma=math.atan2(coupler_y, coupler_x),
        pin_a_x=pin_a_x,
        pin_a_y=pin_a_y,
        pin_b_x=linkage.ground_x + rocker_x,
        pin_b_y=linkage.ground_y + rocker_y,
        transmission_angle=math.atan2(abs(sine), cosine),
    )


def solve_many(
    linkage: FourBar, alpha: np.ndarray, drive: DriveLaw, branch: int = 1
) -> LinkageState:
    """The exact states at an array of crank angles, as a LinkageState of arrays.

    Raises, naming the first offending α, if any α is unreachable or at a dead point.
    """
    alpha = np.asarray(alpha, dtype=float)
    if not np.all(np.isfinite(alpha)):
        raise UnreachableError("crank angles must be finite")
    _check_branch(branch)
    if not _within_one_interval(linkage, alpha):
        reachable = reachable_mask(linkage, alpha)
        if not np.all(reachable):
            linkage.reachability.require(float(alpha[np.argmin(reachable)]))
    with np.errstate(divide="ignore", invalid="ignore"):
        if alpha.size <= _CHUNK:
            *values, sine = _closed_form(linkage, branch, alpha, drive, _ARRAY_MATH)
            _raise_at_first_dead_point(alpha, sine)
            return LinkageState(*values)
        flat_alpha = alpha.reshape(-1)
        columns = [np.empty(flat_alpha.size) for _ in range(len(fields(LinkageState)) - 1)]
        for start in range(0, flat_alpha.size, _CHUNK):
            piece = slice(start, start + _CHUNK)
            _, *values, sine = _closed_form(linkage, branch, flat_alpha[piece], drive, _ARRAY_MATH)
            _raise_at_first_dead_point(flat_alpha[piece], sine)
            for column, value in zip(columns, values):
                column[piece] = value
    return LinkageState(alpha, *(column.reshape(alpha.shape) for column in columns))


def _raise_at_first_dead_point(alpha: np.ndarray, sine: np.ndarray) -> None:
    """DeadPointError naming the first α whose |S| is below SINGULAR_SINE, if any."""
    singular = np.abs(sine) < SINGULAR_SINE
    if np.any(singular):
        first = int(np.argmax(singular))
        raise DeadPointError(_dead_point_message(float(alpha[first]), float(sine[first])))


def _within_one_interval(linkage: FourBar, alpha: np.ndarray) -> bool:
    """True if every α lies in one reachable interval [low, high] without wrapping.

    Then reachable_mask is all True: α − low rounds monotonically in α, so its extremes are
    those of min(α) − low and max(α) − low. This costs two reductions instead of a float mod.
    """
    if alpha.size == 0:
        return True
    lowest = float(alpha.min())
    highest = float(alpha.max())
    return any(
        lowest - low >= 0.0 and highest - low <= high - low + ANGLE_TOLERANCE
        for low, high in linkage.reachability.intervals
    )


def reachable_mask(linkage: FourBar, alpha: np.ndarray) -> np.ndarray:
    """Which crank angles of an array the loop closes at."""
    alpha = np.asarray(alpha, dtype=float)
    mask = np.zeros(alpha.shape, dtype=bool)
    for low, high in linkage.reachability.intervals:
        past_low = np.mod(alpha - low, TWO_PI)
        mask |= (past_low <= high - low + ANGLE_TOLERANCE) | (past_low >= TWO_PI - ANGLE_TOLERANCE)
    return mask


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
