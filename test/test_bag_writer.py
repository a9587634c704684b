# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Logging to rosbag2 MCAP: the CDR encoders, BagWriter and Recorder on their own.

A real node's bag, read back by two independent readers, and linkage-replay are in
test_bag_node_run.py; the helpers the bag tests share are in bag_files.py.
"""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
import re
import time
from typing import Any

from ament_index_python.packages import get_package_share_directory
from bag_files import bag_information, message_stamp_ns
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import Point
from hypothesis import example, given, settings
from hypothesis import strategies as st
from linkage_kinematics.bag import reader as bag_reader
from linkage_kinematics.bag.definitions import DEFINITION_SEPARATOR, message_definition
from linkage_kinematics.bag.errors import BagExistsError
from linkage_kinematics.bag.metadata import offered_qos_profiles_for, package_version, yaml_text
from linkage_kinematics.bag.recorder import Recorder
from linkage_kinematics.bag.writer import BagWriter, DEFAULT_CHUNK_SIZE, WRITE_BATCH
from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import preset
from linkage_kinematics.kinematics.solver import solve
from linkage_kinematics.model import scene
from linkage_kinematics.model.joints import (
    DEFAULT_JOINT_NAMES,
    Driver,
    tree_values,
    unwrap_positions,
)
from linkage_kinematics.ros import messages
from linkage_kinematics.shared.cdr import encode_cdr, FixedShapeEncoder, ros_type_name
from mcap.reader import make_reader
from node_process import decode, expected_state_point, time_msg, TYPESTORE
import numpy as np
import pytest
from rclpy.qos import QoSProfile
from rclpy.serialization import deserialize_message, serialize_message
from sensor_msgs.msg import CameraInfo, JointState, Range
from std_msgs.msg import Float64, String
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint
from visualization_msgs.msg import Marker, MarkerArray
import yaml

NAMES = list(DEFAULT_JOINT_NAMES.values())


# --- BagWriter and Recorder on their own ---------------------------------------------------------


def sample_messages() -> list[Any]:
    """
    Return one message of every type the node logs.

    The per-tick messages and the scene as rclpy decodes the bytes of the node's encoders (the
    only way the node makes them), the status built as the node builds it.
    """
    paper = preset('paper')
    state = solve(paper.geometry, 0.3, DriveLaw(2.0, 0.0))
    stamp_ns = 1_234_567_890_123
    return [
        # empty effort: the case rclpy pads
        deserialize_message(messages.JointStateEncoder(NAMES).encode(
            stamp_ns, *tree_values(state, Driver.CRANK)), JointState),
        deserialize_message(messages.LinkageStateEncoder(paper.geometry, 'linkage_base').encode(
            state, stamp_ns, 0.1), JointTrajectory),
        deserialize_message(messages.MarkerArrayEncoder(paper.geometry, 'linkage_base').encode(
            state, stamp_ns), MarkerArray),
        deserialize_message(messages.diagnostics_message(stamp_ns, [messages.DiagnosticEntry(
            'linkage_node: crank motion', 'four-bar', 1, '1.2° from a dead point',
            {'α (deg)': '12.5', 'empty': ''})]), DiagnosticArray),
        String(data="<robot name='ü'/>"),
        String(data=''),
    ]


def encoded_by_rosbags(data: bytes, type_name: str) -> bytes:
    """Decode ``data`` and encode it again by rosbags: exact length, alignment padding zeroed."""
    return bytes(TYPESTORE.serialize_cdr(TYPESTORE.deserialize_cdr(data, type_name), type_name))


def assert_exact_encoding(data: bytes, message: Any) -> None:
    """
    Check that ``data`` is ``message``.

    rclpy (Fast CDR) decodes it as it decodes its own serialization of ``message`` (float32 fields
    rounded alike), and rosbags encodes what it decodes to the very same bytes (exact length, zero
    padding).
    """
    msg_type = type(message)
    assert deserialize_message(data, msg_type) == deserialize_message(
        serialize_message(message), msg_type)
    assert data == encoded_by_rosbags(data, ros_type_name(type(message)))


@pytest.mark.parametrize('message', sample_messages(), ids=lambda m: type(m).__name__)
def test_encode_cdr_writes_every_logged_type_as_the_independent_serializers(message: Any) -> None:
    logged = encode_cdr(message)
    assert_exact_encoding(logged, message)
    decoded = TYPESTORE.deserialize_cdr(logged, ros_type_name(type(message)))
    if isinstance(message, String):
        assert decoded.data == message.data
    elif isinstance(message, MarkerArray):
        assert [(p.x, p.y) for m in decoded.markers for p in m.points] == [
            (p.x, p.y) for m in message.markers for p in m.points]
    else:
        assert message_stamp_ns(decoded) == 1_234_567_890_123


def test_joint_state_values_survive_encoding() -> None:
    message = sample_messages()[0]
    decoded = TYPESTORE.deserialize_cdr(encode_cdr(message), 'sensor_msgs/msg/JointState')
    assert list(decoded.name) == list(message.name)
    assert list(decoded.position) == list(message.position)
    assert list(decoded.velocity) == list(message.velocity)
    assert len(decoded.effort) == 0


finite = st.floats(allow_nan=False, allow_infinity=False)
ros_text = st.text(st.characters(codec='utf-8', exclude_characters='\x00'), max_size=7)  # no NUL


@settings(max_examples=60, deadline=None)
@given(
    names=st.lists(ros_text, max_size=4),
    position=st.lists(finite, max_size=4),
    velocity=st.lists(finite, max_size=4),
    effort=st.lists(finite, max_size=4),
    frame_id=ros_text,
)
def test_encoding_holds_for_any_sequence_and_string_lengths(
    names: list[str], position: list[float], velocity: list[float], effort: list[float],
    frame_id: str,
) -> None:
    message = JointState(name=names, position=position, velocity=velocity, effort=effort)
    message.header.frame_id = frame_id
    assert_exact_encoding(encode_cdr(message), message)


@settings(max_examples=40, deadline=None)
@given(
    level=st.integers(0, 3),
    texts=st.lists(ros_text, min_size=4, max_size=4),
    values=st.dictionaries(ros_text, ros_text, max_size=3),
    points=st.lists(st.tuples(finite, finite, finite), max_size=3),
    flags=st.lists(st.booleans(), min_size=1, max_size=3),
)
def test_encoding_holds_for_bytes_booleans_nested_messages_and_their_sequences(
    level: int, texts: list[str], values: dict[str, str], points: list[tuple[float, float, float]],
    flags: list[bool],
) -> None:
    """
    Return the other field kinds the node logs.

    A byte (the diagnostic level), a bool between wider fields, sequences of messages inside
    sequences of messages, an empty uint8 sequence; and a run of fixed-size fields (a uint8, then
    float32s) starting at every offset a string of any length leaves; fixed-size arrays (numpy
    arrays in rclpy).
    """
    status = DiagnosticStatus(level=bytes([level]), name=texts[0], message=texts[1],
                              hardware_id=texts[2],
                              values=[KeyValue(key=k, value=v) for k, v in values.items()])
    diagnostics = DiagnosticArray(status=[status, status])
    assert_exact_encoding(encode_cdr(diagnostics), diagnostics)
    markers = MarkerArray(markers=[
        Marker(ns=texts[3], id=index, frame_locked=flag, points=[
            Point(x=x, y=y, z=z) for x, y, z in points]) for index, flag in enumerate(flags)])
    assert_exact_encoding(encode_cdr(markers), markers)
    ranged = Range(radiation_type=Range.INFRARED, field_of_view=0.5, min_range=0.25,
                   max_range=2.0, range=1.5)
    ranged.header.frame_id = texts[0]
    assert_exact_encoding(encode_cdr(ranged), ranged)
    camera = CameraInfo(distortion_model=texts[1], d=[x for point in points for x in point],
                        k=[float(index) for index in range(9)], binning_x=level)
    camera.header.frame_id = texts[0]
    camera.roi.do_rectify = flags[0]
    assert_exact_encoding(encode_cdr(camera), camera)


def test_encode_cdr_follows_every_change_of_a_reused_message() -> None:
    message = JointState(name=['abc', 'c'], position=[1.0], velocity=[2.0])
    message.header.frame_id = 'aaa'
    # Each step changes one field of the reused message, as a node would, and with it the exact
    # length. Two steps keep every Python length and change only the UTF-8 bytes.
    steps: list[Callable[[JointState], None]] = [
        lambda m: None,
        lambda m: setattr(m, 'name', ['übc', 'c']),
        lambda m: setattr(m, 'name', ['ab']),
        lambda m: setattr(m.header, 'frame_id', 'üaa'),
        lambda m: setattr(m, 'name', ['ab', 'c']),
        lambda m: setattr(m, 'effort', [3.0]),
        lambda m: setattr(m, 'effort', []),  # where rclpy's serialize_message returned 4 too many
        lambda m: setattr(m, 'position', [1.0, 4.0]),
        lambda m: setattr(m.header, 'frame_id', 'the_base_link'),
    ]
    lengths = []
    for step in steps:
        step(message)
        data = encode_cdr(message)
        assert_exact_encoding(data, message)
        lengths.append(len(data))
    assert all(before != after for before, after in zip(lengths, lengths[1:])), lengths


point_lengths = st.tuples(*[st.integers(0, 3)] * 4)  # positions, velocities, accelerations, effort
# Few choices, so that consecutive messages often differ in one place only.
few_texts = st.sampled_from(['', 'base', 'bäse', 'the_base_link'])


@settings(max_examples=40, deadline=None)
@given(
    shapes=st.lists(
        st.tuples(few_texts, st.lists(few_texts, max_size=2), st.lists(point_lengths, max_size=2)),
        min_size=2, max_size=6,
    )
)
@example(shapes=[('base', ['a'], [(1, 0, 0, 0)]), ('base', ['a'], [(2, 0, 0, 0)])])
def test_encode_cdr_follows_every_reshaping_of_a_trajectory(
    shapes: list[tuple[str, list[str], list[tuple[int, int, int, int]]]],
) -> None:
    """One JointTrajectory, reused and reshaped between calls."""
    message = JointTrajectory()
    for frame_id, joint_names, points in shapes:
        message.header.frame_id = frame_id
        message.joint_names = joint_names
        message.points = [
            JointTrajectoryPoint(
                positions=[0.5] * sizes[0], velocities=[1.5] * sizes[1],
                accelerations=[2.5] * sizes[2], effort=[3.5] * sizes[3],
            )
            for sizes in points
        ]
        assert_exact_encoding(encode_cdr(message), message)


def assert_one_encoding(data: bytes, msg_type: type) -> Any:
    """
    Check that ``data`` is one message's exact encoding; return rosbags' decoding of it.

    rosbags encodes what it decodes to the very same bytes, and encode_cdr writes the same bytes
    of what rclpy decodes.
    """
    assert data == encoded_by_rosbags(data, ros_type_name(msg_type))
    assert encode_cdr(deserialize_message(data, msg_type)) == data
    return decode(data, ros_type_name(msg_type))


def rgba(color: Any) -> tuple[float, float, float, float]:
    """Return a decoded ColorRGBA as the float32 values of the wire."""
    return color.r, color.g, color.b, color.a


def float32(*values: float) -> tuple[float, ...]:
    return tuple(float(np.float32(value)) for value in values)


@settings(max_examples=60, deadline=None)
@given(
    preset_name=st.sampled_from(['paper', 'paper_full_turn', 'grashof_crank_rocker']),
    alpha=st.floats(-10.0, 10.0),
    stamp=st.integers(0, 2**31 * 10**9 - 1),  # builtin_interfaces/Time.sec is an int32
    motion_time=st.floats(0.0, 1e6),
    frame_id=st.sampled_from(['', 'linkage_base', 'ü/base', 'left/linkage_base']),
    previous=st.tuples(*[st.floats(-100.0, 100.0)] * 3),
)
def test_the_nodes_encoders_write_each_message_exactly_as_the_independent_readers_decode_it(
    preset_name: str, alpha: float, stamp: int, motion_time: float, frame_id: str,
    previous: tuple[float, float, float],
) -> None:
    """
    The per-tick messages and the scene, encoded straight from the state.

    Are each one message's exact encoding, and rosbags decodes from them the state's values
    (frame ids of any length shift the alignment of everything after them).
    """
    linkage = preset(preset_name).geometry
    try:
        state = solve(linkage, alpha, DriveLaw(2.0, 0.3))
    except ValueError:  # an unreachable or dead-point angle has no state to encode
        return
    seconds, nanoseconds = divmod(stamp, 1_000_000_000)
    positions, velocities = tree_values(state, Driver.CRANK)
    positions = unwrap_positions(positions, previous)
    joints = assert_one_encoding(
        messages.JointStateEncoder(NAMES).encode(stamp, positions, velocities), JointState)
    assert (joints.header.stamp.sec, joints.header.stamp.nanosec) == (seconds, nanoseconds)
    assert joints.header.frame_id == ''
    assert list(joints.name) == NAMES
    assert tuple(joints.position) == positions
    assert tuple(joints.velocity) == velocities
    assert len(joints.effort) == 0

    trajectory = assert_one_encoding(
        messages.LinkageStateEncoder(linkage, frame_id).encode(state, stamp, motion_time),
        JointTrajectory)
    assert (trajectory.header.stamp.sec, trajectory.header.stamp.nanosec) == (
        seconds, nanoseconds)
    assert trajectory.header.frame_id == frame_id
    (point,) = trajectory.points
    assert (tuple(point.positions), tuple(point.velocities), tuple(point.accelerations)) == (
        expected_state_point(linkage, state))
    elapsed = point.time_from_start
    assert elapsed.sec * 1_000_000_000 + elapsed.nanosec == round(motion_time * 1e9)

    scene_message = assert_one_encoding(
        messages.MarkerArrayEncoder(linkage, frame_id).encode(state, stamp), MarkerArray)
    markers = scene_message.markers
    assert [m.id for m in markers] == list(range(6))
    for marker in markers:
        assert (marker.header.stamp.sec, marker.header.stamp.nanosec) == (seconds, nanoseconds)
        assert (marker.header.frame_id, marker.ns) == (frame_id, messages.MARKER_NAMESPACE)
    pin_a, pin_b = (state.pin_a_x, state.pin_a_y), (state.pin_b_x, state.pin_b_y)
    ground_c = (linkage.ground_x, linkage.ground_y)
    bars = markers[messages.BARS_ID]
    assert [(p.x, p.y) for p in bars.points] == [(0.0, 0.0), pin_a, pin_a, pin_b, pin_b,
                                                 ground_c]
    assert [rgba(c) for c in bars.colors] == [
        float32(*color) for color in (scene.CRANK_COLOR, scene.CRANK_COLOR, scene.COUPLER_COLOR,
                                      scene.COUPLER_COLOR, scene.ROCKER_COLOR,
                                      scene.ROCKER_COLOR)]
    position = markers[messages.PIN_A_ID].pose.position
    assert (position.x, position.y) == pin_a
    position = markers[messages.PIN_B_ID].pose.position
    assert (position.x, position.y) == pin_b
    position = markers[messages.PIVOT_C_ID].pose.position
    assert (position.x, position.y) == ground_c
    disk = markers[messages.DISK_ID]
    assert (disk.pose.orientation.z, disk.pose.orientation.w) == messages.disk_orientation(state)
    assert disk.scale.x == disk.scale.y == 2.0 * linkage.crank_length
    assert rgba(disk.color) == float32(*scene.DISK_COLOR[:3], scene.DISK_MARKER_ALPHA)


@settings(max_examples=60, deadline=None)
@given(
    stamp=st.integers(0, 2**31 * 10**9 - 1),
    statuses=st.lists(st.tuples(st.integers(0, 3), st.lists(ros_text, min_size=3, max_size=3),
                                st.dictionaries(ros_text, ros_text, max_size=4)),
                      min_size=1, max_size=3),
)
def test_the_diagnostics_written_from_their_texts_are_encode_cdr_of_the_message(
    stamp: int, statuses: list[tuple[int, list[str], dict[str, str]]],
) -> None:
    """
    ``diagnostics_message`` writes the bytes ``encode_cdr`` writes of the rclpy message.

    Texts of any length (UTF-8 of any width) shift the alignment of everything after them.
    """
    entries = [messages.DiagnosticEntry(name, hardware_id, level, text, values)
               for level, (name, hardware_id, text), values in statuses]
    message = DiagnosticArray(status=[
        DiagnosticStatus(level=bytes([entry.level]), name=entry.name, message=entry.message,
                         hardware_id=entry.hardware_id,
                         values=[KeyValue(key=key, value=value)
                                 for key, value in entry.values.items()])
        for entry in entries])
    message.header.stamp = time_msg(stamp)
    data = messages.diagnostics_message(stamp, entries)
    assert data == encode_cdr(message)
    decoded = assert_one_encoding(data, DiagnosticArray)
    assert [(status.name, status.message, status.hardware_id) for status in decoded.status] == [
        (entry.name, entry.message, entry.hardware_id) for entry in entries]


def test_a_fixed_shape_encoder_of_one_field_and_one_naming_no_field() -> None:
    encoder = FixedShapeEncoder(Float64(data=0.0), ['data'])
    assert encoder.value_count == 1
    assert encoder.encode((2.5,)) == encode_cdr(Float64(data=2.5))
    with pytest.raises(ValueError,
                       match=r"std_msgs/msg/Float64 has no fixed-size field \['dat'\]"):
        FixedShapeEncoder(Float64(data=0.0), ['dat'])


def test_schema_names_dependencies_as_the_referencing_field_spells_them() -> None:
    text = message_definition('sensor_msgs/msg/JointState')
    msg_file = Path(get_package_share_directory('sensor_msgs')) / 'msg' / 'JointState.msg'
    assert text.startswith(msg_file.read_text().rstrip('\n'))
    sections = text.split(DEFINITION_SEPARATOR + '\n')
    assert [section.splitlines()[0] for section in sections[1:]] == [
        'MSG: std_msgs/Header',
        'MSG: builtin_interfaces/Time',
    ]
    assert 'std_msgs/msg/Header' not in text
    markers = message_definition('visualization_msgs/msg/MarkerArray')
    dependency_names = re.findall(r'^MSG: (\S+)$', markers, flags=re.MULTILINE)
    assert len(dependency_names) == len(set(dependency_names))
    # bare names in a .msg file (``Marker[] markers``) get the package of that file
    assert {'visualization_msgs/Marker', 'geometry_msgs/Point', 'std_msgs/Header'} <= set(
        dependency_names
    )


def test_bag_writer_defaults_chunked_zstd_ros2_profile_and_time_flush(tmp_path: Path) -> None:
    bag = tmp_path / 'unit_bag'
    writer = BagWriter(bag, metadata={'rate_hz': '200'}, flush_interval=0.05)
    assert (bag / 'metadata.yaml').is_file(), "a killed run's folder must already be a bag"
    channel = writer.add_topic(
        '/chatter',
        'std_msgs/msg/String',
        message_definition('std_msgs/msg/String'),
        offered_qos_profiles_for(QoSProfile(depth=7)),
    )
    payload = encode_cdr(String(data='hello'))
    writer.write(channel, payload, 1_000, 1_000)
    time.sleep(0.06)
    writer.write(channel, payload, 2_000, 2_000)  # the interval has passed: the chunk is flushed
    flushed = list(bag_reader.iter_messages(bag))
    assert [m.log_time_ns for m in flushed] == [1_000, 2_000]
    for index in range(3, 2_000):
        writer.write(channel, payload, index * 1_000, index * 1_000)
    writer.close()
    writer.close()

    with open(writer.mcap_path, 'rb') as stream:
        reader = make_reader(stream)
        header = reader.get_header()
        summary = reader.get_summary()
        assert header.profile == 'ros2'
        assert header.library.startswith(f'linkage_kinematics/{package_version()} mcap-python/')
        assert summary.statistics.message_count == 1_999
        assert {index.compression for index in summary.chunk_indexes} == {'zstd'}
        assert len(summary.chunk_indexes) >= 2
        (schema,) = summary.schemas.values()
        (channel_record,) = summary.channels.values()
        assert (schema.name, schema.encoding) == ('std_msgs/msg/String', 'ros2msg')
        assert channel_record.message_encoding == 'cdr'
        assert yaml.safe_load(channel_record.metadata['offered_qos_profiles'])[0]['depth'] == 7
        assert channel_record.metadata['topic_type_hash'].startswith('RIHS01_')
        records = {record.name: record.metadata for record in reader.iter_metadata()}
    assert records['linkage_kinematics'] == {
        'package_version': package_version(), 'rate_hz': '200'}
    rosbag2_record = yaml.safe_load(records['rosbag2']['serialized_metadata'])
    assert rosbag2_record['version'] == 9 and rosbag2_record['message_count'] == 1_999
    information = bag_information(bag)
    assert information['message_count'] == 1_999
    assert information['custom_data']['rate_hz'] == '200'


@pytest.mark.parametrize('count', [1, WRITE_BATCH - 1, WRITE_BATCH, 3 * WRITE_BATCH + 1])
def test_bag_writer_keeps_every_queued_message_in_order(tmp_path: Path, count: int) -> None:
    """
    Messages wait in a queue before they enter the chunk.

    Flush and close take them all, in the order written, on their channels.
    """
    writer = BagWriter(tmp_path / 'queued', metadata={}, flush_interval=3600.0)
    channels = [
        writer.add_topic(topic, 'std_msgs/msg/String', message_definition('std_msgs/msg/String'),
                         offered_qos_profiles_for(QoSProfile(depth=10)))
        for topic in ('/a', '/b')
    ]
    written = [(('/a', '/b')[index % 2], encode_cdr(String(data=f'm{index}')), 1_000 + index)
               for index in range(count)]
    for index, (_, data, log_time) in enumerate(written):
        writer.write(channels[index % 2], data, log_time, log_time)
    writer.flush()
    flushed = [(m.topic, m.data, m.log_time_ns) for m in bag_reader.iter_messages(writer.bag_path)]
    assert flushed == written
    writer.write(channels[0], encode_cdr(String(data='last')), 5_000, 5_000)
    writer.close()
    logged = [(m.topic, m.data, m.log_time_ns) for m in bag_reader.iter_messages(writer.bag_path)]
    assert logged == written + [('/a', encode_cdr(String(data='last')), 5_000)]
    information = bag_information(writer.bag_path)
    assert information['message_count'] == count + 1
    assert information['starting_time']['nanoseconds_since_epoch'] == 1_000
    assert information['duration']['nanoseconds'] == 4_000


@pytest.mark.parametrize('flushes, chunk_size', [(0, DEFAULT_CHUNK_SIZE), (1, DEFAULT_CHUNK_SIZE),
                                                 (7, DEFAULT_CHUNK_SIZE), (1, 2048)])
def test_finished_size_is_the_size_of_the_bag_closed_then(tmp_path: Path, flushes: int,
                                                          chunk_size: int) -> None:
    """Also where chunks end by size between flushes (chunk_size 2048: about 40 chunks)."""
    writer = BagWriter(tmp_path / 'sized', metadata={'run': 'x'}, flush_interval=3600.0,
                       chunk_size=chunk_size)
    channels = [
        writer.add_topic(topic, type_name, message_definition(type_name),
                         offered_qos_profiles_for(QoSProfile(depth=10)))
        for topic, type_name in (('/a', 'std_msgs/msg/String'),
                                 ('/tf', 'tf2_msgs/msg/TFMessage'))
    ]
    for index in range(700):
        writer.write(channels[0], encode_cdr(String(data=f'message {index}')), index, index)
        if flushes and index % (700 // flushes) == 0:
            writer.flush()
    writer.flush()
    projected = writer.finished_size()
    writer.close()
    # to a few bytes per chunk: its index counted with an offset for every channel
    with open(writer.mcap_path, 'rb') as stream:
        chunks = len(make_reader(stream).get_summary().chunk_indexes)
    assert 0 <= projected - writer.mcap_path.stat().st_size <= 10 * (chunks + 3)


def test_bag_writer_refuses_an_existing_bag_folder(tmp_path: Path) -> None:
    bag = tmp_path / 'taken'
    bag.mkdir()
    (bag / 'keep.txt').write_text('untouched')
    with pytest.raises(BagExistsError, match=re.escape(str(bag))):
        BagWriter(bag, metadata={})
    assert [p.name for p in bag.iterdir()] == ['keep.txt']
    assert (bag / 'keep.txt').read_text() == 'untouched'


def test_recorder_refuses_a_log_folder_under_a_regular_file(tmp_path: Path) -> None:
    blocker = tmp_path / 'afile'
    blocker.write_text('')
    with pytest.raises(OSError, match=re.escape(str(blocker / 'bags'))):
        Recorder(blocker / 'bags', metadata={})


def test_the_metadata_text_is_what_pythons_yaml_dumper_writes(tmp_path: Path) -> None:
    """The metadata's text (``metadata.yaml_text``, libyaml's dumper) is PyYAML's safe_dump's."""
    writer = BagWriter(tmp_path / 'texts', metadata={'run': 'ünïcode', 'long': 'x ' * 200})
    channel = writer.add_topic('/a', 'std_msgs/msg/String',
                               message_definition('std_msgs/msg/String'),
                               offered_qos_profiles_for(QoSProfile(depth=10)))
    writer.write(channel, encode_cdr(String(data='a')), 1, 1)
    writer.close()
    information = yaml.safe_load((writer.bag_path / 'metadata.yaml').read_text())
    assert yaml_text(information) == yaml.safe_dump(information, sort_keys=False)
    assert yaml_text(information) == (writer.bag_path / 'metadata.yaml').read_text()
