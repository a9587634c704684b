# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A closure group as an exact transmission between its actuators and its output joints.

A group's actuators m are its measured joints; its output joints o are the joints a lab's
controllers see (ankle pitch and roll, a knee, a boom angle; ``loops.output_joints``), as many
as the actuators. At a closed pose q the loops' tangent space is J·q̇ = 0 (J the closure
Jacobian of the group), and both m and o parametrise it; the transmission there is

    M = ∂m/∂o,    ṁ = M·q̇_o,    τ_o = Mᵀ·τ_m,    τ_m = M⁻ᵀ·τ_o.

The efforts follow from virtual work: the serial model's joints o, driven by τ_o, do the work
the actuators do, τ_oᵀ·δo = τ_mᵀ·δm for every motion the loops allow (δm = M·δo), so
τ_o = Mᵀ·τ_m; then τ_mᵀ·ṁ = τ_mᵀ·M·q̇_o = τ_oᵀ·q̇_o, the power balance, holds whatever M's
error, to the rounding of the two products. Every other joint of the loops is passive: the
serial model sees it unactuated, effort 0.

**How M is computed.** J's rows R chosen independent at the assembled pose (``newton``'s
pivoted Gram–Schmidt on the dimensionless J: rank J rows), the unknowns of one direction U
(every joint of the group but the known ones) and that direction's idle freedoms N (their rows
Nᵀ·δq_U = 0, as ``newton`` holds them): the square A = [J_R,U; Nᵀ]. With o known (U' = all but
o), δq_U' = −A'⁻¹·[J_R,o; 0]·δo, so M is the actuators' rows of −A'⁻¹·[J_R,o; 0]. Idle
freedoms move neither m nor o, so M does not depend on how they are held. Rods that both
directions reduce to a distance (``structure.reducible_rods``) are reduced here too: the Jacobian
of the ankle's two legs is then 2×4, A' 2×2. Plain floats on the per-sample path (``linear``).

