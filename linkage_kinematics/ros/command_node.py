# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
``linkage_command_node``: commands written in a robot's output joints, relayed to its actuators.

A planner, MoveIt or a whole-body controller writes in the serial joints of the URDF (ankle
pitch and roll, a knee, a boom angle); the robot's ros2_control controllers drive its motors
and cylinders. This node sits between them, as a joint_trajectory_controller and a
forward_command_controller would for a serial robot: it subscribes to ``~/joint_trajectory``
(``trajectory_msgs/JointTrajectory``) and ``~/commands`` (``std_msgs/Float64MultiArray``) and
publishes each message converted (``run.relay``) on ``actuators/joint_trajectory`` and
``actuators/commands``, to be remapped to the actuators' controllers. It reads the robot
description and closure file as ``linkage_node`` does (parameter, or the latched topic), and
the same ``loops.*`` parameters; velocity and effort commands are converted at the pose the
loops node's follower closes from ``measured_joint_states``. Messages go in and out as CDR
bytes (``shared.command_cdr``); a refused message is logged (``run.relay_diagnostics``: at most
a line a second per input), counted in ``/diagnostics`` and not relayed; the node keeps
running. Its bag holds every message received and published. docs/following_loops.md ("The
command direction") and docs/parameters.md ("linkage_command_node") document it.
"""

from __future__ import annotations

import sys
import time
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray
from linkage_kinematics.bag.recorder import Topic
from linkage_kinematics.loops.command import CommandRefused, JointPoint
from linkage_kinematics.ros import messages
from linkage_kinematics.ros.exit_codes import ExitCode
from linkage_kinematics.ros.node_log import NodeLog
from linkage_kinematics.ros.outputs import (
    CLOSURES_TOPIC,
    DATA_QOS,
    MEASURED_QOS,
    MEASURED_TOPIC,
    ROBOT_DESCRIPTION_QOS,
    ROBOT_DESCRIPTION_TOPIC,
)
from linkage_kinematics.ros.parameters import (
    add_ranges,
    declare_relay_parameters,
    keep_declared_types,
    parameter_values,
)
from linkage_kinematics.ros.process import run_node, StartupError
from linkage_kinematics.run.configuration import build_relay_configuration
from linkage_kinematics.run.parameter_specs import (
    CommandInterface,
    RELAY_NODE_NAME,
    RELAY_SPECS,
    unknown_parameters,
)
from linkage_kinematics.run.placement import CpuPlacement
from linkage_kinematics.run.relay import (
    MessageKind,
    read_relay,
    Relay,
    RELAY_ERRORS,
    RelayRefusal,
    RelayRefused,
)
from linkage_kinematics.run.relay_diagnostics import relay_status, RelayRecord, RelayView
from linkage_kinematics.shared.cdr import encode_cdr, FixedShapeEncoder, JointStateDecoder
from linkage_kinematics.shared.command_cdr import (
    decode_float64_array,
    decode_joint_trajectory,
    encode_joint_trajectory,
    TrajectoryPoint,
)
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray, String
from trajectory_msgs.msg import JointTrajectory

TRAJECTORY_INPUT = '~/joint_trajectory'  # joint_trajectory_controller's
COMMANDS_INPUT = '~/commands'  # forward_command_controller's
TRAJECTORY_OUTPUT = 'actuators/joint_trajectory'
COMMANDS_OUTPUT = 'actuators/commands'
# The controllers subscribe with rclcpp::SystemDefaultsQoS(), which Fast DDS makes a best-effort,
# volatile reader: every publisher that reaches a controller reaches the relay. Deeper than its
# default (keep last 1), so that a burst waiting for one slow callback is not lost.
COMMAND_INPUT_QOS = QoSProfile(depth=100, reliability=ReliabilityPolicy.BEST_EFFORT,
                               durability=DurabilityPolicy.VOLATILE)
# Reliable and volatile: the controllers' best-effort readers and any reliable one match.
COMMAND_OUTPUT_QOS = QoSProfile(depth=10)
DIAGNOSTICS_PERIOD = 1.0  # s
REFUSAL_STATUS_NS = 100_000_000  # a refusal's status at once, at most this often


def _logged_topics(node: CommandNode) -> list[Topic]:
    """Return every topic ``node`` reads or writes (what its bag holds)."""
    topics = node.topics
    return [
        (topics['trajectory in'], JointTrajectory, COMMAND_INPUT_QOS, None),
        (topics['commands in'], Float64MultiArray, COMMAND_INPUT_QOS, None),
        *([(topics['measured'], JointState, MEASURED_QOS, None)] if node.measures_pose
          else []),
        (topics['trajectory out'], JointTrajectory, COMMAND_OUTPUT_QOS, None),
        (topics['commands out'], Float64MultiArray, COMMAND_OUTPUT_QOS, None),
        # the latest status starts every file of a split bag
        (topics['diagnostics'], DiagnosticArray, DATA_QOS, True),
        (topics['description'], String, ROBOT_DESCRIPTION_QOS, None),
        *([(topics['closures'], String, ROBOT_DESCRIPTION_QOS, None)]
          if node.config.loops.robot_description_closures else []),
    ]


class CommandNode(Node):
    """
    The command relay (module docstring; docs/following_loops.md, "The command direction").

    Construction raises ConfigurationError for bad parameters and StartupError for a description
    given as a parameter that cannot be relayed (or a log that cannot be written), before
    anything is published.
    """

    exit_code: ExitCode | None = None  # process.ProcessNode: only SIGINT or SIGTERM ends a relay

    def __init__(self, **node_options: Any) -> None:
        super().__init__(RELAY_NODE_NAME, **node_options)
        specs = declare_relay_parameters(self)
        for warning in unknown_parameters(self._parameter_overrides,
                                          self.list_parameters([], 0).names,
                                          RELAY_NODE_NAME, RELAY_SPECS):
            self.get_logger().warning(warning)
        self.config = config = build_relay_configuration(self.parameter_values())
        add_ranges(self, specs)
        self.add_pre_set_parameters_callback(keep_declared_types)  # all are read-only
        self._placement = CpuPlacement()
        change = self._placement.place(config.logging.cpu_affinity)
        if change is not None:
            self.get_logger().info(change)
        relay = None
        if config.loops.robot_description:
            try:
                relay = read_relay(config.loops.robot_description, config)
            except RELAY_ERRORS as error:
                raise StartupError('cannot relay commands to the actuators of parameter '
                                   'robot_description: '
                                   + str(error).replace('\n', '; ')) from None
        self._relay: Relay | None = None
        self._record = RelayRecord()
        self._problem: str | None = None
        self._status_ns = 0
        self.measures_pose = config.commands.interface is not CommandInterface.POSITION
        self._joint_states = JointStateDecoder()
        self._array_encoder: FixedShapeEncoder | None = None
        resolve = self.resolve_topic_name
        self.topics = {
            'trajectory in': resolve(TRAJECTORY_INPUT), 'commands in': resolve(COMMANDS_INPUT),
            'trajectory out': resolve(TRAJECTORY_OUTPUT),
            'commands out': resolve(COMMANDS_OUTPUT), 'measured': resolve(MEASURED_TOPIC),
            'description': resolve(ROBOT_DESCRIPTION_TOPIC),
            'closures': resolve(CLOSURES_TOPIC), 'diagnostics': resolve('/diagnostics')}
        self._description_from = ('parameter robot_description' if relay is not None
                                  else f'topic {self.topics["description"]}')
        self._trajectory_out = self.create_publisher(JointTrajectory, TRAJECTORY_OUTPUT,
                                                     COMMAND_OUTPUT_QOS)
        self._commands_out = self.create_publisher(Float64MultiArray, COMMANDS_OUTPUT,
                                                   COMMAND_OUTPUT_QOS)
        self._diagnostics = self.create_publisher(DiagnosticArray, '/diagnostics', DATA_QOS)
        self.log = NodeLog(self, config.logging, _logged_topics(self), self.parameter_values(),
                           self._placement.bag_writer_cpus)
        if relay is None:
            self.create_subscription(String, ROBOT_DESCRIPTION_TOPIC, self._on_description,
                                     ROBOT_DESCRIPTION_QOS)
        else:
            self._take(config.loops.robot_description, relay)
        self.create_subscription(JointTrajectory, TRAJECTORY_INPUT, self._on_trajectory,
                                 COMMAND_INPUT_QOS, raw=True)
        self.create_subscription(Float64MultiArray, COMMANDS_INPUT, self._on_commands,
                                 COMMAND_INPUT_QOS, raw=True)
        if self.measures_pose:
            self.create_subscription(JointState, MEASURED_TOPIC, self._on_measured,
                                     MEASURED_QOS, raw=True)
        self.get_logger().info(
            f'relaying {self.topics["trajectory in"]} to {self.topics["trajectory out"]} and '
            f'{self.topics["commands in"]} ({config.commands.interface.value} of '
            f'{", ".join(config.commands.joints)}) to {self.topics["commands out"]}'
            + (f', at the pose measured on {self.topics["measured"]}' if self.measures_pose
               else ''))
        self.create_timer(DIAGNOSTICS_PERIOD, self.publish_diagnostics)
        self.publish_diagnostics()

    def parameter_values(self) -> dict[str, Any]:
        """Return the current values of the relay's parameters (name → value)."""
        return parameter_values(self, tuple(RELAY_SPECS))

    def now_ns(self) -> int:
        """Return the node clock's time (ns)."""
        return self.get_clock().now().nanoseconds

    # the log

    def close_log(self) -> bool:
        """Finalize the bag (idempotent); False, with an error logged, if that failed."""
        return self.log.close()

    def flush(self, timeout: float = 1.0) -> None:
        """Give subscribers up to ``timeout`` s in all to acknowledge what was published."""
        deadline = time.monotonic() + timeout
        for publisher in (self._trajectory_out, self._commands_out, self._diagnostics):
            publisher.wait_for_all_acked(Duration(seconds=max(deadline - time.monotonic(), 0.0)))

    # the description

    def _take(self, urdf: str, relay: Relay) -> None:
        """Relay to ``relay``'s actuators from now on; log its description and closure file."""
        self._relay = relay
        self._problem = None
        self._array_encoder = FixedShapeEncoder(
            Float64MultiArray(data=[0.0] * len(relay.controller_joints)), ['data'])
        now = self.now_ns()
        self.log.record(self.topics['description'], encode_cdr(String(data=urdf)), now)
        closures = self.config.loops.robot_description_closures
        if closures:
            self.log.record(self.topics['closures'], encode_cdr(String(data=closures)), now)
        logger = self.get_logger()
        logger.info(f'relaying commands in the output joints of robot {relay.robot_name!r} to '
                    f'its actuators {", ".join(relay.controller_joints)}')
        for group in relay.groups:
            logger.info(group.describe())

    def _on_description(self, message: String) -> None:
        """Read a description afresh; one that cannot be relayed leaves the last one relayed."""
        try:
            relay = read_relay(message.data, self.config)
        except RELAY_ERRORS as error:
            self._problem = (f'cannot relay commands to the actuators of the robot description '
                             f'on {self.topics["description"]}: '
                             + str(error).replace('\n', '; '))
            self.get_logger().error(self._problem)
            self.publish_diagnostics()
            return
        self._take(message.data, relay)
        self._description_from = f'topic {self.topics["description"]}'
        self.publish_diagnostics()

    # the inputs

    def _refuse(self, kind: MessageKind, refusal: CommandRefused | RelayRefused,
                now_ns: int) -> None:
        """Count, log (at most a line a second per input) and report a refused message."""
        line = self._record.refuse(kind, refusal.reason, str(refusal), now_ns)
        if line is not None:
            self.get_logger().warning(line)
        if now_ns - self._status_ns >= REFUSAL_STATUS_NS:
            self.publish_diagnostics()

    def _take_input(self, kind: MessageKind, topic: str, data: bytes,
                    now: int) -> Relay | None:
        """Log an input; return the relay, or None with the input refused before a description."""
        self.log.record(self.topics[topic], data, now)
        if self._relay is None:
            self._refuse(kind, RelayRefused(
                RelayRefusal.NO_DESCRIPTION, f'waiting on {self._description_from}'), now)
        return self._relay

    def _on_commands(self, data: bytes) -> None:
        now = self.now_ns()
        relay = self._take_input(MessageKind.COMMANDS, 'commands in', data, now)
        if relay is None:
            return
        started = time.perf_counter_ns()
        try:
            values = decode_float64_array(data)
        except ValueError as error:
            self._refuse(MessageKind.COMMANDS, RelayRefused(RelayRefusal.MALFORMED, str(error)),
                         now)
            return
        try:
            converted = relay.forward(values, now)
        except (CommandRefused, RelayRefused) as refusal:
            self._refuse(MessageKind.COMMANDS, refusal, now)
            return
        out = self._array_encoder.encode(converted)
        self._record.relay(MessageKind.COMMANDS, 1, time.perf_counter_ns() - started)
        self._commands_out.publish(out)
        self.log.record(self.topics['commands out'], out, now)

    def _on_trajectory(self, data: bytes) -> None:
        now = self.now_ns()
        relay = self._take_input(MessageKind.TRAJECTORY, 'trajectory in', data, now)
        if relay is None:
            return
        started = time.perf_counter_ns()
        try:
            message = decode_joint_trajectory(data)
        except ValueError as error:
            self._refuse(MessageKind.TRAJECTORY,
                         RelayRefused(RelayRefusal.MALFORMED, str(error)), now)
            return
        given = message.points
        try:
            names, points = relay.trajectory(message.joint_names, [
                JointPoint(point.positions, point.velocities, point.accelerations,
                           point.efforts) for point in given])
        except CommandRefused as refusal:
            self._refuse(MessageKind.TRAJECTORY, refusal, now)
            return
        out = encode_joint_trajectory(
            message.sec, message.nanosec, message.frame_id, names,
            [TrajectoryPoint(point.positions, point.velocities, point.accelerations,
                             point.efforts, before.sec, before.nanosec)
             for point, before in zip(points, given)])
        self._record.relay(MessageKind.TRAJECTORY, len(points), time.perf_counter_ns() - started)
        self._trajectory_out.publish(out)
        self.log.record(self.topics['trajectory out'], out, now)

    def _on_measured(self, data: bytes) -> None:
        now = self.now_ns()
        self.log.record(self.topics['measured'], data, now)
        relay = self._relay
        if relay is None or relay.pose is None:
            return
        try:
            stamp_ns, names, positions, velocities, _ = self._joint_states.decode(data)
        except ValueError:
            return  # not a pose: velocity and effort commands wait for one (measured.timeout)
        relay.pose.take(stamp_ns, names, positions, velocities, now)

    # diagnostics

    def publish_diagnostics(self) -> None:
        """Publish (and log) the relay's status now."""
        now = self.now_ns()
        self._status_ns = now
        relay, recorder = self._relay, self.log.recorder
        config = self.config
        status = relay_status(self._record, RelayView(
            robot_name=None if relay is None else relay.robot_name,
            description_from=self._description_from,
            groups=() if relay is None else relay.groups,
            interface=config.commands.interface.value,
            joints=config.commands.joints,
            controller_joints=() if relay is None else relay.controller_joints,
            inputs=(self.topics['trajectory in'], self.topics['commands in']),
            outputs=(self.topics['trajectory out'], self.topics['commands out']),
            pose_age=(None if relay is None or relay.pose is None
                      else relay.pose.age(now)),
            measures_pose=self.measures_pose,
            problem=self._problem or self.log.error,
            log_file=None if recorder is None else str(recorder.bag_path),
            log_size=None if recorder is None else recorder.size_bytes))
        data = messages.statuses_message(now, self.get_name(), (status,))
        self._diagnostics.publish(data)
        self.log.record(self._diagnostics.topic_name, data, now)


# --- process ------------------------------------------------------------------------------


def main(args: list[str] | None = None) -> int:
    """Run the relay until SIGINT or SIGTERM; return the exit status (2: it could not start)."""
    return run_node(RELAY_NODE_NAME, CommandNode, args)


if __name__ == '__main__':
    sys.exit(main())
