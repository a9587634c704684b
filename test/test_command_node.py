# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
linkage_command_node over DDS: commands in the output joints relayed to the actuators.

Real relays run in their own processes, fed from this process as a planner or a controller
would feed a joint_trajectory_controller or a forward_command_controller, their outputs heard
as the actuators' controllers would hear them:

* the humanoid ankle (a ``toe`` joint outside its loops added): a JointTrajectory with
  positions, velocities, accelerations and efforts and a stream of Float64MultiArray position
  commands, relayed with the ankle's motors within 1e-12 of the 50-digit reference
  (test/closure_reference.py) and bit for bit the package's own conversion in-process, the toe
  passed through, ``time_from_start`` and the header kept, the forward commands in the
  controller's declared order; then refusals, one of each reason (NaN, joints the robot does
  not have or a loop's inner joint, unequal array lengths, a motor beyond its URDF limit, bytes
  that are no such message): each refused whole, nothing sent for it (the next good command's
  answer is the next output), a log line naming it, counted by reason in /diagnostics, the node
  still running; its bag holds every input and output;
* the lab knee (the rocker commanded): a trajectory within 1e-12 of test/loop_reference.py, a
  knee angle no assembly reaches refused; with the crank commanded (the rocker measured), a
  command across the rocker's dead point refused as crossing a singular configuration;
* velocity commands to the ankle: refused until a pose is measured on measured_joint_states,
  then the motors' velocities at that pose;
