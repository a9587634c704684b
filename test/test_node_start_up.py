# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Start-up failures of a real node process: each is one line naming its cause, and exit 2.

A bad parameter's line is tested in test_node_bad_input.py; here the others: no ament
environment, a message definition missing from the ament index, ROS arguments rcl refuses.
The node's stderr holds the one plain ``linkage_node: …`` line, the same text logged at FATAL,
and nothing else of the node's (rcl's own log line about its arguments aside).
"""

from __future__ import annotations

import os
from pathlib import Path
import subprocess
import sys

from node_process import node_command, PROCESS_TIMEOUT, REPOSITORY, ros_environment


def start_up_failure(
    tmp_path: Path, environment: dict[str, str], ros_arguments: tuple[str, ...] = ()
) -> tuple[int, list[str]]:
    """Run a node that cannot start; return its exit status and its stderr's lines."""
    completed = subprocess.run(
        node_command({'log.folder': str(tmp_path / 'bags')}, ros_arguments=ros_arguments),
        cwd=REPOSITORY, env=environment, capture_output=True, text=True,
        timeout=PROCESS_TIMEOUT,
    )
    return completed.returncode, completed.stderr.splitlines()


def assert_one_line(lines: list[str], cause: str) -> None:
    """One plain line names ``cause``; the only other is the same text logged at FATAL."""
    plain = [line for line in lines if line.startswith('linkage_node: ')]
    assert len(plain) == 1 and cause in plain[0], lines
    text = plain[0].removeprefix('linkage_node: ')
    assert all(line == plain[0] or ('[FATAL]' in line and line.endswith(text))
               or '[rcl]' in line for line in lines), lines
    assert not any('Traceback' in line for line in lines)


def test_a_missing_ament_environment_is_one_line_naming_it(
    domain_id: int, tmp_path: Path
) -> None:
    environment = ros_environment(domain_id)
    del environment['AMENT_PREFIX_PATH']
    status, lines = start_up_failure(tmp_path, environment)
    assert status == 2, lines
    assert_one_line(lines, 'AMENT_PREFIX_PATH')
    assert not (tmp_path / 'bags').exists()


def test_a_missing_message_definition_is_one_line_naming_it(
    domain_id: int, tmp_path: Path
) -> None:
    """An ament prefix with every package of this environment but visualization_msgs."""
    prefix = tmp_path / 'prefix'
    index = prefix / 'share' / 'ament_index' / 'resource_index' / 'packages'
    index.mkdir(parents=True)
    installed = Path(sys.prefix) / 'share'
    for marker in (installed / 'ament_index' / 'resource_index' / 'packages').iterdir():
        if marker.name != 'visualization_msgs' and (installed / marker.name).is_dir():
            (index / marker.name).write_text('')
            os.symlink(installed / marker.name, prefix / 'share' / marker.name)
    environment = ros_environment(domain_id)
    environment['AMENT_PREFIX_PATH'] = str(prefix)
    status, lines = start_up_failure(tmp_path, environment)
    assert status == 2, lines
    assert_one_line(lines, 'visualization_msgs/msg/MarkerArray.msg')
    assert not (tmp_path / 'bags').exists()


def test_ros_arguments_rcl_refuses_are_one_line_naming_them(
    domain_id: int, tmp_path: Path
) -> None:
    missing = tmp_path / 'no_such_parameters.yaml'
    status, lines = start_up_failure(tmp_path, ros_environment(domain_id),
                                     ('--params-file', str(missing)))
    assert status == 2, lines
    assert_one_line(lines, f"cannot start ROS: failed to initialize rcl: Couldn't parse params "
                           f"file: '--params-file {missing}'")
    assert not (tmp_path / 'bags').exists()
