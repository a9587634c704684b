# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Where the node's process runs: the ``cpu_affinity`` parameter (as ros2_control's).

On one CPU the executor's timer thread and the thread running the callbacks wake each other
without crossing CPUs, and the bag writer process, on the other CPUs, cannot delay either
(docs/benchmarks.md, "The node against a minimal hand-written publisher"). No ROS.
"""

from __future__ import annotations

import os

from linkage_kinematics.run.limits import NO_CPU_AFFINITY
from linkage_kinematics.run.parameter_values import ConfigurationError
from linkage_kinematics.shared.affinity import set_process_affinity


class CpuPlacement:
    """The CPUs this process may use, and whether (and where) it is pinned."""

    def __init__(self) -> None:
        self.available = os.sched_getaffinity(0) if hasattr(os, 'sched_getaffinity') else set()
        # The bag writer's CPUs while the node is pinned, None while it is not.
        self.bag_writer_cpus: set[int] | None = None

    def check(self, cpu: int) -> None:
        """Raise ConfigurationError naming cpu_affinity unless this process may use ``cpu``."""
        if cpu == NO_CPU_AFFINITY:
            return
        if not hasattr(os, 'sched_setaffinity'):
            raise ConfigurationError('cpu_affinity', 'CPU affinity is not supported here')
        if cpu not in self.available:
            raise ConfigurationError(
                'cpu_affinity',
                f'CPU {cpu} is not one this process may run on (it may run on '
                f"{', '.join(map(str, sorted(self.available)))})",
            )

    def place(self, cpu: int) -> str | None:
        """
        Pin every thread of this process to ``cpu``, or give a pinned process back every CPU.

        Fast DDS's threads included; threads started later inherit it. Return what changed, for
        the log (None if nothing did).
        """
        self.check(cpu)
        if cpu == NO_CPU_AFFINITY and self.bag_writer_cpus is None:
            return None  # never pinned: the process stays as it was started
        node_cpus = self.available if cpu == NO_CPU_AFFINITY else {cpu}
        set_process_affinity(os.getpid(), node_cpus)
        if cpu == NO_CPU_AFFINITY:
            self.bag_writer_cpus = None
            return 'no longer pinned to a CPU'
        self.bag_writer_cpus = (self.available - node_cpus) or node_cpus
        return (f'running on CPU {cpu}; the bag writer on CPU '
                f"{', '.join(map(str, sorted(self.bag_writer_cpus)))}")
