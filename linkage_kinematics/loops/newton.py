# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
One closure group closed per sample: its known joints in, every other joint of its loops out.

``GroupSolver`` takes any set of known coordinates the structure found determining (the
measured actuators now; output joints in issue 30's direction). Per sample:

1. **Positions.** Newton on the square system A·Δq_U = −r: the rows of J_U chosen at the
   assembled pose as independent (pivoted Gram–Schmidt: a planar loop welded in 3D keeps 3 of
   its 6 rows), plus one row per idle freedom, N_refᵀ·(q_U − q_U,ref) = 0 (exact, linear,
   path-independent: an idle joint cannot drift over any number of samples). It stops when the
   step is at rounding level (‖Δq‖ ≤ 8 ulp of max(‖q‖, 1)) or stops shrinking below ``NOISE``
   (the noise floor of an ill-conditioned pose), then checks the residual of every row at that
   iterate against the rounding of the loop's forward kinematics. Closed forms replace Newton
   where the structure found one (``GroupKind``); a rod reduced to a distance
   (structure.reducible_rods) gets its angles in closed form.
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
3. **Refusals**, each by name with its own reason (``Refusal``), never NaN: no continuation
   converges (no assembly reaches the known values, as beyond a dead point: the state is kept,
   a later sample continues from the last solution); det A changes sign along the motion
   however short the substep (the motion crossed a singular configuration, as a delta's does
   where its arms pass a flat configuration: which assembly the mechanism took there is not
   known, so this and every later sample are refused until ``reset``: going on from the last
   solution to a later sample would be no continuation of the motion, which may have changed
   assembly in between, even without crossing det A = 0 where it turns about a cusp); the
   conditioning κ (1-norm, rows and columns dimensionless) such that the answer would lose
   ``ACCURACY``: positions carry κ·ε of the inputs' rounding, velocities and accelerations κ²·ε
   (their Jacobian is taken at positions off by κ·ε), so samples with κ²·ε > 1e-3 are refused
   (the continuation goes on through them).
4. **Velocities** from the same Jacobian: q̇_U = −A⁻¹·J_K·q̇_K. On request (``Derivatives``, on
   the unreduced equations): the sensitivity ∂q_U/∂q_K, accelerations with the Jacobian's
   rate, q̈_U = −A⁻¹·(J_K·q̈_K + J̇·q̇), and the distance to a singular configuration.

``plan_group`` assembles, analyses and classifies a group and builds its solver (or says in
one line why not): the one call the node and the checker make per group.

``Derivatives.singular_distance`` estimates how far the known joints are from a singular
configuration: at a fold (the generic singular configuration: a dead point) det A vanishes as
the square root of the distance δ, so δ ≈ det A / (2‖∇ det A‖) = 1 / (2‖∇ log|det A|‖), with
∂log|det A|/∂q_K,i = tr(A⁻¹·∂A/∂q_K,i) from J̇ along the motion that q_K,i drives. It is exact
to first order at a fold and half the true distance where det A crosses zero linearly. Pure:
no ROS.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
import enum
import math
import sys

from linkage_kinematics.loops.assembly import assemble, Assembly
from linkage_kinematics.loops.closed_forms import (
    FiveBarPositions,
    LegPositions,
    OutOfReach,
    TurnChain,
)
from linkage_kinematics.loops.equations import Evaluation, LoopEquations, RowKind
from linkage_kinematics.loops.linear import condition, factor, Factors
from linkage_kinematics.loops.reduction import reduce_group, Reduction
from linkage_kinematics.loops.spatial import apply_transposed, cross, dot, subtract
from linkage_kinematics.loops.structure import (
    analyse,
    classify,
    ClosureGroup,
    GroupKind,
    GroupStructure,
    RANK_TOLERANCE,
    reducible_rods,
    scaled_jacobian,
)
from linkage_kinematics.loops.tree import KinematicTree, MotionKind
import numpy as np

EPSILON = sys.float_info.epsilon
ACCURACY = 1e-3
CONDITION_LIMIT = math.sqrt(ACCURACY / EPSILON)
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
# A rewritten closure's joints (reduction.py) must come out of its closed forms at the
# assembled pose within this (rad) of the pose's, else the closures are solved as written.
FOLLOWED = 1e-9
# The residual of a closed loop is the rounding of its forward kinematics: this many ε per
# step of the loop, times the group's size for length rows.
RESIDUAL_ROUNDING = 64.0


class Refusal(enum.Enum):
    """Why a sample is refused."""

    UNREACHABLE = 'no assembly reaches the known joints'
    ASSEMBLY_CHANGE = 'the answer would jump to another assembly'
    SINGULAR = 'too near a singular configuration'


class SampleRefused(ValueError):
    """A sample a group cannot be closed at; ``reason`` says why, the message in full."""

    def __init__(self, group: str, reason: Refusal, detail: str) -> None:
        super().__init__(f'group {group}: {reason.value} ({detail})')
        self.group = group
        self.reason = reason


class PlanError(ValueError):
    """A group that cannot be solved per sample from its assembled pose; the message says why."""


@dataclass
class GroupState:
    """A solved sample: ``solved`` joints' positions and velocities, κ and Newton's iterations."""

    positions: tuple[float, ...]
    velocities: tuple[float, ...]
    conditioning: float
    iterations: int


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


class _System:
    """The square system of one set of equations: its rows, idle rows and scales."""

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


class _Rods:
    """The rods reduced to distances: their angles in closed form, continued from the last."""

    def __init__(self, equations: LoopEquations, unknown: Sequence[int], rods: dict) -> None:
        names = [name for name, _, _ in equations.closure_rows]
        self.equations = equations
        # (closure place, rod, outputs: the rod's coordinates' places in ``unknown``, its
        # universal joint's turns)
        self.rods = [(names.index(name), rod, [list(unknown).index(c)
                                               for c in rod.coordinates],
                      TurnChain(rod.origins, rod.axes))
                     for name, rod in rods.items()]
        self.coordinates = {c for rod in rods.values() for c in rod.coordinates}
        self.branches: list[int] = []
        self.angles: list[list[float]] = []

    def reset(self, evaluation: Evaluation, values: Sequence[float]) -> None:
        """Take each rod's branch and angles at an assembled pose (all the tree's values)."""
        self.branches = [min((1, -1), key=lambda branch: abs(math.remainder(
            chain.pointing(rod.rod, self.target(place, evaluation)[0], branch)[1]
            - values[rod.coordinates[1]], 2.0 * math.pi)))
            for place, rod, _, chain in self.rods]
        self.angles = [[values[c] for c in rod.coordinates] for _, rod, *_ in self.rods]

    def target(self, place: int, evaluation: Evaluation) -> tuple:
        """Return the ball relative to the rod's centre in the socket frame, d, the socket."""
        program, slot = self.equations.socket(place)
        socket = evaluation.frames[program][0][slot]
        ball, center = evaluation.points[place]
        d = (ball[0] - center[0], ball[1] - center[1], ball[2] - center[2])
        return apply_transposed(socket, d), d, socket

    def solve(self, evaluation: Evaluation, rates: Sequence[float],
              refuse: Callable[[Refusal, str], SampleRefused]
              ) -> list[tuple[list[float], tuple[float, float], float]]:
        """Return per rod its angles (continued), their rates and the rates' conditioning."""
        results = []
        for (place, rod, _, chain), branch, last in zip(self.rods, self.branches, self.angles):
            target, d, socket = self.target(place, evaluation)
            try:
                angles = chain.pointing(rod.rod, target, branch)
            except OutOfReach as error:
                raise refuse(Refusal.UNREACHABLE, f'rod of {rod.closure}: {error}') from None
            angles = [angle if abs(angle - previous) <= math.pi else angle - 2.0 * math.pi
                      * round((angle - previous) / (2.0 * math.pi))
                      for angle, previous in zip(angles, last)]
            # the joint's axes in the base frame: the first fixed on the socket, the second
            # turned with the first
            axis1, axis2 = chain.world_axes(socket, [(math.cos(angles[0]),
                                                      math.sin(angles[0]))])
            # ḋ = (Ω_socket + θ̇₁ω₁ + θ̇₂ω₂) × d: the rod turns with its socket too
            velocity, spin = self.equations.relative_motion(place, evaluation, rates)
            d_rate = subtract(velocity, cross(spin, d))
            # ω₁θ̇₁ × d + ω₂θ̇₂ × d = ḋ: three consistent equations, solved by their normal
            # equations; κ of [c₁ c₂] is the square root of its Gram matrix's
            c1, c2 = cross(axis1, d), cross(axis2, d)
            g11, g12, g22 = dot(c1, c1), dot(c1, c2), dot(c2, c2)
            det = g11 * g22 - g12 * g12
            if not det > 0.0:
                raise refuse(Refusal.SINGULAR, f"rod of {rod.closure} along its joint's axis")
            r1, r2 = dot(c1, d_rate), dot(c2, d_rate)
            trace = g11 + g22
            spread = math.sqrt(max(trace * trace - 4.0 * det, 0.0))
            results.append((angles, ((g22 * r1 - g12 * r2) / det, (g11 * r2 - g12 * r1) / det),
                            math.sqrt((trace + spread) / max(trace - spread, 1e-300))))
        return results


class GroupSolver:
    """
    Closes one group per sample from its known joints (module docstring).

    ``known`` and ``solved`` name the coordinates given and returned, in the tree's order;
    ``solve`` takes and returns values in those orders. Built from the group's structure and an
    assembled pose (its known joints at the first sample's values, or the checker's); ``kind``
    is how positions are solved (structure.classify).
    """

    def __init__(self, tree: KinematicTree, group: ClosureGroup, structure: GroupStructure,
                 assembly: Assembly, kind: GroupKind = GroupKind.NEWTON) -> None:
        self.name = group.name
        self.kind = kind
        self.known = structure.known
        self.solved = structure.solved
        values = assembly.values
        # closures rewritten smaller where their end joints allow (reduction.py); a planar
        # loops' group stays as the planar closed forms read it
        reduction = (reduce_group(tree, group, structure, values)
                     if kind is not GroupKind.PLANAR_LOOPS else Reduction(group, structure, ()))
        try:
            self._build(tree, group, reduction, kind, values)
        except PlanError:
            # a rewriting that does not hold at the assembled pose: the closures as written
            self._build(tree, group, Reduction(group, structure, ()), kind, values)
        self.derivatives = Derivatives(tree, group, structure, values)
        self.reset(values)

    def _build(self, tree: KinematicTree, group: ClosureGroup, reduction: Reduction,
               kind: GroupKind, values: Sequence[float]) -> None:
        """Build the per-sample equations, system and closed forms; PlanError if they fail."""
        work = reduction.group
        rods = (reducible_rods(tree, work, reduction.structure)
                if kind in (GroupKind.NEWTON, GroupKind.LEG_INVERSE) else {})
        self.equations = LoopEquations(tree, work.closures, {**rods, **reduction.distances})
        self._rods = _Rods(self.equations, group.unknown, rods)
        self._followers = reduction.followers
        local = [values[i] for i in self.equations.coordinates]
        newton = [i for i in work.unknown if i not in self._rods.coordinates]
        self._system = _System(tree, self.equations, newton, reduction.structure, local)
        self._known_columns = [self.equations.coordinates.index(i) for i in group.known]
        self._known_set = frozenset(self._known_columns)
        self._unknown_set = frozenset(self._system.columns)
        # the rows of the Newton system: the only ones the per-sample Jacobian needs
        self._row_set = frozenset(self._system.rows)
        self._wrapped = self._system.wrapped(tree, self.equations)
        self._known_turns = [tree.coordinates[i].kind is MotionKind.TURN for i in group.known]
        self._outputs = [self.equations.coordinates.index(i) if i in newton else None
                         for i in group.unknown]
        unknown = list(group.unknown)
        self._follower_outputs = [[unknown.index(c) for c in follower.coordinates]
                                  for follower in self._followers]
        self._bounds = residual_bounds(tree, work, self.equations, reduction.structure.size)
        if kind is GroupKind.LEG_INVERSE:
            self._closed_form = LegPositions(tree, work, self.equations,
                                             next(iter(rods.values())))
        elif kind is GroupKind.FIVE_BAR:
            self._closed_form = FiveBarPositions(tree, work, self.equations, values)
        else:
            self._closed_form = None
        evaluation = self.equations.evaluate(local)
        for follower in self._followers:
            if not follower.reset(self.equations, evaluation, values) <= FOLLOWED:
                raise PlanError(f'group {self.name}: closure {follower.closure} rewritten '
                                'does not hold at the assembled pose')

    def reset(self, values: Sequence[float]) -> None:
        """Start again at an assembled pose (``values`` over all the tree's coordinates)."""
        local = [float(values[i]) for i in self.equations.coordinates]
        evaluation = self.equations.evaluate(local)
        jacobian = self.equations.jacobian(evaluation)
        matrix = self._system.matrix(jacobian)
        factors = factor(matrix) if matrix else None
        found = (factors.inverse(), factors.determinant) if factors is not None else (
            None if matrix else ([], 1.0))
        if found is None or found[1] == 0.0:
            raise PlanError(f'group {self.name}: the assembled pose is a singular configuration')
        self._sign = 1.0 if found[1] > 0.0 else -1.0
        self._lost: SampleRefused | None = None
        self._values = local
        self._sensitivity = self._system.sensitivity(found[0], jacobian, self._known_columns)
        # (S at the sample before, the known joints' change since, its square length)
        self._bend: tuple[list[list[float]], list[float], float] | None = None
        self._rods.reset(evaluation, values)
        for follower in self._followers:
            follower.reset(self.equations, evaluation, values)
        if self._closed_form is not None:
            self._closed_form.reset(local)
        self.derivatives.last = None

    @property
    def orientation(self) -> int:
        """Return the sign of det A at the last solution (±1), which names the assembly."""
        return int(self._sign)

    @property
    def lost(self) -> bool:
        """Return whether a sample crossed a singular configuration: all refused until reset."""
        return self._lost is not None

    def solve(self, positions: Sequence[float], velocities: Sequence[float]) -> GroupState:
        """
        Return the ``solved`` joints' positions and velocities for the ``known`` joints'.

        SampleRefused (with its ``Refusal``) leaves the answer (``derivatives``) as it was; the
        continuation follows a sample refused as too near a singular configuration, and is
        lost at a sample that crossed one (module docstring).
        """
        if self._lost is not None:
            raise self._lost
        values = list(self._values)
        changes = []
        for column, value, turn in zip(self._known_columns, positions, self._known_turns):
            if not math.isfinite(value):
                raise self._refuse(Refusal.UNREACHABLE, f'a known joint is {value!r}')
            change = value - values[column]
            changes.append(math.remainder(change, 2.0 * math.pi) if turn else change)
        if self._closed_form is not None:
            for column, value in zip(self._known_columns, positions):
                values[column] = value
            try:
                iterations, evaluation, jacobian = self._closed_form(values)
            except OutOfReach as error:
                raise self._refuse(Refusal.UNREACHABLE, str(error)) from None
            found = self._closed(values, evaluation, jacobian)
        else:
            iterations, values, evaluation, jacobian, found = self._follow(
                values, changes, positions)
        return self._finish(values, evaluation, jacobian, found, velocities, iterations)

    def _refuse(self, reason: Refusal, detail: str) -> SampleRefused:
        return SampleRefused(self.name, reason, detail)

    def _follow(self, start: list[float], changes: Sequence[float],
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
        lost (``_lost``) until ``reset``.
        """
        system, known = self._system, self._known_columns
        scales = system.column_scale
        base, sensitivity = start, self._sensitivity
        done, length, iterations, tries = 0.0, 1.0, 0, 0
        failure: _StepFailed | None = None
        while True:
            tries += 1
            if tries > SUBSTEPS:
                raise self._refuse(Refusal.UNREACHABLE, f'the continuation from the last sample '
                                   f'took more than {SUBSTEPS} substeps')
            if length < SHORTEST:
                assert failure is not None
                if failure.reason is not Refusal.ASSEMBLY_CHANGE:
                    raise self._refuse(failure.reason, failure.detail)
                self._lost = self._refuse(
                    Refusal.ASSEMBLY_CHANGE, 'an earlier sample crossed a singular '
                    'configuration: which assembly the mechanism took is not known until the '
                    'group is assembled again')
                raise self._refuse(Refusal.ASSEMBLY_CHANGE, f'det A changes sign {done:.3g} of '
                                   'the way from the last sample: the motion crosses a singular '
                                   'configuration')
            last = length >= 1.0 - done
            if last:
                length = 1.0 - done
            # the first-order prediction over this substep, no longer than PREDICTION: near a
            # singular configuration S is steep, and a longer prediction would be no prediction
            moves = [length * c for c in changes]
            prediction = [sum([s * m for s, m in zip(row, moves)]) for row in sensitivity]
            if base is start and self._bend is not None:
                # the second-order term, from how S changed over the last sample (module text):
                # (S − S_last)·Δq_K along the last change
                last_sensitivity, before, square = self._bend
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
                    raise self._refuse(Refusal.SINGULAR, 'the continuation needs substeps '
                                       f'shorter than {SHORTEST:.3g} of the change: too steep')
            end = 1.0 if last else done + length
            values = list(base)
            for column, change, value in zip(known, changes, positions):
                values[column] = value if last else start[column] + end * change
            for x, column in zip(prediction, system.columns):
                values[column] += x
            try:
                count, evaluation, jacobian, factors = self._newton(values, base)
                iterations += count
                self._check_residual(evaluation, _StepFailed)
                found = self._closed(values, evaluation, jacobian, factors)
                if found is None:
                    raise _StepFailed(Refusal.SINGULAR, 'the Newton matrix is singular')
                if (found[1] > 0.0) != (self._sign > 0.0):
                    raise _StepFailed(Refusal.ASSEMBLY_CHANGE, 'the sign of det A changed')
            except _StepFailed as failed:
                failure = failed
                length *= 0.5
                continue
            if last:
                return iterations, values, evaluation, jacobian, found
            base, sensitivity, done = values, found[2], end
            length *= 2.0

    def _newton(self, values: list[float],
                base: Sequence[float]) -> tuple[int, Evaluation, list, Factors | None]:
        """
        Move ``values`` to the closed pose by Newton; return its iterations and last iterate.

        The last iterate's evaluation, Jacobian and its Newton matrix's factors (None without
        unknowns).

        _StepFailed where Newton does not contract from ``values`` (module docstring). Turns
        outside the idle freedoms are kept within π of ``base`` (the same pose, and sines of
        small arguments).
        """
        system, equations = self._system, self.equations
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
                raise _StepFailed(Refusal.UNREACHABLE, 'the Newton matrix became singular')
            step = (factors.solve(system.right_side(evaluation.residual, values))
                    if factors is not None else [])
            if not all(map(math.isfinite, step)):
                raise _StepFailed(Refusal.UNREACHABLE, 'the Newton matrix became singular')
            length = max([abs(x) / s for x, s in zip(step, scales)], default=0.0)
            # a correction that does not contract: the start was not near this continuation
            if length > NOISE and (length > CONTRACTION * last_length if iteration > 1
                                   else length > CORRECTION):
                raise _StepFailed(Refusal.UNREACHABLE, f'Newton does not contract (step '
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
                    for column in self._known_columns:
                        row[column] = known_row[column]
                return iteration, evaluation, jacobian, factors
            last_length = length
        raise _StepFailed(Refusal.UNREACHABLE, f'Newton did not converge in {ITERATIONS} '
                          f'steps, residual {max(map(abs, evaluation.residual)):.3g}')

    def _check_residual(self, evaluation: Evaluation, error: Callable) -> None:
        """Raise ``error`` (reason, detail) for a row left open beyond its rounding."""
        for place, (residual, bound) in enumerate(zip(evaluation.residual, self._bounds)):
            if not abs(residual) <= bound:
                name = next(name for name, start, count in self.equations.closure_rows
                            if start <= place < start + count)
                raise error(Refusal.UNREACHABLE,
                            f'closure {name} stays open by {abs(residual):.3g}')

    def _closed(self, values: Sequence[float], evaluation: Evaluation, jacobian: list,
                factors: Factors | None = None) -> tuple[list, float, list] | None:
        """
        Return (A⁻¹, det A, S) at a closed pose; None where A is singular.

        ``factors``: A's, where Newton's last step made them.
        """
        system = self._system
        if not system.columns:
            return [], self._sign, []
        if factors is None:
            factors = factor(system.matrix(jacobian))
            if factors is None:
                return None
        inverse_matrix = factors.inverse()
        return (inverse_matrix, factors.determinant,
                system.sensitivity(inverse_matrix, jacobian, self._known_columns))

    def _finish(self, values: list[float], evaluation: Evaluation, jacobian: list,
                found: tuple[list, float, list] | None, velocities: Sequence[float],
                iterations: int) -> GroupState:
        self._check_residual(evaluation, self._refuse)
        if found is None:
            raise self._refuse(Refusal.SINGULAR, 'the Newton matrix is singular')
        system = self._system
        inverse_matrix, det, sensitivity = found
        conditioning = (system.conditioning(system.matrix(jacobian), inverse_matrix)
                        if inverse_matrix else 1.0)
        known = self._known_columns
        rates = [0.0] * len(values)
        for column, rate in zip(known, velocities):
            rates[column] = rate
        for line, column in zip(sensitivity, system.columns):
            total = 0.0
            for s, v in zip(line, velocities):  # in order: the same bits on every Python
                total += s * v
            rates[column] = total
        rods = self._rods.solve(evaluation, rates, self._refuse)
        try:
            followed = [follower.solve(self.equations, evaluation, rates)
                        for follower in self._followers]
        except OutOfReach as error:
            raise self._refuse(Refusal.UNREACHABLE, str(error)) from None
        # the continuation goes on from here even where the answer is too inaccurate to give
        # (Newton's substeps have kept det A's sign; a closed form keeps its branch)
        if self._closed_form is None:
            self._bend = _bend(values, self._values, known, self._known_turns, self._sensitivity)
        self._values, self._sensitivity = values, sensitivity
        self._rods.angles = [rod[0] for rod in rods]
        for follower, (angles, _, _) in zip(self._followers, followed):
            follower.angles = angles
        conditioning = max([conditioning] + [rod[2] for rod in rods]
                           + [result[2] for result in followed])
        if not conditioning <= CONDITION_LIMIT:
            raise self._refuse(Refusal.SINGULAR, f'conditioning {conditioning:.3g} above '
                               f'{CONDITION_LIMIT:.3g}')
        if (det > 0.0) != (self._sign > 0.0):
            raise self._refuse(Refusal.ASSEMBLY_CHANGE, 'the sign of det A changed')
        positions = [values[c] if c is not None else 0.0 for c in self._outputs]
        speeds = [rates[c] if c is not None else 0.0 for c in self._outputs]
        for (angles, angle_rates, _), (_, _, outputs, _) in zip(rods, self._rods.rods):
            for output, angle, rate in zip(outputs, angles, angle_rates):
                positions[output], speeds[output] = angle, rate
        for (angles, angle_rates, _), outputs in zip(followed, self._follower_outputs):
            for output, angle, rate in zip(outputs, angles, angle_rates):
                positions[output], speeds[output] = angle, rate
        self.derivatives.last = (positions, speeds, [values[c] for c in known])
        return GroupState(tuple(positions), tuple(speeds), conditioning, iterations)


def _bend(values: Sequence[float], last: Sequence[float], known: Sequence[int],
          turns: Sequence[bool], last_sensitivity: list[list[float]]
          ) -> tuple[list[list[float]], list[float], float] | None:
    """
    Return S_last, the known joints' change Δ from ``last`` to ``values`` and |Δ|².

    None where the known joints did not move (GroupSolver._follow's second-order term).
    """
    change = [values[c] - last[c] for c in known]
    square = 0.0
    for place, turn in enumerate(turns):
        if turn:
            change[place] = math.remainder(change[place], 2.0 * math.pi)
        square += change[place] * change[place]
    return (last_sensitivity, change, square) if square > 0.0 else None


class _StepFailed(Exception):
    """A substep of the continuation that is not taken: why, as a refusal would say."""

    def __init__(self, reason: Refusal, detail: str) -> None:
        super().__init__(detail)
        self.reason = reason
        self.detail = detail


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
        self._system = _System(tree, self.full, group.unknown, structure,
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


@dataclass(frozen=True)
class PlannedGroup:
    """
    A group planned at a start: its assembly, structure and solver, or why it is refused.

    ``solver`` is None exactly when ``structure.problem`` says why (under- or over-determined)
    or ``problem`` does (a singular assembled pose).
    """

    assembly: Assembly
    structure: GroupStructure
    kind: GroupKind
    solver: GroupSolver | None
    problem: str | None


def plan_group(tree: KinematicTree, group: ClosureGroup, start: Sequence[float],
               seed: Mapping[str, float] | None = None, hold_known: bool = True) -> PlannedGroup:
    """
    Return a group assembled nearest ``start`` (all the tree's coordinates), analysed, solved.

    ``hold_known``: the known joints stay at the start's values (the node, at its first
    sample); False assembles the whole group freely (the checker, at the zero pose). ``seed``:
    start values of some unknown joints (assembly.assemble). Raises AssemblyError (one line)
    where no closed pose is found.
    """
    assembly = assemble(tree, group, start, None if hold_known else (), seed)
    structure = analyse(tree, group, assembly.values)
    kind = classify(tree, group, structure, assembly.values)
    if kind is GroupKind.NEWTON and structure.problem is None:
        # a closed form may solve the group once its closures are rewritten (reduction.py)
        reduction = reduce_group(tree, group, structure, assembly.values)
        reduced = classify(tree, reduction.group, reduction.structure, assembly.values)
        if reduced in (GroupKind.FIVE_BAR, GroupKind.LEG_INVERSE):
            kind = reduced
    if structure.problem is not None:
        return PlannedGroup(assembly, structure, kind, None, structure.problem)
    try:
        solver = GroupSolver(tree, group, structure, assembly, kind)
    except PlanError as error:
        return PlannedGroup(assembly, structure, kind, None, str(error))
    return PlannedGroup(assembly, structure, kind, solver, None)
