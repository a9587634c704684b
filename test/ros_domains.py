# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The ROS_DOMAIN_IDs the tests and the benchmarks run their nodes in, leased so that none share.

Every test module that starts nodes holds one id (conftest's ``domain_id``), bench/run.py five
in a row for its node sections; each holds the ids' locks while it uses them, so that test runs
and benchmark runs on one machine at once (two worktrees, a rerun started before the last
ended, a benchmark beside a test run) never see each other's nodes. Standard library only:
bench/run.py takes its ids here too, without the tests' ROS imports.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
import fcntl
import os
from pathlib import Path
import tempfile

# The ids handed out: those whose DDS ports stay below Linux's ephemeral range, but 0, the
# default, which other ROS programs on the machine use.
DOMAIN_IDS = range(1, 102)
# One lock file per id: a holder keeps the id's lock (flock) while it uses it.
DOMAIN_LOCKS = Path(tempfile.gettempdir()) / 'linkage_kinematics-ros-domains'


def _lock(first: int, count: int) -> list[int] | None:
    """Lock ids ``first`` to ``first + count - 1``: their descriptors, None if one is held."""
    DOMAIN_LOCKS.mkdir(exist_ok=True)
    descriptors: list[int] = []
    for domain_id in range(first, first + count):
        descriptor = os.open(DOMAIN_LOCKS / f'{domain_id}', os.O_RDWR | os.O_CREAT, 0o666)
        try:
            fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            for taken in (*descriptors, descriptor):
                os.close(taken)  # which releases its lock
            return None
        descriptors.append(descriptor)
    return descriptors


class _DomainIds:
    """Hands out the ROS_DOMAIN_IDs no other holder (here or in another run) has."""

    def __init__(self) -> None:
        # Ids go round: the next lease starts after the last id taken, so a module (or a rerun)
        # never gets the id its predecessor just gave back.
        self.last = DOMAIN_IDS[-1]

    def take(self, count: int) -> tuple[int, list[int]]:
        """Lock the next ``count`` free ids in a row; return the first and the locks."""
        start = DOMAIN_IDS.index(self.last) + 1
        for offset in range(len(DOMAIN_IDS)):
            first = DOMAIN_IDS[(start + offset) % len(DOMAIN_IDS)]
            if first + count - 1 > DOMAIN_IDS[-1]:
                continue
            descriptors = _lock(first, count)
            if descriptors is not None:
                self.last = first + count - 1
                return first, descriptors
        raise RuntimeError(f'no {count} ROS_DOMAIN_IDs in a row in {DOMAIN_IDS} are free: '
                           'other test or benchmark runs hold them')


_DOMAIN_IDS = _DomainIds()


@contextmanager
def domain_lease(count: int = 1, first: int | None = None) -> Iterator[int]:
    """
    Hold ``count`` ROS_DOMAIN_IDs in a row that no other test or run holds meanwhile.

    Yield the first. By default the next free ones of DOMAIN_IDS; from ``first`` (any id, also
    outside DOMAIN_IDS) those or RuntimeError if another holder has one of them.
    """
    if first is None:
        first, descriptors = _DOMAIN_IDS.take(count)
    else:
        held = _lock(first, count)
        if held is None:
            raise RuntimeError(f'ROS_DOMAIN_IDs {first} to {first + count - 1}: another test '
                               'or benchmark run holds one of them')
        descriptors = held
    try:
        yield first
    finally:
        for descriptor in descriptors:
            os.close(descriptor)  # which releases its lock
