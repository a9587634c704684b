# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
rosbag2-compatible MCAP bags (Jazzy, metadata version 9) from already-serialized CDR bytes.

A bag is a folder ``<name>/`` holding ``<name>_0.mcap`` and ``metadata.yaml``, as ``ros2 bag
record -s mcap`` makes it, so ``ros2 bag play <name>``, ``ros2 bag info``, Foxglove, rosbags and
mcap-ros2-support all read it. The MCAP file uses the ``ros2`` profile: schemas are the full
``ros2msg`` text with every dependent definition, channels carry ``cdr`` messages and the
``offered_qos_profiles`` / ``topic_type_hash`` metadata rosbag2 expects.

Crash safety: the Python mcap writer keeps the open chunk in memory until it is full (and this
writer queues up to ``WRITE_BATCH`` messages before adding them to it), so the writer also ends
the chunk and flushes the OS file once ``flush_interval`` has passed; a killed process loses at
most that much. ``metadata.yaml`` exists from the start (so a killed run's
folder is already a bag folder) and gets its final counts on ``close()``. ``recover_bag()``
(``linkage-replay --recover BAG``) rewrites a file without summary into a complete one.

This module is plain Python (no rclpy): bytes in, files out.
"""
from __future__ import annotations

from collections.abc import Mapping
import os
from pathlib import Path
import time

from linkage_kinematics.bag.definitions import SCHEMA_ENCODING, type_description_hash
from linkage_kinematics.bag.errors import BagError, BagExistsError
from linkage_kinematics.bag.metadata import (
    BagMetadata,
    FileInfo,
    MESSAGE_ENCODING,
    METADATA_FILE,
    PACKAGE_NAME,
    package_version,
    TopicInfo,
)
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
import yaml

METADATA_RECORD_NAME = PACKAGE_NAME
ROSBAG2_METADATA_RECORD_NAME = 'rosbag2'
PROFILE = 'ros2'
DEFAULT_CHUNK_SIZE = 1024 * 1024
# Messages queued before they go into the MCAP chunk together (see BagWriter._add_queued): at
# 5 kHz, 16 messages are 8 ticks, and adding them takes well under one tick's period.
WRITE_BATCH = 16
_COMPRESSION = {
    'zstd': CompressionType.ZSTD, 'lz4': CompressionType.LZ4, 'none': CompressionType.NONE
}


def _record_size(record: McapRecord) -> int:
    """Return the bytes mcap writes for ``record``."""
    builder = RecordBuilder()
    record.write(builder)
    return builder.count


class BagWriter:
    """
    Writes one rosbag2 MCAP bag folder; see the module docstring for the layout.

    ``metadata`` (the run's parameters, strings) goes into the MCAP metadata record
    ``linkage_kinematics`` and into ``custom_data`` of metadata.yaml, together with
    ``package_version`` unless ``metadata`` already has it.
    """

    def __init__(
        self,
        bag_path: Path | str,
        *,
        metadata: Mapping[str, str],
        compression: str = 'zstd',
        chunk_size: int = DEFAULT_CHUNK_SIZE,
        flush_interval: float = 1.0,
    ) -> None:
        if compression not in _COMPRESSION:
            raise ValueError(
                f'compression must be one of {sorted(_COMPRESSION)}, not {compression!r}'
            )
        not_text = [key for key, value in metadata.items() if not isinstance(value, str)]
        if not_text:
            raise TypeError(f'bag metadata values must be strings; not so for {not_text}')
        if chunk_size <= 0 or flush_interval <= 0:
            raise ValueError('chunk_size and flush_interval must be positive')
        self.bag_path = Path(bag_path)
        self.mcap_path = self.bag_path / f'{self.bag_path.name}_0.mcap'
        self.metadata_path = self.bag_path / METADATA_FILE
        self.custom_data = {'package_version': package_version(), **dict(metadata)}
        self._flush_interval = flush_interval
        self._topics: dict[int, TopicInfo] = {}
        self._schema_ids: dict[str, int] = {}
        self._pending_counts: dict[int, int] = {}
        self._queued: list[tuple[int, int, bytes, int]] = []
        self._start_time_ns: int | None = None
        self._end_time_ns = 0
        self._pending_start_ns: int | None = None
        self._pending_end_ns = 0
        self._last_flush = time.monotonic()
        self._durable_size = 0
        self._compression = compression
        # Bytes of the schema and channel records, which the summary repeats, and the chunks
        # written so far (each gets a chunk index in the summary).
        self._registered_size = 0
        self._chunk_count = 0
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
        try:
            self._file = open(self.mcap_path, 'wb')
            self._writer = Writer(
                self._file, chunk_size=chunk_size, compression=_COMPRESSION[compression]
            )
            self._writer.start(
                profile=PROFILE, library=f'{PACKAGE_NAME}/{package_version()} {LIBRARY_IDENTIFIER}'
            )
            self._writer.add_metadata(METADATA_RECORD_NAME, self.custom_data)
            self._file.flush()
            self._durable_size = self._file.tell()
            self._write_metadata_yaml()
        except OSError as error:
            raise BagError(f'cannot write bag {self.mcap_path}: {error.strerror}') from None

    @property
    def size_bytes(self) -> int:
        """Bytes of the MCAP file written so far (what a reader would see after a flush)."""
        if self._failure is not None or self._closed:
            return self._durable_size
        return self._file.tell()

    def add_topic(
        self, topic: str, type_name: str, message_definition: str, offered_qos_profiles: str
    ) -> int:
        """
        Register a topic (``type_name`` like ``std_msgs/msg/String``).

        Returns its channel id.

        ``offered_qos_profiles`` is rosbag2's YAML text of the publisher's QoS list.
        """
        self._check_writable()
        if any(existing.name == topic for existing in self._topics.values()):
            raise ValueError(f'topic {topic} is already in bag {self.bag_path}')
        type_hash = type_description_hash(type_name)
        try:
            schema_id = self._schema_ids.get(type_name)
            if schema_id is None:
                data = message_definition.encode('utf-8')
                schema_id = self._writer.register_schema(type_name, SCHEMA_ENCODING, data)
                self._schema_ids[type_name] = schema_id
                self._registered_size += _record_size(
                    Schema(id=schema_id, data=data, encoding=SCHEMA_ENCODING, name=type_name))
            channel_metadata = {'offered_qos_profiles': offered_qos_profiles,
                                'topic_type_hash': type_hash}
            channel_id = self._writer.register_channel(
                topic, MESSAGE_ENCODING, schema_id, channel_metadata)
            self._registered_size += _record_size(Channel(
                id=channel_id, topic=topic, message_encoding=MESSAGE_ENCODING,
                metadata=channel_metadata, schema_id=schema_id))
        except OSError as error:
            raise self._fail(error) from None
        self._topics[channel_id] = TopicInfo(
            topic, type_name, yaml.safe_load(offered_qos_profiles) or [], type_hash
        )
        try:
            self._write_metadata_yaml()
        except OSError as error:
            raise self._fail(error) from None
        return channel_id

    def write(self, channel_id: int, data: bytes, log_time_ns: int, publish_time_ns: int) -> None:
        """Append one serialized (CDR) message; raises BagError if the disk refuses it."""
        self._check_writable()
        if channel_id not in self._topics:
            raise ValueError(f'unknown channel id {channel_id} in bag {self.bag_path}')
        self._queued.append((channel_id, log_time_ns, data, publish_time_ns))
        if len(self._queued) >= WRITE_BATCH:
            self._add_queued()
        if time.monotonic() - self._last_flush >= self._flush_interval:
            self.flush()

    def _add_queued(self) -> None:
        """
        Hand the queued messages to the MCAP writer's open chunk, in one go.

        The writer's Python then runs warm, at about a third of its cost per message when called
        once per message between ticks.
        """
        queued, self._queued = self._queued, []
        add_message = self._writer.add_message
        counts = self._pending_counts
        try:
            for channel_id, log_time_ns, data, publish_time_ns in queued:
                add_message(channel_id, log_time_ns, data, publish_time_ns)
                counts[channel_id] = counts.get(channel_id, 0) + 1
        except OSError as error:
            raise self._fail(error) from None
        log_times = [entry[1] for entry in queued]
        if self._pending_start_ns is None:
            self._pending_start_ns = min(log_times)
        else:
            self._pending_start_ns = min(self._pending_start_ns, *log_times)
        self._pending_end_ns = max(self._pending_end_ns, *log_times)

    def flush(self) -> None:
        """End the open chunk and hands everything to the OS (survives a killed process)."""
        self._check_writable()
        if self._queued:
            self._add_queued()
        try:
            self._writer.flush()
        except OSError as error:
            raise self._fail(error) from None
        self._last_flush = time.monotonic()
        if self._file.tell() > self._durable_size:
            self._chunk_count += 1
        self._durable_size = self._file.tell()
        self._commit_pending()

    def finished_size(self) -> int:
        """
        Return the size the MCAP file would have if it were finished now.

        What is written out (``flush`` first, to count the open chunk) and what ``close`` adds to
        it: the rosbag2 metadata record, the data end, and the summary, which repeats the schema
        and channel records and holds the statistics, a chunk index per chunk, the metadata
        indexes, the group offsets and the footer; each measured as mcap writes it (a chunk index
        as if every channel had messages in its chunk, so at most 10 bytes per channel and chunk
        too many).
        """
        if self._failure is not None or self._closed:
            return self._durable_size
        channel_counts = {channel_id: 0 for channel_id in self._topics}
        tail = [
            Metadata(name=ROSBAG2_METADATA_RECORD_NAME,
                     metadata={'serialized_metadata': self._bag_metadata().serialized()}),
            DataEnd(data_section_crc=0),
            Statistics(attachment_count=0, channel_count=len(self._topics),
                       channel_message_counts=channel_counts, chunk_count=0, message_count=0,
                       message_end_time=0, message_start_time=0, metadata_count=0,
                       schema_count=0),
            *[ChunkIndex(chunk_length=0, chunk_start_offset=0, compression=self._compression,
                         compressed_size=0, message_end_time=0, message_index_length=0,
                         message_index_offsets=channel_counts, message_start_time=0,
                         uncompressed_size=0)] * self._chunk_count,
            *[MetadataIndex(offset=0, length=0, name=name)
              for name in (METADATA_RECORD_NAME, ROSBAG2_METADATA_RECORD_NAME)],
            # schemas, channels, statistics, chunk, attachment and metadata indexes
            *[SummaryOffset(group_opcode=Opcode.SCHEMA, group_start=0, group_length=0)] * 6,
            Footer(summary_start=0, summary_offset_start=0, summary_crc=0),
        ]
        return (self._file.tell() + self._registered_size + sum(map(_record_size, tail))
                + len(MCAP0_MAGIC))

    def close(self) -> None:
        """
        Write the summary (indexes, statistics) and the final metadata.yaml. Idempotent.

        After a write failure the file is left as it was after the last successful flush
        (readable without summary, see ``recover_bag``) and metadata.yaml gets those counts;
        a failure during close itself is raised (as BagError) after that.
        """
        if self._closed:
            return
        failure_in_close = None
        if self._failure is None:
            try:
                self.flush()
                self._writer.add_metadata(
                    ROSBAG2_METADATA_RECORD_NAME,
                    {'serialized_metadata': self._bag_metadata().serialized()},
                )
                self._writer.finish()
                self._file.close()
                self._durable_size = self.mcap_path.stat().st_size
            except OSError as error:
                failure_in_close = error if isinstance(error, BagError) else self._fail(error)
        self._closed = True
        try:
            self._write_metadata_yaml()
        except OSError as error:
            if failure_in_close is None and self._failure is None:
                failure_in_close = BagError(
                    f'cannot write {self.metadata_path}: {error.strerror or error}'
                )
        if failure_in_close is not None:
            raise failure_in_close

    def _check_writable(self) -> None:
        if self._closed:
            raise BagError(f'bag {self.bag_path} is closed')
        if self._failure is not None:
            raise BagError(
                f'bag {self.mcap_path} stopped at an earlier error: {self._failure}'
            )

    def _fail(self, error: OSError) -> BagError:
        """Cuts the file back to its last complete flush so what was written stays readable."""
        self._failure = BagError(
            f'writing bag {self.mcap_path} failed ({error.strerror or error}); '
            f'the file keeps the {self._durable_size} bytes flushed before'
        )
        try:
            self._file.close()
        except OSError:
            pass  # the buffered rest is what failed; it is cut off below
        try:
            os.truncate(self.mcap_path, self._durable_size)
        except OSError:
            pass
        self._pending_counts.clear()
        self._queued.clear()
        return self._failure

    def _commit_pending(self) -> None:
        for channel_id, count in self._pending_counts.items():
            self._topics[channel_id].message_count += count
        self._pending_counts.clear()
        if self._pending_start_ns is not None:
            if self._start_time_ns is None or self._pending_start_ns < self._start_time_ns:
                self._start_time_ns = self._pending_start_ns
            self._end_time_ns = max(self._end_time_ns, self._pending_end_ns)
            self._pending_start_ns = None

    def _bag_metadata(self) -> BagMetadata:
        start = self._start_time_ns or 0
        duration = max(0, self._end_time_ns - start) if self._start_time_ns is not None else 0
        count = sum(topic.message_count for topic in self._topics.values())
        return BagMetadata(
            relative_file_paths=[self.mcap_path.name],
            topics=list(self._topics.values()),
            files=[FileInfo(self.mcap_path.name, start, duration, count)],
            custom_data=dict(self.custom_data),
            starting_time_ns=start,
            duration_ns=duration,
            message_count=count,
        )

    def _write_metadata_yaml(self) -> None:
        self._bag_metadata().write(self.bag_path)
