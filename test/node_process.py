# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Helpers for the node tests: run linkage_node in its own process, listen with real rclpy.

Every test module that starts nodes runs in its own ROS_DOMAIN_ID (the ``domain_id`` fixture,
leased by ``ros_domains``), so that tests never see each other's nodes; every process a test
starts through ``NodeProcesses`` (the ``nodes`` fixture) has ended when the test has.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
import math
import os
from pathlib import Path
import signal
import subprocess
import sys
import time
from typing import Any

from builtin_interfaces.msg import Time
from linkage_kinematics.kinematics.geometry import FourBar
from linkage_kinematics.kinematics.solver import LinkageState
from linkage_kinematics.run.parameter_specs import parameter_specs
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter, parameter_value_to_python
from rclpy.parameter_client import AsyncParameterClient
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.task import Future
from rosbags.typesys import get_typestore, Stores
from rosgraph_msgs.msg import Clock

REPOSITORY = Path(__file__).resolve().parent.parent
# s; a generous bound on any one wait in these tests, also on a busy machine
PROCESS_TIMEOUT = 60.0
# The message types of ROS 2 Jazzy, as rosbags knows them independently of rclpy.
TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
# How long a process that outlived its test gets after each signal of the teardown (s): SIGINT is
# how the node is meant to end (it finalizes its bag), SIGTERM and SIGKILL are the escalation.
STOP_TIMEOUTS = ((signal.SIGINT, 30.0), (signal.SIGTERM, 10.0), (signal.SIGKILL, PROCESS_TIMEOUT))


