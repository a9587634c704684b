# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
rosbag2-compatible MCAP bags (Jazzy, metadata version 9) from already-serialized CDR bytes.

A bag is a folder ``<name>/`` holding ``<name>_0.mcap`` and ``metadata.yaml``, as ``ros2 bag
record -s mcap`` makes it, so ``ros2 bag play <name>``, ``ros2 bag info``, Foxglove, rosbags and
mcap-ros2-support all read it. The MCAP file uses the ``ros2`` profile: schemas are the full
``ros2msg`` text with every dependent definition, channels carry ``cdr`` messages and the
``offered_qos_profiles`` / ``topic_type_hash`` metadata rosbag2 expects.

Splitting, as rosbag2's ``--max-bag-size`` and ``--max-bag-duration`` split: before each
message, the file is ended if its size has reached ``max_bag_size`` bytes or the message is more
than ``max_bag_duration_ns`` after the file's first message, and the message starts the next
file, ``<name>_1.mcap``, ``<name>_2.mcap``, …; metadata.yaml lists every file with its own
start, duration and count. Each file is a complete MCAP file with every schema and channel, and
it starts with the latest message of each topic added with ``repeat_latest`` (what rosbag2
later named ``--repeat-transient-local``), logged at the time of the file's first message, so
that every file opens alone.

Messages go into the open chunk as Message records packed once (``mcap_chunk``; mcap's
writer writes all else), from ``write`` or, as the bag writer's node packs them, ``write_records``.

Crash safety: the Python mcap writer keeps the open chunk in memory until it is full (and this
writer queues up to ``WRITE_BATCH`` messages before adding them to it), so the writer also ends
the chunk and flushes the OS file once ``flush_interval`` has passed; a killed process loses at
most that much. ``metadata.yaml`` exists from the start (so a killed run's folder is already a
bag folder), is rewritten when a file is added and gets its final counts on ``close()``.
``recovery.recover_bag`` (``linkage-replay --recover BAG``) rewrites a file without summary
into a complete one.

