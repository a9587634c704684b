# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Section "cost": linkage_node against the rclpy node a lab would write by hand, side by side.

Both run as processes at the same time, at the same timer rate, nothing subscribed:
linkage_node at ``rate_hz`` with logging on (``end_behavior:=bounce``) and
``minimal_publisher.py`` (one JointState per tick on rclpy's default executor). CPU is
utime + stime from /proc/PID/stat over the same seconds, the node's with its bag writer's.
Then the highest timer rate at which the node, logging, misses under 1 % of its ticks (from
its own /diagnostics), with the default placement and with ``cpu_affinity:=0``, and timer
jitter and latency to another process at 100 Hz, 1 kHz and those rates. Last, both side by side
at each of a range of rates, for the plot of CPU against rate.
"""

from __future__ import annotations

import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import node_bench
from timing import format_seconds, markdown_table

MINIMAL_PUBLISHER = pathlib.Path(__file__).resolve().parent / 'minimal_publisher.py'
CPU_SECONDS = 5.0  # the window CPU time is measured over, after STARTUP_S
RATES = (1000.0, 2000.0, 3000.0, 4000.0, 5000.0, 7500.0, 10000.0)
MISSED_LIMIT = 0.01
# The timer rates of the CPU-against-rate plot: the node's default 100 Hz to twice a lab's 1 kHz.
PLOT_RATES = (100.0, 250.0, 500.0, 1000.0, 2000.0)
# The node's placements the rates are measured with: the operating system's, and the node on
# CPU 0 with its bag writer on the others (the cpu_affinity parameter).
PLACEMENTS = {'default': {}, 'cpu_affinity:=0': {'cpu_affinity': '0'}}
CLOCK_TICKS = os.sysconf('SC_CLK_TCK')


def cpu_seconds(pid: int, children: bool = True) -> float:
    """
    Utime + stime so far (s) of a process and its children (a logging node's bag writer).

    ``children`` False: of the process alone.
    """
    total = 0
    for process in node_bench.with_children(pid) if children else [pid]:
        with open(f'/proc/{process}/stat', encoding='ascii') as stat:
            fields = stat.read().rsplit(')', 1)[1].split()
        total += int(fields[11]) + int(fields[12])
    return total / CLOCK_TICKS


def start_minimal_publisher(rate: float, executor: str, domain: int) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, str(MINIMAL_PUBLISHER), f'{rate:g}', executor],
                            cwd=node_bench.ROOT, env=node_bench.ros_environment(domain),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def side_by_side(rate: float, executor: str, domain_base: int) -> tuple[float, float]:
    """
    CPU share of one core of (linkage_node logging, minimal publisher on ``executor``).

    Running at the same time at ``rate``, each alone on its ROS domain.
    """
    with tempfile.TemporaryDirectory(prefix='linkage_bench_cost_') as folder:
        node = node_bench.start_node(
            {'rate_hz': f'{rate:.1f}', 'end_behavior': 'bounce', 'log.folder': folder},
            domain_base + node_bench.DOMAIN_RATE)
        minimal = start_minimal_publisher(rate, executor, domain_base + node_bench.DOMAIN_SPLIT)
        try:
            time.sleep(node_bench.STARTUP_S)
            for process in (node, minimal):
                if process.poll() is not None:
                    raise RuntimeError(f'{process.args} exited early')
            started = time.monotonic()
            before = [cpu_seconds(process.pid) for process in (node, minimal)]
            time.sleep(CPU_SECONDS)
            after = [cpu_seconds(process.pid) for process in (node, minimal)]
            elapsed = time.monotonic() - started
        finally:
            node_bench.stop(minimal)
            node_bench.stop(node)
    node_share, minimal_share = ((end - start) / elapsed for start, end in zip(before, after))
    return node_share, minimal_share


def missed_share(
    rate: float, seconds: float, domain_base: int, placement: dict[str, str]
) -> float:
    """
    Return the share of ticks the node missed.

    The node logs, runs with ``placement`` as its cpu_affinity and has nothing but /diagnostics
    subscribed; the share is 1 − its achieved rate over its /diagnostics windows after the first
    ÷ ``rate``.
    """
    with tempfile.TemporaryDirectory(prefix='linkage_bench_cost_rate_') as folder:
        data = node_bench.observe(
            {'rate_hz': f'{rate:.1f}', 'end_behavior': 'bounce', 'log.folder': folder,
             **placement},
            seconds, domain_base + node_bench.DOMAIN_RATE, topics=[])
    windows = node_bench.achieved_rates(data)
    if not windows:
        raise RuntimeError(f'no /diagnostics windows from the node at {rate:g} Hz')
    return max(0.0, 1.0 - statistics.mean(windows) / rate)


def run(quick: bool, ros_domain: int) -> str:
    """
    Return the section as markdown.

    ``ros_domain`` is the first of the node sections' domains.
    """
    repetitions = 2 if quick else 3
    rows = []
    ratios = []
    for executor in ('single',) * repetitions + ('events',):
        node_share, minimal_share = side_by_side(1000.0, executor, ros_domain)
        ratio = node_share / minimal_share
        if executor == 'single':
            ratios.append(ratio)
        rows.append([f'{100.0 * node_share:.1f} %',
                     f'{100.0 * minimal_share:.1f} %',
                     "SingleThreadedExecutor (rclpy's default)" if executor == 'single'
                     else 'rclpy.experimental.EventsExecutor',
                     f'{ratio:.2f}×'])
    ratio = statistics.median(ratios)
    lines = [
        f'CPU at 1 kHz, one core = 100 %, utime + stime over {CPU_SECONDS:g} s, both processes '
        'running at once, nothing subscribed (linkage_node: end_behavior:=bounce, logging on; '
        'its CPU includes its bag writer process):',
        '',
        markdown_table(['linkage_node', 'minimal publisher', 'its executor',
                        'linkage_node ÷ minimal'], rows),
        '',
        f'- linkage_node ÷ minimal publisher on the default executor: {ratio:.2f}× '
        f"(median of {len(ratios)}; goal ≤ 1: {'met' if ratio <= 1.0 else 'missed'})",
        '',
    ]

    seconds = 4.0 if quick else 8.0
    rows = []
    highest: dict[str, float | None] = dict.fromkeys(PLACEMENTS)
    below_limit = dict.fromkeys(PLACEMENTS, True)
    for rate in RATES:
        row = [f'{rate:g} Hz']
        for name, placement in PLACEMENTS.items():
            fraction = missed_share(rate, seconds, ros_domain, placement)
            row.append(f'{100.0 * fraction:.2f} %')
            below_limit[name] = below_limit[name] and fraction < MISSED_LIMIT
            if below_limit[name]:
                highest[name] = rate
        rows.append(row)
    lines += [
        f'Sustained rate, logging on, {seconds:g} s per rate and placement, missed share from '
        "the node's /diagnostics (only /diagnostics subscribed); the highest rate counts if it "
        'and every lower rate missed under the limit:',
        '',
        markdown_table(['timer rate', *(f'ticks missed, {name}' for name in PLACEMENTS)], rows),
        '',
        *(f'- highest rate with < {100 * MISSED_LIMIT:g} % missed, {name}: '
          f'{node_bench.rate_text(highest[name])} (goal 5 kHz)' for name in PLACEMENTS),
        '',
    ]

    rows = []
    timing_runs = [(rate, 'default') for rate in (100.0, 1000.0)] + [
        (rate, name) for name, rate in highest.items() if rate is not None and rate > 1000.0]
    for rate, name in timing_runs:
        figures = node_bench.timing_figures(rate, seconds, ros_domain, PLACEMENTS[name])
        rows.append([f'{rate:g} Hz', name, format_seconds(figures['jitter_p50']),
                     format_seconds(figures['jitter_p99']), format_seconds(figures['latency_p50']),
                     format_seconds(figures['latency_p99']),
                     f"{figures['received']} of {figures['expected']:.0f}"])
    lines += [
        'Timer jitter (|interval between header stamps − period|) and latency (receive time in '
        'a listener process − header stamp), logging on, /joint_states subscribed, at 100 Hz, '
        "1 kHz and each placement's highest rate:",
        '',
        markdown_table(['rate', 'placement', 'jitter p50', 'jitter p99', 'latency p50',
                        'latency p99', 'messages received'], rows),
    ]
    return '\n'.join(lines)


def cpu_against_rate(quick: bool, ros_domain: int
                     ) -> tuple[str, list[tuple[float, float, float]]]:
    """
    Return the table of both processes' CPU at each of ``PLOT_RATES``, and its figures.

    Side by side as ``side_by_side`` runs them, on the default executor; the figures are
    (rate, linkage_node's share, the minimal publisher's share) for the plot.
    """
    rates = (100.0, 1000.0) if quick else PLOT_RATES
    figures = [(rate, *side_by_side(rate, 'single', ros_domain)) for rate in rates]
    rows = [[f'{rate:g} Hz', f'{100.0 * node:.1f} %', f'{100.0 * minimal:.1f} %',
             f'{node / minimal:.2f}×'] for rate, node, minimal in figures]
    return ('\n'.join([
        f'CPU against the timer rate, one core = 100 %, both side by side over {CPU_SECONDS:g} s '
        "at each rate (logging on, the minimal publisher on rclpy's default executor):", '',
        markdown_table(['timer rate', 'linkage_node', 'minimal publisher',
                        'linkage_node ÷ minimal'], rows)]), figures)


def plot_cpu_against_rate(figures: list[tuple[float, float, float]], path: str) -> None:
    """Draw both processes' CPU (% of one core) against the timer rate, log-log."""
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    rates = [rate for rate, _, _ in figures]
    figure, axis = plt.subplots(figsize=(7, 4.5))
    for index, (label, marker, colour) in enumerate((
            ('linkage_node (logging on, with its bag writer)', 'o', 'tab:green'),
            ('minimal hand-written rclpy publisher', 's', 'tab:blue')), start=1):
        axis.loglog(rates, [100.0 * row[index] for row in figures], marker=marker,
                    color=colour, label=label)
    axis.set_xlabel('timer rate (Hz)')
    axis.set_ylabel('CPU (% of one core)')
    axis.set_title('Cost against rate, side by side at each rate (lower is better)')
    axis.grid(True, which='both', alpha=0.3)
    axis.legend(fontsize=9)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
