# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
What the node's log survives.

SIGKILL (and the documented recovery), SIGINT/SIGTERM, a log folder that cannot be created, a bag
name already taken, and a disk that fills during the run.
"""
from __future__ import annotations

from collections.abc import Iterator
import contextlib
import hashlib
import os
from pathlib import Path
import resource
import signal
import subprocess
import sys
import time
from typing import Any

from bag_files import (
    bag_information,
    listen_to_node_topics,
    LOGGED_TOPICS,
    only_bag,
    read_with_rosbags,
    stopped,
    topic_counts,
)
from diagnostic_msgs.msg import DiagnosticStatus
from linkage_kinematics.bag import reader as bag_reader
from mcap.exceptions import EndOfFile
from mcap.reader import make_reader
from mcap.records import Channel, Message
from mcap.stream_reader import StreamReader
from node_process import (
    bag_writer_pid,
    Listener,
    NodeProcesses,
    PROCESS_TIMEOUT,
    REPOSITORY,
    ros_context,
    ros_environment,
    stamp_ns,
    TYPESTORE,
)
import pytest
from rosbags.rosbag2 import Reader

LOOP_PARAMETERS = {'rate_hz': 200.0, 'end_behavior': 'loop'}


@pytest.fixture(autouse=True)
def udp_only(monkeypatch: pytest.MonkeyPatch) -> None:
    """
    Run this module's nodes and listeners over UDP only.

    These tests kill processes on purpose; Fast DDS's shared-memory transport can crash a peer
    that tears down after another was killed (eProsima/Fast-DDS#5469, #6501 and others; seen
    once here as a segfault in the listener's destroy_node), so the killed processes and their
    peers keep out of shared memory. What is tested, the bag, does not depend on the transport.
    """
    monkeypatch.setenv('FASTDDS_BUILTIN_TRANSPORTS', 'UDPv4')


# The bag writer's flush interval (1 s) plus one tick and scheduling slack.
MAX_LOSS_AT_KILL_NS = 1_500_000_000
# The node's last batch (at most 16 KiB and 50 ms old) plus scheduling slack.
MAX_LOSS_AT_NODE_KILL_NS = 500_000_000
# A second's chunk of a 1 kHz run (about 260 KB with /tf) fits, the next one does not.
FILE_SIZE_LIMIT_BYTES = 512 * 1024


@contextlib.contextmanager
def node_with_listener(
    nodes: NodeProcesses, parameters: dict[str, Any], output: Path, **start_options: Any
) -> Iterator[tuple[Listener, subprocess.Popen]]:
    """
    Return a node process (``NodeProcesses.start``'s arguments) and a listener to all its topics.

    The listener is destroyed on leaving; the node at the latest after the test (``nodes``).
    """
    with ros_context(nodes.domain_id) as context:
        listener = listen_to_node_topics(context, 'faults_listener')
        process = nodes.start(parameters, output, **start_options)
        try:
            yield listener, process
        finally:
            listener.destroy()


def wait_for_bag(folder: Path, process: subprocess.Popen, timeout: float = 20.0) -> Path:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        mcap_files = list(folder.glob('*/*.mcap'))
        if mcap_files:
            return mcap_files[0].parent
        assert process.poll() is None, f'the node ended with status {process.returncode}'
        time.sleep(0.05)
    raise AssertionError(f'no bag appeared in {folder}')


def stream_records(mcap_path: Path) -> tuple[dict[int, str], list[Message]]:
    """
    Return channel topics by id and the messages an mcap streaming reader gets from the file.

    The streaming reader needs no summary and reads the file as it is: a running or killed
    recorder's file ends after its last complete chunk, without footer.
    """
    topics: dict[int, str] = {}
    messages: list[Message] = []
    with open(mcap_path, 'rb') as stream:
        try:
            for record in StreamReader(stream, validate_crcs=True).records:
                if isinstance(record, Channel):
                    topics[record.id] = record.topic
                elif isinstance(record, Message):
                    messages.append(record)
        except EndOfFile:
            pass
    return topics, messages


def stream_topics(mcap_path: Path) -> set[str]:
    """Return the topics of the messages in the complete chunks of a recorder's file so far."""
    topics, messages = stream_records(mcap_path)
    return {topics[message.channel_id] for message in messages}


def recover(bag: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, '-m', 'linkage_kinematics.cli.replay', '--recover', str(bag)],
        cwd=REPOSITORY, env=ros_environment(35), capture_output=True, text=True, timeout=60,
    )


def kill_once_every_topic_is_logged(nodes: NodeProcesses, tmp_path: Path, folder: Path,
                                    kill_writer: bool) -> tuple[Path, int, int]:
    """
    Run a logging node until complete chunks hold every topic, then SIGKILL it.

    A listener must have heard them all too; the bag writer is killed first if ``kill_writer``.
    Return the bag, the stamp of the last /joint_states heard and the wall time of the kill (ns).
    """
    with node_with_listener(
        nodes, {**LOOP_PARAMETERS, 'log.folder': str(folder)}, tmp_path / 'node.log'
    ) as (listener, process):
        bag = wait_for_bag(folder, process)
        (mcap_path,) = bag.glob('*.mcap')
        assert listener.spin_until(
            lambda: listener.heard_every_topic()
            and stream_topics(mcap_path) == set(LOGGED_TOPICS)
        ), (tmp_path / 'node.log').read_text()
        last_heard_ns = stamp_ns(listener.received['/joint_states'][-1])
        killed_at_ns = time.time_ns()
        if kill_writer:
            writer = bag_writer_pid(process.pid)
            os.kill(writer, signal.SIGKILL)
            wait_until_gone(writer)
        process.kill()
        process.wait(timeout=PROCESS_TIMEOUT)
    return bag, last_heard_ns, killed_at_ns


def wait_until_gone(pid: int) -> None:
    deadline = time.monotonic() + PROCESS_TIMEOUT
    while Path(f'/proc/{pid}').exists() and b') Z' not in Path(f'/proc/{pid}/stat').read_bytes():
        assert time.monotonic() < deadline, f'process {pid} still runs'
        time.sleep(0.05)


def test_sigkill_of_the_node_leaves_a_finished_bag_with_all_it_handed_over(
    nodes: NodeProcesses, tmp_path: Path,
) -> None:
    """
    Return the bag writer outlives a killed node.

    It writes what the node handed over (all but the last batch of at most 16 KiB or 50 ms),
    the summary and the final metadata.yaml.
    """
    folder = tmp_path / 'bags'
    bag, last_heard_ns, killed_at_ns = kill_once_every_topic_is_logged(
        nodes, tmp_path, folder, kill_writer=False)
    deadline = time.monotonic() + PROCESS_TIMEOUT
    while bag_reader.bag_files(bag)[0].truncated or not bag_information(bag)['message_count']:
        assert time.monotonic() < deadline, 'the bag writer did not finish the bag'
        time.sleep(0.1)

    logged = list(bag_reader.iter_messages(bag))
    assert {message.topic for message in logged} == set(LOGGED_TOPICS)
    assert last_heard_ns - MAX_LOSS_AT_NODE_KILL_NS < logged[-1].log_time_ns < killed_at_ns
    with open(bag_reader.bag_files(bag)[0].path, 'rb') as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None and summary.statistics.message_count == len(logged)
    information = bag_information(bag)
    assert information['message_count'] == len(logged)
    by_rosbags = read_with_rosbags(bag)
    assert topic_counts(information) == {topic: len(entries)
                                         for topic, entries in by_rosbags.items()}


def test_sigkill_of_node_and_writer_keeps_complete_chunks_and_recovery_completes_the_bag(
    nodes: NodeProcesses, tmp_path: Path,
) -> None:
    folder = tmp_path / 'bags'
    bag, last_heard_ns, killed_at_ns = kill_once_every_topic_is_logged(
        nodes, tmp_path, folder, kill_writer=True)

    (mcap_file,) = bag_reader.bag_files(bag)
    assert mcap_file.truncated
    survivors = list(bag_reader.iter_messages(bag))
    assert len(survivors) == len(stream_records(mcap_file.path)[1])
    assert {message.topic for message in survivors} == set(LOGGED_TOPICS)
    for message in survivors:
        TYPESTORE.deserialize_cdr(message.data, message.schema_name)
    # What the writer had flushed before the kill is kept up to the last chunk.
    assert last_heard_ns - MAX_LOSS_AT_KILL_NS < survivors[-1].log_time_ns < killed_at_ns

    recovery = recover(bag)
    assert recovery.returncode == 0, recovery.stderr
    assert f'({len(survivors)} messages)' in recovery.stdout
    with open(mcap_file.path, 'rb') as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None and summary.statistics.message_count == len(survivors)
    logged = read_with_rosbags(bag)
    assert sum(len(entries) for entries in logged.values()) == len(survivors)
    information = bag_information(bag)
    assert information['message_count'] == len(survivors)
    assert topic_counts(information) == {topic: len(entries) for topic, entries in logged.items()}
    assert [(m.topic, m.data, m.log_time_ns) for m in bag_reader.iter_messages(bag)] == [
        (m.topic, m.data, m.log_time_ns) for m in survivors
    ]
    assert information['custom_data']['parameters']


@pytest.mark.parametrize('stop_signal', [signal.SIGINT, signal.SIGTERM], ids=['SIGINT', 'SIGTERM'])
def test_sigint_and_sigterm_finalize_the_bag(
    nodes: NodeProcesses, tmp_path: Path, stop_signal: signal.Signals
) -> None:
    folder = tmp_path / 'bags'
    with node_with_listener(
        nodes, {**LOOP_PARAMETERS, 'log.folder': str(folder)}, tmp_path / 'node.log'
    ) as (listener, process):
        bag = wait_for_bag(folder, process)
        assert listener.wait_for_every_topic(), (tmp_path / 'node.log').read_text()
        assert nodes.interrupt(process, stop_signal) == 0, (tmp_path / 'node.log').read_text()

    (mcap_file,) = bag_reader.bag_files(bag)
    assert mcap_file.complete
    with open(mcap_file.path, 'rb') as stream:
        summary = make_reader(stream).get_summary()
    logged = read_with_rosbags(bag)
    information = bag_information(bag)
    total = sum(len(entries) for entries in logged.values())
    assert summary.statistics.message_count == information['message_count'] == total > 0
    counts = topic_counts(information)
    assert counts == {topic: len(entries) for topic, entries in logged.items()}
    assert set(counts) == set(LOGGED_TOPICS)


def test_log_folder_that_cannot_be_created_stops_the_node_before_publishing(
        nodes: NodeProcesses, tmp_path: Path) -> None:
    # chmod does not stop root; a path under a regular file fails for everyone.
    blocker = tmp_path / 'afile'
    blocker.write_text('not a folder')
    folder = blocker / 'bags'
    with node_with_listener(
        nodes, {**LOOP_PARAMETERS, 'log.folder': str(folder)}, tmp_path / 'node.log'
    ) as (listener, process):
        assert listener.spin_until(stopped(process))
        listener.spin_until(lambda: False, timeout=1.0)  # anything published arrives by now
    output = (tmp_path / 'node.log').read_text()
    assert process.returncode != 0
    assert str(folder) in output
    assert 'Traceback' not in output
    assert all(not messages for messages in listener.received.values())
    assert blocker.read_text() == 'not a folder'


def test_a_taken_bag_name_gets_a_new_name_and_the_old_bag_stays_identical(
    nodes: NodeProcesses, tmp_path: Path
) -> None:
    folder = tmp_path / 'bags'
    folder.mkdir()
    now = time.time()
    taken = {}
    # Every name the node could pick in the next seconds is already a bag.
    for offset in range(-2, 30):
        name = time.strftime('rosbag2_%Y_%m_%d-%H_%M_%S', time.localtime(now + offset))
        bag = folder / name
        bag.mkdir(exist_ok=True)
        (bag / f'{name}_0.mcap').write_bytes(hashlib.sha256(name.encode()).digest() * 64)
        (bag / 'metadata.yaml').write_text(f'old run {name}\n')
        taken[name] = {p.name: p.read_bytes() for p in bag.iterdir()}
    status, output = nodes.run(
        {'log.folder': str(folder), 'rate_hz': 200.0, 'omega0': 10.0, 'end_behavior': 'stop'},
        tmp_path / 'node.log'
    )
    assert status == 0, output

    new_bags = [path for path in folder.iterdir() if path.name not in taken]
    assert len(new_bags) == 1
    (new_bag,) = new_bags
    assert new_bag.name.removesuffix('_1') in taken and new_bag.name.endswith('_1')
    assert read_with_rosbags(new_bag)['/linkage/state']
    for name, files in taken.items():
        assert {p.name: p.read_bytes() for p in (folder / name).iterdir()} == files


def test_a_bag_writer_that_dies_turns_diagnostics_to_error_and_publishing_goes_on(
    nodes: NodeProcesses, tmp_path: Path,
) -> None:
    folder = tmp_path / 'bags'
    with node_with_listener(
        nodes, {**LOOP_PARAMETERS, 'log.folder': str(folder)}, tmp_path / 'node.log'
    ) as (listener, process):
        assert listener.wait_for_every_topic(), (tmp_path / 'node.log').read_text()
        writer = bag_writer_pid(process.pid)
        # a batch task: it never preempts the node when a batch wakes it
        assert os.sched_getscheduler(writer) == os.SCHED_BATCH
        os.kill(writer, signal.SIGKILL)
        assert listener.spin_until(lambda: any(
            status.level == DiagnosticStatus.ERROR
            and 'recording stopped' in status.message and 'ended unexpectedly' in status.message
            for array in listener.received['/diagnostics'] for status in array.status
        ))
        states_then = len(listener.received['/linkage/state'])
        assert listener.spin_until(
            lambda: len(listener.received['/linkage/state']) > states_then + 100)
        status = nodes.interrupt(process)
    output = (tmp_path / 'node.log').read_text()
    # The log could not be finalized: status 1, and the one error that says so.
    assert status == 1, output
    assert 'could not finalize the log' in output and 'Traceback' not in output
    assert recover(only_bag(folder)).returncode == 0


def _limit_file_size() -> None:
    # Writes past the limit then fail with EFBIG instead of killing the process with SIGXFSZ.
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (FILE_SIZE_LIMIT_BYTES, FILE_SIZE_LIMIT_BYTES))


