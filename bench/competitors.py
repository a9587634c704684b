# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Other ways to get the four-bar's positions, rates and accelerations, for comparison.

Each ``*_states`` function takes a list of crank angles (in sweep order, so that iterative
solvers can warm-start from the previous angle, as a timer-driven node would) and returns the
six quantities the report compares, as lists: β, γ (rad), ω_AB, ω_BC (rad/s), ω̇_AB, ω̇_BC
(rad/s²). NaN marks a configuration a method gave no result for.
"""

from __future__ import annotations

import math
from math import atan2, cos, sin, sqrt

from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import FourBar
from linkage_kinematics.kinematics.solver import continued_branch, solve_many
import numpy as np
import scipy.optimize

QUANTITIES = ('beta', 'gamma', 'omega_ab', 'omega_bc', 'omega_dot_ab', 'omega_dot_bc')
States = dict[str, list[float]]


def minimal_closed_form(
    crank: float, coupler: float, rocker: float, ground_x: float, ground_y: float,
    branch: int, omega0: float, k: float, alpha: float,
) -> tuple[float, ...]:
    """
    Return the library's closed form as bare straight-line ``math`` code.

    No checks, no state object, the same 22 outputs as a tuple. The yardstick for the scalar path's
    overhead.
    """
    sin_alpha = sin(alpha)
    cos_alpha = cos(alpha)
    pin_a_x = crank * sin_alpha
    pin_a_y = -crank * cos_alpha
    to_c_x = ground_x - pin_a_x
    to_c_y = ground_y - pin_a_y
    distance = sqrt(to_c_x * to_c_x + to_c_y * to_c_y)
    u_x = to_c_x / distance
    u_y = to_c_y / distance
    along = (coupler * coupler - rocker * rocker + distance * distance) / (2.0 * distance)
    heron = ((coupler + rocker - distance) * (rocker + distance - coupler)
             * (coupler + distance - rocker) * (coupler + rocker + distance))
    height = branch * sqrt(heron if heron > 0.0 else 0.0) / (2.0 * distance)
    coupler_x = along * u_x - height * u_y
    coupler_y = along * u_y + height * u_x
    rocker_along = along - distance
    rocker_x = rocker_along * u_x - height * u_y
    rocker_y = rocker_along * u_y + height * u_x
    e_ab_x = coupler_x / coupler
    e_ab_y = coupler_y / coupler
    e_bc_x = rocker_x / rocker
    e_bc_y = rocker_y / rocker
    sine = height * distance / (coupler * rocker)
    omega = omega0 + k * alpha
    omega_dot = k * omega
    velocity_a_x = crank * omega * cos_alpha
    velocity_a_y = crank * omega * sin_alpha
    omega_squared = omega * omega
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
        alpha, atan2(rocker_y, -rocker_x), atan2(coupler_y, coupler_x), omega, omega_dot,
        omega_ab, omega_bc, omega_dot_ab, omega_dot_bc, pin_a_x, pin_a_y,
        ground_x + rocker_x, ground_y + rocker_y, velocity_a_x, velocity_a_y,
        -omega_bc * rocker_y, omega_bc * rocker_x, acceleration_a_x, acceleration_a_y,
        -rocker_tangential * e_bc_y - rocker_centripetal * e_bc_x,
        rocker_tangential * e_bc_x - rocker_centripetal * e_bc_y,
        atan2(abs(sine), e_ab_x * e_bc_x + e_ab_y * e_bc_y),
    )


def minimal_states(
    linkage: FourBar, alphas: list[float], drive: DriveLaw, sides: list[int]
) -> States:
    """
    ``minimal_closed_form`` at every angle, each on the given side of A→C.

    Where it divides by a sine that rounded to zero, NaN (no result).
    """
    rows = []
    for alpha, side in zip(alphas, sides):
        try:
            rows.append(minimal_closed_form(
                linkage.crank_length, linkage.coupler_length, linkage.rocker_length,
                linkage.ground_x, linkage.ground_y, side, drive.omega0, drive.k, alpha))
        except ZeroDivisionError:
            rows.append((math.nan,) * 22)
    return {name: [row[index] for row in rows]
            for name, index in zip(QUANTITIES, (1, 2, 5, 6, 7, 8))}


def minimal_numpy_closed_form(
    crank: float, coupler: float, rocker: float, ground_x: float, ground_y: float,
    branch: int | np.ndarray, omega0: float, k: float, alpha: np.ndarray,
) -> tuple[np.ndarray, ...]:
    """
    Return ``minimal_closed_form`` as bare whole-array ``numpy`` code.

    No checks, no pieces, no state object: the same 22 outputs as a tuple of arrays. The yardstick
    for the vectorised path's overhead (``solve_many``); a sine that rounded to zero gives inf or
    NaN there.
    """
    sin_alpha = np.sin(alpha)
    cos_alpha = np.cos(alpha)
    pin_a_x = crank * sin_alpha
    pin_a_y = -crank * cos_alpha
    to_c_x = ground_x - pin_a_x
    to_c_y = ground_y - pin_a_y
    distance = np.sqrt(to_c_x * to_c_x + to_c_y * to_c_y)
    u_x = to_c_x / distance
    u_y = to_c_y / distance
    along = (coupler * coupler - rocker * rocker + distance * distance) / (2.0 * distance)
    heron = ((coupler + rocker - distance) * (rocker + distance - coupler)
             * (coupler + distance - rocker) * (coupler + rocker + distance))
    height = branch * np.sqrt(np.maximum(heron, 0.0)) / (2.0 * distance)
    coupler_x = along * u_x - height * u_y
    coupler_y = along * u_y + height * u_x
    rocker_along = along - distance
    rocker_x = rocker_along * u_x - height * u_y
    rocker_y = rocker_along * u_y + height * u_x
    e_ab_x = coupler_x / coupler
    e_ab_y = coupler_y / coupler
    e_bc_x = rocker_x / rocker
    e_bc_y = rocker_y / rocker
    sine = height * distance / (coupler * rocker)
    omega = omega0 + k * alpha
    omega_dot = k * omega
    velocity_a_x = crank * omega * cos_alpha
    velocity_a_y = crank * omega * sin_alpha
    omega_squared = omega * omega
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
        alpha, np.arctan2(rocker_y, -rocker_x), np.arctan2(coupler_y, coupler_x), omega,
        omega_dot, omega_ab, omega_bc, omega_dot_ab, omega_dot_bc, pin_a_x, pin_a_y,
        ground_x + rocker_x, ground_y + rocker_y, velocity_a_x, velocity_a_y,
        -omega_bc * rocker_y, omega_bc * rocker_x, acceleration_a_x, acceleration_a_y,
        -rocker_tangential * e_bc_y - rocker_centripetal * e_bc_x,
        rocker_tangential * e_bc_x - rocker_centripetal * e_bc_y,
        np.arctan2(np.abs(sine), e_ab_x * e_bc_x + e_ab_y * e_bc_y),
    )


def minimal_numpy_states(
    linkage: FourBar, alphas: list[float], drive: DriveLaw, sides: list[int]
) -> States:
    """``minimal_numpy_closed_form`` over the angles, each on the given side of A→C."""
    with np.errstate(divide='ignore', invalid='ignore'):
        columns = minimal_numpy_closed_form(
            linkage.crank_length, linkage.coupler_length, linkage.rocker_length,
            linkage.ground_x, linkage.ground_y, np.array(sides), drive.omega0, drive.k,
            np.array(alphas))
    return {name: list(columns[index]) for name, index in zip(QUANTITIES, (1, 2, 5, 6, 7, 8))}


# --- Generic solution of the loop-closure equations -----------------------------------------
# Unknowns x = (γ, β); with A = OA·(sin α, −cos α), B = A + AB·(cos γ, sin γ) and
# B = C + BC·(−cos β, sin β), the loop closes where
#   F1 = OA·sin α + AB·cos γ + BC·cos β − x_C = 0
#   F2 = −OA·cos α + AB·sin γ − BC·sin β − y_C = 0.

def loop_residual(
    linkage: FourBar, alpha: float, gamma: float, beta: float
) -> tuple[float, float]:
    """(F1, F2) above."""
    return (
        linkage.crank_length * sin(alpha) + linkage.coupler_length * cos(gamma)
        + linkage.rocker_length * cos(beta) - linkage.ground_x,
        -linkage.crank_length * cos(alpha) + linkage.coupler_length * sin(gamma)
        - linkage.rocker_length * sin(beta) - linkage.ground_y,
    )


def loop_jacobian(
    linkage: FourBar, gamma: float, beta: float
) -> tuple[float, float, float, float]:
    """∂(F1, F2)/∂(γ, β) as (J11, J12, J21, J22)."""
    b = linkage.coupler_length
    c = linkage.rocker_length
    return (-b * sin(gamma), -c * sin(beta), b * cos(gamma), -c * cos(beta))


def solve_2x2(
    jacobian: tuple[float, float, float, float], right_x: float, right_y: float
) -> tuple[float, float]:
    """Cramer's rule on J·x = right."""
    j11, j12, j21, j22 = jacobian
    determinant = j11 * j22 - j12 * j21
    return ((right_x * j22 - j12 * right_y) / determinant,
            (j11 * right_y - right_x * j21) / determinant)


