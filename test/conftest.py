# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The fixtures of the tests that start processes, and which tests ``./dev test`` runs again.

``domain_id``: the module's own ROS_DOMAIN_ID. ``nodes``: starts node processes in it and ends
every one after the test (node_process.NodeProcesses); ``module_nodes`` after the module.
"""

from collections.abc import Iterator

from node_process import NodeProcesses
import pytest
from ros_domains import domain_lease


def pytest_addoption(parser: pytest.Parser) -> None:
    """Add --process-reruns (./dev test passes 2; colcon test, without it, runs each test once)."""
    parser.addoption(
        '--process-reruns', type=int, default=0, metavar='N',
        help='run a failed test marked "processes" again, up to N times (pytest-rerunfailures)')


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """
    Mark every test in a ROS domain "processes"; with --process-reruns, make those flaky.

    A test in a domain talks to processes over DDS, where a discovery race (a first message or
    a service reply sent before the peer matched) has failed single tests on a busy machine; a
    pure test is never rerun, so that one that fails once fails the run.
    """
    reruns = config.getoption('process_reruns')
    for item in items:
        if 'domain_id' in item.fixturenames:
            item.add_marker(pytest.mark.processes)
        if reruns and item.get_closest_marker('processes'):
            item.add_marker(pytest.mark.flaky(reruns=reruns))


@pytest.fixture(scope='module')
def domain_id() -> Iterator[int]:
    """Return the module's ROS_DOMAIN_ID, which no other module or concurrent test run holds."""
    with domain_lease() as leased:
        yield leased


@pytest.fixture
def other_domain_id() -> Iterator[int]:
    """Return a ROS_DOMAIN_ID for one test, apart from its module's (e.g. its listener's)."""
    with domain_lease() as leased:
        yield leased


def _node_processes(domain_id: int) -> Iterator[NodeProcesses]:
    processes = NodeProcesses(domain_id)
    yield processes
    processes.finish()


@pytest.fixture
def nodes(domain_id: int) -> Iterator[NodeProcesses]:
    """Start processes in the module's domain; each has ended (SIGINT, or worse) after the test."""
    yield from _node_processes(domain_id)


@pytest.fixture(scope='module')
def module_nodes(domain_id: int) -> Iterator[NodeProcesses]:
    """``nodes`` for a module's fixture (e.g. one run that many tests read)."""
    yield from _node_processes(domain_id)
