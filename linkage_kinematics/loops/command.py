# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Commands written in a group's output joints, turned into its actuators' (issue 30's direction).

Per point, with the output joints known (``transmission.Transmission.command_groups``: the
ankle's two legs are two groups then, each solved alone by ``command_parts``):

* **positions** of the actuators and of every passive joint: in closed form where the loop has
  one (a chain of planar one-degree-of-freedom loops from the output joint by the planar
  ``solver.LoopSolver``; one crank–rod–ball leg by its inverse), else by the same exact Newton
  as the measured direction (``newton.GroupSolver`` with the outputs known);
* **velocities** ṁ = M·q̇_o and **efforts** τ_m = M⁻ᵀ·τ_o, M = ∂m/∂o from the group's exact
  Jacobian at the solution (``transmission.Transmission.linearize``, which the refusals below
  need anyway): the power balance τ_mᵀ·ṁ = τ_oᵀ·q̇_o holds to rounding with one M;
* **accelerations** with the Jacobian's rate term, q̈_U = −A⁻¹·(J_o·q̈_o + J̇·q̇)
  (``derivatives.Derivatives``), and the passive joints' velocities from the solvers, where asked
  (``passive=True`` or accelerations given: the full path). Otherwise only what the
  transmission's equations need is solved (the lean path: a leg's crank without its rod's
  angles), which is what a relay to the actuators sends.

