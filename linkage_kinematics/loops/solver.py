# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A plan's loops closed sample by sample: the measured joints in, every passive loop joint out.

``LoopSolver`` turns each sample of the measured joints' positions and velocities into every
passive joint's, in URDF units (rad, m), in the plan's order: the planar loops loop by loop in
closed form, keeping each loop on its assembly through change points and continuous joints
continuous across turns; then each group of the general closure (``GroupStep``), assembled at
the motion's first sample nearest its zero-pose assembly with the measured joints held there,
and continued from sample to sample by its ``newton.GroupSolver``. A sample that cannot be
closed is a ``LoopSampleError`` naming the loop or group (and, for a group, its
``refusals.Refusal``). Pure: no ROS graph.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
import math

from linkage_kinematics.kinematics.geometry import TWO_PI
from linkage_kinematics.kinematics.planar_loop import (
    DeadPointError,
    driven_loop,
    JointKind,
    known_joint_range,
    UnreachableError,
)
from linkage_kinematics.kinematics.solver import unwrap_near
from linkage_kinematics.loops.assembly import Assembly, AssemblyError
from linkage_kinematics.loops.newton import GroupSolver, GroupState, plan_group
from linkage_kinematics.loops.plan import GroupPlan, LoopPlan
from linkage_kinematics.loops.refusals import Refusal, SampleRefused
from linkage_kinematics.loops.tree import KinematicTree
import numpy as np


class LoopSampleError(ValueError):
    """
    A sample the loops cannot be closed at (a dead point, out of reach, a missing joint).

    ``constraint`` names the loop or group that could not be closed (None: the sample itself is
    bad); ``refusal`` says why a group of the general closure refused it (None for a loop).
    """

    def __init__(self, message: str, constraint: str | None = None,
                 refusal: Refusal | None = None) -> None:
        super().__init__(message)
        self.constraint = constraint
        self.refusal = refusal


class GroupStep:
    """
    One group of the general closure followed sample by sample; ``restart`` forgets the motion.

    At a motion's first sample the group is assembled (``newton.plan_group``, the measured
    joints held at the sample) from its zero-pose assembly, which ``loops.assemblies`` seeds:
    the assembly nearest it at those measured values. Then its ``GroupSolver`` continues it.
    ``places``: where its known joints are among the sample's values; ``published``: where the
    published joints are among the solver's ``solved`` (None: all of them). After a sample:
    ``assembly`` (the motion's), ``solver`` and ``state`` (the last solved sample's).
    """

    def __init__(self, plan: GroupPlan, tree: KinematicTree, places: Sequence[int]) -> None:
        self.plan = plan
        self.tree = tree
        self.places = tuple(places)
        solved = plan.solved
        # None: every solved joint is published, in order (no joint the closure file overrides)
        self.published = (None if not plan.hidden
                          else tuple(solved.index(name) for name in plan.published))
        self.assembly: Assembly | None = None
        self.solver: GroupSolver | None = None
        self.state: GroupState | None = None
        self.fresh = True

    def restart(self) -> None:
        """Assemble again at the next sample, from the zero-pose assembly."""
        self.fresh = True

    def _assemble(self, known: Sequence[float]) -> GroupSolver:
        """Assemble the group at the measured ``known`` values; LoopSampleError if it cannot."""
        tree, plan = self.tree, self.plan
        start = list(plan.zero.assembly.values)
        for name, value in zip(plan.known, known):
            start[tree.index[name]] = value
        try:
            planned = plan_group(tree, plan.group, start, hold_known=True)
        except AssemblyError as error:
            raise LoopSampleError(f'{error} at the first sample', plan.name,
                                  Refusal.UNREACHABLE) from None
        if planned.solver is None:
            raise LoopSampleError(f'group {plan.name}: at the first sample: {planned.problem}',
                                  plan.name, Refusal.SINGULAR)
        self.assembly, self.solver, self.fresh = planned.assembly, planned.solver, False
        self.state = None  # the new solver's, once it has solved a sample
        return planned.solver

    def solve(self, values: Sequence[float], rates: Sequence[float]) -> GroupState:
        """Return the group's state at a sample (``values``, ``rates``: its measured joints')."""
        places = self.places
        known = [values[place] for place in places]
        solver = self._assemble(known) if self.fresh else self.solver
        try:
            self.state = state = solver.solve(known, [rates[place] for place in places])
        except SampleRefused as error:
            raise LoopSampleError(str(error), self.plan.name, error.reason) from None
        return state


