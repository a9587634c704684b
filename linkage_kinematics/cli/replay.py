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
from pathlib import Path
import sys

from linkage_kinematics.bag import player, reader
from linkage_kinematics.bag.errors import BagError
from linkage_kinematics.bag.recovery import recover_bag
from linkage_kinematics.cli.arguments import number

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


def main(argv: Sequence[str] | None = None) -> int:
    arguments = _parser().parse_args(argv)
    bag = Path(arguments.bag)
    try:
        if arguments.recover:
            result = recover_bag(bag)
            state = (
                'was cut short; its complete part' if result.was_truncated else 'was complete; it'
            )
            paths = ', '.join(str(path) for path in result.mcap_paths)
            print(f'linkage-replay: {bag} {state} is now {paths} '
                  f'with summary ({result.message_count} messages)')
            return 0
        files = reader.bag_files(bag)
        cut = [str(file.path) for file in files if file.truncated]
        if cut:
            print(
                f"linkage-replay: {', '.join(cut)} ends without its summary (the recorder was "
                f'killed); run `linkage-replay --recover {bag}` first', file=sys.stderr,
            )
            return 1
        plans = player.plan_topics(bag, arguments.topics, arguments.exclude_topics)
        published = player.replay(
            bag, plans, arguments.rate, arguments.loop, arguments.delay)
    except OSError as error:
        # A BagError's text names the bag and the cause; another OSError's only the cause.
        detail = str(error) if isinstance(error, BagError) else f'{bag}: {error.strerror or error}'
        print(f'linkage-replay: {detail}', file=sys.stderr)
        return 1
    print(f'linkage-replay: published {published} messages from {bag}', file=sys.stderr)
    return 0


if __name__ == '__main__':
    sys.exit(main())
