# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
``mcap_chunk``: Message records packed once into mcap's open chunk, byte for byte mcap's own.

The same message sequences go through mcap 1.6.0's ``Writer.add_message`` and through
``MessageChunk`` (runs of records cut anywhere, chunks ending in and between runs, several
channels, log times out of order, a channel registered between messages, flushes, every
compression), then through ``BagWriter`` with each (bags split by size and by duration): the
files must be identical. ``MessageChunk`` uses mcap's private state, so the pinned version and
that state are checked first, to fail loudly when mcap changes.
"""
from __future__ import annotations

from dataclasses import dataclass
import io
from pathlib import Path
import re

from hypothesis import given, settings
from hypothesis import strategies as st
from linkage_kinematics.bag import writer as writer_module
from linkage_kinematics.bag.definitions import message_definition
from linkage_kinematics.bag.mcap_chunk import (
    message_record,
    MessageChunk,
    record_fields,
    Records,
)
from linkage_kinematics.bag.metadata import offered_qos_profiles_for
from linkage_kinematics.bag.writer import BagWriter
from linkage_kinematics.shared.cdr import encode_cdr
from mcap._chunk_builder import ChunkBuilder
from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer
import pytest
from rclpy.qos import QoSProfile
from std_msgs.msg import String

REPOSITORY = Path(__file__).resolve().parent.parent


def test_mcap_is_the_version_whose_private_state_message_chunk_uses() -> None:
    """A newer mcap must be read again before the pin in requirements.txt moves."""
    assert 'mcap==1.6.0' in (REPOSITORY / 'requirements.txt').read_text().splitlines()
    from mcap.writer import __version__
    assert __version__ == '1.6.0', f'mcap {__version__}: check mcap_chunk against its writer'
    writer = Writer(io.BytesIO())
    assert type(writer._Writer__chunk_builder) is ChunkBuilder
    assert callable(writer._Writer__finalize_chunk)
    assert writer._Writer__statistics.message_count == 0
    chunk = MessageChunk.attach(writer, 1024)
    assert writer._Writer__chunk_builder is chunk


def test_attach_refuses_a_writer_it_cannot_take_the_chunk_of() -> None:
    unchunked = Writer(io.BytesIO(), use_chunking=False)
    with pytest.raises(RuntimeError, match=re.escape('mcap==1.6.0')):
        MessageChunk.attach(unchunked, 1024)
    started = Writer(io.BytesIO())
    started.start()
    started.register_schema('s', 'ros2msg', b'x')  # the schema record is in the open chunk
    with pytest.raises(RuntimeError, match='chunk builder'):
        MessageChunk.attach(started, 1024)


@dataclass(frozen=True)
class Step:
    """One thing written: a message (channel index, log time, size), a new channel, a flush."""

    kind: str
    channel: int = 0
    log_time: int = 0
    size: int = 0
    cut: bool = False  # a message that starts a new run of records


def _data(step: Step, index: int) -> bytes:
    return bytes((index + offset) % 256 for offset in range(step.size))


def _write(steps: list[Step], chunk_size: int, compression: CompressionType,
           fast: bool) -> tuple[bytes, int]:
    """Return the file ``steps`` make and its chunk count: by add_message or runs of records."""
    stream = io.BytesIO()
    writer = Writer(stream, chunk_size=chunk_size, compression=compression)
    chunk = MessageChunk.attach(writer, chunk_size) if fast else None
    writer.start(profile='ros2', library='test')
    writer.add_metadata('run', {'a': 'b'})
    schema_id = writer.register_schema('std_msgs/msg/String', 'ros2msg', b'string data')
    channel_ids = [writer.register_channel(f'/topic{n}', 'cdr', schema_id) for n in range(2)]
    run: list[bytes] = []
    run_times: list[int] = []
    counts: dict[int, int] = {}

    def add_run() -> None:
        if run:
            records = b''.join(run)
            assert chunk is not None
            assert chunk.add_records(records, 0, len(records), counts) == run_times
            run.clear()
            run_times.clear()

    for index, step in enumerate(steps):
        if step.kind == 'message':
            channel_id = channel_ids[step.channel % len(channel_ids)]
            data = _data(step, index)
            if not fast:
                writer.add_message(channel_id, step.log_time, data, step.log_time + 7)
                continue
            if step.cut:
                add_run()
            run.append(message_record(channel_id, step.log_time, step.log_time + 7, data))
            run_times.append(step.log_time)
            continue
        add_run()
        if step.kind == 'channel':
            channel_ids.append(writer.register_channel(
                f'/topic{len(channel_ids)}', 'cdr', schema_id, {'k': 'v'}))
        else:
            writer.flush()
    add_run()
    writer.finish()
    if fast:
        assert sum(counts.values()) == sum(step.kind == 'message' for step in steps)
    stream.seek(0)
    summary = make_reader(stream).get_summary()
    return stream.getvalue(), len(summary.chunk_indexes)


messages = st.builds(Step, kind=st.just('message'), channel=st.integers(0, 7),
                     log_time=st.integers(0, 10_000), size=st.integers(0, 300),
                     cut=st.booleans())
steps_strategy = st.lists(st.one_of(messages, messages, messages, messages,
                                    st.builds(Step, kind=st.sampled_from(['channel', 'flush']))),
                          max_size=120)


@settings(max_examples=150, deadline=None)
@given(steps=steps_strategy, chunk_size=st.sampled_from([1, 200, 700, 4096, 1 << 20]),
       compression=st.sampled_from(list(CompressionType)))
def test_runs_of_records_write_the_bytes_of_mcap_add_message(
        steps: list[Step], chunk_size: int, compression: CompressionType) -> None:
    expected, chunks = _write(steps, chunk_size, compression, fast=False)
    assert _write(steps, chunk_size, compression, fast=True) == (expected, chunks)


def test_chunks_end_inside_runs_as_add_message_ends_them() -> None:
    """The case the property test must cover: many chunks, runs cut across their boundaries."""
    steps = [Step('message', channel=index % 3, log_time=(index * 7919) % 1000,
                  size=index % 97, cut=index % 11 == 0) for index in range(400)]
    steps[150:150] = [Step('channel'), Step('flush')]
    expected, chunks = _write(steps, 500, CompressionType.ZSTD, fast=False)
    assert chunks >= 50
    assert _write(steps, 500, CompressionType.ZSTD, fast=True) == (expected, chunks)


def test_a_chunk_of_exactly_chunk_size_bytes_stays_open_as_add_message_keeps_it() -> None:
    """Records of 51 bytes and 51 chunk sizes in a row: one of them is reached exactly."""
    steps = [Step('message', channel=index % 2, log_time=index, size=20, cut=index % 5 == 0)
             for index in range(40)]
    for chunk_size in range(300, 351):
        expected = _write(steps, chunk_size, CompressionType.NONE, fast=False)
        assert _write(steps, chunk_size, CompressionType.NONE, fast=True) == expected


def test_a_record_of_an_unknown_channel_is_refused_after_those_before_it() -> None:
    def file(count: int, fast: bool) -> bytes:
        stream = io.BytesIO()
        writer = Writer(stream, chunk_size=100)
        chunk = MessageChunk.attach(writer, 100) if fast else None
        writer.start()
        channel_id = writer.register_channel('/a', 'cdr', 0)
        if fast:
            assert chunk is not None
            records = b''.join([message_record(channel_id, n, n, b'x' * 40) for n in range(3)]
                               + [message_record(9, 3, 3, b'y')])
            with pytest.raises(ValueError, match='unknown channel id 9'):
                chunk.add_records(records, 0, len(records), {})
        else:
            for n in range(count):
                writer.add_message(channel_id, n, b'x' * 40, n)
        writer.finish()
        return stream.getvalue()

    assert file(3, fast=True) == file(3, fast=False)


# --- BagWriter: with MessageChunk and with mcap's add_message -------------------------------


class _AddMessageChunk:
    """The open chunk through mcap's own ``Writer.add_message``, one message at a time."""

    def __init__(self, writer: Writer) -> None:
        self._writer = writer

    @classmethod
    def attach(cls, writer: Writer, chunk_size: int) -> _AddMessageChunk:
        return cls(writer)

    def add(self, channel_id: int, log_time_ns: int, data: bytes, publish_time_ns: int,
            counts: dict[int, int]) -> None:
        record = message_record(channel_id, log_time_ns, publish_time_ns, data)
        self.add_records(record, 0, len(record), counts)

    def add_records(self, records: Records, start: int, end: int,
                    counts: dict[int, int]) -> list[int]:
        log_times = []
        while start < end:
            next_start, channel_id, log_time_ns, publish_time_ns, data_start = record_fields(
                records, start)
            data = bytes(records[data_start:next_start])
            self._writer.add_message(channel_id, log_time_ns, data, publish_time_ns)
            counts[channel_id] = counts.get(channel_id, 0) + 1
            log_times.append(log_time_ns)
            start = next_start
        return log_times


