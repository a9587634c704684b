# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The topics whose latest message starts each further file of a split bag, and those messages.

``BagWriter.add_topic(..., repeat_latest=True)`` (what rosbag2 later named
``--repeat-transient-local``): a file of a split bag then opens alone, with the latest message
of each latched topic (the node's scene and URDF). Plain Python, no MCAP: the writer writes
what this keeps.
"""

from __future__ import annotations

from collections.abc import Iterator


class RepeatedTopics:
    """The channel ids added with ``repeat_latest``, and each one's latest message."""

    def __init__(self) -> None:
        self._channel_ids: set[int] = set()
        self._latest: dict[int, tuple[bytes, int]] = {}  # data and publish time, by channel id

    def add(self, channel_id: int) -> None:
        """Repeat the topic of ``channel_id`` at the start of each further file."""
        self._channel_ids.add(channel_id)

    def remember(self, channel_id: int, data: bytes, publish_time_ns: int) -> None:
        """Keep a message just written, if its topic is repeated."""
        if channel_id in self._channel_ids:
            self._latest[channel_id] = (data, publish_time_ns)

    def latest(self) -> Iterator[tuple[int, bytes, int]]:
        """Yield the latest message of each repeated topic: channel id, data, publish time."""
        for channel_id, (data, publish_time_ns) in self._latest.items():
            yield channel_id, data, publish_time_ns
