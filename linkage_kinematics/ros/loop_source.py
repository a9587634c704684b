# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The measured source of ``loops:=robot_description``: every loop of a lab's URDF, closed on ROS.

``RobotLoopsSubscription`` is a ``source.Source``: it reads the robot description (the parameter
``robot_description``, or the relative ``robot_description`` topic as robot_state_publisher
publishes it) with its closure file (the parameter ``robot_description_closures``, for every
description), feeds each ``measured_joint_states`` message (``measured_input.MeasuredInput``)
to a ``loops.follower`` ``RobotLoopsFollower`` and publishes the passive joints it solves on
``joint_states``, stamped as the input. With ``loops.output_joints`` it reads the input's
efforts too, and a message whose actuators carry them gives every published joint its effort
(``loops.robot_transmission``); output joints that cannot be the groups' stop the node at start
(a description from the parameter) or make the status ERROR (one from the topic, or one planned
at the first message), as a description whose loops cannot be closed does. The node publishes
no URDF, ``linkage/state`` or markers of its own then: those describe its own four-bar. Its bag
holds the input, the completed joint states, the description and its closure file, and the /tf
robot_state_publisher would publish for the whole robot.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from dataclasses import replace
import math
from typing import Any, Protocol

from linkage_kinematics.loops.assembly import ClosureGap
from linkage_kinematics.loops.closures import ClosureError, Encoding
from linkage_kinematics.loops.description import LoopError
from linkage_kinematics.loops.follower import LoopDrop, RobotLoopsFollower
from linkage_kinematics.loops.intake import DropReason
from linkage_kinematics.loops.plan import GroupPlan, read_loops
from linkage_kinematics.loops.solver import GroupStep
from linkage_kinematics.loops.transmission import TransmissionError
from linkage_kinematics.model.urdf_reader import read_urdf, UrdfError
from linkage_kinematics.ros.measured_input import MeasuredInput
from linkage_kinematics.ros.messages import RobotStateTransforms
from linkage_kinematics.ros.outputs import (
    NodeOutputs,
    ROBOT_DESCRIPTION_QOS,
    ROBOT_DESCRIPTION_TOPIC,
)
from linkage_kinematics.ros.process import StartupError
from linkage_kinematics.ros.source import SourceHost
from linkage_kinematics.run.configuration import RunConfiguration
from linkage_kinematics.run.control import ServiceAnswer
from linkage_kinematics.run.diagnostics import RateMeter, Status, StatusInputs, StatusSchedule
from linkage_kinematics.run.loop_diagnostics import loop_statuses, LoopsHealth, LoopsView
from linkage_kinematics.run.parameter_values import ConfigurationError
from std_msgs.msg import String


class LoopsHost(SourceHost, Protocol):
    """What this source asks of the node beyond ``SourceHost``: its logger."""

    def get_logger(self) -> Any:
        """Return the node's logger."""


# What reading a description may refuse, each with its one line.
DESCRIPTION_ERRORS = (LoopError, UrdfError, ClosureError)
OUTPUT_JOINTS = 'loops.output_joints'


def output_joints_problem(error: TransmissionError) -> str:
    """Return the line of output joints that cannot be the description's groups'."""
    return f'{OUTPUT_JOINTS}: {error}'


class ClosedRobot:
    """A robot description whose loops close: its follower and robot_state_publisher's TF."""

    def __init__(self, urdf: str, config: RunConfiguration) -> None:
        """
        Read ``urdf`` and the configured closure file, if any.

        LoopError, UrdfError or ClosureError, one line naming the problem, if they cannot be
        closed; TransmissionError if the measured joints are known and the output joints
        cannot be the groups'.
        """
        tree = read_urdf(urdf)  # once, for the loops and for robot_state_publisher's TF
        self.urdf = urdf
        self.closures = config.loops.robot_description_closures
        self.follower = RobotLoopsFollower(
            read_loops(tree, self.closures or None), config.loops.measured_joints,
            dict(config.loops.branches), config.measured.max_jump,
            dict(config.loops.assemblies), config.loops.output_joints)
        self.transforms = RobotStateTransforms(tree, config.outputs.frame_prefix)
        # robot_state_publisher's /tf is of every movable joint; mimic joints follow theirs.
        self.tree_joints = self.transforms.driven_joints