def _bag(folder: Path, **split: int) -> dict[str, bytes]:
    """Write one message sequence into a bag; return its files' bytes by name."""
    folder.parent.mkdir()
    writer = BagWriter(folder, metadata={'run': 'x'}, chunk_size=2000, flush_interval=3600.0,
                       **split)
    qos = offered_qos_profiles_for(QoSProfile(depth=10))
    definition = message_definition('std_msgs/msg/String')
    latched = writer.add_topic('/latched', 'std_msgs/msg/String', definition, qos, True)
    data = writer.add_topic('/data', 'std_msgs/msg/String', definition, qos)
    writer.write(latched, encode_cdr(String(data='first')), 1_000, 1_000)
    pending: list[bytes] = []
    for index in range(600):
        payload = encode_cdr(String(data='d' * (index % 50)))
        # out of order within a few messages, as messages of several sources arrive
        log_time = 1_000 + 1_000 * index - 2_500 * (index % 4 == 3)
        if index % 3:
            pending.append(message_record(data, log_time, log_time, payload))
        else:
            writer.write(data, payload, log_time, log_time)
        if index % 40 == 39:
            writer.write_records(b''.join(pending))
            pending.clear()
        if index == 300:
            writer.write(latched, encode_cdr(String(data='second')), log_time, log_time)
            writer.add_topic('/late', 'std_msgs/msg/String', definition, qos)
            writer.flush()
    writer.write_records(b''.join(pending))
    writer.close()
    return {path.name: path.read_bytes() for path in sorted(folder.iterdir())}


@pytest.mark.parametrize('split', [{}, {'max_bag_size': 5000}, {'max_bag_duration_ns': 90_000}])
def test_a_bag_is_the_bag_mcap_add_message_writes(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, split: dict[str, int]) -> None:
    # the same folder name: the files name each other (metadata.yaml, the rosbag2 record)
    fast = _bag(tmp_path / 'fast' / 'run', **split)
    monkeypatch.setattr(writer_module, 'MessageChunk', _AddMessageChunk)
    expected = _bag(tmp_path / 'add_message' / 'run', **split)
    assert fast.keys() == expected.keys()
    mcap_files = [name for name in fast if name.endswith('.mcap')]
    assert (len(mcap_files) == 1) == (not split)
    assert len(mcap_files) >= (4 if split else 1)
    for name in mcap_files:
        assert fast[name] == expected[name], name
    assert fast['metadata.yaml'] == expected['metadata.yaml']