def rates_from_loop(
    linkage: FourBar, alpha: float, gamma: float, beta: float, drive: DriveLaw
) -> tuple[float, float, float, float]:
    """(ω_AB, ω_BC, ω̇_AB, ω̇_BC) from the loop equations differentiated once and twice."""
    r = linkage.crank_length
    b = linkage.coupler_length
    c = linkage.rocker_length
    omega = drive.omega0 + drive.k * alpha
    omega_dot = drive.k * omega
    jacobian = loop_jacobian(linkage, gamma, beta)
    sin_a, cos_a = sin(alpha), cos(alpha)
    gamma_rate, beta_rate = solve_2x2(jacobian, -r * cos_a * omega, -r * sin_a * omega)
    gamma_acc, beta_acc = solve_2x2(
        jacobian,
        r * sin_a * omega**2 - r * cos_a * omega_dot + b * cos(gamma) * gamma_rate**2
        + c * cos(beta) * beta_rate**2,
        -r * cos_a * omega**2 - r * sin_a * omega_dot + b * sin(gamma) * gamma_rate**2
        - c * sin(beta) * beta_rate**2,
    )
    return gamma_rate, -beta_rate, gamma_acc, -beta_acc


def seed_start_guess(linkage: FourBar) -> tuple[float, float]:
    """(γ, β) of the seed's Fig. 1a starting position, the guess a user would start from."""
    return (math.atan2(linkage.crank_length, linkage.ground_x - linkage.rocker_length), 0.0)


