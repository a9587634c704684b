# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
linkage_node closing every loop of a robot description (``loops:=robot_description``), over DDS.

A real node is fed measured joints from this process; its ``joint_states`` are checked against
the independent mpmath reference (test/loop_reference.py) to 1e-12 and closed by urchin's
forward kinematics within 1e-12 m. The description comes from the topic, published transient
local as robot_state_publisher does, or from the ``robot_description`` parameter.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from contextlib import contextmanager
import math
from pathlib import Path
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray
import loop_reference
from loop_robots import ROBOTS
from mpmath import mpf
from node_process import Listener, NodeProcesses, PROCESS_TIMEOUT, ros_context, stamp_ns
import numpy as np
import pytest
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosbags.rosbag2 import Reader
from rosbags.typesys import get_typestore, Stores
from sensor_msgs.msg import JointState
from std_msgs.msg import String

TOLERANCE = 1e-12
TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
DESCRIPTION_QOS = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL,
                             reliability=ReliabilityPolicy.RELIABLE)
START_NS = 1_000_000_000
PERIOD_NS = 10_000_000
KNEE = ROBOTS['four_bar_knee']
EXCAVATOR = ROBOTS['excavator']
# A joint outside the loops, which the input carries, and a fixed one below it: the bag's /tf
# poses the whole robot.
ANKLE = 0.5
FOOT = ('  <link name="foot"/>\n  <link name="sole"/>\n'
        '  <joint name="ankle" type="revolute"><parent link="shank"/><child link="foot"/>'
        '<origin xyz="0.01 -0.1 0.0" rpy="0.0 0.0 0.3"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n'
        '  <joint name="sole_joint" type="fixed"><parent link="foot"/><child link="sole"/>'
        '<origin xyz="0.05 0.0 0.0" rpy="0.0 0.0 0.0"/></joint>\n</robot>')


@pytest.fixture(scope='module')
def context(domain_id):
    with ros_context(domain_id) as ros:
        yield ros


class LoopNode:
    """A running loops node, and this process's publishers and subscriptions beside it."""

    def __init__(self, listener: Listener, process: Any, log: Path) -> None:
        self.listener = listener
        self.process = process
        self.log = log
        node = listener.node
        self.inputs = node.create_publisher(JointState, '/measured_joint_states',
                                            QoSProfile(depth=1000))
        self.description = node.create_publisher(String, '/robot_description', DESCRIPTION_QOS)
        assert listener.spin_until(lambda: self.inputs.get_subscription_count() > 0), (
            log.read_text())

    @property
    def outputs(self) -> list[JointState]:
        return self.listener.received['/joint_states']

    def send(self, stamp: int, names: Sequence[str], positions: Sequence[float],
             velocities: Sequence[float] = (), answered: bool = True) -> None:
        """Publish one input; wait for the joint state stamped like it if it is ``answered``."""
        message = JointState(name=list(names), position=[float(p) for p in positions],
                             velocity=[float(v) for v in velocities])
        message.header.stamp.sec, message.header.stamp.nanosec = divmod(stamp, 1_000_000_000)
        self.inputs.publish(message)
        if answered:
            assert self.listener.spin_until(
                lambda: any(stamp_ns(output) == stamp for output in self.outputs)), (
                f'no joint state stamped {stamp}: {self.log.read_text()}')

    def status(self, task: str, done: Any = lambda status: True) -> Any:
        """Wait for a status named '<node>: <task>' for which ``done(status)``; return it."""
        found = []

        def seen() -> bool:
            for array in self.listener.received['/diagnostics']:
                for status in array.status:
                    if status.name == f'linkage_node: {task}' and done(status):
                        found.append(status)
                        return True
            return False

        assert self.listener.spin_until(seen), (task, self.log.read_text())
        return found[0]


def values(status: Any) -> dict[str, str]:
    return {item.key: item.value for item in status.values}


@contextmanager
def loop_node(context, nodes: NodeProcesses, tmp_path: Path,
              parameters: dict[str, Any] | None = None,
              ros_arguments: Sequence[str] = ()) -> Iterator[LoopNode]:
    """Start a loops node (its bag under tmp_path/bags) and a listener beside it."""
    listener = Listener('loops_listener', context)
    listener.subscribe('/joint_states', JointState)
    listener.subscribe('/diagnostics', DiagnosticArray)
    log = tmp_path / 'node.log'
    process = nodes.start({'source': 'measured', 'loops': 'robot_description',
                           'measured.timeout': PROCESS_TIMEOUT,
                           'log.folder': str(tmp_path / 'bags'), **(parameters or {})}, log,
                          ros_arguments=ros_arguments)
    try:
        yield LoopNode(listener, process, log)
    finally:
        listener.destroy()


