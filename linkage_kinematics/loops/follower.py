# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The measured source of ``loops:=robot_description``: a robot's loops closed message by message.

``RobotLoopsFollower.follow`` takes the fields of one ``sensor_msgs/JointState`` (stamp, names,
positions, velocities), takes the measured joints in through the measured modes' one
``intake.Intake`` and closes every loop of the robot's description from them
(``plan.RobotLoops.plan``, ``solver.LoopSolver``): planar loops and closure groups alike. It
returns a ``LoopSample``, the passive joints' positions and velocities (URDF units, rad or m),
or a ``LoopDrop``, why the message was dropped and which loops or groups it concerned. The
measured joints are those given, else the closure file's actuated joints (``name_mot``), else
the loop joints the first message carries. A measured joint without a velocity gets the
intake's estimate (the backward difference over the header stamps, 0 for a first sample). A
revolute measured joint is unwrapped across turns, as the four-bar's driver is, and
``measured.max_jump`` (rad) applies to it; a prismatic one's length (m) has no such bound.

With output joints (``loops.output_joints``, ``robot_transmission.plan_transmissions``, checked
when the plan is made) and a message whose measured actuators carry finite efforts, the sample
also holds every published joint's effort (``robot_transmission.OutputEfforts``): only then is
that path taken. No ROS.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from linkage_kinematics.kinematics.planar_loop import JointKind, known_joint_range
from linkage_kinematics.loops.intake import DropReason, Estimate, Intake
from linkage_kinematics.loops.plan import LoopPlan, RobotLoops
from linkage_kinematics.loops.refusals import Refusal
from linkage_kinematics.loops.robot_transmission import OutputEfforts, plan_transmissions
from linkage_kinematics.loops.solver import LoopSampleError, LoopSolver
from linkage_kinematics.loops.transmission import TransmissionSingular
from linkage_kinematics.loops.tree import MotionKind

# Why a closure group refused a sample, as the message's drop reason
REFUSAL_DROPS = {Refusal.UNREACHABLE: DropReason.NO_ASSEMBLY,
                 Refusal.ASSEMBLY_CHANGE: DropReason.ASSEMBLY_JUMP,
                 Refusal.SINGULAR: DropReason.SINGULAR}


@dataclass(frozen=True)
class LoopDrop:
    """A dropped message: why, the loops or groups it concerned (none: all) and the detail."""

    reason: DropReason
    constraints: tuple[str, ...]
    detail: str


@dataclass
class LoopSample:
    """
    The passive joints at one message, in solve order, and what came with them.

    ``joints`` holds every measured and published solved joint's position (for /tf);
    ``estimates`` how each measured joint's velocity was obtained; ``known_values`` each
    loop's known joint value (URDF units), by constraint. ``efforts``: each published joint's
    effort (N·m or N), empty without output joints or without the actuators' efforts;
    ``withheld``: the group whose transmission was too near a singular configuration to give
    them (None: not withheld). A value, not frozen: a frozen dataclass's
    ``object.__setattr__`` per field costs four times its plain ``__init__`` per sample.
    """

    stamp_ns: int
    names: tuple[str, ...]
    positions: tuple[float, ...]
    velocities: tuple[float, ...]
    joints: dict[str, float]
    estimates: dict[str, Estimate]
    known_values: dict[str, float]
    efforts: tuple[float, ...] = ()
    withheld: str | None = None