* bad parameters and a description that cannot be relayed: exit 2, one line.
"""

from __future__ import annotations

from collections.abc import Sequence
import math
from pathlib import Path
import re
import struct
import sys
import time
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray
from linkage_kinematics.loops.command import JointPoint
from linkage_kinematics.run.configuration import build_relay_configuration
from linkage_kinematics.run.parameter_specs import relay_parameter_specs
from linkage_kinematics.run.relay import read_relay
from mpmath import mpf
from node_process import Listener, PROCESS_TIMEOUT, ros_context
import pytest
from rclpy.qos import QoSProfile
from rosbags.rosbag2 import Reader
from rosbags.typesys import get_typestore, Stores
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray
from test_command_relay import ANKLE, KNEE
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint
import transmission_robots
from transmission_robots import reference_pose, reference_velocities, relative

TOLERANCE = 1e-12
TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
EXECUTABLE = [sys.executable, '-m', 'linkage_kinematics.ros.command_node']
NODE = '/linkage_command_node'
ANKLE_PARAMETERS = {
    'robot_description': ANKLE, 'loops.measured_joints': ['motor_left', 'motor_right'],
    'loops.output_joints': ['ankle_pitch', 'ankle_roll'],
    'commands.joints': ['ankle_roll', 'toe', 'ankle_pitch'],
    'commands.controller_joints': ['motor_right', 'toe', 'motor_left'],
}
KNEE_PARAMETERS = {'robot_description': KNEE, 'loops.measured_joints': ['knee_motor'],
                   'loops.output_joints': ['knee_output']}
REVERSED_PARAMETERS = {'robot_description': KNEE, 'loops.measured_joints': ['knee_output'],
                       'loops.output_joints': ['knee_motor']}


@pytest.fixture(scope='module')
def context(domain_id):
    with ros_context(domain_id) as ros:
        yield ros


def pure_relay(parameters: dict[str, Any]):
    """Return the relay the node builds from ``parameters``, in this process."""
    values = {spec.name: spec.default for spec in relay_parameter_specs()}
    values.update(parameters)
    return read_relay(values['robot_description'], build_relay_configuration(values))


class RelayNode:
    """A running relay, this process's publishers to it and its outputs heard."""

    def __init__(self, context, nodes, tmp_path: Path, parameters: dict[str, Any],
                 measured: bool = False) -> None:
        self.listener = listener = Listener('relay_listener', context)
        for topic, kind in (('/actuators/joint_trajectory', JointTrajectory),
                            ('/actuators/commands', Float64MultiArray),
                            ('/diagnostics', DiagnosticArray)):
            listener.subscribe(topic, kind)
        self.log = tmp_path / 'relay.log'
        self.bags = tmp_path / 'bags'
        self.process = nodes.start({'log.folder': str(self.bags), **parameters}, self.log,
                                   executable=EXECUTABLE)
        node = listener.node
        qos = QoSProfile(depth=100)
        self.trajectories = node.create_publisher(JointTrajectory, f'{NODE}/joint_trajectory',
                                                  qos)
        self.commands = node.create_publisher(Float64MultiArray, f'{NODE}/commands', qos)
        publishers = [self.trajectories, self.commands]
        if measured:
            self.measured = node.create_publisher(JointState, '/measured_joint_states', qos)
            publishers.append(self.measured)
        # every publisher matched by the relay, and the relay's outputs by the listener, before
        # anything is sent: nothing is lost to discovery
        assert listener.spin_until(lambda: all(
            publisher.get_subscription_count() > 0 for publisher in publishers) and all(
            subscription.get_publisher_count() > 0
            for subscription in node.subscriptions)), self.log.read_text()
        self.sent = {'trajectory': 0, 'commands': 0, 'measured': 0}

    def handshake(self, joints: Sequence[str],
                  command: Sequence[float] | None) -> dict[str, list[Any]]:
        """
        Send an empty trajectory, and ``command`` if given, until the relay answers each.

        The relay's readers are best effort, as the controllers' (command_node): a message sent
        before a reader has matched its writer is lost, and the writer cannot tell. Return the
        answers by kind (each answered message's), which the test's outputs then leave out.
        """
        inputs = [('trajectory', 'joint_trajectory', JointTrajectory(joint_names=list(joints)))]
        if command is not None:
            inputs.append(('commands', 'commands', Float64MultiArray(data=list(command))))
        answers = {}
        for kind, topic, message in inputs:
            for _ in range(round(PROCESS_TIMEOUT / 0.5)):
                self.send(kind, message, answered=False)
                if self.listener.spin_until(lambda: bool(self.outputs(topic)), 0.5):
                    break
            self.listener.spin_until(lambda: False, 0.5)  # a late answer to an earlier one
            answers[kind] = list(self.outputs(topic))
            assert answers[kind], self.log.read_text()
            self.outputs(topic).clear()
        return answers

    def outputs(self, kind: str) -> list[Any]:
        return self.listener.received[f'/actuators/{kind}']

    def send(self, kind: str, message: Any, answered: bool = True) -> Any:
        """Publish one message; return the relay's answer to it (None if not ``answered``)."""
        topic = 'joint_trajectory' if kind == 'trajectory' else kind
        before = len(self.outputs(topic)) if kind != 'measured' else 0
        {'trajectory': self.trajectories, 'commands': self.commands,
         'measured': getattr(self, 'measured', None)}[kind].publish(message)
        self.sent[kind] += 1
        if not answered or kind == 'measured':
            return None
        assert self.listener.spin_until(lambda: len(self.outputs(topic)) > before), (
            self.log.read_text())
        # one answer to one message, and only to this one
        assert len(self.outputs(topic)) == before + 1
        return self.outputs(topic)[-1]

    def status(self, done) -> dict[str, str]:
        """Wait for a status of the relay for which ``done(values)``; return its values."""
        found = []

        def seen() -> bool:
            for array in self.listener.received['/diagnostics']:
                for status in array.status:
                    values = {item.key: item.value for item in status.values}
                    if status.name == 'linkage_command_node: command relay' and done(values):
                        found.append((status, values))
                        return True
            return False

        assert self.listener.spin_until(seen), self.log.read_text()
        return found[0][1]

    def stop(self, nodes) -> None:
        assert nodes.interrupt(self.process) == 0, self.log.read_text()
        self.listener.drain()
        self.listener.destroy()


