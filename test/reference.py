# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Independent high-precision reference for the four-bar kinematics (mpmath, 50 digits).

Why it is independent of ``linkage_kinematics.kinematics.solver``:

* Positions. The library intersects two circles (Heron's formula for the height of B over the
  line A→C). Here the loop closure is written as one equation in the rocker angle β alone.
  With A = r·(sin α, −cos α), C = (x_C, y_C), B = C + c·(−cos β, sin β) and (P, Q) = C − A,
  |B − A|² = b² reads

      P·cos β − Q·sin β = K,      K = (P² + Q² + c² − b²)/(2c),

  i.e. R·cos(β + φ) = K with R = |C − A| and φ = atan2(Q, P). Its two roots are
  β = −φ ± acos(K/R); the cross product (C − A) × (B − A) = c·R·sin(±acos(K/R)) shows that
  ``branch = +1`` (B left of A→C) is the ``+`` root. γ is then the direction of B − A.
* Rates and accelerations. The library solves the differentiated loop equations by Cramer's
  rule. Here β(α) and γ(α) are differentiated numerically in high precision (``mpmath.diffs``,
  which steps by about 2^-(prec+10) and raises the working precision to match), and the chain
  rule with ω = ω0 + k·α and α̈ = k·ω gives the time derivatives:
  β̇ = β'·ω, β̈ = β''·ω² + β'·α̈ (likewise γ); pin B's rates follow from B(β) the same way.
* Dead points come from |C − A(α)| = AB + BC or |AB − BC| written in coordinates
  (x_C·sin α − y_C·cos α = (OC² + OA² − L²)/(2·OA)) and solved with asin, where the library
  uses the cosine of the angle between OA and OC.
* Through change points (``continued_sides``) the motion is followed in small steps, choosing
  at each the root whose angles and slopes continue those before it; the library instead flips
  the side by rule at each change point it knows of.
* The input floor (``input_floor``) is the change of the exact answer between α and its
  neighbouring floats.