def _gaps(gaps: Sequence[ClosureGap]) -> str:
    """Return closures' gaps for people: per closure, metres and (if it has one) radians."""
    return ', '.join(f'{gap.closure} {gap.position:.3g} m'
                     + ('' if gap.angle is None else f' and {gap.angle:.3g} rad')
                     for gap in gaps)


def group_plan_line(group: GroupPlan) -> str:
    """Return the log line of a planned group: how it is solved and how open its zero pose is."""
    structure = group.zero.structure
    return (f'group {group.name}: {structure.dof} degrees of freedom '
            f'({len(structure.idle)} idle), known {", ".join(group.known)}, solving '
            f'{", ".join(group.solved)} by {group.kind.value}; the zero pose is open by '
            f'{_gaps(group.zero.assembly.start_gaps)}; it is assembled at the first sample, '
            'nearest its zero-pose assembly (loops.assemblies picks another)')


def assembly_line(step: GroupStep) -> str:
    """Return the log line of a group's assembly at a motion's first sample."""
    values = dict(zip(step.tree.names, step.assembly.values))
    return (f'group {step.plan.name}: assembled at the first sample '
            f'({", ".join(f"{name} = {values[name]:.6g}" for name in step.plan.known)}): '
            f'{", ".join(f"{name} = {values[name]:.6g}" for name in step.plan.solved)}, '
            f'orientation {step.solver.orientation:+d} (the sign of det A), closed to '
            f'{_gaps(step.assembly.gaps)}')


class TreePositions:
    """
    The positions of a robot's tree joints (``driven_joints``, in order) for its /tf.

    The loops' joints as the last sample closed them, every other joint as the input last gave
    it (0 before that). Kept from message to message: what is fixed for a names list and for a
    plan is found once, and a sample sets only the joints that moved.
    """

    def __init__(self, tree_joints: Sequence[str], loop_joints: Collection[str],
                 heard: dict[str, float]) -> None:
        """``heard``: the input's last finite value of each joint outside the loops, kept."""
        self._slots = {name: slot for slot, name in enumerate(tree_joints)}
        self._loop_joints = loop_joints
        self._heard = heard
        self.positions = [heard.get(name, 0.0) for name in tree_joints]
        self._from_loops: tuple[tuple[int, str], ...] | None = None  # slot, joint
        self._names: Sequence[str] | None = None
        self._others: tuple[tuple[int, str, int | None], ...] = ()  # index, name, slot

    def note_input(self, names: Sequence[str], positions: Sequence[float]) -> None:
        """Keep the input's finite value of each joint outside the loops."""
        if names is not self._names:  # a source sends the same names message after message
            slots, loop_joints = self._slots, self._loop_joints
            self._others = tuple((index, name, slots.get(name))
                                 for index, name in enumerate(names) if name not in loop_joints)
            self._names = names
        count = len(positions)
        heard, tree_positions, isfinite = self._heard, self.positions, math.isfinite
        for index, name, slot in self._others:
            if index < count and isfinite(position := positions[index]):
                heard[name] = position
                if slot is not None:
                    tree_positions[slot] = position

    def at_sample(self, joints: Mapping[str, float]) -> list[float]:
        """
        Return the positions with a sample's measured and solved ``joints`` set.

        Their names are the same at every sample of a plan.
        """
        if self._from_loops is None:
            self._from_loops = tuple((slot, name) for name, slot in self._slots.items()
                                     if name in joints)
        tree_positions = self.positions
        for slot, name in self._from_loops:
            tree_positions[slot] = joints[name]
        return tree_positions


def robot_from_parameter(config: RunConfiguration) -> ClosedRobot | None:
    """
    Return the robot of the ``robot_description`` parameter, None when it is empty (the topic).

    Raises StartupError, one line naming the problem, for a description that cannot be closed,
    and ConfigurationError of ``loops.output_joints`` for output joints that cannot be its
    groups'.
    """
    if not config.loops.robot_description:
        return None
    try:
        return ClosedRobot(config.loops.robot_description, config)
    except DESCRIPTION_ERRORS as error:
        raise StartupError('cannot close the loops of parameter robot_description: '
                           + str(error).replace('\n', '; ')) from None
    except TransmissionError as error:
        raise ConfigurationError(OUTPUT_JOINTS, str(error)) from None


