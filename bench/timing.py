# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""Timing and reporting helpers shared by the benchmark sections."""

from __future__ import annotations

import math
import os
import platform
import statistics
import time
from typing import Callable, Sequence

import numpy as np


def interleaved_medians(
    workloads: dict[str, Callable[[], int]], repetitions: int,
    clock: Callable[[], float] = time.perf_counter,
) -> dict[str, float]:
    """
    Median seconds per configuration of each workload, timed in turn ``repetitions`` times.

    Each workload runs once and returns how many configurations it did. Running all of them
    round-robin exposes each to the same drift of a shared machine, so their ratios hold even
    when the absolute times move. ``clock``: wall time by default; ``time.process_time`` counts
    this process's CPU time only (not time spent waiting, e.g. on a full pipe).
    """
    samples: dict[str, list[float]] = {name: [] for name in workloads}
    for _ in range(repetitions):
        for name, workload in workloads.items():
            start = clock()
            count = workload()
            samples[name].append((clock() - start) / count)
    return {name: statistics.median(times) for name, times in samples.items()}


def paired_ratio(
    first: Callable[[], int], second: Callable[[], int], pairs: int
) -> float:
    """
    Median over ``pairs`` back-to-back runs of the ratio of ``first``'s time to ``second``'s.

    Per configuration; the two alternate which runs first. Each ratio compares two runs a few
    milliseconds apart, so a burst of another process's work moves single pairs, not the
    median: a steadier figure for an overhead goal than the ratio of two medians taken among
    many other methods' runs.
    """
    ratios = []
    for index in range(pairs):
        seconds = {}
        for workload in ((first, second) if index % 2 == 0 else (second, first)):
            start = time.perf_counter()
            count = workload()
            seconds[workload] = (time.perf_counter() - start) / count
        ratios.append(seconds[first] / seconds[second])
    return statistics.median(ratios)


def machine_description() -> str:
    """CPU model, cores, load, Python and numpy versions, for the report."""
    model = 'unknown CPU'
    with open('/proc/cpuinfo', encoding='utf-8') as cpuinfo:
        for line in cpuinfo:
            if line.startswith('model name'):
                model = line.split(':', 1)[1].strip()
                break
    load = ', '.join(f'{value:.2f}' for value in os.getloadavg())
    return (
        f'{model}, {os.cpu_count()} cores (load average {load}); Linux {platform.release()}; '
        f'Python {platform.python_version()}, numpy {np.__version__}'
    )


def format_seconds(seconds: float) -> str:
    """Return a duration with a unit that keeps 3 significant digits readable."""
    if not math.isfinite(seconds):
        return '–'
    for unit, scale in (('s', 1.0), ('ms', 1e-3), ('µs', 1e-6), ('ns', 1e-9)):
        if seconds >= scale or unit == 'ns':
            return f'{seconds / scale:.3g} {unit}'
    raise AssertionError('unreachable')


def format_error(error: float) -> str:
    """Return an error for a table: NaN becomes 'no result'."""
    if math.isnan(error):
        return 'no result'
    return f'{error:.1e}'


def markdown_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """Return a GitHub markdown table."""
    lines = ['| ' + ' | '.join(header) + ' |', '|' + '---|' * len(header)]
    lines += ['| ' + ' | '.join(row) + ' |' for row in rows]
    return '\n'.join(lines)
