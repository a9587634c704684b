# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
MCAP message records written straight into mcap's open chunk: the bytes of mcap's own writer.

mcap 1.6.0's ``Writer.add_message`` costs about 3 µs per message in Python: a ``Message``
dataclass, the statistics, the chunk builder's index entry (a tuple) and the record written
with six small ``BytesIO`` writes and a seek back; ending a chunk writes its message indexes
entry by entry. ``MessageChunk`` takes the place of the writer's chunk builder. A message
record comes already packed (``message_header`` and the data: the bag writer's node packs it,
so its child only copies runs of records), its index entries go into a list of integers per
channel, packed in one go when the chunk ends, and the writer's statistics are updated once
per run of records. The writer itself still writes everything else: the header, schemas and
channels (through ``add_schema`` and ``add_channel`` here, into the chunk as its own builder
does), the metadata, each chunk (its compression, CRC, index) and the summary.

This relies on mcap's private state, which ``requirements.txt`` pins at ``mcap==1.6.0``: the
``Writer``'s name-mangled ``__chunk_builder``, ``__statistics`` and ``__finalize_chunk``, and
what ``__finalize_chunk`` reads of the chunk builder (``num_messages``, ``end()``, the start and
end times, ``message_indices`` and their ``write``, ``reset()``). ``MessageChunk.attach``
refuses a writer without that state; test/test_mcap_chunk.py checks the version and the
bytes against mcap's own ``add_message``, so a changed mcap fails there loudly.

