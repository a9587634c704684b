# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Every closed loop of a lab's robot description, and the plan that closes them from its joints.

``find_loops`` reads a parsed URDF's closures in every encoding (``encodings``: ``<constraint>``
and ``<loop_joint>`` elements, the closure file) into a ``RobotLoops``: the robot's
``KinematicTree`` (with the closure file's joint overrides), every closure that can be closed,
and among them the pins whose loops are planar four-bar or slider loops, each derived as a
``planar.Loop``. What cannot be closed is one line each (``read_loops`` refuses it).

``RobotLoops.plan`` plans for a set of measured joints. Closures that share an unknown joint
form a closure group (``structure.closure_groups``); groups share no unknown joint, so each is
solved on its own. A group whose closures are all planar loops (a chain of planar
one-degree-of-freedom loops) is closed in closed form as it always was: its loops ordered so
that each is solved from exactly one known joint (measured, or solved by an earlier loop), each
on its assembly branch (the zero pose's, or a per-closure override), as ``PlannedLoop``s that
``solver.LoopSolver`` closes. Every other group is the general closure's: assembled at the zero
pose with its joints free (``newton.plan_group``, from a seed where ``assemblies`` gives one of
its joints), analysed (degrees of freedom from the rank, idle freedoms, whether the measured
joints determine it) and given a solver. The ``LoopPlan`` holds both kinds of ``GroupPlan`` in
solve order, the planar loops first: one plan, one solver. Pure: no ROS graph.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, field, replace
import math

from linkage_kinematics.kinematics.geometry import GeometryError
from linkage_kinematics.kinematics.planar_loop import branch_of, DeadPointError, UnreachableError
from linkage_kinematics.loops.assembly import AssemblyError
from linkage_kinematics.loops.closures import (
    Closure,
    ClosureKind,
    ClosureSide,
    JointOverride,
    Vector,
)
from linkage_kinematics.loops.description import (
    LoopError,
    read_robot,
    Robot,
    side_frame,
    tree_path,
)
from linkage_kinematics.loops.encodings import read_closures
from linkage_kinematics.loops.newton import plan_group, PlannedGroup
from linkage_kinematics.loops.planar import derive_loop, four_joint_pin, Loop, LoopJoint
from linkage_kinematics.loops.structure import closure_groups, ClosureGroup, GroupKind
from linkage_kinematics.loops.tree import KinematicTree, TreeError
from linkage_kinematics.model.urdf_reader import ROTATING_TYPES, UrdfTree

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
class GroupPlan:
    """
    One closure group of the plan: what it knows and solves, and how.

    ``loops``: a group of planar loops, its loops in solve order (closed in closed form by
    ``solver.LoopSolver``; ``zero`` None); every other group has none, and ``zero`` plans it:
    assembled at the zero pose with its joints free (the checker's assembly; the node assembles
    again at its first sample, from there, with the measured joints held), analysed, classified
    and given a solver (``newton.PlannedGroup``). ``known`` and ``solved`` name coordinates of
    the tree, in the order the group takes and gives them; ``hidden`` the solved coordinates of
    joints the closure file overrides (solved, never published: they are no URDF joints).
    ``seed``: the ``assemblies`` start values of its joints.
    """

    group: ClosureGroup
    known: tuple[str, ...]
    solved: tuple[str, ...]
    loops: tuple[PlannedLoop, ...] = ()
    zero: PlannedGroup | None = None
    seed: Mapping[str, float] = field(default_factory=dict)
    hidden: tuple[str, ...] = ()

    @property
    def name(self) -> str:
        """Return the group's name: its closures' names joined by '+'."""
        return self.group.name

    @property
    def kind(self) -> GroupKind:
        """Return how the group's positions are solved."""
        if self.zero is None:
            return GroupKind.PLANAR_LOOPS
        # a planar loop the planar closed forms do not take (two prismatic joints): Newton
        return (GroupKind.NEWTON if self.zero.kind is GroupKind.PLANAR_LOOPS
                else self.zero.kind)

    @property
    def published(self) -> tuple[str, ...]:
        """Return the solved joints published on joint_states: ``solved`` less ``hidden``."""
        return tuple(name for name in self.solved if name not in self.hidden)


@dataclass(frozen=True)
class LoopPlan:
    """
    The robot's loops in solve order for one set of measured joints, and what to warn about.

    ``loops``: the planar loops in solve order (of every planar group); ``groups``: every
    closure group, the planar ones first, then the general closure's (``GroupPlan.zero`` set),
    in solve order. ``problems``: what ``RobotLoops.survey`` found wrong (a plan from
    ``RobotLoops.plan`` has none).
    """

    loops: tuple[PlannedLoop, ...]
    measured: tuple[str, ...]
    warnings: tuple[str, ...]
    groups: tuple[GroupPlan, ...] = ()
    tree: KinematicTree | None = None
    problems: tuple[str, ...] = ()
    unassembled: tuple[str, ...] = ()

    @property
    def general(self) -> tuple[GroupPlan, ...]:
        """Return the groups the general closure solves (not planar loops), in solve order."""
        return tuple(group for group in self.groups if group.zero is not None)

    @property
    def passive(self) -> tuple[str, ...]:
        """Return the names of every joint the plan publishes, in solve order."""
        return (tuple(joint.name for planned in self.loops for joint in planned.passive)
                + tuple(name for group in self.general for name in group.published))


def zero_pose_branch(loop: Loop, known: LoopJoint) -> int:
    """Return the loop's assembly branch at the zero pose, seen from ``known`` (±1)."""
    try:
        return branch_of(loop.planar, known.index, (0.0, 0.0, 0.0, 0.0))
    except (DeadPointError, UnreachableError, GeometryError) as error:
        raise LoopError(f'{loop.label}: no assembly branch at the zero pose '
                        f'with {known.name!r} known: {error}') from None


def zero_pose_warnings(loops: Sequence[Loop]) -> tuple[str, ...]:
    """
    Return a warning for each loop whose zero pose is not assembled.

    Its assembly branch at the zero pose (the default) is then only the nearer of the two,
    which may not be the one the robot is built in.
    """
    return tuple(
        f'{loop.label}: the zero pose is not assembled (its pin is '
        f'{loop.planar.closure_gap:.3g} m open in the plane), so the assembly branch taken there '
        "may not be the robot's; check it, and give the node loops.branches if it is not"
        for loop in loops
        if loop.planar.closure_gap > ASSEMBLED_TOLERANCE * max(
            math.hypot(*link) for link in loop.planar.links))


def mimic_warnings(loops: Sequence[Loop], known: Collection[str]) -> tuple[str, ...]:
    """Return a warning for each loop joint not in ``known`` that also carries a ``<mimic>``."""
    return tuple(
        f'joint {joint.name!r} ({loop.label}) is solved by its loop but also '
        f'mimics {joint.mimic!r}: robot_state_publisher would pose it from two sources'
        for loop in loops for joint in loop.joints
        if joint.mimic is not None and joint.name not in known)


def override_warning(joint: str, child: str, override: JointOverride) -> str:
    """
    Return the warning for a loop's joint the closure file reads as another (not published).

    A JointState gives robot_state_publisher one value per URDF joint, and the URDF joint
    (``child`` its child link) is not the one the closure file reads: its coordinates are
    solved but not published.
    """
    if override is JointOverride.FIXED:
        return (f'joint {joint!r} is held at 0 by the closure file (joint_type FIXED): nothing '
                f'publishes it, so robot_state_publisher cannot pose link {child!r} and the '
                'links below it; make it a fixed joint in the URDF')
    coordinates = override.coordinates(joint)
    return (f'joint {joint!r} is read as {override.name} by the closure file: its coordinates '
            f'{", ".join(coordinates)} are solved but not published (they are no URDF joints), '
            f'so robot_state_publisher cannot pose link {child!r} and the links below it; model '
            f'it in the URDF as {len(coordinates)} revolute joints to publish them')


@dataclass(frozen=True)
class RobotLoops:
    """
    A URDF's closures: the planar loops among them, every closable one, and those refused.

    ``loops``: the pins whose loops are planar four-bar or slider loops, in closure order;
    ``closures``: every closure that can be closed (the planar loops' too), as the kinematic
    ``tree`` reads them (a ``<constraint>`` pin without an axis turns about its loop's first
    revolute joint's); ``actuated`` and ``overrides``: the closure file's ``name_mot`` (None
    without one) and joint overrides.
    """

    robot_name: str
    joint_names: frozenset[str]
    loops: tuple[Loop, ...]
    # one line per closure that cannot be closed, naming it and saying why
    problems: tuple[str, ...]
    # what urdf_parser_py said about the text (its own notes, not problems of the loops)
    parser_messages: tuple[str, ...] = ()
    closures: tuple[Closure, ...] = ()
    tree: KinematicTree | None = None
    actuated: tuple[str, ...] | None = None
    overrides: Mapping[str, JointOverride] = field(default_factory=dict)
    # whatever the measured joints: each joint on a loop that the closure file overrides
    warnings: tuple[str, ...] = ()

    def plan(self, measured: Sequence[str], branches: Mapping[str, int] | None = None,
             assemblies: Mapping[str, float] | None = None) -> LoopPlan:
        """
        Plan every closure for the ``measured`` joints (module docstring).

        ``branches``: closure name → ±1, a planar loop's assembly branch at the zero pose, for
        loops whose zero pose is not the assembly wanted; ``assemblies``: joint → value (rad or
        m), a start value of a joint a general group solves, to assemble it nearer another
        assembly. Raises LoopError, one line per problem, naming the joints, closures or
        groups: an unknown joint or closure name, a branch other than ±1, a planar loop none of
        whose joints is known or with more than one known joint, a group the measured joints do
        not determine (under- or over-determined) or that does not assemble. The closures in
        ``problems`` are not in the plan: a caller that needs every loop refuses those first.
        """
        plan = self.survey(measured, branches, assemblies)
        if plan.problems:
            raise LoopError('\n'.join(plan.problems))
        return plan

    def survey(self, measured: Sequence[str], branches: Mapping[str, int] | None = None,
               assemblies: Mapping[str, float] | None = None) -> LoopPlan:
        """Return the plan as far as it goes, its ``problems`` listed rather than raised."""
        branches = dict(branches or {})
        problems = [f'measured joint {name!r} is not a joint of the robot'
                    for name in measured if name not in self.joint_names]
        tree = self.tree
        groups: tuple[ClosureGroup, ...] = ()
        if tree is not None:
            problems += [f'measured joint {name!r} has no value of its own (a fixed joint, a '
                         'mimic or a joint the closure file overrides)'
                         for name in measured if name in self.joint_names
                         and name not in tree.index]
            groups = closure_groups(tree, self.closures,
                                    [name for name in measured if name in tree.index])
        planar = {loop.constraint for loop in self.loops}
        planar_groups = [group for group in groups
                         if all(closure.name in planar for closure in group.closures)]
        in_planar = {closure.name for group in planar_groups for closure in group.closures}
        loops = [loop for loop in self.loops if loop.constraint in in_planar]
        problems += [f'branch given for {name!r}, which is not a closable constraint'
                     for name in branches if name not in planar]
        problems += [f'branch given for {name!r}, whose loop shares joints with spatial '
                     'closures and is solved with them (loops.assemblies picks their assembly)'
                     for name in branches if name in planar and name not in in_planar]
        labels = {loop.constraint: loop.label for loop in self.loops}
        problems += [f'{labels.get(name, repr(name))}: branch {value!r} is not -1 or 1'
                     for name, value in branches.items() if value not in BRANCHES]
        ordered, ordering_problems = _order(loops, measured, branches)
        problems += ordering_problems
        general, unassembled, general_problems = self._general(
            [group for group in groups if group not in planar_groups], dict(assemblies or {}))
        problems += unassembled + general_problems
        planned = tuple(_planar_group(tree, group, ordered) for group in planar_groups) + general
        warnings = (zero_pose_warnings(loops) + mimic_warnings(loops, measured)
                    + self.warnings)
        return LoopPlan(tuple(ordered), tuple(measured), warnings, planned, tree,
                        tuple(problems), tuple(unassembled))

    def _general(self, groups: Sequence[ClosureGroup], seeds: dict[str, float]
                 ) -> tuple[tuple[GroupPlan, ...], list[str], list[str]]:
        """
        Return the general closure's groups planned at the zero pose, and their problems.

        One line for each group that does not assemble, then the others' problems.
        """
        tree = self.tree
        plans, unassembled, problems = [], [], []
        seeded: set[str] = set()
        start = [0.0] * len(tree.names)
        for group in groups:
            seed = {name: value for name, value in seeds.items()
                    if tree.index.get(name) in group.unknown}
            seeded.update(seed)
            try:
                zero = plan_group(tree, group, start, seed, hold_known=False)
            except AssemblyError as error:
                unassembled.append(f'{error}: it cannot be assembled as given')
                continue
            if zero.problem is not None:
                problems.append(zero.problem)
            plans.append(GroupPlan(
                group, zero.structure.known, zero.structure.solved, (), zero, seed,
                tuple(name for name in zero.structure.solved
                      if tree.coordinates[tree.index[name]].joint in self.overrides)))
        problems += [f'loops.assemblies: {name!r} is not a joint a closure group solves by the '
                     'general closure (a planar loop takes loops.branches)'
                     for name in seeds if name not in seeded]
        return tuple(plans), unassembled, problems


def _planar_group(tree: KinematicTree, group: ClosureGroup,
                  ordered: Sequence[PlannedLoop]) -> GroupPlan:
    """Return a group of planar loops: its measured joints, and its loops in solve order."""
    names = {closure.name for closure in group.closures}
    loops = tuple(item for item in ordered if item.loop.constraint in names)
    return GroupPlan(group, tuple(tree.coordinates[i].name for i in group.known),
                     tuple(joint.name for item in loops for joint in item.passive), loops)


def _order(loops: Sequence[Loop], measured: Sequence[str],
           branches: Mapping[str, int]) -> tuple[list[PlannedLoop], list[str]]:
    """
    Order planar loops so that each is solved from exactly one known joint.

    Returns the loops in solve order, and one line per problem: a loop with more than one
    known joint, a loop none of whose joints is known, a loop without a branch at the zero pose.
    """
    problems = []
    known = set(measured)
    remaining = list(loops)
    ordered: list[PlannedLoop] = []
    while True:
        ready = next((loop for loop in remaining if known & set(loop.names)), None)
        if ready is None:
            break
        remaining.remove(ready)
        hits = [name for name in ready.names if name in known]
        if len(hits) > 1:
            problems.append(f'{ready.label}: {len(hits)} of its joints {hits} are known '
                            '(measured or solved by another loop); exactly one must be')
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
    problems += [f'{loop.label}: none of its joints {list(loop.names)} is measured or solved '
                 'by another loop' for loop in remaining]
    return ordered, problems


def _pin_axes(robot: Robot, closure: Closure) -> Closure:
    """
    Return a ``<constraint>`` pin without an axis turning about its loop's first revolute joint.

    As the planar loops read it (constraint_element): the joint's world axis at the zero pose,
    in each side's frame. LoopError when the loop has no revolute joint.
    """
    if closure.kind is not ClosureKind.PIN or closure.parent.axis is not None:
        return closure
    axis = next((joint.axis for joint, _ in tree_path(robot, closure.parent.link,
                                                      closure.child.link)
                 if joint.joint_type in ROTATING_TYPES), None)
    if axis is None:
        raise LoopError(f'{closure.label}: a pin without parent_axis turns about the first '
                        'revolute joint of its loop, which has none')

    def local(side: ClosureSide) -> Vector:  # the world axis in the side's frame
        x, y, z = (float(component) for component in side_frame(robot, side).rotation.T @ axis)
        return (x, y, z)

    child = closure.child if closure.child.axis is not None else replace(
        closure.child, axis=local(closure.child))
    return replace(closure, parent=replace(closure.parent, axis=local(closure.parent)),
                   child=child)


def find_loops(tree: UrdfTree, closure_file: str | None = None) -> RobotLoops:
    """
    Read every closure of a parsed URDF and of its closure file text (if any).

    Closures that cannot be closed are returned as ``problems``. Raises ClosureError (one line)
    for a closure file that is no closure file at all: unreadable input, as a URDF that is not
    XML is to ``read_urdf``.
    """
    description = read_closures(tree, closure_file)
    problems = list(description.problems)
    robot = read_robot(tree)
    try:
        kinematic: KinematicTree | None = KinematicTree(tree, description.overrides)
    except TreeError as error:
        problems.append(str(error))
        kinematic = None
    loops, closures = [], []
    for closure in description.closures if kinematic is not None else ():
        try:
            if four_joint_pin(robot, closure, description.overrides):
                loops.append(derive_loop(robot, closure))
            elif closure.parent.link == closure.child.link:
                raise LoopError(f'{closure.label}: joins link {closure.parent.link!r} to itself')
            resolved = _pin_axes(robot, closure)
            kinematic.loop(resolved)
            closures.append(resolved)
        except (LoopError, TreeError) as error:
            problems.append(str(error))
    on_loops = {joint.name for closure in closures
                for joint, _ in tree_path(robot, closure.parent.link, closure.child.link)}
    warnings = tuple(override_warning(joint, robot.joints[joint].child, override)
                     for joint, override in description.overrides.items() if joint in on_loops)
    return RobotLoops(robot.name, frozenset(robot.joints), tuple(loops), tuple(problems),
                      tree.parser_messages, tuple(closures), kinematic, description.actuated,
                      description.overrides, warnings)


def read_loops(tree: UrdfTree, closure_file: str | None = None) -> RobotLoops:
    """
    Return a parsed robot description's loops; LoopError, one line, if any cannot be closed.

    The line names every closure's problem; a robot without any closure is refused too: there
    is nothing to close. ClosureError for an unreadable closure file (``find_loops``).
    """
    loops = find_loops(tree, closure_file)
    if loops.problems:
        raise LoopError('; '.join(loops.problems))
    if not loops.closures:
        raise LoopError(f'robot {loops.robot_name!r} has no <constraint> loop to close')
    return loops
