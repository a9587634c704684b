# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Stamps are mechanism time.

Every logged state sits at the node-clock time at which the drive law puts the crank at its α, in
both modes and under both laws, and the log shows the motion's activity as it changes. Real node
runs, read back with rosbags.
"""

from __future__ import annotations

import math
from pathlib import Path

from linkage_kinematics.bag.reader import iter_messages
from linkage_kinematics.kinematics.drive import DriveLaw
from node_process import NodeProcesses
import pytest
from rosbags.rosbag2 import Reader
from rosbags.typesys import get_typestore, Stores

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
ALPHA_START = 0.3  # rad; far enough from the paper's dead point for an OK status
ALPHA_END = math.pi / 2
LAWS = {'constant': DriveLaw(4.0), 'variable': DriveLaw(0.1, 2.3)}


def _stamp_ns(message) -> int:
    return message.header.stamp.sec * 1_000_000_000 + message.header.stamp.nanosec


def _logged(bag: Path) -> dict[str, list[tuple[int, object]]]:
    """Topic -> [(log time ns, decoded message)] in log order."""
    logged: dict[str, list[tuple[int, object]]] = {}
    with Reader(bag) as reader:
        for connection, log_time, raw in reader.messages():
            logged.setdefault(connection.topic, []).append(
                (log_time, TYPESTORE.deserialize_cdr(raw, connection.msgtype)))
    return logged


@pytest.fixture(scope='module', params=[(mode, law) for mode in ('real_time', 'fixed_step')
                                        for law in LAWS], ids=lambda p: f'{p[0]}-{p[1]}')
def run(
    request, tmp_path_factory, module_nodes: NodeProcesses
) -> tuple[DriveLaw, dict[str, list[tuple[int, object]]], Path]:
    mode, law = request.param
    drive = LAWS[law]
    folder = tmp_path_factory.mktemp(f'{mode}_{law}')
    status, output = module_nodes.run(
        {'mode': mode, 'omega0': drive.omega0, 'k': drive.k, 'alpha_start': ALPHA_START,
         'alpha_end': ALPHA_END, 'alpha_step': math.radians(2.0), 'end_behavior': 'stop',
         'log.folder': str(folder / 'bags')},
        folder / 'node.log')
    assert status == 0, output
    (bag,) = (folder / 'bags').iterdir()
    return drive, _logged(bag), bag


def test_each_state_is_stamped_when_the_drive_law_reaches_its_alpha(run) -> None:
    drive, logged, _ = run
    states = logged['/linkage/state']
    start = _stamp_ns(states[0][1])
    for log_time, message in states:
        point = message.points[0]
        elapsed_ns = _stamp_ns(message) - start
        assert log_time == _stamp_ns(message)
        # 1e-9 rad, plus what half a nanosecond of the stamp's resolution moves the crank.
        assert point.positions[0] == pytest.approx(
            drive.alpha_at(ALPHA_START, elapsed_ns * 1e-9),
            abs=1e-9 + 0.5e-9 * abs(point.velocities[0]))
        time_from_start = point.time_from_start
        assert time_from_start.sec * 1_000_000_000 + time_from_start.nanosec == elapsed_ns
    last = states[-1][1]
    assert last.points[0].positions[0] == ALPHA_END
    assert _stamp_ns(last) - start == round(drive.time_to(ALPHA_START, ALPHA_END) * 1e9)


def test_the_log_spans_the_motion_and_starts_with_the_scene(run) -> None:
    drive, logged, bag = run
    everything = [(message.log_time_ns, message.topic) for message in iter_messages(bag)]
    start = _stamp_ns(logged['/linkage/state'][0][1])
    # The scene comes first, so a viewer knows the frame before anything refers to it.
    assert everything[0] == (start, '/linkage/markers')
    assert everything[-1][0] - start == round(drive.time_to(ALPHA_START, ALPHA_END) * 1e9)
    assert logged['/robot_description'][0][0] == start


def test_the_logged_diagnostics_follow_the_motion(run) -> None:
    _, logged, _ = run
    statuses = [(message.status[0].level, message.status[0].message)
                for _, message in logged['/diagnostics']]
    assert statuses[0] == (0, 'moving')
    level, text = statuses[-1]
    assert level == 0 and text.startswith('reached alpha_end = 90.000000°')
