# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A robot's command direction with names: what the relay to the actuators' controllers converts.

A point names joints (a ``JointTrajectory``'s ``joint_names``, a forward command's declared
order) and carries positions, velocities, accelerations and efforts for them
(``command.JointPoint``). The URDF's joints outside the loops pass through unchanged; every group
whose output joints it names is converted (``command.CommandGroup``, the lean path: actuators
only), its actuators following the joints passed through. Refused whole (``CommandRefused``,
reason ``JOINTS``), one line listing every problem: a name the URDF does not have, a loop joint
that is not an output joint (an actuator or passive joint: command the outputs), a group's
output joints given in part, a name given twice, an array neither empty nor one value per
joint, accelerations without velocities, loop outputs without positions; and NaN or inf
anywhere (``NOT_FINITE``). A trajectory's points are converted in order, continuing from the
last accepted point, and refused whole, naming the first point refused: the groups are then as
before it. A forward command is a trajectory of one point. A trajectory of many is converted
at once (``command_batch``, numpy) where it can be, with the same answers to a few ulps and
the same refusals (it declines whatever it would not decide as the per-point path does).

``plan_command`` builds one from a robot description's loops as the loops node plans them (the
same measured joints, branches and assemblies), each group's output joints from
``loops.output_joints``. Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass
import math

from linkage_kinematics.loops.command import (
    CommandGroup,
    CommandRefusal,
    CommandRefused,
    CommandState,
    getter,
    JointPoint,
)
from linkage_kinematics.loops.command_batch import convert_many
from linkage_kinematics.loops.plan import RobotLoops
from linkage_kinematics.loops.robot_transmission import assembled_pose
from linkage_kinematics.loops.structure import analyse
from linkage_kinematics.loops.transmission import (
    assign_outputs,
    Transmission,
    TransmissionError,
)
import numpy as np

# lists of names whose conversion is kept
LAYOUTS = 64


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
        self._owner: dict[str, int] = {}
        self._loop_joints: dict[str, str] = {}
        self._layouts: dict[tuple[str, ...], _Layout | CommandRefused] = {}
        for number, group in enumerate(self.groups):
            for name in group.outputs:
                self._owner[name] = number
            for name in (*group.actuators, *group.passive):
                self._loop_joints[name] = group.name

    def reset(self) -> None:
        """Start every group again from its assembled pose."""
        for group in self.groups:
            group.reset()

    def names(self, names: Sequence[str]) -> tuple[str, ...]:
        """Return the joint names a point given for ``names`` is converted to."""
        return self._layout(names).names

    def _layout(self, names: Sequence[str]) -> _Layout:
        """Return how a point for ``names`` is converted (kept per list of names); or refuse."""
        key = tuple(names)
        layout = self._layouts.get(key)
        if layout is None:
            layout = self._split(key)
            if len(self._layouts) >= LAYOUTS:  # a relay has a few lists; a stream of others
                self._layouts.clear()
            self._layouts[key] = layout
        if isinstance(layout, CommandRefused):
            raise layout
        return layout

    def _split(self, names: tuple[str, ...]) -> _Layout | CommandRefused:
        """Return the groups commanded and the joints passed through, or the refusal."""
        problems = []
        twice = sorted({name for name in names if names.count(name) > 1})
        if twice:
            problems.append(f'joints named twice: {twice}')
        passing = []
        given: dict[int, int] = {}
        for name in dict.fromkeys(names):  # each name once, in order
            if name in self._owner:
                number = self._owner[name]
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
            return CommandRefused(CommandRefusal.JOINTS, '; '.join(problems))
        commanded = tuple(sorted(given))
        passing_places = [names.index(name) for name in passing]
        output_places = tuple([names.index(name) for name in self.groups[number].outputs]
                              for number in commanded)
        return _Layout(
            tuple(passing) + tuple(name for number in commanded
                                   for name in self.groups[number].actuators),
            commanded, getter(passing_places) if passing else None,
            tuple((self.groups[number], getter(places))
                  for number, places in zip(commanded, output_places)),
            passing_places, output_places)

    def _check(self, names: Sequence[str], point: JointPoint, commanded: bool) -> None:
        for what, array in (('positions', point.positions), ('velocities', point.velocities),
                            ('accelerations', point.accelerations), ('effort', point.efforts)):
            if array and len(array) != len(names):
                raise CommandRefused(CommandRefusal.JOINTS, f'{len(array)} {what} for '
                                     f'{len(names)} joints')
            if not all(map(math.isfinite, array)):
                name, value = next((n, v) for n, v in zip(names, array)
                                   if not math.isfinite(v))
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

        A forward command (one point): CommandRefused whole, every group's state as it was.
        """
        layout = self._layout(names)
        self._check(names, point, bool(layout.commanded))
        states = [self.groups[number].state() for number in layout.commanded]
        try:
            return self._point(layout, point)
        except CommandRefused:
            self._restore(layout, states)
            raise

    def trajectory(self, names: Sequence[str],
                   points: Sequence[JointPoint]) -> tuple[JointPoint, ...]:
        """
        Return every point converted, in order, for ``self.names(names)``.

        CommandRefused whole, naming the first point refused (0-based); the groups' states are
        then as before the trajectory. Converted at once where ``command_batch`` can, else
        point by point: the same answers to a few ulps, the same refusals.
        """
        layout = self._layout(names)
        stacked = _stacked(len(names), points)
        # every point's arrays alike and finite: the first point's check is every point's
        for number, point in enumerate(points[:1] if stacked is not None else points):
            try:
                self._check(names, point, bool(layout.commanded))
            except CommandRefused as refusal:
                raise _at_point(refusal, number) from None
        states = [self.groups[number].state() for number in layout.commanded]
        if stacked is not None and stacked[2] is None and len(points) > 1:
            batched = self._batched(layout, stacked, len(points))
            if batched is not None:
                return batched
            self._restore(layout, states)
        converted = []
        for number, point in enumerate(points):
            try:
                converted.append(self._point(layout, point))
            except CommandRefused as refusal:
                self._restore(layout, states)
                raise _at_point(refusal, number) from None
        return tuple(converted)

    def _batched(self, layout: _Layout, stacked: Sequence[np.ndarray | None],
                 count: int) -> tuple[JointPoint, ...] | None:
        """
        Return every point converted by ``command_batch``, or None: the per-point path then.

        ``stacked``: ``_stacked``'s arrays, without accelerations (their rate term is the
        per-point path's). None where any group's batch declines (a point it would not decide
        as the per-point path does); the groups may then have moved (the caller restores them).
        """
        out: list[list[np.ndarray]] = [[array[:, layout.passing_places]]
                                       if array is not None else [] for array in stacked]
        for (group, _), places in zip(layout.groups, layout.output_places):
            found = convert_many(group, *(array[:, places] if array is not None else None
                                          for array in (stacked[0], stacked[1], stacked[3])))
            if found is None:
                return None
            for field, array in ((0, found.positions), (1, found.velocities),
                                 (3, found.efforts)):
                if array is not None:
                    out[field].append(array)
        fields = [list(map(tuple, np.hstack(arrays).tolist())) if arrays else [()] * count
                  for arrays in out]
        return tuple(map(JointPoint, *fields))

    def _restore(self, layout: _Layout, states: Sequence[CommandState]) -> None:
        """Put the groups a point moved back where they were."""
        for number, state in zip(layout.commanded, states):
            if self.groups[number].state() is not state:
                self.groups[number].restore(state)

    def _point(self, layout: _Layout, point: JointPoint) -> JointPoint:
        """Return the point converted: the joints passed through, then each group's."""
        passing = layout.passing
        if passing is None and len(layout.groups) == 1:  # one group's actuators alone
            group, outputs = layout.groups[0]
            return group.solve(*[outputs(array) if array else () for array in point]).actuators
        out = [list(passing(array)) if passing is not None and array else []
               for array in point]
        for group, outputs in layout.groups:
            found = group.solve(*[outputs(array) if array else () for array in point]).actuators
            for target, array in zip(out, found):
                target += array
        return JointPoint(*map(tuple, out))