def sweep(robot_name: str, count: int) -> list[dict[str, float]]:
    """Return the measured joints along a sweep out and back over their ranges."""
    ranges = ROBOTS[robot_name].measured_ranges
    fractions = list(np.linspace(0.0, 1.0, count)) + list(np.linspace(1.0, 0.0, count))[1:]
    return [{name: low + (high - low) * fraction for name, (low, high) in ranges.items()}
            for fraction in fractions]


Fed = list[tuple[int, dict[str, float], dict[str, float]]]


def follow_sweep(node: LoopNode, robot_name: str, count: int,
                 rates: dict[str, float] | None) -> Fed:
    """
    Feed a sweep; return each input's stamp, measured positions and velocities.

    ``rates`` None: no velocities in the input, so the node estimates them: the backward
    difference over the stamps, 0 at the first sample.
    """
    fed = []
    previous = None
    for index, measured in enumerate(sweep(robot_name, count)):
        stamp = START_NS + index * PERIOD_NS
        names = list(measured)
        if rates is None:
            velocities = {name: 0.0 if previous is None
                          else (measured[name] - previous[name]) / (PERIOD_NS * 1e-9)
                          for name in names}
            node.send(stamp, ['ankle', *names], [ANKLE, *measured.values()])
        else:
            velocities = rates
            node.send(stamp, ['ankle', *names], [ANKLE, *measured.values()],
                      [0.0, *(rates[name] for name in names)])
        fed.append((stamp, measured, velocities))
        previous = measured
    return fed


def assert_matches_the_reference(node: LoopNode, urdf: str, passive: Sequence[str],
                                 fed: Fed) -> None:
    """Positions and velocities to 1e-12 of the reference; urchin closes every constraint."""
    outputs = {stamp_ns(message): message for message in node.outputs}
    assert sorted(outputs) == [stamp for stamp, _, _ in fed]  # one per input, at its stamp
    guess: dict[str, mpf] = {}
    for stamp, measured, rates in fed:
        message = outputs[stamp]
        assert sorted(message.name) == sorted(passive)  # only the passive loop joints
        published = dict(zip(message.name, message.position))
        published_rates = dict(zip(message.name, message.velocity))
        exact = loop_reference.solve(urdf, measured, guess)
        exact_rates = loop_reference.velocities(urdf, {**measured, **exact}, rates)
        for name in passive:
            assert abs(published[name] - float(exact[name])) < TOLERANCE, (name, measured)
            scale = max(1.0, max(abs(rate) for rate in rates.values()))
            assert abs(published_rates[name] - float(exact_rates[name])) < TOLERANCE * scale, (
                name, measured)
        gaps = loop_reference.closure_residuals(urdf, {**measured, **published})
        assert max(gaps.values()) < TOLERANCE, gaps
        guess = exact


def test_the_knee_from_the_topic_matches_the_reference_and_is_logged(context, nodes, tmp_path):
    """The knee's description on the topic; measured velocities; a jump dropped; the bag."""
    urdf = KNEE.urdf().replace('</robot>', FOOT)
    with loop_node(context, nodes, tmp_path) as node:
        node.status('robot loops', lambda status: 'waiting for the robot description' in (
            status.message))
        node.description.publish(String(data=urdf))
        node.status('robot loops', lambda status: status.hardware_id == 'robot four_bar_knee')
        fed = follow_sweep(node, 'four_bar_knee', 9, {'knee_front': 0.7})
        last = fed[-1][0]
        # A revolute measured joint further than measured.max_jump (π/2) from the last: dropped.
        node.send(last + PERIOD_NS, ['knee_front'], [2.0], answered=False)
        loop = node.status('loop knee_rear_pin', lambda status: values(status).get(
            'dropped jumping further than measured.max_jump') == '1')
        assert values(loop)['known joint'] == 'knee_front (measured)'
        assert values(loop)['estimated'] == 'none'
        assert values(loop)['kind'] == 'four-bar'
        # The knee's front link turns fully: it has no dead point.
        assert values(loop)['dead point distance'] == 'none (no dead point)'
        assert nodes.interrupt(node.process) == 0
        node.listener.drain()
    assert_matches_the_reference(node, urdf, KNEE.passive_joints, fed)
    (bag,) = (tmp_path / 'bags').iterdir()
    assert_bag_holds_the_whole_robot(bag, urdf, fed, node.outputs)


