# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The benchmark report: ``./dev bench`` (= ``python bench/run.py``) from the repository root.

Sections: kinematics (cost per configuration against error), drive (the drive law in time),
tf (one state's /tf bytes, prepared against the generic forward kinematics), node (the ROS node's
tick, rates, jitter, latency and log size), cost (the node's CPU side by side with a minimal
hand-written rclpy publisher, its highest sustained rate with the default placement and with
cpu_affinity:=0), measured and loops (the measured source, and a URDF's four loops closed, each
against a minimal hand-written rclpy relay), biped (issue 29's cost goal: a biped's two knees
and two parallel ankles closed at 1 kHz beside the relay, and its per-sample path part by part),
relay (issue 30's cost goal: linkage_command_node relaying the biped's forward commands at
1 kHz beside a hand-written relay, and a 1000-point trajectory converted), parallel (parallel
robots' loops closed per sample by the package and beside it by toolbox-parallel-robots,
Pinocchio with Gauss–Newton and PlaCo, which it installs on first use: bench/peers.py) and
memory (the node's resident memory over a long 1 kHz run). Every section
prints markdown tables, which the run writes into docs/benchmarks.md (bench/document.py); the
kinematics section also draws docs/benchmark_speed_error.png, the cost section
docs/benchmark_cost_rate.png, the parallel section docs/benchmark_parallel.png.
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
DOCS = ROOT / 'docs'
# The high-precision reference lives with the tests; the library is imported from the tree.
sys.path[1:1] = [str(ROOT), str(ROOT / 'test')]

import document  # noqa: E402
from ros_domains import domain_lease  # noqa: E402
from timing import machine_description  # noqa: E402

SECTIONS = ('kinematics', 'drive', 'tf', 'node', 'cost', 'measured', 'loops', 'biped', 'relay',
            'parallel', 'memory')
# The sections that run nodes, each kind of run on its own ROS_DOMAIN_ID: the first one and the
# four after it (node_bench's DOMAIN_* offsets).
ROS_SECTIONS = ('node', 'cost', 'measured', 'loops', 'biped', 'relay', 'memory')
DOMAIN_COUNT = 5


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--quick', action='store_true',
                        help='fewer angles, shorter timings and node runs (about 7 minutes '
                             'in all)')
    parser.add_argument('--repetitions', type=int, default=None,
                        help='timing repetitions per method (default 7, 5 with --quick)')
    parser.add_argument('--only', choices=SECTIONS, action='append',
                        help='run only this section (may be repeated)')
    parser.add_argument('--plot', default=str(DOCS / 'benchmark_speed_error.png'),
                        help='where to write the speed-against-error plot')
    parser.add_argument('--cost-plot', default=str(DOCS / 'benchmark_cost_rate.png'),
                        help='where to write the plot of CPU against timer rate')
    parser.add_argument('--parallel-plot', default=str(DOCS / 'benchmark_parallel.png'),
                        help="where to write the parallel section's time-against-error plot")
    parser.add_argument('--document', default=str(document.DOCUMENT),
                        help="the document the run's figures are written to (its sections "
                             'that did not run are kept)')
    parser.add_argument('--no-document', action='store_true',
                        help='print the figures only; write no document')
    parser.add_argument('--memory-minutes', type=float, default=None,
                        help="length of the node's resident-memory run at 1 kHz "
                             '(default 10, 0.5 with --quick)')
    parser.add_argument('--ros-domain', type=int, default=None,
                        help='first of the five ROS_DOMAIN_IDs the node, cost, measured, loops, '
                             'biped, relay and memory sections use (default: five in a row that '
                             'no test or other benchmark run holds)')
    arguments = parser.parse_args(argv)
    if arguments.repetitions is not None and arguments.repetitions < 1:
        parser.error('--repetitions must be at least 1')
    if arguments.ros_domain is not None and not 0 <= arguments.ros_domain <= 228:
        parser.error('--ros-domain must be between 0 and 228 (five IDs up to 232)')
    sections = arguments.only or SECTIONS
    started = time.perf_counter()
    machine = machine_description()
    command = ' '.join(['./dev bench', *(sys.argv[1:] if argv is None else argv)])
    print(f'machine: {machine}')
    print(f'command: {command}')
    run = document.Run.now(machine, command)
    measured: dict[str, document.Measured] = {}
    try:
        with ExitStack() as held:
            ros_domain = None
            if any(section in ROS_SECTIONS for section in sections):
                # Taken through the tests' lease (test/ros_domains.py), so that a test run or
                # another benchmark run beside this one never shares an id with it: a fixed
                # default (it was 50) lay among the ids the tests are handed, and its nodes saw
                # theirs.
                try:
                    ros_domain = held.enter_context(
                        domain_lease(DOMAIN_COUNT, arguments.ros_domain))
                except RuntimeError as error:
                    parser.error(str(error))
                print(f'ROS domains: {ros_domain}–{ros_domain + DOMAIN_COUNT - 1}')
            run_sections(arguments, sections, ros_domain, measured)
    finally:
        # what the sections measured, also when a later one failed: their figures stand
        if measured and not arguments.no_document:
            document.write(pathlib.Path(arguments.document), run, measured)
            print(f'\n{arguments.document} written ({", ".join(measured)})')
    load = ', '.join(f'{value:.2f}' for value in os.getloadavg())
    print(f'\nbenchmark took {time.perf_counter() - started:.0f} s; load average at the end: '
          f'{load}')
    return 0


