# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
run.relay and run.relay_diagnostics: the command relay's conversions, counts and status, no ROS.

The relay of the humanoid ankle's description (a joint outside the loops added, the ``toe``)
and of the lab knee: forward commands in ``commands.joints`` order out in
``commands.controller_joints`` order, bit for bit the robot's own command direction; velocity and
effort commands at the measured pose (refused without one, or with one older than
``measured.timeout``); settings that do not fit the robot refused at start in one line; the
relay's record: counts by kind and reason, a log line for the first refusal and then at most one
a second per input saying how many were not logged, the status's level and key values.
"""

from __future__ import annotations

import math
from pathlib import Path

from linkage_kinematics.loops.command import CommandRefusal, CommandRefused, JointPoint
from linkage_kinematics.loops.plan import read_loops
from linkage_kinematics.loops.robot_command import plan_command
from linkage_kinematics.model.urdf_reader import read_urdf
from linkage_kinematics.run.configuration import build_relay_configuration
from linkage_kinematics.run.diagnostics import Level
from linkage_kinematics.run.parameter_specs import relay_parameter_specs
from linkage_kinematics.run.parameter_values import ConfigurationError
from linkage_kinematics.run.relay import (
    MessageKind,
    read_relay,
    RELAY_ERRORS,
    RelayError,
    RelayRefusal,
    RelayRefused,
)
from linkage_kinematics.run.relay_diagnostics import relay_status, RelayRecord, RelayView
import pytest

REPOSITORY = Path(__file__).resolve().parent.parent
TOE = """
  <link name="toe"/>
  <joint name="toe" type="revolute">
    <parent link="foot"/>
    <child link="toe"/>
    <origin xyz="0.1 0 -0.03"/>
    <axis xyz="0 1 0"/>
    <limit lower="-0.5" upper="0.5" effort="10" velocity="5"/>
  </joint>
</robot>"""
ANKLE = (REPOSITORY / 'urdf' / 'humanoid_ankle.urdf').read_text(encoding='utf-8').replace(
    '</robot>', TOE)
KNEE = (REPOSITORY / 'urdf' / 'lab_knee.urdf').read_text(encoding='utf-8')
SECOND = 1_000_000_000


def settings(**values):
    """Return the relay's configuration: its defaults with ``values``."""
    return build_relay_configuration({
        **{spec.name: spec.default for spec in relay_parameter_specs()}, **values})


def config(**values):
    """Return the relay's configuration of the ankle (motors measured), with ``values``."""
    return settings(**{
        'robot_description': ANKLE, 'loops.measured_joints': ['motor_left', 'motor_right'],
        'loops.output_joints': ['ankle_pitch', 'ankle_roll'], **values})


def robot_command(urdf=ANKLE, measured=('motor_left', 'motor_right'),
                  outputs=('ankle_pitch', 'ankle_roll')):
    return plan_command(read_loops(read_urdf(urdf)), measured, outputs)


def test_forward_commands_are_the_robot_s_command_direction_in_the_controller_s_order():
    relay = read_relay(ANKLE, config(**{
        'commands.joints': ['ankle_roll', 'toe', 'ankle_pitch'],
        'commands.controller_joints': ['motor_right', 'toe', 'motor_left']}))
    own = robot_command()
    assert relay.robot_name == 'humanoid_ankle'
    assert relay.controller_joints == ('motor_right', 'toe', 'motor_left')
    assert own.names(('ankle_roll', 'toe', 'ankle_pitch')) == ('toe', 'motor_left',
                                                               'motor_right')
    for step in range(20):
        roll, toe, pitch = 0.1 * math.sin(0.3 * step), 0.2, 0.2 * math.cos(0.2 * step)
        found = relay.forward((roll, toe, pitch), 0)
        expected = own.convert(('ankle_roll', 'toe', 'ankle_pitch'),
                               JointPoint((roll, toe, pitch))).positions
        assert found == (expected[2], expected[0], expected[1])  # bit for bit


