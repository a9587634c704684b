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

from linkage_kinematics.kinematics.geometry import GeometryError
from linkage_kinematics.kinematics.planar_loop import (
    branch_of,
    continued_branch_of,
    DeadPointError,
    JointKind,
    solve_loop,
    UnreachableError,
)
from linkage_kinematics.kinematics.solver import unwrap_near
from linkage_kinematics.model.loop_geometry import derive_loop, Loop, LoopJoint
from linkage_kinematics.model.loop_urdf import LoopError, read_robot

BRANCHES = (-1, 1)


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
        return LoopPlan(tuple(ordered), tuple(measured), mimic_warnings(self.loops, measured))


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
    from sample to sample (``continued_branch_of``), so that it stays on its assembly through
    change points; revolute and continuous joints are kept within π of their previous value
    (at first, of the zero pose). A refused sample leaves that state as it was.
    """

    def __init__(self, plan: LoopPlan) -> None:
        self.plan = plan
        self.reset()

    def reset(self) -> None:
        """Start again from the zero pose on the planned branches."""
        self._known_values = {planned.loop.constraint: 0.0 for planned in self.plan.loops}
        self._branches = {planned.loop.constraint: planned.branch for planned in self.plan.loops}
        self._previous = {name: 0.0 for name in self.plan.passive}

    def solve(self, positions: Mapping[str, float],
              velocities: Mapping[str, float]) -> tuple[dict[str, float], dict[str, float]]:
        """
        Return every passive loop joint's position and velocity (rad or m, rad/s or m/s).

        From the measured joints' ``positions`` and ``velocities`` (by joint name, URDF units;
        other names are ignored). Raises LoopSampleError, naming the constraint and the
        joint, at a dead point, out of reach, or for a measured joint missing or not finite.
        """
        values = {}
        rates = {}
        for name in self.plan.measured:
            if name not in positions or name not in velocities:
                raise LoopSampleError(f'no position and velocity for measured joint {name!r}')
            values[name], rates[name] = float(positions[name]), float(velocities[name])
            if not (math.isfinite(values[name]) and math.isfinite(rates[name])):
                raise LoopSampleError(f'measured joint {name!r}: position {values[name]} and '
                                      f'velocity {rates[name]} are not both finite')
        known_values, branches = {}, {}
        solved_positions, solved_velocities = {}, {}
        for planned in self.plan.loops:
            constraint, known = planned.loop.constraint, planned.known
            value = known.sign * values[known.name]
            planar = planned.loop.planar
            try:
                branch = continued_branch_of(planar, known.index,
                                             self._known_values[constraint],
                                             self._branches[constraint], value)
                state = solve_loop(planar, known.index, value, known.sign * rates[known.name],
                                   branch)
            except (DeadPointError, UnreachableError) as error:
                raise LoopSampleError(f'constraint {constraint!r} at {known.name} = '
                                      f'{values[known.name]:.9g}: {error}',
                                      constraint) from None
            known_values[constraint], branches[constraint] = value, state.branch
            for joint in planned.passive:
                position = joint.sign * state.coordinates[joint.index]
                if joint.kind is JointKind.REVOLUTE:
                    position = unwrap_near(position, self._previous[joint.name])
                values[joint.name] = solved_positions[joint.name] = position
                rates[joint.name] = solved_velocities[joint.name] = (
                    joint.sign * state.rates[joint.index])
        self._known_values, self._branches = known_values, branches
        self._previous = dict(solved_positions)
        return solved_positions, solved_velocities
