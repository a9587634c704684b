# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Start control, from another process: autostart, ~/pause, ~/resume and ~/reset.

Also the default end behaviour (a node started without parameters keeps running) and the pure
RunControl state machine.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from diagnostic_msgs.msg import DiagnosticArray
from linkage_kinematics.run.control import RunControl, RunState, ServiceAnswer
from node_process import (
    Listener,
    NodeProcesses,
    PROCESS_TIMEOUT,
    ros_context,
    stamp_ns,
)
import pytest
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from std_srvs.srv import Trigger
from trajectory_msgs.msg import JointTrajectory
from visualization_msgs.msg import MarkerArray

ALPHA_START = 0.25  # rad; not the default, so the first state is recognisably alpha_start


def _seconds(duration) -> float:
    return duration.sec + duration.nanosec * 1e-9


def _status_values(array: DiagnosticArray) -> dict[str, str]:
    (status,) = array.status
    return {value.key: value.value for value in status.values}


@pytest.fixture(scope='module')
def context(domain_id: int) -> Iterator:
    with ros_context(domain_id) as ros:
        yield ros


@pytest.fixture
def listener(context, request) -> Iterator[Listener]:
    listening = Listener(f"listener_{request.node.name.split('[')[0]}", context)
    listening.subscribe('/linkage/state', JointTrajectory)
    listening.subscribe('/linkage/markers', MarkerArray)
    listening.subscribe('/diagnostics', DiagnosticArray)
    listening.subscribe('/robot_description', String, transient_local=True)
    yield listening
    listening.destroy()


class Services:
    """The node's Trigger services, called from this process."""

    def __init__(self, listener: Listener) -> None:
        self.listener = listener
        self.clients = {
            name: listener.node.create_client(Trigger, f'/linkage_node/{name}')
            for name in ('pause', 'resume', 'reset')
        }
        for client in self.clients.values():
            assert client.wait_for_service(timeout_sec=PROCESS_TIMEOUT)

    def call(self, name: str) -> Trigger.Response:
        return self.listener.result_of(self.clients[name].call_async(Trigger.Request()))


def _statuses(listener: Listener, run_state: str) -> list[DiagnosticArray]:
    return [array for array in listener.received['/diagnostics']
            if _status_values(array).get('run state') == run_state]


def test_without_autostart_the_node_waits_and_the_first_state_after_resume_is_alpha_start(
    listener: Listener, nodes: NodeProcesses, tmp_path: Path
) -> None:
    output = tmp_path / 'node.log'
    process = nodes.start({'autostart': False, 'alpha_start': ALPHA_START, 'log.enabled': False},
                          output)
    states = listener.received['/linkage/state']
    # The scene (at alpha_start), the URDF and the status that says it waits arrive ...
    assert listener.spin_until(
        lambda: listener.received['/robot_description'] and listener.received[
            '/linkage/markers'] and _statuses(listener, 'paused')), output.read_text()
    services = Services(listener)
    (waiting, *_) = _statuses(listener, 'paused')
    assert 'waiting at alpha_start for ~/resume' in waiting.status[0].message
    # ... and no state, even after a further status (1 Hz) has come.
    count = len(listener.received['/diagnostics'])
    assert listener.spin_until(lambda: len(listener.received['/diagnostics']) > count)
    assert states == []

    answer = services.call('resume')
    assert (answer.success, answer.message) == (True, 'started from alpha_start')
    assert listener.spin_until(lambda: states)
    first = states[0].points[0]
    assert first.positions[0] == ALPHA_START
    assert _seconds(first.time_from_start) == 0.0
    assert listener.spin_until(lambda: _statuses(listener, 'running'))

    again = services.call('resume')
    assert not again.success
    assert again.message == 'already running; ~/pause stops it'
    status = nodes.interrupt(process)
    assert status == 0, output.read_text()


def test_pause_holds_the_motion_resume_goes_on_and_reset_goes_back_to_alpha_start(
    listener: Listener, nodes: NodeProcesses, tmp_path: Path
) -> None:
    output = tmp_path / 'node.log'
    process = nodes.start({'alpha_start': ALPHA_START, 'end_behavior': 'loop',
                           'log.enabled': False}, output)
    states = listener.received['/linkage/state']
    assert listener.spin_until(
        lambda: states and _seconds(states[-1].points[0].time_from_start) > 0.1
    ), output.read_text()
    services = Services(listener)

    answer = services.call('pause')
    assert answer.success and answer.message.startswith('paused at α = ')
    assert listener.spin_until(lambda: _statuses(listener, 'paused'))
    paused_status = _statuses(listener, 'paused')[0]
    assert paused_status.status[0].message.startswith('paused at α = ')
    # The pause's status is stamped with the latest state's time; none comes after it,
    # however long the pause lasts (here: until two more statuses have come).
    held_stamp = stamp_ns(paused_status)
    count = len(listener.received['/diagnostics'])
    assert listener.spin_until(lambda: len(listener.received['/diagnostics']) >= count + 2)
    assert not services.call('pause').success
    before_resume = len(states)
    assert all(stamp_ns(state) <= held_stamp for state in states)
    last = states[-1].points[0]

    answer = services.call('resume')
    assert (answer.success, answer.message) == (True, 'resumed')
    assert listener.spin_until(lambda: len(states) > before_resume)
    going_on = states[before_resume].points[0]
    # The motion goes on where it stopped: its drive-law time did not run during the pause.
    assert 0.0 < _seconds(going_on.time_from_start) - _seconds(last.time_from_start) < 0.1
    assert stamp_ns(states[before_resume]) > held_stamp

    answer = services.call('reset')
    assert answer.success and 'back to alpha_start' in answer.message
    assert listener.spin_until(
        lambda: any(_seconds(state.points[0].time_from_start) == 0.0
                    for state in states[before_resume:]))
    restart = next(state for state in states[before_resume:]
                   if _seconds(state.points[0].time_from_start) == 0.0)
    assert restart.points[0].positions[0] == ALPHA_START

    # A reset while paused stays paused at alpha_start; resume starts from there.
    assert services.call('pause').success
    assert services.call('reset').success
    count = len(states)
    answer = services.call('resume')
    assert (answer.success, answer.message) == (True, 'started from alpha_start')
    assert listener.spin_until(lambda: len(states) > count)
    first = states[count].points[0]
    assert (first.positions[0], _seconds(first.time_from_start)) == (ALPHA_START, 0.0)
    status = nodes.interrupt(process)
    assert status == 0, output.read_text()


