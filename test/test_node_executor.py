# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
linkage_node's executor: what it must deliver besides ticks.

On wall time the node spins on rclpy.experimental.EventsExecutor, which dispatches timers from
C++ and takes timers and services from the node when they change; on simulated time on rclpy's
default executor (see ros.process). Other modules cover parameter changes (test_node_parameters.py,
test_node_bad_input.py), signals (test_recording_faults.py) and long runs on simulated time
(test_node_long_runs.py). This one covers what they do not: the list/describe parameter
services, and the state timer re-created at run time (rate_hz changed), on wall time and on
simulated time: the old timer must stop (it keeps firing on the events executor if the node
only calls ``Timer.destroy()``, which leaves it in ``node.timers``; ``Node.destroy_timer``
removes it) and the new one run on its own period.
"""

from __future__ import annotations

from linkage_kinematics.bag import reader as bag_reader
from linkage_kinematics.run.parameter_specs import PARAMETER_NAMES, parameter_specs
from node_process import (
    drive_sim_clock,
    Listener,
    PROCESS_TIMEOUT,
    ros_context,
    stamp_ns,
    time_msg,
)
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from rclpy.qos import QoSProfile
from rosgraph_msgs.msg import Clock
from trajectory_msgs.msg import JointTrajectory

CLOCK_START = 1_000_000_000_000  # ns of simulated time at the first tick
STEP = 10_000_000  # ns of simulated time per /clock step: one period at 100 Hz, half at 50 Hz


def test_events_executor_serves_parameters_and_re_creates_the_state_timer(nodes, tmp_path):
    with ros_context(nodes.domain_id) as context:
        listener = Listener('executor_tester', context)
        listener.subscribe('/linkage/state', JointTrajectory)
        states = listener.received['/linkage/state']
        process = nodes.start({'end_behavior': 'loop', 'rate_hz': 100.0, 'log.enabled': False},
                              tmp_path / 'node.log')
        try:
            client = AsyncParameterClient(listener.node, 'linkage_node')
            assert client.wait_for_services(timeout_sec=PROCESS_TIMEOUT)
            listed = listener.result_of(client.list_parameters([], 0)).result.names
            assert set(PARAMETER_NAMES) <= set(listed)
            specs = {spec.name: spec for spec in parameter_specs('paper')}
            (descriptor,) = listener.result_of(client.describe_parameters(['rate_hz'])).descriptors
            assert descriptor.description == specs['rate_hz'].description
            (interval,) = descriptor.floating_point_range
            assert (interval.from_value, interval.to_value) == specs['rate_hz'].floating_range
            assert listener.spin_until(lambda: len(states) > 5)

            (result,) = listener.result_of(
                client.set_parameters([Parameter('rate_hz', value=2.0)])).results
            assert result.successful, result.reason
            # One state of the old timer may still be on its way.
            changed_at = len(states) + 1
            assert listener.spin_until(lambda: len(states) >= changed_at + 3)
            assert process.poll() is None
        finally:
            listener.destroy()

    # Timers never fire early: only the new 0.5 s timer ticks (the old one ticked every 10 ms).
    stamps = [stamp_ns(message) for message in states[changed_at:]]
    assert all(later - earlier >= 250_000_000 for earlier, later in zip(stamps, stamps[1:])), [
        (later - earlier) * 1e-6 for earlier, later in zip(stamps, stamps[1:])]


def test_rate_change_on_sim_time_ticks_on_the_new_period(nodes, tmp_path):
    bags = tmp_path / 'bags'
    with ros_context(nodes.domain_id) as context:
        listener = Listener('executor_tester', context)
        listener.subscribe('/linkage/state', JointTrajectory)
        states = listener.received['/linkage/state']
        clock = listener.node.create_publisher(Clock, '/clock', QoSProfile(depth=10))
        process = nodes.start(
            {'end_behavior': 'loop', 'rate_hz': 100.0, 'display_rate_hz': 1.0,
             'use_sim_time': True, 'log.folder': str(bags)},
            tmp_path / 'node.log')
        try:
            client = AsyncParameterClient(listener.node, 'linkage_node')
            assert client.wait_for_services(timeout_sec=PROCESS_TIMEOUT)
            assert listener.spin_until(lambda: listener.node.count_subscribers('/clock') > 0)
            assert listener.spin_until(lambda: listener.node.count_publishers('/linkage/state'))
            before = [CLOCK_START + n * STEP for n in range(6)]
            for clock_ns in before:
                drive_sim_clock(listener, clock, states, clock_ns)

            (result,) = listener.result_of(
                client.set_parameters([Parameter('rate_hz', value=50.0)])).results
            assert result.successful, result.reason
            # The change restarts the motion, whose first state is published at once, at the
            # last /clock time; the new timer starts there too: its periods end on every second
            # step from here, and the steps between must not tick.
            restarted = before[-1]
            assert listener.spin_until(lambda: len(states) == len(before) + 1)
            after = []
            for n in range(1, 7):
                clock_ns = before[-1] + n * STEP
                if n % 2:
                    clock.publish(Clock(clock=time_msg(clock_ns)))
                else:
                    drive_sim_clock(listener, clock, states, clock_ns)
                    after.append(clock_ns)
            assert process.poll() is None
            status = nodes.interrupt(process)
        finally:
            listener.destroy()

    assert status == 0, (tmp_path / 'node.log').read_text()
    received = [stamp_ns(message) for message in states]
    assert received == before + [restarted] + after, [
        (stamp - CLOCK_START) // 1_000_000 for stamp in received]
    (bag,) = bags.iterdir()
    assert all(part.complete for part in bag_reader.bag_files(bag))
    logged = [message.log_time_ns for message in bag_reader.iter_messages(bag, ['/linkage/state'])]
    assert logged == received
