# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Every planar kinematic loop of a lab's URDF, closed from its measured joints.

A lab writes each loop's cut joint as a revolute ``<constraint>`` (see ``loop_urdf``);
``find_loops`` reads them all, ``loop_geometry`` turns each into a ``PlanarLoop`` with its joints'
signs, and the loops that cannot be closed are kept as one-line problems. ``RobotLoops.plan``
orders the loops for a set of measured joints so that each loop is solved from exactly one known
joint (measured, or solved by an earlier loop) and picks each loop's assembly branch (the zero
pose's, or a per-constraint override). ``LoopSolver`` then turns each sample of the measured
joints' positions and velocities into every passive loop joint's, in URDF units (rad, m), loop by
loop, keeping each loop on its assembly through change points and continuous joints continuous
across turns. Pure: no ROS graph.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass
import math

from linkage_kinematics.kinematics.geometry import GeometryError, TWO_PI
from linkage_kinematics.kinematics.planar_loop import (
    branch_of,
    DeadPointError,
    driven_loop,
    JointKind,
    known_joint_range,
    UnreachableError,
)
from linkage_kinematics.kinematics.solver import unwrap_near
from linkage_kinematics.model.loop_geometry import derive_loop, Loop, LoopJoint
from linkage_kinematics.model.loop_urdf import LoopError, read_robot

BRANCHES = (-1, 1)
# A pin open by more than this fraction of the loop's longest link at the zero pose: not an
# assembled pose (an exporter's rounding is some 1e-16 of it, six printed digits 1e-6).
ASSEMBLED_TOLERANCE = 1e-5


class LoopSampleError(ValueError):
    """
    A sample the loops cannot be closed at (a dead point, out of reach, a missing joint).

    ``constraint`` names the loop that could not be closed (None: the sample itself is bad).
    """

    def __init__(self, message: str, constraint: str | None = None) -> None:
        super().__init__(message)
        self.constraint = constraint


@dataclass(frozen=True)
class PlannedLoop:
    """A loop in solve order: its known joint and its assembly branch at the zero pose."""

    loop: Loop
    known: LoopJoint
    # the known joint is measured (else an earlier loop solves it)
    measured: bool
    branch: int

    @property
    def passive(self) -> tuple[LoopJoint, LoopJoint]:
        """Return the two joints this loop solves, in loop order."""
        first, second = (joint for joint in self.loop.joints if joint is not self.known)
        return first, second


@dataclass(frozen=True)
class LoopPlan:
    """The loops in solve order for one set of measured joints, and what to warn about."""

    loops: tuple[PlannedLoop, ...]
    measured: tuple[str, ...]
    warnings: tuple[str, ...]

    @property
    def passive(self) -> tuple[str, ...]:
        """Return the names of every joint the loops solve, in solve order."""
        return tuple(joint.name for planned in self.loops for joint in planned.passive)


def zero_pose_branch(loop: Loop, known: LoopJoint) -> int:
    """Return the loop's assembly branch at the zero pose, seen from ``known`` (±1)."""
    try:
        return branch_of(loop.planar, known.index, (0.0, 0.0, 0.0, 0.0))
    except (DeadPointError, UnreachableError, GeometryError) as error:
        raise LoopError(f'constraint {loop.constraint!r}: no assembly branch at the zero pose '
                        f'with {known.name!r} known: {error}') from None


def zero_pose_warnings(loops: Sequence[Loop]) -> tuple[str, ...]:
    """
    Return a warning for each loop whose zero pose is not assembled.

    Its assembly branch at the zero pose (the default) is then only the nearer of the two,
    which may not be the one the robot is built in.
    """
    return tuple(
        f'constraint {loop.constraint!r}: the zero pose is not assembled (its pin is '
        f'{loop.planar.closure_gap:.3g} m open in the plane), so the assembly branch taken there '
        "may not be the robot's; check it, and give the node loops.branches if it is not"
        for loop in loops
        if loop.planar.closure_gap > ASSEMBLED_TOLERANCE * max(
            math.hypot(*link) for link in loop.planar.links))


def mimic_warnings(loops: Sequence[Loop], known: Collection[str]) -> tuple[str, ...]:
    """Return a warning for each loop joint not in ``known`` that also carries a ``<mimic>``."""
    return tuple(
        f'joint {joint.name!r} (constraint {loop.constraint!r}) is solved by its loop but also '
        f'mimics {joint.mimic!r}: robot_state_publisher would pose it from two sources'
        for loop in loops for joint in loop.joints
        if joint.mimic is not None and joint.name not in known)


