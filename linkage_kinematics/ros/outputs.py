# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The node's outputs: its publishers and its log, one place that publishes and records.

Every message is encoded once (``encode_cdr``, or for the per-state messages, the scene and the
diagnostics an encoder that writes the same bytes straight from the state or the texts),
published, and the very same bytes logged at the message's stamp, so subscribers receive exactly
what the bag holds.
"""

from __future__ import annotations

from collections.abc import Sequence
import time
from typing import Any, NamedTuple

from diagnostic_msgs.msg import DiagnosticArray
from linkage_kinematics.bag.recorder import Topic
from linkage_kinematics.kinematics.geometry import FourBar
from linkage_kinematics.kinematics.solver import LinkageState
from linkage_kinematics.model.joints import JointMap, JointStream, TreeValues
from linkage_kinematics.model.urdf import node_description
from linkage_kinematics.ros import messages
from linkage_kinematics.ros.node_log import NodeLog
from linkage_kinematics.run.configuration import LoopsSource, RunConfiguration, SourceKind
from linkage_kinematics.run.diagnostics import Status
from linkage_kinematics.shared.cdr import encode_cdr
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from trajectory_msgs.msg import JointTrajectory
from visualization_msgs.msg import MarkerArray

DATA_QOS = QoSProfile(depth=10)
# TF is logged, never published (see docs/logging.md), with tf2_ros's broadcaster QoS: the
# static one keeps the last message for late subscribers, as robot_state_publisher's does.
TF_TOPIC = '/tf'
TF_STATIC_TOPIC = '/tf_static'
TF_QOS = QoSProfile(depth=100)
TF_STATIC_QOS = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)
# robot_state_publisher's convention: late joiners get the latest description.
ROBOT_DESCRIPTION_QOS = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)
# The measured input: deep enough that a burst of encoder samples waiting for one slow callback
# is never lost.
MEASURED_QOS = QoSProfile(depth=100)
MEASURED_TOPIC = 'measured_joint_states'
ROBOT_DESCRIPTION_TOPIC = 'robot_description'
# The closure file's text, logged beside the description (latched as it is), never published:
# the parameter robot_description_closures holds it.
CLOSURES_TOPIC = 'robot_description_closures'


class Publishers(NamedTuple):
    """The node's publishers by what they carry, in the order they are made and recorded."""

    joint_states: Publisher
    # None with loops robot_description: they describe the node's own four-bar
    state: Publisher | None
    markers: Publisher | None
    diagnostics: Publisher
    # None with publish_robot_description false, and with loops robot_description
    robot_description: Publisher | None

    def present(self) -> tuple[Publisher, ...]:
        """Return the publishers the node has, in order."""
        return tuple(publisher for publisher in self if publisher is not None)


def _loops_topics(outputs: NodeOutputs, joint_states: str) -> list[tuple]:
    """Return what loops robot_description logs beyond what it publishes: description, input."""
    topics = [(outputs.description_topic, String, ROBOT_DESCRIPTION_QOS, None)]
    if outputs.config.loops.robot_description_closures:
        topics.append((outputs.closures_topic, String, ROBOT_DESCRIPTION_QOS, None))
    # Heard on the topic the node publishes to, the input goes to that topic's record.
    if outputs.input_topic != joint_states:
        topics.append((outputs.input_topic, JointState, MEASURED_QOS, None))
    return topics