class RobotLoopsSubscription(MeasuredInput):
    """
    The source of ``loops:=robot_description``: descriptions and measured joints in.

    The input's bytes are also logged as received (``record_input``).
    """

    health = None  # no four-bar: its statuses are this source's own (``statuses``)
    paused_answer = 'paused: the measured joints are ignored'
    resumed_answer = 'following the measured joints again from their next sample'

    def __init__(self, host: LoopsHost, outputs: NodeOutputs, robot: ClosedRobot | None) -> None:
        self._outputs = outputs
        self._robot: ClosedRobot | None = None
        self._loops_health = LoopsHealth(host.now_ns())
        self._rate_meter = RateMeter()
        self._schedule = StatusSchedule()
        self._problem: str | None = None
        self._input_positions: dict[str, float] = {}  # joints outside the loops, as last heard
        self._tree: TreePositions | None = None  # the robot's /tf positions
        self._following = False  # a message of this motion followed since the last start
        self._description_from = ('parameter robot_description' if robot is not None
                                  else f'topic {outputs.description_topic}')
        if robot is None:  # subscribed before the input, as the node always was
            host.create_subscription(String, ROBOT_DESCRIPTION_TOPIC, self._on_description,
                                     ROBOT_DESCRIPTION_QOS)
        # the input's efforts are read only where output joints give them a use
        super().__init__(host, self._loops_health, bool(host.config.loops.output_joints))
        if robot is not None:
            self._take(robot)
        self._show_activity()

    def start(self) -> None:
        """Publish the first status (the description's, and what the node waits for)."""
        self._host.publish_diagnostics()

    def _show_activity(self) -> None:
        host, robot = self._host, self._robot
        if host.control.paused:
            activity = 'paused: the measured joints are not followed until ~/resume'
        elif robot is None:
            activity = f'waiting for the robot description on {self._description_from}'
        elif robot.follower.plan is None or not self._following:
            joints = ('the loop joints' if robot.follower.plan is None
                      else ', '.join(robot.follower.plan.measured))
            activity = f'waiting for {joints} on {self._outputs.input_topic}'
        else:
            activity = 'following ' + ', '.join(robot.follower.plan.measured)
        host.set_activity(activity)

    def _take(self, robot: ClosedRobot) -> None:
        """Follow ``robot`` from now on, and log it with its /tf_static."""
        self._robot = robot
        self._problem = None
        self._tree = TreePositions(robot.tree_joints, robot.follower.loop_joints,
                                   self._input_positions)
        self._following = False
        self._outputs.record_robot(robot.urdf, robot.closures, robot.transforms,
                                   self._host.now_ns())
        loops = robot.follower.loops
        # by encoding, as each names its closures: constraints a, b; closures (closure file) c
        written: dict[Encoding, list[str]] = {}
        for closure in loops.closures:
            written.setdefault(closure.encoding, []).append(closure.name)
        self._host.get_logger().info(
            f'closing the loops of robot {loops.robot_name!r}: ' + '; '.join(
                f'{encoding.word}s ' + ('(closure file) ' if encoding is Encoding.CLOSURE_FILE
                                        else '') + ', '.join(names)
                for encoding, names in written.items()))
        if robot.follower.plan is not None:
            self._planned()

    def _planned(self) -> None:
        """Say which joints the loops are closed from, how, and what to be warned of."""
        plan = self._robot.follower.plan
        logger = self._host.get_logger()
        logger.info(f"measured joints {', '.join(plan.measured)}; publishing "
                    + ', '.join(plan.passive))
        for group in plan.general:
            logger.info(group_plan_line(group))
        # zero poses not assembled, passive joints that mimic, joints the closure file overrides
        for warning in plan.warnings:
            logger.warning(warning)

    def _assembled(self) -> None:
        """Say which assembly each group of the general closure took at the first sample."""
        logger = self._host.get_logger()
        for step in self._robot.follower.solver.groups:
            logger.info(assembly_line(step))

    def _report(self, problem: str) -> None:
        """Make the status ERROR with ``problem``: logged and reported at once, when it is new."""
        if problem == self._problem:
            return  # e.g. every message that cannot be planned: once, not at the input's rate
        self._problem = problem
        self._host.get_logger().error(problem)
        self._host.publish_diagnostics()

    def _on_description(self, message: String) -> None:
        """Read a description afresh; one that cannot be closed leaves the last one followed."""
        try:
            robot = ClosedRobot(message.data, self._host.config)
        except (*DESCRIPTION_ERRORS, TransmissionError) as error:
            problem = (output_joints_problem(error) if isinstance(error, TransmissionError)
                       else str(error).replace('\n', '; '))
            self._report(f'cannot close the loops of the robot description on '
                         f'{self._outputs.description_topic}: {problem}')
            return
        self._take(robot)
        self._show_activity()
        self._host.publish_diagnostics()

    def statuses(self, inputs: StatusInputs) -> tuple[Status, ...]:
        """Return the node's status and one per loop (``loop_diagnostics``)."""
        robot = self._robot
        self._rate_meter.update(inputs.now_ns)
        return loop_statuses(
            replace(inputs, problem=inputs.problem or self._problem,
                    achieved_rate=self._rate_meter.rate),
            LoopsView(robot_name=None if robot is None else robot.follower.loops.robot_name,
                      description_from=self._description_from,
                      plan=None if robot is None else robot.follower.plan,
                      health=self._loops_health,
                      groups=(() if robot is None or robot.follower.solver is None
                              else robot.follower.solver.groups),
                      transmissions=None if robot is None else robot.follower.output_efforts))

    def reconfigure(self, new: RunConfiguration) -> None:
        """Take the node's new configuration: the thresholds (timeout, jump)."""
        if self._robot is not None:
            self._robot.follower.max_jump = new.measured.max_jump
        self._retime(new)

    def restart(self) -> None:
        """Forget the motion: the next valid message starts it afresh on the planned branches."""
        self._following = False
        if self._robot is not None:
            self._robot.follower.restart()

    def _forget_motion(self) -> None:
        self.restart()

    def reset(self) -> ServiceAnswer:
        """Start the motion afresh at the next valid message; the status says so at once."""
        answer = super().reset()
        self._show_activity()
        self._host.publish_diagnostics()  # as ~/pause and ~/resume: the status says what now
        return answer

    def _on_message(self, data: bytes) -> None:
        host = self._host
        if host.control.paused:
            return  # ~/pause: not followed, not counted
        try:
            stamp_ns, names, positions, velocities, efforts = self._decoder.decode(data)
        except ValueError:  # not logged: it has no stamp, and readers would refuse it
            self._loops_health.drop(DropReason.MALFORMED)
            return
        robot = self._robot
        if robot is None:
            self._outputs.record_input(data, stamp_ns)
            self._loops_health.drop(DropReason.NO_DESCRIPTION)
            return
        follower = robot.follower
        planned = follower.plan is not None
        try:
            followed = follower.follow(stamp_ns, names, positions, velocities, efforts)
        except (LoopError, TransmissionError) as error:
            self._outputs.record_input(data, stamp_ns)
            self._loops_health.drop(DropReason.NOT_PLANNED)
            self._report('the measured joints cannot close the loops: ' + (
                output_joints_problem(error) if isinstance(error, TransmissionError)
                else str(error).replace('\n', '; ')))
            return
        if followed is None:
            return  # none of the measured joints: e.g. this node's own output, heard back
        self._outputs.record_input(data, stamp_ns)
        self._tree.note_input(names, positions)
        if not planned:
            self._problem = None
            self._planned()
        if isinstance(followed, LoopDrop):
            self._loops_health.drop(followed.reason, followed.constraints)
            return
        self._loops_health.accept(host.now_ns(), followed)
        self._rate_meter.tick()
        first = not self._following
        self._following, self.stale = True, False
        self._outputs.publish_joint_states(followed.names, followed.positions,
                                           followed.velocities, stamp_ns, followed.efforts)
        # The whole robot as robot_state_publisher would pose it.
        self._outputs.record_tf(self._tree.at_sample(followed.joints), stamp_ns)
        if first:
            self._show_activity()
            if self._robot.follower.solver.groups:
                self._assembled()
        if self._schedule.due(stamp_ns) or first:
            self._schedule.sent(stamp_ns)
            host.publish_diagnostics(at_ns=stamp_ns)
