# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Recovery of a bag whose writer was killed: ``linkage-replay --recover BAG``.

A killed writer leaves its open MCAP file without summary (its complete chunks are readable by
streaming, see ``reader``; the files a split bag finished before are complete) and a
metadata.yaml without the last counts. ``recover_bag`` rewrites every file into a complete one
and metadata.yaml with what the files hold. Plain Python (no rclpy).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
import os
from pathlib import Path
import shutil

from linkage_kinematics.bag import reader
from linkage_kinematics.bag.definitions import message_definition
from linkage_kinematics.bag.errors import BagError
from linkage_kinematics.bag.metadata import (
    BagMetadata,
    FileInfo,
    METADATA_FILE,
    TopicInfo,
)
from linkage_kinematics.bag.writer import BagWriter


@dataclass(frozen=True)
class RecoveryResult:
    """What ``recover_bag`` did: the files it rewrote, their messages, whether one was cut."""

    mcap_paths: list[Path]
    message_count: int
    was_truncated: bool


def recover_bag(bag_path: Path | str) -> RecoveryResult:
    """
    Rewrite a bag's MCAP files with summary, indexes and true counts (e.g. after SIGKILL).

    Every message of every complete record is kept with its topic and times; a partly written
    last chunk is dropped. Topics, types, QoS and the run's metadata come from the bag's
    metadata.yaml (written when the run started), schemas from the installed .msg files.
    On a complete bag it rewrites the same content.
    """
    bag = Path(bag_path)
    if not (bag / METADATA_FILE).is_file():
        raise BagError(f'{bag} is not a bag folder (no metadata.yaml)')
    files = reader.bag_files(bag)
    metadata = BagMetadata.read(bag)
    topics = {topic.name: topic for topic in metadata.topics}
    work = bag.parent / f'.{bag.name}.recovering'
    shutil.rmtree(work, ignore_errors=True)  # left over from an interrupted recovery
    work.mkdir()
    try:
        entries = [_rewrite(bag, mcap_file.path, topics, metadata.custom_data, work)
                   for mcap_file in files]
    finally:
        shutil.rmtree(work, ignore_errors=True)
    counts: Counter[str] = sum((counted for _, counted in entries), Counter())
    infos = [info for info, _ in entries if info.message_count]
    start = min((info.starting_time_ns for info in infos), default=0)
    end = max((info.starting_time_ns + info.duration_ns for info in infos), default=0)
    BagMetadata(
        relative_file_paths=[info.path for info, _ in entries],
        topics=[TopicInfo(topic.name, topic.type_name, topic.offered_qos_profiles,
                          topic.type_hash, counts[topic.name]) for topic in topics.values()],
        files=[info for info, _ in entries],
        custom_data=metadata.custom_data,
        starting_time_ns=start,
        duration_ns=end - start,
        message_count=sum(counts.values()),
    ).write(bag)
    return RecoveryResult([mcap_file.path for mcap_file in files], sum(counts.values()),
                          any(mcap_file.truncated for mcap_file in files))


def _rewrite(bag: Path, source: Path, topics: dict[str, TopicInfo],
             custom_data: dict[str, str], work: Path) -> tuple[FileInfo, Counter[str]]:
    """Rewrite one MCAP file of ``bag`` complete; its metadata entry and its topics' counts."""
    # a first file keeps its name inside its rosbag2 record too
    writer = BagWriter(work / source.stem.removesuffix('_0'), metadata=custom_data)
    channel_ids: dict[str, int] = {}
    counts: Counter[str] = Counter()
    log_times = []
    for message in reader.iter_messages(source):
        if message.topic not in channel_ids:
            topic = topics.get(message.topic)
            if topic is None:
                raise BagError(
                    f'{source} has messages on {message.topic}, which {bag}/metadata.yaml '
                    'does not list'
                )
            channel_ids[message.topic] = writer.add_topic(
                message.topic, topic.type_name, message_definition(topic.type_name),
                topic.offered_qos_profiles,
            )
        writer.write(channel_ids[message.topic], message.data, message.log_time_ns,
                     message.publish_time_ns)
        counts[message.topic] += 1
        log_times.append(message.log_time_ns)
    writer.close()
    os.replace(writer.mcap_path, source)
    start = min(log_times, default=0)
    return FileInfo(source.name, start, max(log_times, default=0) - start, len(log_times)), counts