Plain Python, no ROS.
"""
from __future__ import annotations

from collections.abc import MutableMapping
import struct

from mcap._chunk_builder import ChunkBuilder
from mcap.data_stream import RecordBuilder
from mcap.opcode import Opcode
from mcap.records import Channel, Schema
from mcap.writer import Writer

# A Message record up to its data: opcode, record length, channel id, sequence, log time,
# publish time (mcap's Message.write, field by field).
_MESSAGE_HEADER = struct.Struct('<BQHIQQ')
_RECORD_PREFIX = 9  # every record's opcode and record length
# The record length of a message besides its data: channel id to publish time.
_MESSAGE_FIELDS_SIZE = _MESSAGE_HEADER.size - _RECORD_PREFIX
# What an index entry and a split need of a record: its length, channel, log and publish time.
_RECORD_FIELDS = struct.Struct('<xQH4xQQ')
_INDEX_HEADER = struct.Struct('<BQHI')  # opcode, record length, channel id, entries' length
Records = bytes | bytearray  # Message records, one after the other


def message_header(channel_id: int, log_time_ns: int, publish_time_ns: int,
                   data_length: int) -> bytes:
    """Return a Message record up to its ``data_length`` bytes of data (sequence 0)."""
    return _MESSAGE_HEADER.pack(Opcode.MESSAGE, _MESSAGE_FIELDS_SIZE + data_length, channel_id,
                                0, log_time_ns, publish_time_ns)


def message_record(channel_id: int, log_time_ns: int, publish_time_ns: int,
                   data: bytes) -> bytes:
    """Return the MCAP Message record of one message (sequence 0, as the bag writer's)."""
    return message_header(channel_id, log_time_ns, publish_time_ns, len(data)) + data


def record_fields(records: Records, offset: int) -> tuple[int, int, int, int, int]:
    """Return the end, channel id, log time, publish time and data start of one record."""
    length, channel_id, log_time_ns, publish_time_ns = _RECORD_FIELDS.unpack_from(
        records, offset)
    return (offset + _RECORD_PREFIX + length, channel_id, log_time_ns, publish_time_ns,
            offset + _MESSAGE_HEADER.size)


class _MessageIndex:
    """One channel's message index of a chunk; writes what mcap's ``MessageIndex`` writes."""

    __slots__ = ('channel_id', 'entries')

    def __init__(self, channel_id: int, entries: list[int]) -> None:
        self.channel_id = channel_id
        self.entries = entries  # log time and offset in the chunk, alternately

    def write(self, stream: RecordBuilder) -> None:
        size = 8 * len(self.entries)
        stream.write(_INDEX_HEADER.pack(Opcode.MESSAGE_INDEX, 6 + size, self.channel_id, size))
        stream.write(struct.pack(f'<{len(self.entries)}Q', *self.entries))


class MessageChunk:
    """
    The open chunk of an mcap ``Writer``, in place of its chunk builder (see the module).

    ``add_records`` adds runs of packed Message records and ends the chunk, through the
    writer, after the first message that takes it over ``chunk_size`` bytes, as
    ``Writer.add_message`` does.
    """

    def __init__(self, writer: Writer, chunk_size: int) -> None:
        """Use ``attach``: this takes the writer's private state without checking it."""
        self._chunk_size = chunk_size
        self._statistics = writer._Writer__statistics
        self._finalize = writer._Writer__finalize_chunk
        self._data = bytearray()
        self._entries: dict[int, list[int]] = {}
        self._channel_ids: set[int] = set()
        self.num_messages = 0
        self.message_start_time = 0
        self.message_end_time = 0
        self.chunks_ended = 0  # each a chunk of the file, and a chunk index in its summary

    @classmethod
    def attach(cls, writer: Writer, chunk_size: int) -> MessageChunk:
        """
        Put a new MessageChunk in place of a new writer's chunk builder; return it.

        ``chunk_size`` is the writer's. Raises RuntimeError if the writer is not mcap 1.6.0's
        as this module knows it, or has written into its chunk already.
        """
        builder = getattr(writer, '_Writer__chunk_builder', None)
        if (type(builder) is not ChunkBuilder or builder.count
                or not hasattr(writer, '_Writer__statistics')
                or not hasattr(writer, '_Writer__finalize_chunk')):
            raise RuntimeError(
                'the mcap writer is not the new, chunked mcap 1.6.0 Writer whose chunk builder '
                'MessageChunk replaces (requirements.txt pins mcap==1.6.0)')
        chunk = cls(writer, chunk_size)
        writer._Writer__chunk_builder = chunk
        return chunk

    # --- what mcap's Writer calls ------------------------------------------------------------

    @property
    def count(self) -> int:
        """Return the chunk's uncompressed bytes so far."""
        return len(self._data)

    @property
    def message_indices(self) -> dict[int, _MessageIndex]:
        """Return each channel's message index, in the order of the channels' first messages."""
        return {channel_id: _MessageIndex(channel_id, entries)
                for channel_id, entries in self._entries.items()}

    def add_schema(self, schema: Schema) -> None:
        self._add_record(schema)

    def add_channel(self, channel: Channel) -> None:
        self._add_record(channel)
        self._channel_ids.add(channel.id)

    def end(self) -> bytes:
        """Return the chunk's records and empty it."""
        self.chunks_ended += 1
        data = bytes(self._data)
        self._data.clear()
        return data

    def reset(self) -> None:
        self._data.clear()
        self._entries.clear()
        self.num_messages = 0
        self.message_start_time = 0
        self.message_end_time = 0

    # --- messages ---------------------------------------------------------------------------

    def add(self, channel_id: int, log_time_ns: int, data: bytes, publish_time_ns: int,
            counts: MutableMapping[int, int]) -> None:
        """``Writer.add_message`` of one message; ``counts`` as in ``add_records``."""
        record = message_record(channel_id, log_time_ns, publish_time_ns, data)
        self.add_records(record, 0, len(record), counts)

    def add_records(self, records: Records, start: int, end: int,
                    counts: MutableMapping[int, int]) -> list[int]:
        """
        Add the Message records ``records[start:end]``, in order; return their log times.

        As many ``Writer.add_message`` calls would (the same bytes). ``counts`` gets each
        channel's number of messages added. A record of a channel the writer has not registered
        raises ValueError; the records before it are added.
        """
        unpack = _RECORD_FIELDS.unpack_from
        entries = self._entries
        log_times: list[int] = []
        piece = offset = start  # records[piece:offset] are indexed but not yet in the chunk
        first = 0  # log_times[first:] are the piece's
        base = len(self._data) - start  # a record's offset in the chunk is base + its offset
        limit = self._chunk_size - base  # the chunk ends after a record that ends beyond this
        lengths = {channel_id: len(index) for channel_id, index in entries.items()}
        while offset < end:
            length, channel_id, log_time_ns, _ = unpack(records, offset)
            index = entries.get(channel_id)
            if index is None:
                if channel_id not in self._channel_ids:
                    self._take(records, piece, offset, log_times[first:], lengths, counts)
                    raise ValueError(f'message of unknown channel id {channel_id}')
                index = entries[channel_id] = []
            index += (log_time_ns, base + offset)
            log_times.append(log_time_ns)
            offset += _RECORD_PREFIX + length
            if offset > limit:
                self._take(records, piece, offset, log_times[first:], lengths, counts)
                self._finalize()
                piece, first, base, lengths = offset, len(log_times), -offset, {}
                limit = self._chunk_size + offset
        self._take(records, piece, offset, log_times[first:], lengths, counts)
        return log_times

    def _take(self, records: Records, start: int, end: int, log_times: list[int],
              lengths: dict[int, int], counts: MutableMapping[int, int]) -> None:
        """
        Put indexed records into the chunk and count them in the writer's statistics.

        ``lengths`` are the channels' index lengths before them. The statistics' channels are
        new ones in the order of their first messages, as ``Writer.add_message`` adds them.
        """
        if not log_times:
            return
        self._data += memoryview(records)[start:end]
        low, high = min(log_times), max(log_times)
        statistics = self._statistics
        if statistics.message_count == 0:
            statistics.message_start_time = low
        statistics.message_start_time = min(statistics.message_start_time, low)
        statistics.message_end_time = max(statistics.message_end_time, high)
        statistics.message_count += len(log_times)
        channel_counts = statistics.channel_message_counts
        for channel_id, index in self._entries.items():
            added = (len(index) - lengths.get(channel_id, 0)) // 2
            if added:
                channel_counts[channel_id] += added
                counts[channel_id] = counts.get(channel_id, 0) + added
        if self.num_messages == 0:
            self.message_start_time = low
        self.message_start_time = min(self.message_start_time, low)
        self.message_end_time = max(self.message_end_time, high)
        self.num_messages += len(log_times)

    def _add_record(self, record: Schema | Channel) -> None:
        builder = RecordBuilder()
        record.write(builder)
        self._data += builder.end()