class NodeOutputs:
    """
    The node's publishers, the encoders of its per-state messages, and its recorder.

    Relative names resolve under the node's namespace (as joint_state_publisher's and
    robot_state_publisher's do); /diagnostics is absolute, diagnostic_updater's convention.
    Construction raises as ``NodeLog`` does where the log cannot be opened, before anything is
    published.
    """

    def __init__(self, node: Node, config: RunConfiguration, parameter_values: dict[str, Any],
                 bag_writer_cpus: set[int] | None) -> None:
        self._node = node
        self._node_name = node.get_name()
        self.config = config
        four_bar = config.loops.source is LoopsSource.PARAMETERS
        self._publishers = Publishers(
            joint_states=node.create_publisher(JointState, 'joint_states', DATA_QOS),
            state=(node.create_publisher(JointTrajectory, 'linkage/state', DATA_QOS)
                   if four_bar else None),
            markers=(node.create_publisher(MarkerArray, 'linkage/markers', DATA_QOS)
                     if four_bar else None),
            diagnostics=node.create_publisher(DiagnosticArray, '/diagnostics', DATA_QOS),
            robot_description=(
                node.create_publisher(String, ROBOT_DESCRIPTION_TOPIC, ROBOT_DESCRIPTION_QOS)
                if config.joints.publish_robot_description and four_bar else None),
        )
        # loops robot_description: the input and the lab's description are logged too
        self.input_topic = node.resolve_topic_name(MEASURED_TOPIC)
        self.description_topic = node.resolve_topic_name(ROBOT_DESCRIPTION_TOPIC)
        self.closures_topic = node.resolve_topic_name(CLOSURES_TOPIC)
        self._described: tuple[FourBar, JointMap] | None = None
        self._prepared_for: RunConfiguration | None = None
        self._encoded: FourBar | None = None
        self._streamed: JointMap | None = None
        self._robot_transforms: messages.RobotStateTransforms | None = None
        self._loop_joint_names: tuple[str, ...] | None = None  # publish_joint_states's encoders'
        self._loop_effort_encoder: messages.JointStateEffortEncoder | None = None
        # frame_id and frame_prefix are read-only: one frame for the node's life.
        self._frame_id = config.outputs.frame_prefix + config.outputs.frame_id
        self.log = NodeLog(node, config.logging, self._logged_topics(), parameter_values,
                           bag_writer_cpus)

    def _logged_topics(self) -> list[Topic]:
        """Return every topic the bag holds: those published, TF, and the loops' inputs."""
        # The latest status starts every file of a split bag, as the latched URDF does.
        topics = [
            (publisher.topic_name, publisher.msg_type, publisher.qos_profile,
             True if publisher is self._publishers.diagnostics else None)
            for publisher in self._publishers.present()
        ]
        # and the TF robot_state_publisher would publish, logged only (docs/logging.md)
        topics += [(TF_STATIC_TOPIC, messages.TFMessage, TF_STATIC_QOS, None),
                   (TF_TOPIC, messages.TFMessage, TF_QOS, None)]
        if self.config.loops.source is LoopsSource.ROBOT_DESCRIPTION:
            topics += _loops_topics(self, self._publishers.joint_states.topic_name)
        return topics

    def send(self, publisher: Publisher, data: bytes, log_time_ns: int) -> None:
        """Publish bytes encoded as ``encode_cdr`` does, and log the same bytes."""
        publisher.publish(data)
        self.log.record(publisher.topic_name, data, log_time_ns)

    def _prepare(self) -> None:
        """Prepare the encoders of the per-state messages for the geometry and joints."""
        if self._prepared_for is self.config:
            return  # a dataclass's != compares every field: once per configuration, not state
        self._prepared_for = config = self.config
        if self._encoded != config.geometry.linkage:
            linkage = config.geometry.linkage
            self._state_encoder = messages.LinkageStateEncoder(linkage, self._frame_id)
            self._marker_encoder = messages.MarkerArrayEncoder(linkage, self._frame_id)
            self._encoded = linkage
        joints = config.joints
        if self._streamed != joints.lab:
            # A measured driver stays with its own source: only the passive joints go out.
            self._joints = JointStream(joints.lab, joints.driver,
                                       include_driver=joints.source is SourceKind.DRIVE_LAW)
            self._joint_state_encoder = messages.JointStateEncoder(self._joints.names)
            self._streamed = joints.lab

    def publish_state(self, state: LinkageState, stamp_ns: int, motion_time: float,
                      joints: TreeValues | None = None) -> None:
        """
        Publish the joint states and ``linkage/state`` of ``state``, stamped ``stamp_ns``.

        ``joints``: the tree's lab values where the source solved them (the measured source's
        loop), else the four-bar's (``JointStream``).
        """
        self._prepare()
        positions, velocities = joints if joints is not None else self._joints.values(state)
        published = self._joints.published
        self.send(self._publishers.joint_states,
                  self._joint_state_encoder.encode(stamp_ns, positions[published],
                                                   velocities[published]), stamp_ns)
        if self._robot_transforms is not None:
            # What robot_state_publisher makes of the driver and the passive joints, bag only.
            self.log.record(TF_TOPIC, self._robot_transforms.message(
                dict(zip(self._joints.tree_names, positions)), stamp_ns), stamp_ns)
        self.send(self._publishers.state,
                  self._state_encoder.encode(state, stamp_ns, motion_time), stamp_ns)

    def publish_markers(self, state: LinkageState, stamp_ns: int) -> None:
        """Publish the scene of ``state``."""
        self._prepare()
        self.send(self._publishers.markers, self._marker_encoder.encode(state, stamp_ns),
                  stamp_ns)

    def publish_description(self, stamp_ns: int) -> None:
        """Publish the URDF if published and its geometry or joints are new; log its /tf_static."""
        config = self.config
        joints = config.joints
        described = (config.geometry.linkage, joints.lab)
        if self._described == described or config.loops.source is LoopsSource.ROBOT_DESCRIPTION:
            return
        self._described = described
        description = node_description(config.geometry.linkage, config.outputs.frame_id,
                                       joints.lab, joints.driver)
        if self._publishers.robot_description is not None:
            self.send(self._publishers.robot_description,
                      encode_cdr(String(data=description.text)), stamp_ns)
        # robot_state_publisher's TF, also where a lab runs it on its own URDF: the node's URDF
        # has the lab's joints
        if self.log.recorder is not None:
            self._robot_transforms = tf = messages.RobotStateTransforms(
                description.tree, config.outputs.frame_prefix)
            self.log.record(TF_STATIC_TOPIC, tf.static_message(stamp_ns), stamp_ns)

    # loops robot_description: the lab's description, its closed loops and their input

    def publish_joint_states(self, names: tuple[str, ...], positions: tuple[float, ...],
                             velocities: tuple[float, ...], stamp_ns: int,
                             efforts: tuple[float, ...] = ()) -> None:
        """
        Publish (and log) one ``joint_states`` message of ``names``, stamped ``stamp_ns``.

        ``efforts``: one per joint, or none (the message's effort array empty).
        """
        if names != self._loop_joint_names:
            # The names are the plan's, the same message after message: one encoder per plan
            # (the one with efforts made when a message first has them).
            self._loop_joint_state_encoder = messages.JointStateEncoder(names)
            self._loop_effort_encoder = None
            self._loop_joint_names = names
        if efforts:
            if self._loop_effort_encoder is None:
                self._loop_effort_encoder = messages.JointStateEffortEncoder(names)
            data = self._loop_effort_encoder.encode(stamp_ns, positions, velocities, efforts)
        else:
            data = self._loop_joint_state_encoder.encode(stamp_ns, positions, velocities)
        self.send(self._publishers.joint_states, data, stamp_ns)

    def record_input(self, data: bytes, stamp_ns: int) -> None:
        """Log one input message's bytes as received, at its stamp."""
        self.log.record(self.input_topic, data, stamp_ns)

    def record_robot(self, urdf: str, closures: str, transforms: messages.RobotStateTransforms,
                     stamp_ns: int) -> None:
        """Log a lab's description, closure file ('': none) and /tf_static (/tf: record_tf)."""
        self._robot_transforms = transforms
        self.log.record(self.description_topic, encode_cdr(String(data=urdf)), stamp_ns)
        if closures:
            self.log.record(self.closures_topic, encode_cdr(String(data=closures)), stamp_ns)
        self.log.record(TF_STATIC_TOPIC, transforms.static_message(stamp_ns), stamp_ns)

    def record_tf(self, positions: Sequence[float], stamp_ns: int) -> None:
        """
        Log the /tf robot_state_publisher would publish at ``positions``.

        The positions of the recorded robot's ``driven_joints``, in that order.
        """
        if self.log.recorder is not None and self._robot_transforms is not None:
            self.log.record(TF_TOPIC, self._robot_transforms.tree_message(positions, stamp_ns),
                            stamp_ns)

    def publish_statuses(self, stamp_ns: int, statuses: tuple[Status, ...]) -> None:
        """Publish several statuses in one array, each named '<node>: <task>'."""
        self.send(self._publishers.diagnostics,
                  messages.statuses_message(stamp_ns, self._node_name, statuses), stamp_ns)

    def flush(self, timeout: float = 1.0) -> None:
        """
        Give subscribers up to ``timeout`` seconds in all to acknowledge what was published.

        The final state of a 'stop' run must not die with the process.
        """
        deadline = time.monotonic() + timeout
        for publisher in self._publishers.present():
            publisher.wait_for_all_acked(Duration(seconds=max(deadline - time.monotonic(), 0.0)))