@dataclass(frozen=True)
class _Layout:
    """
    How a point for one list of names is converted.

    Its out names, the groups commanded (their numbers) and, prepared once, the getter of the
    joints passed through (None: none) and per group its output joints' getter.
    """

    names: tuple[str, ...]
    commanded: tuple[int, ...]
    passing: Callable[[Sequence[float]], tuple[float, ...]] | None
    groups: tuple[tuple[CommandGroup, Callable[[Sequence[float]], tuple[float, ...]]], ...]
    # the same places as lists, for a trajectory's arrays (``RobotCommand._batched``)
    passing_places: list[int]
    output_places: tuple[list[int], ...]


def _stacked(width: int, points: Sequence[JointPoint]) -> list[np.ndarray | None] | None:
    """
    Return each of the points' arrays stacked (N, width), None where no point has it.

    None for all where a field is on some points only, of another length, or not finite: the
    points are then checked (and converted) one by one.
    """
    if not points:
        return None
    fields: list[np.ndarray | None] = []
    for field in range(4):
        arrays = [point[field] for point in points]
        if not arrays[0]:
            if any(arrays):
                return None
            fields.append(None)
            continue
        try:
            array = np.array(arrays, dtype=float)
        except ValueError:  # of unequal lengths
            return None
        if array.shape != (len(points), width) or not np.isfinite(array).all():
            return None
        fields.append(array)
    return fields


def _at_point(refusal: CommandRefused, number: int) -> CommandRefused:
    """Return the refusal with the point's number before its detail."""
    return CommandRefused(refusal.reason, f'point {number}: {refusal.detail}')


def plan_command(loops: RobotLoops, measured: Sequence[str], outputs: Sequence[str],
                 branches: Mapping[str, int] | None = None,
                 assemblies: Mapping[str, float] | None = None) -> RobotCommand:
    """
    Return the command direction of a robot's loops: ``measured`` the actuators.

    The loops planned as the loops node plans them (``RobotLoops.plan``: LoopError, one line per
    problem), each group assembled as there: a general group at its zero-pose assembly, a
    planar group's loops on their planned branches (``branches``, else the zero pose's) at the
    actuators' zero values; each group's output joints from ``outputs`` (every group needs its
    own: ``transmission.assign_outputs`` and ``check_outputs``; TransmissionError, one line per
    problem), and its ``CommandGroup`` (PlanError where the assembled pose is a singular
    configuration of the transmission).
    """
    plan = loops.plan(measured, branches, assemblies)
    tree = plan.tree
    assigned, problems = assign_outputs(tree, [group.group for group in plan.groups], outputs)
    problems = list(problems)
    values = assembled_pose(plan)
    commands = []
    for group in plan.groups:
        structure = (group.zero.structure if group.zero is not None
                     else analyse(tree, group.group, values))
        try:
            transmission = Transmission(tree, group.group, structure, assigned[group.name],
                                        values)
        except TransmissionError as error:
            problems.append(str(error))
            continue
        commands.append(CommandGroup(tree, transmission, values, loops.loops))
    if problems:
        raise TransmissionError('; '.join(problems))
    return RobotCommand(commands, loops.joint_names)
