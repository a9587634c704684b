# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Measure the planar-loop solver's error near dead and change points against the reference.

The reference is test/prismatic_reference.py. Run from the repository root:
.venv/bin/python docs/loop_accuracy.py   (about 12 s)
Prints the tables of docs/kinematics.md, "Planar loops of four joints":

* the loops with one slide of test_planar_loop's REFERENCE_LOOPS, every case of known joint,
  both branches, each dead point approached from its reachable side at 1e-3 … 1e-15 of its
  value (one distance per decade): the worst coordinate error (rad or m), the worst normwise
  rate error, the worst ratio of each to the input floor, and how often solve_loop refuses;
* the change-point loops (CHANGE_LOOP, ISOSCELES) at ±1e-1 … ±1e-15 from each change point on
  the smooth branch: the worst errors.
"""

from __future__ import annotations

from pathlib import Path
import sys

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / 'test'))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from linkage_kinematics.kinematics.planar_loop import (  # noqa: E402
    continued_branch_of,
    known_joint_range,
    PlanarLoop,
    solve_loop,
)
from linkage_kinematics.kinematics.solver import DeadPointError  # noqa: E402
from prismatic_reference import (  # noqa: E402
    errors,
    input_floor,
    reference_dead_point,
    reference_state,
)
from test_planar_loop import CHANGE_LOOP, ISOSCELES, REFERENCE_LOOPS  # noqa: E402

RATE = 1.3


def case_name(loop: PlanarLoop, known: int) -> str:
    """Name the case of the known joint relative to the prismatic one."""
    return {0: 'the slide', 1: 'next to it, p + 1', 2: 'opposite it',
            3: 'next to it, p − 1'}[(known - loop.prismatic) % 4]


def dead_point_rows() -> dict[tuple[str, int], list]:
    """Return, per case and decade, [coordinate error, rate error, ratios, answered, refused]."""
    rows: dict[tuple[str, int], list] = {}
    for loops in REFERENCE_LOOPS.values():
        for loop in loops:
            for known in (1, 2, 3):
                reach = known_joint_range(loop, known)
                for dead in reach.dead_points:
                    exact = reference_dead_point(loop, known, dead)
                    scale = max(1.0, abs(dead))
                    inward = 1.0 if reach.contains(dead + 1e-6 * scale) else -1.0
                    for branch in (1, -1):
                        for decade in range(3, 16):
                            value = float(exact + inward * 10.0 ** -decade * scale)
                            row = rows.setdefault((case_name(loop, known), decade),
                                                  [0.0, 0.0, 0.0, 0.0, 0, 0])
                            try:
                                state = solve_loop(loop, known, value, RATE, branch)
                            except DeadPointError:
                                row[5] += 1
                                continue
                            reference = reference_state(loop, known, value, RATE,
                                                        state.coordinates)
                            error = errors(loop, state.coordinates, state.rates, reference)
                            floor = input_floor(loop, known, value, RATE, state.coordinates)
                            row[0] = max(row[0], error[0])
                            row[1] = max(row[1], error[1])
                            row[2] = max(row[2], error[0] / floor[0])
                            row[3] = max(row[3], error[1] / floor[1])
                            row[4] += 1
    return rows


def change_point_rows() -> list[tuple[str, float, float]]:
    """Return the worst coordinate and rate errors through each loop's change points."""
    rows = []
    for name, loop, knowns in (('CHANGE_LOOP', CHANGE_LOOP, (1, 2, 3)),
                               ('ISOSCELES', ISOSCELES, (1, 3))):
        for known in knowns:
            worst = [0.0, 0.0]
            for point in known_joint_range(loop, known).change_points:
                for branch in (1, -1):
                    for offset in [sign * 10.0 ** -k for k in range(1, 16) for sign in (1, -1)]:
                        value = point + offset
                        state = solve_loop(loop, known, value, RATE, continued_branch_of(
                            loop, known, point - 0.05, branch, value))
                        error = errors(loop, state.coordinates, state.rates, reference_state(
                            loop, known, value, RATE, state.coordinates))
                        worst = [max(worst[0], error[0]), max(worst[1], error[1])]
            rows.append((f'{name} known {known}, {case_name(loop, known)}', *worst))
    return rows


def main() -> None:
    """Print both tables."""
    print('| known joint | distance | coordinates | rates | ÷ floor | answered | refused |')
    print('|---|---|---|---|---|---|---|')
    for (case, decade), row in sorted(dead_point_rows().items()):
        errors_shown = (f'{row[0]:.1e} | {row[1]:.1e} | {row[2]:.2g}, {row[3]:.2g}'
                        if row[4] else '— | — | —')
        print(f'| {case} | 1e-{decade} | {errors_shown} | {row[4]} | {row[5]} |')
    print()
    print('| change points | coordinates | rates |')
    print('|---|---|---|')
    for name, coordinate_error, rate_error in change_point_rows():
        print(f'| {name} | {coordinate_error:.1e} | {rate_error:.1e} |')


if __name__ == '__main__':
    main()
