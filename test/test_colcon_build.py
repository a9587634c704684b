# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The package in a colcon workspace.

It builds, its installed linkage_node runs and publishes, and `colcon test` runs the suite with
pytest and `colcon test-result` counts it. The workspace gets the files git lists, so outside a
git checkout (a release tarball's) these tests are skipped, saying why.
"""

from __future__ import annotations

import os
from pathlib import Path
import re
import shutil
import subprocess
import sys

from linkage_kinematics.bag import reader as bag_reader
from linkage_kinematics.bag.metadata import BagMetadata
from node_process import (
    Listener,
    NodeProcesses,
    PROCESS_TIMEOUT,
    REPOSITORY,
    ros_context,
    ros_environment,
)
import pytest
from sensor_msgs.msg import JointState

# Every test here builds the package with colcon or runs what it built: ./dev test reruns one
# that failed (conftest.py), as it does a test that talks to a node.
pytestmark = pytest.mark.processes
# What the nested `colcon test` runs in full: quick tests that need the test dependencies
# (hypothesis, and mpmath through test/reference.py). Naming them keeps the nested suite from
# running this module again, and so from nesting for ever.
NESTED_TESTS = ('test/test_drive.py',)


def _package_files() -> list[str]:
    """Return the repository's files as a clone has them (tracked, or new and not ignored)."""
    listed = subprocess.run(
        ['git', 'ls-files', '--cached', '--others', '--exclude-standard'],
        cwd=REPOSITORY, capture_output=True, text=True,
    )
    if listed.returncode != 0:
        # e.g. `colcon test` in a workspace made from a release tarball (git archive)
        pytest.skip('needs a git checkout to know the package files: '
                    + listed.stderr.strip().splitlines()[-1])
    return [path for path in listed.stdout.split() if (REPOSITORY / path).is_file()]


def _colcon_environment(install: Path, base: dict[str, str]) -> dict[str, str]:
    """
    Return what sourcing install/local_setup.sh would set.

    Each package's hook .dsv files prepend their paths (relative to the package prefix) to the
    named variables.
    """
    environment = dict(base)
    for package_dsv in sorted(install.glob('*/share/*/package.dsv')):
        prefix = package_dsv.parents[2]
        for line in package_dsv.read_text().splitlines():
            kind, hook = line.split(';', 1)
            if kind != 'source' or not hook.endswith('.dsv'):
                continue
            for entry in (prefix / hook).read_text().splitlines():
                action, variable, relative = entry.split(';', 2)
                assert action == 'prepend-non-duplicate', entry
                value = str(prefix / relative) if relative else str(prefix)
                current = environment.get(variable, '').split(os.pathsep)
                environment[variable] = os.pathsep.join(
                    [value, *(part for part in current if part and part != value)])
    return environment


def _colcon(workspace: Path, *arguments: str) -> str:
    """Run colcon in ``workspace`` on this environment's ROS; its output (it must succeed)."""
    colcon = Path(sys.executable).parent / 'colcon'
    completed = subprocess.run(
        [str(colcon), *arguments], cwd=workspace,
        env={**os.environ, 'AMENT_PREFIX_PATH': sys.prefix}, capture_output=True, text=True,
        timeout=PROCESS_TIMEOUT * 4,
    )
    assert completed.returncode == 0, completed.stdout + completed.stderr
    return completed.stdout


def _collected(arguments: list[str], cwd: Path) -> int:
    """Return how many tests pytest collects with ``arguments`` in ``cwd``."""
    output = subprocess.run(
        [sys.executable, '-m', 'pytest', '--collect-only', '-q', *arguments], cwd=cwd,
        capture_output=True, text=True, check=True,
    ).stdout
    return int(re.search(r'^(\d+) tests? collected', output, re.MULTILINE)[1])


@pytest.fixture(scope='module')
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Return a colcon workspace with this repository (as git knows it) built in it."""
    workspace = tmp_path_factory.mktemp('colcon') / 'ws'
    source = workspace / 'src' / 'linkage_kinematics'
    for path in _package_files():
        target = source / path
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(REPOSITORY / path, target)
    _colcon(workspace, 'build', '--base-paths', 'src')
    return workspace


def test_colcon_test_runs_the_suite_with_pytest_and_test_result_counts_it(
    workspace: Path,
) -> None:
    # The whole suite is collected in colcon's test environment: pytest runs it (not unittest's
    # discovery, which finds none of these tests) and every test module imports.
    output = _colcon(workspace, 'test', '--base-paths', 'src', '--event-handlers',
                     'console_direct+', '--pytest-args', '--collect-only', '-q')
    everything = _collected([], REPOSITORY)
    assert f'{everything} tests collected' in output, output
    # A part of it runs to the end, and colcon test-result counts each of its tests.
    _colcon(workspace, 'test', '--base-paths', 'src', '--pytest-args', *NESTED_TESTS)
    summary = _colcon(workspace, 'test-result', '--verbose')
    expected = _collected(list(NESTED_TESTS), REPOSITORY)
    assert expected > 0
    assert f'Summary: {expected} tests, 0 errors, 0 failures, 0 skipped' in summary, summary


def test_colcon_build_installs_a_node_that_publishes(
    workspace: Path, nodes: NodeProcesses, tmp_path: Path
) -> None:
    install = workspace / 'install'
    executable = install / 'linkage_kinematics' / 'lib' / 'linkage_kinematics' / 'linkage_node'
    assert executable.is_file() and os.access(executable, os.X_OK)
    share = install / 'linkage_kinematics' / 'share' / 'linkage_kinematics'
    for installed in ('launch/linkage.launch.py', 'config/seed_constant.yaml',
                      'config/seed_variable.yaml', 'urdf/linkage.urdf',
                      'interfaces/tf2_msgs/msg/TFMessage.msg',
                      'interfaces/tf2_msgs/msg/TFMessage.json'):
        assert (share / installed).is_file(), installed

    environment = _colcon_environment(install, ros_environment(nodes.domain_id))
    imported = subprocess.run(
        [sys.executable, '-c', 'import linkage_kinematics.ros.node as n; print(n.__file__)'],
        cwd=tmp_path, env=environment, capture_output=True, text=True, check=True,
    ).stdout.strip()
    assert Path(imported).is_relative_to(install), imported

    with ros_context(nodes.domain_id) as context:
        listener = Listener('colcon_listener', context)
        listener.subscribe('/joint_states', JointState)
        process = nodes.start(
            {'end_behavior': 'loop', 'log.folder': str(tmp_path / 'bags')}, tmp_path / 'node.log',
            executable=[str(executable)], environment=environment, cwd=tmp_path,
        )
        try:
            assert listener.spin_until(lambda: len(listener.received['/joint_states']) >= 5), (
                tmp_path / 'node.log').read_text()
            assert nodes.interrupt(process) == 0
        finally:
            listener.destroy()
    assert list(listener.received['/joint_states'][0].name) == [
        'crank_joint', 'coupler_joint', 'rocker_joint']
    # The installed package's bag writer process finished the log.
    (bag,) = (tmp_path / 'bags').iterdir()
    (mcap_file,) = bag_reader.bag_files(bag)
    assert mcap_file.complete
    count = BagMetadata.read(bag).message_count
    assert count >= 5
    assert f'bag finalized: {bag}, {count} messages' in (tmp_path / 'node.log').read_text()
