# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
``linkage-replay``.

Republish a logged run for labs without rosbag2, or recover a killed one.

    linkage-replay BAG [--rate FACTOR] [--loop] [--topics TOPIC ...]
                       [--exclude-topics TOPIC ...] [--delay SECONDS]
    linkage-replay --recover BAG

Replaying publishes each message's logged CDR bytes unchanged on its logged topic, with its
logged type and QoS (from the bag's metadata.yaml; without one, reliable depth 10, and transient
local for ``/robot_description`` as the node offers it), at the logged log-time spacing divided
by ``--rate``. Topics whose message type is not installed here are skipped with a warning.
``--exclude-topics /tf /tf_static`` leaves out the bag's TF where a robot_state_publisher
publishes it from the replayed joint states (as ``ros2 bag play --exclude-topics``).
``--recover`` rewrites a bag whose recorder was killed into a complete one (see
docs/logging.md).
"""
from __future__ import annotations

import argparse
from collections.abc import Sequence
from dataclasses import dataclass
import importlib
from pathlib import Path
import signal
import sys
import time
from typing import Any

from linkage_kinematics import bag_reader
from linkage_kinematics.bag_writer import BagWriteError, recover_bag
from linkage_kinematics.cli_types import number
import rclpy
from rclpy.duration import Duration
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
import yaml

TRANSIENT_LOCAL_TOPICS = frozenset({'/robot_description'})
ACK_TIMEOUT_S = 2.0


class ReplayError(Exception):
    """The bag cannot be replayed; the message says why."""


@dataclass(frozen=True)
class TopicPlan:
    topic: str
    type_name: str
    msg_type: type
    offered_qos: dict[str, Any] | None


_positive_rate = number(above=0.0, rule='a positive factor')
_non_negative_seconds = number(at_least=0.0, rule='zero or more seconds')


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog='linkage-replay',
        description='Republish a logged linkage run (a rosbag2 MCAP bag folder or .mcap file) '
        'with its recorded timing, or recover a bag whose recorder was killed.',
    )
    parser.add_argument('bag', help='bag folder (as logged by the node) or .mcap file')
    parser.add_argument(
        '--rate', type=_positive_rate, default=1.0, help='speed factor (2 = twice as fast)'
    )
    parser.add_argument('--loop', action='store_true', help='start over at the end, until Ctrl-C')
    parser.add_argument('--topics', nargs='+', metavar='TOPIC', help='replay only these topics')
    parser.add_argument(
        '--exclude-topics', nargs='+', metavar='TOPIC', default=[],
        help='do not replay these topics, e.g. /tf /tf_static where a robot_state_publisher '
        'publishes TF from the replayed joint states',
    )
    parser.add_argument(
        '--delay',
        type=_non_negative_seconds,
        default=1.0,
        help='seconds to wait after creating the publishers, for subscribers to connect (1.0)',
    )
    parser.add_argument(
        '--recover',
        action='store_true',
        help='instead of replaying, rewrite BAG (after SIGKILL) so every reader accepts it',
    )
    return parser


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
    metadata_path = bag / 'metadata.yaml'
    if bag.is_dir() and metadata_path.is_file():
        try:
            information = yaml.safe_load(metadata_path.read_text(encoding='utf-8'))[
                'rosbag2_bagfile_information'
            ]
            topics = {}
            for entry in information['topics_with_message_count']:
                topic = entry['topic_metadata']
                profiles = topic.get('offered_qos_profiles') or []
                if isinstance(profiles, str):  # metadata versions before 9 keep YAML text
                    profiles = yaml.safe_load(profiles) or []
                topics[topic['name']] = (topic['type'], profiles[0] if profiles else None)
            return topics
        except (yaml.YAMLError, KeyError, TypeError, IndexError, AttributeError) as error:
            raise ReplayError(f'{metadata_path} is not rosbag2 bag metadata ({error!r})') from None
    found: dict[str, tuple[str, dict[str, Any] | None]] = {}
    for message in bag_reader.iter_messages(bag):
        found.setdefault(message.topic, (message.schema_name, None))
    return found


def _plan(bag: Path, wanted: Sequence[str] | None, excluded: Sequence[str]) -> list[TopicPlan]:
    logged = _logged_topics(bag)
    if wanted:
        missing = sorted(set(wanted) - set(logged))
        if missing:
            raise ReplayError(
                f"{bag} has no topic {', '.join(missing)}; it has {', '.join(sorted(logged))}"
            )
        logged = {topic: logged[topic] for topic in wanted}
    # Like rosbag2, an excluded topic the bag does not hold is no error (an older bag has no TF).
    logged = {topic: entry for topic, entry in logged.items() if topic not in excluded}
    if not logged:
        raise ReplayError(f'nothing to replay in {bag}: every topic is excluded')
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
        raise ReplayError(
            f'nothing to replay in {bag}: none of its message types is installed here'
        )
    return plans


def _qos(plan: TopicPlan) -> QoSProfile:
    offered = plan.offered_qos or {}
    durability = offered.get('durability') or (
        'transient_local' if plan.topic in TRANSIENT_LOCAL_TOPICS else 'volatile'
    )
    history = offered.get('history', 'keep_last')
    return QoSProfile(
        history=_policy(HistoryPolicy, history),
        depth=int(offered.get('depth') or 10),
        reliability=_policy(ReliabilityPolicy, offered.get('reliability', 'reliable')),
        durability=_policy(DurabilityPolicy, durability),
    )


def _policy(policy_enum: Any, value: Any) -> Any:
    """
    Return an rclpy QoS policy from rosbag2's metadata.

    The metadata has names since version 9, integers before.
    """
    try:
        if isinstance(value, int):
            return policy_enum(value)
        return policy_enum[str(value).upper()]
    except (KeyError, ValueError):
        raise ReplayError(
            f"the bag's QoS has an unknown {policy_enum.__name__} {value!r}") from None


def _replay(bag: Path, plans: list[TopicPlan], rate: float, loop: bool, delay: float) -> int:
    # Without rclpy's handler, Ctrl-C (and SIGTERM) is a KeyboardInterrupt here instead of a
    # context shut down under a publish in progress; set even where SIGINT came in ignored.
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    for stop_signal in (signal.SIGINT, signal.SIGTERM):
        signal.signal(stop_signal, signal.default_int_handler)
    node = rclpy.create_node('linkage_replay')
    published = 0
    try:
        publishers = {
            plan.topic: node.create_publisher(plan.msg_type, plan.topic, _qos(plan))
            for plan in plans
        }
        time.sleep(delay)
        while True:
            first_log_time = None
            wall_start = time.monotonic()
            for message in bag_reader.iter_messages(bag, topics=publishers.keys()):
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
    print(f'linkage-replay: published {published} messages from {bag}', file=sys.stderr)
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    arguments = _parser().parse_args(argv)
    bag = Path(arguments.bag)
    try:
        if arguments.recover:
            result = recover_bag(bag)
            state = (
                'was cut short; its complete part' if result.was_truncated else 'was complete; it'
            )
            print(
                f'linkage-replay: {bag} {state} is now {result.mcap_path} '
                f'with summary ({result.message_count} messages)'
            )
            return 0
        files = bag_reader.bag_files(bag)
        cut = [str(file.path) for file in files if file.truncated]
        if cut:
            raise ReplayError(
                f"{', '.join(cut)} ends without its summary (the recorder was killed); "
                f'run `linkage-replay --recover {bag}` first'
            )
        plans = _plan(bag, arguments.topics, arguments.exclude_topics)
        return _replay(bag, plans, arguments.rate, arguments.loop, arguments.delay)
    except (ReplayError, bag_reader.BagError, BagWriteError) as error:
        print(f'linkage-replay: {error}', file=sys.stderr)
        return 1
    except OSError as error:
        print(f'linkage-replay: {bag}: {error.strerror or error}', file=sys.stderr)
        return 1


if __name__ == '__main__':
    sys.exit(main())