Every input is the exact float the library receives (converted to mpf without rounding), so
any difference is the library's own error. Used by the tests and by the benchmarks.
"""

from __future__ import annotations

import math
from typing import Callable

from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import FourBar
from linkage_kinematics.kinematics.solver import CrankRates, LinkageState
from mpmath import mp, mpf

# Enough digits that the reference's own error stays far below anything float64 can show, even
# 1e-15 rad from a dead point where the square-root conditioning eats half of them.
DIGITS = 50


def _wrap(angle: mpf) -> mpf:
    """``angle`` wrapped to (−π, π]."""
    wrapped = angle - 2 * mp.pi * mp.floor(angle / (2 * mp.pi) + mpf('0.5'))
    return wrapped if wrapped > -mp.pi else wrapped + 2 * mp.pi


def _angles(linkage: FourBar, alpha: mpf, branch: int) -> tuple[mpf, mpf]:
    """(β, γ) at crank angle ``alpha`` from the rocker-angle equation (module docstring)."""
    r = mpf(linkage.crank_length)
    b = mpf(linkage.coupler_length)
    c = mpf(linkage.rocker_length)
    pin_a_x = r * mp.sin(alpha)
    pin_a_y = -r * mp.cos(alpha)
    p = mpf(linkage.ground_x) - pin_a_x
    q = mpf(linkage.ground_y) - pin_a_y
    distance_squared = p * p + q * q
    ratio = (distance_squared + c * c - b * b) / (2 * c * mp.sqrt(distance_squared))
    if abs(ratio) > 1:
        # At a change point |ratio| touches 1; rounding in the last digits may pass it.
        if abs(ratio) - 1 > mpf(10) ** (10 - mp.dps):
            raise ValueError(f'reference: the loop does not close at α = {alpha}')
        ratio = mp.sign(ratio)
    beta = -mp.atan2(q, p) + branch * mp.acos(ratio)
    pin_b_x = mpf(linkage.ground_x) - c * mp.cos(beta)
    pin_b_y = mpf(linkage.ground_y) + c * mp.sin(beta)
    gamma = mp.atan2(pin_b_y - pin_a_y, pin_b_x - pin_a_x)
    return _wrap(beta), gamma


def _derivatives(function: Callable[[mpf], mpf], alpha: mpf) -> tuple[mpf, mpf, mpf]:
    """
    Return an angle-valued function and its first two α-derivatives.

    Unwrapped around ``alpha``.
    """
    centre = function(alpha)
    value, first, second = mp.diffs(lambda t: _wrap(function(t) - centre), alpha, 2)
    return centre + value, first, second


def _crank_rates(drive: DriveLaw | CrankRates, alpha: mpf) -> tuple[mpf, mpf]:
    """ω and ω̇ at ``alpha``: from the drive law, or as given."""
    if isinstance(drive, CrankRates):
        return mpf(drive.omega), mpf(drive.omega_dot)
    omega = mpf(drive.omega0) + mpf(drive.k) * alpha
    return omega, mpf(drive.k) * omega


def reference_state(
    linkage: FourBar, alpha: float, drive: DriveLaw | CrankRates, branch: int = 1
) -> dict[str, mpf]:
    """Every ``LinkageState`` quantity at ``alpha``, as mpf values keyed by field name."""
    with mp.workdps(DIGITS):
        a = mpf(alpha)
        beta, beta_1, beta_2 = _derivatives(lambda t: _angles(linkage, t, branch)[0], a)
        gamma, gamma_1, gamma_2 = _derivatives(lambda t: _angles(linkage, t, branch)[1], a)
        omega, omega_dot = _crank_rates(drive, a)
        beta_rate = beta_1 * omega
        beta_acceleration = beta_2 * omega * omega + beta_1 * omega_dot
        r = mpf(linkage.crank_length)
        c = mpf(linkage.rocker_length)
        sin_a, cos_a = mp.sin(a), mp.cos(a)
        sin_b, cos_b = mp.sin(beta), mp.cos(beta)
        pin_a = (r * sin_a, -r * cos_a)
        pin_b = (mpf(linkage.ground_x) - c * cos_b, mpf(linkage.ground_y) + c * sin_b)
        # dB/dβ = c·(sin β, cos β) and d²B/dβ² = c·(cos β, −sin β)
        velocity_b = (c * sin_b * beta_rate, c * cos_b * beta_rate)
        acceleration_b = (
            c * (sin_b * beta_acceleration + cos_b * beta_rate**2),
            c * (cos_b * beta_acceleration - sin_b * beta_rate**2),
        )
        coupler = (pin_b[0] - pin_a[0], pin_b[1] - pin_a[1])
        rocker = (pin_b[0] - mpf(linkage.ground_x), pin_b[1] - mpf(linkage.ground_y))
        cosine = (coupler[0] * rocker[0] + coupler[1] * rocker[1]) / (
            mp.sqrt(coupler[0] ** 2 + coupler[1] ** 2) * mp.sqrt(rocker[0] ** 2 + rocker[1] ** 2)
        )
        return {
            'alpha': a,
            'beta': beta,
            'gamma': gamma,
            'omega': omega,
            'omega_dot': omega_dot,
            'omega_ab': gamma_1 * omega,
            'omega_bc': -beta_rate,
            'omega_dot_ab': gamma_2 * omega * omega + gamma_1 * omega_dot,
            'omega_dot_bc': -beta_acceleration,
            'pin_a_x': pin_a[0],
            'pin_a_y': pin_a[1],
            'pin_b_x': pin_b[0],
            'pin_b_y': pin_b[1],
            'velocity_a_x': r * cos_a * omega,
            'velocity_a_y': r * sin_a * omega,
            'velocity_b_x': velocity_b[0],
            'velocity_b_y': velocity_b[1],
            'acceleration_a_x': r * (cos_a * omega_dot - sin_a * omega * omega),
            'acceleration_a_y': r * (sin_a * omega_dot + cos_a * omega * omega),
            'acceleration_b_x': acceleration_b[0],
            'acceleration_b_y': acceleration_b[1],
            'transmission_angle': mp.acos(max(-1, min(1, cosine))),
        }


def _crank_side(linkage: FourBar, theta: mpf, side: int) -> tuple[mpf, mpf]:
    """
    (α, γ) at rocker angle θ_BC = ``theta``, with A on ``side`` of the directed line B→O.

    With B = C + BC·(cos θ, sin θ) and A = OA·(sin α, −cos α), |B − A|² = AB² reads
    B_x·sin α − B_y·cos α = K, K = (|B|² + OA² − AB²)/(2·OA), i.e. |B|·sin(α − ψ) = K with
    ψ = atan2(B_y, B_x): α = ψ + asin(K/|B|) or ψ + π − asin(K/|B|); the side is the sign of
    (O − B) × (A − B).
    """
    r = mpf(linkage.crank_length)
    b = mpf(linkage.coupler_length)
    c = mpf(linkage.rocker_length)
    pin_b_x = mpf(linkage.ground_x) + c * mp.cos(theta)
    pin_b_y = mpf(linkage.ground_y) + c * mp.sin(theta)
    reach = mp.sqrt(pin_b_x**2 + pin_b_y**2)
    ratio = (pin_b_x**2 + pin_b_y**2 + r * r - b * b) / (2 * r * reach)
    if abs(ratio) > 1:
        raise ValueError(f'reference: the loop does not close at θ = {theta}')
    heading = mp.atan2(pin_b_y, pin_b_x)
    for alpha in (heading + mp.asin(ratio), heading + mp.pi - mp.asin(ratio)):
        pin_a_x, pin_a_y = r * mp.sin(alpha), -r * mp.cos(alpha)
        cross = (-pin_b_x) * (pin_a_y - pin_b_y) - (-pin_b_y) * (pin_a_x - pin_b_x)
        if mp.sign(cross) == side:
            return _wrap(alpha), mp.atan2(pin_b_y - pin_a_y, pin_b_x - pin_a_x)
    raise ValueError(f'reference: no assembly on side {side} at θ = {theta}')


def reference_rocker_driven(
    linkage: FourBar, theta: float, rates: CrankRates, side: int = 1
) -> dict[str, mpf]:
    """
    Return the quantities of a rocker-driven state at rocker angle ``theta`` (θ_BC = π − β).

    ``rates`` are the rocker's ω_BC and ω̇_BC; ``side`` that of A relative to B→O. Independent
    of the library's inversion: the crank side is solved directly (``_crank_side``, an asin
    form) and differentiated numerically in θ, then the chain rule with ω_BC, ω̇_BC.
    """
    with mp.workdps(DIGITS):
        t = mpf(theta)
        alpha, alpha_1, alpha_2 = _derivatives(lambda u: _crank_side(linkage, u, side)[0], t)
        gamma, gamma_1, gamma_2 = _derivatives(lambda u: _crank_side(linkage, u, side)[1], t)
        omega_bc, omega_dot_bc = mpf(rates.omega), mpf(rates.omega_dot)
        r = mpf(linkage.crank_length)
        c = mpf(linkage.rocker_length)
        return {
            'alpha': alpha,
            'beta': _wrap(mp.pi - t),
            'gamma': gamma,
            'omega': alpha_1 * omega_bc,
            'omega_dot': alpha_2 * omega_bc**2 + alpha_1 * omega_dot_bc,
            'omega_ab': gamma_1 * omega_bc,
            'omega_dot_ab': gamma_2 * omega_bc**2 + gamma_1 * omega_dot_bc,
            'omega_bc': omega_bc,
            'omega_dot_bc': omega_dot_bc,
            'pin_a_x': r * mp.sin(alpha),
            'pin_a_y': -r * mp.cos(alpha),
            'pin_b_x': mpf(linkage.ground_x) + c * mp.cos(t),
            'pin_b_y': mpf(linkage.ground_y) + c * mp.sin(t),
        }


def reference_singular_angles(linkage: FourBar) -> list[mpf]:
    """
    Crank angles in (−π, π] where coupler and rocker are collinear, ascending.

    These are the dead points (interval ends) and, for Grashof-equality linkages, the change
    points where the two branches meet (double roots).
    """
    with mp.workdps(DIGITS):
        r = mpf(linkage.crank_length)
        b = mpf(linkage.coupler_length)
        c = mpf(linkage.rocker_length)
        x_c = mpf(linkage.ground_x)
        y_c = mpf(linkage.ground_y)
        ground = mp.sqrt(x_c * x_c + y_c * y_c)
        # x_C·sin α − y_C·cos α = OC·sin(α − θ) with θ the direction of OC
        theta = mp.atan2(y_c, x_c)
        angles: list[mpf] = []
        for collinear_length in (b + c, abs(b - c)):
            sine = (ground * ground + r * r - collinear_length**2) / (2 * r * ground)
            if abs(sine) <= 1:
                for root in (mp.asin(sine), mp.pi - mp.asin(sine)):
                    angle = _wrap(theta + root)
                    # a double root (change point) comes out twice, equal to ~DIGITS digits
                    if all(abs(angle - known) > mpf(10) ** (10 - DIGITS) for known in angles):
                        angles.append(angle)
        return sorted(angles)


def continued_sides(
    linkage: FourBar, alpha_start: float, branch: int, alphas: list[float],
    max_step: float = 0.01,
) -> list[int]:
    """
    Return the assembly at each of ``alphas`` of a smooth motion.

    The assembly is ``reference_state``'s ``branch`` argument; the motion starts at
    ``alpha_start`` on ``branch`` and turns smoothly through ``alphas``.

    ``alphas`` must run monotonically away from ``alpha_start``. Independent of the library's
    rule (change points flip the side): this follows the motion in steps of at most
    ``max_step`` rad in 30-digit arithmetic, taking at each step the root of the rocker-angle
    equation whose β and γ continue those of the steps before (extrapolated along their
    secant). Where both roots fit about equally (a step landing on a change point, where the
    roots have the same angles but different slopes), the root whose slopes dβ/dα, dγ/dα
    continue the motion's is taken.
    """
    with mp.workdps(30):
        def slopes(alpha: mpf, side: int, angles: tuple[mpf, mpf]) -> tuple[mpf, mpf]:
            return tuple(
                mp.diff(lambda t, i=i: _wrap(_angles(linkage, t, side)[i] - angles[i]), alpha)
                for i in (0, 1)
            )

        side = branch
        position = mpf(alpha_start)
        angles = _angles(linkage, position, side)
        rates = slopes(position, side, angles)
        sides = []
        for target in alphas:
            target = mpf(target)
            pieces = max(1, int(mp.ceil(abs(target - position) / max_step)))
            start = position
            for index in range(1, pieces + 1):
                here = start + (target - start) * index / pieces if index < pieces else target
                moved = here - position
                predicted = [angle + rate * moved for angle, rate in zip(angles, rates)]
                candidates = {s: _angles(linkage, here, s) for s in (1, -1)}
                misfit = {s: sum(abs(_wrap(c - p)) for c, p in zip(candidates[s], predicted))
                          for s in candidates}
                best, other = sorted(candidates, key=misfit.get)
                if misfit[best] < mpf('0.01') * misfit[other]:
                    side = best
                    # the secant carries the slopes on (its error is O(step·curvature))
                    rates = [_wrap(c - a) / moved for c, a in zip(candidates[side], angles)]
                else:
                    candidate_rates = {s: slopes(here, s, candidates[s]) for s in candidates}
                    side = min(candidates, key=lambda s: sum(
                        abs(c - r) for c, r in zip(candidate_rates[s], rates)))
                    rates = list(candidate_rates[side])
                angles = candidates[side]
                position = here
            sides.append(side)
        return sides


def _group_errors(values: dict[str, mpf], reference: dict[str, mpf]) -> dict[str, float]:
    """``state_errors`` for any values keyed like ``reference_state``."""
    with mp.workdps(DIGITS):
        def gap(name: str) -> mpf:
            return abs(values[name] - reference[name])

        def angle_gap(name: str) -> mpf:
            return abs(_wrap(values[name] - reference[name]))

        def normwise(names: tuple[str, ...], floor: mpf = mpf(0)) -> float:
            scale = max([abs(reference[name]) for name in names] + [floor])
            return float(max(gap(name) for name in names) / scale)

        omega_squared = reference['omega'] ** 2
        pin_names = ('pin_a_x', 'pin_a_y', 'pin_b_x', 'pin_b_y')
        return {
            'angle': float(max(angle_gap('beta'), angle_gap('gamma'))),
            'pin': normwise(pin_names),
            'angular_rate': normwise(('omega', 'omega_ab', 'omega_bc')),
            'angular_acceleration': normwise(
                ('omega_dot', 'omega_dot_ab', 'omega_dot_bc'), omega_squared
            ),
            'velocity': normwise(('velocity_a_x', 'velocity_a_y', 'velocity_b_x', 'velocity_b_y')),
            'acceleration': normwise(
                ('acceleration_a_x', 'acceleration_a_y', 'acceleration_b_x', 'acceleration_b_y')
            ),
        }


def state_errors(state: LinkageState, reference: dict[str, mpf]) -> dict[str, float]:
    """
    How far a float ``LinkageState`` is from ``reference_state``, by kind of quantity.

    ``angle``: largest error of β and γ (rad). ``pin``: largest pin-coordinate error relative to
    the largest pin distance from O. The rest are normwise relative errors of a group: angular
    rates (ω, ω_AB, ω_BC), angular accelerations (ω̇, ω̇_AB, ω̇_BC, scaled by at least ω²),
    pin velocities and pin accelerations; a group's scale is its largest reference magnitude,
    so a component passing through zero does not blow up the figure.
    """
    with mp.workdps(DIGITS):
        values = {name: mpf(getattr(state, name)) for name in reference}
    return _group_errors(values, reference)


def input_floor(
    linkage: FourBar, alpha: float, drive: DriveLaw, branch: int = 1
) -> dict[str, float]:
    """
    Return what a one-ulp change of the float α alone does to the exact answer.

    In the terms of ``state_errors``: the larger change over the two neighbouring floats of α (only
    those on which the loop closes), on the same assembly.

    No float64 evaluation from α can be expected to do better than this.
    """
    exact = reference_state(linkage, alpha, drive, branch)
    floors = []
    for neighbour in (math.nextafter(alpha, math.inf), math.nextafter(alpha, -math.inf)):
        try:
            floors.append(_group_errors(reference_state(linkage, neighbour, drive, branch), exact))
        except ValueError:  # past a dead point
            continue
    return {kind: max(floor[kind] for floor in floors) for kind in floors[0]}
