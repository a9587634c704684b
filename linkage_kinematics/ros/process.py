# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A node's process, the same for ``linkage_node`` and ``linkage_command_node``.

ROS started, the one line that says why a node cannot start, SIGINT and SIGTERM, the collector
frozen after start-up, timed waits that end on time, the executor and its loop, what is
published acknowledged and the log closed, and the exit status (``exit_codes``).
"""

from __future__ import annotations

from collections.abc import Callable
import ctypes
import gc
import re
import signal
import sys
from typing import Protocol

from linkage_kinematics.ros.exit_codes import ExitCode
from linkage_kinematics.run.parameter_values import ConfigurationError
import rclpy
from rclpy.executors import Executor, SingleThreadedExecutor
from rclpy.experimental import EventsExecutor
from rclpy.logging import get_logger
from rclpy.signals import SignalHandlerOptions

PR_SET_TIMERSLACK = 29  # prctl option (linux/prctl.h)


class StartupError(Exception):
    """The node cannot start for a reason other than a parameter; the message names it."""


class ProcessNode(Protocol):
    """What the process asks of its node, besides being an rclpy Node."""

    @property
    def exit_code(self) -> ExitCode | None:
        """How the run ended on its own; None while it runs (until a signal ends it)."""

    def flush(self, timeout: float = 1.0) -> None:
        """Give subscribers up to ``timeout`` s in all to acknowledge what was published."""

    def close_log(self) -> bool:
        """Finalize the bag (idempotent); False, with an error logged, if that failed."""


def report_start_up_failure(node_name: str, text: str) -> None:
    """
    Report the one line saying why the node cannot start.

    To the node's logger (console, /rosout, log file) and plainly to stderr.
    """
    get_logger(node_name).fatal(text)
    print(f'{node_name}: {text}', file=sys.stderr, flush=True)


def wake_on_time() -> None:
    """
    Ask Linux to end this thread's timed waits, and those of the threads it starts, on time.

    A thread's timed waits may end as much as its timer slack late (50 us by default, which
    lets the kernel batch wake-ups); the events executor's timer thread inherits the slack of
    the thread that starts it, and each timer tick waits on it: at 5 kHz its ticks came 90 us
    after their deadlines at the median, 40 us with the least slack Linux takes (1 ns). Elsewhere,
    or where prctl refuses, the waits keep their slack.
    """
    if sys.platform.startswith('linux'):
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_TIMERSLACK, 1, 0, 0, 0)


def run_node(node_name: str, make_node: Callable[[], ProcessNode], args: list[str] | None,
             ) -> int:
    """
    Run the node ``make_node`` makes until it ends its run, or until SIGINT or SIGTERM.

    Return the exit status: the node's own, OK after a signal, CONFIGURATION when ROS or the
    node cannot start (``make_node`` raising ConfigurationError or StartupError, one line
    reported), FAILED when the log could not be closed.
    """
    # rclpy's own SIGINT handler would shut the context down under our feet; ours lets the
    # loop below finalize the log first.
    try:
        rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    except RuntimeError as error:  # rclpy's RCLError: ROS arguments rcl cannot use
        # rcl's text, without the source locations it appends ('…, at /src/rcl/x.c:352')
        report_start_up_failure(
            node_name, 'cannot start ROS: ' + re.sub(r', at \S+:\d+', '', str(error)))
        return ExitCode.CONFIGURATION
    received: list[int] = []

    def request_stop(signal_number: int, _frame: object) -> None:
        received.append(signal_number)

    signal.signal(signal.SIGINT, request_stop)
    signal.signal(signal.SIGTERM, request_stop)
    try:
        try:
            node = make_node()
        except ConfigurationError as error:
            report_start_up_failure(node_name, f'invalid parameter {error}')
            return ExitCode.CONFIGURATION
        except StartupError as error:
            report_start_up_failure(node_name, str(error))
            return ExitCode.CONFIGURATION
        # What the imports and the start-up made (some 50 000 objects: rclpy, numpy, the URDF
        # and message modules) lives as long as the process; once frozen, the collector no
        # longer walks it. A full collection through it stopped the node for 20-30 ms at some
        # moment after start, a hundred ticks at 5 kHz; now it walks only what came later.
        gc.freeze()
        wake_on_time()  # before the executor starts its timer thread
        # The events executor dispatches timers, subscriptions and services from C++ instead of
        # rebuilding a wait set in Python for every callback: at 1 kHz it halves the process's
        # CPU (docs/benchmarks.md, "The node against a minimal hand-written publisher"). On
        # simulated time rclpy 7.1.6's events executor runs a timer created at run time (a
        # rate_hz change) twice at its first /clock step, which also shifts its schedule by a
        # period, so there the process keeps rclpy's default executor. The events executor's
        # spin() busy-waits without running timers; spin_once returns after each callback, and
        # at the latest after the timeout, so the signal handlers above run and the loop sees
        # the end of the run.
        if node.get_parameter('use_sim_time').value:
            executor: Executor = SingleThreadedExecutor()
        else:
            executor = EventsExecutor()
        executor.add_node(node)
        try:
            while node.exit_code is None and not received:
                executor.spin_once(timeout_sec=0.1)
        finally:
            node.flush()
            log_closed = node.close_log()
            executor.remove_node(node)
            node.destroy_node()
        exit_code = ExitCode.OK if received else node.exit_code
        return exit_code if log_closed else ExitCode.FAILED
    finally:
        rclpy.try_shutdown()
