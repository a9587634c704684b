# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A group's positions by Newton, continued from the last solution along the known joints' motion.

1. **Newton** on the square system A·Δq_U = −r (square_system.py). It stops when the step is at
   rounding level (‖Δq‖ ≤ 8 ulp of max(‖q‖, 1)) or stops shrinking below ``NOISE`` (the noise
   floor of an ill-conditioned pose), then checks the residual of every row at that iterate
   against the rounding of the loop's forward kinematics (``square_system.residual_bounds``).
2. **Continuation.** The answer is the continuation of the last solution along the known
   joints' motion. The change since the last sample (a turn's the short way) is followed in
   substeps, the whole change first: each is predicted to first order (q_U += S·Δq_K, S =
   −A⁻¹·J_K at the substep's start, no longer than ``PREDICTION``) and corrected by Newton, and
   taken only if Newton contracts from the prediction (its first correction at most
   ``CORRECTION``, each next one at most ``CONTRACTION`` times the one before, down to
   ``NOISE``), closes the loops and keeps det A's sign; otherwise it is halved (at most
   ``SUBSTEPS`` tries, none shorter than ``SHORTEST`` of the change). Newton contracting from
   a near prediction reaches the solution nearest it, which is the continuation; a prediction
   alone is not enough: near a ball written as three turns at its gimbal lock, where the
   angles move 1.8 rad in a sample and the first-order prediction said 0.5, Newton had gone on
   to the ball's other angle triple. A sample almost always takes one substep. The whole
   change's prediction adds the second-order term ½·H(Δq_K, Δq_K), H = ∂S/∂q_K, from how S
   changed over the last sample's change Δ_last: (S − S_last)·Δq_K ≈ H(Δ_last, Δq_K), taken
   along Δ_last, i.e. times (Δ_last·Δq_K)/|Δ_last|² (exact to second order where the known
   joints move along a line, as one known joint always does; otherwise an estimate of the
   term's size at most). A smooth motion's first correction shrinks from some 1e-5 to 1e-7
   (rad), and Newton often stops an iteration earlier.
3. **Refusals** (refusals.py): no continuation converges (no assembly reaches the known values,
   as beyond a dead point: the state is kept, a later sample continues from the last
   solution); det A changes sign along the motion however short the substep (the motion
   crossed a singular configuration, as a delta's does where its arms pass a flat
   configuration: which assembly the mechanism took there is not known, so this and every
   later sample are refused until ``reset``: going on from the last solution to a later sample
   would be no continuation of the motion, which may have changed assembly in between, even
   without crossing det A = 0 where it turns about a cusp).

Per sample, in plain floats; the group's solver (newton.GroupSolver) owns one. Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
import math
import sys

from linkage_kinematics.loops.equations import Evaluation, LoopEquations
from linkage_kinematics.loops.linear import factor, Factors
from linkage_kinematics.loops.refusals import PlanError, Refusal, SampleRefused
from linkage_kinematics.loops.square_system import NewtonSystem

EPSILON = sys.float_info.epsilon
ITERATIONS = 12
# A step at rounding level: the last step of a converged Newton is the rounding of the
# residual mapped through A⁻¹, some 2–6 ulp of 1 rad for a well-conditioned loop.
STEP_ROUNDING = 8.0
# Below this (rad, or L-scaled m) a Newton step is within the noise of an ill-conditioned pose
# (κ·ε of 1 rad at the refusal's κ is 5e-10): it is not asked to contract further.
NOISE = 1e-6
# Continuation (module docstring): a substep's predicted move is at most PREDICTION, its first
# Newton correction at most CORRECTION, each next correction at most CONTRACTION times the one
# before; at most SUBSTEPS tries per sample, none shorter than SHORTEST of its change.
PREDICTION = 0.25
CORRECTION = 0.25
CONTRACTION = 0.25
SUBSTEPS = 64
SHORTEST = 2.0 ** -12


class Continuation:
    """
    A group's Newton closure continued from sample to sample (module docstring).

    Built per plan from the group's equations (as reduced), their square system and the
    columns of the known joints. ``reset`` starts it at an assembled pose. Its state: ``sign``,
    det A's at the assembly (which names it); ``sensitivity``, S at the last solution;
    ``bend``, S at the solution before with the known joints' change since, for the
    second-order prediction (the function ``bend``'s, which the solver sets once a sample is
    answered); ``lost``, the refusal every sample gets once the motion crossed a singular
    configuration, until ``reset``.
    """

    def __init__(self, name: str, equations: LoopEquations, system: NewtonSystem,
                 known_columns: Sequence[int], wrapped: Sequence[int],
                 bounds: Sequence[float]) -> None:
        self.name = name
        self.equations = equations
        self.system = system
        self.known_columns = known_columns
        self._known_set = frozenset(known_columns)
        self._unknown_set = frozenset(system.columns)
        # the rows of the Newton system: the only ones the per-sample Jacobian needs
        self._row_set = frozenset(system.rows)
        self._wrapped = wrapped
        self._bounds = bounds
        self.sign = 1.0
        self.lost: SampleRefused | None = None
        self.sensitivity: list[list[float]] = []
        # (S at the sample before, the known joints' change since, its square length)
        self.bend: tuple[list[list[float]], list[float], float] | None = None

    def reset(self, evaluation: Evaluation) -> None:
        """Start again at an assembled pose's evaluation; PlanError where it is singular."""
        jacobian = self.equations.jacobian(evaluation)
        matrix = self.system.matrix(jacobian)
        factors = factor(matrix) if matrix else None
        found = (factors.inverse(), factors.determinant) if factors is not None else (
            None if matrix else ([], 1.0))
        if found is None or found[1] == 0.0:
            raise PlanError(f'group {self.name}: the assembled pose is a singular configuration')
        self.sign = 1.0 if found[1] > 0.0 else -1.0
        self.lost = None
        self.sensitivity = self.system.sensitivity(found[0], jacobian, self.known_columns)
        self.bend = None

    def refuse(self, reason: Refusal, detail: str) -> SampleRefused:
        """Return the group's refusal of a sample for ``reason``."""
        return SampleRefused(self.name, reason, detail)

    def follow(self, start: list[float], changes: Sequence[float],
               positions: Sequence[float]) -> tuple:
        """
        Continue the last solution to the known joints' ``positions``; return the closed pose.

        Path-following in substeps of the known joints' change (module docstring): each
        substep is predicted to first order and corrected by Newton, and taken only if Newton
        contracts from the prediction (the pose it reaches is the continuation, not another
        assembly's), closes the loops and keeps det A's sign; else it is halved. Returns
        (iterations, values, evaluation, Jacobian, (A⁻¹, det A, S)) at the known joints'
        ``positions``. SampleRefused where no continuation reaches them; where det A changes
        sign along the motion however short the substep, the motion crossed a singular
        configuration and the assembly the mechanism took is not known: the continuation is
        lost (``lost``) until ``reset``.
        """
        system, known = self.system, self.known_columns
        scales = system.column_scale
        base, sensitivity = start, self.sensitivity
        done, length, iterations, tries = 0.0, 1.0, 0, 0
        failure: StepFailed | None = None
        while True:
            tries += 1
            if tries > SUBSTEPS:
                raise self.refuse(Refusal.UNREACHABLE, f'the continuation from the last sample '
                                  f'took more than {SUBSTEPS} substeps')
            if length < SHORTEST:
                assert failure is not None
                if failure.reason is not Refusal.ASSEMBLY_CHANGE:
                    raise self.refuse(failure.reason, failure.detail)
                self.lost = self.refuse(
                    Refusal.ASSEMBLY_CHANGE, 'an earlier sample crossed a singular '
                    'configuration: which assembly the mechanism took is not known until the '
                    'group is assembled again')
                raise self.refuse(Refusal.ASSEMBLY_CHANGE, f'det A changes sign {done:.3g} of '
                                  'the way from the last sample: the motion crosses a singular '
                                  'configuration')
            last = length >= 1.0 - done
            if last:
                length = 1.0 - done
            # the first-order prediction over this substep, no longer than PREDICTION: near a
            # singular configuration S is steep, and a longer prediction would be no prediction
            moves = [length * c for c in changes]
            prediction = [sum([s * m for s, m in zip(row, moves)]) for row in sensitivity]
            if base is start and self.bend is not None:
                # the second-order term, from how S changed over the last sample (module text):
                # (S − S_last)·Δq_K along the last change
                last_sensitivity, before, square = self.bend
                along = 0.0
                for b, m in zip(before, moves):
                    along += b * m
                along = 0.5 * along / square
                for place, row in enumerate(last_sensitivity):
                    before_move = 0.0
                    for s, m in zip(row, moves):
                        before_move += s * m
                    prediction[place] += along * (prediction[place] - before_move)
            reach = max([abs(x) / s for x, s in zip(prediction, scales)], default=0.0)
            if reach > PREDICTION:
                factor = PREDICTION / reach
                length, last = factor * length, False
                prediction = [factor * x for x in prediction]
                if length < SHORTEST:
                    raise self.refuse(Refusal.SINGULAR, 'the continuation needs substeps '
                                      f'shorter than {SHORTEST:.3g} of the change: too steep')
            end = 1.0 if last else done + length
            values = list(base)
            for column, change, value in zip(known, changes, positions):
                values[column] = value if last else start[column] + end * change
            for x, column in zip(prediction, system.columns):
                values[column] += x
            try:
                count, evaluation, jacobian, factors = self.newton(values, base)
                iterations += count
                self.check_residual(evaluation, StepFailed)
                found = self.closed(values, evaluation, jacobian, factors)
                if found is None:
                    raise StepFailed(Refusal.SINGULAR, 'the Newton matrix is singular')
                if (found[1] > 0.0) != (self.sign > 0.0):
                    raise StepFailed(Refusal.ASSEMBLY_CHANGE, 'the sign of det A changed')
            except StepFailed as failed:
                failure = failed
                length *= 0.5
                continue
            if last:
                return iterations, values, evaluation, jacobian, found
            base, sensitivity, done = values, found[2], end
            length *= 2.0

    def newton(self, values: list[float],
               base: Sequence[float]) -> tuple[int, Evaluation, list, Factors | None]:
        """
        Move ``values`` to the closed pose by Newton; return its iterations and last iterate.

        The last iterate's evaluation, Jacobian and its Newton matrix's factors (None without
        unknowns).

        StepFailed where Newton does not contract from ``values`` (module docstring). Turns
        outside the idle freedoms are kept within π of ``base`` (the same pose, and sines of
        small arguments).
        """
        system, equations = self.system, self.equations
        scales, columns = system.column_scale, system.columns
        last_length = math.inf
        # the known joints' frames are posed once per sample, the unknowns' at each iteration
        evaluation = equations.evaluate(values)
        for iteration in range(1, ITERATIONS + 1):
            if iteration > 1:
                evaluation = equations.evaluate(values, evaluation, self._unknown_set)
            jacobian = equations.jacobian(evaluation, self._unknown_set, self._row_set)
            matrix = system.matrix(jacobian)
            factors = factor(matrix) if matrix else None
            if matrix and factors is None:
                raise StepFailed(Refusal.UNREACHABLE, 'the Newton matrix became singular')
            step = (factors.solve(system.right_side(evaluation.residual, values))
                    if factors is not None else [])
            if not all(map(math.isfinite, step)):
                raise StepFailed(Refusal.UNREACHABLE, 'the Newton matrix became singular')
            length = max([abs(x) / s for x, s in zip(step, scales)], default=0.0)
            # a correction that does not contract: the start was not near this continuation
            if length > NOISE and (length > CONTRACTION * last_length if iteration > 1
                                   else length > CORRECTION):
                raise StepFailed(Refusal.UNREACHABLE, f'Newton does not contract (step '
                                 f'{length:.3g} after {last_length:.3g})')
            size = 1.0
            for column, x, s in zip(columns, step, scales):
                values[column] -= x
                size = max(size, abs(values[column]) / s)
            for column in self._wrapped:
                previous = base[column]
                values[column] = previous + math.remainder(values[column] - previous,
                                                           2.0 * math.pi)
            if length <= STEP_ROUNDING * EPSILON * size or 0.5 * last_length < length:
                known_jacobian = equations.jacobian(evaluation, self._known_set, self._row_set)
                for place in system.rows:
                    row, known_row = jacobian[place], known_jacobian[place]
                    for column in self.known_columns:
                        row[column] = known_row[column]
                return iteration, evaluation, jacobian, factors
            last_length = length
        raise StepFailed(Refusal.UNREACHABLE, f'Newton did not converge in {ITERATIONS} '
                         f'steps, residual {max(map(abs, evaluation.residual)):.3g}')

    def check_residual(self, evaluation: Evaluation, error: Callable) -> None:
        """Raise ``error`` (reason, detail) for a row left open beyond its rounding."""
        for place, (residual, bound) in enumerate(zip(evaluation.residual, self._bounds)):
            if not abs(residual) <= bound:
                name = next(name for name, start, count in self.equations.closure_rows
                            if start <= place < start + count)
                raise error(Refusal.UNREACHABLE,
                            f'closure {name} stays open by {abs(residual):.3g}')

    def closed(self, values: Sequence[float], evaluation: Evaluation, jacobian: list,
               factors: Factors | None = None) -> tuple[list, float, list] | None:
        """
        Return (A⁻¹, det A, S) at a closed pose; None where A is singular.

        ``factors``: A's, where Newton's last step made them.
        """
        system = self.system
        if not system.columns:
            return [], self.sign, []
        if factors is None:
            factors = factor(system.matrix(jacobian))
            if factors is None:
                return None
        inverse_matrix = factors.inverse()
        return (inverse_matrix, factors.determinant,
                system.sensitivity(inverse_matrix, jacobian, self.known_columns))


def bend(values: Sequence[float], last: Sequence[float], known: Sequence[int],
         turns: Sequence[bool], last_sensitivity: list[list[float]]
         ) -> tuple[list[list[float]], list[float], float] | None:
    """
    Return S_last, the known joints' change Δ from ``last`` to ``values`` and |Δ|².

    None where the known joints did not move (``Continuation.bend``, the second-order term).
    """
    change = [values[c] - last[c] for c in known]
    square = 0.0
    for place, turn in enumerate(turns):
        if turn:
            change[place] = math.remainder(change[place], 2.0 * math.pi)
        square += change[place] * change[place]
    return (last_sensitivity, change, square) if square > 0.0 else None


class StepFailed(Exception):
    """A substep of the continuation that is not taken: why, as a refusal would say."""

    def __init__(self, reason: Refusal, detail: str) -> None:
        super().__init__(detail)
        self.reason = reason
        self.detail = detail
