# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A BagWriter in a process of its own, so that a node's timer never waits for the MCAP writer.

The Python mcap writer stops for 4–15 ms each time it ends a chunk (it writes the chunk's
message index entry by entry); at a 5 kHz timer that is 20–75 ticks. In a thread it would
still hold the GIL for those milliseconds. Here the node only appends each message to a
buffer and hands batches to a pipe (``BagWriterProcess``); ``python -m
linkage_kinematics.bag.writer_process`` runs the ``BagWriter`` on the other end, on whatever
core is free.

The child lives as long as the pipe: when the node closes it, or dies in any way (SIGKILL
included), the child writes every message it received, the summary and the final
metadata.yaml, then exits. It runs in a session of its own, so a Ctrl-C meant for the node
(SIGINT to the terminal's process group) does not end it first.

Frames on the child's stdin: one kind byte, a uint32 length, the payload. ``S`` (JSON:
folder, metadata, split) opens a new bag folder ``rosbag2_<local time>[_<n>]`` in folder; ``T``
(JSON) adds a topic; ``M`` holds messages, each as its MCAP Message record (``mcap_chunk``), so
that the child copies them into the open chunk as they are; ``F`` (empty) asks the child to
write out everything it holds. The child answers on stdout with JSON lines: ``bag`` or
``channel`` for S and T, ``size`` (the size the finished bag would have,
``BagWriter.finished_size``) now and then and with ``flushed`` for F, ``error`` when the bag
cannot go on, and ``closed`` when it is done.

