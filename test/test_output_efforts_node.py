# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
linkage_node's efforts through the loops (``loops.output_joints``), over DDS.

A real node closes the excavator (three planar groups, cylinders measured, boom, stick and
bucket joints the outputs) and the humanoid ankle (one group of two balls, motors measured,
pitch and roll the outputs); this process sends measured positions, velocities and efforts.
Every ``joint_states`` message it publishes gives each output joint an effort that balances the
power of the input it answers, τ_mᵀ·ṁ = τ_outᵀ·q̇_out to rounding (the actuators' velocities and
efforts as sent, the outputs' as published), and every other joint 0; a message without efforts
is answered without; the bag holds the input and the output as they went. Each group with output
joints has its status with its mechanical advantage. Without the parameter nothing of this is
published. Output joints that cannot be a group's end the start with one line (exit 2), or, for a
description on the topic, make the status ERROR while the node keeps running. The efforts
docs/following_loops.md shows for the excavator and the ankle are what the node publishes.
"""

from __future__ import annotations

import math
from pathlib import Path
import re
import sys

import loop_robots
from node_process import ros_context, stamp_ns
import pytest
from rosbags.rosbag2 import Reader
from rosbags.typesys import get_typestore, Stores
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from test_robot_loops import loop_node, LoopNode, values
import yaml

REPOSITORY = Path(__file__).resolve().parent.parent
ANKLE = (REPOSITORY / 'urdf' / 'humanoid_ankle.urdf').read_text(encoding='utf-8')
TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
EPSILON = sys.float_info.epsilon
START_NS = 1_000_000_000
PERIOD_NS = 10_000_000
SAMPLES = 8
# robot → URDF, measured joints, output joints, per measured joint (amplitude, effort), and
# per group its actuators and output joints
ROBOTS = {
    'excavator': (loop_robots.excavator(), ['boom_cylinder', 'stick_cylinder', 'bucket_cylinder'],
                  ['boom_joint', 'stick_joint', 'bucket_joint'],
                  ((0.1, 2e5), (0.15, -1e5), (0.1, 5e4)),
                  {'boom_cylinder_pin': (['boom_cylinder'], ['boom_joint']),
                   'stick_cylinder_pin': (['stick_cylinder'], ['stick_joint']),
                   'bucket_cylinder_pin+bucket_pin': (['bucket_cylinder'], ['bucket_joint'])}),
    'ankle': (ANKLE, ['motor_left', 'motor_right'], ['ankle_pitch', 'ankle_roll'],
              ((0.4, 2.0), (0.3, -1.5)),
              {'ball_left+ball_right': (['motor_left', 'motor_right'],
                                        ['ankle_pitch', 'ankle_roll'])}),
}


@pytest.fixture(scope='module')
def context(domain_id):
    with ros_context(domain_id) as ros:
        yield ros


def motion(name: str) -> list[tuple[list[float], list[float], list[float]]]:
    """Return the measured joints' positions, velocities and efforts at each sample."""
    amplitudes = ROBOTS[name][3]
    samples = []
    for index in range(SAMPLES):
        phase = [2.0 * math.pi * index / SAMPLES + k for k in range(len(amplitudes))]
        samples.append(([a * math.sin(p) for (a, _), p in zip(amplitudes, phase)],
                        [a * math.cos(p) for (a, _), p in zip(amplitudes, phase)],
                        [effort * (1.0 + 0.5 * math.cos(p))
                         for (_, effort), p in zip(amplitudes, phase)]))
    return samples


def send(node: LoopNode, stamp: int, names: list[str], positions: list[float],
         velocities: list[float], efforts: list[float]) -> None:
    """Publish one input with efforts; wait for the joint state stamped like it."""
    message = JointState(name=names, position=positions, velocity=velocities, effort=efforts)
    message.header.stamp.sec, message.header.stamp.nanosec = divmod(stamp, 1_000_000_000)
    node.inputs.publish(message)
    assert node.listener.spin_until(
        lambda: any(stamp_ns(output) == stamp for output in node.outputs)), node.log.read_text()


def parameters(name: str, outputs: bool = True) -> dict:
    urdf, measured, output_joints, _, _ = ROBOTS[name]
    return {'robot_description': urdf, 'loops.measured_joints': measured,
            **({'loops.output_joints': output_joints} if outputs else {})}


@pytest.mark.parametrize('name', list(ROBOTS))
def test_the_published_efforts_balance_the_inputs_power(context, nodes, tmp_path, name):
    _, measured, outputs, _, groups = ROBOTS[name]
    fed = motion(name)
    with loop_node(context, nodes, tmp_path, parameters(name)) as node:
        for index, (positions, velocities, efforts) in enumerate(fed):
            send(node, START_NS + index * PERIOD_NS, measured, positions, velocities, efforts)
        # an input without efforts is answered without: the first sample's pose again
        last = START_NS + len(fed) * PERIOD_NS
        node.send(last, measured, fed[0][0], fed[0][1])
        statuses = {group: values(node.status(f'transmission {group}', lambda status: values(
            status)['efforts'].startswith('not published'))) for group in groups}
        assert nodes.interrupt(node.process) == 0
        node.listener.drain()
    answers = {stamp_ns(message): message for message in node.outputs}
    assert sorted(answers) == [START_NS + index * PERIOD_NS for index in range(len(fed) + 1)]
    assert list(answers.pop(last).effort) == []
    for index, (_, velocities, efforts) in enumerate(fed):
        message = answers[START_NS + index * PERIOD_NS]
        assert len(message.effort) == len(message.name)
        published = dict(zip(message.name, zip(message.velocity, message.effort)))
        assert all(effort == 0.0 for joint, (_, effort) in published.items()
                   if joint not in outputs)
        actuator_power = math.fsum(t * v for t, v in zip(efforts, velocities))
        output_power = math.fsum(published[joint][0] * published[joint][1]
                                 for joint in outputs)
        scale = math.fsum(abs(t * v) for t, v in zip(efforts, velocities))
        assert abs(actuator_power - output_power) <= 1e3 * EPSILON * scale
        assert all(published[joint][1] != 0.0 for joint in outputs)
    first = answers[START_NS]
    published = dict(zip(first.name, first.effort))
    for group, status in statuses.items():
        actuators, group_outputs = groups[group]
        assert (status['actuators'], status['output joints']) == (
            ', '.join(actuators), ', '.join(group_outputs))
        assert status['efforts withheld (samples)'] == '0'
        # M at the last sample, which had no efforts (the positions suffice), the first's pose:
        # there τ_o = Mᵀ·τ_m (six digits shown)
        rows = [[float(value) for value in row.split(': ')[1].split(', ')]
                for row in status['d(actuators)/d(outputs)'].split('; ')]
        given = [fed[0][2][measured.index(actuator)] for actuator in actuators]
        for column, output in enumerate(group_outputs):
            expected = math.fsum(row[column] * effort for row, effort in zip(rows, given))
            assert published[output] == pytest.approx(expected, rel=1e-5)
        assert status['mechanical advantage'].startswith(
            f'd({actuators[0]})/d({group_outputs[0]}) = ' if len(actuators) == 1
            else 'singular values of d(actuators)/d(outputs) ')
    (bag,) = (tmp_path / 'bags').iterdir()
    assert_the_bag_holds_the_efforts_in_and_out(bag, node, fed)


def assert_the_bag_holds_the_efforts_in_and_out(bag: Path, node: LoopNode,
                                                fed: list[tuple[list[float], ...]]) -> None:
    """Check that the bag's input carries the efforts sent, its joint_states those published."""
    recorded: dict[str, list] = {'/measured_joint_states': [], '/joint_states': []}
    with Reader(bag) as reader:
        for connection, _, raw in reader.messages():
            if connection.topic in recorded:
                recorded[connection.topic].append(
                    TYPESTORE.deserialize_cdr(raw, connection.msgtype))
    inputs = recorded['/measured_joint_states']
    assert [list(message.effort) for message in inputs] == [
        efforts for _, _, efforts in fed] + [[]]
    assert [list(message.effort) for message in recorded['/joint_states']] == [
        list(message.effort) for message in node.outputs]


def test_without_the_parameter_no_effort_is_published(context, nodes, tmp_path):
    _, measured, _, _, _ = ROBOTS['ankle']
    (positions, velocities, efforts), *_ = motion('ankle')
    with loop_node(context, nodes, tmp_path, {**parameters('ankle', outputs=False),
                                              'log.enabled': False}) as node:
        send(node, START_NS, measured, positions, velocities, efforts)
        node.status('robot loops', lambda status: values(status).get('valid samples') == '1')
        assert nodes.interrupt(node.process) == 0
        node.listener.drain()
    (message,) = node.outputs
    assert list(message.effort) == []
    tasks = {status.name for array in node.listener.received['/diagnostics']
             for status in array.status}
    assert not [task for task in tasks if 'transmission' in task]


def test_output_joints_that_are_not_a_groups_end_the_start_with_one_line(nodes, tmp_path):
    status, output = nodes.run(
        {'source': 'measured', 'loops': 'robot_description', **parameters('ankle'),
         'loops.output_joints': ['ankle_pitch', 'motor_left'],
         'log.folder': str(tmp_path / 'bags')}, tmp_path / 'node.log')
    assert status == 2, output
    lines = [line for line in output.splitlines() if line.startswith('linkage_node: ')]
    assert lines == [
        'linkage_node: invalid parameter loops.output_joints: group ball_left+ball_right: output '
        "joints ['ankle_pitch', 'motor_left']: ['motor_left'] are measured; an output joint is "
        "one the actuators ['motor_left', 'motor_right'] move"]
    assert not (tmp_path / 'bags').exists()


def test_a_description_on_the_topic_with_bad_output_joints_is_an_error(
        context, nodes, tmp_path):
    """The node keeps running, its status ERROR naming the group, as for loops not closing."""
    with loop_node(context, nodes, tmp_path, {
            'loops.measured_joints': ['motor_left', 'motor_right'],
            'loops.output_joints': ['ankle_pitch'], 'log.enabled': False}) as node:
        node.description.publish(String(data=ANKLE))
        error = node.status('robot loops', lambda status: status.level == bytes([2]))
        assert error.message == (
            'cannot close the loops of the robot description on /robot_description: '
            "loops.output_joints: group ball_left+ball_right: output joints ['ankle_pitch']: 1 "
            'joints for 2 degrees of freedom that move it (as many as its actuators '
            "['motor_left', 'motor_right'])")
        assert node.process.poll() is None


def documented_section(title: str) -> str:
    """Return a section of docs/following_loops.md, from its heading to the next one."""
    text = (REPOSITORY / 'docs' / 'following_loops.md').read_text(encoding='utf-8')
    start = text.index(f'### {title}\n')
    return text[start:text.index('\n##', start + 4)]


def documented_sample(section: str) -> tuple[list[str], list[float], list[float], list[float]]:
    """Return the names, positions, velocities and efforts of a section's JointState pub."""
    published = re.search(r'"\{name: \[(.*?)\], position: \[(.*?)\], velocity: \[(.*?)\], '
                          r'effort: \[(.*?)\]\}"', section)
    names = [name.strip() for name in published.group(1).split(',')]
    positions, velocities, efforts = ([float(value) for value in published.group(k).split(',')]
                                      for k in (2, 3, 4))
    return names, positions, velocities, efforts


@pytest.mark.parametrize(('title', 'name'), [
    ('The excavator: cylinder forces and a boom trajectory', 'excavator'),
    ("The humanoid ankle's torques", 'ankle')])
def test_the_documented_efforts_are_what_the_node_publishes(context, nodes, tmp_path, title,
                                                            name):
    """The document's sample with efforts in, the efforts of its echo out."""
    section = documented_section(title)
    names, positions, velocities, efforts = documented_sample(section)
    echo = yaml.safe_load(re.search(r'```text\n(.*?)```', section, re.DOTALL).group(1))
    urdf, measured, outputs, _, _ = ROBOTS[name]
    assert names == measured
    with loop_node(context, nodes, tmp_path, {**parameters(name), 'log.enabled': False}) as node:
        send(node, START_NS, names, positions, velocities, efforts)
        group = f'transmission {next(iter(ROBOTS[name][4]))}'
        status = values(node.status(group, lambda status: values(status)[
            'mechanical advantage'] != 'not followed yet'))
        assert nodes.interrupt(node.process) == 0
        node.listener.drain()
    (message,) = node.outputs
    if 'name' in echo:
        assert list(message.name) == echo['name']
    assert list(message.effort) == pytest.approx(echo['effort'], rel=1e-12, abs=1e-12)
    if name == 'excavator':
        assert (f'`mechanical advantage: {status["mechanical advantage"]}`'
                in ' '.join(section.split()))
