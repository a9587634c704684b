# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The timer node against an earlier commit's: CPU of this one ÷ that one, or ticks missed.

Usage (from the repository root, inside the environment)::

    python bench/against_commit.py OTHER_VENV [--module M] [--pairs N] [--rate HZ]
                                   [--missed [--cpu-affinity CPU]]

OTHER_VENV is a virtual environment in which the earlier commit is installed (e.g. a ``git
worktree`` of it set up by its own ``./dev`` with ``LINKAGE_VENV=OTHER_VENV``); ``--module`` is
its node's module (``linkage_kinematics.node`` before the layers of issue 24). Each pair starts
both nodes at ``--rate`` with logging on (``end_behavior:=bounce``), each on its own ROS
domain, and measures their CPU with their bag writers' over the same 10 s, as section "cost"
does; the pairs' ratios and their median are printed. Running both at once is what makes the
ratio steady: the machine's state changes between runs more than the versions differ.

With ``--missed``, each pair runs the two nodes one after the other instead (which first
alternates from pair to pair), each alone for 8 s with ``cpu_affinity:=CPU`` (default 0) and
logging on, and prints the share of ticks each missed, from its own /diagnostics as section
"cost" measures it: pinned to one CPU, two nodes at once would take each other's ticks.
"""

from __future__ import annotations

import argparse
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

from cost_bench import cpu_seconds
import node_bench

# The tests' lease of ROS domains (test/ros_domains.py), as bench/run.py takes it.
sys.path.insert(1, str(pathlib.Path(__file__).resolve().parent.parent / 'test'))
from ros_domains import domain_lease  # noqa: E402

WINDOW_S = 10.0
MISSED_WINDOW_S = 8.0  # as section "cost" measures the highest rate


def start(python: str, prefix: str, module: str, domain: int,
          folder: str, rate: float, *arguments: str) -> subprocess.Popen:
    """Start a logging timer node of the environment of ``python`` on ``domain``."""
    environment = dict(node_bench.ros_environment(domain), AMENT_PREFIX_PATH=prefix)
    return subprocess.Popen(
        [python, '-m', module, '--ros-args', '-p', f'rate_hz:={rate:.1f}',
         '-p', 'end_behavior:=bounce', '-p', f'log.folder:={folder}', *arguments],
        cwd=folder, env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def missed(python: str, prefix: str, module: str, rate: float, cpu: int, domain: int) -> float:
    """
    Return the share of ticks a node of the environment of ``python`` missed, alone.

    1 − its achieved rate over its /diagnostics windows after the first ÷ ``rate``, as
    ``cost_bench.missed_share`` measures it (only /diagnostics subscribed).
    """
    with tempfile.TemporaryDirectory(prefix='linkage_bench_against_missed_') as folder:
        process = start(python, prefix, module, domain, folder, rate,
                        '-p', f'cpu_affinity:={cpu}')
        try:
            time.sleep(node_bench.STARTUP_S)
            if process.poll() is not None:
                raise RuntimeError(f'a node exited early: {process.args}')
            listener, output = node_bench.listen(MISSED_WINDOW_S, [], domain)
            data = node_bench.collect(listener, output)
        finally:
            node_bench.stop(process)
    windows = node_bench.achieved_rates(data)
    if not windows:
        raise RuntimeError(f'no /diagnostics windows from {process.args}')
    return max(0.0, 1.0 - statistics.mean(windows) / rate)


def missed_pairs(arguments: argparse.Namespace, first: int) -> None:
    """Print each pair's missed shares, this node's and the other's, one after the other."""
    this = (sys.executable, sys.prefix, 'linkage_kinematics.ros.node')
    other = (str(arguments.other_venv / 'bin' / 'python'), str(arguments.other_venv),
             arguments.module)
    shares: dict[str, list[float]] = {'this': [], 'other': []}
    for index in range(arguments.pairs):
        order = [('this', this), ('other', other)]
        for name, (python, prefix, module) in order if index % 2 == 0 else order[::-1]:
            shares[name].append(missed(python, prefix, module, arguments.rate,
                                       arguments.cpu_affinity, first))
        print(f"this {100 * shares['this'][-1]:.2f} %, other {100 * shares['other'][-1]:.2f} % "
              f'of ticks missed (load average {os.getloadavg()[0]:.2f})', flush=True)
    for name, values in shares.items():
        print(f'{name}: median {100 * statistics.median(values):.2f} %, '
              f'range {100 * min(values):.2f}–{100 * max(values):.2f} %')


def pair(other: pathlib.Path, module: str, rate: float, domains: range) -> tuple[float, float]:
    """Return the CPU shares of one core of (this node, the other commit's), run at once."""
    with tempfile.TemporaryDirectory(prefix='linkage_bench_against_') as folder:
        processes = [
            start(sys.executable, sys.prefix, 'linkage_kinematics.ros.node', domains[0],
                  folder, rate),
            start(str(other / 'bin' / 'python'), str(other), module, domains[1], folder, rate),
        ]
        try:
            time.sleep(node_bench.STARTUP_S)
            if any(process.poll() is not None for process in processes):
                raise RuntimeError(f'a node exited early: {[p.args for p in processes]}')
            started = time.monotonic()
            before = [cpu_seconds(process.pid) for process in processes]
            time.sleep(WINDOW_S)
            after = [cpu_seconds(process.pid) for process in processes]
            elapsed = time.monotonic() - started
        finally:
            for process in processes:
                node_bench.stop(process)
    this, that = ((end - begin) / elapsed for begin, end in zip(before, after))
    return this, that


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('other_venv', type=pathlib.Path)
    parser.add_argument('--module', default='linkage_kinematics.ros.node')
    parser.add_argument('--pairs', type=int, default=6)
    parser.add_argument('--rate', type=float, default=1000.0)
    parser.add_argument('--missed', action='store_true',
                        help='ticks missed, one node after the other, instead of CPU at once')
    parser.add_argument('--cpu-affinity', type=int, default=0,
                        help="the nodes' cpu_affinity with --missed")
    arguments = parser.parse_args()
    if arguments.missed:
        print(f'load average {os.getloadavg()[0]:.2f}; {arguments.pairs} pairs at '
              f'{arguments.rate:g} Hz, cpu_affinity:={arguments.cpu_affinity}, '
              f'{MISSED_WINDOW_S:g} s each, one after the other')
        with domain_lease(count=1) as first:
            missed_pairs(arguments, first)
        return 0
    print(f'load average {os.getloadavg()[0]:.2f}; {arguments.pairs} pairs at '
          f'{arguments.rate:g} Hz, {WINDOW_S:g} s each')
    ratios = []
    with domain_lease(count=2) as first:
        for _ in range(arguments.pairs):
            this, that = pair(arguments.other_venv, arguments.module, arguments.rate,
                              range(first, first + 2))
            ratios.append(this / that)
            print(f'this {100 * this:.1f} %, other {100 * that:.1f} %, '
                  f'this ÷ other {ratios[-1]:.3f}', flush=True)
    print(f'median this ÷ other: {statistics.median(ratios):.3f} '
          f'(range {min(ratios):.3f}–{max(ratios):.3f})')
    return 0


if __name__ == '__main__':
    sys.exit(main())