**Continuation.** The solvers keep the assembly of the last accepted point (the assembled pose
at first). A point farther than ``SUBSTEP`` (rad, or m ÷ the group's size) from the last in any
output joint is reached through intermediate points on the straight line between them, each
solved and checked: the solvers' warm start never jumps to another assembly, and what lies
between two points (a region no assembly reaches, a singular configuration, an actuator's
limit) is seen. A continuous output joint goes the short way; every solved turn is kept within
π of its last accepted value.

**Refusals** (``CommandRefused``, its ``CommandRefusal``), a point or command whole, the state
as it was (every group restored to its last accepted point), never NaN:

* ``UNREACHABLE``: no assembly reaches the output joints (or a point between);
* ``SINGULAR``: the conditioning of either direction's system (``transmission.Linearization``)
  above ``refusals.CONDITION_LIMIT`` (the answer would lose 1e-3), or its orientation (the sign of
  its determinant) changed since the last accepted point: the motion crossed a singular
  configuration, where the node's measured direction would refuse the samples or jump to
  another assembly (a change point of a planar loop too: the general transmission is singular
  there, though its closed form passes);
* ``LIMIT``: an actuator outside its URDF ``<limit>``: the position of a revolute or prismatic
  actuator at the point and at every intermediate point (a transmission need not be monotonic),
  its velocity and effort where the point carries them and the URDF bounds them (a velocity or
  effort limit of 0 bounds nothing: ``model.urdf_reader``). Output and passive joints' limits
  are the planner's and the mechanism's, not checked here;
* ``NOT_FINITE``: NaN or inf among the values.

``robot_command.RobotCommand`` does this for a robot's groups at once, with names. Pure: no
ROS.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
import enum
import math
import operator
from typing import NamedTuple

from linkage_kinematics.loops.command_parts import command_part, TransmissionLegs
from linkage_kinematics.loops.equations import Evaluation
from linkage_kinematics.loops.planar import Loop
from linkage_kinematics.loops.refusals import CONDITION_LIMIT, PlanError, Refusal, SampleRefused
from linkage_kinematics.loops.structure import GroupKind
from linkage_kinematics.loops.transmission import actuator_efforts, Linearization, Transmission
from linkage_kinematics.loops.tree import KinematicTree, MotionKind
from linkage_kinematics.model.urdf_reader import JointType

# The longest step (rad, or m ÷ the group's size) between two points solved without an
# intermediate point. Newton's warm start is first order: from 0.05 rad its error is some 1e-3
# rad and converges in three or four iterations, far inside the basin of the assembly it is on.
SUBSTEP = 0.05


class CommandRefusal(enum.Enum):
    """Why a command is refused."""

    UNREACHABLE = 'no assembly reaches it'
    SINGULAR = 'it crosses or comes too near a singular configuration'
    LIMIT = 'an actuator would leave its URDF <limit>'
    NOT_FINITE = 'a value is not finite'
    JOINTS = 'its joints or arrays do not fit the robot'


class CommandRefused(ValueError):
    """A command refused whole: ``reason`` says why, ``detail`` what; the message in full."""

    def __init__(self, reason: CommandRefusal, detail: str) -> None:
        super().__init__(f'{reason.value}: {detail}')
        self.reason = reason
        self.detail = detail


class JointPoint(NamedTuple):
    """
    Values of named joints, as a trajectory point holds them (SI units; rad or m).

    Each array is empty or has one value per joint (``JointTrajectoryPoint``'s convention).
    The per-point values (this, ``GroupCommand``, ``CommandState``) are named tuples: made at
    every point of a 1 kHz relay, where a frozen dataclass's ``__init__`` costs twice as much.
    """

    positions: tuple[float, ...] = ()
    velocities: tuple[float, ...] = ()
    accelerations: tuple[float, ...] = ()
    efforts: tuple[float, ...] = ()


class GroupCommand(NamedTuple):
    """
    One group's converted point.

    ``actuators``: in ``CommandGroup.actuators`` order, each array where the point had it;
    ``passive``: on the full path, every other joint of the group but the outputs, in
    ``CommandGroup.passive`` order (positions, velocities, and accelerations where asked; their
    efforts are 0), else empty. ``linearization``: the transmission there (M, both directions'
    conditioning and orientation).
    """

    actuators: JointPoint
    passive: JointPoint
    linearization: Linearization


class CommandState(NamedTuple):
    """
    A command group's last accepted point.

    Every tree coordinate's value (the group's as last solved, the others as assembled) and
    both directions' orientations there.
    """

    values: tuple[float, ...]
    orientations: tuple[int, int]


class Limits(NamedTuple):
    """An actuator's URDF <limit>: position range, velocity and effort bounds (None: none)."""

    position: tuple[float, float] | None
    velocity: float | None
    effort: float | None


# the passive joints of the lean path: none
_NONE = JointPoint()


def getter(indices: Sequence[int]) -> Callable[[Sequence[float]], tuple[float, ...]]:
    """Return a function of a list that gives a tuple of its items at ``indices``, in order."""
    if len(indices) > 1:
        return operator.itemgetter(*indices)
    if indices:
        index = indices[0]
        return lambda values: (values[index],)
    return lambda values: ()


class CommandGroup:
    """
    One group's command direction (module docstring): its output joints in, actuators out.

    Built from the group's ``Transmission``, the assembled pose ``values`` (all the tree's
    coordinates) and, for the planar closed forms, the robot's planar ``Loop``s
    (``plan.find_loops``; those of other groups are ignored). PlanError (one line) where the
    assembled pose is a singular configuration of either direction.

    What ``command_batch`` converts a trajectory with, prepared once: ``parts`` (each command
    group's part and its outputs' places), ``legs`` (the ankle's ``TransmissionLegs``, or None),
    the tree columns of the ``output_columns``, ``actuator_columns``, the transmission's
    ``columns`` and the ``lean_turns``; per output its ``steps`` (scale, short way) and per
    actuator its ``limits``.
    """

    def __init__(self, tree: KinematicTree, transmission: Transmission,
                 values: Sequence[float], planar_loops: Sequence[Loop] = ()) -> None:
        self.name = transmission.name
        self.tree = tree
        self.transmission = transmission
        self.actuators = transmission.actuators
        self.outputs = transmission.outputs
        self.passive = tuple(name for name in transmission.solved if name not in self.outputs)
        self.parts = [(command_part(tree, subgroup, structure, values, planar_loops),
                       [self.outputs.index(name) for name in structure.known])
                      for subgroup, structure in transmission.command_groups]
        index = tree.index
        self.output_columns = [index[name] for name in self.outputs]
        self.actuator_columns = [index[name] for name in self.actuators]
        self._passive = [index[name] for name in self.passive]
        self.columns = [index[name] for name in transmission.columns]
        self._turns = [index[name] for name in transmission.solved
                       if tree.coordinates[index[name]].kind is MotionKind.TURN]
        # the turns the lean path writes (the others keep their last value exactly)
        lean = {column for part, _ in self.parts for column in part.lean_columns}
        self.lean_turns = [column for column in self._turns if column in lean]
        # the ankle's lean path (command_parts.TransmissionLegs), None for other groups
        self.legs = TransmissionLegs.of([part for part, _ in self.parts],
                                        transmission.equations, self.columns)
        # whole-tree values → a tuple of some of them, in one C call per point
        self._get_actuators = getter(self.actuator_columns)
        self._get_passive = getter(self._passive)
        self._get_columns = getter(self.columns)
        self._get_outputs = getter(self.output_columns)
        joints = {joint.name: joint for joint in tree.joint_above.values()}
        self.steps = []  # per output: its scale, and whether it goes the short way
        for name in self.outputs:
            coordinate = tree.coordinates[index[name]]
            joint = joints.get(coordinate.joint)
            wraps = coordinate.kind is MotionKind.TURN and (
                joint is None or joint.joint_type is not JointType.REVOLUTE
                or coordinate.name != coordinate.joint)
            self.steps.append((transmission.size if coordinate.kind is MotionKind.SLIDE
                               else 1.0, wraps))
        self.limits = [Limits(None, None, None) if name not in joints else Limits(
            joints[name].position_limits, joints[name].velocity_limit,
            joints[name].effort_limit) for name in self.actuators]
        linearization = transmission.linearize([values[i] for i in self.columns])
        if linearization.command_orientation == 0 or linearization.measured_orientation == 0:
            raise PlanError(f'group {self.name}: the assembled pose is a singular '
                            'configuration of the transmission')
        self._initial = CommandState(tuple(float(value) for value in values), (
            linearization.measured_orientation, linearization.command_orientation))
        self._state = self._initial

    @property
    def kinds(self) -> tuple[GroupKind, ...]:
        """Return how each group the outputs make is solved (``transmission.command_groups``)."""
        return tuple(part.kind for part, _ in self.parts)

    def reset(self) -> None:
        """Start again from the assembled pose."""
        self.restore(self._initial)

    def position(self, name: str) -> float:
        """
        Return a joint of the group's position at the last accepted point (rad or m).

        A passive joint the lean path does not solve (a leg's rod) keeps its last solved value.
        """
        return self._state.values[self.tree.index[name]]

    def state(self) -> CommandState:
        """Return the last accepted point's state, for ``restore``."""
        return self._state

    def restore(self, state: CommandState) -> None:
        """Put every solver back at a state ``state`` returned."""
        for part, _ in self.parts:
            part.restore(state.values)
        self._state = state

    def solve(self, positions: Sequence[float], velocities: Sequence[float] = (),
              accelerations: Sequence[float] = (), efforts: Sequence[float] = (),
              passive: bool = False) -> GroupCommand:
        """
        Return the actuators (and, on the full path, passive joints) for the output joints.

        Each array in ``outputs`` order; velocities, accelerations and efforts may be empty
        (accelerations need velocities, and take the full path, as ``passive`` does).
        CommandRefused whole, the state as it was.
        """
        isfinite = math.isfinite
        for what, array in (('position', positions), ('velocity', velocities),
                            ('acceleration', accelerations), ('effort', efforts)):
            if all(map(isfinite, array)):
                continue
            for name, value in zip(self.outputs, array):
                if not isfinite(value):
                    raise CommandRefused(CommandRefusal.NOT_FINITE,
                                         f'output joint {name!r}: {what} {value!r}')
        before = self._state
        last = self._get_outputs(before.values)
        changes = [math.remainder(target - value, 2.0 * math.pi) if wraps else target - value
                   for (_, wraps), target, value in zip(self.steps, positions, last)]
        steps = max(1, math.ceil(max(abs(c) / scale for c, (scale, _)
                                     in zip(changes, self.steps)) / SUBSTEP))
        try:
            for step in range(1, steps):
                fraction = step / steps
                self._step([b + fraction * c for b, c in zip(last, changes)], (), (), (), False)
            return self._step(positions, velocities, accelerations, efforts,
                              passive or bool(accelerations))
        except CommandRefused:
            self.restore(before)
            raise

    def _solve_parts(self, values: list[float], velocities: Sequence[float],
                     accelerations: Sequence[float], full: bool
                     ) -> tuple[list[float], list[float]]:
        """Solve every part into ``values``; return the rates and accelerations (full path)."""
        if not full:
            for part, _ in self.parts:
                part.positions(values)
            return [], []
        rates = [0.0] * len(values)
        found_accelerations = [0.0] * len(values)
        given = velocities or (0.0,) * len(self.outputs)
        for column, rate in zip(self.output_columns, given):
            rates[column] = rate
        for part, places in self.parts:
            known_rates = [given[p] for p in places]
            found, speeds = part.solve(values, known_rates)
            for column, value, speed in zip(part.columns, found, speeds):
                values[column], rates[column] = value, speed
            if accelerations:
                for column, value in zip(part.columns, part.accelerations(
                        known_rates, [accelerations[p] for p in places])):
                    found_accelerations[column] = value
        return rates, found_accelerations

    def _step(self, positions: Sequence[float], velocities: Sequence[float],
              accelerations: Sequence[float], efforts: Sequence[float],
              full: bool) -> GroupCommand:
        """Solve one point from the last; on success it becomes the last accepted one."""
        last = self._state
        values = list(last.values)
        for column, value in zip(self.output_columns, positions):
            values[column] = value
        evaluation: Evaluation | None = None  # the legs give the equations posed
        try:
            if self.legs is not None and not full:
                evaluation = self.legs.positions(values, last.values)
                rates, found_accelerations = [], []
            else:
                rates, found_accelerations = self._solve_parts(values, velocities,
                                                               accelerations, full)
        except SampleRefused as refusal:
            reason = (CommandRefusal.UNREACHABLE if refusal.reason is Refusal.UNREACHABLE
                      else CommandRefusal.SINGULAR)
            # the refusal names the command group it came from (the ankle's one leg)
            detail = (str(refusal) if refusal.group == self.name
                      else f'group {self.name}, {refusal}')
            raise CommandRefused(reason, detail) from None
        remainder, turn = math.remainder, 2.0 * math.pi
        for column in self._turns if full else self.lean_turns:
            before = last.values[column]
            values[column] = before + remainder(values[column] - before, turn)
        linearization = self.transmission.linearize(self._get_columns(values), evaluation)
        orientations = self._check_singular(linearization, last.orientations)
        # M (``linearization.ratio``) is worked out only where velocities or efforts need it
        actuators = JointPoint(
            self._get_actuators(values),
            tuple(math.fsum([m * v for m, v in zip(row, velocities)])
                  for row in linearization.ratio) if velocities else (),
            self._get_actuators(found_accelerations) if accelerations else (),
            self._efforts(linearization.ratio, efforts) if efforts else ())
        self._check_limits(actuators)
        passive_joints = JointPoint(
            self._get_passive(values), self._get_passive(rates) if velocities else (),
            self._get_passive(found_accelerations) if accelerations else ()
        ) if full else _NONE
        self._state = CommandState(tuple(values), orientations)
        return GroupCommand(actuators, passive_joints, linearization)

    def _check_singular(self, linearization: Linearization,
                        before: tuple[int, int]) -> tuple[int, int]:
        """Return both orientations; CommandRefused if either direction is or was singular."""
        orientations = (linearization.measured_orientation, linearization.command_orientation)
        for direction, conditioning, orientation, last in (
                ('measured', linearization.measured_conditioning, orientations[0], before[0]),
                ('command', linearization.command_conditioning, orientations[1], before[1])):
            if orientation != last:
                raise CommandRefused(CommandRefusal.SINGULAR, f'group {self.name}: the '
                                     f'{direction} direction crossed a singular configuration '
                                     '(its orientation changed)')
            if not conditioning <= CONDITION_LIMIT:
                raise CommandRefused(CommandRefusal.SINGULAR, f'group {self.name}: the '
                                     f"{direction} direction's conditioning {conditioning:.3g} "
                                     f'is above {CONDITION_LIMIT:.3g}')
        return orientations

    def _efforts(self, ratio: Sequence[Sequence[float]],
                 efforts: Sequence[float]) -> tuple[float, ...]:
        found = actuator_efforts(ratio, efforts)
        if found is None or not all(map(math.isfinite, found)):
            raise CommandRefused(CommandRefusal.SINGULAR,
                                 f'group {self.name}: the transmission is singular')
        return found

    def _check_limits(self, actuators: JointPoint) -> None:
        for place, (name, limits) in enumerate(zip(self.actuators, self.limits)):
            position = actuators.positions[place]
            if limits.position is not None and not (
                    limits.position[0] <= position <= limits.position[1]):
                raise CommandRefused(CommandRefusal.LIMIT, (
                    f'group {self.name}: actuator {name!r} at {position:.9g} outside '
                    f'[{limits.position[0]:.9g}, {limits.position[1]:.9g}]'))
            for what, array, bound in (('velocity', actuators.velocities, limits.velocity),
                                       ('effort', actuators.efforts, limits.effort)):
                if array and bound is not None and not abs(array[place]) <= bound:
                    raise CommandRefused(CommandRefusal.LIMIT, (
                        f'group {self.name}: actuator {name!r} {what} {array[place]:.9g} '
                        f'beyond ±{bound:.9g}'))