def newton_states(
    linkage: FourBar, alphas: list[float], drive: DriveLaw, tolerance: float,
    start: tuple[float, float],
) -> States:
    """Plain Newton on (F1, F2), warm-started from the previous angle's solution."""
    result: States = {name: [] for name in QUANTITIES}
    gamma, beta = start
    for alpha in alphas:
        for _ in range(50):
            f1, f2 = loop_residual(linkage, alpha, gamma, beta)
            step_gamma, step_beta = solve_2x2(loop_jacobian(linkage, gamma, beta), f1, f2)
            gamma -= step_gamma
            beta -= step_beta
            if abs(step_gamma) + abs(step_beta) < tolerance:
                break
        _append(result, linkage, alpha, gamma, beta, drive)
    return result


def scipy_root_states(
    linkage: FourBar, alphas: list[float], drive: DriveLaw, tolerance: float,
    start: tuple[float, float],
) -> States:
    """scipy.optimize.root (MINPACK hybrd, analytic Jacobian), warm-started."""
    result: States = {name: [] for name in QUANTITIES}
    guess = np.array(start)
    for alpha in alphas:
        solution = scipy.optimize.root(
            lambda x: loop_residual(linkage, alpha, x[0], x[1]),
            guess,
            jac=lambda x: np.reshape(loop_jacobian(linkage, x[0], x[1]), (2, 2)),
            method='hybr',
            tol=tolerance,
        )
        guess = solution.x
        _append(result, linkage, alpha, float(guess[0]), float(guess[1]), drive)
    return result


