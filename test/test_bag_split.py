# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Long runs: a bag split into files as rosbag2 splits it, each file opened alone.

BagWriter on its own (by duration and by size), then a real node with ``log.max_bag_duration``
and ``log.max_bag_size``. Every file is read by itself with rosbags and with mcap-ros2-support
(independent readers), and must hold the latched topics; metadata.yaml must list every file with
what it holds.
"""

from __future__ import annotations

from collections import Counter
import ctypes
import errno
import os
from pathlib import Path
import select
import time

from bag_files import only_bag
from linkage_kinematics.bag.definitions import message_definition
from linkage_kinematics.bag.errors import BagError
from linkage_kinematics.bag.metadata import (
    BagMetadata,
    offered_qos_profiles_for,
)
from linkage_kinematics.bag.reader import bag_files, iter_messages
from linkage_kinematics.bag.recovery import recover_bag
from linkage_kinematics.bag.writer import BagWriter
from linkage_kinematics.shared.cdr import encode_cdr
from linkage_kinematics.shared.rosbag2_split import MIN_SPLIT_SIZE
from mcap_ros2.reader import read_ros2_messages
from node_process import (
    NodeProcesses,
    PROCESS_TIMEOUT,
    TYPESTORE,
)
import pytest
from rclpy.qos import DurabilityPolicy, QoSProfile
from rosbags.rosbag2 import Reader
from std_msgs.msg import String

# inotify(7): a file created in a watched folder, one renamed into it
IN_CREATE, IN_MOVED_TO = 0x100, 0x80
LATCHED = ('/robot_description', '/tf_static', '/diagnostics')
# the node's topics and the TF robot_state_publisher would publish (logged only)
LOGGED_TOPICS = ('/joint_states', '/linkage/state', '/robot_description', '/linkage/markers',
                 '/diagnostics', '/tf', '/tf_static')


def read_file_alone(path: Path) -> list[tuple[str, int, bytes]]:
    """
    Return (topic, log time, CDR bytes) of every message of one MCAP file, read by rosbags.

    mcap-ros2-support must decode the same messages from the file by itself.
    """
    with Reader(path) as reader:
        logged = [(connection.topic, log_time, bytes(raw))
                  for connection, log_time, raw in reader.messages()]
        for connection, _, raw in reader.messages():
            TYPESTORE.deserialize_cdr(raw, connection.msgtype)
    decoded = [(message.channel.topic, message.log_time_ns)
               for message in read_ros2_messages(str(path))]
    assert sorted(decoded) == sorted((topic, log_time) for topic, log_time, _ in logged)
    return logged


def assert_metadata_lists_every_file(bag: Path) -> list[list[tuple[str, int, bytes]]]:
    """Check metadata.yaml's files against what each file holds; return each file's messages."""
    metadata = BagMetadata.read(bag)
    names = sorted(path.name for path in bag.glob('*.mcap'))
    assert metadata.relative_file_paths == [f'{bag.name}_{index}.mcap'
                                            for index in range(len(names))]
    assert sorted(metadata.relative_file_paths) == names
    assert [file.path for file in metadata.files] == metadata.relative_file_paths
    assert all(part.complete for part in bag_files(bag))
    files = []
    for entry in metadata.files:
        logged = read_file_alone(bag / entry.path)
        log_times = [log_time for _, log_time, _ in logged]
        assert entry.message_count == len(logged)
        assert entry.starting_time_ns == min(log_times)
        assert entry.duration_ns == max(log_times) - min(log_times)
        files.append(logged)
    counts = Counter(topic for logged in files for topic, _, _ in logged)
    assert {topic.name: topic.message_count for topic in metadata.topics} == dict(counts)
    assert metadata.message_count == sum(counts.values())
    first = min(file.starting_time_ns for file in metadata.files)
    last = max(file.starting_time_ns + file.duration_ns for file in metadata.files)
    assert (metadata.starting_time_ns, metadata.duration_ns) == (first, last - first)
    return files


def string_topic(writer: BagWriter, topic: str, latched: bool) -> int:
    qos = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL if latched
                     else DurabilityPolicy.VOLATILE)
    type_name = 'std_msgs/msg/String'
    return writer.add_topic(topic, type_name, message_definition(type_name),
                            offered_qos_profiles_for(qos),
                            repeat_latest=latched)


def test_a_bag_split_by_duration_repeats_the_latched_topic_in_every_file(tmp_path: Path) -> None:
    writer = BagWriter(tmp_path / 'run', metadata={}, max_bag_duration_ns=100)
    latched = string_topic(writer, '/latched', latched=True)
    data = string_topic(writer, '/data', latched=False)
    writer.write(latched, encode_cdr(String(data='first')), 1_000, 1_000)
    for index in range(10):
        writer.write(data, encode_cdr(String(data=f'd{index}')), 1_000 + 50 * index, 7)
        if index == 4:
            writer.write(latched, encode_cdr(String(data='second')), 1_220, 1_220)
    writer.close()
    files = assert_metadata_lists_every_file(writer.bag_path)
    # A file ends before the first message more than 100 ns after its first message.
    assert [[(topic, log_time) for topic, log_time, _ in logged] for logged in files] == [
        [('/latched', 1_000), ('/data', 1_000), ('/data', 1_050), ('/data', 1_100)],
        [('/latched', 1_150), ('/data', 1_150), ('/data', 1_200), ('/latched', 1_220),
         ('/data', 1_250)],
        [('/latched', 1_300), ('/data', 1_300), ('/data', 1_350), ('/data', 1_400)],
        [('/latched', 1_450), ('/data', 1_450)],
    ]
    repeated = [logged[0][2] for logged in files]
    assert repeated == [encode_cdr(String(data=text)) for text in
                        ('first', 'first', 'second', 'second')]
    # the repeats keep their publish time
    publish_times = [m.publish_time_ns for m in iter_messages(writer.bag_path, ['/latched'])]
    assert publish_times == [1_000, 1_000, 1_220, 1_220, 1_220]


def test_a_bag_split_by_size_ends_each_file_once_it_reached_the_size(tmp_path: Path) -> None:
    writer = BagWriter(tmp_path / 'run', metadata={}, chunk_size=256,
                       max_bag_size=MIN_SPLIT_SIZE, compression='none')
    data = string_topic(writer, '/data', latched=False)
    written = [encode_cdr(String(data=f'{index:0>100}')) for index in range(100)]
    for index, payload in enumerate(written):
        writer.write(data, payload, 1_000 + index, 1_000 + index)
    sizes_before_close = [path.stat().st_size for path in sorted(writer.bag_path.glob('*.mcap'))]
    writer.close()
    files = assert_metadata_lists_every_file(writer.bag_path)
    assert len(files) >= 3
    # every file but the open one had reached the size when the next one began
    assert all(size >= MIN_SPLIT_SIZE for size in sizes_before_close[:-1])
    assert [raw for logged in files for _, _, raw in logged] == written


def test_a_next_file_that_cannot_be_opened_ends_the_bag_with_the_finished_file(
        tmp_path: Path) -> None:
    """
    Something already has the next file's name: the bag stops there and loses nothing.

    A directory in its place makes the open fail for root too. The file before it stays
    complete and is listed once, with what it holds; the error names the next file and why.
    """
    writer = BagWriter(tmp_path / 'run', metadata={}, max_bag_duration_ns=100)
    latched = string_topic(writer, '/latched', latched=True)
    data = string_topic(writer, '/data', latched=False)
    blocker = writer.bag_path / 'run_1.mcap'
    blocker.mkdir()
    writer.write(latched, encode_cdr(String(data='first')), 1_000, 1_000)
    for index in range(10):
        writer.write(data, encode_cdr(String(data=f'd{index}')), 1_000 + 50 * index, 7)
    with pytest.raises(BagError) as raised:
        writer.flush()  # the message at 1_150 starts the next file
    assert str(raised.value) == (
        f'cannot open {blocker}, the next file of bag {writer.bag_path} '
        f'({os.strerror(errno.EEXIST)}); the bag ends with run_0.mcap, complete')
    with pytest.raises(BagError, match='stopped at an earlier error: cannot open .*run_1.mcap'):
        writer.write(data, encode_cdr(String(data='later')), 2_000, 7)
    writer.close()
    finished = writer.bag_path / 'run_0.mcap'
    assert writer.size_bytes == writer.finished_size() == finished.stat().st_size
    assert blocker.is_dir() and not any(blocker.iterdir())  # not written into, not deleted
    blocker.rmdir()
    (logged,) = assert_metadata_lists_every_file(writer.bag_path)
    assert [(topic, log_time) for topic, log_time, _ in logged] == [
        ('/latched', 1_000), ('/data', 1_000), ('/data', 1_050), ('/data', 1_100)]


def test_recovery_completes_every_file_of_a_split_bag(tmp_path: Path) -> None:
    """A writer that never closes (killed): its last file has no summary until recovered."""
    writer = BagWriter(tmp_path / 'run', metadata={'run': 'killed'}, max_bag_duration_ns=100)
    latched = string_topic(writer, '/latched', latched=True)
    data = string_topic(writer, '/data', latched=False)
    writer.write(latched, encode_cdr(String(data='first')), 1_000, 1_000)
    for index in range(10):
        writer.write(data, encode_cdr(String(data=f'd{index}')), 1_000 + 50 * index, 7)
    writer.flush()
    bag = writer.bag_path
    assert [part.complete for part in bag_files(bag)] == [True, True, True, False]
    before = [(m.topic, m.data, m.log_time_ns) for m in iter_messages(bag)]
    result = recover_bag(bag)
    assert (result.message_count, result.was_truncated) == (len(before), True)
    assert result.mcap_paths == [part.path for part in bag_files(bag)]
    assert [(m.topic, m.data, m.log_time_ns) for m in iter_messages(bag)] == before
    assert len(assert_metadata_lists_every_file(bag)) == 4
    assert BagMetadata.read(bag).custom_data['run'] == 'killed'


def test_a_node_splits_its_bag_by_duration_and_every_file_opens_alone(
    nodes: NodeProcesses, tmp_path: Path
) -> None:
    """The seed's 0.785 s turn in files of 0.2 s: each holds the URDF and a status."""
    folder = tmp_path / 'bags'
    status, output = nodes.run(
        {'log.folder': str(folder), 'log.max_bag_duration': 0.2, 'rate_hz': 200.0,
         'end_behavior': 'stop'}, tmp_path / 'node.log')
    assert status == 0, output
    bag = only_bag(folder)
    files = assert_metadata_lists_every_file(bag)
    assert len(files) in (3, 4), [len(logged) for logged in files]  # 0.785 s in files of > 0.2 s
    with Reader(bag) as reader:  # rosbags reads the bag as a whole, too
        assert reader.message_count == sum(1 for _ in reader.messages()) == sum(map(len, files))
    (description,) = [raw for topic, _, raw in files[0] if topic == '/robot_description']
    for logged in files:
        log_times = [log_time for _, log_time, _ in logged]
        assert log_times == sorted(log_times)
        assert log_times[-1] - log_times[0] <= 200_000_000
        topics = Counter(topic for topic, _, _ in logged)
        assert set(topics) == set(LOGGED_TOPICS), topics
        assert topics['/robot_description'] == topics['/tf_static'] == 1
        assert [raw for topic, _, raw in logged if topic == '/robot_description'] == [
            description]
    # the states of all files are the run's, once each, in order
    stamps = [TYPESTORE.deserialize_cdr(raw, 'trajectory_msgs/msg/JointTrajectory').header.stamp
              for logged in files for topic, _, raw in logged if topic == '/linkage/state']
    nanoseconds = [stamp.sec * 1_000_000_000 + stamp.nanosec for stamp in stamps]
    assert nanoseconds == sorted(set(nanoseconds))
    assert nanoseconds[-1] - nanoseconds[0] == round(0.5 * 3.141592653589793 / 2.0 * 1e9)