def test_a_refused_command_is_refused_whole_and_leaves_the_relay_as_it_was():
    relay, untouched = read_relay(ANKLE, config()), read_relay(ANKLE, config())
    for ankle in ((0.1, 0.05), (0.12, 0.06)):
        assert relay.forward(ankle, 0) == untouched.forward(ankle, 0)
    state = relay.command.groups[0].state()
    for values, reason in (((0.1, math.nan), CommandRefusal.NOT_FINITE),
                           ((2.0, 0.0), CommandRefusal.LIMIT),
                           ((0.1, 0.05, 0.0), CommandRefusal.JOINTS)):
        with pytest.raises(CommandRefused) as refused:
            relay.forward(values, 0)
        assert refused.value.reason is reason
    assert refused.value.detail == '3 values for the 2 joints of commands.joints'
    assert relay.command.groups[0].state() is state
    # the next command as if none had come between
    assert relay.forward((0.11, 0.04), 0) == untouched.forward((0.11, 0.04), 0)


def test_velocity_and_effort_commands_are_converted_at_the_measured_pose():
    for interface, field in (('velocity', 'velocities'), ('effort', 'efforts')):
        relay = read_relay(ANKLE, config(**{'commands.interface_name': interface,
                                            'measured.timeout': 0.5}))
        with pytest.raises(RelayRefused) as refused:
            relay.forward((0.3, -0.2), 0)
        assert refused.value.reason is RelayRefusal.NO_POSE
        # the motors where the ankle is at pitch 0.1, roll 0.05
        motors = robot_command().convert(('ankle_pitch', 'ankle_roll'),
                                         JointPoint((0.1, 0.05))).positions
        assert relay.pose.take(5, ('motor_left', 'motor_right', 'other'), (*motors, 3.0),
                               (0.0, 0.0, 0.0), 2 * SECOND)
        found = relay.forward((0.3, -0.2), 2 * SECOND + SECOND // 4)
        arrays = {'velocities': JointPoint((0.1, 0.05), (0.3, -0.2)),
                  'efforts': JointPoint((0.1, 0.05), (), (), (0.3, -0.2))}
        expected = getattr(robot_command().convert(('ankle_pitch', 'ankle_roll'),
                                                   arrays[field]), field)
        assert max(abs(a - b) for a, b in zip(found, expected)) <= 1e-12 * max(map(abs,
                                                                                   expected))
        assert relay.pose.age(2 * SECOND + SECOND // 4) == 0.25
        with pytest.raises(RelayRefused):  # older than measured.timeout
            relay.forward((0.3, -0.2), 2 * SECOND + SECOND // 2 + 1)


@pytest.mark.parametrize(('values', 'problem'), [
    ({'commands.joints': ['ankle_pitch']},
     "commands.joints ['ankle_pitch']: group ball_left+ball_right needs all its output joints "
     "['ankle_pitch', 'ankle_roll']; ['ankle_roll'] missing"),
    ({'commands.joints': ['ankle_pitch', 'ankle_roll', 'motor_left', 'heel']},
     "commands.joints ['ankle_pitch', 'ankle_roll', 'motor_left', 'heel']: joint 'motor_left' "
     "is solved by group ball_left+ball_right: command its output joints; joint 'heel' is "
     'not a joint of the robot'),
    ({'commands.controller_joints': ['motor_left']},
     "commands.controller_joints ['motor_left']: not the joints commands.joints "
     "['ankle_pitch', 'ankle_roll'] are relayed to, ['motor_left', 'motor_right'], in some "
     'order'),
    ({'loops.output_joints': ['ankle_pitch', 'toe']},
     "output joint 'toe' is not a joint of any closure group; group ball_left+ball_right: "
     "output joints ['ankle_pitch']: 1 joints for 2 degrees of freedom that move it"),
    ({'loops.measured_joints': []},
     "loops.measured_joints: the relay needs the actuators, given here or as the closure file's "
     'actuated joints (name_mot)'),
])
def test_settings_that_do_not_fit_the_robot_are_refused_in_one_line(values, problem):
    with pytest.raises(RELAY_ERRORS) as refused:
        read_relay(ANKLE, config(**values))
    assert str(refused.value).startswith(problem)
    assert '\n' not in str(refused.value)


def test_the_relay_needs_output_joints():
    with pytest.raises(ConfigurationError, match='loops.output_joints: the command relay needs '
                                                 'the output joints'):
        settings()
    with pytest.raises(ConfigurationError, match='commands.interface_name: must be one of '
                                                 "position, velocity, effort; got 'speed'"):
        config(**{'commands.interface_name': 'speed'})


def test_a_knee_s_relay_commands_its_motor_and_refuses_what_its_loop_cannot_reach():
    relay = read_relay(KNEE, settings(**{
        'robot_description': KNEE, 'loops.measured_joints': ['knee_motor'],
        'loops.output_joints': ['knee_output']}))
    assert relay.groups[0].describe() == ('group knee_output_pin: knee_output → knee_motor '
                                          '(planar one-degree-of-freedom loops in closed form)')
    assert relay.forward((0.1,), 0) == robot_command(KNEE, ('knee_motor',),
                                                     ('knee_output',)).convert(
        ('knee_output',), JointPoint((0.1,))).positions
    with pytest.raises(CommandRefused) as refused:
        relay.forward((2.5,), 0)  # beyond the rocker's swing
    assert refused.value.reason in (CommandRefusal.UNREACHABLE, CommandRefusal.SINGULAR)


def test_the_record_counts_and_logs_a_refusal_a_second_per_input_and_reason():
    record = RelayRecord()
    limit = CommandRefused(CommandRefusal.LIMIT, 'motor')
    assert record.refuse(MessageKind.COMMANDS, limit.reason, str(limit), SECOND) == (
        'refused commands: an actuator would leave its URDF <limit>: motor')
    for step in range(1, 5):  # within the second: counted, not logged
        assert record.refuse(MessageKind.COMMANDS, limit.reason, str(limit),
                             SECOND + step) is None
    # another input or another reason has its own lines
    assert record.refuse(MessageKind.TRAJECTORY, RelayRefusal.MALFORMED, 'x', SECOND + 9) == (
        'refused joint_trajectory: x')
    assert record.refuse(MessageKind.COMMANDS, RelayRefusal.MALFORMED, 'y', SECOND + 10) == (
        'refused commands: y')
    assert record.refuse(MessageKind.COMMANDS, limit.reason, str(limit), 2 * SECOND) == (
        'refused commands: an actuator would leave its URDF <limit>: motor (4 more refused '
        'since the last such line)')
    record.relay(MessageKind.COMMANDS, 1, 40_000)
    record.relay(MessageKind.COMMANDS, 1, 60_000)
    record.relay(MessageKind.TRAJECTORY, 100, 2_000_000)
    assert record.refused[MessageKind.COMMANDS][CommandRefusal.LIMIT] == 6
    assert record.relayed == {MessageKind.COMMANDS: 2, MessageKind.TRAJECTORY: 1}
    assert record.points == 100
    view = RelayView(robot_name='humanoid_ankle', description_from='parameter robot_description',
                     groups=read_relay(ANKLE, config()).groups, interface='position',
                     joints=('ankle_pitch', 'ankle_roll'),
                     controller_joints=('motor_left', 'motor_right'),
                     inputs=('/r/joint_trajectory', '/r/commands'),
                     outputs=('/actuators/joint_trajectory', '/actuators/commands'),
                     pose_age=None, measures_pose=False, problem=None, log_file=None,
                     log_size=None)
    status = relay_status(record, view)
    assert status.level is Level.WARN
    assert status.message == ('refused 8 messages since the last status: an actuator would '
                              'leave its URDF <limit> (6); its bytes are not such a message (2)')
    assert status.values['relayed commands'] == '2'
    assert status.values['refused commands'] == '7'
    assert status.values['refused trajectories'] == '1'
    assert status.values['refused: an actuator would leave its URDF <limit>'] == '6'
    assert status.values['conversion per command (µs)'] == '50.0'
    assert status.values['conversion per trajectory point (µs)'] == '20.0'
    assert status.values['group ball_left+ball_right'] == (
        'ankle_pitch, ankle_roll → motor_left, motor_right (crank-rod-ball leg in closed form)')
    assert 'measured pose age (s)' not in status.values
    # nothing refused since: OK, saying what it relays; a problem: ERROR
    status = relay_status(record, view)
    assert (status.level, status.message) == (
        Level.OK, 'relaying /r/joint_trajectory, /r/commands to /actuators/joint_trajectory, '
                  '/actuators/commands')
    status = relay_status(record, RelayView(**{**view.__dict__, 'problem': 'no log'}))
    assert (status.level, status.message) == (Level.ERROR, 'no log')
    status = relay_status(RelayRecord(), RelayView(**{**view.__dict__, 'robot_name': None,
                                                      'description_from': 'topic /x'}))
    assert (status.level, status.message) == (Level.OK,
                                              'waiting for the robot description on topic /x')


def test_relay_errors_are_value_errors_one_line():
    assert all(issubclass(error, ValueError) for error in RELAY_ERRORS)
    with pytest.raises(RelayError):
        read_relay(ANKLE, config(**{'commands.controller_joints': ['toe']}))