This module is plain Python (no rclpy): bytes in, files out.
"""
from __future__ import annotations

from collections.abc import Collection, Iterable, Mapping
import os
from pathlib import Path
import time
from typing import Any, BinaryIO

from linkage_kinematics.bag.definitions import SCHEMA_ENCODING, type_description_hash
from linkage_kinematics.bag.errors import BagError, BagExistsError
from linkage_kinematics.bag.mcap_chunk import message_record, MessageChunk, record_fields, Records
from linkage_kinematics.bag.metadata import (
    BagMetadata,
    FileInfo,
    MESSAGE_ENCODING,
    METADATA_FILE,
    PACKAGE_NAME,
    package_version,
    qos_profiles_yaml,
    TopicInfo,
)
from linkage_kinematics.bag.repeated import RepeatedTopics
from linkage_kinematics.shared.rosbag2_split import MIN_SPLIT_SIZE, NO_SPLIT
from mcap.data_stream import RecordBuilder
from mcap.opcode import Opcode
from mcap.records import (
    Channel,
    ChunkIndex,
    DataEnd,
    Footer,
    McapRecord,
    Metadata,
    MetadataIndex,
    Schema,
    Statistics,
    SummaryOffset,
)
from mcap.writer import CompressionType, LIBRARY_IDENTIFIER, MCAP0_MAGIC, Writer

METADATA_RECORD_NAME = PACKAGE_NAME
ROSBAG2_METADATA_RECORD_NAME = 'rosbag2'
PROFILE = 'ros2'
DEFAULT_CHUNK_SIZE = 1024 * 1024
# Messages ``write`` queues before they go into the MCAP chunk together (a run of records
# costs less per message than one).
WRITE_BATCH = 16
_COMPRESSION = {
    'zstd': CompressionType.ZSTD, 'lz4': CompressionType.LZ4, 'none': CompressionType.NONE
}
# The compression a chunk (index) names, as mcap writes it.
_CHUNK_COMPRESSION = {CompressionType.ZSTD: 'zstd', CompressionType.LZ4: 'lz4',
                      CompressionType.NONE: ''}


def _record_size(record: McapRecord) -> int:
    """Return the bytes mcap writes for ``record``."""
    builder = RecordBuilder()
    record.write(builder)
    return builder.count


def _check_options(metadata: Mapping[str, str], compression: str, chunk_size: int,
                   flush_interval: float, max_bag_size: int, max_bag_duration_ns: int) -> None:
    """Raise ValueError (TypeError) for an option BagWriter cannot write with."""
    if compression not in _COMPRESSION:
        raise ValueError(
            f'compression must be one of {sorted(_COMPRESSION)}, not {compression!r}'
        )
    not_text = [key for key, value in metadata.items() if not isinstance(value, str)]
    if not_text:
        raise TypeError(f'bag metadata values must be strings; not so for {not_text}')
    if chunk_size <= 0 or flush_interval <= 0:
        raise ValueError('chunk_size and flush_interval must be positive')
    if max_bag_size != NO_SPLIT and max_bag_size < MIN_SPLIT_SIZE:
        raise ValueError(f'max_bag_size must be 0 (no split) or at least {MIN_SPLIT_SIZE}')
    if max_bag_duration_ns < 0:
        raise ValueError('max_bag_duration_ns must be 0 (no split) or positive')


class _Span:
    """The count and log-time range of some messages (a file's, the bag's)."""

    __slots__ = ('start_ns', 'end_ns', 'count')

    def __init__(self) -> None:
        self.start_ns: int | None = None
        self.end_ns = 0
        self.count = 0

    def add(self, log_times: list[int]) -> None:
        if not log_times:
            return
        low, high = min(log_times), max(log_times)
        self.start_ns = low if self.start_ns is None else min(self.start_ns, low)
        self.end_ns = max(self.end_ns, high)
        self.count += len(log_times)

    def absorb(self, other: _Span) -> None:
        if other.start_ns is not None:
            self.start_ns = (other.start_ns if self.start_ns is None
                             else min(self.start_ns, other.start_ns))
            self.end_ns = max(self.end_ns, other.end_ns)
        self.count += other.count

    @property
    def duration_ns(self) -> int:
        return self.end_ns - self.start_ns if self.start_ns is not None else 0


class _McapFile:
    """
    One MCAP file of a bag being written: header, the run's metadata, schemas and channels.

    ``flushed`` spans the messages handed to the OS (``durable_size`` bytes), ``pending`` those
    in the open chunk since.
    """

    def __init__(self, path: Path, custom_data: dict[str, str],
                 topics: Iterable[tuple[TopicInfo, str]], chunk_size: int,
                 compression: CompressionType) -> None:
        """
        Create ``path`` and start it with every topic of ``topics`` (info, definition).

        The file must not exist: the writer never overwrites anything. If it cannot be started,
        the half-made file is deleted (it is this writer's own) and the error raised.
        """
        self.path = path
        self.durable_size = 0
        self.flushed = _Span()
        self.pending = _Span()
        self.new_messages = 0  # besides the repeated ones it starts with
        self._compression = _CHUNK_COMPRESSION[compression]
        # Bytes of the schema and channel records, which the summary repeats.
        self._registered_size = 0
        self._schema_ids: dict[str, int] = {}
        self.stream: BinaryIO = open(path, 'xb')
        try:
            self.writer = Writer(self.stream, chunk_size=chunk_size, compression=compression)
            self.chunk = MessageChunk.attach(self.writer, chunk_size)
            self.writer.start(
                profile=PROFILE,
                library=f'{PACKAGE_NAME}/{package_version()} {LIBRARY_IDENTIFIER}',
            )
            self.writer.add_metadata(METADATA_RECORD_NAME, custom_data)
            self.stream.flush()
            self.durable_size = self.stream.tell()
            for info, definition in topics:
                self.register(info, definition)
        except OSError:
            self._delete()
            raise

    def register(self, info: TopicInfo, definition: str) -> int:
        """Add the channel (and if new, the schema) of a topic; its channel id."""
        schema_id = self._schema_ids.get(info.type_name)
        if schema_id is None:
            data = definition.encode('utf-8')
            schema_id = self.writer.register_schema(info.type_name, SCHEMA_ENCODING, data)
            self._schema_ids[info.type_name] = schema_id
            self._registered_size += _record_size(
                Schema(id=schema_id, data=data, encoding=SCHEMA_ENCODING, name=info.type_name))
        channel_metadata = {'offered_qos_profiles': qos_profiles_yaml(info.offered_qos_profiles),
                            'topic_type_hash': info.type_hash}
        channel_id = self.writer.register_channel(
            info.name, MESSAGE_ENCODING, schema_id, channel_metadata)
        self._registered_size += _record_size(Channel(
            id=channel_id, topic=info.name, message_encoding=MESSAGE_ENCODING,
            metadata=channel_metadata, schema_id=schema_id))
        return channel_id

    def ends_before(self, log_time_ns: int, max_size: int, max_duration_ns: int) -> bool:
        """
        Whether the message at ``log_time_ns`` starts the next file: rosbag2's rule.

        The file's size has reached ``max_size``, or the message is more than
        ``max_duration_ns`` after the file's first message (``NO_SPLIT``: no limit). Every file
        holds a message besides the repeated ones it starts with.
        """
        if not self.new_messages:
            return False
        if max_size != NO_SPLIT and self.stream.tell() >= max_size:
            return True
        start = self.flushed.start_ns
        if start is None:
            start = self.pending.start_ns
        return max_duration_ns != NO_SPLIT and log_time_ns - start > max_duration_ns

    def flush(self) -> None:
        self.writer.flush()
        self.durable_size = self.stream.tell()

    def finished_size(self, serialized_metadata: str, channel_ids: Collection[int]) -> int:
        """
        Return the size the file would have if it were finished now.

        What is written out (``flush`` first, to count the open chunk) and what ``finish`` adds
        to it: the rosbag2 metadata record, the data end, and the summary, which repeats the
        schema and channel records and holds the statistics, a chunk index per chunk, the
        metadata indexes, the group offsets and the footer; each measured as mcap writes it (a
        chunk index as if every channel had messages in its chunk, so at most 10 bytes per
        channel and chunk too many).
        """
        channel_counts = {channel_id: 0 for channel_id in channel_ids}
        tail = [
            Metadata(name=ROSBAG2_METADATA_RECORD_NAME,
                     metadata={'serialized_metadata': serialized_metadata}),
            DataEnd(data_section_crc=0),
            Statistics(attachment_count=0, channel_count=len(channel_counts),
                       channel_message_counts=channel_counts, chunk_count=0, message_count=0,
                       message_end_time=0, message_start_time=0, metadata_count=0,
                       schema_count=0),
            *[ChunkIndex(chunk_length=0, chunk_start_offset=0, compression=self._compression,
                         compressed_size=0, message_end_time=0, message_index_length=0,
                         message_index_offsets=channel_counts, message_start_time=0,
                         uncompressed_size=0)] * self.chunk.chunks_ended,
            *[MetadataIndex(offset=0, length=0, name=name)
              for name in (METADATA_RECORD_NAME, ROSBAG2_METADATA_RECORD_NAME)],
            # schemas, channels, statistics, chunk, attachment and metadata indexes
            *[SummaryOffset(group_opcode=Opcode.SCHEMA, group_start=0, group_length=0)] * 6,
            Footer(summary_start=0, summary_offset_start=0, summary_crc=0),
        ]
        return (self.stream.tell() + self._registered_size + sum(map(_record_size, tail))
                + len(MCAP0_MAGIC))

    def finish(self, serialized_metadata: str) -> None:
        """Write the rosbag2 record (rosbag2's ``update_metadata``) and the summary."""
        self.writer.add_metadata(
            ROSBAG2_METADATA_RECORD_NAME, {'serialized_metadata': serialized_metadata})
        self.writer.finish()
        self.stream.close()
        self.durable_size = self.path.stat().st_size

    def cut_back(self) -> None:
        """Close the file and cut it back to its last flush, so what it holds stays readable."""
        try:
            self.stream.close()
        except OSError:
            pass  # the buffered rest is what failed; it is cut off below
        try:
            os.truncate(self.path, self.durable_size)
        except OSError:
            pass

    def _delete(self) -> None:
        """Close and delete the file; the error that made it useless is the one to report."""
        try:
            self.stream.close()
        except OSError:
            pass  # the buffered rest is what failed; the file goes anyway
        try:
            self.path.unlink()
        except OSError:
            pass  # it stays, unlisted in metadata.yaml, beside the error that is raised

    def info(self) -> FileInfo:
        """Return the file's entry in metadata.yaml (its flushed messages)."""
        return FileInfo(self.path.name, self.flushed.start_ns or 0, self.flushed.duration_ns,
                        self.flushed.count)


class _BagListing:
    """
    What metadata.yaml lists of a bag being written: its topics, its files and their span.

    Only flushed messages count, so that metadata.yaml never lists one a killed run lost: the
    writer counts the messages of the open chunk in ``pending_counts``, and ``count_flushed``
    adds them once the chunk is flushed. Finished files are listed with what they hold, the open
    one (passed in) with what it has flushed.
    """

    def __init__(self, folder: Path, custom_data: dict[str, str]) -> None:
        self.folder = folder
        self.custom_data = custom_data
        self.topics: dict[int, TopicInfo] = {}  # by channel id, with their flushed counts
        self.pending_counts: dict[int, int] = {}
        self.finished: list[FileInfo] = []
        self.finished_size = 0  # bytes of the finished files
        self._span = _Span()  # flushed messages of every file

    def count_flushed(self, flushed: _Span) -> None:
        """Add the chunk just flushed (``pending_counts``, ``flushed``) to the bag's counts."""
        for channel_id, count in self.pending_counts.items():
            self.topics[channel_id].message_count += count
        self.pending_counts.clear()
        self._span.absorb(flushed)

    def add_finished(self, mcap_file: _McapFile) -> None:
        self.finished.append(mcap_file.info())
        self.finished_size += mcap_file.durable_size

    def metadata(self, open_file: _McapFile) -> BagMetadata:
        """Return the bag's metadata, with ``open_file`` as its last file."""
        files = [*self.finished, open_file.info()]
        return BagMetadata(
            relative_file_paths=[file.path for file in files],
            topics=list(self.topics.values()),
            files=files,
            custom_data=dict(self.custom_data),
            starting_time_ns=self._span.start_ns or 0,
            duration_ns=self._span.duration_ns,
            message_count=sum(topic.message_count for topic in self.topics.values()),
        )

    def write_metadata_yaml(self, open_file: _McapFile) -> None:
        """Write metadata.yaml, with ``open_file`` as the bag's last file."""
        self.metadata(open_file).write(self.folder)


class BagWriter:
    """
    Writes one rosbag2 MCAP bag folder; see the module docstring for the layout.

    ``metadata`` (the run's parameters, strings) goes into the MCAP metadata record
    ``linkage_kinematics`` of every file and into ``custom_data`` of metadata.yaml, together
    with ``package_version`` unless ``metadata`` already has it. ``max_bag_size`` (bytes) and
    ``max_bag_duration_ns`` split the bag into files (``NO_SPLIT``: never).
    """

    def __init__(self, bag_path: Path | str, *, metadata: Mapping[str, str],
                 compression: str = 'zstd', chunk_size: int = DEFAULT_CHUNK_SIZE,
                 flush_interval: float = 1.0, max_bag_size: int = NO_SPLIT,
                 max_bag_duration_ns: int = NO_SPLIT) -> None:
        _check_options(metadata, compression, chunk_size, flush_interval, max_bag_size,
                       max_bag_duration_ns)
        self.bag_path = Path(bag_path)
        self.metadata_path = self.bag_path / METADATA_FILE
        self.custom_data = {'package_version': package_version(), **dict(metadata)}
        self._file_options = (chunk_size, _COMPRESSION[compression])
        self._flush_interval = flush_interval
        self._max_size = max_bag_size
        self._max_duration_ns = max_bag_duration_ns
        self._splits = max_bag_size != NO_SPLIT or max_bag_duration_ns != NO_SPLIT
        self._listing = _BagListing(self.bag_path, self.custom_data)
        self._definitions: dict[str, str] = {}
        self._repeated = RepeatedTopics()
        self._queued: list[bytes] = []  # Message records
        self._last_flush = time.monotonic()
        self._failure: BagError | None = None
        self._closed = False
        try:
            self.bag_path.mkdir()
        except FileExistsError:
            raise BagExistsError(
                f'bag folder {self.bag_path} already exists; refusing to overwrite it'
            ) from None
        except OSError as error:
            raise BagError(
                f'cannot create bag folder {self.bag_path}: {error.strerror}'
            ) from None
        self.mcap_path = self._file_path(0)
        try:
            self._file = self._open_file(self.mcap_path)
            self._listing.write_metadata_yaml(self._file)
        except OSError as error:
            raise BagError(f'cannot write bag {self.mcap_path}: {error.strerror}') from None

    @property
    def size_bytes(self) -> int:
        """Bytes of the bag's MCAP files written so far (what a reader sees after a flush)."""
        if self._failure is not None or self._closed:
            return self._listing.finished_size + self._file.durable_size
        return self._listing.finished_size + self._file.stream.tell()

    def add_topic(
        self, topic: str, type_name: str, message_definition: str,
        offered_qos_profiles: list[dict[str, Any]], repeat_latest: bool = False,
    ) -> int:
        """
        Register a topic (``type_name`` like ``std_msgs/msg/String``); return its channel id.

        ``offered_qos_profiles`` is the publisher's QoS as rosbag2 lists it
        (``metadata.offered_qos_profiles_for``). With
        ``repeat_latest``, each further file of a split bag starts with the topic's latest
        message.
        """
        self._check_writable()
        if any(existing.name == topic for existing in self._listing.topics.values()):
            raise ValueError(f'topic {topic} is already in bag {self.bag_path}')
        info = TopicInfo(topic, type_name, list(offered_qos_profiles),
                         type_description_hash(type_name))
        self._definitions.setdefault(type_name, message_definition)
        try:
            channel_id = self._file.register(info, self._definitions[type_name])
            self._listing.topics[channel_id] = info
            if repeat_latest:
                self._repeated.add(channel_id)
            self._listing.write_metadata_yaml(self._file)
        except OSError as error:
            raise self._fail(error) from None
        return channel_id

    def write(self, channel_id: int, data: bytes, log_time_ns: int, publish_time_ns: int) -> None:
        """Append one serialized (CDR) message; raises BagError if the disk refuses it."""
        self._check_writable()
        if channel_id not in self._listing.topics:
            raise ValueError(f'unknown channel id {channel_id} in bag {self.bag_path}')
        self._queued.append(message_record(channel_id, log_time_ns, publish_time_ns, data))
        if len(self._queued) >= WRITE_BATCH:
            self._add_queued()
        if time.monotonic() - self._last_flush >= self._flush_interval:
            self.flush()

    def write_records(self, records: Records) -> None:
        """``write`` of each Message record (``mcap_chunk.message_record``) in turn."""
        self._check_writable()
        if self._queued:
            self._add_queued()
        self._add_records(records)
        if time.monotonic() - self._last_flush >= self._flush_interval:
            self.flush()

    def flush(self) -> None:
        """End the open chunk and hand everything to the OS (survives a killed process)."""
        self._check_writable()
        if self._queued:
            self._add_queued()
        try:
            self._flush_file()
        except OSError as error:
            raise self._fail(error) from None
        self._last_flush = time.monotonic()

    def finished_size(self) -> int:
        """
        Return the size the bag's MCAP files would have if the bag were finished now.

        Those finished, and the open one's ``finished_size`` (``flush`` first, to count its
        open chunk).
        """
        if self._failure is not None or self._closed:
            return self.size_bytes
        return self._listing.finished_size + self._file.finished_size(
            self._listing.metadata(self._file).serialized(), self._listing.topics)

    def close(self) -> None:
        """
        Write the summary (indexes, statistics) and the final metadata.yaml. Idempotent.

        After a write failure the file is left as it was after the last successful flush
        (readable without summary, see ``recovery``) and metadata.yaml gets those counts;
        a failure during close itself is raised (as BagError) after that.
        """
        if self._closed:
            return
        failure_in_close = None
        if self._failure is None:
            try:
                self.flush()
                self._file.finish(self._listing.metadata(self._file).serialized())
            except OSError as error:
                failure_in_close = error if isinstance(error, BagError) else self._fail(error)
        self._closed = True
        try:
            self._listing.write_metadata_yaml(self._file)
        except OSError as error:
            if failure_in_close is None and self._failure is None:
                failure_in_close = BagError(
                    f'cannot write {self.metadata_path}: {error.strerror or error}'
                )
        if failure_in_close is not None:
            raise failure_in_close

    def _file_path(self, index: int) -> Path:
        return self.bag_path / f'{self.bag_path.name}_{index}.mcap'

    def _open_file(self, path: Path) -> _McapFile:
        """Start ``path`` with every topic registered (in order: same channel ids)."""
        topics = [(info, self._definitions[info.type_name])
                  for info in self._listing.topics.values()]
        return _McapFile(path, self.custom_data, topics, *self._file_options)

    def _add_queued(self) -> None:
        queued, self._queued = b''.join(self._queued), []
        self._add_records(queued)

    def _add_records(self, records: Records) -> None:
        """Add Message records to the open chunk; a split bag checks each for the next file."""
        counts = self._listing.pending_counts
        try:
            if not self._splits:
                self._file.pending.add(
                    self._file.chunk.add_records(records, 0, len(records), counts))
                return
            offset = 0
            while offset < len(records):
                end, channel_id, log_time_ns, publish_time_ns, data_start = record_fields(
                    records, offset)
                if self._file.ends_before(log_time_ns, self._max_size, self._max_duration_ns):
                    self._split(log_time_ns)
                self._file.pending.add(self._file.chunk.add_records(records, offset, end, counts))
                self._file.new_messages += 1
                self._repeated.remember(channel_id, bytes(records[data_start:end]),
                                        publish_time_ns)
                offset = end
        except BagError:
            raise  # the next file could not be opened (_split); the bag has stopped
        except OSError as error:
            raise self._fail(error) from None

    def _split(self, log_time_ns: int) -> None:
        """
        Finish the open file and open the next, which starts with the repeated messages.

        The finished file is listed as finished only once the next one is open. If that cannot
        be opened, the finished file, complete, stays the bag's last and the bag stops.
        """
        self._flush_file()
        self._file.finish(self._listing.metadata(self._file).serialized())
        next_path = self._file_path(len(self._listing.finished) + 1)
        try:
            next_file = self._open_file(next_path)
        except OSError as error:
            raise self._stop(BagError(
                f'cannot open {next_path}, the next file of bag {self.bag_path} '
                f'({error.strerror or error}); the bag ends with {self.mcap_path.name}, complete'
            )) from None
        self._listing.add_finished(self._file)
        self._file = next_file
        self.mcap_path = next_path
        counts = self._listing.pending_counts
        for channel_id, data, publish_time_ns in self._repeated.latest():
            self._file.chunk.add(channel_id, log_time_ns, data, publish_time_ns, counts)
            self._file.pending.add([log_time_ns])
        self._listing.write_metadata_yaml(self._file)

    def _flush_file(self) -> None:
        """Flush the open file and count what it flushed."""
        self._file.flush()
        self._listing.count_flushed(self._file.pending)
        self._file.flushed.absorb(self._file.pending)
        self._file.pending = _Span()

    def _check_writable(self) -> None:
        if self._closed:
            raise BagError(f'bag {self.bag_path} is closed')
        if self._failure is not None:
            raise BagError(
                f'bag {self.mcap_path} stopped at an earlier error: {self._failure}'
            )

    def _fail(self, error: OSError) -> BagError:
        """Cut the open file back to its last flush so what was written stays readable."""
        self._file.cut_back()
        return self._stop(BagError(
            f'writing bag {self.mcap_path} failed ({error.strerror or error}); '
            f'the file keeps the {self._file.durable_size} bytes flushed before'
        ))

    def _stop(self, failure: BagError) -> BagError:
        """Refuse every later write with ``failure``; drop the messages not written out."""
        self._failure = failure
        self._listing.pending_counts.clear()
        self._file.pending = _Span()
        self._queued.clear()
        return failure
