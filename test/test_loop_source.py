# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
ros.loop_source's source, hosted by test_sources' fake host: ~/pause, ~/resume, ~/reset, timeout.

What crosses DDS is test_robot_loops.py's; here the order of services and messages is the
test's own, so that a paused message is known to have come while paused.
"""

from __future__ import annotations

from typing import Any

from linkage_kinematics.loops.intake import Estimate
from linkage_kinematics.ros.loop_source import ClosedRobot, RobotLoopsSubscription, TreePositions
from linkage_kinematics.run.control import RunState
from linkage_kinematics.run.diagnostics import Level, StatusInputs
from loop_robots import ROBOTS
import pytest
from rclpy.serialization import serialize_message
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from test_sources import configuration, FakeHost, FakeLogger, START_NS
from urdf_parser_py import urdf as urdf_parser

KNEE = ROBOTS['four_bar_knee'].urdf()
# the parallelogram's coupler joint also mimics the crank
MIMIC = ROBOTS['parallelogram'].urdf().replace(
    '<axis xyz="0.0 0.0 -1.0"/>',
    '<axis xyz="0.0 0.0 -1.0"/><mimic joint="crank_joint" multiplier="1.0"/>', 1)
PERIOD_NS = 10_000_000


class LoopsLogger(FakeLogger):
    def warning(self, text: str) -> None:
        self._record.append(('log warning', text))


class LoopsHost(FakeHost):
    """The fake host, with a logger that also warns."""

    def __init__(self, **overrides: Any) -> None:
        super().__init__(configuration(**{'source': 'measured', 'loops': 'robot_description',
                                          **overrides}))
        self._logger = LoopsLogger(self.record)


class FakeOutputs:
    """Records what the source publishes and logs."""

    input_topic = '/measured_joint_states'
    description_topic = '/robot_description'

    def __init__(self) -> None:
        self.joint_states: list[tuple] = []
        self.logged: list[str] = []

    def publish_joint_states(self, names, positions, velocities, stamp_ns, efforts=()) -> None:
        self.joint_states.append((stamp_ns, dict(zip(names, positions))))

    def record_input(self, data: bytes, stamp_ns: int) -> None:
        self.logged.append('input')

    def record_robot(self, urdf, closures, transforms, stamp_ns) -> None:
        self.logged.append('robot')

    def record_tf(self, positions, stamp_ns) -> None:
        self.logged.append('tf')


def hosted(from_parameter: bool = True
           ) -> tuple[LoopsHost, FakeOutputs, RobotLoopsSubscription]:
    host = LoopsHost(**({'robot_description': KNEE} if from_parameter else {}))
    outputs = FakeOutputs()
    robot = ClosedRobot(KNEE, host.config) if from_parameter else None
    source = RobotLoopsSubscription(host, outputs, robot)
    source.start()
    return host, outputs, source


def send(host: LoopsHost, stamp: int, angle: float) -> None:
    message = JointState(name=['knee_front'], position=[angle])
    message.header.stamp.sec, message.header.stamp.nanosec = divmod(stamp, 1_000_000_000)
    host.subscriptions['measured_joint_states'](serialize_message(message))


def node_status(host: LoopsHost, source: RobotLoopsSubscription) -> Any:
    inputs = StatusInputs(config=host.config, run_state=host.control.state, state=None,
                          activity=host.activity, achieved_rate=None, missed_deadlines=0,
                          log_file=None, log_size=None, now_ns=host.clock_ns)
    return source.statuses(inputs)[0]


def test_pause_ignores_the_input_and_resume_follows_again_afresh() -> None:
    host, outputs, source = hosted()
    send(host, START_NS, 0.1)
    assert source.pause().success
    assert host.control.state is RunState.PAUSED
    send(host, START_NS + PERIOD_NS, 0.2)  # ignored, not counted
    assert [stamp for stamp, _ in outputs.joint_states] == [START_NS]
    assert not source.pause().success
    assert source.resume().success
    send(host, START_NS + 2 * PERIOD_NS, 0.3)
    assert [stamp for stamp, _ in outputs.joint_states] == [START_NS, START_NS + 2 * PERIOD_NS]
    status = node_status(host, source)
    assert (status.values['valid samples'], status.values['dropped samples']) == ('2', '0')
    # afresh: the first sample after ~/resume has no previous one to difference
    assert 'estimated (0: first sample without velocity)' in status.values['estimated']


def test_reset_starts_afresh_and_stale_data_is_an_error() -> None:
    host, outputs, source = hosted()
    send(host, START_NS, 0.1)
    send(host, START_NS + PERIOD_NS, 0.2)
    assert 'backward difference' in node_status(host, source).values['estimated']
    assert source.reset().success
    send(host, START_NS + 2 * PERIOD_NS, 0.25)
    assert 'first sample' in node_status(host, source).values['estimated']
    assert source.stale is False
    host.clock_ns += round(2e9 * host.config.measured.timeout)
    (freshness,) = host.timers
    freshness.callback()
    assert source.stale
    status = node_status(host, source)
    assert status.level is Level.ERROR
    assert status.message.startswith('no valid measured sample for')
    send(host, START_NS + 3 * PERIOD_NS, 0.3)
    assert not source.stale
    assert node_status(host, source).level is Level.OK
    assert Estimate.FIRST_SAMPLE.value in node_status(host, source).values['estimated']


def test_descriptions_from_the_topic_are_read_afresh_and_bad_ones_reported() -> None:
    host, outputs, source = hosted(from_parameter=False)
    send(host, START_NS, 0.1)
    assert outputs.joint_states == []
    assert host.activity == 'waiting for the robot description on topic /robot_description'
    status = node_status(host, source)
    assert status.message == 'dropped 1 message before the robot description was closed'
    assert status.values['dropped before the robot description was closed'] == '1'
    assert node_status(host, source).message == host.activity  # the drop was reported once
    host.subscriptions['robot_description'](String(data=KNEE))
    send(host, START_NS + PERIOD_NS, 0.1)
    assert len(outputs.joint_states) == 1
    plain = '<robot name="r"><link name="a"/></robot>'
    host.subscriptions['robot_description'](String(data=plain))
    status = node_status(host, source)
    assert status.level is Level.ERROR
    assert status.message == ('cannot close the loops of the robot description on '
                              "/robot_description: robot 'r' has no <constraint> loop to close")
    assert ('log error', status.message) in host.record
    send(host, START_NS + 2 * PERIOD_NS, 0.15)  # the knee is still followed
    assert len(outputs.joint_states) == 2
    host.subscriptions['robot_description'](String(data=KNEE))
    assert node_status(host, source).level is Level.OK
    assert outputs.logged.count('robot') == 2


def test_malformed_bytes_are_dropped_counted_and_not_logged() -> None:
    host, outputs, source = hosted()
    message = JointState(name=['knee_front'], position=[0.1])
    data = serialize_message(message)
    for malformed in (data[:20], b'\x00\x02' + data[2:], b''):
        host.subscriptions['measured_joint_states'](malformed)
    assert (outputs.joint_states, outputs.logged) == ([], ['robot'])
    status = node_status(host, source)
    assert status.level is Level.WARN
    assert status.message == 'dropped 3 messages whose bytes are not a well-formed JointState'
    assert status.values['dropped whose bytes are not a well-formed JointState'] == '3'
    send(host, START_NS, 0.1)  # the next good message is followed
    assert [stamp for stamp, _ in outputs.joint_states] == [START_NS]


def test_a_passive_joint_that_also_mimics_is_warned_about_once_planned() -> None:
    host = LoopsHost(robot_description=MIMIC)
    source = RobotLoopsSubscription(host, FakeOutputs(), ClosedRobot(MIMIC, host.config))
    source.start()
    message = JointState(name=['crank_joint'], position=[0.1])
    host.subscriptions['measured_joint_states'](serialize_message(message))
    assert ('log warning', "joint 'coupler_joint' (constraint 'follower_pin') is solved by its "
            "loop but also mimics 'crank_joint': robot_state_publisher would pose it from two "
            'sources') in host.record


def test_tree_positions_are_the_mapping_robot_state_publisher_would_get() -> None:
    """
    Loop joints as solved, others as last heard (finite), 0 before; names found once per list.

    Each sample's positions equal the mapping the source built per sample before: every tree
    joint from the sample's joints, else the input's last finite value, else 0.
    """
    tree_joints = ('hip', 'knee_front', 'knee_back', 'ankle', 'wrist')
    heard = {'wrist': 0.5}  # heard under an earlier description
    tree = TreePositions(tree_joints, frozenset({'knee_front', 'knee_back'}), heard)
    names = ['knee_front', 'hip', 'other']
    messages = [
        (names, [0.1, 0.2, 9.0], {'knee_front': 0.1, 'knee_back': 0.3}),
        (names, [0.15, float('nan'), 9.5], {'knee_front': 0.15, 'knee_back': 0.35}),
        (['ankle', 'knee_front', 'hip'], [-0.4, 0.2], {'knee_front': 0.2, 'knee_back': 0.4}),
        (names, [0.25], {'knee_front': 0.25, 'knee_back': 0.45}),
    ]
    expected_heard: dict[str, float] = {'wrist': 0.5}
    for names_given, positions, joints in messages:
        tree.note_input(names_given, positions)
        for name, position in zip(names_given, positions):
            if name not in ('knee_front', 'knee_back') and position == position:
                expected_heard[name] = position
        assert tree.at_sample(joints) == [
            joints.get(name, expected_heard.get(name, 0.0)) for name in tree_joints]
    assert heard == expected_heard == {'wrist': 0.5, 'hip': 0.2, 'other': 9.5, 'ankle': -0.4}
    assert tree.positions == [0.2, 0.25, 0.45, -0.4, 0.5]


def test_a_description_is_parsed_once_for_its_loops_and_its_tf(
        monkeypatch: pytest.MonkeyPatch) -> None:
    parses = []
    parse = urdf_parser.Robot.from_xml
    monkeypatch.setattr(urdf_parser.Robot, 'from_xml',
                        lambda *arguments: parses.append(arguments) or parse(*arguments))
    robot = ClosedRobot(KNEE, LoopsHost(robot_description=KNEE).config)
    assert robot.follower.loops.robot_name == 'four_bar_knee'
    assert robot.tree_joints == ('knee_front', 'knee_rear', 'knee_shank')
    assert len(parses) == 1
