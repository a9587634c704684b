# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Every planar kinematic loop of a lab's URDF, and their order from the measured joints.

A lab writes each loop's cut joint as a revolute ``<constraint>`` (see ``description``);
``find_loops`` reads them all, ``planar`` turns each into a ``PlanarLoop`` with its joints'
signs, and the loops that cannot be closed are kept as one-line problems (``read_loops`` refuses
them). ``RobotLoops.plan`` orders the loops for a set of measured joints so that each loop is
solved from exactly one known joint (measured, or solved by an earlier loop) and picks each
loop's assembly branch (the zero pose's, or a per-constraint override): the ``LoopPlan`` that
``solver.LoopSolver`` closes sample by sample. Pure: no ROS graph.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass
import math

from linkage_kinematics.kinematics.geometry import GeometryError
from linkage_kinematics.kinematics.planar_loop import branch_of, DeadPointError, UnreachableError
from linkage_kinematics.loops.description import LoopError, read_robot
from linkage_kinematics.loops.planar import derive_loop, Loop, LoopJoint
from linkage_kinematics.model.urdf_reader import UrdfTree

BRANCHES = (-1, 1)
# A pin open by more than this fraction of the loop's longest link at the zero pose: not an
# assembled pose (an exporter's rounding is some 1e-16 of it, six printed digits 1e-6).
ASSEMBLED_TOLERANCE = 1e-5


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


def find_loops(tree: UrdfTree) -> RobotLoops:
    """
    Read every ``<constraint>``'s loop of a parsed URDF.

    Constraints that cannot be closed are returned as ``problems``.
    """
    robot = read_robot(tree)
    loops, problems = [], list(robot.constraint_problems)
    for constraint in robot.constraints:
        try:
            loops.append(derive_loop(robot, constraint))
        except LoopError as error:
            problems.append(str(error))
    return RobotLoops(robot.name, frozenset(robot.joints), tuple(loops), tuple(problems),
                      tree.parser_messages)


def read_loops(tree: UrdfTree) -> RobotLoops:
    """
    Return a parsed robot description's loops; LoopError, one line, if any cannot be closed.

    The line names every constraint's problem; a robot without any ``<constraint>`` is refused
    too: there is nothing to close.
    """
    loops = find_loops(tree)
    if loops.problems:
        raise LoopError('; '.join(loops.problems))
    if not loops.loops:
        raise LoopError(f'robot {loops.robot_name!r} has no <constraint> loop to close')
    return loops
