# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A closure group's assembled pose nearest a start, and how far the start was from closing.

Exported models are often far from assembled at their zero pose (the Gepetto models' closures
open by 1 cm to 0.5 m, their welded frames turned by 90–180°), so the assembly is found by a
method that converges from far and then polished to rounding:

1. Levenberg–Marquardt on the closure residual (``equations``: welds by the log map, which has
   no false zero at a half turn), rows and columns made dimensionless by the group's size L,
   Marquardt's diagonal scaling and Nielsen's damping update, first with the distance from the
   start added, ‖r‖² + μ·‖q − q_start‖², μ decreasing to 0 (``ANCHORS``): this follows the
   closed pose nearest the start rather than wherever the damped steps lead.
2. Restarts from the start with the free turns shifted by seeded random angles (the same every
   run): ``COMPARED`` of them always, more until one closes where the first attempt did not
   (a local minimum of the residual); the closed pose nearest the start is taken.
3. Gauss–Newton with minimum-norm steps (the pseudo-inverse at the rank tolerance of
   structure.py) until the step is at rounding level: the pose is then closed to rounding, and
   idle freedoms and redundant rows do not move it.

The held coordinates (``fixed``) stay at the start: the known joints at the first sample's
values for the node; none for the checker, which looks for the nearest closed pose of the whole
group. A ``seed`` (joint name → value) replaces the start of those unknown joints: it picks
another assembly where several are near (continuation.py keeps it per sample). Plan time:
numpy. Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass
import math
import sys

from linkage_kinematics.loops.equations import LoopEquations, RowKind
from linkage_kinematics.loops.structure import (
    ClosureGroup,
    group_size,
    RANK_TOLERANCE,
    scaled_jacobian,
)
from linkage_kinematics.loops.tree import KinematicTree, MotionKind
import numpy as np

EPSILON = sys.float_info.epsilon
# A scaled residual below this ends Levenberg–Marquardt: Gauss–Newton takes it to rounding.
NEAR = 1e-8
# A pose is assembled when every scaled residual row is below this after polishing: rounding of
# a metre-sized loop of ten joints leaves some 1e-15; an exporter's printed digits more.
CLOSED = 1e-10
LM_STEPS = 400
RESTARTS = 24
# restarts made even when the start closed, to compare the assemblies they find with it
COMPARED = 6
POLISH_STEPS = 30
RESTART_SEED = 29
# The weights μ of ‖q − q_start‖² the first attempt closes through (dimensionless, against the
# residual scaled by the group's size), decreasing to 0.
ANCHORS = (1.0, 1e-2, 1e-4, 1e-6, 1e-8, 0.0)


class AssemblyError(ValueError):
    """No assembled pose was found; the message names the group and how far it stays open."""


@dataclass(frozen=True)
class ClosureGap:
    """How far a closure is open: its frames' origins (m) and their angle (rad; None: ball)."""

    closure: str
    position: float
    angle: float | None


@dataclass(frozen=True)
class Assembly:
    """
    A group's assembled pose, how far the start was open, and how it was found.

    ``values`` covers all the tree's coordinates: the start's, the group's free ones assembled.
    """

    group: str
    values: tuple[float, ...]
    start_gaps: tuple[ClosureGap, ...]
    gaps: tuple[ClosureGap, ...]
    # 0: found from the start itself; k: from the k-th restart
    restart: int
    iterations: int


def closure_gaps(equations: LoopEquations, values: Sequence[float]) -> tuple[ClosureGap, ...]:
    """Return each closure's gap at ``values`` (over the equations' coordinates)."""
    return tuple(ClosureGap(name, position, angle) for (name, _, _), (position, angle)
                 in zip(equations.closure_rows, equations.gaps(equations.evaluate(values))))