def wait_for_listed_files(folder: Path, count: int, timeout: float = PROCESS_TIMEOUT) -> bool:
    """
    Wait until the metadata.yaml of a bag in ``folder`` lists ``count`` files; whether it did.

    Woken by inotify when the bag folder is made in ``folder`` and whenever the bag writer
    replaces metadata.yaml (a rename into the bag folder, ``BagMetadata.write``: at each file it
    begins). Each folder is watched before it is read, so that no change goes unseen.
    """
    libc = ctypes.CDLL(None, use_errno=True)
    libc.inotify_add_watch.argtypes = (ctypes.c_int, ctypes.c_char_p, ctypes.c_uint32)
    events = libc.inotify_init1(os.O_CLOEXEC)
    assert events >= 0, os.strerror(ctypes.get_errno())
    watched: set[Path] = set()

    def watch(path: Path, mask: int) -> None:
        assert libc.inotify_add_watch(events, os.fsencode(path), mask) >= 0, (
            path, os.strerror(ctypes.get_errno()))
        watched.add(path)

    def listed() -> bool:
        for bag in (path for path in folder.iterdir() if path.is_dir()):
            if bag not in watched:
                watch(bag, IN_MOVED_TO)
            if ((bag / 'metadata.yaml').exists()
                    and len(BagMetadata.read(bag).relative_file_paths) >= count):
                return True
        return False

    deadline = time.monotonic() + timeout
    try:
        watch(folder, IN_CREATE)
        while not listed():
            remaining = deadline - time.monotonic()
            if remaining <= 0.0 or not select.select([events], [], [], remaining)[0]:
                return listed()
            os.read(events, 65536)  # what changed is read from the folders themselves
        return True
    finally:
        os.close(events)


def test_a_node_splits_its_bag_by_size(nodes: NodeProcesses, tmp_path: Path) -> None:
    """
    A looping node in files of 4 KiB: split at each flushed chunk.

    Not the 1 KiB minimum: a file's preamble (schemas, channels and the run's parameters) is
    above 1 KiB, so there every message would start a file before the status was logged once.
    """
    folder = tmp_path / 'bags'
    folder.mkdir()
    process = nodes.start(
        {'log.folder': str(folder), 'log.max_bag_size': 4 * MIN_SPLIT_SIZE, 'rate_hz': 200.0,
         'end_behavior': 'loop'}, tmp_path / 'node.log')
    assert wait_for_listed_files(folder, 3), (tmp_path / 'node.log').read_text()
    assert nodes.interrupt(process) == 0, (tmp_path / 'node.log').read_text()
    files = assert_metadata_lists_every_file(only_bag(folder))
    assert len(files) >= 3
    for logged in files:
        topics = Counter(topic for topic, _, _ in logged)
        assert topics['/robot_description'] == 1 and topics['/diagnostics'] >= 1, topics
