# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A group's derivatives at its solver's last solution, on request: what issue 30 needs.

On the group's unreduced equations (``Derivatives``), from the same square system as Newton's
(square_system.py): the sensitivity ∂q_U/∂q_K = −A⁻¹·[J_K; 0], whose transpose maps efforts
back; the accelerations with the Jacobian's rate, q̈_U = −A⁻¹·(J_K·q̈_K + J̇·q̇); and the
distance to a singular configuration. The velocities, q̇_U = −A⁻¹·J_K·q̇_K, the solver gives
with every sample (newton.GroupSolver).

``Derivatives.singular_distance`` estimates how far the known joints are from a singular
configuration: at a fold (the generic singular configuration: a dead point) det A vanishes as
the square root of the distance δ, so δ ≈ det A / (2‖∇ det A‖) = 1 / (2‖∇ log|det A|‖), with
∂log|det A|/∂q_K,i = tr(A⁻¹·∂A/∂q_K,i) from J̇ along the motion that q_K,i drives. It is exact
to first order at a fold and half the true distance where det A crosses zero linearly.

In numpy: not on the per-sample path at 1 kHz. Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Sequence
import math

from linkage_kinematics.loops.equations import LoopEquations
from linkage_kinematics.loops.refusals import PlanError
from linkage_kinematics.loops.square_system import NewtonSystem
from linkage_kinematics.loops.structure import ClosureGroup, GroupStructure
from linkage_kinematics.loops.tree import KinematicTree
import numpy as np


class Derivatives:
    """
    A group's unreduced equations at its solver's last solution: what issue 30 needs.

    The sensitivity ∂(solved)/∂(known), the accelerations with J̇, and the distance to the
    nearest singular configuration; in numpy (not per sample at 1 kHz). ``last`` is set by
    the solver: (solved positions, solved velocities, known positions).
    """

    def __init__(self, tree: KinematicTree, group: ClosureGroup, structure: GroupStructure,
                 values: Sequence[float]) -> None:
        self.name = group.name
        self.full = LoopEquations(tree, group.closures)
        self._system = NewtonSystem(tree, self.full, group.unknown, structure,
                                    [values[i] for i in self.full.coordinates])
        self._places = [self.full.coordinates.index(i) for i in group.unknown]
        self._known = [self.full.coordinates.index(i) for i in group.known]
        self.last: tuple[list[float], list[float], list[float]] | None = None

    def _state(self, known_velocities: Sequence[float]) -> tuple[list[float], list[float]]:
        """Return the last solution's values and rates over the unreduced equations."""
        if self.last is None:
            raise PlanError(f'group {self.name}: no sample solved yet')
        positions, speeds, known = self.last
        values = [0.0] * len(self.full.coordinates)
        rates = [0.0] * len(self.full.coordinates)
        for place, position, speed in zip(self._places, positions, speeds):
            values[place], rates[place] = position, speed
        for place, position, speed in zip(self._known, known, known_velocities):
            values[place], rates[place] = position, speed
        return values, rates

    def accelerations(self, known_velocities: Sequence[float],
                      known_accelerations: Sequence[float]) -> tuple[float, ...]:
        """
        Return the ``solved`` joints' accelerations at the last solution.

        q̈_U = −A⁻¹·(J_K·q̈_K + J̇·q̇), for the known joints' velocities (as last solved) and
        accelerations.
        """
        values, rates = self._state(known_velocities)
        evaluation = self.full.evaluate(values)
        jacobian = np.array(self.full.jacobian(evaluation))
        bias = np.array(self.full.jacobian_rate(evaluation, rates)) @ np.array(rates)
        system = self._system
        rhs = jacobian[system.rows][:, self._known] @ np.array(known_accelerations, float)
        rhs = np.concatenate([rhs + bias[system.rows], np.zeros(len(system.idle))])
        result = -np.linalg.solve(np.array(system.matrix(jacobian.tolist())), rhs)
        return tuple(float(x) for x in result)

    def sensitivity(self) -> list[list[float]]:
        """
        Return ∂(solved)/∂(known) at the last solution: −A⁻¹·[J_K; 0] over the whole group.

        Rows in ``solved`` order, columns in ``known`` order. Velocities are this times the
        known joints' velocities; efforts map back by its transpose (issue 30: τ_known =
        Sᵀ·τ_solved for the solved actuators).
        """
        values, _ = self._state([0.0] * len(self._known))
        jacobian = np.array(self.full.jacobian(self.full.evaluate(values)))
        system = self._system
        known_block = np.vstack([jacobian[system.rows][:, self._known],
                                 np.zeros((len(system.idle), len(self._known)))])
        sensitivity = -np.linalg.solve(np.array(system.matrix(jacobian.tolist())), known_block)
        return sensitivity.tolist()

    def singular_distance(self, known_velocities: Sequence[float]) -> float:
        """
        Return the estimated distance to the nearest singular configuration.

        From the last solution, in the known joints (rad or m, Euclidean): 1/(2‖∇ log|det A|‖)
        (module docstring).
        """
        values, _ = self._state(known_velocities)
        evaluation = self.full.evaluate(values)
        jacobian = self.full.jacobian(evaluation)
        system = self._system
        matrix = np.array(system.matrix(jacobian))
        inverse_matrix = np.linalg.inv(matrix)
        known_block = np.array(jacobian)[system.rows][:, self._known]
        known_block = np.vstack([known_block, np.zeros((len(system.idle), len(self._known)))])
        sensitivity = -inverse_matrix @ known_block
        gradient = []
        for k in range(len(self._known)):
            rates = [0.0] * len(values)
            rates[self._known[k]] = 1.0
            for place, column in enumerate(system.columns):
                rates[column] = float(sensitivity[place, k])
            rate = np.array(self.full.jacobian_rate(evaluation, rates))
            change = np.vstack([rate[system.rows][:, system.columns],
                                np.zeros((len(system.idle), len(system.columns)))])
            gradient.append(float(np.trace(inverse_matrix @ change)))
        length = math.sqrt(math.fsum(g * g for g in gradient))
        return math.inf if length == 0.0 else 1.0 / (2.0 * length)
