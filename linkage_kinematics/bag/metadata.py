# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A bag's ``metadata.yaml``, rosbag2's bag description (Jazzy, metadata version 9).

``BagMetadata`` is the one place that reads and writes it (and the ``rosbag2`` MCAP metadata
record, which holds the same text): the writer fills one in as it writes, the reader, the
recovery and the player read one back. The publishers' QoS lives in it as rosbag2 writes it,
a list of profiles with its policy names (``offered_qos_profiles_for`` makes that list from an
rclpy QoSProfile, ``qos_profile`` turns a profile back into one).

Plain Python: rclpy is imported only where a QoSProfile is made, so that the bag writer process
never loads it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from importlib import metadata as distribution_metadata
import os
from pathlib import Path
from typing import Any

from linkage_kinematics.bag.errors import BagError
import yaml

PACKAGE_NAME = 'linkage_kinematics'
METADATA_FILE = 'metadata.yaml'
ROSBAG2_METADATA_VERSION = 9
ROS_DISTRO = 'jazzy'
MESSAGE_ENCODING = 'cdr'
_TOP_KEY = 'rosbag2_bagfile_information'
# Topics a bare .mcap file (no metadata.yaml) is replayed transient local on, as the node
# offers them.
TRANSIENT_LOCAL_TOPICS = frozenset({'/robot_description'})
DEFAULT_DEPTH = 10
TRANSIENT_LOCAL = 'transient_local'  # rosbag2's name of the latching durability


def package_version() -> str:
    """Return this package's installed version ('unknown' when run from a source tree)."""
    try:
        return distribution_metadata.version(PACKAGE_NAME)
    except distribution_metadata.PackageNotFoundError:
        return 'unknown'


