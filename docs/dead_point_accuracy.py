"""Measure the library's error near singular configurations against test/reference.py.

Run from the repository root:  .venv/bin/python docs/dead_point_accuracy.py
Prints the tables of docs/kinematics.md: the paper mechanism approaching its dead point at
α ≈ −1.941° (both dead points, both branches, both drive laws, 16 angles per decade of δ), and
three change-point linkages approaching their change points. Errors are those of
reference.state_errors: angle in rad, the rest normwise relative. The dead-point table measures
the closed form with the SINGULAR_SINE cut-off lifted, to show the whole curve; its last column
says how many of those angles solve() itself refuses with DeadPointError.
"""

from __future__ import annotations

import math
import random
import sys
from pathlib import Path

from mpmath import mpf

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "test"))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from reference import reference_singular_angles, reference_state, state_errors  # noqa: E402

from linkage_kinematics.drive import DriveLaw  # noqa: E402
from linkage_kinematics.geometry import PRESETS, FourBar  # noqa: E402
from linkage_kinematics import kinematics  # noqa: E402
from linkage_kinematics.kinematics import DeadPointError, solve  # noqa: E402

DRIVES = (DriveLaw(2.0), DriveLaw(0.10, 2.3))
KINDS = ("angle", "angular_rate", "angular_acceleration", "velocity", "acceleration")


def worst(samples: list[tuple[float, dict[str, float]]]) -> dict[str, float]:
    return {kind: max(errors[kind] for _, errors in samples) for kind in KINDS}


def dead_point_table(rng: random.Random) -> None:
    paper = PRESETS["paper"].geometry
    low, high = paper.reachability.intervals[0]
    points = reference_singular_angles(paper)
    sides = []
    for end, side in ((low, 1), (high, -1)):
        point = min(points, key=lambda p: abs(math.remainder(float(p) - end, 2 * math.pi)))
        sides.append((point, side))
    print("paper mechanism, approaching its dead points (worst of 16 δ per decade × 2 dead "
          "points × 2 branches × 2 drive laws)")
    print("| δ (rad) | β, γ error (rad) | ω_AB, ω_BC | ω̇_AB, ω̇_BC | V_A, V_B | a_A, a_B | "
          "solve() raises DeadPointError |")
    print("|---|---|---|---|---|---|---|")
    constants = {"angle": 0.0, "rate": 0.0, "acceleration": 0.0}
    for decade in range(3, 16):
        samples = []
        raised = total = 0
        for _ in range(16):
            delta = 10.0 ** -(decade + rng.random())
            for point, side in sides:
                alpha = float(point + side * delta)
                exact_delta = abs(float(mpf(alpha) - point))
                for branch in (1, -1):
                    for drive in DRIVES:
                        total += 1
                        try:
                            solve(paper, alpha, drive, branch)
                        except DeadPointError:
                            raised += 1
                        cut_off = kinematics.SINGULAR_SINE
                        kinematics.SINGULAR_SINE = 0.0
                        try:
                            state = solve(paper, alpha, drive, branch)
                        except DeadPointError:  # S rounded to exactly 0
                            continue
                        finally:
                            kinematics.SINGULAR_SINE = cut_off
                        reference = reference_state(paper, alpha, drive, branch)
                        samples.append((exact_delta, state_errors(state, reference)))
        for exact_delta, errors in samples:
            constants["angle"] = max(constants["angle"], errors["angle"] * math.sqrt(exact_delta))
            constants["rate"] = max(constants["rate"], max(
                errors["angular_rate"], errors["velocity"]) * exact_delta)
            constants["acceleration"] = max(constants["acceleration"], max(
                errors["angular_acceleration"], errors["acceleration"]) * exact_delta)
        cells = (" | ".join(f"{value:.1e}" for value in worst(samples).values())
                 if samples else " | ".join("—" for _ in KINDS))
        print(f"| 1e-{decade + 1}…1e-{decade} | {cells} | {raised}/{total} |")
    print(f"worst angle·√δ = {constants['angle']:.2e} rad^1.5, rate·δ = {constants['rate']:.2e} "
          f"rad, acceleration·δ = {constants['acceleration']:.2e} rad")


def change_point_table(rng: random.Random) -> None:
    linkages = {
        "parallelogram 0.3/1.3/0.3/1.3": FourBar(0.3, 1.3, 0.3, 1.3, 0.0),
        "kite 0.4/0.4/1/1": FourBar(0.4, 0.4, 1.0, 1.0, 0.0),
        "folding kite 1/0.4/0.4/1": FourBar(1.0, 0.4, 0.4, 1.0, 0.0),
    }
    print()
    print("change points (worst over both sides, both branches, 8 offsets per decade), in terms "
          "of S = |sin μ| ≥ SINGULAR_SINE")
    print("| linkage | angle·S | rate·S² | acceleration·S³ | smallest S seen |")
    print("|---|---|---|---|---|")
    for name, linkage in linkages.items():
        angle = rate = acceleration = 0.0
        smallest = 1.0
        for point in linkage.reachability.change_points:
            for decade in range(1, 8):
                for _ in range(8):
                    offset = 10.0 ** -(decade + rng.random())
                    for side in (1, -1):
                        for branch in (1, -1):
                            alpha = point + side * offset
                            try:
                                state = solve(linkage, alpha, DRIVES[0], branch)
                            except DeadPointError:
                                continue
                            sine = math.sin(state.transmission_angle)
                            smallest = min(smallest, sine)
                            errors = state_errors(
                                state, reference_state(linkage, alpha, DRIVES[0], branch))
                            angle = max(angle, errors["angle"] * sine)
                            rate = max(rate, max(errors["angular_rate"], errors["velocity"])
                                       * sine**2)
                            acceleration = max(acceleration, max(
                                errors["angular_acceleration"], errors["acceleration"]) * sine**3)
        print(f"| {name} | {angle:.1e} | {rate:.1e} | {acceleration:.1e} | {smallest:.1e} |")


if __name__ == "__main__":
    generator = random.Random(20261121)
    dead_point_table(generator)
    change_point_table(generator)
