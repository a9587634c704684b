# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The seed paper's numbers beside this package's, for docs/kinematics.md.

Run from the repository root:  .venv/bin/python docs/seed_comparison.py
Prints (1) the seed's Tables 3 and 4 (variable law ω = 0.10 + 2.3·α) beside the exact values at
α = 0 and 90°, (2) the error of the seed's position constraint sin α = 1 − cos β (its Eq. 2)
over the 90° turn, and (3) the reachable set of its "full revolution" redesign.
"""

from __future__ import annotations

import math
from pathlib import Path
import sys

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from linkage_kinematics.kinematics.drive import DriveLaw  # noqa: E402
from linkage_kinematics.kinematics.geometry import PRESETS  # noqa: E402
from linkage_kinematics.kinematics.solver import solve  # noqa: E402

PAPER = PRESETS['paper'].geometry
VARIABLE = DriveLaw(0.10, 2.3)

# The seed's Tables 3 and 4 as printed (ω̇ is its Eq. 6c, a constant 4.4 rad/s²).
SEED = {
    0: {'omega': 0.1, 'omega_dot': 4.4, 'v_a': 0.03, 'v_b': 0.1, 'omega_ab': 0.1,
        'omega_bc': -0.33, 'omega_dot_ab': 4.2, 'omega_dot_bc': -14.1},
    90: {'omega': 7.0, 'omega_dot': 4.4, 'v_a': 2.1, 'v_b': 0.63, 'omega_ab': -2.1,
         'omega_bc': -2.1, 'omega_dot_ab': -1.3, 'omega_dot_bc': 61.7},
}
LABELS = {'omega': 'ω (rad/s)', 'omega_dot': 'ω̇ (rad/s²)', 'v_a': 'V_A (m/s)',
          'v_b': 'V_B (m/s)', 'omega_ab': 'ω_AB (rad/s)', 'omega_bc': 'ω_BC (rad/s)',
          'omega_dot_ab': 'ω̇_AB (rad/s²)', 'omega_dot_bc': 'ω̇_BC (rad/s²)'}


def with_seed_inputs(degrees: int) -> DriveLaw:
    """Return a drive law whose ω and ω̇ at this α are the seed's (ω̇ = k·ω fixes k, then ω0)."""
    omega, omega_dot = SEED[degrees]['omega'], SEED[degrees]['omega_dot']
    k = omega_dot / omega
    return DriveLaw(omega - k * math.radians(degrees), k)


def tables_3_and_4() -> None:
    exact = {degrees: solve(PAPER, math.radians(degrees), VARIABLE) for degrees in SEED}
    replayed = {degrees: solve(PAPER, math.radians(degrees), with_seed_inputs(degrees))
                for degrees in SEED}
    print("| quantity | seed α = 0 | exact α = 0 | exact, seed's ω, ω̇ | seed α = 90° | "
          "exact α = 90° | exact, seed's ω, ω̇ |")
    print('|---|---|---|---|---|---|---|')
    for name, label in LABELS.items():
        cells = []
        for degrees in SEED:
            cells += [f'{SEED[degrees][name]:g}', f'{float(getattr(exact[degrees], name)):.4g}',
                      f'{float(getattr(replayed[degrees], name)):.4g}']
        print(f'| {label} | ' + ' | '.join(cells) + ' |')
    turn = VARIABLE.time_to(0.0, math.pi / 2)
    print(f"\nexact time for the 90° turn: {turn:.4f} s (the seed's α = 1.9·t gives "
          f'{(math.pi / 2) / 1.9:.4f} s)')


def seed_position_error() -> None:
    """β from sin α = 1 − cos β, γ and |AB| from the seed's Eqs. (3)–(4)."""
    oa, bc, oc = PAPER.crank_length, PAPER.rocker_length, PAPER.ground_x
    worst_beta = (0.0, 0.0)
    worst_stretch = (0.0, 0.0)
    print('\n| α (°) | seed β (°) | exact β (°) | seed γ (°) | exact γ (°) | '
          "seed's AB length / AB |")
    print('|---|---|---|---|---|---|')
    for tenth_degrees in range(0, 901):
        alpha = math.radians(tenth_degrees / 10)
        beta = math.acos(1.0 - math.sin(alpha))
        opposite = bc * math.sin(beta) + oa * math.cos(alpha)
        adjacent = oc - oa * math.sin(alpha) - bc * math.cos(beta)
        stretch = math.hypot(opposite, adjacent) / PAPER.coupler_length
        exact = solve(PAPER, alpha, VARIABLE)
        beta_error = math.degrees(beta - exact.beta)
        worst_beta = max(worst_beta, (abs(beta_error), tenth_degrees / 10))
        worst_stretch = max(worst_stretch, (abs(stretch - 1.0), tenth_degrees / 10))
        if tenth_degrees % 150 == 0:
            print(f'| {tenth_degrees / 10:g} | {math.degrees(beta):.2f} | '
                  f'{round(math.degrees(exact.beta), 2) + 0.0:.2f} | '
                  f'{math.degrees(math.atan2(opposite, adjacent)):.2f} | '
                  f'{math.degrees(exact.gamma):.2f} | {stretch:.4f} |')
    print(f'\nlargest β error {worst_beta[0]:.2f}° at α = {worst_beta[1]:g}°; '
          f'largest change of |AB| {100 * worst_stretch[0]:.2f}% at α = {worst_stretch[1]:g}°')


def full_turn_design() -> None:
    design = PRESETS['paper_full_turn'].geometry
    print(f"\n'full revolution' redesign: OC = {design.ground_x:.4f} m, Grashof: "
          f'{design.is_grashof}; the loop closes only for α in {design.reachability.describe()}')


if __name__ == '__main__':
    tables_3_and_4()
    seed_position_error()
    full_turn_design()
