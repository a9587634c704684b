# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
/tf and /tf_static in the bag: what robot_state_publisher would publish for the logged run.

``robot_transforms`` is checked against urchin's forward kinematics (an independent URDF
library from PyPI) on a URDF with every joint type; the node's bag, from a namespaced node with
a frame prefix, is read with rosbags and mcap-ros2-support, and chaining its transforms from the
URDF's root link gives urchin's forward kinematics of each logged joint state.
"""

from __future__ import annotations

import math
from pathlib import Path
import tempfile
from typing import Any

from linkage_kinematics.bag.definitions import message_definition, type_description_hash
from linkage_kinematics.model.robot_transforms import RobotTransforms, Transform
from linkage_kinematics.model.urdf_reader import read_urdf, UrdfError
from linkage_kinematics.ros import messages
from linkage_kinematics.shared.cdr import encode_cdr
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from node_process import NodeProcesses, PROCESS_TIMEOUT, REPOSITORY
import numpy as np
import pytest
from rosbags.rosbag2 import Reader
from rosbags.typesys import get_typestore, Stores
import urchin
import yaml

NAMESPACE = '/left'
FRAME_PREFIX = 'left/'
TF_TYPE = 'tf2_msgs/msg/TFMessage'
TYPESTORE = get_typestore(Stores.ROS2_JAZZY)

# Every joint type, origins with all three rpy angles, axes off the coordinate axes, a mimic.
EVERY_JOINT_URDF = """<?xml version="1.0"?>
<robot name="every_joint">
  <link name="base"/><link name="mount"/><link name="arm"/><link name="slider"/>
  <link name="wheel"/><link name="follower"/><link name="free"/><link name="tool"/>
  <joint name="mount_joint" type="fixed">
    <parent link="base"/><child link="mount"/>
    <origin xyz="0.1 -0.2 0.3" rpy="0.3 -0.7 1.1"/>
  </joint>
  <joint name="arm_joint" type="revolute">
    <parent link="mount"/><child link="arm"/>
    <origin xyz="0.5 0.0 0.05" rpy="-0.4 0.2 0.9"/>
    <axis xyz="1 2 -2"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="slider_joint" type="prismatic">
    <parent link="arm"/><child link="slider"/>
    <origin xyz="0.3 0.1 -0.2" rpy="1.2 0.5 -2.0"/>
    <axis xyz="0 3 4"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="wheel_joint" type="continuous">
    <parent link="slider"/><child link="wheel"/>
    <origin xyz="0 0.2 0"/>
  </joint>
  <joint name="follower_joint" type="continuous">
    <parent link="wheel"/><child link="follower"/>
    <origin xyz="0.05 0 0.1" rpy="0 1.5 0"/>
    <axis xyz="0 0 1"/>
    <mimic joint="arm_joint" multiplier="-0.5" offset="0.25"/>
  </joint>
  <joint name="free_joint" type="floating">
    <parent link="base"/><child link="free"/>
    <origin xyz="-1 0 0" rpy="0 0 0.5"/>
  </joint>
  <joint name="tool_joint" type="fixed">
    <parent link="follower"/><child link="tool"/>
    <origin xyz="0 0 0.4" rpy="3.0 0.1 -0.3"/>
  </joint>
</robot>
"""


def matrix(transform: Transform) -> np.ndarray:
    """Return the homogeneous matrix of a transform (child frame in parent frame)."""
    x, y, z, w = transform.rotation
    assert x * x + y * y + z * z + w * w == pytest.approx(1.0, abs=1e-15)
    result = np.eye(4)
    result[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]
    result[:3, 3] = transform.translation
    return result


def chain(transforms: list[Transform], root: str) -> dict[str, np.ndarray]:
    """Each frame's pose in ``root``, chaining the transforms outwards from it."""
    poses = {root: np.eye(4)}
    pending = list(transforms)
    while pending:
        reachable = [t for t in pending if t.parent_frame in poses]
        assert reachable, f'frames {[t.parent_frame for t in pending]} hang off no chain'
        for transform in reachable:
            assert transform.child_frame not in poses, f'{transform.child_frame} twice'
            poses[transform.child_frame] = poses[transform.parent_frame] @ matrix(transform)
            pending.remove(transform)
    return poses


def moving_transforms(robot: RobotTransforms, positions: dict[str, float]) -> list[Transform]:
    """Return the transforms of ``robot.moving`` at ``positions`` (joint name → rad or m)."""
    moving = robot.moving(list(positions))
    values = moving.values(positions.values())
    return [Transform(parent, child, values[start:start + 3], values[start + 3:start + 7])
            for start, (parent, child) in zip(range(0, len(values), 7), moving.frames)]


def urchin_poses(urdf: str, positions: dict[str, float], prefix: str) -> dict[str, np.ndarray]:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / 'robot.urdf'
        path.write_text(urdf, encoding='utf-8')
        robot = urchin.URDF.load(str(path), lazy_load_meshes=True)
    return {prefix + link.name: pose for link, pose in robot.link_fk(cfg=positions).items()}


