# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The node's side of logging: topics and encoded messages in, a bag written by another process.

Adding a topic to the recording is one call, ``Recorder.add_topic(topic, msg_type, qos)``,
with the publisher's resolved topic name, its rclpy message class and its QoSProfile; the
recorder finds the type's definition and hash in the ament index and stores the QoS as
rosbag2 does. A latched topic (transient local, or ``repeat_latest=True``) has its latest
message repeated at the start of every further file of a split bag. The node's own topics are
given to the constructor, which finds all their definitions before the bag folder is made.
Then ``record(topic, data, log_time_ns)`` logs each message's CDR bytes (the bytes the node
publishes, ``cdr.encode_cdr`` or a ``FixedShapeEncoder``). Every failure is a ``BagError``
(an ``OSError``) whose text names the file and the cause.
"""

from __future__ import annotations

from collections.abc import Sequence, Set
from pathlib import Path
from typing import Any

from linkage_kinematics.bag.definitions import message_definition
from linkage_kinematics.bag.metadata import (
    offered_qos_profiles_for,
    TRANSIENT_LOCAL,
)
from linkage_kinematics.bag.writer_process import BagWriterProcess
from linkage_kinematics.shared.cdr import ros_type_name
from linkage_kinematics.shared.rosbag2_split import NO_SPLIT

# A topic to record: its resolved name, rclpy message class, QoS profile and whether its latest
# message starts every file (None: if the QoS is transient local).
Topic = tuple[str, type, Any, bool | None]


class Recorder:
    """
    Logs a run into a new rosbag2 bag folder inside ``folder`` (never overwriting one).

    Written by a BagWriter in a process of its own (``writer_process``) and split as it is
    told (``max_bag_size`` bytes, ``max_bag_duration`` s; ``NO_SPLIT``: never). ``topics`` are
    added first, their definitions found before anything is created (MessageDefinitionError
    otherwise; LogFolderError if ``folder`` cannot be written); ``metadata`` (the run's
    parameters, strings) goes into the bag's custom data, ``cpus`` are the CPUs the writer
    process may run on.
    """

    def __init__(
        self, folder: Path, *, topics: Sequence[Topic] = (), metadata: dict[str, str],
        cpus: Set[int] | None = None, max_bag_size: int = NO_SPLIT,
        max_bag_duration: float = NO_SPLIT,
    ) -> None:
        for _, msg_type, _, _ in topics:
            message_definition(ros_type_name(msg_type))
        self._writer = BagWriterProcess(
            folder, metadata=metadata, cpus=cpus, max_bag_size=max_bag_size,
            max_bag_duration_ns=round(max_bag_duration * 1e9),
        )
        self.bag_path: Path = self._writer.bag_path
        self._channels: dict[str, int] = {}
        try:
            for topic in topics:
                self.add_topic(*topic)
        except OSError:
            self._writer.close()
            raise

    @property
    def size_bytes(self) -> int:
        """
        Return the size the finished MCAP file will have, as the writer last reported it.

        Counting what it has written out: it reports at most every 0.25 s and after ``flush``.
        """
        return self._writer.size_bytes

    def add_topic(
        self, topic: str, msg_type: type, qos: Any, repeat_latest: bool | None = None
    ) -> None:
        """
        Record ``topic`` (its resolved name) of rclpy class ``msg_type`` offered at ``qos``.

        ``repeat_latest``: whether each further file of a split bag starts with the topic's
        latest message; by default if ``qos`` is transient local (a latched topic).
        """
        type_name = ros_type_name(msg_type)
        if repeat_latest is None:
            repeat_latest = qos.durability.name.lower() == TRANSIENT_LOCAL
        self._channels[topic] = self._writer.add_topic(
            topic, type_name, message_definition(type_name),
            offered_qos_profiles_for(qos), repeat_latest,
        )

    def run_writer_on(self, cpus: Set[int]) -> None:
        """Let the bag writer process run only on ``cpus``."""
        self._writer.run_on(cpus)

    def record(self, topic: str, data: bytes, log_time_ns: int) -> None:
        """Log ``data``, a message of ``topic`` encoded as the node publishes it."""
        self._writer.write(self._channels[topic], data, log_time_ns, log_time_ns)

    def flush(self) -> None:
        """Wait until the writer has written out everything it was given (``size_bytes`` too)."""
        self._writer.flush()

    def close(self) -> None:
        """Finish the bag: wait until its writer has written everything it was given."""
        self._writer.close()