**Refusals.** M is exact to the rounding of J times κ(A'), the conditioning of the command
direction's system (rows and columns dimensionless, as ``newton``'s): near a configuration
where the outputs cannot move the actuators (a knee's output at its dead point) M and the
efforts grow without bound. ``output_efforts`` raises ``TransmissionSingular`` where κ(A') >
``refusals.CONDITION_LIMIT`` (κ²·ε > 1e-3, the rule the closure refuses samples by).

**The mechanical advantage** (``MechanicalAdvantage``): M itself. One degree of freedom: the
transmission ratio dm/do, which is also τ_o/τ_m (a cylinder's moment arm about the boom joint in
m/rad, a knee motor's ratio in rad/rad), signed. Several: the singular values of M, largest
first: for any actuator efforts σ_min ≤ |τ_o|/|τ_m| ≤ σ_max (and |ṁ|/|q̇_o| likewise), so
σ_min is the output effort per unit actuator effort in the weakest direction; and, to size each
actuator, the effort it must give per unit effort of every output in the worst combination of
signs (the row sums of |M⁻ᵀ|). M = ∂m/∂o rather than its inverse because with one degree of
freedom that is the ratio the efforts scale by (boom torque = cylinder force × ∂length/∂angle).
Singular values compare like with like: with actuators or outputs of mixed units (a slide and a
turn) they depend on the units, and the matrix is the statement.

``assign_outputs`` splits the parameter's names among the groups and ``check_outputs`` checks a
group's (one line each). Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
import math
from typing import NamedTuple

from linkage_kinematics.loops.batch_equations import BatchEquations, BatchEvaluation
from linkage_kinematics.loops.equations import Evaluation, LoopEquations, RowKind
from linkage_kinematics.loops.linear import condition, factor
from linkage_kinematics.loops.refusals import CONDITION_LIMIT
from linkage_kinematics.loops.square_system import independent_rows
from linkage_kinematics.loops.structure import (
    analyse,
    closure_groups,
    ClosureGroup,
    Determinacy,
    GroupStructure,
    reducible_rods,
    scaled_jacobian,
)
from linkage_kinematics.loops.tree import KinematicTree, MotionKind
import numpy as np


class TransmissionError(ValueError):
    """Output joints that cannot be a group's; the message is one line naming the group."""


class TransmissionSingular(ValueError):
    """A pose where the transmission's efforts would lose 1e-3; the message says why."""

    def __init__(self, group: str, conditioning: float) -> None:
        super().__init__(f'group {group}: the output joints are too near a singular '
                         f'configuration of the transmission (conditioning {conditioning:.3g} '
                         f'above {CONDITION_LIMIT:.3g})')
        self.group = group
        self.conditioning = conditioning


@dataclass(frozen=True)
class MechanicalAdvantage:
    """
    The transmission at one pose (module docstring).

    ``ratio`` is M = ∂m/∂o, one row per actuator, one column per output joint (actuator unit
    per output unit: rad/rad, m/rad, …); ``singular_values`` M's, largest first;
    ``actuator_load`` per actuator the effort it gives per unit effort of every output joint,
    signs at their worst (the row sums of |M⁻ᵀ|; inf where M is singular).
    """

    actuators: tuple[str, ...]
    outputs: tuple[str, ...]
    ratio: tuple[tuple[float, ...], ...]
    singular_values: tuple[float, ...]
    actuator_load: tuple[float, ...]

    def describe(self) -> str:
        """Return the advantage in one line (diagnostics)."""
        if len(self.outputs) == 1:
            return (f'd({self.actuators[0]})/d({self.outputs[0]}) = {self.ratio[0][0]:.6g} '
                    f'(= output effort per actuator effort)')
        values = ', '.join(f'{value:.6g}' for value in self.singular_values)
        loads = ', '.join(f'{name} {load:.6g}'
                          for name, load in zip(self.actuators, self.actuator_load))
        return (f'singular values of d(actuators)/d(outputs) {values}; actuator effort per '
                f'unit output effort at worst: {loads}')


def mechanical_advantage(actuators: Sequence[str], outputs: Sequence[str],
                         ratio: Sequence[Sequence[float]]) -> MechanicalAdvantage:
    """Return the ``MechanicalAdvantage`` of the ratio M = ∂m/∂o (not the per-sample path)."""
    matrix = np.array(ratio, dtype=float)
    singular = np.linalg.svd(matrix, compute_uv=False)
    if singular[-1] > 0.0:
        loads = np.sum(np.abs(np.linalg.inv(matrix).T), axis=1)
    else:
        loads = np.full(len(actuators), math.inf)
    return MechanicalAdvantage(tuple(actuators), tuple(outputs),
                               tuple(tuple(float(x) for x in row) for row in ratio),
                               tuple(float(x) for x in singular),
                               tuple(float(x) for x in loads))


def assign_outputs(tree: KinematicTree, groups: Sequence[ClosureGroup],
                   outputs: Sequence[str]) -> tuple[dict[str, tuple[str, ...]], tuple[str, ...]]:
    """
    Return each group's output joints (group name → names, in the order given) and problems.

    A problem (one line each): a name that is no joint of the robot, named twice, or a joint of
    no group. A group none of whose joints is named gets an empty tuple (``check_outputs`` says
    how many it needs).
    """
    assigned: dict[str, list[str]] = {group.name: [] for group in groups}
    problems: list[str] = []
    seen: set[str] = set()
    for name in outputs:
        if name in seen:
            problems.append(f'output joint {name!r} is named twice')
            continue
        seen.add(name)
        index = tree.index.get(name)
        if index is None:
            problems.append(f'output joint {name!r} is not a joint of the robot')
            continue
        owners = [group.name for group in groups if index in group.coordinates]
        if not owners:
            problems.append(f'output joint {name!r} is not a joint of any closure group')
            continue
        for owner in owners:
            assigned[owner].append(name)
    return {name: tuple(names) for name, names in assigned.items()}, tuple(problems)


def check_outputs(tree: KinematicTree, group: ClosureGroup, structure: GroupStructure,
                  values: Sequence[float], outputs: Sequence[str]) -> str | None:
    """
    Return None if ``outputs`` can be the group's output joints, else one line saying why.

    ``group`` and ``structure`` are the measured direction's (its known joints the measured
    actuators), ``values`` the assembled pose (all the tree's coordinates). The outputs must be
    joints of the group, none measured, as many as the freedoms that move it (DOF − idle
    freedoms) and independent at the assembled pose: the group determined with them known.
    """
    return _command_structures(tree, group, structure, values, outputs)[1]


def _command_structures(tree: KinematicTree, group: ClosureGroup, structure: GroupStructure,
                        values: Sequence[float], outputs: Sequence[str]
                        ) -> tuple[list[tuple[ClosureGroup, GroupStructure]], str | None]:
    """Return the groups with the outputs known and their structures, or why not (one line)."""
    head = f'group {group.name}: output joints {list(outputs)}'
    foreign = [name for name in outputs if tree.index.get(name) not in group.coordinates]
    if foreign:
        joints = [tree.coordinates[i].name for i in group.coordinates]
        return [], f'{head}: {foreign} are not joints of the group (its joints: {joints})'
    measured = [name for name in outputs if name in structure.known]
    if measured:
        return [], (f'{head}: {measured} are measured; an output joint is one the actuators '
                    f'{list(structure.known)} move')
    freedoms = structure.dof - len(structure.idle)
    if len(outputs) != freedoms or len(set(outputs)) != len(outputs):
        return [], (f'{head}: {len(set(outputs))} joints for {freedoms} degrees of freedom '
                    f'that move it (as many as its actuators {list(structure.known)})')
    subgroups = closure_groups(tree, group.closures, outputs)
    structures = [(subgroup, analyse(tree, subgroup, values)) for subgroup in subgroups]
    for _, found in structures:
        if found.determinacy is not Determinacy.DETERMINED:
            return [], f'{head} are not independent at the assembled pose: {found.problem}'
    return structures, None


class Linearization:
    """
    The transmission at one pose, both directions' square systems (module docstring).

    ``ratio``: M = ∂m/∂o (actuators × outputs); the orientation (sign of det) and conditioning
    κ₁ of A (actuators known) and A' (outputs known). An orientation that changes between two
    poses of a motion means it crossed a singular configuration of that direction. One is made
    per commanded point, where a relay of positions needs the orientations and conditionings
    alone: M is worked out when first asked for, from the Jacobian and A'⁻¹ kept (a slotted
    class rather than a frozen dataclass for that; ``Transmission.linearize`` makes them).
    """

    __slots__ = ('measured_orientation', 'measured_conditioning', 'command_orientation',
                 'command_conditioning', '_ratio', '_factors')

    def __init__(self, measured_orientation: int, measured_conditioning: float,
                 command_orientation: int, command_conditioning: float,
                 factors: tuple[Transmission, list[list[float]], list[list[float]]]) -> None:
        """``factors``: the transmission, its Jacobian's rows J and A'⁻¹ (empty: singular)."""
        self.measured_orientation = measured_orientation
        self.measured_conditioning = measured_conditioning
        self.command_orientation = command_orientation
        self.command_conditioning = command_conditioning
        self._ratio: tuple[tuple[float, ...], ...] | None = None
        self._factors = factors

    @property
    def ratio(self) -> tuple[tuple[float, ...], ...]:
        """Return M = ∂m/∂o (inf throughout where A' is exactly singular)."""
        if self._ratio is None:
            transmission, jacobian, inverse_matrix = self._factors
            self._ratio = transmission.ratio_from(jacobian, inverse_matrix)
        return self._ratio


class BatchLinearization(NamedTuple):
    """
    ``Linearization`` at many poses (``Transmission.linearize_many``), arrays over the poses.

    Orientations as ±1 (0 where singular); ``ratio`` (N, actuators, outputs), inf where A' is
    exactly singular.
    """

    measured_orientation: np.ndarray
    measured_conditioning: np.ndarray
    command_orientation: np.ndarray
    command_conditioning: np.ndarray
    ratio: np.ndarray


class Transmission:
    """
    One group's transmission between actuators and output joints (module docstring).

    Built at the assembled pose from the measured direction's group and structure; raises
    TransmissionError (one line, ``check_outputs``) for outputs that cannot be the group's.
    ``command_groups`` are the groups (with their structures) that the outputs known make of
    the group's closures: the ankle's two legs, each solved on its own in the command direction.
    """

    def __init__(self, tree: KinematicTree, group: ClosureGroup, structure: GroupStructure,
                 outputs: Sequence[str], values: Sequence[float]) -> None:
        self.name = group.name
        structures, problem = _command_structures(tree, group, structure, values, outputs)
        if problem is not None:
            raise TransmissionError(problem)
        self.command_groups = tuple(structures)
        self.actuators = structure.known
        self.outputs = tuple(outputs)
        self.solved = structure.solved
        rods = reducible_rods(tree, group, structure)
        for subgroup, found in structures:
            kept = reducible_rods(tree, subgroup, found)
            rods = {name: rod for name, rod in rods.items()
                    if name not in {c.name for c in subgroup.closures} or name in kept}
        self.equations = equations = LoopEquations(tree, group.closures, rods)
        # what the equations were made of, for their batched twin (``batch_equations``)
        self.closures, self.rods = group.closures, rods
        columns = equations.coordinates
        names = [tree.coordinates[i].name for i in columns]
        self._actuator_columns = [names.index(name) for name in self.actuators]
        self._output_columns = [names.index(name) for name in self.outputs]
        self.size = size = structure.size
        self._column_scale = [size if tree.coordinates[i].kind is MotionKind.SLIDE else 1.0
                              for i in columns]
        local = [float(values[i]) for i in columns]
        self._rows = independent_rows(scaled_jacobian(equations, tree, local, size))
        # asked of the equations' Jacobian, which then skips the closures' rows left out (a
        # planar pin's two angle rows: the knee's are a third of its linearization)
        self._row_set = frozenset(self._rows)
        row_scale = [1.0 / size if equations.row_kinds[row] is RowKind.LENGTH else 1.0
                     for row in self._rows]
        # U: every column but the actuators; U': every column but the outputs
        measured_unknown = [c for c in range(len(columns)) if c not in self._actuator_columns]
        command_unknown = [c for c in range(len(columns)) if c not in self._output_columns]
        command_idle = [row for subgroup, found in structures
                        for row in _idle_rows(tree, found, names, command_unknown)]
        self._measured = _Square(measured_unknown,
                                 _idle_rows(tree, structure, names, measured_unknown),
                                 row_scale, self._column_scale)
        self._command = _Square(command_unknown, command_idle, row_scale, self._column_scale)
        for square in (self._measured, self._command):
            if len(square.columns) != len(square.row_scale):
                raise TransmissionError(
                    f'group {self.name}: {len(self._rows)} independent rows and '
                    f'{len(square.idle)} idle freedoms for {len(square.columns)} unknowns')
        # the actuators' places among U'
        self._actuator_places = [command_unknown.index(c) for c in self._actuator_columns]
        # where each column's value comes from: (0, place among the actuators) or (1, place
        # among the measured direction's solved joints)
        solved = list(structure.solved)
        self._sources = [(0, list(self.actuators).index(name)) if name in self.actuators
                         else (1, solved.index(name)) for name in names]
        self._output_places = [solved.index(name) for name in self.outputs]
        self.columns = tuple(names)
        self._tree = tree
        self._batch: BatchEquations | None = None  # made when a trajectory first needs it

    def local(self, known: Sequence[float], solved: Sequence[float]) -> list[float]:
        """Return the pose over ``columns`` from the actuators' and the solved joints' values."""
        sources = (known, solved)
        return [sources[source][place] for source, place in self._sources]

    def _jacobian(self, local: Sequence[float],
                  evaluation: Evaluation | None = None) -> list[list[float]]:
        if evaluation is None:
            evaluation = self.equations.evaluate(local)
        jacobian = self.equations.jacobian(evaluation, rows=self._row_set)
        return [jacobian[row] for row in self._rows]

    def _ratio(self, jacobian: Sequence[Sequence[float]],
               inverse_matrix: Sequence[Sequence[float]]) -> tuple[tuple[float, ...], ...]:
        """Return M = ∂m/∂o: the actuators' rows of −A'⁻¹·[J_R,o; 0]."""
        count = len(self._rows)
        outputs = self._output_columns
        ratio = []
        for place in self._actuator_places:
            line = inverse_matrix[place]
            ratio.append(tuple(-math.fsum([line[k] * jacobian[k][o] for k in range(count)])
                               for o in outputs))
        return tuple(ratio)

    def ratio(self, local: Sequence[float]) -> tuple[tuple[float, ...], ...]:
        """Return M = ∂m/∂o at a pose (over ``columns``); TransmissionSingular near one."""
        jacobian = self._jacobian(local)
        inverse_matrix, _, conditioning = self._command.factor(jacobian)
        if not conditioning <= CONDITION_LIMIT:
            raise TransmissionSingular(self.name, conditioning)
        return self._ratio(jacobian, inverse_matrix)

    def output_efforts(self, known: Sequence[float], solved: Sequence[float],
                       efforts: Sequence[float]) -> tuple[float, ...]:
        """
        Return every solved joint's effort for the actuators' ``efforts`` (N·m or N).

        At the pose of the actuators' values ``known`` and the solved joints' ``solved`` (the
        measured direction's answer, in ``structure.solved`` order); in that order: each output
        joint τ_o = Mᵀ·τ_m, every other joint 0. TransmissionSingular near a singular
        configuration of the transmission.
        """
        ratio = self.ratio(self.local(known, solved))
        result = [0.0] * len(self.solved)
        for place, column in zip(self._output_places, zip(*ratio)):
            result[place] = math.fsum([r * t for r, t in zip(column, efforts)])
        return tuple(result)

    def advantage(self, known: Sequence[float], solved: Sequence[float]) -> MechanicalAdvantage:
        """Return the mechanical advantage at a pose (as ``output_efforts`` takes it)."""
        return mechanical_advantage(self.actuators, self.outputs,
                                    self.ratio(self.local(known, solved)))

    def linearize(self, local: Sequence[float],
                  evaluation: Evaluation | None = None) -> Linearization:
        """
        Return both directions' systems at a pose (over ``columns``), singular or not.

        ``evaluation``: ``equations``' at ``local``, where the caller posed them already.
        """
        jacobian = self._jacobian(local, evaluation)
        inverse_matrix, det, conditioning = self._command.factor(jacobian)
        _, measured_det, measured_conditioning = self._measured.factor(jacobian)
        return Linearization(_sign(measured_det), measured_conditioning, _sign(det),
                             conditioning, (self, jacobian, inverse_matrix))

    @property
    def batch(self) -> BatchEquations:
        """Return the equations' batched twin (``batch_equations``), made when first asked."""
        if self._batch is None:
            self._batch = BatchEquations(self._tree, self.closures, self.rods,
                                         self.equations.coordinates)
        return self._batch

    def linearize_many(self, local: np.ndarray,
                       evaluation: BatchEvaluation | None = None) -> BatchLinearization | None:
        """
        Return ``linearize`` at every row of ``local`` (N, columns), or None if not batched.

        ``evaluation``: ``batch``'s at ``local``, where the caller evaluated it already.

        None where the equations have no batched twin (``BatchEquations.supports``: a weld, a
        stretched rod). A one- or two-unknown system (the planar loops, the ankle's legs) is
        solved by the same formulas as ``linear``'s, so M agrees with ``linearize``'s bit for
        bit but for the Jacobian's few ulps.
        """
        batch = self.batch
        if not batch.supports:
            return None
        if evaluation is None:
            evaluation = batch.evaluate(local)
        jacobian = batch.jacobian(evaluation)[:, self._rows, :]
        inverse_matrix, det, conditioning = self._command.factor_many(jacobian)
        _, measured_det, measured_conditioning = self._measured.factor_many(jacobian)
        # M = −(A'⁻¹ rows of the actuators)·J_R,o; two terms at most add as fsum would
        lines = inverse_matrix[:, self._actuator_places, :len(self._rows)]
        ratio = -np.einsum('nak,nko->nao', lines, jacobian[:, :, self._output_columns])
        ratio[det == 0.0] = math.inf
        return BatchLinearization(np.sign(measured_det), measured_conditioning, np.sign(det),
                                  conditioning, ratio)

    def ratio_from(self, jacobian: Sequence[Sequence[float]],
                   inverse_matrix: Sequence[Sequence[float]]) -> tuple[tuple[float, ...], ...]:
        """Return M from ``linearize``'s J and A'⁻¹ (inf throughout without an inverse)."""
        if not inverse_matrix:
            return tuple((math.inf,) * len(self.outputs) for _ in self.actuators)
        return self._ratio(jacobian, inverse_matrix)


class _Square:
    """One direction's square system A = [J_R,U; Nᵀ] and its scales (module docstring)."""

    def __init__(self, columns: list[int], idle: list[list[float]], row_scale: list[float],
                 column_scale: list[float]) -> None:
        self.columns = columns
        self.idle = idle
        self.row_scale = row_scale + [1.0] * len(idle)
        self.column_scale = [column_scale[c] for c in columns]

    def factor(self, jacobian: Sequence[Sequence[float]]
               ) -> tuple[list[list[float]], float, float]:
        """
        Return A⁻¹, det A and κ₁ of A with rows and columns dimensionless.

        κ = inf and no inverse where A is exactly singular. A 1×1 or 2×2 A (a planar loop, the
        ankle's legs) is done inline: ``linear.condition``'s general loops cost more there than
        the rest of the per-sample algebra.
        """
        columns = self.columns
        matrix = [[row[c] for c in columns] for row in jacobian] + self.idle
        factors = factor(matrix)
        if factors is None or factors.determinant == 0.0:
            return [], 0.0, math.inf
        inverse_matrix, det = factors.inverse(), factors.determinant
        rows, scales = self.row_scale, self.column_scale
        if len(columns) == 1:
            return inverse_matrix, det, 1.0
        if len(columns) == 2:
            (a, b), (c, d) = matrix
            (r0, r1), (s0, s1) = rows, scales
            norm = max((abs(a) * r0 + abs(c) * r1) * s0, (abs(b) * r0 + abs(d) * r1) * s1)
            (p, q), (u, v) = inverse_matrix
            norm_inverse = max((abs(p) / s0 + abs(u) / s1) / r0,
                               (abs(q) / s0 + abs(v) / s1) / r1)
            return inverse_matrix, det, norm * norm_inverse
        return inverse_matrix, det, condition(matrix, inverse_matrix, rows, scales)

    def factor_many(self, jacobian: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """
        Return ``factor`` at every pose: A⁻¹ (N, n, n), det A and κ₁ (N,); inf where singular.

        One and two unknowns by ``linear``'s own formulas (the same bits from the same J).
        """
        count, size = jacobian.shape[0], len(self.columns)
        matrix = np.empty((count, size, size))
        matrix[:, :jacobian.shape[1], :] = jacobian[:, :, self.columns]
        if self.idle:
            matrix[:, jacobian.shape[1]:, :] = self.idle
        with np.errstate(divide='ignore', invalid='ignore'):
            if size == 1:
                det = matrix[:, 0, 0]
                inverse_matrix = 1.0 / matrix
                conditioning = np.ones(count)
            elif size == 2:
                a, b, c, d = (matrix[:, 0, 0], matrix[:, 0, 1], matrix[:, 1, 0],
                              matrix[:, 1, 1])
                det = a * d - b * c
                inverse_matrix = np.empty((count, 2, 2))
                p, q, u, v = d / det, -b / det, -c / det, a / det
                inverse_matrix[:, 0, 0], inverse_matrix[:, 0, 1] = p, q
                inverse_matrix[:, 1, 0], inverse_matrix[:, 1, 1] = u, v
                # ``factor``'s own κ₁ of a 2×2, term by term
                (r0, r1), (s0, s1) = self.row_scale, self.column_scale
                a, b, c, d, p, q, u, v = map(np.abs, (a, b, c, d, p, q, u, v))
                conditioning = (np.maximum((a * r0 + c * r1) * s0, (b * r0 + d * r1) * s1)
                                * np.maximum((p / s0 + u / s1) / r0, (q / s0 + v / s1) / r1))
            else:
                det = np.linalg.det(matrix)
                inverse_matrix = np.linalg.inv(np.where((det == 0.0)[:, None, None],
                                                        np.eye(size), matrix))
                rows = np.array(self.row_scale)[:, None]
                scales = np.array(self.column_scale)
                # κ₁ of diag(rows)·A·diag(scales): the largest column sums of it and its inverse
                norm = np.max(np.sum(np.abs(matrix) * rows * scales, axis=1), axis=1)
                norm_inverse = np.max(np.sum(np.abs(inverse_matrix) / scales[:, None] / rows.T,
                                             axis=1), axis=1)
                conditioning = norm * norm_inverse
        conditioning[det == 0.0] = math.inf
        return inverse_matrix, det, conditioning


def _sign(value: float) -> int:
    return 1 if value > 0.0 else -1 if value < 0.0 else 0


def _idle_rows(tree: KinematicTree, structure: GroupStructure, names: Sequence[str],
               unknown: Sequence[int]) -> list[list[float]]:
    """
    Return a structure's idle freedoms as rows over the ``unknown`` columns.

    A direction is over the structure's solved joints in its dimensionless coordinates
    (q / its size for a slide), as ``newton`` holds it: Σ n_i·δq_i / scale_i = 0.
    """
    solved = list(structure.solved)
    rows = []
    for idle in structure.idle:
        row = []
        for column in unknown:
            name = names[column]
            if name in solved:
                scale = (structure.size if tree.coordinates[tree.index[name]].kind
                         is MotionKind.SLIDE else 1.0)
                row.append(idle.direction[solved.index(name)] / scale)
            else:
                row.append(0.0)
        rows.append(row)
    return rows


def actuator_efforts(ratio: Sequence[Sequence[float]],
                     output_efforts: Sequence[float]) -> tuple[float, ...] | None:
    """Return τ_m = M⁻ᵀ·τ_o for M = ``ratio``; None where M is exactly singular."""
    transposed = [list(column) for column in zip(*ratio)]
    factors = factor(transposed)
    return None if factors is None else tuple(factors.solve(list(output_efforts)))