def test_a_reset_while_paused_publishes_the_state_at_alpha_start_once(
    listener: Listener, nodes: NodeProcesses, tmp_path: Path
) -> None:
    listener.subscribe('/joint_states', JointState)
    output = tmp_path / 'node.log'
    process = nodes.start({'alpha_start': ALPHA_START, 'end_behavior': 'loop',
                           'log.enabled': False}, output)
    states = listener.received['/linkage/state']
    joint_states = listener.received['/joint_states']
    diagnostics = listener.received['/diagnostics']
    assert listener.spin_until(
        lambda: states and _seconds(states[-1].points[0].time_from_start) > 0.1
    ), output.read_text()
    services = Services(listener)
    assert services.call('pause').success
    # Whatever was published before the pause has arrived once two more statuses have.
    count = len(diagnostics)
    assert listener.spin_until(lambda: len(diagnostics) >= count + 2)
    held_alpha = states[-1].points[0].positions[0]
    assert held_alpha != ALPHA_START
    # Counted before the call: what the reset publishes may arrive with its answer.
    before = len(states), len(joint_states), len(diagnostics)

    answer = services.call('reset')
    assert (answer.success, answer.message) == (
        True, 'back to alpha_start = 14.323945°; paused: ~/resume starts the motion')
    assert listener.spin_until(
        lambda: len(states) > before[0] and len(joint_states) > before[1])
    (reset_state,) = states[before[0]:]
    assert reset_state.points[0].positions[0] == ALPHA_START
    assert _seconds(reset_state.points[0].time_from_start) == 0.0
    (reset_joints,) = joint_states[before[1]:]
    assert dict(zip(reset_joints.name, reset_joints.position))['crank_joint'] == ALPHA_START
    # The scene of it, stamped as the state, and a status that says it waits there.
    assert listener.spin_until(lambda: any(
        stamp_ns(markers.markers[0]) == stamp_ns(reset_state)
        for markers in listener.received['/linkage/markers']))
    assert any(array.status[0].message == 'paused: waiting at alpha_start for ~/resume'
               for array in diagnostics[before[2]:])
    # Once: still paused, nothing more comes (here: until two more statuses have come).
    count = len(diagnostics)
    assert listener.spin_until(lambda: len(diagnostics) >= count + 2)
    assert (len(states), len(joint_states)) == (before[0] + 1, before[1] + 1)
    status = nodes.interrupt(process)
    assert status == 0, output.read_text()


def test_a_node_started_without_parameters_keeps_running_until_stopped(
    listener: Listener, nodes: NodeProcesses, tmp_path: Path
) -> None:
    output = tmp_path / 'node.log'
    process = nodes.start({}, output, cwd=tmp_path)
    states = listener.received['/linkage/state']
    # The paper's 90° take 0.785 s at 2 rad/s; the crank then swings back (bounce).
    assert listener.spin_until(
        lambda: states and states[-1].points[0].velocities[0] < 0.0), output.read_text()
    assert process.poll() is None
    assert nodes.interrupt(process) == 0, output.read_text()
    assert 'bag finalized' in output.read_text()


def test_run_control_answers_what_it_did_and_why_not() -> None:
    control = RunControl(autostart=False)
    assert control.state is RunState.PAUSED
    assert control.activity(None) == 'paused: waiting at alpha_start for ~/resume'
    assert control.pause(None, None) == ServiceAnswer(False, 'already paused; ~/resume goes on')
    assert control.resume() == (ServiceAnswer(True, 'started from alpha_start'), None)
    assert control.resume() == (ServiceAnswer(False, 'already running; ~/pause stops it'), None)
    assert control.pause(1_500_000_000, 0.5) == ServiceAnswer(True, 'paused at α = 28.647890°')
    assert control.activity(0.5) == 'paused at α = 28.647890°; ~/resume goes on'
    assert control.resume() == (ServiceAnswer(True, 'resumed'), 1_500_000_000)
    assert control.state is RunState.RUNNING
    assert control.reset(0.0) == ServiceAnswer(
        True, 'back to alpha_start = 0.000000°; the motion starts again')
    assert control.pause(2_000_000_000, 0.1).success
    assert control.reset(0.0) == ServiceAnswer(
        True, 'back to alpha_start = 0.000000°; paused: ~/resume starts the motion')
    assert control.resume() == (ServiceAnswer(True, 'started from alpha_start'), None)