def assemble(tree: KinematicTree, group: ClosureGroup, start: Sequence[float],
             fixed: Collection[int] | None = None,
             seed: Mapping[str, float] | None = None) -> Assembly:
    """
    Return the group's assembled pose nearest ``start`` (values of all the tree's coordinates).

    ``fixed``: the coordinates held at the start (default: the group's known ones); ``seed``:
    start values for some of the others, by name. AssemblyError naming the group and its gaps
    when no restart closes it, or for a seed naming no free coordinate of the group.
    """
    fixed = set(group.known if fixed is None else fixed)
    equations = LoopEquations(tree, group.closures)
    start_local = [float(start[i]) for i in equations.coordinates]
    free = [column for column, i in enumerate(equations.coordinates) if i not in fixed]
    begin = list(start_local)
    for name, value in (seed or {}).items():
        index = tree.index.get(name)
        if index not in equations.coordinates or index in fixed:
            raise AssemblyError(f'group {group.name}: seed {name!r} is not a joint it solves')
        begin[equations.coordinates.index(index)] = float(value)
    size = group_size(equations, begin)
    turns = [tree.coordinates[equations.coordinates[column]].kind is MotionKind.TURN
             for column in free]
    rng = np.random.default_rng(RESTART_SEED)
    found = []
    iterations = 0
    for attempt in range(RESTARTS + 1):
        trial = list(begin)
        if attempt:
            for column, turn in zip(free, turns):
                trial[column] += rng.uniform(-math.pi, math.pi) if turn else (
                    rng.uniform(-0.5, 0.5) * size)
        values, steps = _close(tree, equations, trial, free, size,
                               ANCHORS if attempt == 0 else (0.0,))
        iterations += steps
        if values is not None:
            found.append((attempt, _near(values, begin, free, turns)))
        # a few restarts always, then only until one closes: another assembly may be nearer
        if found and attempt >= COMPARED:
            break
    if not found:
        gaps = ', '.join(f'{gap.closure} {_gap_text(gap)}' for gap in
                         closure_gaps(equations, begin))
        raise AssemblyError(f'group {group.name}: no assembled pose found from the start '
                            f'(open by {gaps}) in {RESTARTS + 1} tries')

    def distance(candidate: list[float]) -> float:
        return math.fsum(((candidate[c] - begin[c]) / (1.0 if turn else size)) ** 2
                         for c, turn in zip(free, turns))

    restart, values = min(found, key=lambda item: distance(item[1]))
    full = [float(x) for x in start]
    for column, i in enumerate(equations.coordinates):
        full[i] = values[column]
    return Assembly(group.name, tuple(full), closure_gaps(equations, start_local),
                    closure_gaps(equations, values), restart, iterations)


def _gap_text(gap: ClosureGap) -> str:
    angle = '' if gap.angle is None else f' and {gap.angle:.3g} rad'
    return f'{gap.position:.3g} m{angle}'


def _near(values: list[float], begin: Sequence[float], free: Sequence[int],
          turns: Sequence[bool]) -> list[float]:
    """Return ``values`` with each free turn shifted by whole turns to within π of its start."""
    shifted = list(values)
    for column, turn in zip(free, turns):
        if turn:
            shifted[column] -= 2.0 * math.pi * round((values[column] - begin[column])
                                                     / (2.0 * math.pi))
    return shifted


def _scaled(equations: LoopEquations, tree: KinematicTree, values: Sequence[float],
            free: Sequence[int], size: float) -> tuple[np.ndarray, np.ndarray]:
    """Return the scaled residual and the scaled Jacobian's free columns at ``values``."""
    residual = np.array(equations.residual(values))
    scale = np.array([1.0 / size if kind is RowKind.LENGTH else 1.0
                      for kind in equations.row_kinds])
    jacobian = scaled_jacobian(equations, tree, values, size)[:, free]
    return residual * scale, jacobian