@dataclass(frozen=True)
class RobotLoops:
    """A URDF's loops, and the constraints among its ``<constraint>``s that cannot be closed."""

    robot_name: str
    joint_names: frozenset[str]
    loops: tuple[Loop, ...]
    # one line per constraint that cannot be closed, naming it and saying why
    problems: tuple[str, ...]
    # what urdf_parser_py said about the text (its own notes, not problems of the loops)
    parser_messages: tuple[str, ...] = ()

    def plan(self, measured: Sequence[str],
             branches: Mapping[str, int] | None = None) -> LoopPlan:
        """
        Order the loops so that each is solved from exactly one known joint.

        ``measured``: the joints whose values come in; ``branches``: constraint name → ±1, the
        assembly branch at the zero pose, for constraints whose zero pose is not the assembly
        wanted. Raises LoopError, one line per problem, naming the joints or constraints: an
        unknown joint or constraint name, a branch other than ±1, a loop none of whose joints is
        known, a loop with more than one known joint. The constraints in ``problems`` have no
        loop and are not in the plan: a caller that needs every loop refuses those first.
        """
        branches = dict(branches or {})
        problems = [f'measured joint {name!r} is not a joint of the robot'
                    for name in measured if name not in self.joint_names]
        constraints = {loop.constraint for loop in self.loops}
        problems += [f'branch given for {name!r}, which is not a closable constraint'
                     for name in branches if name not in constraints]
        problems += [f'constraint {name!r}: branch {value!r} is not -1 or 1'
                     for name, value in branches.items() if value not in BRANCHES]
        known = set(measured)
        remaining = list(self.loops)
        ordered: list[PlannedLoop] = []
        while True:
            ready = next((loop for loop in remaining if known & set(loop.names)), None)
            if ready is None:
                break
            remaining.remove(ready)
            hits = [name for name in ready.names if name in known]
            if len(hits) > 1:
                problems.append(f'constraint {ready.constraint!r}: {len(hits)} of its joints '
                                f'{hits} are known (measured or solved by another loop); '
                                'exactly one must be')
                continue
            joint = ready.joint(hits[0])
            branch = branches.get(ready.constraint)
            if branch is None:
                try:
                    branch = zero_pose_branch(ready, joint)
                except LoopError as error:
                    problems.append(str(error))
                    continue
            ordered.append(PlannedLoop(ready, joint, joint.name in measured, branch))
            known.update(ready.names)
        problems += [f'constraint {loop.constraint!r}: none of its joints {list(loop.names)} is '
                     'measured or solved by another loop' for loop in remaining]
        if problems:
            raise LoopError('\n'.join(problems))
        return LoopPlan(tuple(ordered), tuple(measured),
                        zero_pose_warnings(self.loops) + mimic_warnings(self.loops, measured))


def find_loops(urdf: str) -> RobotLoops:
    """
    Read every ``<constraint>``'s loop from a URDF text.

    Raises LoopError for a text that is not a URDF robot, or whose joints do not form a tree;
    constraints that cannot be closed are returned as ``problems``.
    """
    robot = read_robot(urdf)
    loops, problems = [], list(robot.constraint_problems)
    for constraint in robot.constraints:
        try:
            loops.append(derive_loop(robot, constraint))
        except LoopError as error:
            problems.append(str(error))
    return RobotLoops(robot.name, frozenset(robot.joints), tuple(loops), tuple(problems),
                      robot.parser_messages)


class LoopSolver:
    """
    Closes a plan's loops sample by sample: measured joints in, passive loop joints out.

    Each loop starts on its planned branch at the zero pose and follows the known joint's motion
    from sample to sample (``DrivenLoop.continued_branch``), so that it stays on its assembly
    through change points; revolute and continuous joints are kept within π of their previous
    value (at first, of the zero pose), and a revolute known joint is followed across whole turns.
    A refused sample leaves that state as it was.
    """

    def __init__(self, plan: LoopPlan) -> None:
        self.plan = plan
        # A sample's joint values and rates are lists: the measured joints', then each passive
        # joint's as it is solved (plan.passive's order). Each loop's step, resolved once here
        # rather than at every sample: its constraint, its known joint's name, place in those
        # lists and sign, whether its branch flips with each whole turn of that joint (a
        # revolute known joint meeting an odd number of change points per turn), the loop
        # driven at that joint, and each passive joint's place among the passive joints, sign,
        # index and revolute-ness.
        self._passive = plan.passive
        places = {name: place for place, name in enumerate(plan.measured + self._passive)}
        passive_places = {name: place for place, name in enumerate(self._passive)}
        self._steps = tuple(
            (planned.loop.constraint, planned.known.name, places[planned.known.name],
             planned.known.sign,
             planned.known.kind is JointKind.REVOLUTE and len(known_joint_range(
                 planned.loop.planar, planned.known.index).change_points) % 2 == 1,
             driven_loop(planned.loop.planar, planned.known.index),
             tuple((passive_places[joint.name], joint.sign, joint.index,
                    joint.kind is JointKind.REVOLUTE) for joint in planned.passive))
            for planned in plan.loops)
        self.reset()

    def reset(self) -> None:
        """Start again from the zero pose on the planned branches."""
        # each loop's known value and branch at the last sample, in solve order
        self._known_values = [0.0] * len(self.plan.loops)
        self._branches = [planned.branch for planned in self.plan.loops]
        self._previous = [0.0] * len(self._passive)  # in plan.passive's order

    def solve(self, positions: Mapping[str, float],
              velocities: Mapping[str, float]) -> tuple[dict[str, float], dict[str, float]]:
        """
        Return every passive loop joint's position and velocity (rad or m, rad/s or m/s).

        From the measured joints' ``positions`` and ``velocities`` (by joint name, URDF units;
        other names are ignored). Raises LoopSampleError, naming the constraint and the
        joint, at a dead point, out of reach, or for a measured joint missing or not finite.
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
        known_values, branches = [], []
        solved = len(values)  # where the passive joints start
        previous = self._previous
        for step, last_value, last_branch in zip(self._steps, self._known_values,
                                                 self._branches):
            constraint, known, place, sign, flips_with_turns, driven, passive = step
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
                raise LoopSampleError(f'constraint {constraint!r} at {known} = '
                                      f'{values[place]:.9g}: {error}', constraint) from None
            known_values.append(value)
            branches.append(state.branch)
            coordinates, state_rates = state.coordinates, state.rates
            for passive_place, joint_sign, index, revolute in passive:
                position = joint_sign * coordinates[index]
                if revolute:
                    position = unwrap_near(position, previous[passive_place])
                values.append(position)
                rates.append(joint_sign * state_rates[index])
        self._known_values, self._branches = known_values, branches
        self._previous = values[solved:]
        return (dict(zip(self._passive, self._previous)),
                dict(zip(self._passive, rates[solved:])))