def trajectory(names: Sequence[str], points: Sequence[JointPoint],
               seconds: float = 0.1) -> JointTrajectory:
    message = JointTrajectory(joint_names=list(names))
    message.header.stamp.sec, message.header.stamp.nanosec = 12, 345
    message.header.frame_id = 'shank'
    for index, point in enumerate(points):
        sec, nanosec = divmod(round((index + 1) * seconds * 1e9), 1_000_000_000)
        message.points.append(JointTrajectoryPoint(
            positions=list(point.positions), velocities=list(point.velocities),
            accelerations=list(point.accelerations), effort=list(point.efforts)))
        message.points[-1].time_from_start.sec = sec
        message.points[-1].time_from_start.nanosec = nanosec
    return message


def points_of(message: Any) -> tuple[JointPoint, ...]:
    return tuple(JointPoint(tuple(p.positions), tuple(p.velocities), tuple(p.accelerations),
                            tuple(p.effort)) for p in message.points)


def ankle_points(count: int) -> list[JointPoint]:
    """Return ankle roll, toe, pitch along a motion: positions to efforts."""
    points = []
    for index in range(count):
        t = 0.1 * index
        points.append(JointPoint(
            (0.1 * math.sin(t), 0.2, 0.2 * math.cos(t)),
            (0.1 * math.cos(t), 0.5, -0.2 * math.sin(t)),
            (-0.1 * math.sin(t), 0.0, -0.2 * math.cos(t)),
            (3.0, 1.0, -2.0)))
    return points


def check_ankle_positions(names: Sequence[str], given: JointPoint, found: JointPoint) -> None:
    """Check the motors: within 1e-12 of the reference at the given ankle roll and pitch."""
    robot = transmission_robots.build('ankle')
    outputs = {'ankle_roll': given.positions[0], 'ankle_pitch': given.positions[2]}
    motors = dict(zip(names, found.positions))
    guess = {name: 0.0 for name in robot.loop_joints()} | motors
    exact = reference_pose(robot, outputs, guess)
    assert max(abs(motors[n] - float(exact[n])) for n in ('motor_left', 'motor_right')) <= (
        TOLERANCE)
    assert motors['toe'] == given.positions[1]


