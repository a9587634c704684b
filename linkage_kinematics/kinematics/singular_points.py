# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Heron's two factors at float64's limit, near the linkage's dead points and change points.

Loop closure needs 4·d²·h² = ((AB + BC)² − d²)·(d² − (AB − BC)²). Taken from d = |C − A|, a
factor that vanishes at a dead point a carries the rounding of d (~2e-16 m) into a difference of
size ~0.3·|α − a|: near a dead point that rounding is the whole of the result. Here each factor
is written in α's offsets to its singular angles instead (``geometry.LoopClosure`` holds them as
double-doubles): ∓4·OA·OC·sin(½(α − a₁))·sin(½(α − a₂)) for two dead points, gap + 4·OA·OC·
sin²(½(α − a)) for a change point (a double zero, whose root continues analytically), so h is
exact to rounding however close α is, after any number of turns too.

The factors of a loop with a prismatic joint (``prismatic_loop``) take the same forms
(``geometry.Factor``), evaluated one at a time by ``factor_value``, in an angle or a
displacement. Also the refusal rule that follows from float64's limit (``RATE_ACCURACY``), the
closure of a linkage whose pin A passes through C (``PIVOT_PASSAGE``), and the double-double
arithmetic that ``continuation`` shares to decide on which side of a change point a float lies.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Callable, Union

from linkage_kinematics.kinematics.geometry import (
    DoubleDouble,
    Factor,
    FactorForm,
    LoopClosure,
    TWO_PI,
)
import numpy as np

FloatOrArray = Union[float, np.ndarray]

# solve refuses a crank angle so close to a dead point that a one-ulp change of α would move the
# exact accelerations by more than this (relative): no float64 answer could be that accurate.
RATE_ACCURACY = 1e-3
# A linkage whose pin A passes through C (OA = OC, AB = BC) is refused this close to it,
# relative to OC: there coupler and rocker lie on each other and can turn together about the
# joined pins, so the motion is undetermined at the point, and on the way to it the direction
# A→C, taken from C − A, carries its rounding divided by |C − A|: the accelerations lose
# accuracy as ~2e-16·(OC/|C − A|)³ (2.4e-4 relative at this distance, docs/kinematics.md).
PIVOT_PASSAGE = 1e-4
# Where AB + BC − d and d − |AB − BC| both exceed this fraction of d, the factors are taken
# from d (their relative error is then at most a few roundings) instead of from α's offsets to
# the singular angles: the shortcut for ordinary angles.
FAR = 0.0625
# |sin(½(α − a))| below which α is checked against the refusal rule: ½δ for the refusal zone's
# widest δ ≈ 1500·ulp(α) at |α| up to ~3e6 rad.
NEAR_DEAD = 1e-6
# Below this |sin(½(α − a))| the half-angle sine is recomputed from α − a less whole turns
# held exactly (``_corrected_half_sine``); above it, the rounding of α − a is harmless beside it.
_NEAR_HALF_SINE = 0.25

_TWO_PI_LOW = 2.4492935982947064e-16  # 2π − TWO_PI
_SPLITTER = 134217729.0  # 2^27 + 1, Veltkamp's splitting constant for doubles


@dataclass(frozen=True, slots=True)
class LoopCheck:
    """
    What the refusal rule needs from the factors, where a dead point may be near.

    ``closes``: whether the loop closes (both factors > 0, or a change factor ≥ 0), per α for
    arrays. ``nearest_dead``: the least |sin(½(α − a))| over the dead points a (for a float only
    if below NEAR_DEAD, for arrays inf where not computed; None if there is none).
    """

    closes: bool | np.ndarray
    nearest_dead: FloatOrArray | None


