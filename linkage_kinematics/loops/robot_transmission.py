# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A robot's transmissions with names: which groups have output joints, and their efforts.

``plan_transmissions`` takes a ``plan.LoopPlan`` and the output joints (``loops.output_joints``)
and gives each closure group that they name joints of its ``transmission.Transmission``, built
and checked at the robot's assembled pose: a group of the general closure at its zero-pose
assembly (``GroupPlan.zero``), the planar loops closed in closed form at the actuators' zero
values on their planned branches (the zero pose's, or ``loops.branches``), as the node closes
them; with that pose, which the command direction (``command.CommandGroup``) starts from too.
A group none of whose joints is named has no transmission: its joints are published as without
the parameter.

``OutputEfforts`` turns one sample's measured actuator efforts into the efforts of the joints
the node publishes (``LoopPlan.passive``, in that order): each output joint τ_o = Mᵀ·τ_m
(``Transmission.output_efforts``), every other published joint 0, the effort of an unactuated
joint as the serial model sees it (a joint of a group without output joints too: its actuators
keep their own efforts, on the input). What it needs of a sample is found once per plan: where
each group's actuators are among the measured joints and its solved joints among the published
ones (a planar group's solve order is its loops', the transmission's its structure's), or, for
a group of the general closure, its ``solver.GroupStep``'s last state (which also holds the
coordinates a closure file overrides, solved, not published). ``advantages`` gives each group's
mechanical advantage at a sample (diagnostics; not the per-sample path). Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

from linkage_kinematics.loops.plan import GroupPlan, LoopPlan
from linkage_kinematics.loops.solver import GroupStep, LoopSampleError, LoopSolver
from linkage_kinematics.loops.structure import analyse, GroupStructure
from linkage_kinematics.loops.transmission import (
    assign_outputs,
    MechanicalAdvantage,
    Transmission,
    TransmissionError,
    TransmissionSingular,
)


@dataclass(frozen=True)
class GroupTransmission:
    """
    One group's transmission and the pose it was built at.

    ``group``: the plan's group; ``structure``: its measured direction's structure at
    ``values``, the assembled pose (every coordinate of the tree).
    """

    group: GroupPlan
    structure: GroupStructure
    values: tuple[float, ...]
    transmission: Transmission


def assembled_pose(plan: LoopPlan) -> list[float]:
    """
    Return the robot's assembled pose (module docstring), every coordinate of the tree.

    The pose both directions' transmissions start from (``robot_command.plan_command`` too).

    TransmissionError where the planar loops do not close at the actuators' zero values.
    """
    tree = plan.tree
    values = [0.0] * len(tree.names)
    for group in plan.general:
        for index in group.group.coordinates:
            values[index] = group.zero.assembly.values[index]
    if plan.loops:
        planar = LoopSolver(replace(plan, groups=tuple(group for group in plan.groups
                                                       if group.zero is None)))
        zeros = dict.fromkeys(plan.measured, 0.0)
        try:
            solved, _ = planar.solve(zeros, zeros)
        except LoopSampleError as error:
            raise TransmissionError("the planar loops do not close at the actuators' zero "
                                    f'values: {error}') from None
        for name, value in solved.items():
            values[tree.index[name]] = value
    return values


def plan_transmissions(plan: LoopPlan,
                       outputs: Sequence[str]) -> tuple[GroupTransmission, ...]:
    """
    Return the transmission of each group ``outputs`` names joints of, in the plan's order.

    TransmissionError, one line naming every problem ('; ' between them): a name that is no
    joint of the robot, is named twice or is a joint of no closure group
    (``transmission.assign_outputs``), a coordinate the closure file overrides (never
    published), and per group output joints that cannot be its (``transmission.check_outputs``:
    measured, not as many as its degrees of freedom, not independent at the assembled pose);
    or planar loops that do not close at the actuators' zero values.
    """
    tree = plan.tree
    assigned, problems = assign_outputs(tree, [group.group for group in plan.groups], outputs)
    problems = list(problems)
    hidden = {name for group in plan.groups for name in group.hidden}
    problems += [f'output joint {name!r} is a coordinate the closure file overrides: it is '
                 'solved but not published' for name in outputs if name in hidden]
    found = []
    try:
        values = assembled_pose(plan) if any(assigned.values()) else []
    except TransmissionError as error:
        raise TransmissionError('; '.join([*problems, str(error)])) from None
    for group in plan.groups:
        names = assigned[group.name]
        if not names:
            continue
        structure = (group.zero.structure if group.zero is not None
                     else analyse(tree, group.group, values))
        try:
            transmission = Transmission(tree, group.group, structure, names, values)
        except TransmissionError as error:
            problems.append(str(error))
            continue
        found.append(GroupTransmission(group, structure, tuple(values), transmission))
    if problems:
        raise TransmissionError('; '.join(problems))
    return tuple(found)


