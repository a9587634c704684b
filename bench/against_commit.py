# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The timer node against an earlier commit's, both running at once: CPU of this one ÷ that one.

Usage (from the repository root, inside the environment)::

    python bench/against_commit.py OTHER_VENV [--module M] [--pairs N] [--rate HZ]

OTHER_VENV is a virtual environment in which the earlier commit is installed (e.g. a ``git
worktree`` of it set up by its own ``./dev`` with ``LINKAGE_VENV=OTHER_VENV``); ``--module`` is
its node's module (``linkage_kinematics.node`` before the layers of issue 24). Each pair starts
both nodes at ``--rate`` with logging on (``end_behavior:=bounce``), each on its own ROS
domain, and measures their CPU with their bag writers' over the same 10 s, as section "cost"
does; the pairs' ratios and their median are printed. Running both at once is what makes the
ratio steady: the machine's state changes between runs more than the versions differ.
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


def start(python: str, prefix: str, module: str, domain: int,
          folder: str, rate: float) -> subprocess.Popen:
    """Start a logging timer node of the environment of ``python`` on ``domain``."""
    environment = dict(node_bench.ros_environment(domain), AMENT_PREFIX_PATH=prefix)
    return subprocess.Popen(
        [python, '-m', module, '--ros-args', '-p', f'rate_hz:={rate:.1f}',
         '-p', 'end_behavior:=bounce', '-p', f'log.folder:={folder}'],
        cwd=folder, env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


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
    arguments = parser.parse_args()
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