def assert_bag_holds_the_whole_robot(bag: Path, urdf: str, fed: list, outputs: list) -> None:
    """Check the bag: inputs, completed joint states, description, and /tf posing every link."""
    recorded: dict[str, list[tuple[int, Any]]] = {}
    with Reader(bag) as reader:
        for connection, timestamp, raw in reader.messages():
            recorded.setdefault(connection.topic, []).append(
                (timestamp, TYPESTORE.deserialize_cdr(raw, connection.msgtype)))
    (description,) = recorded['/robot_description']
    assert description[1].data == urdf
    inputs = [stamp_ns(message) for _, message in recorded['/measured_joint_states']]
    assert inputs[:len(fed)] == [stamp for stamp, _, _ in fed]
    assert len(inputs) == len(fed) + 1  # and the dropped jump
    assert [stamp_ns(message) for _, message in recorded['/joint_states']] == [
        stamp_ns(message) for message in outputs]
    (static,) = recorded['/tf_static']
    tf = recorded['/tf']
    assert [time for time, _ in tf] == [stamp for stamp, _, _ in fed]
    # Compose /tf_static and the last /tf from the root: every link where urchin puts it.
    stamp, measured, _ = fed[-1]
    published = {stamp_ns(message): dict(zip(message.name, message.position))
                 for message in outputs}[stamp]
    expected = loop_reference.link_poses(urdf, {**measured, **published, 'ankle': ANKLE})
    assert {'foot', 'sole'} <= set(expected)
    transforms = {item.child_frame_id: item
                  for item in static[1].transforms + tf[-1][1].transforms}
    poses = {}

    def pose(link: str) -> np.ndarray:
        if link not in transforms:
            return np.eye(4)  # the root
        if link not in poses:
            item = transforms[link]
            poses[link] = pose(item.header.frame_id) @ matrix(item.transform)
        return poses[link]

    for link, world in expected.items():
        assert np.max(np.abs(pose(link) - world)) < TOLERANCE, link