def fsolve_states(
    linkage: FourBar, alphas: list[float], drive: DriveLaw, start: tuple[float, float]
) -> States:
    """
    scipy.optimize.fsolve with its defaults (xtol 1.49e-8, numerical Jacobian).

    Warm-started.
    """
    result: States = {name: [] for name in QUANTITIES}
    guess = np.array(start)
    for alpha in alphas:
        guess = scipy.optimize.fsolve(lambda x: loop_residual(linkage, alpha, x[0], x[1]), guess)
        _append(result, linkage, alpha, float(guess[0]), float(guess[1]), drive)
    return result


def _append(
    result: States, linkage: FourBar, alpha: float, gamma: float, beta: float, drive: DriveLaw
) -> None:
    rates = rates_from_loop(linkage, alpha, gamma, beta, drive)
    wrapped_beta = math.remainder(beta, 2.0 * math.pi)
    for name, value in zip(QUANTITIES, (wrapped_beta, math.remainder(gamma, 2.0 * math.pi),
                                        *rates)):
        result[name].append(value)


# --- Rates by finite differences of exact positions -----------------------------------------

def finite_difference_states(
    linkage: FourBar, alphas: np.ndarray, drive: DriveLaw, step: float, start: float = 0.0,
    branch: int = 1,
) -> States:
    """
    Positions from solve_many, on the smooth motion that has ``branch`` at ``start``.

    Rates from central differences in α (forward ones where α − step is past the dead point), times
    ω, with α̈ = k·ω for the accelerations.
    """
    alphas = np.asarray(alphas, dtype=float)
    central = (np.full(alphas.shape, True) if linkage.reachability.full_rotation
               else alphas - step > linkage.reachability.intervals[0][0])
    stencil = np.concatenate([
        np.where(central, alphas - step, alphas),
        np.where(central, alphas, alphas + step),
        np.where(central, alphas + step, alphas + 2.0 * step),
    ])
    positions = solve_many(linkage, stencil, drive,
                           continued_branch(linkage, start, branch, stencil))
    size = alphas.size
    omega = drive.omega0 + drive.k * alphas
    omega_dot = drive.k * omega
    derivatives = {}
    for name in ('beta', 'gamma'):
        values = getattr(positions, name)
        f0, f1, f2 = values[:size], values[size:2 * size], values[2 * size:]
        first = np.where(central, (f2 - f0) / (2.0 * step),
                         (-3.0 * f0 + 4.0 * f1 - f2) / (2.0 * step))
        second = (f2 - 2.0 * f1 + f0) / step**2
        derivatives[name] = (np.where(central, f1, f0), first, second)
    beta, beta_1, beta_2 = derivatives['beta']
    gamma, gamma_1, gamma_2 = derivatives['gamma']
    return {
        'beta': list(beta),
        'gamma': list(gamma),
        'omega_ab': list(gamma_1 * omega),
        'omega_bc': list(-beta_1 * omega),
        'omega_dot_ab': list(gamma_2 * omega**2 + gamma_1 * omega_dot),
        'omega_dot_bc': list(-(beta_2 * omega**2 + beta_1 * omega_dot)),
    }


# --- pylinkage -------------------------------------------------------------------------------

