# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
One command group (a group the output joints known make) solved by the method it has.

``command_part`` picks, from the structure as ``structure.classify`` recognises it:

* ``PlanarPart``: planar one-degree-of-freedom loops from the output joint, in closed form by
  the planar ``solver.LoopSolver`` (the measured direction's own solver, bit for bit), its
  branch at the zero pose the one whose motion reaches the assembled pose;
* ``LegPart``: one crank–rod–ball leg's inverse (``closed_forms.LegPositions``); where only the
  actuators are asked, the crank alone from the closed form, without the rod's angles and the
  solver's rates (a quarter of the cost: the forward-command relay's case);
  ``TransmissionLegs`` does that for a group of legs alone on its transmission's equations;
* ``NewtonPart``: ``newton.GroupSolver`` (Newton, or the five-bar's closed form it dispatches
  to).

Each part: ``positions`` (the lean path: at least the joints the transmission's equations
need, written into a whole-tree value list; ``lean_columns`` are those it writes),
``solve`` (every solved joint's position and velocity), ``accelerations``
(``derivatives.Derivatives``, after ``solve``), ``restore`` (back to a pose). Each raises
``refusals.SampleRefused``. Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Sequence
import math

from linkage_kinematics.kinematics.planar_loop import branch_of, driven_loop
from linkage_kinematics.loops.assembly import Assembly
from linkage_kinematics.loops.batch_equations import BatchEquations
from linkage_kinematics.loops.closed_forms import crank_to_sphere_many, LegPositions, OutOfReach
from linkage_kinematics.loops.derivatives import Derivatives
from linkage_kinematics.loops.equations import Evaluation, LoopEquations
from linkage_kinematics.loops.newton import GroupSolver
from linkage_kinematics.loops.plan import RobotLoops
from linkage_kinematics.loops.planar import Loop
from linkage_kinematics.loops.refusals import PlanError, Refusal, SampleRefused
from linkage_kinematics.loops.solver import LoopSampleError, LoopSolver
from linkage_kinematics.loops.structure import (
    classify,
    ClosureGroup,
    GroupKind,
    GroupStructure,
    reducible_rods,
)
from linkage_kinematics.loops.tree import KinematicTree, MotionKind
import numpy as np

# A planar chain's closed form must reproduce the assembled pose to this (rad, or m ÷ size).
SAME_POSE = 1e-9


class NewtonPart:
    """A command group solved by ``GroupSolver``."""

    def __init__(self, tree: KinematicTree, group: ClosureGroup, structure: GroupStructure,
                 values: Sequence[float], kind: GroupKind) -> None:
        assembly = Assembly(group.name, tuple(values), (), (), 0, 0)
        self.solver = GroupSolver(tree, group, structure, assembly, kind)
        self.kind = kind
        self.columns = [tree.index[name] for name in structure.solved]
        self.lean_columns = self.columns
        self.known = [tree.index[name] for name in structure.known]

    def positions(self, values: list[float]) -> None:
        """Write the solved joints for the known ones in ``values`` (whole tree) into it."""
        known = [values[c] for c in self.known]
        state = self.solver.solve(known, [0.0] * len(known))
        for column, value in zip(self.columns, state.positions):
            values[column] = value

    def solve(self, values: list[float],
              rates: Sequence[float]) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """Return the solved joints' positions and velocities (``rates``: the known ones')."""
        state = self.solver.solve([values[c] for c in self.known], rates)
        return state.positions, state.velocities

    def accelerations(self, rates: Sequence[float],
                      accelerations: Sequence[float]) -> tuple[float, ...]:
        """Return the solved joints' accelerations at the last ``solve``."""
        return self.solver.derivatives.accelerations(rates, accelerations)

    def restore(self, values: Sequence[float]) -> None:
        """Start again at a pose (whole tree)."""
        self.solver.reset(values)


class LegPart(NewtonPart):
    """A crank–rod–ball leg: the crank alone in closed form where only actuators are asked."""

    def __init__(self, tree: KinematicTree, group: ClosureGroup, structure: GroupStructure,
                 values: Sequence[float]) -> None:
        super().__init__(tree, group, structure, values, GroupKind.LEG_INVERSE)
        rods = reducible_rods(tree, group, structure)
        self.tree, self.group, self.rod = tree, group, next(iter(rods.values()))
        self.equations = LoopEquations(tree, group.closures, rods)
        self.closed_form = LegPositions(tree, group, self.equations, self.rod)
        self.closed_form.reset([values[i] for i in self.equations.coordinates])
        self.crank = self.equations.coordinates[self.closed_form.column]
        self.lean_columns = [self.crank]
        # the solver's pose is not the last one after a lean step: put it there before solving
        self.behind = False

    def positions(self, values: list[float]) -> None:
        """Write the crank for the known joints in ``values`` (whole tree) into it."""
        local = [values[i] for i in self.equations.coordinates]
        try:
            self.closed_form.move(local, self.closed_form.branch)
        except OutOfReach as error:
            raise SampleRefused(self.solver.name, Refusal.UNREACHABLE, str(error)) from None
        values[self.crank] = local[self.closed_form.column]
        self.behind = True

    def solve(self, values: list[float],
              rates: Sequence[float]) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """Return the solved joints' positions and velocities (``rates``: the known ones')."""
        if self.behind:
            self.solver.reset(values)
            self.behind = False
        return super().solve(values, rates)


class PlanarPart:
    """A command group of planar one-degree-of-freedom loops, closed by ``LoopSolver``."""

    def __init__(self, tree: KinematicTree, group: ClosureGroup, structure: GroupStructure,
                 loops: Sequence[Loop], values: Sequence[float]) -> None:
        self.kind = GroupKind.PLANAR_LOOPS
        self.names = structure.solved
        self.known_names = structure.known
        self.columns = [tree.index[name] for name in structure.solved]
        self.lean_columns = self.columns
        self.known = [tree.index[name] for name in structure.known]
        robot = RobotLoops('', frozenset(name for loop in loops for name in loop.names),
                           tuple(loops), (), closures=group.closures, tree=tree)
        # the branch at the zero pose whose motion reaches the assembled pose, loop by loop
        branches = {}
        for planned in robot.plan(self.known_names).loops:
            coordinates = (0.0,) + tuple(joint.sign * float(values[tree.index[joint.name]])
                                         for joint in planned.loop.joints)
            known = planned.known
            here = branch_of(planned.loop.planar, known.index, coordinates)
            branches[planned.loop.constraint] = driven_loop(
                planned.loop.planar, known.index).continued_branch(
                    coordinates[known.index], here, 0.0)
        self.plan = robot.plan(self.known_names, branches)
        self.derivatives = Derivatives(tree, group, structure, values)
        self.restore(values)
        found = list(values)
        self.positions(found)
        for name, column in zip(self.names, self.columns):
            scale = (structure.size if tree.coordinates[column].kind is MotionKind.SLIDE
                     else 1.0)
            # a whole turn apart is the same pose
            if abs(_turned(found[column], values[column], tree, column)
                   - values[column]) > SAME_POSE * scale:
                raise PlanError(f'group {group.name}: the planar closed form does not find '
                                f'the assembled pose ({name})')

    def _closed(self, values: Sequence[float], rates: Sequence[float]) -> tuple[dict, dict]:
        known = [values[c] for c in self.known]
        try:
            return self.solver.solve(dict(zip(self.known_names, known)),
                                     dict(zip(self.known_names, rates)))
        except LoopSampleError as error:
            raise SampleRefused(error.constraint or '', Refusal.UNREACHABLE,
                                str(error)) from None

    def positions(self, values: list[float]) -> None:
        """Write the solved joints for the known ones in ``values`` (whole tree) into it."""
        positions, _ = self._closed(values, [0.0] * len(self.known))
        for name, column in zip(self.names, self.columns):
            values[column] = positions[name]

    def solve(self, values: list[float],
              rates: Sequence[float]) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """Return the solved joints' positions and velocities (``rates``: the known ones')."""
        positions, velocities = self._closed(values, rates)
        found = tuple(positions[name] for name in self.names)
        speeds = tuple(velocities[name] for name in self.names)
        self.derivatives.last = (list(found), list(speeds), [values[c] for c in self.known])
        return found, speeds

    def accelerations(self, rates: Sequence[float],
                      accelerations: Sequence[float]) -> tuple[float, ...]:
        """Return the solved joints' accelerations at the last ``solve``."""
        return self.derivatives.accelerations(rates, accelerations)

    def positions_many(self, values: np.ndarray) -> bool:
        """
        Write the solved joints into every row of ``values`` (N × the whole tree), batched.

        The first row the last accepted point, where the closed form is. False where the rows
        must be solved one by one (``LoopSolver.positions_many``).
        """
        found = self.solver.positions_many([values[:, c] for c in self.known])
        if found is None:
            return False
        by_name = dict(zip(self.plan.passive, found))
        for name, column in zip(self.names, self.columns):
            values[:, column] = by_name[name]
        return True

    def restore(self, values: Sequence[float]) -> None:
        """Start the closed form afresh and take it to the known joints' ``values``."""
        self.solver = LoopSolver(self.plan)
        self._closed(values, [0.0] * len(self.known))


class TransmissionLegs:
    """
    A group of crank–rod–ball legs alone (the ankle), its cranks on its transmission's equations.

    On the lean path the transmission's equations are posed once at the commanded outputs; each
    leg's closed form reads its ball and centre there, and only the cranks' frames are posed
    again, for the linearization: rather than each leg's own equations and the transmission's
    again (a third of the ankle's cost per point). The legs are separate command groups, so one
    leg's crank moves nothing another's closed form reads. ``of`` returns None for any other
    group.
    """

    def __init__(self, legs: Sequence[LegPart], equations: LoopEquations,
                 columns: Sequence[int]) -> None:
        self.equations = equations
        self.columns = columns  # the equations' coordinates (tree columns)
        closures = [name for name, _, _ in equations.closure_rows]
        self.legs: list[tuple[LegPart, LegPositions]] = []
        for leg in legs:
            # the leg's closed form on these equations, which number its closure otherwise
            found = LegPositions(leg.tree, leg.group, equations, leg.rod,
                                 closures.index(leg.group.closures[0].name))
            found.branch = leg.closed_form.branch
            self.legs.append((leg, found))
        self.cranks = frozenset(found.column for _, found in self.legs)

    @staticmethod
    def of(parts: Sequence[NewtonPart | PlanarPart],
           equations: LoopEquations, columns: Sequence[int]) -> TransmissionLegs | None:
        """Return the legs of a group whose ``parts`` are legs alone, every rod reduced."""
        closures = [name for name, _, _ in equations.closure_rows]
        if len(equations.row_kinds) != len(closures) or not all(
                isinstance(part, LegPart) and part.group.closures[0].name in closures
                for part in parts):
            return None
        return TransmissionLegs(parts, equations, columns)

    def positions(self, values: list[float], before: Sequence[float]) -> Evaluation:
        """
        Write every crank for the outputs in ``values`` (whole tree) into it.

        Each turning crank within π of its last value (``before``), as the group keeps every
        turn; return the equations posed there, for ``Transmission.linearize``.
        """
        columns = self.columns
        local = [values[c] for c in columns]
        evaluation = self.equations.evaluate(local)
        for leg, found in self.legs:
            try:
                found.move_at(local, evaluation, found.branch)
            except OutOfReach as error:
                raise SampleRefused(leg.solver.name, Refusal.UNREACHABLE, str(error)) from None
            leg.behind = True
            place = found.column
            if found.turn:  # a turning crank within π of its last value; a sliding one as is
                last = before[columns[place]]
                local[place] = last + math.remainder(local[place] - last, 2.0 * math.pi)
            values[columns[place]] = local[place]
        return self.equations.evaluate(local, evaluation, self.cranks)

    def positions_many(self, local: np.ndarray, batch: BatchEquations) -> bool:
        """
        Write every crank into each row of ``local`` (N × the equations' columns), batched.

        Each row's cranks start at the same pose, the last accepted point's (``positions``
        solves each leg from where its crank is; the closed form gives the same crank from any
        start); each turning crank is then kept within π of the row before's, from the first
        row's start, as ``positions`` keeps it. False where some row is out of reach (the
        per-point path names it). A sliding crank is not batched here: ``supports`` says so.
        """
        evaluation = batch.evaluate(local)
        remainder, turn = math.remainder, 2.0 * math.pi
        for _, found in self.legs:
            axis, origin = batch.step_axis(found.step, evaluation)
            change = crank_to_sphere_many(origin, axis, batch.point(found.closure, 1, evaluation),
                                          batch.point(found.closure, 0, evaluation),
                                          found.length, found.branch)
            if np.isnan(change).any():
                return False
            place = found.column
            cranks = (local[:, place] + change / found.multiplier).tolist()
            last = float(local[0, place])
            for row, value in enumerate(cranks):
                last = cranks[row] = last + remainder(value - last, turn)
            local[:, place] = cranks
        return True

    @property
    def supports(self) -> bool:
        """Return whether ``positions_many`` can batch these legs: every crank turns."""
        return all(found.turn for _, found in self.legs)


def _turned(value: float, near: float, tree: KinematicTree, column: int) -> float:
    """Return a turn's ``value`` moved by whole turns to within π of ``near``."""
    if tree.coordinates[column].kind is not MotionKind.TURN:
        return value
    return near + math.remainder(value - near, 2.0 * math.pi)


def command_part(tree: KinematicTree, group: ClosureGroup, structure: GroupStructure,
                 values: Sequence[float], loops: Sequence[Loop]
                 ) -> NewtonPart | PlanarPart:
    """
    Return the part that solves a command group (module docstring).

    ``loops``: the robot's planar loops (``plan.find_loops``); a planar group whose loops are
    not among them (written other than by ``<constraint>``), or whose closed form cannot be
    planned from this pose, goes to Newton. PlanError where the assembled pose is a singular
    configuration of the group.
    """
    kind = classify(tree, group, structure, values)
    by_name = {loop.constraint: loop for loop in loops}
    if kind is GroupKind.PLANAR_LOOPS:
        if all(closure.name in by_name and all(name in tree.index
                                               for name in by_name[closure.name].names)
               for closure in group.closures):
            try:
                return PlanarPart(tree, group, structure,
                                  [by_name[closure.name] for closure in group.closures], values)
            except ValueError:  # no closed-form plan or branch from this pose
                pass
        return NewtonPart(tree, group, structure, values, GroupKind.NEWTON)
    if kind is GroupKind.LEG_INVERSE:
        return LegPart(tree, group, structure, values)
    return NewtonPart(tree, group, structure, values, kind)
