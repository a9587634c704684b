# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Republishing a logged run with its timing, for labs without rosbag2 (``linkage-replay``).

Each message's logged CDR bytes go out unchanged on its logged topic, with its logged type and
QoS (from the bag's metadata.yaml; for a bare .mcap file ``metadata.qos_profile``'s defaults),
at the logged log-time spacing divided by the rate. Topics whose message type is not installed
here are skipped with a warning.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
import importlib
from pathlib import Path
import signal
import sys
import time
from typing import Any

from linkage_kinematics.bag import reader
from linkage_kinematics.bag.errors import BagError
from linkage_kinematics.bag.metadata import BagMetadata, METADATA_FILE, qos_profile
import rclpy
from rclpy.duration import Duration
from rclpy.signals import SignalHandlerOptions

ACK_TIMEOUT_S = 2.0


@dataclass(frozen=True)
class TopicPlan:
    """A topic to republish: its name, type and first offered QoS profile (if logged)."""

    topic: str
    type_name: str
    msg_type: type
    offered_qos: dict[str, Any] | None


def _import_message_type(type_name: str) -> type | None:
    parts = type_name.split('/')
    if len(parts) != 3:
        return None
    try:
        module = importlib.import_module(f'{parts[0]}.{parts[1]}')
    except ImportError:
        return None
    msg_type = getattr(module, parts[2], None)
    return msg_type if isinstance(msg_type, type) else None


def _logged_topics(bag: Path) -> dict[str, tuple[str, dict[str, Any] | None]]:
    """Topic -> (type name, first offered QoS profile or None) of every logged topic."""
    if bag.is_dir() and (bag / METADATA_FILE).is_file():
        return {
            topic.name: (
                topic.type_name,
                topic.offered_qos_profiles[0] if topic.offered_qos_profiles else None,
            )
            for topic in BagMetadata.read(bag).topics
        }
    found: dict[str, tuple[str, dict[str, Any] | None]] = {}
    for message in reader.iter_messages(bag):
        found.setdefault(message.topic, (message.schema_name, None))
    return found


def plan_topics(
    bag: Path, wanted: Sequence[str] | None, excluded: Sequence[str] = ()
) -> list[TopicPlan]:
    """Return what to republish of ``bag``: only ``wanted`` topics, if given, less ``excluded``."""
    logged = _logged_topics(bag)
    if wanted:
        missing = sorted(set(wanted) - set(logged))
        if missing:
            raise BagError(
                f"{bag} has no topic {', '.join(missing)}; it has {', '.join(sorted(logged))}"
            )
        logged = {topic: logged[topic] for topic in wanted}
    # Like rosbag2, an excluded topic the bag does not hold is no error (an older bag has no TF).
    logged = {topic: entry for topic, entry in logged.items() if topic not in excluded}
    if not logged:
        raise BagError(f'nothing to replay in {bag}: every topic is excluded')
    plans = []
    for topic, (type_name, offered_qos) in logged.items():
        msg_type = _import_message_type(type_name)
        if msg_type is None:
            print(
                f'linkage-replay: skipping {topic}: '
                f'message type {type_name!r} is not installed here',
                file=sys.stderr,
            )
            continue
        plans.append(TopicPlan(topic, type_name, msg_type, offered_qos))
    if not plans:
        raise BagError(
            f'nothing to replay in {bag}: none of its message types is installed here'
        )
    return plans


def replay(bag: Path, plans: list[TopicPlan], rate: float, loop: bool, delay: float) -> int:
    """Republish ``plans``' topics of ``bag`` until done (or Ctrl-C, SIGTERM); count them."""
    # Without rclpy's handler, Ctrl-C (and SIGTERM) is a KeyboardInterrupt here instead of a
    # context shut down under a publish in progress; set even where SIGINT came in ignored.
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    for stop_signal in (signal.SIGINT, signal.SIGTERM):
        signal.signal(stop_signal, signal.default_int_handler)
    node = rclpy.create_node('linkage_replay')
    published = 0
    try:
        publishers = {
            plan.topic: node.create_publisher(
                plan.msg_type, plan.topic, qos_profile(plan.topic, plan.offered_qos))
            for plan in plans
        }
        time.sleep(delay)
        while True:
            first_log_time = None
            wall_start = time.monotonic()
            for message in reader.iter_messages(bag, topics=publishers.keys()):
                if first_log_time is None:
                    first_log_time = message.log_time_ns
                due = wall_start + (message.log_time_ns - first_log_time) * 1e-9 / rate
                pause = due - time.monotonic()
                if pause > 0:
                    time.sleep(pause)
                publishers[message.topic].publish(message.data)
                published += 1
            if not loop:
                break
        for publisher in publishers.values():
            publisher.wait_for_all_acked(Duration(seconds=ACK_TIMEOUT_S))
    except KeyboardInterrupt:
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return published