Plain Python (no rclpy), as ``writer``.
"""
from __future__ import annotations

from collections.abc import Mapping, Set
import json
import os
from pathlib import Path
import signal
import struct
import subprocess
import sys
import time
from typing import Any, BinaryIO

from linkage_kinematics.bag.errors import BagError, BagExistsError, LogFolderError
from linkage_kinematics.bag.mcap_chunk import message_header
from linkage_kinematics.bag.writer import BagWriter
from linkage_kinematics.shared.affinity import set_process_affinity
from linkage_kinematics.shared.rosbag2_split import NO_SPLIT

_FRAME = struct.Struct('<cI')
START, TOPIC, MESSAGES, FLUSH = b'S', b'T', b'M', b'F'
# The node hands over its queued messages once they are this many bytes (well under the
# pipe's 64 KiB, so that a write rarely waits for the child), or older than BATCH_AGE (s):
# a node killed outright loses at most its last batch, of this age, even at low rates.
BATCH_SIZE = 16384
BATCH_AGE = 0.05
SIZE_REPORT_INTERVAL = 0.25  # s between the child's reports of the file size
CLOSE_TIMEOUT = 60.0  # s for the child to write the summary once the pipe is closed


class BagWriterProcess:
    """
    The node's handle on a ``BagWriter`` in a child process.

    A new bag folder in ``folder`` named after the local time (``rosbag2_%Y_%m_%d-%H_%M_%S``,
    ``_1``, … if taken).

    Errors of the child's writer come back as BagError from the next ``write`` (or
    ``close``) after the child reported them. ``cpus``, if given, are the CPUs the child may
    run on (the node's ``cpu_affinity`` keeps it off the node's CPU); ``max_bag_size`` and
    ``max_bag_duration_ns`` split the bag as ``BagWriter``'s do.
    """

    def __init__(
        self, folder: Path | str, *, metadata: Mapping[str, str], cpus: Set[int] | None = None,
        max_bag_size: int = NO_SPLIT, max_bag_duration_ns: int = NO_SPLIT,
    ) -> None:
        self._process = subprocess.Popen(
            [sys.executable, '-m', __name__], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
            bufsize=0, start_new_session=True,
        )
        if cpus is not None:
            self.run_on(cpus)
        self._input = self._process.stdin.fileno()
        self._replies = b''
        self._queued = bytearray()
        self._batch_started = time.monotonic()
        self._failure: str | None = None
        self._closed = False
        self.size_bytes = 0
        try:
            # The child's one answer to START that is an error is about the folder.
            reply = self._request(START, {
                'folder': str(folder), 'metadata': dict(metadata),
                'split': {'max_bag_size': max_bag_size,
                          'max_bag_duration_ns': max_bag_duration_ns},
            }, LogFolderError)
        except BagError:
            self._process.stdin.close()
            self._process.wait(timeout=CLOSE_TIMEOUT)
            raise
        self.bag_path = Path(reply['bag'])
        self.size_bytes = reply['size']

    def add_topic(
        self, topic: str, type_name: str, message_definition: str,
        offered_qos_profiles: list[dict[str, Any]], repeat_latest: bool = False,
    ) -> int:
        """``BagWriter.add_topic`` in the child; its channel id."""
        reply = self._request(TOPIC, {
            'topic': topic, 'type_name': type_name, 'message_definition': message_definition,
            'offered_qos_profiles': offered_qos_profiles, 'repeat_latest': repeat_latest,
        })
        return int(reply['channel'])

    def run_on(self, cpus: Set[int]) -> None:
        """Let the child run only on ``cpus``."""
        set_process_affinity(self._process.pid, cpus)

    def write(self, channel_id: int, data: bytes, log_time_ns: int, publish_time_ns: int) -> None:
        """Queues one serialized message; a full or old batch goes to the child."""
        if self._failure is not None or self._closed:
            raise BagError(self._failure or f'bag {self.bag_path} is closed')
        self._queued += message_header(channel_id, log_time_ns, publish_time_ns, len(data))
        self._queued += data
        if (len(self._queued) >= BATCH_SIZE
                or time.monotonic() - self._batch_started >= BATCH_AGE):
            self._send_queued()

    def flush(self) -> None:
        """
        Hand over what is queued and wait until the child has written it all out.

        ``size_bytes`` is then the size of the finished bag with everything handed over so far.
        """
        if self._failure is not None or self._closed:
            raise BagError(self._failure or f'bag {self.bag_path} is closed')
        if self._queued:
            self._send_queued()
        self._send(FLUSH, b'')
        descriptor = self._process.stdout.fileno()
        os.set_blocking(descriptor, True)
        try:
            while True:
                replies = self._take_replies()
                for reply in replies:
                    self._note(reply)
                if any('flushed' in reply for reply in replies):
                    break
                chunk = os.read(descriptor, 65536)
                if not chunk:
                    raise BagError(f'the bag writer ended with status '
                                   f'{self._process.wait()} before answering')
                self._replies += chunk
        finally:
            os.set_blocking(descriptor, False)
        if self._failure is not None:
            raise BagError(self._failure)

    def close(self) -> None:
        """
        Hand over what is queued, lets the child finish the bag and waits for it.

        Idempotent; raises BagError if the bag could not be finished.
        """
        if self._closed:
            return
        self._closed = True
        if self._failure is None and self._queued:
            try:
                self._send_queued()
            except BagError:
                pass  # reported below with what the child says
        os.set_blocking(self._process.stdout.fileno(), True)
        try:
            # closes the pipe, which tells the child to finish the bag
            rest, _ = self._process.communicate(timeout=CLOSE_TIMEOUT)
        except subprocess.TimeoutExpired:
            self._process.kill()
            self._process.wait()
            raise BagError(
                f'the bag writer of {self.bag_path} did not finish within {CLOSE_TIMEOUT:g} s'
            ) from None
        self._replies += rest
        closing_error = None
        closed = False
        for reply in self._take_replies():
            if 'error' in reply and reply.get('in_close'):
                closing_error = reply['error']
            closed = closed or 'closed' in reply
        if closing_error is not None:
            raise BagError(closing_error)
        if not closed:
            raise BagError(
                f'the bag writer of {self.bag_path} ended with status '
                f'{self._process.returncode} before finishing the bag'
            )

    def _send_queued(self) -> None:
        self._read_replies()
        if self._failure is not None:
            raise BagError(self._failure)
        batch, self._queued = self._queued, bytearray()
        self._batch_started = time.monotonic()
        self._send(MESSAGES, batch)

    def _send(self, kind: bytes, payload: bytes | bytearray) -> None:
        view = memoryview(_FRAME.pack(kind, len(payload)) + payload)
        try:
            while view:
                view = view[os.write(self._input, view):]
        except BrokenPipeError:
            self._failure = (f"the bag writer of {getattr(self, 'bag_path', 'the log')} "
                             f'ended unexpectedly (status {self._process.wait()})')
            raise BagError(self._failure) from None

    def _request(
        self, kind: bytes, payload: dict[str, Any], error_kind: type[BagError] = BagError
    ) -> dict[str, Any]:
        """Send a frame and wait for the child's answer to it (an error as ``error_kind``)."""
        self._send(kind, json.dumps(payload).encode('utf-8'))
        os.set_blocking(self._process.stdout.fileno(), True)
        line = self._process.stdout.readline()
        os.set_blocking(self._process.stdout.fileno(), False)
        if not line:
            raise BagError(
                f'the bag writer ended with status {self._process.wait()} before answering'
            )
        reply = json.loads(line)
        if 'error' in reply:
            raise error_kind(reply['error'])
        return reply

    def _read_replies(self) -> None:
        try:
            while chunk := os.read(self._process.stdout.fileno(), 65536):
                self._replies += chunk
        except BlockingIOError:
            pass
        for reply in self._take_replies():
            self._note(reply)

    def _note(self, reply: dict[str, Any]) -> None:
        """Take note of an unrequested reply: an error or a size."""
        if 'error' in reply and self._failure is None:
            self._failure = reply['error']
        if 'size' in reply:
            self.size_bytes = reply['size']

    def _take_replies(self) -> list[dict[str, Any]]:
        *lines, self._replies = self._replies.split(b'\n')
        return [json.loads(line) for line in lines if line]