def test_the_ankle_s_commands_are_relayed_its_refusals_refused_whole(context, nodes, tmp_path):
    relay = RelayNode(context, nodes, tmp_path, ANKLE_PARAMETERS)
    own = pure_relay(ANKLE_PARAMETERS)  # the same conversion in this process, in step
    names = ('ankle_roll', 'toe', 'ankle_pitch')
    handshakes = relay.handshake(names, (0.0, 0.0, 0.0))
    for answer in handshakes['commands']:
        assert tuple(answer.data) == own.forward((0.0, 0.0, 0.0), 0)
    answered = {kind: len(answers) for kind, answers in handshakes.items()}
    given = ankle_points(6)
    answer = relay.send('trajectory', trajectory(names, given))
    expected_names, expected = own.trajectory(names, given)
    assert tuple(answer.joint_names) == expected_names == ('toe', 'motor_left', 'motor_right')
    assert points_of(answer) == expected  # bit for bit, all four arrays
    assert (answer.header.stamp.sec, answer.header.stamp.nanosec,
            answer.header.frame_id) == (12, 345, 'shank')
    assert [(p.time_from_start.sec, p.time_from_start.nanosec) for p in answer.points] == [
        (0, 100_000_000 * (index + 1)) for index in range(6)]
    for index in (0, 5):
        check_ankle_positions(answer.joint_names, given[index], expected[index])
    # forward commands: roll, toe, pitch in; motor_right, toe, motor_left out
    for step in range(10):
        values = (0.05 * math.sin(0.4 * step), 0.1 * step, 0.15 * math.cos(0.3 * step))
        answer = relay.send('commands', Float64MultiArray(data=list(values)))
        assert tuple(answer.data) == own.forward(values, 0)
        check_ankle_positions(('motor_right', 'toe', 'motor_left'),
                              JointPoint(values), JointPoint(tuple(answer.data)))
    # refusals: each refused whole, the next good message answered by the next output
    good = Float64MultiArray(data=[0.02, 0.0, 0.1])
    bad = [
        ('commands', Float64MultiArray(data=[0.0, math.nan, 0.1]), 'a value is not finite',
         "joint 'toe': positions nan"),
        ('commands', Float64MultiArray(data=[0.0, 0.1]),
         'its joints or arrays do not fit the robot', '2 values for the 3 joints of '
         'commands.joints'),
        ('commands', Float64MultiArray(data=[0.0, 0.0, 2.0]),
         'an actuator would leave its URDF <limit>', "actuator 'motor_left' at"),
        ('trajectory', trajectory(('ankle_roll', 'heel', 'ankle_pitch'), given[:2]),
         'its joints or arrays do not fit the robot', "joint 'heel' is not a joint of the robot"),
        ('trajectory', trajectory(('ankle_roll', 'motor_left', 'ankle_pitch'), given[:2]),
         'its joints or arrays do not fit the robot', "joint 'motor_left' is solved by group"),
        ('trajectory', trajectory(names, [given[0], JointPoint((0.0, 0.0, 0.0), (1.0,))]),
         'its joints or arrays do not fit the robot', 'point 1: 1 velocities for 3 joints'),
        ('trajectory', trajectory(names, [given[0], JointPoint((0.0, 0.0, 2.0))]),
         'an actuator would leave its URDF <limit>',
         "point 1: group ball_left+ball_right: actuator 'motor_left' at"),
        ('commands', b'\x00\x01\x00\x00' + struct.pack('<I', 1000),
         'its bytes are not such a message', 'Float64MultiArray layout claims 1000 dimensions'),
    ]
    logged_at: dict[tuple[str, str], float] = {}
    for kind, message, reason, detail in bad:
        # a refusal of the input and reason of one within the last second is counted, not
        # logged (RelayRecord): a second apart, each has its line
        time.sleep(max(0.0, logged_at.get((kind, reason), 0.0) + 1.1 - time.monotonic()))
        logged_at[(kind, reason)] = time.monotonic()
        relay.send(kind, message, answered=False)
        own_before = own.forward((0.02, 0.0, 0.1), 0)
        answer = relay.send('commands', good)
        assert tuple(answer.data) == own_before
    # counted by reason, the last one named
    values = relay.status(lambda values: values['refused commands'] == '4'
                          and values['refused trajectories'] == '4')
    assert values['refused: a value is not finite'] == '1'
    assert values['refused: its joints or arrays do not fit the robot'] == '4'
    assert values['refused: an actuator would leave its URDF <limit>'] == '2'
    assert values['refused: its bytes are not such a message'] == '1'
    assert values['relayed trajectories'] == str(1 + answered['trajectory'])
    assert values['relayed trajectory points'] == '6'
    assert values['relayed commands'] == str(10 + len(bad) + answered['commands'])
    assert values['last refusal'].startswith('refused commands: its bytes are not such')
    assert float(values['conversion per command (µs)']) > 0.0
    relay.stop(nodes)
    log = relay.log.read_text()
    for kind, _, reason, detail in bad:
        topic = 'joint_trajectory' if kind == 'trajectory' else kind
        assert re.search(f'refused {topic}: {re.escape(reason)}: .*{re.escape(detail)}', log), (
            kind, reason, log)
    # the bag: every input and every output, the outputs' bytes as heard
    recorded: dict[str, list[Any]] = {}
    (bag,) = relay.bags.iterdir()
    with Reader(bag) as reader:
        for connection, _, raw in reader.messages():
            # the inputs as received: the malformed one too, which no reader can read
            recorded.setdefault(connection.topic, []).append(
                raw if connection.topic.startswith(NODE) else
                TYPESTORE.deserialize_cdr(raw, connection.msgtype))
    assert bytes(recorded[f'{NODE}/commands'][-2]) == bad[-1][1]
    # (the handshake's messages lost before the relay's readers matched are in neither)
    assert len(recorded[f'{NODE}/joint_trajectory']) == 5 + answered['trajectory']
    assert len(recorded[f'{NODE}/commands']) == 10 + 2 * len(bad) - 4 + answered['commands']
    assert len(recorded['/actuators/joint_trajectory']) == 1 + answered['trajectory']
    assert [tuple(m.data) for m in recorded['/actuators/commands']] == [
        tuple(m.data) for m in [*handshakes['commands'], *relay.outputs('commands')]]
    assert len(recorded['/robot_description']) == 1


