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
from dataclasses import dataclass
import functools
from importlib import metadata as distribution_metadata
import json
import os
from pathlib import Path
import shutil
import time
from typing import Any

from ament_index_python.packages import get_package_share_directory, PackageNotFoundError
from linkage_kinematics import bag_reader
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

PACKAGE_NAME = 'linkage_kinematics'
METADATA_RECORD_NAME = PACKAGE_NAME
ROSBAG2_METADATA_RECORD_NAME = 'rosbag2'
ROSBAG2_METADATA_VERSION = 9
ROS_DISTRO = 'jazzy'
PROFILE = 'ros2'
SCHEMA_ENCODING = 'ros2msg'
MESSAGE_ENCODING = 'cdr'
DEFAULT_CHUNK_SIZE = 1024 * 1024
# Messages queued before they go into the MCAP chunk together (see BagWriter._add_queued): at
# 5 kHz, 16 messages are 8 ticks, and adding them takes well under one tick's period.
WRITE_BATCH = 16
DEFINITION_SEPARATOR = '=' * 80
_COMPRESSION = {
    'zstd': CompressionType.ZSTD, 'lz4': CompressionType.LZ4, 'none': CompressionType.NONE
}
_PRIMITIVE_TYPES = frozenset(
    'bool byte char float32 float64 int8 uint8 int16 uint16 int32 uint32 int64 uint64 '
    'string wstring'.split()
)


def _record_size(record: McapRecord) -> int:
    """Return the bytes mcap writes for ``record``."""
    builder = RecordBuilder()
    record.write(builder)
    return builder.count


def package_version() -> str:
    try:
        return distribution_metadata.version(PACKAGE_NAME)
    except distribution_metadata.PackageNotFoundError:
        return 'unknown'


class BagWriteError(OSError):
    """A bag cannot be created, written or recovered; the message names the file and the cause."""


class BagExistsError(BagWriteError, FileExistsError):
    """The bag folder to create already exists (nothing in it is touched)."""


class MessageDefinitionError(LookupError):
    """A message type's .msg file (or one it depends on) is not installed."""


def _interface_file(package: str, name: str, suffix: str) -> Path | None:
    """
    Return the installed ``<package>/msg/<name><suffix>``.

    From the package in the ament index, or where that package is not installed, from the copies
    this package ships of the types it logs without publishing them (tf2_msgs, which has no
    package on PyPI; see interfaces/README.md).
    """
    try:
        share = Path(get_package_share_directory(package))
    except PackageNotFoundError:
        try:
            share = Path(get_package_share_directory(PACKAGE_NAME)) / 'interfaces' / package
        except PackageNotFoundError:
            return None
    candidate = share / 'msg' / f'{name}{suffix}'
    return candidate if candidate.is_file() else None


def _split_type_name(type_name: str) -> tuple[str, str]:
    parts = type_name.split('/')
    if len(parts) == 3 and parts[1] == 'msg':
        return parts[0], parts[2]
    if len(parts) == 2:
        return parts[0], parts[1]
    raise MessageDefinitionError(
        f'message type {type_name!r} is not of the form package/msg/Name or package/Name'
    )


def _field_base_type(line: str) -> str | None:
    """
    Return the type a field (or constant) line refers to.

    It is ``pkg/Name``, ``Name`` or a primitive.
    """
    code = line.split('#', 1)[0].strip()
    if not code:
        return None
    return code.split()[0].split('[', 1)[0].split('<=', 1)[0]


@functools.cache
def message_definition(type_name: str) -> str:
    """
    Return the full ros2msg schema text of ``type_name`` (``pkg/msg/Name``) as rosbag2 stores it.

    The root .msg text comes first, then each dependency once, behind an 80-'=' line and a
    ``MSG: pkg/Name`` line. A dependency is named exactly as the referencing field spells it
    (``std_msgs/Header``, not ``std_msgs/msg/Header``), with the package of the referencing
    file added to bare names: Foxglove resolves field types against these names.
    """
    package, name = _split_type_name(type_name)
    root = _read_msg(package, name)
    sections = [root.rstrip('\n')]
    seen: set[str] = set()
    pending = _dependencies(package, root)
    while pending:
        dependency = pending.pop(0)
        if dependency in seen:
            continue
        seen.add(dependency)
        dep_package, dep_name = dependency.split('/')
        text = _read_msg(dep_package, dep_name)
        sections.append(f'{DEFINITION_SEPARATOR}\nMSG: {dependency}\n{text.rstrip(chr(10))}')
        pending += _dependencies(dep_package, text)
    return '\n'.join(sections) + '\n'


