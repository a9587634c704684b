# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A trajectory's points converted for one command group at once (numpy), beside the per-point path.

``command.CommandGroup.solve`` converts one point in plain floats, some tens of µs a group: what
a 1 kHz forward command needs. A ``JointTrajectory`` of a thousand points would take tens of ms
that way; issue 30 asks for it within its first point's ``time_from_start``. ``convert_many``
does the lean path's work for every point at once, from the last accepted point through the
intermediate points to the first (as ``solve`` makes them) and on through the points:

* positions: the ankle's cranks in closed form over all rows at once
  (``TransmissionLegs.positions_many``), a planar chain's joints likewise
  (``PlanarPart.positions_many``: the four-bar's closed form over arrays, its branch continued),
  any other part row by row in order (Newton, continued as on the per-point path);
* every row's transmission at once (``Transmission.linearize_many``): orientations,
  conditionings and M, then velocities ṁ = M·q̇_o and efforts τ_m = M⁻ᵀ·τ_o (one or two
  outputs: ``linear``'s formulas, the same bits from the same M).

**Refusals are the per-point path's.** The batch refuses nothing itself: where any row would
be refused (no assembly, an orientation changed, a conditioning at or near the limit, an
actuator at or near its ``<limit>``, efforts not finite), where two points are farther apart
than ``command.SUBSTEP`` (the per-point path would put intermediate points between them), where
the transmission has no batched twin or a planar loop's branch flips with whole turns, it
returns None with the group's state as it was, and the caller converts the trajectory point by
point: the same refusal, the same point number, the same detail. Accelerations (the rate term
of the full path) are not batched yet: ``RobotCommand`` converts those point by point. Near a
bound means within ``MARGIN`` (relative) of it: the batch's answers differ from the per-point
path's by a few ulps, and a point that one would refuse must never pass the other. Pure: no
ROS.
"""

from __future__ import annotations

from collections.abc import Sequence
import math
from typing import NamedTuple

from linkage_kinematics.loops.command import CommandGroup, CommandState, SUBSTEP
from linkage_kinematics.loops.command_parts import PlanarPart
from linkage_kinematics.loops.refusals import CONDITION_LIMIT, SampleRefused
import numpy as np

# A batched value this close (relative) to a bound goes to the per-point path, which decides.
MARGIN = 1e-9


class GroupArrays(NamedTuple):
    """One group's actuators at N points: positions (N, actuators), velocities, efforts."""

    positions: np.ndarray
    velocities: np.ndarray | None
    efforts: np.ndarray | None


def convert_many(group: CommandGroup, positions: np.ndarray, velocities: np.ndarray | None,
                 efforts: np.ndarray | None) -> GroupArrays | None:
    """
    Return the group's actuators at every point (module docstring), or None: per point then.

    Arrays (N, outputs) in ``group.outputs`` order, finite (the caller checked). On success the
    group's state is the last point's, as after ``solve`` of every point in turn; on None it is
    as before.
    """
    before = group.state()
    try:
        result = _convert(group, positions, velocities, efforts)
    except (SampleRefused, np.linalg.LinAlgError):  # refused, or M singular: decided per point
        result = None
    if result is None:
        group.restore(before)
    return result


def _convert(group: CommandGroup, positions: np.ndarray, velocities: np.ndarray | None,
             efforts: np.ndarray | None) -> GroupArrays | None:
    """``convert_many``'s work; None (or SampleRefused raised) for the per-point path."""
    transmission = group.transmission
    if not transmission.batch.supports:
        return None
    state = group.state()
    # rows: the last accepted point, the intermediate points to the first, then the points
    last = np.array([state.values[column] for column in group.output_columns])
    targets = np.vstack([last, _intermediate(group, last, positions[0]), positions])
    if not _close_enough(group, targets):
        return None
    skip = targets.shape[0] - positions.shape[0]
    values = np.tile(np.array(state.values), (targets.shape[0], 1))
    values[:, group.output_columns] = targets
    local = values[:, group.columns]
    if group.legs is not None:
        if not (group.legs.supports and group.legs.positions_many(local, transmission.batch)):
            return None
        values[:, group.columns] = local
    else:
        if not all(isinstance(part, PlanarPart) and part.positions_many(values)
                   for part, _ in group.parts):
            _positions_in_turn(group, values)
        else:
            _keep_turns(values, group.lean_turns)
        local = values[:, group.columns]
    linearization = transmission.linearize_many(local)
    if linearization is None or not (
            np.all(linearization.measured_orientation == state.orientations[0])
            and np.all(linearization.command_orientation == state.orientations[1])
            and np.all(linearization.measured_conditioning <= CONDITION_LIMIT * (1 - MARGIN))
            and np.all(linearization.command_conditioning <= CONDITION_LIMIT * (1 - MARGIN))):
        return None
    actuators = values[:, group.actuator_columns]
    ratio = linearization.ratio[skip:]
    found = GroupArrays(actuators[skip:],
                        _products(ratio, velocities) if velocities is not None else None,
                        _efforts(ratio, efforts) if efforts is not None else None)
    # every intermediate point's actuators are checked too (a transmission need not be monotonic)
    if not (_within_limits(group, GroupArrays(actuators[1:skip], None, None))
            and _within_limits(group, found)):
        return None
    group.restore(CommandState(tuple(values[-1].tolist()), state.orientations))
    return found


def _intermediate(group: CommandGroup, last: np.ndarray, target: np.ndarray) -> np.ndarray:
    """
    Return the intermediate points from ``last`` to ``target`` (k, outputs), as ``solve`` does.

    On the straight line between them, a continuous output joint the short way.
    """
    changes = [math.remainder(t - v, 2.0 * math.pi) if wraps else t - v
               for (_, wraps), t, v in zip(group.steps, target.tolist(), last.tolist())]
    steps = max(1, math.ceil(max(abs(c) / scale for c, (scale, _)
                                 in zip(changes, group.steps)) / SUBSTEP))
    return np.array([[b + step / steps * c for b, c in zip(last.tolist(), changes)]
                     for step in range(1, steps)]).reshape(-1, len(changes))


def _close_enough(group: CommandGroup, positions: np.ndarray) -> bool:
    """Return whether every row after the first is within ``SUBSTEP`` of the one before."""
    changes = np.diff(positions, axis=0)
    for place, (scale, wraps) in enumerate(group.steps):
        change = changes[:, place]
        if wraps:  # the short way, as the per-point path goes
            change = change - 2.0 * math.pi * np.round(change / (2.0 * math.pi))
        if np.any(np.abs(change) / scale > SUBSTEP * (1 - MARGIN)):
            return False
    return True


def _positions_in_turn(group: CommandGroup, values: np.ndarray) -> None:
    """Solve every row after the first from the one before, by each part's own method."""
    remainder, turn = math.remainder, 2.0 * math.pi
    last = values[0].tolist()
    for row in range(1, values.shape[0]):
        current = last.copy()
        for column, value in zip(group.output_columns, values[row, group.output_columns]):
            current[column] = float(value)
        for part, _ in group.parts:
            part.positions(current)
        for column in group.lean_turns:
            current[column] = last[column] + remainder(current[column] - last[column], turn)
        values[row] = current
        last = current


def _keep_turns(values: np.ndarray, columns: Sequence[int]) -> None:
    """Keep each turn in ``columns`` within π of the row before, as ``CommandGroup`` keeps it."""
    turn = 2.0 * math.pi
    for column in columns:
        angles = values[:, column]
        jumps = np.round((angles[:-1] - angles[1:]) / turn)
        values[1:, column] = angles[1:] + turn * np.cumsum(jumps)


def _products(ratio: np.ndarray, rates: np.ndarray) -> np.ndarray:
    """Return ṁ = M·q̇_o per point, the outputs' terms added in order (two: as fsum)."""
    total = ratio[:, :, 0] * rates[:, None, 0]
    for place in range(1, rates.shape[1]):
        total = total + ratio[:, :, place] * rates[:, None, place]
    return total


def _efforts(ratio: np.ndarray, efforts: np.ndarray) -> np.ndarray:
    """Return τ_m = M⁻ᵀ·τ_o per point (inf or NaN where M is singular: refused then)."""
    with np.errstate(divide='ignore', invalid='ignore'):
        if ratio.shape[1] == 1:
            return efforts / ratio[:, 0, :]
        if ratio.shape[1] == 2:
            # Mᵀ = [[a, b], [c, d]] solved as linear.Factors does a 2×2
            a, b, c, d = ratio[:, 0, 0], ratio[:, 1, 0], ratio[:, 0, 1], ratio[:, 1, 1]
            det = a * d - b * c
            r0, r1 = efforts[:, 0], efforts[:, 1]
            return np.stack([(d * r0 - b * r1) / det, (a * r1 - c * r0) / det], axis=1)
        return np.linalg.solve(np.swapaxes(ratio, 1, 2), efforts[:, :, None])[:, :, 0]


def _within_limits(group: CommandGroup, found: GroupArrays) -> bool:
    """Return whether every actuator is inside its ``<limit>``, clear of it by ``MARGIN``."""
    for place, limits in enumerate(group.limits):
        if limits.position is not None:
            low, high = limits.position
            slack = MARGIN * max(abs(low), abs(high), 1.0)
            column = found.positions[:, place]
            if not np.all((column >= low + slack) & (column <= high - slack)):
                return False
        for array, bound in ((found.velocities, limits.velocity),
                             (found.efforts, limits.effort)):
            if array is not None and bound is not None and not np.all(
                    np.abs(array[:, place]) <= bound * (1 - MARGIN)):
                return False
    if found.efforts is not None and not np.all(np.isfinite(found.efforts)):
        return False
    return True
