# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Measure the general closure's error against the independent 50-digit reference.

The reference is test/closure_reference.py; the mechanisms are test/closure_robots.py's. Run
from the repository root:
.venv/bin/python docs/closure_accuracy.py   (about 2 minutes)
Prints the tables of docs/kinematics.md, "The general closure":

* every mechanism along a motion of its known joints (in both directions for the ankle and the
  five-bar), 2000 samples, every 100th checked: the worst position error (rad or m), the worst
  normwise relative velocity error, the largest conditioning κ met, Newton's iterations;
* the five-bar approaching its stretched configuration (cranks at s and −s), by decade of the
  distance: κ, the errors, their ratio to κ·ε (positions) and κ²·ε (velocities), the
  singular-distance estimate against the true distance, and whether the sample is refused.
"""

from __future__ import annotations

import math
from pathlib import Path
import sys

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / 'test'))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import closure_robots  # noqa: E402
from linkage_kinematics.loops.refusals import SampleRefused  # noqa: E402
from linkage_kinematics.loops.structure import GroupKind  # noqa: E402
from mpmath import mp, mpf  # noqa: E402
from test_closure_newton import errors, known_at, MOTIONS, planned_for, stretched  # noqa: E402

EPSILON = sys.float_info.epsilon
SAMPLES = 2000


def motion_rows() -> list[tuple[str, str, float, float, float, int]]:
    """Return per motion: its name, how it is solved, worst errors, largest κ, iterations."""
    rows = []
    for case in MOTIONS:
        planned = planned_for(case)
        worst = [0.0, 0.0, 0.0]
        iterations = 0
        # the motions' periods are 400 samples or so: five periods at a fifth of the step
        for sample in range(SAMPLES + 1):
            step = sample / 5
            known, rates = known_at(case, step)
            state = planned.solver.solve(known, rates)
            worst[2] = max(worst[2], state.conditioning)
            iterations = max(iterations, state.iterations)
            if sample % 100 == 50:
                position, velocity = errors(planned, known, rates, state)
                worst[0], worst[1] = max(worst[0], position), max(worst[1], velocity)
        rows.append((case, planned.solver.kind.value, *worst, iterations))
    return rows


def singular_rows(kind: GroupKind) -> list[tuple]:
    """Return per decade of the distance to the stretched five-bar: κ, errors, estimate."""
    planned = closure_robots.plan(closure_robots.five_bar(), kind=kind)
    edge = stretched()
    end = float(edge) - 1e-3
    for step in range(301):
        s = step / 300 * end
        planned.solver.solve([s, -s], [1.0, -1.0])
    rows = []
    for decade in range(3, 17):
        with mp.workdps(50):
            s = float(edge - mpf(10) ** -decade)
        try:
            state = planned.solver.solve([s, -s], [1.0, -1.0])
        except SampleRefused as refusal:
            rows.append((decade, None, refusal.reason.value))
            continue
        position, velocity = errors(planned, [s, -s], [1.0, -1.0], state)
        kappa = state.conditioning
        estimate = planned.solver.derivatives.singular_distance([1.0, -1.0])
        rows.append((decade, (kappa, position, velocity, position / (kappa * EPSILON),
                              velocity / (kappa * kappa * EPSILON),
                              estimate / (math.sqrt(2.0) * 10.0 ** -decade)), None))
    return rows


def main() -> None:
    """Print both tables."""
    print('| motion | solved by | positions (rad or m) | velocities (relative) | largest κ '
          '| iterations |')
    print('|---|---|---|---|---|---|')
    for case, kind, position, velocity, kappa, iterations in motion_rows():
        print(f'| {case} | {kind} | {position:.1e} | {velocity:.1e} | {kappa:.3g} '
              f'| ≤ {iterations} |')
    for kind in (GroupKind.FIVE_BAR, GroupKind.NEWTON):
        print()
        print(f'five-bar ({kind.value}), cranks at s and −s, δ below the stretched s')
        print('| δ (rad) | κ | positions | velocities | ÷ κ·ε | ÷ κ²·ε | distance estimate ÷ true '
              '|')
        print('|---|---|---|---|---|---|---|')
        for decade, values, refused in singular_rows(kind):
            if values is None:
                print(f'| 1e-{decade} | — | — | — | — | — | refused: {refused} |')
                continue
            kappa, position, velocity, ratio_p, ratio_v, estimate = values
            print(f'| 1e-{decade} | {kappa:.3g} | {position:.1e} | {velocity:.1e} | '
                  f'{ratio_p:.2g} | {ratio_v:.2g} | {estimate:.4f} |')


if __name__ == '__main__':
    main()
