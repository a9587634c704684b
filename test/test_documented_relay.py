# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The command relay's worked examples in docs/following_loops.md are what the relay sends.

Each example's relay is built as ``linkage_command_node`` builds it, from the parameters its
documented command line gives (``-p NAME:=VALUE``, each value read as YAML as rcl reads it; the
description from the file the line ``cat``s), in this process: test/test_command_node.py shows
the node over DDS sends the same bytes as this conversion. Then the documented message goes in
and the documented answer must come out: the excavator's boom trajectory and its refusal beyond
the cylinder's stroke, the ankle's effort command at the motors' documented sample.
"""

from __future__ import annotations

from pathlib import Path
import re
from typing import Any

from linkage_kinematics.loops.command import CommandRefused, JointPoint
from linkage_kinematics.run.configuration import build_relay_configuration
from linkage_kinematics.run.parameter_specs import relay_parameter_specs
from linkage_kinematics.run.relay import read_relay, Relay
import pytest
import yaml

REPOSITORY = Path(__file__).resolve().parent.parent
RELAY_BLOCK = re.compile(r'```bash\n(\./dev run linkage_command_node .*?)```', re.DOTALL)
PARAMETER = re.compile(r'-p ([\w.]+):=("\$\(cat ([^)]+)\)"|"[^"]*"|\S+)')
TEXT_BLOCK = re.compile(r'```text\n(.*?)```', re.DOTALL)


def documented_section(title: str) -> str:
    """Return a section of docs/following_loops.md, from its heading to the next one."""
    text = (REPOSITORY / 'docs' / 'following_loops.md').read_text(encoding='utf-8')
    start = text.index(f'### {title}\n')
    return text[start:text.index('\n##', start + 4)]


def documented_relay(section: str) -> Relay:
    """Return the relay the section's ``./dev run linkage_command_node`` line starts."""
    command = RELAY_BLOCK.search(section).group(1)
    values: dict[str, Any] = {spec.name: spec.default for spec in relay_parameter_specs()}
    for name, value, path in PARAMETER.findall(command):
        values[name] = ((REPOSITORY / path).read_text(encoding='utf-8') if path
                        else yaml.safe_load(value.strip('"')))
    return read_relay(values['robot_description'], build_relay_configuration(values))


def published(section: str, message_type: str) -> dict[str, Any]:
    """Return the message the section's ``ros2 topic pub`` of ``message_type`` sends."""
    match = re.search(rf'{re.escape(message_type)} \\\n\s*"(\{{.*?\}})"', section)
    return yaml.safe_load(match.group(1))


def test_the_excavator_s_boom_trajectory_reaches_the_cylinder_as_documented():
    section = documented_section('The excavator: cylinder forces and a boom trajectory')
    relay = documented_relay(section)
    sent = published(section, 'trajectory_msgs/msg/JointTrajectory')
    answer, refusal = TEXT_BLOCK.findall(section)[-2:]
    expected = yaml.safe_load(answer)
    names, points = relay.trajectory(sent['joint_names'], [
        JointPoint(tuple(point['positions']), tuple(point['velocities']))
        for point in sent['points']])
    assert list(names) == expected['joint_names']
    for point, documented in zip(points, expected['points'], strict=True):
        assert list(point.positions) == documented['positions']
        assert list(point.velocities) == documented['velocities']
    # the point beyond the stroke: refused whole, in the line the relay logs
    with pytest.raises(CommandRefused) as refused:
        relay.trajectory(['boom_joint'], [JointPoint((0.0,)), JointPoint((-1.0,))])
    assert f'refused joint_trajectory: {refused.value}' == refusal.strip()


def test_the_ankle_s_torques_reach_the_motors_as_documented():
    section = documented_section("The humanoid ankle's torques")
    relay = documented_relay(section)
    sample = published(section, 'sensor_msgs/msg/JointState')
    assert relay.pose.take(1, sample['name'], sample['position'], sample['velocity'], 0)
    command = published(section, 'std_msgs/msg/Float64MultiArray')
    expected = yaml.safe_load(TEXT_BLOCK.findall(section)[-1])
    assert list(relay.forward(command['data'], 0)) == expected['data']
    # the parameters written out are the defaults for this ankle
    defaults = documented_relay(re.sub(r' \\\n\s*-p commands\.(joints|controller_joints)'
                                       r':="[^"]*"', '', section))
    assert (defaults.joints, defaults.controller_joints) == (
        relay.joints, relay.controller_joints)