class RobotLoopsFollower:
    """
    Follows the measured joints of one robot description; ``restart`` forgets the motion.

    Construction raises LoopError (one line per problem, naming the joints, closures or groups)
    when the measured joints (``measured``, else the closure file's actuated ones) are known
    and cannot close the loops; without them the loop joints the first message carries are
    planned then (``follow`` raises LoopError then). ``assemblies``: joint → start value, to
    assemble a group of the general closure nearer another assembly (``RobotLoops.plan``).
    ``outputs``: the output joints (``loops.output_joints``; empty: none), checked with the
    plan: TransmissionError (one line) where they cannot be its groups'.
    """

    def __init__(self, loops: RobotLoops, measured: Sequence[str],
                 branches: Mapping[str, int], max_jump: float,
                 assemblies: Mapping[str, float] | None = None,
                 outputs: Sequence[str] = ()) -> None:
        self.loops = loops
        self._max_jump = max_jump
        self._branches = dict(branches)
        self._assemblies = dict(assemblies or {})
        self._outputs = tuple(outputs)
        # the published joints' efforts, with output joints
        self.output_efforts: OutputEfforts | None = None
        tree = loops.tree
        self.loop_joints = frozenset(
            [name for loop in loops.loops for name in loop.names]
            + [tree.coordinates[index].name for closure in loops.closures
               for index in tree.loop_coordinates(tree.loop(closure))])
        self.solver: LoopSolver | None = None
        self._intake: Intake | None = None
        measured = tuple(measured) or loops.actuated or ()
        if measured:
            self._plan(measured)

    @property
    def plan(self) -> LoopPlan | None:
        """Return the loops in solve order, None until the measured joints are known."""
        return None if self.solver is None else self.solver.plan

    @property
    def max_jump(self) -> float:
        """Return how far (rad) a revolute measured joint may move from one sample to the next."""
        return self._max_jump

    @max_jump.setter
    def max_jump(self, value: float) -> None:
        self._max_jump = value
        if self._intake is not None:
            self._intake.max_jump = value

    def _plan(self, measured: tuple[str, ...]) -> None:
        plan = self.loops.plan(measured, self._branches, self._assemblies)
        output_efforts = (OutputEfforts(plan, plan_transmissions(plan, self._outputs))
                          if self._outputs else None)
        self.solver = LoopSolver(plan)
        self.output_efforts = output_efforts
        # resolved once per plan rather than per message: the revolute measured joints (the
        # intake unwraps them), each loop's constraint and known joint, the loops and groups
        # each feeds
        tree = plan.tree
        revolute = {planned.known.name for planned in plan.loops
                    if planned.measured and planned.known.kind is JointKind.REVOLUTE}
        revolute.update(name for group in plan.general for name in group.known
                        if tree.coordinates[tree.index[name]].kind is MotionKind.TURN)
        self._intake = Intake(plan.measured, revolute, self._max_jump, DropReason.NO_JOINT)
        self._known = tuple((planned.loop.constraint, planned.known.name)
                            for planned in plan.loops)
        self._feeds = {name: tuple(planned.loop.constraint for planned in plan.loops
                                   if planned.known.name == name)
                       + tuple(group.name for group in plan.general if name in group.known)
                       for name in measured}
        self._measured = plan.measured  # in the order the intake takes them
        self._passive = plan.passive  # the solved joints' names, in the order solve gives them

    def restart(self) -> None:
        """Forget the motion: the next valid message starts it on the planned assemblies."""
        if self.solver is not None:
            self._intake.restart()
            self.solver.reset()

    def _loops_of(self, names: Sequence[str]) -> tuple[str, ...]:
        """Return the loops and groups that know one of the measured joints ``names``."""
        return tuple(constraint for name in names for constraint in self._feeds[name])

    def follow(self, stamp_ns: int, names: Sequence[str], positions: Sequence[float],
               velocities: Sequence[float],
               efforts: Sequence[float] = ()) -> LoopSample | LoopDrop | None:
        """
        Return the passive joints at one message, or why it was dropped.

        None for a message that carries none of the measured joints (with none known, none of
        the loop joints), e.g. this node's own output heard back: ignored, not counted.
        ``efforts``: the message's (empty: none, or not read).
        """
        if self.solver is None:
            carried = tuple(name for name in names if name in self.loop_joints)
            if not carried:
                return None
            self._plan(carried)
        taken = self._intake.take(stamp_ns, names, positions, velocities)
        if taken.__class__ is not tuple:
            return None if taken is None else LoopDrop(taken.reason,
                                                       self._loops_of(taken.joints),
                                                       taken.detail)
        _, values, rates, estimates = taken
        try:
            solved, solved_rates = self.solver.solve_measured(values, rates)
        except LoopSampleError as error:
            return LoopDrop(DropReason.JOINTS_UNREACHABLE if error.refusal is None
                            else REFUSAL_DROPS[error.refusal],
                            () if error.constraint is None else (error.constraint,), str(error))
        self._intake.keep(stamp_ns, values)
        measured = self._measured
        joints = dict(zip(measured, values))
        joints.update(zip(self._passive, solved))
        sample = LoopSample(
            stamp_ns, self._passive, solved, solved_rates, joints, dict(zip(measured, estimates)),
            {constraint: joints[known] for constraint, known in self._known})
        output_efforts = self.output_efforts
        if efforts and output_efforts is not None:
            taken_efforts = self._intake.efforts(efforts, output_efforts.actuators)
            if taken_efforts is not None:
                try:
                    sample.efforts = output_efforts.efforts(values, solved,
                                                            self.solver.groups, taken_efforts)
                except TransmissionSingular as singular:
                    sample.withheld = singular.group
        return sample


def dead_point_distances(plan: LoopPlan,
                         known_values: Mapping[str, float]) -> dict[str, float | None]:
    """Return each loop's distance (rad or m) from its known joint to its nearest dead point."""
    return {
        planned.loop.constraint: known_joint_range(
            planned.loop.planar, planned.known.index).dead_point_distance(
                planned.known.sign * known_values[planned.loop.constraint])
        for planned in plan.loops if planned.loop.constraint in known_values}
