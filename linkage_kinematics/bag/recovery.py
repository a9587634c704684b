# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Recovery of a bag whose writer was killed: ``linkage-replay --recover BAG``.

A killed writer leaves an MCAP file without summary (its complete chunks are readable by
streaming, see ``reader``) and a metadata.yaml with the counts of the run's start.
``recover_bag`` rewrites it into a complete bag. Plain Python (no rclpy).
"""

from __future__ import annotations

from dataclasses import dataclass
import os
from pathlib import Path
import shutil

from linkage_kinematics.bag import reader
from linkage_kinematics.bag.definitions import message_definition
from linkage_kinematics.bag.errors import BagError
from linkage_kinematics.bag.metadata import BagMetadata, METADATA_FILE, qos_profiles_yaml
from linkage_kinematics.bag.writer import BagWriter


@dataclass(frozen=True)
class RecoveryResult:
    """What ``recover_bag`` did: the file it rewrote, its messages, whether it was cut short."""

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
    if not (bag / METADATA_FILE).is_file():
        raise BagError(f'{bag} is not a bag folder (no metadata.yaml)')
    files = reader.bag_files(bag)
    if len(files) != 1:
        raise BagError(f'bag {bag} has {len(files)} files; only one-file bags are recovered')
    source = files[0].path
    metadata = BagMetadata.read(bag)
    topics = {topic.name: topic for topic in metadata.topics}
    work = bag.parent / f'.{bag.name}.recovering'
    shutil.rmtree(work, ignore_errors=True)  # left over from an interrupted recovery
    work.mkdir()
    try:
        writer = BagWriter(work / source.stem.removesuffix('_0'), metadata=metadata.custom_data)
        channel_ids: dict[str, int] = {}
        count = 0
        for message in reader.iter_messages(bag):
            if message.topic not in channel_ids:
                topic = topics.get(message.topic)
                if topic is None:
                    raise BagError(
                        f'{source} has messages on {message.topic}, which {bag}/metadata.yaml '
                        'does not list'
                    )
                channel_ids[message.topic] = writer.add_topic(
                    message.topic,
                    topic.type_name,
                    message_definition(topic.type_name),
                    qos_profiles_yaml(topic.offered_qos_profiles),
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
        os.replace(writer.metadata_path, bag / METADATA_FILE)
        writer.bag_path.rmdir()
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return RecoveryResult(source, count, files[0].truncated)
