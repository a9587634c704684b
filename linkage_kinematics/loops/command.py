# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Commands written in a group's output joints, turned into its actuators' (issue 30's direction).

Per point, with the output joints known (``transmission.Transmission.command_groups``: the
ankle's two legs are two groups then, each solved alone):

* **positions** of the actuators and of every passive joint: in closed form where the loop has
  one (a chain of planar one-degree-of-freedom loops from the output joint by the planar
  ``solver.LoopSolver``; one crank–rod–ball leg by its inverse, ``closed_forms``), else by the
  same exact Newton as the measured direction (``newton.GroupSolver`` with the outputs known);
* **velocities** from the same exact Jacobian (the solver's), ṁ = M·q̇_o;
* **accelerations** with the Jacobian's rate term, q̈_U = −A⁻¹·(J_o·q̈_o + J̇·q̇)
  (``newton.Derivatives``);
* **efforts** τ_m = M⁻ᵀ·τ_o (``transmission``).

**Continuation.** The solvers keep the assembly of the last accepted point (the assembled pose
at first). A point farther than ``SUBSTEP`` (rad, or m ÷ the group's size) from the last in any
output joint is reached through intermediate points on the straight line between them, each
solved and checked: the solvers' warm start never jumps to another assembly, and what lies
between two points (a region no assembly reaches, a singular configuration, an actuator's
limit) is seen. A continuous output joint goes the short way.

**Refusals** (``CommandRefused``, its ``CommandRefusal``), a point or command whole, the state
as it was (every group restored to its last accepted point), never NaN:

* ``UNREACHABLE``: no assembly reaches the output joints (or a point between);
* ``SINGULAR``: the conditioning of either direction's system (``transmission.Linearization``)
  above ``newton.CONDITION_LIMIT`` (the answer would lose 1e-3), or its orientation (the sign of
  its determinant) changed since the last accepted point: the motion crossed a singular
  configuration, where the node's measured direction would refuse the samples or jump to
  another assembly;
* ``LIMIT``: an actuator outside its URDF ``<limit>``: the position of a revolute or prismatic
  actuator at the point and at every intermediate point (a transmission need not be monotonic),
  its velocity and effort where the point carries them and the URDF bounds them (a velocity or
  effort limit of 0 bounds nothing: ``model.urdf_reader``). Output and passive joints' limits
  are the planner's and the mechanism's, not checked here;
* ``NOT_FINITE``: NaN or inf among the values.

``RobotCommand`` does this for a robot's groups at once, with names: the URDF's joints outside
the loops pass through unchanged; a name the URDF does not have, a loop joint that is not an
output joint, a group's outputs given in part, unequal array lengths are refused
(``JOINTS``). A trajectory's points are converted in order and refused whole. Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass
import enum
import math

from linkage_kinematics.kinematics.planar_loop import branch_of, driven_loop
from linkage_kinematics.loops.assembly import Assembly
from linkage_kinematics.loops.newton import (
    CONDITION_LIMIT,
    Derivatives,
    GroupSolver,
    PlanError,
    Refusal,
    SampleRefused,
)
from linkage_kinematics.loops.plan import RobotLoops
from linkage_kinematics.loops.planar import Loop
from linkage_kinematics.loops.solver import LoopSampleError, LoopSolver
from linkage_kinematics.loops.structure import classify, ClosureGroup, GroupKind, GroupStructure
from linkage_kinematics.loops.transmission import actuator_efforts, Linearization, Transmission
from linkage_kinematics.loops.tree import KinematicTree, MotionKind
from linkage_kinematics.model.urdf_reader import JointType

# The longest step (rad, or m ÷ the group's size) between two points solved without an
# intermediate point. Newton's warm start is first order: from 0.05 rad its error is some 1e-3
# rad and converges in three or four iterations, far inside the basin of the assembly it is on.
SUBSTEP = 0.05
# A planar chain's closed form must reproduce the assembled pose to this (rad, or m ÷ size).
SAME_POSE = 1e-9


class CommandRefusal(enum.Enum):
    """Why a command is refused."""

    UNREACHABLE = 'no assembly reaches it'
    SINGULAR = 'it crosses or comes too near a singular configuration'
    LIMIT = 'an actuator would leave its URDF <limit>'
    NOT_FINITE = 'a value is not finite'
    JOINTS = 'its joints or arrays do not fit the robot'


class CommandRefused(ValueError):
    """A command refused whole: ``reason`` says why, the message (one line) in full."""

    def __init__(self, reason: CommandRefusal, detail: str) -> None:
        super().__init__(f'{reason.value}: {detail}')
        self.reason = reason
        self.detail = detail


@dataclass(frozen=True)
class JointPoint:
    """
    Values of named joints, as a trajectory point holds them (SI units; rad or m).

    Each array is empty or has one value per joint (``JointTrajectoryPoint``'s convention).
    """

    positions: tuple[float, ...] = ()
    velocities: tuple[float, ...] = ()
    accelerations: tuple[float, ...] = ()
    efforts: tuple[float, ...] = ()


@dataclass(frozen=True)
class GroupCommand:
    """
    One group's converted point.

    ``actuators``: in ``CommandGroup.actuators`` order, its arrays given where the point had
    them; ``passive``: every other joint of the group but the outputs, in
    ``CommandGroup.passive`` order (positions, velocities, and accelerations where asked; their
    efforts are 0). ``linearization``: the transmission there (M, both directions'
    conditioning and orientation).
    """

    actuators: JointPoint
    passive: JointPoint
    linearization: Linearization


class _NewtonGroup:
    """A command group solved by ``GroupSolver`` (closed forms it dispatches to included)."""

    def __init__(self, tree: KinematicTree, group: ClosureGroup, structure: GroupStructure,
                 values: Sequence[float], kind: GroupKind) -> None:
        assembly = Assembly(group.name, tuple(values), (), (), 0, 0)
        self.solver = GroupSolver(tree, group, structure, assembly, kind)
        self.kind = kind

    def solve(self, known: list[float], rates: list[float]) -> tuple[tuple[float, ...],
                                                                     tuple[float, ...]]:
        state = self.solver.solve(known, rates)
        return state.positions, state.velocities

    def accelerations(self, rates: list[float], accelerations: list[float]) -> tuple[float, ...]:
        return self.solver.derivatives.accelerations(rates, accelerations)

    def restore(self, values: Sequence[float]) -> None:
        self.solver.reset(values)


class _PlanarGroup:
    """A command group of planar one-degree-of-freedom loops, closed by ``LoopSolver``."""

    def __init__(self, tree: KinematicTree, group: ClosureGroup, structure: GroupStructure,
                 loops: Sequence[Loop], values: Sequence[float]) -> None:
        self.kind = GroupKind.PLANAR_LOOPS
        self.known = structure.known
        self.solved = structure.solved
        self.index = tree.index
        robot = RobotLoops('', frozenset(name for loop in loops for name in loop.names),
                           tuple(loops), ())
        # the branch at the zero pose whose motion reaches the assembled pose, loop by loop
        branches = {}
        for planned in robot.plan(self.known).loops:
            coordinates = (0.0,) + tuple(joint.sign * float(values[tree.index[joint.name]])
                                         for joint in planned.loop.joints)
            known = planned.known
            here = branch_of(planned.loop.planar, known.index, coordinates)
            branches[planned.loop.constraint] = driven_loop(
                planned.loop.planar, known.index).continued_branch(
                    coordinates[known.index], here, 0.0)
        self.plan = robot.plan(self.known, branches)
        self.derivatives = Derivatives(tree, group, structure, values)
        self.turns = [tree.coordinates[tree.index[name]].kind is MotionKind.TURN
                      for name in self.solved]
        self.restore(values)
        for name, found in zip(self.solved, self.last):
            scale = (structure.size if tree.coordinates[tree.index[name]].kind
                     is MotionKind.SLIDE else 1.0)
            if abs(found - values[tree.index[name]]) > SAME_POSE * scale:
                raise PlanError(f'group {group.name}: the planar closed form does not find '
                                'the assembled pose')

    def solve(self, known: list[float], rates: list[float]) -> tuple[tuple[float, ...],
                                                                     tuple[float, ...]]:
        try:
            positions, velocities = self.solver.solve(dict(zip(self.known, known)),
                                                      dict(zip(self.known, rates)))
        except LoopSampleError as error:
            raise SampleRefused(error.constraint or '', Refusal.UNREACHABLE,
                                str(error)) from None
        self.last = self._near(positions, self.last)
        speeds = tuple(velocities[name] for name in self.solved)
        self.derivatives.last = (list(self.last), list(speeds), list(known))
        return self.last, speeds

    def _near(self, positions: Mapping[str, float],
              last: Sequence[float]) -> tuple[float, ...]:
        """
        Return the solved joints, each turn within π of ``last``.

        The closed form keeps turns within π of its own last answer, and after a restore
        that is the zero pose's.
        """
        return tuple(before + math.remainder(positions[name] - before, 2.0 * math.pi)
                     if turn else positions[name]
                     for name, before, turn in zip(self.solved, last, self.turns))

    def accelerations(self, rates: list[float], accelerations: list[float]) -> tuple[float, ...]:
        return self.derivatives.accelerations(rates, accelerations)

    def restore(self, values: Sequence[float]) -> None:
        """Start a closed form afresh and take it to the known joints' ``values``."""
        self.solver = LoopSolver(self.plan)
        known = {name: float(values[self.index[name]]) for name in self.plan.measured}
        positions, _ = self.solver.solve(known, dict.fromkeys(known, 0.0))
        self.last = self._near(positions, [float(values[self.index[name]])
                                           for name in self.solved])


@dataclass(frozen=True)
class _Limits:
    position: tuple[float, float] | None
    velocity: float | None
    effort: float | None


@dataclass(frozen=True)
class CommandState:
    """
    A command group's last accepted point.

    Every tree coordinate's value (the group's as solved, the others as assembled) and both
    directions' orientations there.
    """

    values: tuple[float, ...]
    orientations: tuple[int, int]


class CommandGroup:
    """
    One group's command direction (module docstring): its output joints in, actuators out.

    Built from the group's ``Transmission``, the assembled pose ``values`` (all the tree's
    coordinates) and, for the planar closed forms, the robot's planar ``Loop``s
    (``plan.find_loops``; those of other groups are ignored). PlanError (one line) where the
    assembled pose is a singular configuration of the command direction.
    """

    def __init__(self, tree: KinematicTree, transmission: Transmission,
                 values: Sequence[float], planar_loops: Sequence[Loop] = ()) -> None:
        self.name = transmission.name
        self.transmission = transmission
        self.actuators = transmission.actuators
        self.outputs = transmission.outputs
        self.passive = tuple(name for name in transmission.solved
                             if name not in self.outputs)
        self.tree = tree
        self._assembled = tuple(float(value) for value in values)
        loops = {loop.constraint: loop for loop in planar_loops}
        joints = {joint.name: joint for joint in tree.joint_above.values()}
        self._parts = []
        for subgroup, structure in transmission.command_groups:
            kind = classify(tree, subgroup, structure, values)
            solver: _NewtonGroup | _PlanarGroup | None = None
            if kind is GroupKind.PLANAR_LOOPS and all(
                    closure.name in loops and all(name in tree.index for name
                                                  in loops[closure.name].names)
                    for closure in subgroup.closures):
                try:
                    solver = _PlanarGroup(tree, subgroup, structure,
                                          [loops[c.name] for c in subgroup.closures], values)
                except ValueError:  # no closed form plan or branch from this pose: Newton
                    solver = None
            if solver is None:
                solver = _NewtonGroup(tree, subgroup, structure, values,
                                      GroupKind.NEWTON if kind is GroupKind.PLANAR_LOOPS
                                      else kind)
            self._parts.append((solver, [self.outputs.index(name) for name in structure.known],
                               structure.solved))
        size = transmission.size
        self._steps = []
        for name in self.outputs:
            coordinate = tree.coordinates[tree.index[name]]
            joint = joints.get(coordinate.joint)
            wraps = coordinate.kind is MotionKind.TURN and (
                joint is None or joint.joint_type is not JointType.REVOLUTE
                or coordinate.name != coordinate.joint)
            self._steps.append((size if coordinate.kind is MotionKind.SLIDE else 1.0, wraps))
        self._limits = []
        for name in self.actuators:
            joint = joints.get(name)
            self._limits.append(_Limits(None, None, None) if joint is None else _Limits(
                joint.position_limits, joint.velocity_limit, joint.effort_limit))
        self._columns = [tree.index[name] for name in transmission.columns]
        self._group_columns = {name: tree.index[name] for name in
                               (*self.actuators, *self.outputs, *self.passive)}
        linearization = transmission.linearize([values[i] for i in self._columns])
        if linearization.command_orientation == 0 or linearization.measured_orientation == 0:
            raise PlanError(f'group {self.name}: the assembled pose is a singular '
                            'configuration of the transmission')
        self._initial = CommandState(self._assembled, (
            linearization.measured_orientation, linearization.command_orientation))
        self._state = self._initial

    @property
    def kinds(self) -> tuple[GroupKind, ...]:
        """Return how each group the outputs make is solved (``transmission.command_groups``)."""
        return tuple(solver.kind for solver, _, _ in self._parts)

    def reset(self) -> None:
        """Start again from the assembled pose."""
        self.restore(self._initial)

    def position(self, name: str) -> float:
        """Return a joint of the group's position at the last accepted point (rad or m)."""
        return self._state.values[self._group_columns[name]]

    def state(self) -> CommandState:
        """Return the last accepted point's state, for ``restore``."""
        return self._state

    def restore(self, state: CommandState) -> None:
        """Put every solver back at a state ``state`` returned."""
        for solver, _, _ in self._parts:
            solver.restore(state.values)
        self._state = state

    def solve(self, positions: Sequence[float], velocities: Sequence[float] = (),
              accelerations: Sequence[float] = (), efforts: Sequence[float] = ()
              ) -> GroupCommand:
        """
        Return the actuators (and passive joints) for the output joints' values.

        Each array in ``outputs`` order; velocities, accelerations and efforts may be empty
        (accelerations need velocities). CommandRefused whole, the state as it was.
        """
        for what, array in (('position', positions), ('velocity', velocities),
                            ('acceleration', accelerations), ('effort', efforts)):
            for name, value in zip(self.outputs, array):
                if not math.isfinite(value):
                    raise CommandRefused(CommandRefusal.NOT_FINITE,
                                         f'output joint {name!r}: {what} {value!r}')
        before = self._state
        last = [before.values[self._group_columns[name]] for name in self.outputs]
        changes = []
        for (_, wraps), target, value in zip(self._steps, positions, last):
            change = target - value
            changes.append(math.remainder(change, 2.0 * math.pi) if wraps else change)
        steps = max(1, math.ceil(max(abs(c) / scale for c, (scale, _)
                                     in zip(changes, self._steps)) / SUBSTEP))
        try:
            for step in range(1, steps):
                fraction = step / steps
                self._step([b + fraction * c for b, c in zip(last, changes)], (), (), ())
            return self._step(positions, velocities, accelerations, efforts)
        except CommandRefused:
            self.restore(before)
            raise

    def _step(self, positions: Sequence[float], velocities: Sequence[float],
              accelerations: Sequence[float], efforts: Sequence[float]) -> GroupCommand:
        """Solve one point from the last; on success it becomes the last accepted one."""
        values = list(self._state.values)
        rates: dict[str, float] = {}
        passive_accelerations: dict[str, float] = {}
        for name, value in zip(self.outputs, positions):
            values[self._group_columns[name]] = value
        given = velocities or (0.0,) * len(self.outputs)
        for name, rate in zip(self.outputs, given):
            rates[name] = rate
        for solver, places, solved in self._parts:
            known = [positions[p] for p in places]
            known_rates = [given[p] for p in places]
            try:
                found, speeds = solver.solve(known, known_rates)
            except SampleRefused as refusal:
                reason = (CommandRefusal.UNREACHABLE if refusal.reason is Refusal.UNREACHABLE
                          else CommandRefusal.SINGULAR)
                # the refusal names the command group it came from (the ankle's one leg)
                detail = (str(refusal) if refusal.group == self.name
                          else f'group {self.name}, {refusal}')
                raise CommandRefused(reason, detail) from None
            for name, value, speed in zip(solved, found, speeds):
                values[self._group_columns[name]] = value
                rates[name] = speed
            if accelerations:
                for name, value in zip(solved, solver.accelerations(
                        known_rates, [accelerations[p] for p in places])):
                    passive_accelerations[name] = value
        linearization = self.transmission.linearize([values[i] for i in self._columns])
        orientations = (linearization.measured_orientation, linearization.command_orientation)
        for direction, conditioning, orientation, before in (
                ('measured', linearization.measured_conditioning, orientations[0],
                 self._state.orientations[0]),
                ('command', linearization.command_conditioning, orientations[1],
                 self._state.orientations[1])):
            if orientation != before:
                raise CommandRefused(CommandRefusal.SINGULAR, f'group {self.name}: the '
                                     f'{direction} direction crossed a singular configuration '
                                     '(its orientation changed)')
            if not conditioning <= CONDITION_LIMIT:
                raise CommandRefused(CommandRefusal.SINGULAR, f'group {self.name}: the '
                                     f"{direction} direction's conditioning {conditioning:.3g} "
                                     f'is above {CONDITION_LIMIT:.3g}')
        actuator_positions = tuple(values[self._group_columns[name]] for name in self.actuators)
        actuator_velocities = (tuple(rates[name] for name in self.actuators)
                               if velocities else ())
        actuator_accelerations = (tuple(passive_accelerations[name] for name in self.actuators)
                                  if accelerations else ())
        actuator_forces: tuple[float, ...] = ()
        if efforts:
            found_efforts = actuator_efforts(linearization.ratio, efforts)
            if found_efforts is None:
                raise CommandRefused(CommandRefusal.SINGULAR,
                                     f'group {self.name}: the transmission is singular')
            actuator_forces = found_efforts
        self._check_limits(actuator_positions, actuator_velocities, actuator_forces)
        for array in (actuator_velocities, actuator_accelerations, actuator_forces):
            if not all(map(math.isfinite, array)):
                raise CommandRefused(CommandRefusal.SINGULAR,
                                     f'group {self.name}: an actuator value is not finite')
        passive = JointPoint(
            tuple(values[self._group_columns[name]] for name in self.passive),
            tuple(rates[name] for name in self.passive) if velocities else (),
            tuple(passive_accelerations[name] for name in self.passive) if accelerations
            else ())
        self._state = CommandState(tuple(values), orientations)
        return GroupCommand(JointPoint(actuator_positions, actuator_velocities,
                                       actuator_accelerations, actuator_forces),
                            passive, linearization)

    def _check_limits(self, positions: Sequence[float], velocities: Sequence[float],
                      efforts: Sequence[float]) -> None:
        for place, (name, limits) in enumerate(zip(self.actuators, self._limits)):
            position = positions[place]
            if limits.position is not None and not (
                    limits.position[0] <= position <= limits.position[1]):
                raise CommandRefused(CommandRefusal.LIMIT, (
                    f'group {self.name}: actuator {name!r} at {position:.9g} outside '
                    f'[{limits.position[0]:.9g}, {limits.position[1]:.9g}]'))
            for what, array, bound in (('velocity', velocities, limits.velocity),
                                       ('effort', efforts, limits.effort)):
                if array and bound is not None and not abs(array[place]) <= bound:
                    raise CommandRefused(CommandRefusal.LIMIT, (
                        f'group {self.name}: actuator {name!r} {what} {array[place]:.9g} '
                        f'beyond ±{bound:.9g}'))


class RobotCommand:
    """
    A robot's command direction with names (module docstring).

    ``groups``: every group's ``CommandGroup``; ``joints``: every joint name of the URDF. The
    output names of a point are the joints passed through (in the order given), then the
    actuators of every group whose outputs it names (groups in order).
    """

    def __init__(self, groups: Sequence[CommandGroup], joints: Collection[str]) -> None:
        self.groups = tuple(groups)
        self.joints = frozenset(joints)
        self._owner: dict[str, tuple[int, int]] = {}
        self._loop_joints: dict[str, str] = {}
        for number, group in enumerate(self.groups):
            for place, name in enumerate(group.outputs):
                self._owner[name] = (number, place)
            for name in (*group.actuators, *group.passive):
                self._loop_joints[name] = group.name

    def reset(self) -> None:
        """Start every group again from its assembled pose."""
        for group in self.groups:
            group.reset()

    def names(self, names: Sequence[str]) -> tuple[str, ...]:
        """Return the joint names a point given for ``names`` is converted to."""
        commanded, passing = self._split(names)
        return tuple(passing) + tuple(name for number in commanded
                                      for name in self.groups[number].actuators)

    def _split(self, names: Sequence[str]) -> tuple[list[int], list[str]]:
        """Return the groups commanded (in order) and the joints passed through; or refuse."""
        problems = []
        twice = sorted({name for name in names if names.count(name) > 1})
        if twice:
            problems.append(f'joints named twice: {twice}')
        passing = []
        given: dict[int, int] = {}
        for name in dict.fromkeys(names):  # each name once, in order
            if name in self._owner:
                number = self._owner[name][0]
                given[number] = given.get(number, 0) + 1
            elif name in self._loop_joints:
                problems.append(f'joint {name!r} is solved by group {self._loop_joints[name]}: '
                                'command its output joints')
            elif name not in self.joints:
                problems.append(f'joint {name!r} is not a joint of the robot')
            else:
                passing.append(name)
        for number, count in given.items():
            group = self.groups[number]
            if count != len(group.outputs):
                missing = [name for name in group.outputs if name not in names]
                problems.append(f'group {group.name} needs all its output joints '
                                f'{list(group.outputs)}; {missing} missing')
        if problems:
            raise CommandRefused(CommandRefusal.JOINTS, '; '.join(problems))
        return sorted(given), passing

    def _check(self, names: Sequence[str], point: JointPoint, commanded: bool) -> None:
        for what, array in (('positions', point.positions), ('velocities', point.velocities),
                            ('accelerations', point.accelerations), ('effort', point.efforts)):
            if array and len(array) != len(names):
                raise CommandRefused(CommandRefusal.JOINTS, f'{len(array)} {what} for '
                                     f'{len(names)} joints')
            for name, value in zip(names, array):
                if not math.isfinite(value):
                    raise CommandRefused(CommandRefusal.NOT_FINITE,
                                         f'joint {name!r}: {what} {value!r}')
        if commanded and not point.positions:
            raise CommandRefused(CommandRefusal.JOINTS, "the loops' output joints need "
                                 'positions')
        if point.accelerations and not point.velocities:
            raise CommandRefused(CommandRefusal.JOINTS, 'accelerations without velocities')

    def convert(self, names: Sequence[str], point: JointPoint) -> JointPoint:
        """
        Return the point for ``self.names(names)``: passed-through joints, then actuators.

        CommandRefused whole (every group's state as it was).
        """
        return self.trajectory(names, (point,))[0]

    def trajectory(self, names: Sequence[str],
                   points: Sequence[JointPoint]) -> tuple[JointPoint, ...]:
        """
        Return every point converted, in order, for ``self.names(names)``.

        CommandRefused whole, naming the first point refused (0-based); the groups' states are
        then as before the trajectory.
        """
        commanded, passing = self._split(names)
        for number, point in enumerate(points):
            try:
                self._check(names, point, bool(commanded))
            except CommandRefused as refusal:
                raise _at_point(refusal, number) from None
        places = {name: place for place, name in enumerate(names)}
        states = [group.state() for group in self.groups]
        converted = []
        try:
            for number, point in enumerate(points):
                try:
                    converted.append(self._point(commanded, passing, places, point))
                except CommandRefused as refusal:
                    raise _at_point(refusal, number) from None
        except CommandRefused:
            for group, state in zip(self.groups, states):
                group.restore(state)
            raise
        return tuple(converted)

    def _point(self, commanded: Sequence[int], passing: Sequence[str],
               places: Mapping[str, int], point: JointPoint) -> JointPoint:
        arrays = (point.positions, point.velocities, point.accelerations, point.efforts)
        out = [[array[places[name]] for name in passing] if array else [] for array in arrays]
        for number in commanded:
            group = self.groups[number]
            given = [[array[places[name]] for name in group.outputs] if array else []
                     for array in arrays]
            found = group.solve(*given).actuators
            for target, array in zip(out, (found.positions, found.velocities,
                                           found.accelerations, found.efforts)):
                target += array
        return JointPoint(*(tuple(array) if given_array else ()
                            for array, given_array in zip(out, arrays)))


def _at_point(refusal: CommandRefused, number: int) -> CommandRefused:
    """Return the refusal with the point's number before its detail."""
    return CommandRefused(refusal.reason, f'point {number}: {refusal.detail}')
