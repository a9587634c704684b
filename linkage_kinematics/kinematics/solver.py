# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Exact positions, rates and accelerations of the four-bar, for one α or for arrays of α.

The library's entry points: ``solve`` (one float α, the node's hot path), ``solve_many`` (arrays,
in cache-sized pieces), ``solve_pose`` (positions alone, defined at a dead point too) and
``continued_branch`` (the assembly of a smooth motion through change points). They check their
inputs and refuse what float64 cannot answer; the work is done by three modules with one concern
each:

* ``closed_form``: the closed form itself (loop closure, Cramer's rule, the analytic rates of
  change-point linkages) and ``LinkageState``;
* ``singular_points``: Heron's factors at float64's limit near dead points and change points,
  and the refusal rule that follows from that limit;
* ``continuation``: which assembly a smooth motion is in after passing change points.

Refusal. ``solve`` raises DeadPointError only where a one-ulp change of the float α moves the
exact accelerations by more than RATE_ACCURACY (δ < 1500·ulp(α) from a dead point), and where
pin A meets C in a linkage with OA = OC and AB = BC (``PIVOT_PASSAGE``).
"""

from __future__ import annotations

import math

from linkage_kinematics.kinematics.closed_form import (
    ARRAY_MATH,
    CrankRates,
    evaluate,
    FloatOrArray,
    LinkagePose,
    LinkageState,
    SCALAR_MATH,
    STATE_FIELDS,
)
from linkage_kinematics.kinematics.continuation import check_branch, continued_branch
from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import (
    ANGLE_TOLERANCE,
    FourBar,
    TWO_PI,
    UnreachableError,
)
from linkage_kinematics.kinematics.singular_points import (
    LoopCheck,
    NEAR_DEAD,
    PIVOT_PASSAGE,
    RATE_ACCURACY,
    too_close,
)
import numpy as np

__all__ = [
    'continued_branch', 'CrankRates', 'DeadPointError', 'LinkagePose', 'LinkageState',
    'loop_closure_residual', 'PIVOT_PASSAGE', 'RATE_ACCURACY', 'reachable_mask', 'solve',
    'solve_at_rates', 'solve_many', 'solve_pose', 'unwrap_near',
]

# Arrays longer than this are solved in pieces of this many angles, so that the closed form's
# temporaries stay in cache instead of streaming whole arrays through memory.
_CHUNK = 8192


class DeadPointError(ValueError):
    """Coupler and rocker are collinear: the crank cannot drive the rates there."""


def _dead_point_message(alpha: float) -> str:
    return (
        f'crank angle α = {math.degrees(alpha):.9f}° is at a dead point: coupler and rocker are '
        'collinear, so the rates are undefined (closer than a one-ulp change of α moving the '
        f'accelerations by {RATE_ACCURACY:.1%})'
    )


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


def _check_closure(linkage: FourBar, alpha: float, check: LoopCheck) -> None:
    """Raise as ``solve`` does where the loop does not close or α is too close to a dead point."""
    if not check.closes:
        raise _refuse(linkage, alpha)
    nearest_dead = check.nearest_dead
    if nearest_dead is not None and nearest_dead < NEAR_DEAD and too_close(alpha, nearest_dead):
        raise DeadPointError(_dead_point_message(alpha))


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
    # The crank's rates here, not through DriveLaw's methods as solve_many takes them: a call
    # costs this hot path more than their arithmetic.
    if type(drive) is CrankRates:
        return solve_at_rates(linkage, alpha, drive.omega, drive.omega_dot, branch)
    omega = drive.omega0 + drive.k * alpha
    return solve_at_rates(linkage, alpha, omega, drive.k * omega, branch)


def solve_at_rates(linkage: FourBar, alpha: float, omega: float, omega_dot: float,
                   branch: int = 1) -> LinkageState:
    """
    Return ``solve``'s state with the crank's rates ω, ω̇ given as they are (rad/s, rad/s²).

    For a caller that has them as numbers rather than as ``CrankRates`` (a loop driven at a
    measured joint, sample after sample); the same refusals as ``solve``.
    """
    if branch != 1 and branch != -1:
        check_branch(branch)
    try:
        state, check = evaluate(linkage, branch, alpha, omega, omega_dot, SCALAR_MATH)
    except ZeroDivisionError:
        # S = 0: past or on a dead point (the loop does not close), or pin A on the pivot C.
        raise _refuse(linkage, alpha) from None
    except ValueError:
        # math.sin of ±inf, or rounding NaN to whole turns
        raise _refuse(linkage, alpha) from None
    if check is not None:
        _check_closure(linkage, alpha, check)
    return state


def solve_pose(linkage: FourBar, alpha: float, branch: int = 1) -> LinkagePose:
    """
    Return the positions alone at one crank angle, at a dead point too (where ``solve`` raises).

    ``branch`` as in ``solve``. Raises UnreachableError outside the reachable set.
    """
    if not math.isfinite(alpha):
        raise UnreachableError(f'crank angle α must be finite, got {alpha!r}')
    check_branch(branch)
    if linkage.closure.passes_through_pivot:
        _check_pivot_passage(linkage, alpha)
    pose, check = evaluate(linkage, branch, alpha, None, None, SCALAR_MATH)
    if check is not None and not check.closes:
        # On the interval end (within its tolerance) the positions are the dead point's.
        linkage.reachability.require(alpha)
    return pose


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
        check_branch(branch)
    computed = STATE_FIELDS[1:]  # alpha is the input itself
    with np.errstate(divide='ignore', invalid='ignore'):
        flat_alpha = alpha.reshape(-1)
        flat_branch = branch.reshape(-1) if isinstance(branch, np.ndarray) else branch
        columns = {name: np.empty(flat_alpha.size) for name in computed}
        for start in range(0, flat_alpha.size, _CHUNK):
            piece = slice(start, start + _CHUNK)
            piece_branch = flat_branch[piece] if isinstance(branch, np.ndarray) else branch
            piece_alpha = flat_alpha[piece]
            state, check = evaluate(
                linkage, piece_branch, piece_alpha, drive.angular_velocity(piece_alpha),
                drive.angular_acceleration(piece_alpha), ARRAY_MATH)
            if check is not None:
                _raise_at_first_refusal(linkage, piece_alpha, check)
            for name in computed:
                columns[name][piece] = getattr(state, name)
    return LinkageState(
        alpha=alpha, **{name: column.reshape(alpha.shape) for name, column in columns.items()})


def _raise_at_first_refusal(linkage: FourBar, alpha: np.ndarray, check: LoopCheck) -> None:
    """Raise the error ``solve`` would raise at the first α it refuses, if any."""
    closes = np.broadcast_to(check.closes, alpha.shape)
    refused = ~closes
    nearest_dead = check.nearest_dead
    if nearest_dead is not None:
        close = nearest_dead < NEAR_DEAD
        if np.any(close):
            refused |= close & too_close(alpha, nearest_dead)
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