def as_transform(stamped: Any) -> Transform:
    """Return a decoded geometry_msgs/TransformStamped (any reader's) as a Transform."""
    translation = stamped.transform.translation
    rotation = stamped.transform.rotation
    return Transform(stamped.header.frame_id, stamped.child_frame_id,
                     (translation.x, translation.y, translation.z),
                     (rotation.x, rotation.y, rotation.z, rotation.w))


def stamp_ns(stamp: Any) -> int:
    return stamp.sec * 1_000_000_000 + stamp.nanosec


# --- robot_transforms against urchin -------------------------------------------------------------


@pytest.mark.parametrize('positions', [
    {'arm_joint': 0.0, 'slider_joint': 0.0, 'wheel_joint': 0.0},
    {'arm_joint': 0.7, 'slider_joint': -0.35, 'wheel_joint': 2.9},
    {'arm_joint': -2.5, 'slider_joint': 0.8, 'wheel_joint': -7.0},
])
@pytest.mark.parametrize('prefix', ['', 'robot_1/'])
def test_transforms_chain_to_urchins_forward_kinematics(
    positions: dict[str, float], prefix: str
) -> None:
    robot = RobotTransforms(read_urdf(EVERY_JOINT_URDF), prefix)
    fixed = robot.fixed_transforms()
    moving = moving_transforms(robot, positions)
    # kdl_parser makes floating joints fixed; the mimic follows arm_joint.
    assert [t.child_frame for t in fixed] == [prefix + name for name in ('free', 'mount', 'tool')]
    assert [t.child_frame for t in moving] == [prefix + name for name in (
        'arm', 'follower', 'slider', 'wheel')]
    poses = chain(fixed + moving, prefix + robot.root_link)
    expected = urchin_poses(EVERY_JOINT_URDF, {
        **positions, 'follower_joint': -0.5 * positions['arm_joint'] + 0.25}, prefix)
    assert poses.keys() == expected.keys()
    for frame, pose in poses.items():
        np.testing.assert_allclose(pose, expected[frame], rtol=0, atol=1e-12, err_msg=frame)


def test_only_joints_named_in_the_joint_state_move_and_a_named_mimic_keeps_its_value() -> None:
    robot = RobotTransforms(read_urdf(EVERY_JOINT_URDF))
    moving = moving_transforms(robot, {'wheel_joint': 1.0, 'follower_joint': 0.5, 'other': 3.0})
    assert [t.child_frame for t in moving] == ['follower', 'wheel']
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / 'robot.urdf'
        path.write_text(EVERY_JOINT_URDF, encoding='utf-8')
        joints = urchin.URDF.load(str(path), lazy_load_meshes=True).joint_map
    for transform, (name, position) in zip(moving, (('follower_joint', 0.5),
                                                    ('wheel_joint', 1.0))):
        np.testing.assert_allclose(matrix(transform), joints[name].get_child_pose(position),
                                   rtol=0, atol=1e-12, err_msg=name)


@pytest.mark.parametrize('text, problem', [
    ('<robot', 'not XML'),
    ('<model/>', 'root element is <model>'),
    ('<robot name="r"><link name="a"/><link name="b"/></robot>', "2 root links ['a', 'b']"),
    ('<robot name="r"><link name="a"/><joint name="j" type="hinge"><parent link="a"/>'
     '<child link="a"/></joint></robot>', "joint 'j': unknown type 'hinge'"),
    ('<robot name="r"><link name="a"/><joint name="j" type="fixed"><parent link="a"/>'
     '<child link="b"/></joint></robot>', "joint 'j': child link 'b' is not a <link>"),
    ('<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="revolute">'
     '<parent link="a"/><child link="b"/><axis xyz="0 0 0"/></joint></robot>',
     "joint 'j': the axis is zero"),
    ('<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="fixed">'
     '<parent link="a"/><child link="b"/><origin xyz="1 2"/></joint></robot>',
     "joint 'j' origin xyz: '1 2' is not the right count of numbers"),
])
def test_a_bad_urdf_is_refused_naming_the_problem(text: str, problem: str) -> None:
    with pytest.raises(UrdfError) as raised:
        read_urdf(text)
    assert problem in str(raised.value)
    assert '\n' not in str(raised.value)


# --- the shipped tf2_msgs/msg/TFMessage ----------------------------------------------------------


def test_shipped_tfmessage_is_rosbag2s_schema_and_type_hash() -> None:
    assert (REPOSITORY / 'interfaces' / 'tf2_msgs' / 'msg' / 'TFMessage.msg').read_text() == (
        'geometry_msgs/TransformStamped[] transforms\n')
    assert type_description_hash(TF_TYPE) == TYPESTORE.hash_rihs01(TF_TYPE)
    definition = message_definition(TF_TYPE)
    assert definition.startswith('geometry_msgs/TransformStamped[] transforms\n' + '=' * 80
                                 + '\nMSG: geometry_msgs/TransformStamped\n')