def run_sections(arguments: argparse.Namespace, sections: Collection[str],
                 ros_domain: int | None, measured: dict[str, document.Measured]) -> None:
    """
    Print each of ``sections`` and keep its markdown in ``measured``.

    The node sections run on ``ros_domain`` and the four after it.
    """
    repetitions = arguments.repetitions or (5 if arguments.quick else 7)

    for key in SECTIONS:
        if key not in sections:
            continue
        started = document.Measured.clock()
        if key == 'kinematics':
            import kinematics_bench

            table, results = kinematics_bench.run(arguments.quick, repetitions)
            kinematics_bench.plot(results, arguments.plot)
            print(f'plot written to {arguments.plot}')
            parts = (table + '\n\n' + kinematics_bench.goals(results),)
        elif key == 'drive':
            import drive_bench

            parts = (drive_bench.run(arguments.quick, repetitions),)
        elif key == 'tf':
            import tf_bench

            parts = (tf_bench.run(arguments.quick, repetitions),)
        elif key == 'node':
            import node_bench

            parts = (node_bench.run(arguments.quick, repetitions, ros_domain),)
        elif key == 'cost':
            import cost_bench

            rates, figures = cost_bench.cpu_against_rate(arguments.quick, ros_domain)
            cost_bench.plot_cpu_against_rate(figures, arguments.cost_plot)
            print(f'plot written to {arguments.cost_plot}')
            parts = (cost_bench.run(arguments.quick, ros_domain) + '\n\n' + rates,)
        elif key == 'measured':
            import measured_bench

            parts = (measured_bench.run(arguments.quick, ros_domain),)
        elif key == 'loops':
            import loops_bench

            parts = (loops_bench.path_run(arguments.quick, repetitions),
                     loops_bench.run(arguments.quick, ros_domain))
        elif key == 'biped':
            import biped_bench

            parts = (biped_bench.path_run(arguments.quick, repetitions),
                     biped_bench.run(arguments.quick, ros_domain))
        elif key == 'relay':
            import relay_bench

            parts = (relay_bench.path_run(arguments.quick, repetitions),
                     relay_bench.run(arguments.quick, ros_domain))
        elif key == 'parallel':
            import parallel_bench
            import peers

            versions = peers.activate(install=True)
            rows, notes = parallel_bench.run(arguments.quick, repetitions)
            parallel_bench.plot(rows, arguments.parallel_plot)
            print(f'plot written to {arguments.parallel_plot}')
            every = parallel_bench.reference_every(arguments.quick)
            parts = ('Peers: ' + ', '.join(f'{name} {version}' for name, version in
                                           versions.items()) + '.\n\n'
                     + parallel_bench.table(rows, notes, every),)
        else:
            import node_bench

            minutes = arguments.memory_minutes
            if minutes is None:
                minutes = 0.5 if arguments.quick else 10.0
            parts = (f'{minutes:g} min at 1 kHz:\n\n'
                     + node_bench.memory_run(minutes, ros_domain),)
        print(f'\n## {document.SECTIONS[key].heading}\n')
        print('\n\n'.join(parts))
        measured[key] = document.Measured(parts, started)


if __name__ == '__main__':
    sys.exit(main())