def _duration(nanoseconds: int) -> dict[str, int]:
    return {'sec': nanoseconds // 1_000_000_000, 'nsec': nanoseconds % 1_000_000_000}


def offered_qos_profiles_for(qos: Any) -> list[dict[str, Any]]:
    """Return rosbag2's (metadata version 9) profile list of a publisher offering ``qos``."""
    return [{
        'history': qos.history.name.lower(),
        'depth': qos.depth,
        'reliability': qos.reliability.name.lower(),
        'durability': qos.durability.name.lower(),
        'deadline': _duration(qos.deadline.nanoseconds),
        'lifespan': _duration(qos.lifespan.nanoseconds),
        'liveliness': qos.liveliness.name.lower(),
        'liveliness_lease_duration': _duration(qos.liveliness_lease_duration.nanoseconds),
        'avoid_ros_namespace_conventions': qos.avoid_ros_namespace_conventions,
    }]


# The bag writer serializes the metadata for its size report every 0.25 s; PyYAML's pure-Python
# dumper took 2 ms for it, libyaml's (in PyYAML's wheels and Debian's python3-yaml) writes the
# same text in a fraction of that. test_bag_writer checks the two agree.
_DUMPER = getattr(yaml, 'CSafeDumper', yaml.SafeDumper)


def yaml_text(data: Any) -> str:
    """Return ``data`` as ``yaml.safe_dump`` writes it, keys in their order."""
    return yaml.dump(data, Dumper=_DUMPER, sort_keys=False)


def qos_profiles_yaml(profiles: list[dict[str, Any]]) -> str:
    """Return the YAML text of a profile list, as the MCAP channel metadata holds it."""
    return yaml_text(profiles)


def qos_profile(topic: str, offered: dict[str, Any] | None) -> Any:
    """
    Return the rclpy QoSProfile to publish ``topic`` with, from its first offered profile.

    Without one (a bare .mcap file): reliable, keep last 10, transient local for the topics the
    node offers so. Names since metadata version 9, integers before.
    """
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    offered = offered or {}
    durability = offered.get('durability') or (
        TRANSIENT_LOCAL if topic in TRANSIENT_LOCAL_TOPICS else 'volatile'
    )
    return QoSProfile(
        history=_policy(HistoryPolicy, offered.get('history', 'keep_last')),
        depth=int(offered.get('depth') or DEFAULT_DEPTH),
        reliability=_policy(ReliabilityPolicy, offered.get('reliability', 'reliable')),
        durability=_policy(DurabilityPolicy, durability),
    )


def _policy(policy_enum: Any, value: Any) -> Any:
    try:
        if isinstance(value, int):
            return policy_enum(value)
        return policy_enum[str(value).upper()]
    except (KeyError, ValueError):
        raise BagError(
            f"the bag's QoS has an unknown {policy_enum.__name__} {value!r}") from None


@dataclass
class TopicInfo:
    """One topic of a bag: ``topic_metadata`` and ``message_count`` of metadata.yaml."""

    name: str
    type_name: str
    offered_qos_profiles: list[dict[str, Any]]
    type_hash: str = ''
    message_count: int = 0

    def entry(self) -> dict[str, Any]:
        return {
            'topic_metadata': {
                'name': self.name,
                'type': self.type_name,
                'serialization_format': MESSAGE_ENCODING,
                'offered_qos_profiles': self.offered_qos_profiles,
                'type_description_hash': self.type_hash,
            },
            'message_count': self.message_count,
        }

    @classmethod
    def from_entry(cls, entry: dict[str, Any]) -> TopicInfo:
        topic = entry['topic_metadata']
        profiles = topic.get('offered_qos_profiles') or []
        if isinstance(profiles, str):  # metadata versions before 9 keep YAML text
            profiles = yaml.safe_load(profiles) or []
        return cls(str(topic['name']), str(topic['type']), list(profiles),
                   str(topic.get('type_description_hash', '')),
                   int(entry.get('message_count', 0)))


@dataclass
class FileInfo:
    """One file of a bag: an entry of ``files`` in metadata.yaml."""

    path: str
    starting_time_ns: int = 0
    duration_ns: int = 0
    message_count: int = 0

    def entry(self) -> dict[str, Any]:
        return {
            'path': self.path,
            'starting_time': {'nanoseconds_since_epoch': self.starting_time_ns},
            'duration': {'nanoseconds': self.duration_ns},
            'message_count': self.message_count,
        }

    @classmethod
    def from_entry(cls, entry: dict[str, Any]) -> FileInfo:
        return cls(str(entry['path']),
                   int(entry.get('starting_time', {}).get('nanoseconds_since_epoch', 0)),
                   int(entry.get('duration', {}).get('nanoseconds', 0)),
                   int(entry.get('message_count', 0)))


@dataclass
class BagMetadata:
    """
    A bag folder's ``metadata.yaml`` (``rosbag2_bagfile_information``), field by field.

    ``read`` accepts what rosbag2 and other writers leave out (only ``relative_file_paths`` is
    required); ``write`` writes every field in rosbag2's order, atomically.
    """

    relative_file_paths: list[str] = field(default_factory=list)
    topics: list[TopicInfo] = field(default_factory=list)
    files: list[FileInfo] = field(default_factory=list)
    custom_data: dict[str, str] = field(default_factory=dict)
    starting_time_ns: int = 0
    duration_ns: int = 0
    message_count: int = 0
    storage_identifier: str = 'mcap'
    version: int = ROSBAG2_METADATA_VERSION
    ros_distro: str = ROS_DISTRO

    def information(self) -> dict[str, Any]:
        """Return the ``rosbag2_bagfile_information`` mapping, in rosbag2's order."""
        return {
            'version': self.version,
            'storage_identifier': self.storage_identifier,
            'duration': {'nanoseconds': self.duration_ns},
            'starting_time': {'nanoseconds_since_epoch': self.starting_time_ns},
            'message_count': self.message_count,
            'topics_with_message_count': [topic.entry() for topic in self.topics],
            'compression_format': '',
            'compression_mode': '',
            'relative_file_paths': list(self.relative_file_paths),
            'files': [file.entry() for file in self.files],
            'custom_data': dict(self.custom_data),
            'ros_distro': self.ros_distro,
        }

    def serialized(self) -> str:
        """Return the text of the ``rosbag2`` MCAP metadata record (``serialized_metadata``)."""
        return yaml_text(self.information())

    def write(self, folder: Path) -> None:
        """Write ``folder``/metadata.yaml (through a temporary file, so never half written)."""
        path = Path(folder) / METADATA_FILE
        temporary = path.with_name(METADATA_FILE + '.tmp')
        temporary.write_text(yaml_text({_TOP_KEY: self.information()}), encoding='utf-8')
        os.replace(temporary, path)

    @classmethod
    def read(cls, folder: str | os.PathLike[str]) -> BagMetadata:
        """Read ``folder``/metadata.yaml; BagError naming the file if it is not bag metadata."""
        path = Path(folder) / METADATA_FILE
        try:
            information = yaml.safe_load(path.read_text(encoding='utf-8'))[_TOP_KEY]
            relative_paths = information['relative_file_paths']
            return cls(
                relative_file_paths=(
                    [str(name) for name in relative_paths]
                    if isinstance(relative_paths, list) else []
                ),
                topics=[TopicInfo.from_entry(entry)
                        for entry in information.get('topics_with_message_count') or []],
                files=[FileInfo.from_entry(entry) for entry in information.get('files') or []],
                custom_data=dict(information.get('custom_data') or {}),
                starting_time_ns=int(
                    information.get('starting_time', {}).get('nanoseconds_since_epoch', 0)),
                duration_ns=int(information.get('duration', {}).get('nanoseconds', 0)),
                message_count=int(information.get('message_count', 0)),
                storage_identifier=str(information.get('storage_identifier', 'mcap')),
                version=int(information.get('version', ROSBAG2_METADATA_VERSION)),
                ros_distro=str(information.get('ros_distro', ROS_DISTRO)),
            )
        except (OSError, ValueError, yaml.YAMLError, KeyError, TypeError, AttributeError) as error:
            raise BagError(
                f'{path} is not rosbag2 bag metadata ({type(error).__name__}: '
                f"{' '.join(str(error).split())})"
            ) from None