class LoopSolver:
    """
    Closes a plan's loops sample by sample: measured joints in, passive joints out.

    Each planar loop starts on its planned branch at the zero pose and follows the known joint's
    motion from sample to sample (``DrivenLoop.continued_branch``), so that it stays on its
    assembly through change points; revolute and continuous joints are kept within π of their
    previous value (at first, of the zero pose), and a revolute known joint is followed across
    whole turns. A refused sample leaves that state as it was. Each group of the general closure
    is a ``GroupStep`` (``groups``, in solve order), solved after the planar loops.
    """

    def __init__(self, plan: LoopPlan) -> None:
        self.plan = plan
        # A sample's joint values and rates are lists: the measured joints', then each passive
        # joint's as it is solved (plan.passive's order). Each loop's step, resolved once here
        # rather than at every sample: its closure's name and label, its known joint's name,
        # place in those lists and sign, whether its branch flips with each whole turn of that
        # joint (a revolute known joint meeting an odd number of change points per turn), the
        # loop driven at that joint, and each passive joint's place among the passive joints,
        # sign, index and revolute-ness.
        self._passive = plan.passive
        places = {name: place for place, name in enumerate(plan.measured + self._passive)}
        passive_places = {name: place for place, name in enumerate(self._passive)}
        self._steps = tuple(
            (planned.loop.constraint, planned.loop.label, planned.known.name,
             places[planned.known.name],
             planned.known.sign,
             planned.known.kind is JointKind.REVOLUTE and len(known_joint_range(
                 planned.loop.planar, planned.known.index).change_points) % 2 == 1,
             driven_loop(planned.loop.planar, planned.known.index),
             tuple((passive_places[joint.name], joint.sign, joint.index,
                    joint.kind is JointKind.REVOLUTE) for joint in planned.passive))
            for planned in plan.loops)
        measured_places = {name: place for place, name in enumerate(plan.measured)}
        self.groups = tuple(GroupStep(group, plan.tree, [measured_places[name]
                                                         for name in group.known])
                            for group in plan.general)
        self.reset()

    def reset(self) -> None:
        """Start again from the zero pose on the planned branches (and assemblies)."""
        # each loop's known value and branch at the last sample, in solve order
        self._known_values = [0.0] * len(self.plan.loops)
        self._branches = [planned.branch for planned in self.plan.loops]
        self._previous = [0.0] * len(self._passive)  # in plan.passive's order
        for group in self.groups:
            group.restart()

    def solve(self, positions: Mapping[str, float],
              velocities: Mapping[str, float]) -> tuple[dict[str, float], dict[str, float]]:
        """
        Return every passive joint's position and velocity (rad or m, rad/s or m/s).

        From the measured joints' ``positions`` and ``velocities`` (by joint name, URDF units;
        other names are ignored). Raises LoopSampleError, naming the closure or group and the
        joint, at a dead point, out of reach, or for a measured joint missing or not finite, or
        naming the group and its refusal. The planar loops' state is then as it was; a group
        solved before the one that refused keeps its solution at the sample (a closed pose at
        measured values, which its continuation goes on from).
        """
        values = []
        rates = []
        isfinite = math.isfinite
        for name in self.plan.measured:
            if name not in positions or name not in velocities:
                raise LoopSampleError(f'no position and velocity for measured joint {name!r}')
            value = float(positions[name])
            rate = float(velocities[name])
            if not (isfinite(value) and isfinite(rate)):
                raise LoopSampleError(f'measured joint {name!r}: position {value} and '
                                      f'velocity {rate} are not both finite')
            values.append(value)
            rates.append(rate)
        solved, solved_rates = self._close(values, rates)
        return dict(zip(self._passive, solved)), dict(zip(self._passive, solved_rates))

    def solve_measured(self, values: Sequence[float], rates: Sequence[float]
                       ) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """
        Return every passive joint's position and velocity, in ``plan.passive``'s order.

        ``solve`` without the names: the measured joints' ``values`` and ``rates`` (floats) in
        ``plan.measured``'s order, as the follower's intake gives them, none missing. Raises as
        ``solve``.
        """
        isfinite = math.isfinite
        # one sum for the usual sample, every value finite; only a sum that is not is searched
        if not isfinite(sum(values) + sum(rates)):
            for name, value, rate in zip(self.plan.measured, values, rates):
                if not (isfinite(value) and isfinite(rate)):
                    raise LoopSampleError(f'measured joint {name!r}: position {value} and '
                                          f'velocity {rate} are not both finite')
        # the passive joints' are appended to the lists: the caller's stay as they are
        return self._close(list(values), list(rates))

    def positions_many(self, values: Sequence[np.ndarray]) -> list[np.ndarray] | None:
        """
        Return every passive joint's positions at a motion's samples, or None: one by one then.

        In ``plan.passive``'s order. ``values``: the measured joints' arrays (``plan.measured``'s
        order), the first sample
        the last one solved (the state stays there). Each loop's branches continued from it
        (``DrivenLoop.positions_many``), each revolute passive joint kept within π of the
        sample before, as ``solve`` keeps it. None with general groups, a branch that flips with
        whole turns of its known joint, or any sample refused (``solve`` names it).
        """
        if self.groups:
            return None
        columns = list(values)
        passive: list[np.ndarray] = []
        for step, last_branch in zip(self._steps, self._branches):
            _, _, _, place, sign, flips_with_turns, driven, joints = step
            if flips_with_turns:
                return None
            coordinates = driven.positions_many(sign * columns[place], last_branch)
            if coordinates is None:
                return None
            for passive_place, joint_sign, index, revolute in joints:
                position = joint_sign * coordinates[index]
                if revolute:
                    position = _unwrapped(position, self._previous[passive_place])
                columns.append(position)
                passive.append(position)
        return passive

    def _close(self, values: list[float], rates: list[float]
               ) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """Close the loops at the measured ``values`` and ``rates`` (checked), appended to."""
        known_values, branches = [], []
        solved = len(values)  # where the passive joints start
        previous = self._previous
        for step, last_value, last_branch in zip(self._steps, self._known_values,
                                                 self._branches):
            constraint, label, known, place, sign, flips_with_turns, driven, passive = step
            value = sign * values[place]
            try:
                branch = driven.continued_branch(last_value, last_branch, value)
                # A revolute known joint is followed across whole turns (an encoder that wraps
                # at ±π): the motion went the short way, the whole turns between it and the way
                # just counted holding an odd number of change points each where it flips.
                if flips_with_turns and round((last_value - value) / TWO_PI) % 2:
                    branch = -branch
                state = driven.solve(value, sign * rates[place], branch)
            except (DeadPointError, UnreachableError) as error:
                raise LoopSampleError(f'{label} at {known} = {values[place]:.9g}: {error}',
                                      constraint) from None
            known_values.append(value)
            branches.append(state.branch)
            coordinates, state_rates = state.coordinates, state.rates
            for passive_place, joint_sign, index, revolute in passive:
                position = joint_sign * coordinates[index]
                if revolute:
                    position = unwrap_near(position, previous[passive_place])
                values.append(position)
                rates.append(joint_sign * state_rates[index])
        for group in self.groups:
            # Measured joints only are known to a group: its outputs go after every planar one.
            state = group.solve(values, rates)
            published = group.published
            if published is None:
                values.extend(state.positions)
                rates.extend(state.velocities)
            else:
                positions_out, velocities_out = state.positions, state.velocities
                for index in published:
                    values.append(positions_out[index])
                    rates.append(velocities_out[index])
        self._known_values, self._branches = known_values, branches
        self._previous = values[solved:]
        return tuple(self._previous), tuple(rates[solved:])


def _unwrapped(angles: np.ndarray, start: float) -> np.ndarray:
    """
    Return ``angles`` moved by whole turns, each within π of the one before (the first: ``start``).

    As ``unwrap_near`` moves them one by one; the whole turns are counted up exactly.
    """
    jumps = np.round((np.concatenate(([start], angles[:-1])) - angles) / TWO_PI)
    return angles + TWO_PI * np.cumsum(jumps)