def too_close(alpha: FloatOrArray, nearest_dead: FloatOrArray) -> bool | np.ndarray:
    """
    Tell whether α is too close to a dead point for float64.

    It is when a one-ulp change of α moves the exact accelerations by more than RATE_ACCURACY
    (they grow as δ^(−3/2): by 1.5·ulp(α)/δ, and nearest_dead = |sin(½δ)| ≈ ½δ).
    """
    ulp = np.spacing(np.abs(alpha)) if isinstance(alpha, np.ndarray) else math.ulp(alpha)
    return 1.5 * ulp > RATE_ACCURACY * 2.0 * nearest_dead


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


def offset(alpha: FloatOrArray, point: tuple[float, float], turns: FloatOrArray) -> FloatOrArray:
    """α − (point + 2π·turns), exact to rounding of the result however close α is to it."""
    high, low = point
    turn_high, turn_low = _two_product(turns, TWO_PI)
    first, first_error = _two_sum(alpha, -high)
    second, second_error = _two_sum(first, -turn_high)
    return second + (first_error + second_error - low - turn_low - turns * _TWO_PI_LOW)


def offset_from(alpha: float, point: tuple[float, float]) -> float:
    """
    Return ``offset(alpha, point, 0.0)``, bit for bit: a displacement's distance from a point.

    The same operations, ``_two_sum`` written out, without Dekker's product of no turns (it is
    (+0.0, +0.0) for 0.0 turns): a slider loop takes several per sample.
    """
    high, low = point
    negated = -high
    first = alpha + negated
    part = first - alpha
    first_error = (alpha - (first - part)) + (negated - part)
    second = first + -0.0
    part = second - first
    second_error = (first - (second - part)) + (-0.0 - part)
    return second + (first_error + second_error - low - 0.0 - 0.0)


def _corrected_half_sine(alpha: FloatOrArray, point: tuple[float, float], difference: FloatOrArray,
                         value: FloatOrArray, sin: Callable) -> FloatOrArray:
    """
    Return ``value`` = sin(½((α − a_high) − a_low)) corrected near another turn's image of a.

    Given ``difference`` = α − a_high. Within half a turn of a, ``value`` carries only the
    rounding of the result; near another turn's image of a, α − a − 2π·k is taken exactly instead
    (Dekker's product for 2π·k), so that the sine keeps its sign and relative accuracy next to
    the zero after many turns too.
    """
    if isinstance(value, np.ndarray):
        near = (np.abs(value) < _NEAR_HALF_SINE) & (np.abs(difference) > math.pi)
        if not np.any(near):
            return value
        turns = np.round(difference / TWO_PI)
        exact = sin(0.5 * offset(alpha, point, turns)) * (1.0 - 2.0 * (turns % 2.0))
        return np.where(near, exact, value)
    turns = float(round(difference / TWO_PI))
    exact = sin(0.5 * offset(alpha, point, turns))
    return -exact if turns % 2.0 else exact


def half_sine(alpha: FloatOrArray, point: tuple[float, float], sin: Callable) -> FloatOrArray:
    """
    Return sin(½(α − a)) for a singular angle a (a double-double).

    To rounding of the result even where it vanishes, after any number of turns.
    """
    high, low = point
    difference = alpha - high
    value = sin(0.5 * (difference - low))
    if isinstance(value, np.ndarray) or not (
            -math.pi <= difference <= math.pi or abs(value) >= _NEAR_HALF_SINE):
        return _corrected_half_sine(alpha, point, difference, value, sin)
    return value


def factor_unit(factor: Factor, value: float, point: DoubleDouble) -> float:
    """sin(½(x − point)) for an angle, x − point for a displacement: exact near the point."""
    if factor.periodic:
        return half_sine(value, point, math.sin)
    return offset_from(value, point)


