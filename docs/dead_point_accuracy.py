# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Measure the library's error near dead points and change points against test/reference.py.

Run from the repository root:  .venv/bin/python docs/dead_point_accuracy.py
Prints the tables of docs/kinematics.md:

* the paper mechanism approaching its two dead points (α ≈ −1.941° and 181.941°) from their
  reachable sides, both branches, both drive laws, 4 random distances δ per decade: the worst
  error of each kind, the worst ratio of error to the input floor (what a one-ulp change of the
  float α does to the exact answer, reference.input_floor), and how often solve() refuses;
* three change-point linkages approaching their change points from both sides, and on the
  float nearest each change point, on both assemblies: the worst errors.

Errors are those of reference.state_errors: angles in rad, the rest normwise relative.
"""

from __future__ import annotations

import math
from pathlib import Path
import random
import sys

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / 'test'))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from linkage_kinematics.kinematics.drive import DriveLaw  # noqa: E402
from linkage_kinematics.kinematics.geometry import FourBar, PRESETS  # noqa: E402
from linkage_kinematics.kinematics.solver import DeadPointError, solve  # noqa: E402
from mpmath import mpf  # noqa: E402
from reference import (  # noqa: E402
    input_floor,
    reference_singular_angles,
    reference_state,
    state_errors,
)

DRIVES = (DriveLaw(2.0), DriveLaw(0.10, 2.3))
GROUPS = {
    'angles': ('angle',),
    'rates': ('angular_rate', 'velocity'),
    'accelerations': ('angular_acceleration', 'acceleration'),
}


def dead_points(linkage: FourBar) -> list[tuple[mpf, int, str]]:
    """Each dead point with the direction of its reachable side and a label."""
    points = reference_singular_angles(linkage)
    low, high = linkage.reachability.intervals[0]
    found = []
    for end, side in ((low, 1), (high, -1)):
        point = min(points, key=lambda p: abs(math.remainder(float(p) - end, 2 * math.pi)))
        found.append((point, side, f'{math.degrees(end):.3f}°'))
    return found


def dead_point_table(rng: random.Random) -> None:
    paper = PRESETS['paper'].geometry
    print('paper mechanism, approaching each dead point from its reachable side (worst of 4 δ '
          'per decade × 2 branches × 2 drive laws)')
    for point, side, label in dead_points(paper):
        print()
        print(f'dead point at {label}')
        print('| δ (rad) | angles (rad) | rates | accelerations | worst error ÷ input floor '
              '(angles, rates, accelerations) | solve() refuses |')
        print('|---|---|---|---|---|---|')
        for decade in range(1, 17):
            worst = {group: 0.0 for group in GROUPS}
            ratio = {group: 0.0 for group in GROUPS}
            refused = total = 0
            for _ in range(4):
                delta = 10.0 ** -(decade + rng.random())
                alpha = float(point + side * delta)
                if alpha == float(point):
                    continue
                for branch in (1, -1):
                    for drive in DRIVES:
                        total += 1
                        try:
                            state = solve(paper, alpha, drive, branch)
                        except DeadPointError:
                            refused += 1
                            continue
                        errors = state_errors(state, reference_state(paper, alpha, drive, branch))
                        floor = input_floor(paper, alpha, drive, branch)
                        for group, kinds in GROUPS.items():
                            for kind in kinds:
                                worst[group] = max(worst[group], errors[kind])
                                ratio[group] = max(ratio[group], errors[kind] / floor[kind])
            answered = total - refused
            cells = (' | '.join(f'{worst[group]:.1e}' for group in GROUPS) if answered
                     else '— | — | —')
            ratios = (', '.join(f'{ratio[group]:.2g}' for group in GROUPS) if answered else '—')
            print(f'| 1e-{decade + 1}…1e-{decade} | {cells} | {ratios} | {refused}/{total} |')


def change_point_table() -> None:
    linkages = {
        'parallelogram 0.3/1.0/0.3, C = (1, 0)': FourBar(0.3, 1.0, 0.3, 1.0, 0.0),
        'kite 0.4/0.4/1, C = (1, 0)': FourBar(0.4, 0.4, 1.0, 1.0, 0.0),
        'general 0.25/0.75/0.5, C = (0.5, 0)': FourBar(0.25, 0.75, 0.5, 0.5, 0.0),
    }
    print()
    print('change points: worst error over both sides, both assemblies and both drive laws, at '
          'offsets 1e-1 … 1e-16 rad and on the float nearest each change point')
    print('| linkage | angles (rad) | rates | accelerations |')
    print('|---|---|---|---|')
    for name, linkage in linkages.items():
        worst = {group: 0.0 for group in GROUPS}
        for point in linkage.reachability.change_points:
            angles = [point] + [point + side * 10.0 ** -decade
                                for decade in range(1, 17) for side in (1, -1)]
            for alpha in angles:
                for branch in (1, -1):
                    for drive in DRIVES:
                        state = solve(linkage, alpha, drive, branch)
                        errors = state_errors(state,
                                              reference_state(linkage, alpha, drive, branch))
                        for group, kinds in GROUPS.items():
                            for kind in kinds:
                                worst[group] = max(worst[group], errors[kind])
        print(f'| {name} | ' + ' | '.join(f'{worst[group]:.1e}' for group in GROUPS) + ' |')


if __name__ == '__main__':
    dead_point_table(random.Random(20261122))
    change_point_table()
