# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The command direction's errors against the 50-digit references: docs/kinematics.md's table.

Run ``.venv/bin/python test/transmission_accuracy.py`` (about a minute). For each robot of
test/transmission_robots.py, test/test_command.py's 400-point motion of the output joints,
every 40th point checked against test/closure_reference.py or test/loop_reference.py
(positions, velocities, accelerations against central differences of the reference's
velocities, efforts against M⁻ᵀ·τ_o with the reference's M, the power balance), and every
point's round trip through the measured direction's own solver.
"""

from __future__ import annotations

import math
from pathlib import Path
import sys

sys.path.insert(0, str(Path(__file__).resolve().parent))

from mpmath import mp, mpf  # noqa: E402
import test_command  # noqa: E402
import transmission_robots  # noqa: E402
from transmission_robots import (  # noqa: E402
    reference_pose,
    reference_ratio,
    reference_velocities,
    relative,
)


def round_trip(robot, returned, point, actuators, names, worst: dict) -> None:
    """Feed the commanded actuators to the measured direction; note how far the outputs are."""
    for place, command in enumerate(robot.commands):
        state = returned.planned[place].solver.solve(
            [actuators.positions[names.index(a)] for a in command.actuators],
            [actuators.velocities[names.index(a)] for a in command.actuators])
        solved = returned.planned[place].structure.solved
        for output in command.outputs:
            k = robot.outputs.index(output)
            worst['round trip'] = max(worst['round trip'], abs(
                state.positions[solved.index(output)] - point.positions[k]))
            worst['round trip rates'] = max(worst['round trip rates'], abs(
                state.velocities[solved.index(output)] - point.velocities[k])
                / max(1.0, abs(point.velocities[k])))


def check(robot, sample: int, point, worst: dict) -> None:
    """Note one point's errors against the reference."""
    efforts_given = test_command.EFFORTS[robot.name]
    outputs = {n: point.positions[k] for k, n in enumerate(robot.outputs)}
    rates = {n: point.velocities[k] for k, n in enumerate(robot.outputs)}
    ours, solved, efforts = {}, {}, []
    for command in robot.commands:
        places = [robot.outputs.index(n) for n in command.outputs]
        found = command.solve([point.positions[k] for k in places],
                              [point.velocities[k] for k in places],
                              [point.accelerations[k] for k in places],
                              [efforts_given[k] for k in places])
        for joints, side in ((command.actuators, found.actuators),
                             (command.passive, found.passive)):
            solved.update(zip(joints, side.positions))
            ours.update(zip(joints, zip(side.velocities, side.accelerations)))
        given = [efforts_given[k] for k in places]
        actuator_power = math.fsum(t * v for t, v in zip(found.actuators.efforts,
                                                         found.actuators.velocities))
        output_power = math.fsum(t * rates[n] for t, n in zip(given, command.outputs))
        scale = math.fsum(abs(t * rates[n]) for t, n in zip(given, command.outputs))
        worst['power balance'] = max(worst['power balance'],
                                     abs(actuator_power - output_power) / scale)
        worst['largest κ'] = max(worst['largest κ'], found.linearization.measured_conditioning,
                                 found.linearization.command_conditioning)
        efforts.append((found.actuators.efforts, given))
    exact = reference_pose(robot, outputs, solved)
    joints = robot.loop_joints()
    worst['positions'] = max(worst['positions'],
                             max(abs(solved[n] - float(exact[n])) for n in joints))
    velocities = reference_velocities(robot, {**outputs, **exact}, rates)
    worst['velocities'] = max(worst['velocities'], relative(
        [ours[n][0] for n in joints], [velocities[n] for n in joints]))
    with mp.workdps(50):
        sides = []
        for offset in (test_command.STEP, -test_command.STEP):
            moved = test_command.exact_motion(robot.name, sample, offset)
            positions = {n: value for n, (value, _) in moved.items()}
            pose = reference_pose(robot, positions, solved)
            sides.append(reference_velocities(robot, {**positions, **pose},
                                              {n: rate for n, (_, rate) in moved.items()}))
        accelerations = [(sides[0][n] - sides[1][n]) / (2 * test_command.STEP) for n in joints]
        worst['accelerations'] = max(worst['accelerations'], relative(
            [ours[n][1] for n in joints], accelerations))
        for place, (mine, given) in enumerate(efforts):
            ratio = reference_ratio(robot, place, {**outputs, **exact})
            expected = mp.lu_solve(ratio.T, mp.matrix([mpf(e) for e in given]))
            worst['efforts'] = max(worst['efforts'], relative(mine, list(expected)))


def main() -> None:
    """Print each robot's worst errors."""
    for name in test_command.MOTIONS:
        robot = transmission_robots.build(name)
        returned = transmission_robots.build(name)
        names = robot.robot.names(robot.outputs)
        worst = dict.fromkeys(('positions', 'velocities', 'accelerations', 'efforts',
                               'power balance', 'round trip', 'round trip rates',
                               'largest κ'), 0.0)
        for sample in range(401):
            point = test_command.commanded(robot, sample)
            actuators = robot.robot.convert(robot.outputs, point)
            round_trip(robot, returned, point, actuators, names, worst)
            if sample % 40 == 20:
                check(robot, sample, point, worst)
        print(name, ', '.join(f'{key} {value:.2g}' for key, value in worst.items()))


if __name__ == '__main__':
    main()
