# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The package's own closure of a parallel model's loops, for the parallel section (the ``ours`` row).

Built as the node builds it, from the model's own texts (``model.source_urdf`` and
``model.closure_file``, not the peers' rewritten URDF): the URDF read once
(``model.urdf_reader.read_urdf``), its closures by ``loops.encodings.read_closures`` (any of the
three encodings), a ``loops.tree.KinematicTree`` with the closure file's joint overrides, the
closure groups for the actuated joints (``loops.structure.closure_groups``), each group planned
at the pose the follower is started at (``loops.newton.plan_group``: assembled there with the
actuated joints held, analysed, classified, its ``GroupSolver`` built), then per sample each
group's ``GroupSolver.solve``, warm started from its last solution as the node runs it.

Velocities: the node hands the solver the actuated joints' velocities and gets the passive ones
back; the peers compute positions only. The section hands zeros (``solve`` costs the same), so
its time per sample includes the velocities the peers do not compute.

A sample one group refuses (``SampleRefused``: no assembly reaches it, too near a singular
configuration, the answer would jump to another assembly) is a sample the node drops: its
answer here is NaN for the refused group's joints and the follower's verdict is False. A group
the plan refuses (under- or over-determined, a singular assembled pose) refuses the whole run:
``start`` raises ``StartRefused`` with the plan's one line.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
import math

from linkage_kinematics.loops.encodings import read_closures
from linkage_kinematics.loops.newton import GroupSolver, plan_group, PlannedGroup
from linkage_kinematics.loops.refusals import SampleRefused
from linkage_kinematics.loops.structure import closure_groups, ClosureGroup
from linkage_kinematics.loops.tree import KinematicTree
from linkage_kinematics.model.urdf_reader import read_urdf
from parallel_models import ParallelModel
from parallel_peers import Answer

LABEL = 'linkage_kinematics (this package)'


class StartRefused(RuntimeError):
    """The package's plan refuses a group of the model; the message is its one line."""


@dataclass(frozen=True)
class _Group:
    """A planned group and where its joints are: known in the sample, solved in the answer."""

    solver: GroupSolver
    known: tuple[int, ...]  # places in the sample (``model.actuated``)
    solved: tuple[int, ...]  # places in the answer (``model.coordinates``)
    velocities: tuple[float, ...]


class PackageClosure:
    """The package's closure of one model, per sample (module docstring)."""

    label = LABEL

    def __init__(self, model: ParallelModel) -> None:
        """Read the model's URDF and closures, build its tree and groups (StartRefused if not)."""
        urdf = read_urdf(model.source_urdf)
        description = read_closures(urdf, model.closure_file)
        if description.problems:
            raise StartRefused(description.problems[0])
        self.model = model
        self.tree = KinematicTree(urdf, description.overrides)
        self.groups: tuple[ClosureGroup, ...] = closure_groups(
            self.tree, description.closures, model.actuated)
        self.planned: tuple[PlannedGroup, ...] = ()
        self._groups: tuple[_Group, ...] = ()
        self._positions: list[float] = []
        self._actuated_places: tuple[int, ...] = ()
        # the largest conditioning of a sample closed since the start (GroupState.conditioning)
        self.conditioning = 1.0

    def start(self, pose: Mapping[str, float]) -> None:
        """
        Plan every group at ``pose`` (every coordinate by name), the actuated joints held there.

        StartRefused with the first group's problem, as the node refuses to start.
        """
        start = [float(pose[name]) for name in self.tree.names]
        self.planned = tuple(plan_group(self.tree, group, start) for group in self.groups)
        for planned in self.planned:
            if planned.solver is None:
                raise StartRefused(planned.problem)
        actuated = {name: index for index, name in enumerate(self.model.actuated)}
        coordinates = {name: index for index, name in enumerate(self.model.coordinates)}
        self._groups = tuple(
            _Group(planned.solver, tuple(actuated[name] for name in planned.solver.known),
                   tuple(coordinates[name] for name in planned.solver.solved),
                   (0.0,) * len(planned.solver.known))
            for planned in self.planned)
        # every coordinate no group solves stays at the pose (the actuated ones take the sample)
        self._positions = [0.0] * len(self.model.coordinates)
        for name, value in zip(self.tree.names, start):
            self._positions[coordinates[name]] = value
        self._actuated_places = tuple(coordinates[name] for name in self.model.actuated)
        self.conditioning = 1.0

    def follow(self, actuated: Sequence[float]) -> Answer:
        """Close every group for the actuated joints' values ``actuated`` (``model.actuated``)."""
        positions = self._positions
        for place, value in zip(self._actuated_places, actuated):
            positions[place] = value
        converged = True
        answer = list(positions)
        for group in self._groups:
            try:
                state = group.solver.solve([actuated[place] for place in group.known],
                                           group.velocities)
            except SampleRefused:
                converged = False
                for place in group.solved:
                    answer[place] = math.nan
                continue
            for place, value in zip(group.solved, state.positions):
                answer[place] = positions[place] = value
            if state.conditioning > self.conditioning:
                self.conditioning = state.conditioning
        return Answer(tuple(answer), converged)
