# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Several mechanisms in one ROS graph.

Nodes in their own namespaces publish only on their own topics, log only those, carry their frame
prefix, and say where their bag goes.
"""

from __future__ import annotations

from pathlib import Path
import re
import signal

from linkage_kinematics.bag.metadata import BagMetadata
from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import preset
from linkage_kinematics.kinematics.solver import solve
from linkage_kinematics.model.urdf import urdf_text
from node_process import (
    Listener,
    NodeProcesses,
    PROCESS_TIMEOUT,
    ros_context,
)
from rosbags.rosbag2 import Reader
from rosbags.typesys import get_typestore, Stores
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from trajectory_msgs.msg import JointTrajectory
from visualization_msgs.msg import MarkerArray

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
# namespace → (preset, frame prefix); '' is a node with no namespace beside them.
MECHANISMS = {
    '/left': ('paper', 'left/'),
    '/right': ('grashof_crank_rocker', 'right/'),
    '': ('paper_full_turn', ''),
}
DRIVE = {'paper': DriveLaw(2.0), 'grashof_crank_rocker': DriveLaw(2.0),
         'paper_full_turn': DriveLaw(-2.0)}


def _topic(namespace: str, name: str) -> str:
    return f'{namespace}/{name}'


def test_mechanisms_in_namespaces_keep_to_their_own_topics_frames_and_bags(
    nodes: NodeProcesses, tmp_path: Path
):
    bags = tmp_path / 'bags'  # one folder for all three: bag names must not collide
    processes = {}
    with ros_context(nodes.domain_id) as context:
        listener = Listener('namespace_tester', context)
        for namespace in MECHANISMS:
            listener.subscribe(_topic(namespace, 'linkage/state'), JointTrajectory)
            listener.subscribe(_topic(namespace, 'joint_states'), JointState)
            listener.subscribe(_topic(namespace, 'linkage/markers'), MarkerArray)
            listener.subscribe(_topic(namespace, 'robot_description'), String,
                               transient_local=True)
        try:
            for namespace, (preset_name, prefix) in MECHANISMS.items():
                drive = DRIVE[preset_name]
                parameters = {'preset': preset_name, 'omega0': drive.omega0,
                              'alpha_end': -1.0 if drive.omega0 < 0 else 1.0,
                              'end_behavior': 'bounce', 'frame_prefix': prefix,
                              'log.folder': str(bags)}
                processes[namespace] = nodes.start(
                    parameters, tmp_path / f"node{namespace.replace('/', '_')}.log",
                    ros_arguments=['-r', f'__ns:={namespace}'] if namespace else [],
                )
            assert listener.wait_for_every_topic(count=3)
            for process in processes.values():
                process.send_signal(signal.SIGINT)
            for namespace, process in processes.items():
                assert process.wait(timeout=PROCESS_TIMEOUT) == 0
        finally:
            listener.destroy()

    for namespace, (preset_name, prefix) in MECHANISMS.items():
        geometry = preset(preset_name).geometry
        # Every state on a namespace's topic is that mechanism's (its geometry, its drive).
        for message in listener.received[_topic(namespace, 'linkage/state')]:
            point = message.points[0]
            state = solve(geometry, point.positions[0],
                          DriveLaw(point.velocities[0]))
            assert (point.positions[5], point.positions[6]) == (state.pin_b_x, state.pin_b_y)
            assert message.header.frame_id == f'{prefix}linkage_base'
        for message in listener.received[_topic(namespace, 'linkage/markers')]:
            assert {marker.header.frame_id for marker in message.markers} == {
                f'{prefix}linkage_base'}
        # robot_state_publisher expects the URDF unprefixed (it applies frame_prefix itself).
        (description,) = listener.received[_topic(namespace, 'robot_description')]
        assert description.data == urdf_text(geometry)

    # Three bags, each holding only its own node's resolved topics (and /diagnostics, /tf and
    # /tf_static, whose frames carry the node's prefix).
    logs = {namespace: (tmp_path / f"node{namespace.replace('/', '_')}.log").read_text()
            for namespace in MECHANISMS}
    seen = set()
    for namespace, log in logs.items():
        (recording,) = re.findall(r'recording to (\S+)', log)
        (finalized, count) = re.findall(r'bag finalized: (\S+), (\d+) messages', log)[0]
        assert recording == finalized and Path(recording).is_dir()
        assert Path(recording).parent == bags and recording not in seen
        seen.add(recording)
        assert int(count) == BagMetadata.read(recording).message_count
        with Reader(recording) as reader:
            topics = {connection.topic for connection in reader.connections}
        assert topics == {_topic(namespace, name) for name in (
            'joint_states', 'linkage/state', 'robot_description', 'linkage/markers')} | {
            '/diagnostics', '/tf', '/tf_static'}
    assert len(list(bags.iterdir())) == 3
