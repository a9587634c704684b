# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Bags the node writes, read back: the helpers the bag and recording tests share.

Which topics the node publishes and logs, a listener to all of them, and a bag read with rosbags
and by its metadata.yaml.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable
from pathlib import Path
import subprocess
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray
from linkage_kinematics.ros import messages
from node_process import Listener, stamp_ns, TYPESTORE
import rclpy
from rosbags.rosbag2 import Reader
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from trajectory_msgs.msg import JointTrajectory
from visualization_msgs.msg import MarkerArray
import yaml

NODE_TOPICS = {
    '/joint_states': JointState,
    '/linkage/state': JointTrajectory,
    '/robot_description': String,
    '/linkage/markers': MarkerArray,
    '/diagnostics': DiagnosticArray,
}
# The node logs TF too, as robot_state_publisher would publish it, without publishing it.
LOGGED_TOPICS = {**NODE_TOPICS, '/tf_static': messages.TFMessage, '/tf': messages.TFMessage}


def listen_to_node_topics(context: rclpy.Context, name: str) -> Listener:
    listener = Listener(name, context)
    for topic, msg_type in NODE_TOPICS.items():
        listener.subscribe(topic, msg_type, transient_local=topic == '/robot_description')
    return listener


def stopped(process: subprocess.Popen) -> Callable[[], bool]:
    return lambda: process.poll() is not None


def only_bag(folder: Path) -> Path:
    bags = [path for path in folder.iterdir() if path.is_dir()]
    assert len(bags) == 1, f'expected one bag in {folder}, found {bags}'
    return bags[0]


def read_with_rosbags(bag: Path) -> dict[str, list[tuple[int, Any, bytes]]]:
    """
    Return topic -> [(log time ns, decoded message, raw CDR)], read with rosbags.

    rosbags needs the file's summary.
    """
    logged: dict[str, list[tuple[int, Any, bytes]]] = defaultdict(list)
    with Reader(bag) as reader:
        for connection, log_time, raw in reader.messages():
            logged[connection.topic].append(
                (log_time, TYPESTORE.deserialize_cdr(raw, connection.msgtype), bytes(raw))
            )
    return logged


def bag_information(bag: Path) -> dict[str, Any]:
    return yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']


def topic_counts(information: dict[str, Any]) -> dict[str, int]:
    """Topic -> message count, as metadata.yaml states them."""
    return {
        entry['topic_metadata']['name']: entry['message_count']
        for entry in information['topics_with_message_count']
    }


def message_stamp_ns(message: Any) -> int:
    """Header stamp; a MarkerArray's is that of its (equally stamped) markers."""
    return stamp_ns(message.markers[0] if hasattr(message, 'markers') else message)