def test_the_knee_s_trajectory_is_the_reference_s_and_what_it_cannot_reach_is_refused(
        context, nodes, tmp_path):
    relay = RelayNode(context, nodes, tmp_path, KNEE_PARAMETERS)
    own = pure_relay(KNEE_PARAMETERS)
    for _ in relay.handshake(['knee_output'], (0.0,))['commands']:
        own.forward((0.0,), 0)
    given = [JointPoint((0.5 * math.sin(0.2 * index),), (0.3,), (), (2.0,))
             for index in range(8)]
    answer = relay.send('trajectory', trajectory(['knee_output'], given))
    assert tuple(answer.joint_names) == ('knee_motor',)
    robot = transmission_robots.build('knee')
    group = own.command.groups[0]
    for point, found in zip(given, points_of(answer)):
        assert own.forward(point.positions, 0) == found.positions  # bit for bit, in step
        exact = reference_pose(robot, {'knee_output': point.positions[0]},
                               {'knee_motor': found.positions[0],
                                'knee_link': group.position('knee_link')})
        assert abs(found.positions[0] - float(exact['knee_motor'])) <= TOLERANCE
        rates = reference_velocities(robot, {'knee_output': point.positions[0], **exact},
                                     {'knee_output': mpf(0.3)})
        assert relative(found.velocities, [rates['knee_motor']]) <= TOLERANCE
        # the power balance: motor torque times its rate is the knee's
        assert abs(found.efforts[0] * found.velocities[0] - 2.0 * 0.3) <= 1e-14
    relay.send('commands', Float64MultiArray(data=[0.8]), answered=False)
    relay.send('commands', Float64MultiArray(data=[0.1]))
    values = relay.status(lambda values: values['refused commands'] == '1')
    assert values['refused: no assembly reaches it'] == '1'
    relay.stop(nodes)
    assert 'refused commands: no assembly reaches it: group knee_output_pin' in (
        relay.log.read_text())


def test_a_command_across_a_singular_configuration_is_refused(context, nodes, tmp_path):
    relay = RelayNode(context, nodes, tmp_path, REVERSED_PARAMETERS)
    relay.handshake(['knee_motor'], (0.0,))
    for crank in (0.5, 1.0, 1.5, 1.9):
        relay.send('commands', Float64MultiArray(data=[crank]))
    # past the rocker's dead point (about 1.95 rad of the crank)
    across = trajectory(['knee_motor'], [JointPoint((1.9,)), JointPoint((2.1,))])
    relay.send('trajectory', across, answered=False)
    relay.send('commands', Float64MultiArray(data=[2.1]), answered=False)
    relay.send('commands', Float64MultiArray(data=[1.8]))
    values = relay.status(lambda values: values['refused commands'] == '1'
                          and values['refused trajectories'] == '1')
    assert values['refused: it crosses or comes too near a singular configuration'] == '2'
    relay.stop(nodes)
    log = relay.log.read_text()
    assert ('refused joint_trajectory: it crosses or comes too near a singular configuration: '
            'point 1: group knee_output_pin: the measured direction crossed a singular '
            'configuration') in log


