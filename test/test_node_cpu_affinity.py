# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
cpu_affinity, and when the nodes' threads wake.

The node's threads on one CPU and its bag writer process on the others, set at start-up and at run
time; a CPU the process may not use is refused naming the parameter. The timed waits of both
nodes' processes (ros.process) end on time (1 ns of timer slack, which the executor's timer
thread inherits); the command relay's threads on its CPU too.
"""

from __future__ import annotations

import os
from pathlib import Path
import signal
import sys

from diagnostic_msgs.msg import DiagnosticArray
from node_process import (
    bag_writer_pid,
    get_parameter,
    Listener,
    NodeProcesses,
    PROCESS_TIMEOUT,
    ros_context,
    set_parameter,
)
import pytest
from rclpy.parameter_client import AsyncParameterClient
from sensor_msgs.msg import JointState
from test_command_relay import KNEE

AVAILABLE = os.sched_getaffinity(0)
NODE_CPU = max(AVAILABLE)
# With one CPU the bag writer shares it with the node.
WRITER_CPUS = (AVAILABLE - {NODE_CPU}) or {NODE_CPU}
NOT_AVAILABLE = min(set(range(1024)) - AVAILABLE)


def thread_cpus(pid: int) -> dict[int, set[int]]:
    """Return the CPUs each thread of process ``pid`` may run on."""
    return {int(thread): os.sched_getaffinity(int(thread))
            for thread in os.listdir(f'/proc/{pid}/task')}


def test_the_node_runs_on_its_cpu_and_its_bag_writer_on_the_others(
    nodes: NodeProcesses, tmp_path: Path
) -> None:
    output = tmp_path / 'node.log'
    with ros_context(nodes.domain_id) as context:
        listener = Listener('cpu_affinity_tester', context)
        listener.subscribe('/joint_states', JointState)
        process = nodes.start(
            {'end_behavior': 'loop', 'rate_hz': 200.0, 'cpu_affinity': NODE_CPU,
             'log.folder': str(tmp_path / 'bags')}, output)
        try:
            client = AsyncParameterClient(listener.node, 'linkage_node')
            assert client.wait_for_services(timeout_sec=PROCESS_TIMEOUT)
            assert listener.spin_until(lambda: listener.received['/joint_states'])
            writer = bag_writer_pid(process.pid)
            node_threads = thread_cpus(process.pid)
            # the main thread, Fast DDS's and the executor's
            assert len(node_threads) > 3
            assert all(cpus == {NODE_CPU} for cpus in node_threads.values()), node_threads
            assert all(cpus == WRITER_CPUS for cpus in thread_cpus(writer).values())
            assert Path(f'/proc/{process.pid}/timerslack_ns').read_text() == '1\n'

            successful, reason = set_parameter(client, listener, 'cpu_affinity', NOT_AVAILABLE)
            assert not successful
            assert reason == (f'cpu_affinity: CPU {NOT_AVAILABLE} is not one this process may '
                              f"run on (it may run on {', '.join(map(str, sorted(AVAILABLE)))})")
            assert get_parameter(client, listener, 'cpu_affinity') == NODE_CPU
            assert all(cpus == {NODE_CPU} for cpus in thread_cpus(process.pid).values())

            # -1 gives both processes every CPU back, and the motion goes on.
            assert set_parameter(client, listener, 'cpu_affinity', -1) == (True, '')
            assert all(cpus == AVAILABLE for cpus in thread_cpus(process.pid).values())
            assert all(cpus == AVAILABLE for cpus in thread_cpus(writer).values())
            count = len(listener.received['/joint_states'])
            assert listener.spin_until(lambda: len(listener.received['/joint_states']) > count + 5)
            assert process.poll() is None
        finally:
            listener.destroy()
    log = output.read_text()
    assert (f'running on CPU {NODE_CPU}; the bag writer on CPU '
            f"{', '.join(map(str, sorted(WRITER_CPUS)))}") in log
    assert 'no longer pinned to a CPU' in log


def test_the_command_relay_runs_on_its_cpu_and_wakes_on_time(
    nodes: NodeProcesses, tmp_path: Path
) -> None:
    output = tmp_path / 'relay.log'
    with ros_context(nodes.domain_id) as context:
        listener = Listener('cpu_affinity_tester', context)
        listener.subscribe('/diagnostics', DiagnosticArray)
        process = nodes.start(
            {'robot_description': KNEE, 'loops.measured_joints': ['knee_motor'],
             'loops.output_joints': ['knee_output'], 'cpu_affinity': NODE_CPU,
             'log.folder': str(tmp_path / 'bags')},
            output, executable=[sys.executable, '-m', 'linkage_kinematics.ros.command_node'])
        try:
            # its status comes from the diagnostics timer, on the executor's threads
            assert listener.spin_until(lambda: len(listener.received['/diagnostics']) > 1), (
                output.read_text())
            node_threads = thread_cpus(process.pid)
            assert len(node_threads) > 3
            assert all(cpus == {NODE_CPU} for cpus in node_threads.values()), node_threads
            assert all(cpus == WRITER_CPUS
                       for cpus in thread_cpus(bag_writer_pid(process.pid)).values())
            assert Path(f'/proc/{process.pid}/timerslack_ns').read_text() == '1\n'
        finally:
            listener.destroy()
        assert nodes.interrupt(process, signal.SIGTERM) == 0, output.read_text()
    assert 'bag finalized: ' in output.read_text()


@pytest.mark.parametrize('value', [NOT_AVAILABLE, -2, 1024, '0'])
def test_a_cpu_the_process_may_not_use_is_a_start_up_error(
    nodes: NodeProcesses, tmp_path: Path, value
) -> None:
    bags = tmp_path / 'bags'
    status, output = nodes.run({'cpu_affinity': value, 'log.folder': str(bags)},
                               tmp_path / 'node.log')
    assert status == 2, output
    assert 'linkage_node: invalid parameter cpu_affinity: ' in output
    assert 'Traceback' not in output
    assert not bags.exists()