@dataclass(frozen=True)
class _Sources:
    """Where one group's transmission finds a sample's values, resolved once per plan."""

    transmission: Transmission
    # places of its actuators among the measured joints (``LoopPlan.measured``)
    actuators: tuple[int, ...]
    # a group of the general closure: its place in ``LoopSolver.groups``; else None
    step: int | None
    # else: the places of its solved joints (``Transmission.solved``) among the published ones
    solved: tuple[int, ...]
    # per output joint: its place among the solved joints, and among the published ones
    outputs: tuple[tuple[int, int], ...]


class OutputEfforts:
    """
    The published joints' efforts from the measured actuators' (module docstring).

    ``actuators``: the places among the measured joints of the efforts ``efforts`` takes, every
    transmission's actuators group after group.
    """

    def __init__(self, plan: LoopPlan, groups: Sequence[GroupTransmission]) -> None:
        self.groups = tuple(groups)
        measured = {name: place for place, name in enumerate(plan.measured)}
        published = {name: place for place, name in enumerate(plan.passive)}
        steps = {group.name: place for place, group in enumerate(plan.general)}
        self._count = len(plan.passive)
        sources = []
        for found in self.groups:
            transmission = found.transmission
            solved = transmission.solved
            general = found.group.zero is not None
            sources.append(_Sources(
                transmission, tuple(measured[name] for name in transmission.actuators),
                steps[found.group.name] if general else None,
                () if general else tuple(published[name] for name in solved),
                tuple((solved.index(name), published[name]) for name in transmission.outputs)))
        self._sources = tuple(sources)
        self.actuators = tuple(place for source in self._sources for place in source.actuators)

    def efforts(self, values: Sequence[float], positions: Sequence[float],
                steps: Sequence[GroupStep], efforts: Sequence[float]) -> tuple[float, ...]:
        """
        Return every published joint's effort at a sample (N·m or N, ``LoopPlan.passive`` order).

        ``values``: the measured joints' values, ``positions`` the published joints' (the
        sample's), ``steps`` the solver's groups after it; ``efforts`` those of the measured
        joints at ``actuators``. TransmissionSingular (naming the group) where a group's
        transmission is too near a singular configuration for its efforts.
        """
        result = [0.0] * self._count
        start = 0
        for source in self._sources:
            places = source.actuators
            end = start + len(places)
            if source.step is None:
                solved = [positions[place] for place in source.solved]
            else:
                solved = steps[source.step].state.positions
            found = source.transmission.output_efforts(
                [values[place] for place in places], solved, efforts[start:end])
            for solved_place, published_place in source.outputs:
                result[published_place] = found[solved_place]
            start = end
        return tuple(result)

    def advantages(self, joints: Mapping[str, float], steps: Sequence[GroupStep]
                   ) -> tuple[MechanicalAdvantage | TransmissionSingular | None, ...]:
        """
        Return each group's mechanical advantage at a sample, or why it has none there.

        ``joints``: the sample's measured and published joints by name; a coordinate the
        closure file overrides is taken from its group's ``steps`` state. None where the sample
        lacks a joint of the group (another description's) or the group has not solved one since
        it was last assembled.
        """
        found: list[MechanicalAdvantage | TransmissionSingular | None] = []
        for source in self._sources:
            transmission = source.transmission
            state = None if source.step is None else steps[source.step].state
            known = [joints.get(name) for name in transmission.actuators]
            solved = [joints.get(name, None if state is None else state.positions[place])
                      for place, name in enumerate(transmission.solved)]
            if None in known or None in solved:
                found.append(None)
                continue
            try:
                found.append(transmission.advantage(known, solved))
            except TransmissionSingular as singular:
                found.append(singular)
        return tuple(found)