def test_velocity_commands_wait_for_a_measured_pose(context, nodes, tmp_path):
    # the controller's joints by default: those passed through, then the actuators
    parameters = {**{name: value for name, value in ANKLE_PARAMETERS.items()
                     if name != 'commands.controller_joints'},
                  'commands.interface_name': 'velocity', 'measured.timeout': PROCESS_TIMEOUT}
    relay = RelayNode(context, nodes, tmp_path, parameters, measured=True)
    relay.handshake(['ankle_roll', 'toe', 'ankle_pitch'], None)
    rates = [0.2, 0.4, -0.3]  # roll, toe, pitch
    # until one arrives (the readers match): refused without a pose
    for _ in range(round(PROCESS_TIMEOUT / 0.5)):
        relay.send('commands', Float64MultiArray(data=rates), answered=False)
        if relay.listener.spin_until(lambda: any(
                item.key == 'refused: no pose measured on measured_joint_states within '
                            'measured.timeout' and item.value != '0'
                for array in relay.listener.received['/diagnostics']
                for status in array.status for item in status.values), 0.5):
            break
    assert not relay.outputs('commands')
    own = pure_relay(ANKLE_PARAMETERS)
    motors = own.forward((0.05, 0.0, 0.1), 0)  # motor_right, toe, motor_left
    message = JointState(name=['motor_left', 'motor_right'],
                         position=[motors[2], motors[0]], velocity=[0.0, 0.0])
    message.header.stamp.sec = 3
    relay.send('measured', message)
    relay.status(lambda values: values['measured pose age (s)'] != 'none yet')
    answer = relay.send('commands', Float64MultiArray(data=rates))
    robot = transmission_robots.build('ankle')
    outputs = {'ankle_roll': 0.05, 'ankle_pitch': 0.1}
    guess = {name: 0.0 for name in robot.loop_joints()}
    exact = reference_pose(robot, outputs, guess | {'motor_left': motors[2],
                                                    'motor_right': motors[0]})
    expected = reference_velocities(robot, {**outputs, **exact},
                                    {'ankle_roll': mpf(rates[0]), 'ankle_pitch': mpf(rates[2])})
    # toe, motor_left, motor_right: the joints passed through, then the actuators
    assert answer.data[0] == rates[1]
    assert relative(list(answer.data[1:]), [expected['motor_left'],
                                            expected['motor_right']]) <= TOLERANCE
    relay.stop(nodes)


@pytest.mark.parametrize(('parameters', 'line'), [
    ({'robot_description': KNEE, 'loops.measured_joints': ['knee_motor']},
     'linkage_command_node: invalid parameter loops.output_joints: the command relay needs the '
     'output joints commands are written in'),
    ({**KNEE_PARAMETERS, 'commands.interface_name': 'torque'},
     'linkage_command_node: invalid parameter commands.interface_name: must be one of position, '
     "velocity, effort; got 'torque'"),
    ({**KNEE_PARAMETERS, 'commands.controller_joints': ['knee_motor', 'hip']},
     'linkage_command_node: cannot relay commands to the actuators of parameter '
     "robot_description: commands.controller_joints ['knee_motor', 'hip']: not the joints"),
    ({**KNEE_PARAMETERS, 'robot_description': '<robot name="x">'},
     'linkage_command_node: cannot relay commands to the actuators of parameter '
     'robot_description: '),
])
def test_what_cannot_start_exits_2_with_one_line(nodes, tmp_path, parameters, line):
    output = tmp_path / 'relay.log'
    process = nodes.start({'log.folder': str(tmp_path / 'bags'), **parameters}, output,
                          executable=EXECUTABLE)
    assert process.wait(timeout=PROCESS_TIMEOUT) == 2
    lines = [text for text in output.read_text().splitlines()
             if text.startswith('linkage_command_node: ')]
    assert len(lines) == 1 and lines[0].startswith(line), output.read_text()
    assert not (tmp_path / 'bags').exists()  # nothing written
