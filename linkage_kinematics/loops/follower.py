# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The measured source of ``loops:=robot_description``: a robot's loops closed message by message.

``RobotLoopsFollower.follow`` takes the fields of one ``sensor_msgs/JointState`` (stamp, names,
positions, velocities), picks the measured joints by name and closes every ``<constraint>``
loop of the robot's URDF from them (``plan.RobotLoops.plan``, ``solver.LoopSolver``). It
returns a ``LoopSample``, the passive loop joints' positions and velocities (URDF units, rad or
m), or a ``LoopDrop``, why the message was dropped and which loops it concerned. A measured
joint without a velocity gets the measured mode's estimate (``intake.joint_velocity``: the
backward difference over the header stamps, 0 for a first sample). A revolute measured joint
is unwrapped across turns, as the measured mode's driver is, and ``measured.max_jump`` (rad)
applies to it; a prismatic one's length (m) has no such bound. No ROS.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from enum import StrEnum
import math

from linkage_kinematics.kinematics.geometry import TWO_PI
from linkage_kinematics.kinematics.planar_loop import JointKind, known_joint_range
from linkage_kinematics.loops.intake import Estimate, joint_velocity
from linkage_kinematics.loops.plan import LoopPlan, RobotLoops
from linkage_kinematics.loops.solver import LoopSampleError, LoopSolver


class LoopRejection(StrEnum):
    """Why an input message was dropped (the text names it in diagnostics)."""

    NO_DESCRIPTION = 'before the robot description was closed'
    NOT_PLANNED = 'while the measured joints cannot close the loops'
    NO_JOINT = 'without every measured joint'
    NON_FINITE = 'with a NaN or infinite position or velocity'
    STAMP_NOT_NEWER = 'with a stamp not newer than the last one used'
    UNREACHABLE = 'at joint values a loop cannot reach (or at a dead point)'
    JUMP = 'jumping further than measured.max_jump'
    MALFORMED = 'whose bytes are not a well-formed JointState'


@dataclass(frozen=True)
class LoopDrop:
    """A dropped message: why, the loops it concerned (none: every loop) and the detail."""

    reason: LoopRejection
    constraints: tuple[str, ...]
    detail: str


@dataclass
class LoopSample:
    """
    The passive loop joints at one message, in solve order, and what came with them.

    ``joints`` holds every measured and solved loop joint's position (for /tf);
    ``estimates`` how each measured joint's velocity was obtained; ``known_values`` each
    loop's known joint value (URDF units), by constraint. A value, not frozen: a frozen
    dataclass's seven ``object.__setattr__`` cost four times its plain ``__init__`` per sample.
    """

    stamp_ns: int
    names: tuple[str, ...]
    positions: tuple[float, ...]
    velocities: tuple[float, ...]
    joints: dict[str, float]
    estimates: dict[str, Estimate]
    known_values: dict[str, float]