def matrix(transform: Any) -> np.ndarray:
    """Return a geometry_msgs/Transform as a 4×4 matrix."""
    x, y, z, w = (transform.rotation.x, transform.rotation.y, transform.rotation.z,
                  transform.rotation.w)
    result = np.eye(4)
    result[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                      [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                      [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    result[:3, 3] = [transform.translation.x, transform.translation.y, transform.translation.z]
    return result


def test_the_excavator_from_the_parameter_with_estimated_velocities(context, nodes, tmp_path):
    """Three cylinders measured without velocities: every chained loop closed, rates estimated."""
    urdf = EXCAVATOR.urdf()
    with loop_node(context, nodes, tmp_path,
                   {'robot_description': urdf, 'log.enabled': False,
                    'loops.measured_joints': list(EXCAVATOR.measured_joints)}) as node:
        fed = follow_sweep(node, 'excavator', 5, None)
        bucket = node.status('loop bucket_pin', lambda status: values(status).get(
            'estimated', 'none') != 'none')
        assert values(bucket)['known joint'] == (
            'bucket_link_joint (solved by loop bucket_cylinder_pin)')
        boom = values(node.status('loop boom_cylinder_pin', lambda status: values(status)[
            'dead point distance'].endswith(' m')))
        assert boom['kind'] == 'one prismatic joint (boom_cylinder)'
        assert float(boom['dead point distance'].removesuffix(' m')) > 0.0
        overall = node.status('robot loops', lambda status: values(status).get(
            'valid samples') == str(len(fed)))
        assert values(overall)['description from'] == 'parameter robot_description'
        assert 'boom_cylinder velocity (estimated (backward difference' in (
            values(overall)['estimated'])
        assert nodes.interrupt(node.process) == 0
        node.listener.drain()
    assert_matches_the_reference(node, urdf, EXCAVATOR.passive_joints, fed)


@pytest.mark.parametrize('robot_name', ['slider_crank', 'balancer', 'parallelogram'])
def test_the_other_test_robots_close_through_the_node(context, nodes, tmp_path, robot_name):
    """A slider-crank, a balancer cylinder and a parallelogram: each matches the reference."""
    robot = ROBOTS[robot_name]
    urdf = robot.urdf()
    with loop_node(context, nodes, tmp_path,
                   {'robot_description': urdf, 'log.enabled': False}) as node:
        fed = follow_sweep(node, robot_name, 7, dict.fromkeys(robot.measured_joints, 0.4))
        node.status('robot loops', lambda status: values(status).get(
            'valid samples') == str(len(fed)))
        assert nodes.interrupt(node.process) == 0
        node.listener.drain()
    assert_matches_the_reference(node, urdf, robot.passive_joints, fed)


def test_bad_samples_are_dropped_and_counted_per_loop(context, nodes, tmp_path):
    """Missing, NaN, old, unreachable: dropped, counted for the loops they concern, no NaN out."""
    names = list(EXCAVATOR.measured_joints)  # boom, stick, bucket cylinders
    with loop_node(context, nodes, tmp_path, {'log.enabled': False}) as node:
        # Before any description: dropped and counted as such.
        node.send(START_NS, names, [0.0, 0.0, 0.0], answered=False)
        node.status('robot loops', lambda status: values(status).get(
            'dropped before the robot description was closed') == '1')
        node.description.publish(String(data=EXCAVATOR.urdf()))
        node.status('robot loops', lambda status: status.hardware_id == 'robot excavator')
        node.send(START_NS + 1 * PERIOD_NS, names, [0.0, 0.0, 0.0])
        node.send(START_NS + 2 * PERIOD_NS, names[:2], [0.01, 0.0], answered=False)
        node.send(START_NS + 3 * PERIOD_NS, names, [0.01, math.nan, 0.0], answered=False)
        node.send(START_NS + 1 * PERIOD_NS, names, [0.01, 0.0, 0.0], answered=False)
        node.send(START_NS + 4 * PERIOD_NS, names, [5.0, 0.0, 0.0], answered=False)
        node.send(START_NS + 5 * PERIOD_NS, names, [0.01, 0.0, 0.0])
        overall = node.status('robot loops', lambda status: values(status).get(
            'dropped samples') == '5')
        node_values = values(overall)
        for reason in ('without every measured joint', 'with a NaN or infinite position or '
                       'velocity', 'with a stamp not newer than the last one used',
                       'at joint values a loop cannot reach (or at a dead point)',
                       'before the robot description was closed'):
            assert node_values[f'dropped {reason}'] == '1', reason
        per_loop = {constraint: values(node.status(f'loop {constraint}', lambda status: (
            values(status)['dropped samples'] == str(count)))) for constraint, count in
            (('boom_cylinder_pin', 1), ('stick_cylinder_pin', 1), ('bucket_cylinder_pin', 1),
             ('bucket_pin', 0))}
        assert per_loop['boom_cylinder_pin'][
            'dropped at joint values a loop cannot reach (or at a dead point)'] == '1'
        assert per_loop['stick_cylinder_pin'][
            'dropped with a NaN or infinite position or velocity'] == '1'
        assert per_loop['bucket_cylinder_pin']['dropped without every measured joint'] == '1'
        assert node.process.poll() is None
    assert [stamp_ns(message) for message in node.outputs] == [
        START_NS + PERIOD_NS, START_NS + 5 * PERIOD_NS]
    for message in node.outputs:
        assert all(math.isfinite(value) for value in [*message.position, *message.velocity])


def test_a_bad_description_on_the_topic_is_reported_and_a_good_one_followed(
        context, nodes, tmp_path):
    """The node keeps running with an ERROR status naming the problem, then follows the next."""
    broken = KNEE.urdf().replace('type="revolute">\n    <parent link="rear_link"',
                                 'type="prismatic">\n    <parent link="rear_link"')
    assert broken != KNEE.urdf()
    with loop_node(context, nodes, tmp_path, {'log.enabled': False}) as node:
        node.description.publish(String(data=broken))
        error = node.status('robot loops', lambda status: status.level == bytes([2]))
        assert 'cannot close the loops of the robot description on /robot_description' in (
            error.message)
        assert 'knee_rear_pin' in error.message
        assert node.process.poll() is None
        node.description.publish(String(data=KNEE.urdf()))
        node.status('robot loops', lambda status: status.hardware_id == 'robot four_bar_knee'
                    and status.level == bytes([0]))
        node.send(START_NS, ['knee_front'], [0.1], [0.0])
        (message,) = node.outputs
        assert sorted(message.name) == sorted(KNEE.passive_joints)
    assert 'cannot close the loops' in node.log.read_text()


def test_a_bad_description_parameter_ends_the_start_with_one_line(nodes, tmp_path):
    """Exit 2 with one line naming the problem, before the bag folder is made."""
    status, output = nodes.run(
        {'source': 'measured', 'loops': 'robot_description',
         'robot_description': '<robot name="plain"><link name="a"/></robot>',
         'log.folder': str(tmp_path / 'bags')}, tmp_path / 'node.log')
    assert status == 2, output
    lines = [line for line in output.splitlines() if line.startswith('linkage_node: ')]
    assert lines == ['linkage_node: cannot close the loops of parameter robot_description: '
                     "robot 'plain' has no <constraint> loop to close"]
    assert not (tmp_path / 'bags').exists()


def test_loops_from_the_description_need_the_measured_source(nodes, tmp_path):
    status, output = nodes.run({'loops': 'robot_description', 'log.enabled': False},
                               tmp_path / 'node.log')
    assert status == 2, output
    assert ('linkage_node: invalid parameter loops: robot_description closes the loops of '
            'measured joints: it needs source measured, got source drive_law') in output