def _read_msg(package: str, name: str) -> str:
    path = _interface_file(package, name, '.msg')
    if path is None:
        raise MessageDefinitionError(
            f'no {package}/msg/{name}.msg in the ament index (AMENT_PREFIX_PATH): '
            'is the message package installed and the environment sourced?'
        )
    return path.read_text(encoding='utf-8')


def _dependencies(package: str, text: str) -> list[str]:
    found = []
    for line in text.splitlines():
        base = _field_base_type(line)
        if base is None or base in _PRIMITIVE_TYPES:
            continue
        found.append(base if '/' in base else f'{package}/{base}')
    return found


@functools.cache
def type_description_hash(type_name: str) -> str:
    """
    Return the RIHS01 type hash rosidl generated for ``type_name``.

    '' if it is not installed.
    """
    package, name = _split_type_name(type_name)
    path = _interface_file(package, name, '.json')
    if path is None:
        return ''
    full_name = f'{package}/msg/{name}'
    for entry in json.loads(path.read_text(encoding='utf-8')).get('type_hashes', []):
        if entry.get('type_name') == full_name:
            return str(entry.get('hash_string', ''))
    return ''


@dataclass
class _Topic:
    name: str
    type_name: str
    offered_qos_profiles: str
    type_hash: str
    message_count: int = 0


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
        self.metadata_path = self.bag_path / 'metadata.yaml'
        self.custom_data = {'package_version': package_version(), **dict(metadata)}
        self._flush_interval = flush_interval
        self._topics: dict[int, _Topic] = {}
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
        self._failure: BagWriteError | None = None
        self._closed = False
        try:
            self.bag_path.mkdir()
        except FileExistsError:
            raise BagExistsError(
                f'bag folder {self.bag_path} already exists; refusing to overwrite it'
            ) from None
        except OSError as error:
            raise BagWriteError(
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
            raise BagWriteError(f'cannot write bag {self.mcap_path}: {error.strerror}') from None

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
        self._topics[channel_id] = _Topic(topic, type_name, offered_qos_profiles, type_hash)
        try:
            self._write_metadata_yaml()
        except OSError as error:
            raise self._fail(error) from None
        return channel_id

    def write(self, channel_id: int, data: bytes, log_time_ns: int, publish_time_ns: int) -> None:
        """Append one serialized (CDR) message; raises BagWriteError if the disk refuses it."""
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
        information = yaml.safe_dump(self._bag_information(), sort_keys=False)
        channel_counts = {channel_id: 0 for channel_id in self._topics}
        tail = [
            Metadata(name=ROSBAG2_METADATA_RECORD_NAME,
                     metadata={'serialized_metadata': information}),
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
        a failure during close itself is raised (as BagWriteError) after that.
        """
        if self._closed:
            return
        failure_in_close = None
        if self._failure is None:
            try:
                self.flush()
                serialized = yaml.safe_dump(self._bag_information(), sort_keys=False)
                self._writer.add_metadata(
                    ROSBAG2_METADATA_RECORD_NAME, {'serialized_metadata': serialized}
                )
                self._writer.finish()
                self._file.close()
                self._durable_size = self.mcap_path.stat().st_size
            except OSError as error:
                failure_in_close = error if isinstance(error, BagWriteError) else self._fail(error)
        self._closed = True
        try:
            self._write_metadata_yaml()
        except OSError as error:
            if failure_in_close is None and self._failure is None:
                failure_in_close = BagWriteError(
                    f'cannot write {self.metadata_path}: {error.strerror or error}'
                )
        if failure_in_close is not None:
            raise failure_in_close

    def _check_writable(self) -> None:
        if self._closed:
            raise BagWriteError(f'bag {self.bag_path} is closed')
        if self._failure is not None:
            raise BagWriteError(
                f'bag {self.mcap_path} stopped at an earlier error: {self._failure}'
            )

    def _fail(self, error: OSError) -> BagWriteError:
        """Cuts the file back to its last complete flush so what was written stays readable."""
        self._failure = BagWriteError(
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

    def _bag_information(self) -> dict[str, Any]:
        start = self._start_time_ns or 0
        duration = max(0, self._end_time_ns - start) if self._start_time_ns is not None else 0
        count = sum(topic.message_count for topic in self._topics.values())
        return {
            'version': ROSBAG2_METADATA_VERSION,
            'storage_identifier': 'mcap',
            'duration': {'nanoseconds': duration},
            'starting_time': {'nanoseconds_since_epoch': start},
            'message_count': count,
            'topics_with_message_count': [
                {
                    'topic_metadata': {
                        'name': topic.name,
                        'type': topic.type_name,
                        'serialization_format': MESSAGE_ENCODING,
                        # metadata version 9 stores the profiles as a YAML list, not as text
                        'offered_qos_profiles': yaml.safe_load(topic.offered_qos_profiles) or [],
                        'type_description_hash': topic.type_hash,
                    },
                    'message_count': topic.message_count,
                }
                for topic in self._topics.values()
            ],
            'compression_format': '',
            'compression_mode': '',
            'relative_file_paths': [self.mcap_path.name],
            'files': [
                {
                    'path': self.mcap_path.name,
                    'starting_time': {'nanoseconds_since_epoch': start},
                    'duration': {'nanoseconds': duration},
                    'message_count': count,
                }
            ],
            'custom_data': dict(self.custom_data),
            'ros_distro': ROS_DISTRO,
        }

    def _write_metadata_yaml(self) -> None:
        text = yaml.safe_dump(
            {'rosbag2_bagfile_information': self._bag_information()}, sort_keys=False
        )
        temporary = self.metadata_path.with_name(self.metadata_path.name + '.tmp')
        temporary.write_text(text, encoding='utf-8')
        os.replace(temporary, self.metadata_path)


@dataclass(frozen=True)
class RecoveryResult:
    mcap_path: Path
    message_count: int
    was_truncated: bool


def recover_bag(bag_path: Path | str) -> RecoveryResult:
    """
    Rewrites a bag's MCAP file with summary, indexes and true counts (e.g. after SIGKILL).

    Every message of every complete record is kept with its topic and times; a partly written
    last chunk is dropped. Topics, types, QoS and the run's metadata come from the bag's
    metadata.yaml (written when the run started), schemas from the installed .msg files.
    On a complete bag it rewrites the same content.
    """
    bag = Path(bag_path)
    if not (bag / 'metadata.yaml').is_file():
        raise BagWriteError(f'{bag} is not a bag folder (no metadata.yaml)')
    files = bag_reader.bag_files(bag)
    if len(files) != 1:
        raise BagWriteError(f'bag {bag} has {len(files)} files; only one-file bags are recovered')
    source = files[0].path
    information = yaml.safe_load((bag / 'metadata.yaml').read_text(encoding='utf-8'))[
        'rosbag2_bagfile_information'
    ]
    topics = {
        entry['topic_metadata']['name']: entry['topic_metadata']
        for entry in information['topics_with_message_count']
    }
    work = bag.parent / f'.{bag.name}.recovering'
    shutil.rmtree(work, ignore_errors=True)  # left over from an interrupted recovery
    work.mkdir()
    try:
        writer = BagWriter(
            work / source.stem.removesuffix('_0'), metadata=information.get('custom_data') or {}
        )
        channel_ids: dict[str, int] = {}
        count = 0
        for message in bag_reader.iter_messages(bag):
            if message.topic not in channel_ids:
                topic = topics.get(message.topic)
                if topic is None:
                    raise BagWriteError(
                        f'{source} has messages on {message.topic}, which {bag}/metadata.yaml '
                        'does not list'
                    )
                channel_ids[message.topic] = writer.add_topic(
                    message.topic,
                    topic['type'],
                    message_definition(topic['type']),
                    yaml.safe_dump(topic['offered_qos_profiles'], sort_keys=False),
                )
            writer.write(
                channel_ids[message.topic],
                message.data,
                message.log_time_ns,
                message.publish_time_ns,
            )
            count += 1
        writer.close()
        os.replace(writer.mcap_path, source)
        os.replace(writer.metadata_path, bag / 'metadata.yaml')
        writer.bag_path.rmdir()
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return RecoveryResult(source, count, files[0].truncated)