# --- the child ------------------------------------------------------------------------------


def _open_bag(folder: Path, metadata: dict[str, str], split: dict[str, int]) -> BagWriter:
    """Return a new bag folder in ``folder``, named as ``ros2 bag record`` names it."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise BagError(
            f'cannot create log folder {folder}: {error.strerror or error}'
        ) from None
    base_name = time.strftime('rosbag2_%Y_%m_%d-%H_%M_%S')
    suffix = 0
    while True:
        name = base_name if suffix == 0 else f'{base_name}_{suffix}'
        try:
            return BagWriter(folder / name, metadata=metadata, **split)
        except BagExistsError:
            suffix += 1
        except BagError as error:
            raise BagError(f'cannot log into folder {folder}: {error}') from None


class _Child:
    def __init__(self, frames: BinaryIO, replies: BinaryIO) -> None:
        self._frames = frames
        self._replies = replies
        self._writer: BagWriter | None = None
        self._failed = False
        self._reported_size = -1
        self._last_report = 0.0

    def run(self) -> None:
        while (frame := self._read_frame()) is not None:
            kind, payload = frame
            if kind == MESSAGES:
                self._write_messages(payload)
            elif kind == START:
                self._start(json.loads(payload))
            elif kind == TOPIC:
                self._add_topic(json.loads(payload))
            elif kind == FLUSH:
                self._flush()
        self._close()

    def _read_frame(self) -> tuple[bytes, bytes] | None:
        header = self._frames.read(_FRAME.size)
        if len(header) < _FRAME.size:
            return None
        kind, length = _FRAME.unpack(header)
        payload = self._frames.read(length)
        # A node killed in the middle of a frame leaves it short: it is not a message.
        return (kind, payload) if len(payload) == length else None

    def _reply(self, **fields: Any) -> None:
        try:
            self._replies.write(json.dumps(fields).encode('utf-8') + b'\n')
            self._replies.flush()
        except BrokenPipeError:
            pass  # the node is gone; the bag is still finished

    def _start(self, request: dict[str, Any]) -> None:
        try:
            self._writer = _open_bag(
                Path(request['folder']), request['metadata'], request['split'])
        except BagError as error:
            self._reply(error=str(error))
            return
        self._reply(bag=str(self._writer.bag_path), size=self._writer.size_bytes)

    def _add_topic(self, request: dict[str, Any]) -> None:
        try:
            channel = self._writer.add_topic(
                request['topic'], request['type_name'], request['message_definition'],
                request['offered_qos_profiles'], request['repeat_latest'],
            )
        except (BagError, ValueError) as error:
            self._reply(error=str(error))
            return
        self._reply(channel=channel)

    def _write_messages(self, batch: bytes) -> None:
        if self._failed:
            return  # the node was told; it stops sending once it reads that
        try:
            self._writer.write_records(batch)
        except (BagError, ValueError) as error:
            self._failed = True
            self._reply(error=str(error))
            return
        now = time.monotonic()
        size = self._writer.size_bytes
        if size != self._reported_size and now - self._last_report >= SIZE_REPORT_INTERVAL:
            self._reported_size = size
            self._last_report = now
            self._reply(size=self._writer.finished_size())

    def _flush(self) -> None:
        if not self._failed:
            try:
                self._writer.flush()
            except BagError as error:
                self._failed = True
                self._reply(error=str(error))
        self._reply(size=self._writer.finished_size(), flushed=True)

    def _close(self) -> None:
        if self._writer is None:
            return
        try:
            self._writer.close()
        except BagError as error:
            self._reply(error=str(error), in_close=True)
        self._reply(closed=True, size=self._writer.size_bytes)


def main() -> None:
    # The node ends the log by closing the pipe; a signal meant for it must not cut the bag.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # Woken by the node's every batch, the child would otherwise preempt the node on its own
    # core for a whole chunk (Linux places a woken task beside its waker): a batch task keeps
    # its fair share of the CPU but never preempts on wake-up (docs/logging.md).
    if hasattr(os, 'SCHED_BATCH'):
        os.sched_setscheduler(0, os.SCHED_BATCH, os.sched_param(0))
    _Child(sys.stdin.buffer, sys.stdout.buffer).run()


if __name__ == '__main__':
    main()
