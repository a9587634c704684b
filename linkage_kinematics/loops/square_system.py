# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The square system A·Δq_U = −r that Newton solves for a group's unknown joints.

Its rows: the rows of J_U chosen at the assembled pose as independent (``independent_rows``,
pivoted Gram–Schmidt: a planar loop welded in 3D keeps 3 of its 6 rows), plus one row per idle
freedom, N_refᵀ·(q_U − q_U,ref) = 0 (exact, linear, path-independent: an idle joint cannot
drift over any number of samples). Rows and columns are made dimensionless by the group's size
(lengths ÷ size, slides ÷ size) for the conditioning and the step's length. S = −A⁻¹·[J_K; 0]
is the unknowns' sensitivity to the known joints, from which velocities and the continuation's
prediction follow. ``residual_bounds``: the rounding a closed loop's residual may carry, which
says whether Newton's last iterate closes the loops. Plan time, but for ``NewtonSystem``'s
methods, which run per sample in plain floats. Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Sequence
import math
import sys

from linkage_kinematics.loops.equations import LoopEquations, RowKind
from linkage_kinematics.loops.linear import condition
from linkage_kinematics.loops.refusals import PlanError
from linkage_kinematics.loops.structure import (
    ClosureGroup,
    GroupStructure,
    RANK_TOLERANCE,
    scaled_jacobian,
)
from linkage_kinematics.loops.tree import KinematicTree, MotionKind
import numpy as np

EPSILON = sys.float_info.epsilon
# The residual of a closed loop is the rounding of its forward kinematics: this many ε per
# step of the loop, times the group's size for length rows.
RESIDUAL_ROUNDING = 64.0


def independent_rows(matrix: np.ndarray) -> list[int]:
    """Return rows of ``matrix`` spanning its row space, largest first (pivoted Gram–Schmidt)."""
    remaining = matrix.astype(float).copy()
    norms = np.linalg.norm(remaining, axis=1)
    largest = float(np.max(norms, initial=0.0))
    chosen: list[int] = []
    while remaining.shape[0]:
        lengths = np.linalg.norm(remaining, axis=1)
        pick = int(np.argmax(lengths))
        if lengths[pick] <= RANK_TOLERANCE * largest or lengths[pick] == 0.0:
            break
        chosen.append(pick)
        direction = remaining[pick] / lengths[pick]
        remaining = remaining - np.outer(remaining @ direction, direction)
        remaining[pick] = 0.0
    return sorted(chosen)


class NewtonSystem:
    """The square system of one set of equations: its rows, idle rows and scales (module text)."""

    def __init__(self, tree: KinematicTree, equations: LoopEquations, unknown: Sequence[int],
                 structure: GroupStructure, values: Sequence[float]) -> None:
        size = structure.size
        self.columns = [equations.coordinates.index(i) for i in unknown]
        jacobian = scaled_jacobian(equations, tree, values, size)
        self.rows = independent_rows(jacobian[:, self.columns]) if self.columns else []
        self.column_scale = [size if tree.coordinates[i].kind is MotionKind.SLIDE else 1.0
                             for i in unknown]
        self.row_scale = [1.0 / size if equations.row_kinds[row] is RowKind.LENGTH else 1.0
                          for row in self.rows] + [1.0] * len(structure.idle)
        solved = list(structure.solved)
        names = [tree.coordinates[i].name for i in unknown]
        # N_refᵀ·(y − y_ref) in the dimensionless y = q / column scale
        self.idle = [[idle.direction[solved.index(name)] / scale
                      for name, scale in zip(names, self.column_scale)]
                     for idle in structure.idle]
        self.reference = [values[column] for column in self.columns]
        if len(self.rows) + len(self.idle) != len(self.columns):
            raise PlanError(f'group {structure.name}: {len(self.rows)} independent rows and '
                            f'{len(self.idle)} idle freedoms for {len(self.columns)} unknowns')

    def matrix(self, jacobian: Sequence[Sequence[float]]) -> list[list[float]]:
        """Return A: the chosen rows' unknown columns, then the idle rows."""
        columns = self.columns
        return [[jacobian[row][c] for c in columns] for row in self.rows] + self.idle

    def right_side(self, residual: Sequence[float], values: Sequence[float]) -> list[float]:
        """Return the chosen rows' residual, then the idle rows'."""
        rhs = [residual[row] for row in self.rows]
        for coefficients in self.idle:
            rhs.append(math.fsum(k * (values[c] - ref) for k, c, ref in
                                 zip(coefficients, self.columns, self.reference)))
        return rhs

    def sensitivity(self, inverse_matrix: Sequence[Sequence[float]],
                    jacobian: Sequence[Sequence[float]],
                    known: Sequence[int]) -> list[list[float]]:
        """Return S = −A⁻¹·[J_K (chosen rows); 0 (idle rows)], rows in ``columns`` order."""
        blocks = [[jacobian[row][c] for row in self.rows] for c in known]
        return [[-sum([a * b for a, b in zip(line, block)]) for block in blocks]
                for line in inverse_matrix]

    def wrapped(self, tree: KinematicTree, equations: LoopEquations) -> list[int]:
        """Return the unknown turns no idle freedom moves: whole turns of them are one pose."""
        return [column for place, column in enumerate(self.columns)
                if tree.coordinates[equations.coordinates[column]].kind is MotionKind.TURN
                and not any(row[place] for row in self.idle)]

    def conditioning(self, matrix: Sequence[Sequence[float]],
                     inverse_matrix: Sequence[Sequence[float]]) -> float:
        """Return κ₁ of A with rows and columns made dimensionless."""
        return condition(matrix, inverse_matrix, self.row_scale, self.column_scale)


def residual_bounds(tree: KinematicTree, group: ClosureGroup, equations: LoopEquations,
                    size: float) -> list[float]:
    """Return per row the rounding a closed loop's residual may carry (m or rad)."""
    steps = max(len(path) for closure in group.closures for path in tree.loop(closure).paths)
    return [RESIDUAL_ROUNDING * EPSILON * (steps + 1) * (size if row is RowKind.LENGTH else 1.0)
            for row in equations.row_kinds]
