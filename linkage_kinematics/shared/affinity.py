# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A process's threads held to a set of CPUs (Linux), for the node and for its bag writer process.

``run.placement`` pins the node's own process (the ``cpu_affinity`` parameter) and chooses the
CPUs left to the bag writer, which ``bag.writer_process`` gives its child process.
"""

from __future__ import annotations

from collections.abc import Set
import os


def set_process_affinity(pid: int, cpus: Set[int]) -> None:
    """
    Let every thread of process ``pid`` run only on ``cpus``.

    Threads it starts later inherit their starter's CPUs. A process that has ended meanwhile is
    left alone: whoever waits for it learns how it ended.
    """
    try:
        threads = os.listdir(f'/proc/{pid}/task')
    except FileNotFoundError:
        return
    for thread in threads:
        try:
            os.sched_setaffinity(int(thread), cpus)
        except ProcessLookupError:
            pass  # the thread ended meanwhile