def factor_value(factor: Factor, value: float) -> tuple[float, float]:
    """
    Return ``factor`` at ``value`` and its nearest root's unit (inf if it has none).

    For the ROOTS and TOUCH forms (a loop with a prismatic joint has no other), one value at a
    time; the unit is ~½·(x − root) for a displacement, as |sin(½(x − root))| for an angle, the
    measure ``too_close`` takes.
    """
    first = factor_unit(factor, value, factor.first)
    if factor.touching:
        return factor.gap + factor.scale * first * first, math.inf
    second = factor_unit(factor, value, factor.second)
    return (factor.orientation * factor.scale * first * second,
            min(abs(first), abs(second)) * (1.0 if factor.periodic else 0.5))


def exact_factors(
    closure: LoopClosure, alpha: FloatOrArray, distance: FloatOrArray, sin: Callable
) -> tuple[FloatOrArray, FloatOrArray, LoopCheck | None]:
    """
    Return Heron's two factors (AB + BC)² − d² and d² − (AB − BC)², and their LoopCheck.

    Each in the form its ``geometry.Factor`` names: from d; from the offsets to its two dead points
    a₁, a₂ as ∓4·OA·OC·sin(½(α − a₁))·sin(½(α − a₂)); or touching zero as gap +
    4·OA·OC·sin²(½(α − a)). A factor that is negative (the loop does not close) is returned as 0:
    B is then placed on the dead point (h = 0), where solve refuses and solve_pose gives the
    interval end for an α within its tolerance. The check is None for a float where the loop
    closes and no dead point is near enough to be checked.
    """
    is_array = isinstance(alpha, np.ndarray)
    nearest_dead = None
    closes = True
    factors = []
    for part in (closure.stretched, closure.folded):
        form = part.form
        if form is FactorForm.PLAIN:
            length = part.length
            value = part.orientation * (distance - length) * (distance + length)
            closes = closes & (value > 0.0)
            factors.append(value)
            continue
        first = half_sine(alpha, part.first, sin)
        if form is FactorForm.TOUCH:
            factors.append(part.gap + part.scale * first * first)
            continue
        second = half_sine(alpha, part.second, sin)
        value = part.orientation * part.scale * first * second
        closes = closes & (value > 0.0)
        first = abs(first)
        second = abs(second)
        if is_array:
            near = np.minimum(first, second)
            nearest_dead = near if nearest_dead is None else np.minimum(nearest_dead, near)
        else:
            # only a float within the refusal check's reach is reported
            near = first if first < second else second
            if near < NEAR_DEAD and (nearest_dead is None or near < nearest_dead):
                nearest_dead = near
        factors.append(value)
    stretched, folded = factors
    if closure.passes_through_pivot:
        closes = closes & (distance >= PIVOT_PASSAGE * closure.ground)
    check = (None if not is_array and closes is True and nearest_dead is None
             else LoopCheck(closes, nearest_dead))
    return stretched * (stretched > 0.0), folded * (folded > 0.0), check


def array_factors(
    closure: LoopClosure, alpha: np.ndarray, distance: np.ndarray, stretched: np.ndarray,
    folded: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, LoopCheck | None]:
    """
    Return Heron's factors of an array, each element in the form the scalar path would take.

    ``stretched`` and ``folded`` are AB + BC − d and d − |AB − BC|. Where both exceed FAR·d the
    factors are their products with AB + BC + d and d + |AB − BC|; elsewhere ``exact_factors``.
    The check is None where every element is far from the factors' zeros.
    """
    near = (stretched < FAR * distance) | (folded < FAR * distance)
    stretched = stretched * (closure.stretched.length + distance)
    folded = folded * (distance + closure.folded.length)
    if not np.any(near):
        return stretched, folded, None
    stretched[near], folded[near], near_check = exact_factors(
        closure, alpha[near], distance[near], np.sin)
    closes = np.ones(alpha.shape, dtype=bool)
    closes[near] = near_check.closes
    nearest_dead = None
    if near_check.nearest_dead is not None:
        nearest_dead = np.full(alpha.shape, np.inf)
        nearest_dead[near] = near_check.nearest_dead
    return stretched, folded, LoopCheck(closes, nearest_dead)