def test_a_full_disk_turns_diagnostics_to_error_and_publishing_goes_on(
    nodes: NodeProcesses, tmp_path: Path
) -> None:
    folder = tmp_path / 'bags'

    def recording_failed(got: dict) -> bool:
        return any(
            status.level == DiagnosticStatus.ERROR and 'recording' in status.message
            for array in got.get('/diagnostics', [])
            for status in array.status
        )

    with node_with_listener(
        nodes, {'log.folder': str(folder), 'rate_hz': 1000.0, 'end_behavior': 'loop'},
        tmp_path / 'node.log', preexec_fn=_limit_file_size,
    ) as (listener, process):
        assert listener.spin_until(lambda: recording_failed(listener.received))
        states_at_failure = len(listener.received['/linkage/state'])
        assert listener.spin_until(
            lambda: len(listener.received['/linkage/state']) > states_at_failure + 200
        )
        nodes.interrupt(process)
    output = (tmp_path / 'node.log').read_text()
    assert 'File too large' in output and 'Traceback' not in output

    bag = only_bag(folder)
    (mcap_file,) = bag_reader.bag_files(bag)
    assert mcap_file.size <= FILE_SIZE_LIMIT_BYTES
    kept = list(bag_reader.iter_messages(bag))
    assert len(kept) == bag_information(bag)['message_count'] > 0
    for message in kept:
        TYPESTORE.deserialize_cdr(message.data, message.schema_name)
    recovery = recover(bag)
    assert recovery.returncode == 0, recovery.stderr
    with Reader(bag) as reader:
        assert reader.message_count == len(kept)