def _close(tree: KinematicTree, equations: LoopEquations, values: list[float],
           free: Sequence[int], size: float,
           anchors: Sequence[float]) -> tuple[list[float] | None, int]:
    """
    Return the closed pose reached from ``values``, and how many steps it took.

    Each anchor μ in turn: Levenberg–Marquardt on ‖r(q)‖² + μ·‖q − q_start‖² (dimensionless,
    from where the previous μ ended); μ decreasing to 0 follows the closed pose nearest the
    start. Then Gauss–Newton to rounding.
    """
    column_scale = np.array([size if tree.coordinates[equations.coordinates[c]].kind
                             is MotionKind.SLIDE else 1.0 for c in free])
    start = np.array(values, dtype=float)
    x = start.copy()
    steps = 0
    for anchor in anchors:
        weight = math.sqrt(anchor)

        def system(point: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            residual, jacobian = _scaled(equations, tree, point, free, size)
            if weight == 0.0:
                return residual, jacobian
            offset = (point[free] - start[free]) / column_scale
            return (np.concatenate([residual, weight * offset]),
                    np.vstack([jacobian, weight * np.eye(len(free))]))

        x, more = _levenberg_marquardt(system, x, free, column_scale, closing=anchor == 0.0)
        steps += more
        if x is None:
            return None, steps
    polished, more = _polish(tree, equations, x, free, size, column_scale)
    return polished, steps + more


def _levenberg_marquardt(system, x: np.ndarray, free: Sequence[int], column_scale: np.ndarray,
                         closing: bool) -> tuple[np.ndarray | None, int]:
    """
    Return where Levenberg–Marquardt on ``system`` (residual and Jacobian of x) ends.

    Marquardt's diagonal scaling, Nielsen's damping update; it ends when the step is at
    rounding level or, ``closing``, when every residual row is below ``NEAR``.
    """
    residual, jacobian = system(x)
    rows = residual.size - (0 if closing else len(free))
    cost = 0.5 * float(residual @ residual)
    normal = jacobian.T @ jacobian
    damping = 1e-3 * max(float(np.max(np.diag(normal), initial=0.0)), 1e-12)
    growth = 2.0
    steps = 0
    while steps < LM_STEPS and not (
            closing and np.max(np.abs(residual[:rows]), initial=0.0) <= NEAR):
        steps += 1
        gradient = jacobian.T @ residual
        diagonal = np.maximum(np.diag(normal), 1e-12 * max(float(np.max(np.diag(normal))), 1.0))
        try:
            step = np.linalg.solve(normal + damping * np.diag(diagonal), -gradient)
        except np.linalg.LinAlgError:
            return None, steps
        trial = x.copy()
        trial[free] += step * column_scale
        trial_residual, trial_jacobian = system(trial)
        trial_cost = 0.5 * float(trial_residual @ trial_residual)
        predicted = -float(step @ gradient) - 0.5 * float(step @ normal @ step)
        ratio = (cost - trial_cost) / predicted if predicted > 0.0 else -1.0
        if ratio > 0.0:
            x, residual, jacobian, cost = trial, trial_residual, trial_jacobian, trial_cost
            normal = jacobian.T @ jacobian
            damping *= max(1.0 / 3.0, 1.0 - (2.0 * ratio - 1.0) ** 3)
            growth = 2.0
        else:
            damping *= growth
            growth *= 2.0
        if np.max(np.abs(step)) <= 4.0 * EPSILON * (1.0 + float(np.max(np.abs(x[free])))):
            break
    return x, steps


def _polish(tree: KinematicTree, equations: LoopEquations, x: np.ndarray, free: Sequence[int],
            size: float, column_scale: np.ndarray) -> tuple[list[float] | None, int]:
    """Return ``x`` after Gauss–Newton with minimum-norm steps to rounding, if it closes."""
    last = math.inf
    for steps in range(1, POLISH_STEPS + 1):
        residual, jacobian = _scaled(equations, tree, x, free, size)
        step = -np.linalg.pinv(jacobian, rcond=RANK_TOLERANCE) @ residual
        x = x.copy()
        x[free] += step * column_scale
        length = float(np.max(np.abs(step), initial=0.0))
        if length <= 4.0 * EPSILON * max(1.0, float(np.max(np.abs(x[free]), initial=0.0))):
            break
        if length > 0.5 * last and length < NEAR:  # no longer shrinking: at the noise floor
            break
        last = length
    residual, _ = _scaled(equations, tree, x, free, size)
    if not np.all(np.isfinite(x)) or np.max(np.abs(residual), initial=0.0) > CLOSED:
        return None, steps
    return [float(value) for value in x], steps