def test_tf_message_encoders_write_what_rosbags_serializes() -> None:
    robot = RobotTransforms(read_urdf(EVERY_JOINT_URDF), 'p/')
    positions = {'arm_joint': 0.4, 'slider_joint': 0.1, 'wheel_joint': 2.0}
    prepared = robot.moving(list(positions))
    stamp = 1_790_000_000_123_456_789
    data = messages.TFMessageEncoder(prepared.frames).encode(
        prepared.values(positions.values()), stamp)
    moving = moving_transforms(robot, positions)
    assert data == encode_cdr(messages.tf_message(moving, stamp))
    decoded = TYPESTORE.deserialize_cdr(data, TF_TYPE)
    assert TYPESTORE.serialize_cdr(decoded, TF_TYPE) == data
    assert [as_transform(stamped) for stamped in decoded.transforms] == moving
    assert {stamp_ns(stamped.header.stamp) for stamped in decoded.transforms} == {stamp}


# --- the node's bag ------------------------------------------------------------------------------


@pytest.fixture(scope='module')
def namespaced_bag(
    tmp_path_factory: pytest.TempPathFactory, module_nodes: NodeProcesses
) -> Path:
    """Return the bag folder of the seed's constant-law turn by a node in /left, frames left/…."""
    run_folder = tmp_path_factory.mktemp('tf_run')
    folder = run_folder / 'bags'
    process = module_nodes.start(
        {'frame_prefix': FRAME_PREFIX, 'end_behavior': 'stop', 'log.folder': str(folder)},
        run_folder / 'node.log', ros_arguments=['-r', f'__ns:={NAMESPACE}'],
    )
    status = process.wait(timeout=PROCESS_TIMEOUT)
    assert status == 0, (run_folder / 'node.log').read_text()
    [bag] = folder.iterdir()
    return bag


def test_every_joint_state_has_the_transforms_robot_state_publisher_gives_it(
    namespaced_bag: Path,
) -> None:
    [mcap_file] = namespaced_bag.glob('*.mcap')
    logged: dict[str, list[Any]] = {}
    with open(mcap_file, 'rb') as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for _, channel, message, decoded in reader.iter_decoded_messages():
            logged.setdefault(channel.topic, []).append((message.log_time, decoded))
    [(description_time, description)] = logged[f'{NAMESPACE}/robot_description']
    urdf = description.data
    root = FRAME_PREFIX + RobotTransforms(read_urdf(urdf)).root_link
    # /tf_static once, at the description's time; this URDF has no fixed joint.
    [(static_time, static)] = logged['/tf_static']
    assert static_time == description_time and static.transforms == []

    joint_states = logged[f'{NAMESPACE}/joint_states']
    transforms = logged['/tf']
    assert len(joint_states) == len(transforms) > 50
    for (state_time, joint_state), (tf_time, tf) in zip(joint_states, transforms, strict=True):
        stamp = stamp_ns(joint_state.header.stamp)
        assert tf_time == state_time == stamp
        assert {stamp_ns(t.header.stamp) for t in tf.transforms} == {stamp}
        positions = dict(zip(joint_state.name, joint_state.position))
        poses = chain([as_transform(t) for t in tf.transforms], root)
        expected = urchin_poses(urdf, positions, FRAME_PREFIX)
        assert poses.keys() == expected.keys() == {
            FRAME_PREFIX + link for link in ('linkage_base', 'disk', 'coupler', 'rocker')}
        for frame, pose in poses.items():
            np.testing.assert_allclose(pose, expected[frame], rtol=0, atol=1e-12, err_msg=frame)
    # The last state ends the turn at alpha_end = 90°: the disk frame is turned by it.
    disk = chain([as_transform(t) for t in transforms[-1][1].transforms], root)
    assert math.atan2(disk['left/disk'][1, 0], disk['left/disk'][0, 0]) == pytest.approx(
        math.pi / 2, abs=1e-12)


def test_tf_topics_decode_with_rosbags_with_tf2s_qos_and_type_hash(namespaced_bag: Path) -> None:
    metadata = yaml.safe_load((namespaced_bag / 'metadata.yaml').read_text())
    topics = {entry['topic_metadata']['name']: entry['topic_metadata'] for entry in
              metadata['rosbag2_bagfile_information']['topics_with_message_count']}
    for topic, durability, depth in (('/tf', 'volatile', 100),
                                     ('/tf_static', 'transient_local', 1)):
        assert topics[topic]['type'] == TF_TYPE
        assert topics[topic]['type_description_hash'] == TYPESTORE.hash_rihs01(TF_TYPE)
        [qos] = topics[topic]['offered_qos_profiles']
        assert (qos['durability'], qos['depth'], qos['reliability']) == (
            durability, depth, 'reliable')
    decoded = 0
    with Reader(namespaced_bag) as reader:
        connections = [c for c in reader.connections if c.topic in ('/tf', '/tf_static')]
        assert {c.msgtype for c in connections} == {TF_TYPE}
        for connection, timestamp, data in reader.messages(connections=connections):
            message = TYPESTORE.deserialize_cdr(data, connection.msgtype)
            assert all(stamp_ns(t.header.stamp) == timestamp for t in message.transforms)
            assert all(t.header.frame_id.startswith(FRAME_PREFIX)
                       and t.child_frame_id.startswith(FRAME_PREFIX) for t in message.transforms)
            decoded += 1
    assert decoded > 50