class RobotLoopsFollower:
    """
    Follows the measured joints of one robot description; ``restart`` forgets the motion.

    Construction raises LoopError (one line per problem, naming the joints or constraints)
    when ``measured`` is given and cannot close the loops; with ``measured`` empty the loop
    joints the first message carries are planned then (``follow`` raises LoopError then).
    """

    def __init__(self, loops: RobotLoops, measured: Sequence[str],
                 branches: Mapping[str, int], max_jump: float) -> None:
        self.loops = loops
        self.max_jump = max_jump
        self._branches = dict(branches)
        self.loop_joints = frozenset(name for loop in loops.loops for name in loop.names)
        self.solver: LoopSolver | None = None
        if measured:
            self._plan(tuple(measured))
        self.restart()

    @property
    def plan(self) -> LoopPlan | None:
        """Return the loops in solve order, None until the measured joints are known."""
        return None if self.solver is None else self.solver.plan

    def _plan(self, measured: tuple[str, ...]) -> None:
        plan = self.loops.plan(measured, self._branches)
        self.solver = LoopSolver(plan)
        # resolved once per plan rather than per message: the revolute measured joints (in
        # measured order), each loop's constraint and known joint, the loops each feeds
        revolute = {planned.known.name for planned in plan.loops
                    if planned.measured and planned.known.kind is JointKind.REVOLUTE}
        self._revolute = tuple(name for name in plan.measured if name in revolute)
        self._known = tuple((planned.loop.constraint, planned.known.name)
                            for planned in plan.loops)
        self._feeds = {name: tuple(planned.loop.constraint for planned in plan.loops
                                   if planned.known.name == name) for name in measured}
        self._passive = plan.passive  # the solved joints' names, in the order solve gives them
        self._names: Sequence[str] | None = None  # the names _indices were found in

    def restart(self) -> None:
        """Forget the motion: the next valid message starts it again on the planned branches."""
        self._last_stamp_ns: int | None = None
        self._last: dict[str, float] = {}  # measured joint → its last value used, unwrapped
        if self.solver is not None:
            self.solver.reset()

    def _loops_of(self, names: Sequence[str]) -> tuple[str, ...]:
        """Return the loops whose known joint is one of the measured joints ``names``."""
        return tuple(constraint for name in names for constraint in self._feeds[name])

    def follow(self, stamp_ns: int, names: Sequence[str], positions: Sequence[float],
               velocities: Sequence[float]) -> LoopSample | LoopDrop | None:
        """
        Return the passive loop joints at one message, or why it was dropped.

        None for a message that carries none of the measured joints (with none given, none of
        the loop joints), e.g. this node's own output heard back: ignored, not counted.
        """
        if self.solver is None:
            carried = tuple(name for name in names if name in self.loop_joints)
            if not carried:
                return None
            self._plan(carried)
        measured = self.solver.plan.measured
        if names != self._names:
            # A source sends the same names message after message: found once, not per message.
            index = {name: i for i, name in enumerate(names)}
            self._names = names[:]
            self._indices = tuple(index.get(name) for name in measured)
            self._present = tuple(i for i in self._indices if i is not None)
        indices = self._indices
        if not self._present:
            return None
        if len(self._present) < len(measured) or max(self._present) >= len(positions):
            count = len(positions)
            missing = [name for name, i in zip(measured, indices) if i is None or i >= count]
            return LoopDrop(LoopRejection.NO_JOINT, self._loops_of(missing),
                            f'no position of {missing}')
        count = len(velocities)
        values, given, finite = {}, [], True
        isfinite = math.isfinite
        for name, i in zip(measured, indices):
            value = values[name] = positions[i]
            rate = velocities[i] if i < count else None
            given.append(rate)
            if not isfinite(value) or (rate is not None and not isfinite(rate)):
                finite = False
        if not finite:
            bad = [name for name, rate in zip(measured, given)
                   if not isfinite(values[name]) or not isfinite(0.0 if rate is None else rate)]
            return LoopDrop(LoopRejection.NON_FINITE, self._loops_of(bad),
                            f'{bad} not finite')
        last_stamp_ns = self._last_stamp_ns
        if last_stamp_ns is not None and stamp_ns <= last_stamp_ns:
            return LoopDrop(LoopRejection.STAMP_NOT_NEWER, (), 'stamp not newer')
        last_values = self._last
        if last_values:
            jumps = []
            for name in self._revolute:
                # An encoder that wraps (at ±π, or anywhere) is unwrapped: whole turns are
                # counted.
                last = last_values[name]
                value = values[name] = (values[name]
                                        + round((last - values[name]) / TWO_PI) * TWO_PI)
                if abs(value - last) > self.max_jump:
                    jumps.append(name)
            if jumps:
                return LoopDrop(LoopRejection.JUMP, self._loops_of(jumps), f'{jumps} jumped')
        rates, estimates = {}, {}
        for name, rate in zip(measured, given):
            last = None if not last_values else (last_stamp_ns, last_values[name])
            rates[name], estimates[name] = joint_velocity(stamp_ns, values[name], rate, last)
        try:
            solved, solved_rates = self.solver.solve(values, rates)
        except LoopSampleError as error:
            return LoopDrop(LoopRejection.UNREACHABLE,
                            () if error.constraint is None else (error.constraint,), str(error))
        self._last_stamp_ns, self._last = stamp_ns, values
        joints = {**values, **solved}
        return LoopSample(
            stamp_ns, self._passive, tuple(solved.values()), tuple(solved_rates.values()),
            joints, estimates,
            {constraint: joints[known] for constraint, known in self._known})


def dead_point_distances(plan: LoopPlan,
                         known_values: Mapping[str, float]) -> dict[str, float | None]:
    """Return each loop's distance (rad or m) from its known joint to its nearest dead point."""
    return {
        planned.loop.constraint: known_joint_range(
            planned.loop.planar, planned.known.index).dead_point_distance(
                planned.known.sign * known_values[planned.loop.constraint])
        for planned in plan.loops if planned.loop.constraint in known_values}