class PylinkageModel:
    """
    The mechanism in pylinkage 1.3: grounds O and C, a Crank OA, an RRR dyad for B.

    pylinkage measures the crank angle from +x, so its angle is α − 90°; its crank advances by
    ``angular_velocity`` per step, and its kinematics take ω and α̈ per crank.
    """

    def __init__(self, linkage: FourBar, step: float = 0.0, start: float = 0.0,
                 branch: int = 1) -> None:
        import pylinkage

        self.linkage = linkage
        self.ground_o = pylinkage.Ground(0.0, 0.0, name='O')
        self.ground_c = pylinkage.Ground(linkage.ground_x, linkage.ground_y, name='C')
        self.crank = pylinkage.Crank(self.ground_o, linkage.crank_length,
                                     angular_velocity=step, initial_angle=start - math.pi / 2)
        self.pin_b = pylinkage.RRRDyad(self.crank.output, self.ground_c,
                                       distance1=linkage.coupler_length,
                                       distance2=linkage.rocker_length, name='B')
        # start B on the requested branch at the start angle (the paper's: left of A→C)
        placed = minimal_closed_form(linkage.crank_length, linkage.coupler_length,
                                     linkage.rocker_length, linkage.ground_x, linkage.ground_y,
                                     branch, 0.0, 0.0, start)
        self.pin_b.set_coord(placed[11], placed[12])
        self.model = pylinkage.Linkage([self.ground_o, self.ground_c, self.crank, self.pin_b])

    def states(self, alphas: list[float], drive: DriveLaw) -> States:
        """Place the crank at each α, give it ω and α̈, and take one pylinkage step."""
        result: States = {name: [] for name in QUANTITIES}
        self.crank.angular_velocity = 0.0
        r = self.linkage.crank_length
        for alpha in alphas:
            self.crank.set_coord(r * sin(alpha), -r * cos(alpha))
            omega = drive.omega0 + drive.k * alpha
            self.model.set_input_velocity(self.crank, omega, drive.k * omega)
            positions, velocities, accelerations = next(
                self.model.step_with_derivatives(iterations=1))
            self._append(result, positions, velocities, accelerations)
        return result

    def _append(self, result: States, positions, velocities, accelerations) -> None:
        (a_x, a_y), (b_x, b_y) = positions[2], positions[3]
        c_x, c_y = self.linkage.ground_x, self.linkage.ground_y
        coupler_x, coupler_y = b_x - a_x, b_y - a_y
        rocker_x, rocker_y = b_x - c_x, b_y - c_y
        result['beta'].append(atan2(rocker_y, -rocker_x))
        result['gamma'].append(atan2(coupler_y, coupler_x))
        if velocities[3] is None or accelerations[3] is None:
            for name in QUANTITIES[2:]:
                result[name].append(math.nan)
            return
        relative_v = (velocities[3][0] - velocities[2][0], velocities[3][1] - velocities[2][1])
        relative_a = (accelerations[3][0] - accelerations[2][0],
                      accelerations[3][1] - accelerations[2][1])
        coupler_squared = coupler_x**2 + coupler_y**2
        rocker_squared = rocker_x**2 + rocker_y**2
        # ω = (r × v)/|r|² about the bar's other end; the centripetal part of a is along r.
        result['omega_ab'].append((coupler_x * relative_v[1] - coupler_y * relative_v[0])
                                  / coupler_squared)
        result['omega_bc'].append((rocker_x * velocities[3][1] - rocker_y * velocities[3][0])
                                  / rocker_squared)
        result['omega_dot_ab'].append((coupler_x * relative_a[1] - coupler_y * relative_a[0])
                                      / coupler_squared)
        result['omega_dot_bc'].append(
            (rocker_x * accelerations[3][1] - rocker_y * accelerations[3][0]) / rocker_squared)

    def sweep(self, count: int, drive: DriveLaw) -> int:
        """
        Run pylinkage's own loop.

        ``count`` steps of step_with_derivatives from α = 0 (constant ω, the only law its per-crank
        ω supports without resetting it every step).
        """
        r = self.linkage.crank_length
        self.crank.set_coord(0.0, -r)
        self.model.set_input_velocity(self.crank, drive.omega0, 0.0)
        for _ in self.model.step_with_derivatives(iterations=count):
            pass
        return count

    def sweep_positions(self, count: int) -> int:
        """Run pylinkage's positions-only loop (Linkage.step) for ``count`` steps from α = 0."""
        r = self.linkage.crank_length
        self.crank.set_coord(0.0, -r)
        for _ in self.model.step(iterations=count):
            pass
        return count
