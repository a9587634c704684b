# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""The test scaffolding itself: domain ids no two share, and a teardown that always ends."""

from pathlib import Path
import signal
import subprocess
import sys

from node_process import end_process, NodeProcesses, PROCESS_TIMEOUT
import pytest
from ros_domains import DOMAIN_IDS, domain_lease

# A process that ignores SIGINT and SIGTERM: only SIGKILL ends it. It says so once it does.
STUBBORN = [sys.executable, '-c', (
    'import signal, sys, time\n'
    'signal.signal(signal.SIGINT, signal.SIG_IGN)\n'
    'signal.signal(signal.SIGTERM, signal.SIG_IGN)\n'
    'print("ignoring", flush=True)\n'
    'time.sleep(600)\n'
)]
# Deadlines short enough for a test that waits through all of them, long enough to be kept.
QUICK = ((int(signal.SIGINT), 2.0), (int(signal.SIGTERM), 2.0),
         (int(signal.SIGKILL), PROCESS_TIMEOUT))


def _stubborn() -> subprocess.Popen:
    """Start STUBBORN and wait until it ignores the signals (before that SIGINT would end it)."""
    process = subprocess.Popen(STUBBORN, stdout=subprocess.PIPE, text=True)
    assert process.stdout.readline() == 'ignoring\n'
    return process


def test_domain_leases_are_distinct_until_given_back() -> None:
    with domain_lease() as first, domain_lease() as second:
        assert first != second
        assert {first, second} <= set(DOMAIN_IDS)
    # Given back, an id is not the next one handed out: the leases go round.
    with domain_lease() as third:
        assert third not in (first, second)


def test_a_lease_of_ids_in_a_row_holds_each_of_them() -> None:
    """bench/run.py's five ids: no other lease gets one of them, neither by number nor next."""
    with domain_lease(5) as first:
        block = range(first, first + 5)
        assert set(block) <= set(DOMAIN_IDS)
        with pytest.raises(RuntimeError, match=(
                f'^ROS_DOMAIN_IDs {first + 4} to {first + 5}: another test or benchmark run '
                'holds one of them$')):
            with domain_lease(2, first + 4):
                pass
        with domain_lease() as single:
            assert single not in block


def test_domain_id_fixtures_differ(domain_id: int, other_domain_id: int) -> None:
    assert domain_id != other_domain_id


def test_end_process_escalates_to_sigkill() -> None:
    process = _stubborn()
    assert end_process(process, QUICK) == ['SIGINT', 'SIGTERM']
    assert process.returncode == -9


def test_end_process_leaves_an_ended_process_alone() -> None:
    process = subprocess.Popen([sys.executable, '-c', 'pass'])
    assert process.wait(timeout=PROCESS_TIMEOUT) == 0
    assert end_process(process, QUICK) == []


def test_a_process_ended_by_sigint_is_no_teardown_problem() -> None:
    processes = NodeProcesses(domain_id=0)
    process = processes.add(
        subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(600)']))
    assert processes.stop_all() == []
    assert process.returncode != 0  # KeyboardInterrupt


def test_teardown_failure_stays_beside_the_tests_own(pytester: pytest.Pytester) -> None:
    """The test's assertion is its reported failure; the teardown's is an error of its own."""
    pytester.makeconftest(f"""
import pytest
from node_process import NodeProcesses

@pytest.fixture
def nodes():
    processes = NodeProcesses(domain_id=0, stop_timeouts={QUICK!r})
    yield processes
    processes.finish()
""")
    pytester.makepyfile(f"""
import subprocess

def test_fails(nodes):
    process = nodes.add(subprocess.Popen({STUBBORN!r}, stdout=subprocess.PIPE, text=True))
    assert process.stdout.readline() == 'ignoring\\n'
    with open('pid', 'w') as pid:
        pid.write(str(process.pid))
    assert 1 == 2, 'the failure of the test itself'
""")
    result = pytester.runpytest_inprocess('-p', 'no:rerunfailures', '-p', 'no:cacheprovider')
    result.assert_outcomes(failed=1, errors=1)
    # pytest lists the errors (the teardown's) before the failures (the test's own).
    result.stdout.fnmatch_lines([
        '*ERROR at teardown of test_fails*',
        f'teardown: {sys.executable} (pid *) outlived SIGINT, SIGTERM',
        '*test_fails*',
        'E * AssertionError: the failure of the test itself',
    ])
    pid = int((pytester.path / 'pid').read_text())
    assert not Path(f'/proc/{pid}').exists()
