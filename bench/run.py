# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The benchmark report: ``./dev bench`` (= ``python bench/run.py``) from the repository root.

Sections: kinematics (cost per configuration against error), drive (the drive law in time),
tf (one state's /tf bytes, prepared against the generic forward kinematics), node (the ROS node's
tick, rates, jitter, latency and log size), cost (the node's CPU side by side with a minimal
hand-written rclpy publisher, its highest sustained rate with the default placement and with
cpu_affinity:=0), measured and loops (the measured source, and a URDF's four loops closed, each
against a minimal hand-written rclpy relay), parallel (parallel robots' loops closed per sample
beside toolbox-parallel-robots, Pinocchio with Gauss–Newton and PlaCo, which it installs on first
use: bench/peers.py) and memory (the node's resident memory over a long 1 kHz run). Every section
prints markdown tables for docs/benchmarks.md; the kinematics section also draws
docs/benchmark_speed_error.png, the parallel section docs/benchmark_parallel.png.
"""

from __future__ import annotations

import argparse
from collections.abc import Collection
from contextlib import ExitStack
import os
import pathlib
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
# The high-precision reference lives with the tests; the library is imported from the tree.
sys.path[1:1] = [str(ROOT), str(ROOT / 'test')]

from ros_domains import domain_lease  # noqa: E402
from timing import machine_description  # noqa: E402

SECTIONS = ('kinematics', 'drive', 'tf', 'node', 'cost', 'measured', 'loops', 'parallel',
            'memory')
# The sections that run nodes, each kind of run on its own ROS_DOMAIN_ID: the first one and the
# four after it (node_bench's DOMAIN_* offsets).
ROS_SECTIONS = ('node', 'cost', 'measured', 'loops', 'memory')
DOMAIN_COUNT = 5


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--quick', action='store_true',
                        help='fewer angles, shorter timings and node runs (about a minute)')
    parser.add_argument('--repetitions', type=int, default=None,
                        help='timing repetitions per method (default 7, 5 with --quick)')
    parser.add_argument('--only', choices=SECTIONS, action='append',
                        help='run only this section (may be repeated)')
    parser.add_argument('--plot', default=str(ROOT / 'docs' / 'benchmark_speed_error.png'),
                        help='where to write the speed-against-error plot')
    parser.add_argument('--parallel-plot',
                        default=str(ROOT / 'docs' / 'benchmark_parallel.png'),
                        help="where to write the parallel section's time-against-error plot")
    parser.add_argument('--memory-minutes', type=float, default=None,
                        help="length of the node's resident-memory run at 1 kHz "
                             '(default 10, 0.5 with --quick)')
    parser.add_argument('--ros-domain', type=int, default=None,
                        help='first of the five ROS_DOMAIN_IDs the node, cost, measured, loops '
                             'and memory sections use (default: five in a row that no test or '
                             'other benchmark run holds)')
    arguments = parser.parse_args(argv)
    if arguments.repetitions is not None and arguments.repetitions < 1:
        parser.error('--repetitions must be at least 1')
    if arguments.ros_domain is not None and not 0 <= arguments.ros_domain <= 228:
        parser.error('--ros-domain must be between 0 and 228 (five IDs up to 232)')
    sections = arguments.only or SECTIONS
    started = time.perf_counter()
    print(f'machine: {machine_description()}')
    print(f"command: python bench/run.py {' '.join(sys.argv[1:])}".rstrip())
    with ExitStack() as held:
        ros_domain = None
        if any(section in ROS_SECTIONS for section in sections):
            # Taken through the tests' lease (test/ros_domains.py), so that a test run or another
            # benchmark run beside this one never shares an id with it: a fixed default (it was
            # 50) lay among the ids the tests are handed, and its nodes saw theirs.
            try:
                ros_domain = held.enter_context(domain_lease(DOMAIN_COUNT, arguments.ros_domain))
            except RuntimeError as error:
                parser.error(str(error))
            print(f'ROS domains: {ros_domain}–{ros_domain + DOMAIN_COUNT - 1}')
        run_sections(arguments, sections, ros_domain)
    load = ', '.join(f'{value:.2f}' for value in os.getloadavg())
    print(f'\nbenchmark took {time.perf_counter() - started:.0f} s; load average at the end: '
          f'{load}')
    return 0


def run_sections(arguments: argparse.Namespace, sections: Collection[str],
                 ros_domain: int | None) -> None:
    """Print each of ``sections``; the node sections run on ``ros_domain`` and the four after."""
    repetitions = arguments.repetitions or (5 if arguments.quick else 7)
    if 'kinematics' in sections:
        import kinematics_bench

        table, results = kinematics_bench.run(arguments.quick, repetitions)
        print('\n## Kinematics: time per configuration and largest error\n')
        print(table)
        print()
        print(kinematics_bench.goals(results))
        kinematics_bench.plot(results, arguments.plot)
        print(f'\nplot written to {arguments.plot}')
    if 'drive' in sections:
        import drive_bench

        print('\n## Drive law in time\n')
        print(drive_bench.run(arguments.quick, repetitions))
    if 'tf' in sections:
        import tf_bench

        print("\n## One state's /tf: prepared against generic forward kinematics\n")
        print(tf_bench.run(arguments.quick, repetitions))
    if 'node' in sections:
        import node_bench

        print('\n## Node\n')
        print(node_bench.run(arguments.quick, repetitions, ros_domain))
    if 'cost' in sections:
        import cost_bench

        print('\n## Node against a minimal hand-written publisher\n')
        print(cost_bench.run(arguments.quick, ros_domain))
    if 'measured' in sections:
        import measured_bench

        print('\n## Measured source against a minimal hand-written relay\n')
        print(measured_bench.run(arguments.quick, ros_domain))
    if 'loops' in sections:
        import loops_bench

        print("\n## A URDF's loops closed: the per-sample path in this process\n")
        print(loops_bench.path_run(arguments.quick, repetitions))
        print("\n## A URDF's loops closed, against a minimal hand-written relay\n")
        print(loops_bench.run(arguments.quick, ros_domain))
    if 'parallel' in sections:
        import parallel_bench
        import peers

        print('\n## Parallel robots closed per sample, against the peers\n')
        versions = peers.activate(install=True)
        print('peers: ' + ', '.join(f'{name} {version}' for name, version in versions.items()))
        rows, notes = parallel_bench.run(arguments.quick, repetitions)
        print(parallel_bench.table(rows, notes))
        parallel_bench.plot(rows, arguments.parallel_plot)
        print(f'\nplot written to {arguments.parallel_plot}')
    if 'memory' in sections:
        import node_bench

        minutes = arguments.memory_minutes
        if minutes is None:
            minutes = 0.5 if arguments.quick else 10.0
        print(f'\n## Node memory over {minutes:g} min at 1 kHz\n')
        print(node_bench.memory_run(minutes, ros_domain))


if __name__ == '__main__':
    sys.exit(main())
