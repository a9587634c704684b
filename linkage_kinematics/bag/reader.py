# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Read the node's logged runs: rosbag2 MCAP bag folders or bare ``.mcap`` files.

Every file is read by streaming through its records, never through its summary, so a run that
was killed (an MCAP with no summary and no footer, its last chunk cut short) reads the same way
as a finished one: first the file's leading complete records are found by walking the record
headers, then only those are parsed. A record cut short is never parsed, so a half-written
message can never come out as a short, wrong one. ``bag_files`` says which files were cut short.

Messages come out in file order, which is the order the recorder received them (rosbag2 and the
node write each message as it arrives).
"""

from __future__ import annotations

from collections.abc import Collection, Iterator
from dataclasses import dataclass
import io
import os
from pathlib import Path
import struct
from typing import NamedTuple, Optional

from linkage_kinematics.bag.errors import BagError
from linkage_kinematics.bag.metadata import BagMetadata, METADATA_FILE
from linkage_kinematics.bag.state_layout import (
    READ_COORDINATES,
    state_from_coordinates,
    state_point,
    STATE_TOPIC,
    STATE_TYPE,
)
from linkage_kinematics.kinematics.solver import LinkageState
from mcap.exceptions import EndOfFile, McapError
from mcap.opcode import Opcode
from mcap.reader import NonSeekingReader
from mcap.records import Channel, Message, Schema
from mcap_ros2.decoder import DecoderFactory
import numpy as np
import zstandard

_MAGIC = b'\x89MCAP0\r\n'
_RECORD_PREFIX = struct.Struct('<BQ')  # opcode, length of the record's content
# Failures of the mcap readers on records that are complete but damaged. lz4 reports a corrupt
# frame as RuntimeError.
_CORRUPT_DATA_ERRORS = (McapError, ValueError, struct.error, zstandard.ZstdError, RuntimeError)
# Failures of mcap_ros2's CDR decoder on a message that does not match its schema.
_UNDECODABLE_ERRORS = (McapError, ValueError, struct.error, IndexError)


class BagMessage(NamedTuple):
    """One logged message, still serialized (CDR for ROS 2 bags)."""

    topic: str
    schema_name: str
    data: bytes
    log_time_ns: int
    publish_time_ns: int


@dataclass(frozen=True)
class McapFile:
    """One MCAP file of a bag and how much of it holds complete records."""

    path: Path
    size: int
    readable_size: int
    complete: bool

    @property
    def truncated(self) -> bool:
        """Return True for a file that ends without its footer (a recorder that was killed)."""
        return not self.complete


def bag_files(path: str | os.PathLike[str]) -> list[McapFile]:
    """
    Return the MCAP files of a bag folder (in recording order) or the one ``.mcap`` file given.

    A folder's files are those its ``metadata.yaml`` lists, or every ``*.mcap`` in it when it has
    no ``metadata.yaml`` (a recorder killed before writing one).
    """
    bag = Path(path)
    if not bag.exists():
        raise BagError(f'no bag at {bag}: no such file or folder')
    if bag.is_dir():
        paths = _folder_files(bag)
    else:
        paths = [bag]
    return [_scan(file_path) for file_path in paths]


def iter_messages(
    path: str | os.PathLike[str], topics: Optional[Collection[str]] = None
) -> Iterator[BagMessage]:
    """
    Every message of a bag (only those on ``topics`` when given), in file order.

    A truncated file yields its complete messages and then ends; check ``bag_files`` to know.
    """
    wanted = None if topics is None else frozenset(topics)
    for schema, channel, message in _iter_records(bag_files(path)):
        if wanted is None or channel.topic in wanted:
            yield BagMessage(
                topic=channel.topic,
                schema_name=schema.name if schema is not None else '',
                data=message.data,
                log_time_ns=message.log_time,
                publish_time_ns=message.publish_time,
            )


def read_states(path: str | os.PathLike[str]) -> tuple[np.ndarray, LinkageState]:
    """
    Return the states the node logged on ``linkage/state`` (in any namespace), in file order.

    Returns each state's header stamp (int64 ns) and a LinkageState of arrays. The message does
    not carry the transmission angle, so ``transmission_angle`` is all NaN. Other topics are
    ignored.
    """
    files = bag_files(path)
    decoders = DecoderFactory()
    other_topics: set[str] = set()
    stamps: list[int] = []
    positions: list[list[float]] = []
    velocities: list[list[float]] = []
    accelerations: list[list[float]] = []
    for schema, channel, message in _iter_records(files):
        if not channel.topic.endswith(STATE_TOPIC):  # under any namespace
            other_topics.add(channel.topic)
            continue
        where = f'{STATE_TOPIC} message {len(stamps)} (log time {message.log_time} ns) in {path}'
        if schema is None or schema.name != STATE_TYPE:
            found = 'no schema' if schema is None else f'type {schema.name}'
            raise BagError(f'{where} has {found}; expected {STATE_TYPE}')
        try:
            decode = decoders.decoder_for(channel.message_encoding, schema)
            trajectory = None if decode is None else decode(message.data)
        except _UNDECODABLE_ERRORS as error:
            raise BagError(f'{where} cannot be decoded: {_one_line(error)}') from None
        if trajectory is None:
            raise BagError(
                f'{where} cannot be decoded: message encoding {channel.message_encoding!r} with '
                f"schema encoding {schema.encoding!r} (expected 'cdr' and 'ros2msg')"
            )
        point = state_point(trajectory, where)
        stamp = trajectory.header.stamp
        stamps.append(stamp.sec * 1_000_000_000 + stamp.nanosec)
        positions.append(point.positions[:READ_COORDINATES])
        velocities.append(point.velocities[:READ_COORDINATES])
        accelerations.append(point.accelerations[:READ_COORDINATES])
    if not stamps:
        present = ', '.join(sorted(other_topics)) if other_topics else 'none'
        raise BagError(f'{path} holds no {STATE_TOPIC} messages (topics present: {present})')
    return np.array(stamps, dtype=np.int64), state_from_coordinates(
        np.array(positions, dtype=float),
        np.array(velocities, dtype=float),
        np.array(accelerations, dtype=float),
    )


def _folder_files(folder: Path) -> list[Path]:
    metadata_path = folder / METADATA_FILE
    if not metadata_path.exists():
        paths = sorted(folder.glob('*.mcap'))
        if not paths:
            raise BagError(f'{folder} is not a bag: no metadata.yaml and no .mcap file')
        return paths
    metadata = BagMetadata.read(folder)
    storage = metadata.storage_identifier
    relative_paths = metadata.relative_file_paths
    if storage != 'mcap':
        raise BagError(f'{folder} stores its messages in {storage!r}; only MCAP bags can be read')
    if not relative_paths:
        raise BagError(f'{metadata_path} lists no bag files')
    paths = [folder / str(relative) for relative in relative_paths]
    missing = [str(file_path) for file_path in paths if not file_path.is_file()]
    if missing:
        raise BagError(f"{metadata_path} lists files that are missing: {', '.join(missing)}")
    return paths


def _scan(file_path: Path) -> McapFile:
    """Walk the record headers to find where the complete records end."""
    try:
        with open(file_path, 'rb') as stream:
            size = os.fstat(stream.fileno()).st_size
            magic = stream.read(len(_MAGIC))
            if magic != _MAGIC:
                found = 'it is empty' if not magic else f'it starts with {magic[:8]!r}'
                raise BagError(f'{file_path} is not an MCAP file: {found}')
            offset = len(_MAGIC)
            while offset + _RECORD_PREFIX.size <= size:
                stream.seek(offset)
                opcode, length = _RECORD_PREFIX.unpack(stream.read(_RECORD_PREFIX.size))
                end = offset + _RECORD_PREFIX.size + length
                if end > size:
                    break
                if opcode == Opcode.FOOTER:
                    stream.seek(end)
                    if stream.read(len(_MAGIC)) == _MAGIC:
                        return McapFile(file_path, size, end + len(_MAGIC), complete=True)
                    break
                offset = end
    except BagError:
        raise
    except OSError as error:
        raise BagError(f'cannot read {file_path}: {error.strerror or error}') from None
    return McapFile(file_path, size, offset, complete=False)


class _BoundedFile(io.RawIOBase):
    """A read-only view of the first ``limit`` bytes of a file."""

    def __init__(self, stream: io.BufferedReader, limit: int) -> None:
        super().__init__()
        self._stream = stream
        self._remaining = limit

    def readable(self) -> bool:
        return True

    def readinto(self, buffer: memoryview) -> int:  # type: ignore[override]
        wanted = min(len(buffer), self._remaining)
        if wanted == 0:
            return 0
        count = self._stream.readinto(memoryview(buffer)[:wanted])
        self._remaining -= count
        return count


def _iter_records(files: list[McapFile]) -> Iterator[tuple[Optional[Schema], Channel, Message]]:
    for mcap_file in files:
        try:
            with open(mcap_file.path, 'rb') as stream:
                reader = NonSeekingReader(
                    _BoundedFile(stream, mcap_file.readable_size), validate_crcs=True
                )
                yield from reader.iter_messages(log_time_order=False)
        except EndOfFile:
            # The readable part of a truncated file ends on a record boundary: nothing is lost.
            if mcap_file.complete:
                raise BagError(f'{mcap_file.path} is damaged: it ends inside a record') from None
        except OSError as error:
            raise BagError(f'cannot read {mcap_file.path}: {error.strerror or error}') from None
        except _CORRUPT_DATA_ERRORS as error:
            raise BagError(f'{mcap_file.path} is damaged: {_one_line(error)}') from None


def _one_line(error: BaseException) -> str:
    """Return an error's text on one line (YAML and decoder errors span several)."""
    return ' '.join(str(error).split())