def ros_environment(domain_id: int) -> dict[str, str]:
    """Return the environment a node process (and the test's own rclpy) runs in."""
    environment = dict(os.environ)
    environment['ROS_DOMAIN_ID'] = str(domain_id)
    environment['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    environment.setdefault('AMENT_PREFIX_PATH', sys.prefix)
    environment['PYTHONUNBUFFERED'] = '1'
    return environment


def parameter_argument(name: str, value: Any) -> str:
    """``name:=value`` for ``--ros-args -p`` (floats exactly, strings as YAML strings)."""
    if isinstance(value, bool):
        text = 'true' if value else 'false'
    elif isinstance(value, float):
        text = '.nan' if math.isnan(value) else repr(value).replace('inf', '.inf')
    elif isinstance(value, str):
        text = "'" + value.replace("'", "''") + "'"
    else:
        text = str(value)
    return f'{name}:={text}'


def node_command(
    parameters: Mapping[str, Any],
    executable: list[str] | None = None,
    ros_arguments: Sequence[str] = (),
) -> list[str]:
    """
    Return the command line of a node with ``parameters`` and further ``ros_arguments`` (e.g.

    ``-r __ns:=/left``).
    """
    command = executable or [sys.executable, '-m', 'linkage_kinematics.ros.node']
    arguments = ['--ros-args']
    for name, value in parameters.items():
        arguments += ['-p', parameter_argument(name, value)]
    return command + arguments + list(ros_arguments)


def start_node(
    parameters: Mapping[str, Any],
    domain_id: int,
    output: Path,
    executable: list[str] | None = None,
    environment: Mapping[str, str] | None = None,
    cwd: Path = REPOSITORY,
    preexec_fn: Callable[[], None] | None = None,
    ros_arguments: Sequence[str] = (),
) -> subprocess.Popen:
    """
    Start a node process (by default the working tree's, from the repository root).

    Its stdout and stderr go to the file ``output``; ``preexec_fn`` runs in the child first.
    """
    with open(output, 'w') as log:
        return subprocess.Popen(
            node_command(parameters, executable, ros_arguments),
            cwd=cwd,
            env=dict(environment) if environment is not None else ros_environment(domain_id),
            stdout=log,
            stderr=subprocess.STDOUT,
            preexec_fn=preexec_fn,
        )


def end_process(
    process: subprocess.Popen, stop_timeouts: Sequence[tuple[int, float]] = STOP_TIMEOUTS
) -> list[str]:
    """
    End ``process`` if it still runs: SIGINT, then SIGTERM, then SIGKILL, each with a deadline.

    Return the signals it outlived (empty when it had ended or ended on the first).
    """
    outlived = []
    for signal_number, timeout in stop_timeouts:
        if process.poll() is not None:
            break
        process.send_signal(signal_number)
        try:
            process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            outlived.append(signal.Signals(signal_number).name)
    return outlived


class NodeProcesses:
    """
    The processes one test starts (the ``nodes`` fixture), all ended by ``finish``.

    ``finish`` runs after the test whatever it did, so a failing test leaves no process behind,
    and a process that needed more than SIGINT is reported as a teardown error beside (not
    instead of) the test's own failure.
    """

    def __init__(
        self, domain_id: int, stop_timeouts: Sequence[tuple[int, float]] = STOP_TIMEOUTS
    ) -> None:
        self.domain_id = domain_id
        self.stop_timeouts = stop_timeouts
        self.processes: list[tuple[subprocess.Popen, str]] = []

    def add(self, process: subprocess.Popen, output: Path | None = None) -> subprocess.Popen:
        """Have ``process`` (started elsewhere, e.g. an encoder) ended with the test's."""
        self.processes.append((process, f' (output in {output})' if output else ''))
        return process

    def start(
        self, parameters: Mapping[str, Any], output: Path, **options: Any
    ) -> subprocess.Popen:
        """``start_node`` in the test's domain, ended with the test at the latest."""
        return self.add(start_node(parameters, self.domain_id, output, **options), output)

    def run(
        self, parameters: Mapping[str, Any], output: Path, ros_arguments: Sequence[str] = ()
    ) -> tuple[int, str]:
        """Run a node to its end; return its exit status and output."""
        process = self.start(parameters, output, ros_arguments=ros_arguments)
        return process.wait(timeout=PROCESS_TIMEOUT), output.read_text()

    @staticmethod
    def interrupt(
        process: subprocess.Popen, signal_number: int = signal.SIGINT,
        timeout: float = PROCESS_TIMEOUT,
    ) -> int:
        """Send SIGINT (or ``signal_number``) and wait: the exit status."""
        process.send_signal(signal_number)
        return process.wait(timeout=timeout)

    def stop_all(self) -> list[str]:
        """End every process still running; describe each that SIGINT did not end."""
        problems = []
        for process, output in self.processes:
            outlived = end_process(process, self.stop_timeouts)
            if outlived:
                still = ', still running' if process.poll() is None else ''
                # the module of a `python -m`, else the program
                command = process.args[2] if process.args[1:2] == ['-m'] else process.args[0]
                problems.append(f"{command} (pid {process.pid}) outlived {', '.join(outlived)}"
                                f'{still}{output}')
        return problems

    def finish(self) -> None:
        """End every process; fail the teardown if one needed more than SIGINT."""
        problems = self.stop_all()
        if problems:
            pytest.fail('teardown: ' + '; '.join(problems), pytrace=False)


def bag_writer_pid(node_pid: int) -> int:
    """Return the process id of the node's bag writer (bag.writer_process), its child."""
    for stat in Path('/proc').glob('[0-9]*/stat'):
        try:
            fields = stat.read_text().rsplit(')', 1)[1].split()
            cmdline = (stat.parent / 'cmdline').read_bytes()
        except OSError:
            continue  # a process that ended meanwhile
        if int(fields[1]) == node_pid and b'linkage_kinematics.bag.writer_process' in cmdline:
            return int(stat.parent.name)
    raise AssertionError(f'no bag writer process under the node (pid {node_pid})')


class Listener:
    """A node in the test process that keeps every message it receives, per topic."""

    def __init__(self, name: str, context: rclpy.Context) -> None:
        self.node = Node(name, context=context)
        self.executor = SingleThreadedExecutor(context=context)
        self.executor.add_node(self.node)
        self.received: dict[str, list[Any]] = {}
        # Transient-local topics (the robot description) are published once, not once per tick.
        self.latched: set[str] = set()

    def subscribe(self, topic: str, msg_type: type, transient_local: bool = False) -> None:
        self.received.setdefault(topic, [])
        qos = QoSProfile(depth=1000)
        if transient_local:
            self.latched.add(topic)
            qos = QoSProfile(
                depth=1,
                durability=DurabilityPolicy.TRANSIENT_LOCAL,
                reliability=ReliabilityPolicy.RELIABLE,
            )
        self.node.create_subscription(msg_type, topic, self.received[topic].append, qos)

    def spin_until(self, done: Callable[[], bool], timeout: float = PROCESS_TIMEOUT) -> bool:
        """Spin until ``done()`` or the timeout; return ``done()``."""
        deadline = time.monotonic() + timeout
        while not done() and time.monotonic() < deadline:
            self.executor.spin_once(timeout_sec=0.05)
        return done()

    def wait_for_publisher(self, topic: str, timeout: float = PROCESS_TIMEOUT) -> bool:
        return self.spin_until(lambda: self.node.count_publishers(topic) > 0, timeout)

    def heard_every_topic(self, count: int = 1) -> bool:
        """
        Tell whether at least ``count`` messages arrived on every subscribed topic.

        On a transient-local topic one is enough.
        """
        return all(
            len(messages) >= (1 if topic in self.latched else count)
            for topic, messages in self.received.items()
        )

    def wait_for_every_topic(self, count: int = 1, timeout: float = PROCESS_TIMEOUT) -> bool:
        """Spin until ``heard_every_topic(count)``."""
        return self.spin_until(lambda: self.heard_every_topic(count), timeout)

    def drain(self) -> None:
        """
        Take every message that has already arrived.

        E.g. after the node exited (it waits for its subscribers' acknowledgements first): spin
        until three spins in a row bring nothing new.
        """
        idle = 0
        while idle < 3:
            before = sum(map(len, self.received.values()))
            self.executor.spin_once(timeout_sec=0.05)
            idle = idle + 1 if sum(map(len, self.received.values())) == before else 0

    def result_of(self, future: Future, timeout: float = PROCESS_TIMEOUT) -> Any:
        """Spin until ``future`` (e.g. a parameter service call) is done; its result."""
        assert self.spin_until(future.done, timeout), 'no answer within the timeout'
        return future.result()

    def destroy(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()


@contextmanager
def ros_context(domain_id: int) -> Iterator[rclpy.Context]:
    """Return a private rclpy context in the test process on ``domain_id``, loopback only."""
    previous = os.environ.get('ROS_AUTOMATIC_DISCOVERY_RANGE')
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain_id)
    try:
        yield context
    finally:
        rclpy.shutdown(context=context)
        if previous is None:
            os.environ.pop('ROS_AUTOMATIC_DISCOVERY_RANGE')
        else:
            os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = previous


def drive_sim_clock(listener: Listener, clock: Any, states: list, clock_ns: int) -> None:
    """
    Set simulated time to ``clock_ns`` and wait for the node's state of that instant.

    A lost /clock message is sent again; the same time again makes no tick.
    """
    message = Clock(clock=time_msg(clock_ns))
    # A state lost to a subscription that has not matched the node's writer yet would never come
    # again (the same time makes no second tick): step the clock only once every subscription
    # here has matched its publisher (the node publishes nothing before its first tick).
    assert listener.spin_until(lambda: all(
        subscription.get_publisher_count() > 0 for subscription in listener.node.subscriptions
    )), 'a subscription never matched the node'

    def ticked() -> bool:
        return bool(states) and stamp_ns(states[-1]) == clock_ns

    for _ in range(round(PROCESS_TIMEOUT / 0.5)):
        clock.publish(message)
        if listener.spin_until(ticked, timeout=0.5):
            return
    raise AssertionError(f'no state stamped {clock_ns} ns')


def time_msg(nanoseconds: int) -> Time:
    """Return a builtin_interfaces/Time from integer nanoseconds."""
    return Time(sec=nanoseconds // 1_000_000_000, nanosec=nanoseconds % 1_000_000_000)


def decode(data: bytes, type_name: str) -> Any:
    """Decode CDR bytes of ``type_name`` (``pkg/msg/Name``) with rosbags, an independent reader."""
    return TYPESTORE.deserialize_cdr(data, type_name)


def stamp_ns(message: Any) -> int:
    """Return the header stamp of ``message`` in integer nanoseconds."""
    return message.header.stamp.sec * 1_000_000_000 + message.header.stamp.nanosec


def expected_state_point(
    linkage: FourBar, state: LinkageState
) -> tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]:
    """
    Return the positions.

    Velocities and accelerations /linkage/state carries for a library state, in its joint order
    (docs/parameters.md, Topics): α, β, γ, pins A and B, θ_BC = π − β, OA·α, BC·β.
    """
    crank, rocker = linkage.crank_length, linkage.rocker_length
    return (
        (state.alpha, state.beta, state.gamma, state.pin_a_x, state.pin_a_y, state.pin_b_x,
         state.pin_b_y, math.pi - state.beta, crank * state.alpha, rocker * state.beta),
        (state.omega, -state.omega_bc, state.omega_ab, state.velocity_a_x, state.velocity_a_y,
         state.velocity_b_x, state.velocity_b_y, state.omega_bc, crank * state.omega,
         -rocker * state.omega_bc),
        (state.omega_dot, -state.omega_dot_bc, state.omega_dot_ab, state.acceleration_a_x,
         state.acceleration_a_y, state.acceleration_b_x, state.acceleration_b_y,
         state.omega_dot_bc, crank * state.omega_dot, -rocker * state.omega_dot_bc),
    )


def configuration_values(**overrides: Any) -> dict[str, Any]:
    """
    Return the node's default parameter values (preset 'paper') with ``overrides``, by name.

    Dotted names are passed as ``**{"log.enabled": False}``.
    """
    return {**{spec.name: spec.default for spec in parameter_specs('paper')}, **overrides}


def set_parameter(
    client: AsyncParameterClient, listener: Listener, name: str, value: Any
) -> tuple[bool, str]:
    """Set one parameter of the node over its service: (successful, reason)."""
    future = client.set_parameters([Parameter(name, value=value)])
    assert listener.spin_until(future.done)
    (result,) = future.result().results
    return result.successful, result.reason


def get_parameter(client: AsyncParameterClient, listener: Listener, name: str) -> Any:
    """One parameter's value, got from the node over its service."""
    future = client.get_parameters([name])
    assert listener.spin_until(future.done)
    (value,) = future.result().values
    return parameter_value_to_python(value)
