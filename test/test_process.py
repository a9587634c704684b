# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
ros.process, the process both nodes run in, around a node of its own.

A small real node (a timer that looks at its process, then ends the run or waits) runs in a
process of its own: what start-up made is frozen for the collector and the timed waits have 1 ns
of slack by the time the executor runs a callback; the node's own exit status is the process's,
a signal's is 0, a log that cannot be closed 1, and a node that cannot start 2 with one line.
The nodes' own tests hold them to this (test_node*.py, test_command_node.py,
test_node_cpu_affinity.py); here each way out is taken once.
"""

from __future__ import annotations

from pathlib import Path
import signal
import subprocess
import sys
import time

from node_process import PROCESS_TIMEOUT, REPOSITORY, ros_environment
import pytest

# The node ends its run (EXIT_CODE) or waits for a signal ('none'); its log closes or not.
SCRIPT = """
import gc
import sys
from linkage_kinematics.ros.exit_codes import ExitCode
from linkage_kinematics.ros.process import run_node, StartupError
from rclpy.node import Node

ending, log_closes = sys.argv[1], sys.argv[2] == 'closes'


class Looking(Node):
    exit_code = None

    def __init__(self):
        if ending == 'start':
            raise StartupError('cannot record: no room')
        super().__init__('looking')
        self.create_timer(0.01, self.look)

    def look(self):
        with open('/proc/self/timerslack_ns') as slack:
            print('frozen', gc.get_freeze_count() > 0, 'slack', slack.read().strip(), flush=True)
        if ending != 'none':
            self.exit_code = ExitCode[ending]

    def flush(self, timeout=1.0):
        print('flushed', flush=True)

    def close_log(self):
        return log_closes


sys.exit(run_node('looking', Looking, None))
"""


def run(domain_id: int, tmp_path: Path, ending: str, log: str,
        stop: int | None = None) -> tuple[int, list[str]]:
    """Run SCRIPT to its end (after ``stop`` once it looked); its status and output lines."""
    output = tmp_path / 'process.log'
    with open(output, 'w') as out:
        process = subprocess.Popen([sys.executable, '-c', SCRIPT, ending, log], cwd=REPOSITORY,
                                   env=ros_environment(domain_id), stdout=out,
                                   stderr=subprocess.STDOUT)
    try:
        if stop is not None:
            with open(output) as lines:
                while 'frozen' not in lines.readline():
                    assert process.poll() is None, output.read_text()
                    time.sleep(0.01)  # a poll of the file, not a wait on time
            process.send_signal(stop)
        status = process.wait(timeout=PROCESS_TIMEOUT)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    return status, output.read_text().splitlines()


@pytest.mark.parametrize(('ending', 'log', 'status'), [
    ('OK', 'closes', 0), ('FAILED', 'closes', 1), ('OK', 'fails', 1)])
def test_the_node_s_end_is_the_process_s(domain_id, tmp_path, ending, log, status):
    code, lines = run(domain_id, tmp_path, ending, log)
    assert code == status, lines
    # start-up frozen for the collector, waits on time, before the first callback
    assert lines[0] == 'frozen True slack 1'
    assert lines[-1] == 'flushed'


@pytest.mark.parametrize('stop', [signal.SIGINT, signal.SIGTERM])
def test_a_signal_ends_the_run_with_0(domain_id, tmp_path, stop):
    code, lines = run(domain_id, tmp_path, 'none', 'closes', stop)
    assert code == 0, lines
    assert lines[-1] == 'flushed'


def test_a_node_that_cannot_start_exits_2_with_one_line(domain_id, tmp_path):
    code, lines = run(domain_id, tmp_path, 'start', 'closes')
    assert code == 2, lines
    assert [line for line in lines if line.startswith('looking: ')] == [
        'looking: cannot record: no room']
