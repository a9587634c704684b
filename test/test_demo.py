# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
`linkage-demo` end to end.

The real node runs both seed scenarios, logs them, and the tables printed from the logs carry the
exact values (the seed's Table 1/2 rows and ω = 3.713 at 90°); the diagnostics in its bags move
with the mechanism.
"""

import math
from pathlib import Path
import subprocess
import sys

from diagnostic_msgs.msg import DiagnosticArray
from linkage_kinematics.bag.metadata import BagMetadata
from linkage_kinematics.bag.reader import iter_messages, read_states
from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.run.diagnostics import STATUS_PERIOD
import matplotlib.image
from node_process import ros_environment
import numpy as np
import pytest
from rclpy.serialization import deserialize_message

REPO = Path(__file__).resolve().parents[1]
DEMO = [sys.executable, '-m', 'linkage_kinematics.cli.demo']


def test_demo_logs_both_laws_and_prints_the_seed_tables(domain_id: int, tmp_path: Path) -> None:
    environment = ros_environment(domain_id)
    completed = subprocess.run(
        [*DEMO, '--log-folder', str(tmp_path / 'bags')],
        cwd=REPO, env=environment, capture_output=True, text=True, timeout=300,
    )
    assert completed.returncode == 0, completed.stderr
    bags = sorted(path for path in (tmp_path / 'bags').iterdir() if path.is_dir())
    assert len(bags) == 2
    for bag in bags:
        assert (bag / 'metadata.yaml').is_file()
        assert len(list(bag.glob('*.mcap'))) == 1
        height, width, _channels = matplotlib.image.imread(bag.parent / f'{bag.name}.png').shape
        assert width > 600 and height > 400
    # Each bag lasts the seed's turn in mechanism time, its 181 steps of 0.5° each logged when
    # the drive law reaches it.
    for bag, drive in zip(bags, (DriveLaw(2.0), DriveLaw(0.1, 2.3))):
        assert BagMetadata.read(bag).duration_ns == round(
            drive.time_to(0.0, math.pi / 2) * 1e9)
        log_times, states = read_states(bag)
        assert len(log_times) == 181
        assert states.alpha == pytest.approx(np.radians(np.arange(181) * 0.5), abs=1e-15)
        elapsed_ns = log_times - log_times[0]
        assert list(elapsed_ns) == [
            round(drive.time_to(0.0, alpha) * 1e9) for alpha in states.alpha]
    assert [round(BagMetadata.read(bag).duration_ns * 1e-6) for bag in bags] == [
        785, 1571]
    for bag in bags:
        check_diagnostics_follow_the_run(bag)
    constant, variable = completed.stdout.split('Variable law')
    # Table 1 and 2, α = 0 and 90° rows (constant law)
    for value in ('-6.667', '-57.78', '192.6', '0.1800', '5.200'):
        assert value in constant
    # exact variable law: ω = 0.1 at 0°, 3.713 at 90°, α̈ = 2.3·ω
    for value in ('0.1000', '3.713', '-0.3333', '0.0856', '-0.2852'):
        assert value in variable


def check_diagnostics_follow_the_run(bag: Path) -> None:
    """
    Check a status at least every STATUS_PERIOD of mechanism time, with right key values.

    From the first state to the last; the last one's log size within 10 % of the bag's.
    """
    statuses, state_times = [], []
    for message in iter_messages(bag, topics={'/diagnostics', '/linkage/state'}):
        if message.topic == '/linkage/state':
            state_times.append(message.log_time_ns)
            continue
        (status,) = deserialize_message(message.data, DiagnosticArray).status
        statuses.append((message.log_time_ns, {kv.key: kv.value for kv in status.values}))
    times = [time for time, _ in statuses]
    assert times[0] <= state_times[0] and times[-1] >= state_times[-1]
    within_run = [time for time in times if state_times[0] <= time <= state_times[-1]]
    gaps = np.diff([state_times[0], *within_run, state_times[-1]])
    assert gaps.max() <= STATUS_PERIOD * 1e9, bag
    assert len(within_run) >= (state_times[-1] - state_times[0]) / (STATUS_PERIOD * 1e9)
    (mcap_file,) = bag.glob('*.mcap')
    final = statuses[-1][1]
    assert abs(int(final['log size (bytes)']) - mcap_file.stat().st_size) <= (
        0.1 * mcap_file.stat().st_size)
    for _, values in statuses:
        # fixed_step paces by the drive law: no rate_hz, which it does not use
        assert values['mode'] == 'fixed_step' and 'rate_hz' not in values
        assert values['alpha_step (deg)'] == '0.5'
        assert values['missed deadlines'].isdigit() and values['log size (bytes)'].isdigit()
    residual = final['loop closure residual']
    assert 'e' in residual and float(residual) < 1e-12


@pytest.mark.parametrize(
    ('arguments', 'message'),
    [
        (['--rows', '0'], '--rows: must be at least 1'),
        (['--rows', 'two'], '--rows: not a whole number'),
        (['--rows', 'nan'], '--rows: not a whole number'),
    ],
)
def test_bad_arguments_get_one_line_and_no_run(
    arguments: list[str], message: str, tmp_path: Path
) -> None:
    completed = subprocess.run(
        [*DEMO, '--log-folder', str(tmp_path / 'bags'),
         *arguments],
        cwd=REPO, capture_output=True, text=True, timeout=60,
    )
    assert completed.returncode == 2
    assert message in completed.stderr
    assert 'Traceback' not in completed.stderr
    assert not (tmp_path / 'bags').exists()


def test_unwritable_log_folder_is_reported_without_a_traceback(
    domain_id: int, tmp_path: Path
) -> None:
    blocker = tmp_path / 'a_file'
    blocker.write_text('not a folder')
    environment = ros_environment(domain_id)
    completed = subprocess.run(
        [*DEMO, '--log-folder', str(blocker / 'bags')],
        cwd=REPO, env=environment, capture_output=True, text=True, timeout=60,
    )
    assert completed.returncode == 1
    assert 'invalid parameter log.folder' in completed.stderr
    assert 'linkage_node exited with status 2' in completed.stderr
    assert 'Traceback' not in completed.stderr
