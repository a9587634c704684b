# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
linkage_node end to end: a real node process, real rclpy and Fast DDS, a listener here.

Also the node's pure motion functions (loop, bounce, fixed steps) and the URDF's kinematics.
"""

from __future__ import annotations

from dataclasses import replace
import math
from pathlib import Path
import resource
import signal
import time
import xml.etree.ElementTree as ElementTree

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from linkage_kinematics.bag.state_layout import STATE_JOINT_NAMES
from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import preset, TWO_PI
from linkage_kinematics.kinematics.solver import solve
from linkage_kinematics.model.joints import DEFAULT_JOINT_NAMES, Driver, tree_values
from linkage_kinematics.model.urdf import urdf_text
from linkage_kinematics.ros import messages
from linkage_kinematics.run.configuration import build_configuration
from linkage_kinematics.run.motion import sample_at_step, sample_at_time, solve_sample
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from node_process import (
    configuration_values,
    expected_state_point,
    Listener,
    NodeProcesses,
    PROCESS_TIMEOUT,
    REPOSITORY,
    ros_context,
)
import pytest
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from trajectory_msgs.msg import JointTrajectory
from visualization_msgs.msg import Marker, MarkerArray
import yaml

PAPER = preset('paper').geometry
DEAD_POINT = min(PAPER.reachability.dead_points, key=abs)  # ≈ −1.94°, clockwise from 0
DATA_TOPICS = {
    '/joint_states': JointState,
    '/linkage/state': JointTrajectory,
    '/linkage/markers': MarkerArray,
    '/diagnostics': DiagnosticArray,
}
QUIET = {'log.enabled': False}


@pytest.fixture(scope='module')
def context(domain_id):
    with ros_context(domain_id) as ros:
        yield ros


@pytest.fixture
def listener(context, request):
    listening = Listener(f"listener_{request.node.name.split('[')[0]}", context)
    for topic, msg_type in DATA_TOPICS.items():
        listening.subscribe(topic, msg_type)
    yield listening
    listening.destroy()


def _listen_to_run(
    listener: Listener, nodes: NodeProcesses, parameters: dict, output: Path
) -> int:
    """
    Run a node with ``parameters`` (end_behavior 'stop') to its end while listening.

    Return its exit status. Keep only what the listener heard of that run.

    The node first loops; once the listener hears it (discovery may take seconds), switching
    end_behavior to 'stop' restarts the motion from alpha_start, so the listener sees the whole
    run. The restart is where time_from_start, counting up through the loop, starts again; so
    the switch waits until the listener has heard a time after the first, which the restart's
    zero is below even if the listener joined at the node's very first state.
    """
    process = nodes.start({**parameters, 'end_behavior': 'loop'}, output)
    trajectories = listener.received['/linkage/state']
    assert listener.spin_until(
        lambda: trajectories and _seconds(trajectories[-1].points[0].time_from_start) > 0.0
    ), output.read_text()
    client = AsyncParameterClient(listener.node, 'linkage_node')
    assert client.wait_for_services(timeout_sec=PROCESS_TIMEOUT)
    future = client.set_parameters([Parameter('end_behavior', value='stop')])
    assert listener.spin_until(future.done)
    assert future.result().results[0].successful
    listener.spin_until(lambda: process.poll() is not None)
    listener.drain()
    status = process.wait(timeout=PROCESS_TIMEOUT)
    times = [_seconds(message.points[0].time_from_start) for message in trajectories]
    restart = max(i for i in range(1, len(times)) if times[i] < times[i - 1])
    restart_stamp = _stamp_ns(trajectories[restart])
    for topic, received in listener.received.items():
        received[:] = [message for message in received
                       if _stamp_ns(_header_of(message)) >= restart_stamp]
    return status


def _header_of(message):
    """Return the message, or for a MarkerArray its first marker: whatever carries the header."""
    return message.markers[0] if isinstance(message, MarkerArray) else message


def _stamp_ns(message) -> int:
    return message.header.stamp.sec * 1_000_000_000 + message.header.stamp.nanosec


def _seconds(duration) -> float:
    return duration.sec + duration.nanosec * 1e-9


def _values(status: DiagnosticStatus) -> dict[str, str]:
    return {pair.key: pair.value for pair in status.values}


def _assert_matches_library(listener: Listener, drive: DriveLaw) -> None:
    joint_states = listener.received['/joint_states']
    assert joint_states, 'no /joint_states received'
    previous = None
    for message in joint_states:
        assert list(message.name) == list(DEFAULT_JOINT_NAMES.values())
        assert message.header.frame_id == ''
        alpha, coupler, rocker = message.position
        state = solve(PAPER, alpha, drive)
        assert math.remainder(coupler - (state.gamma - state.alpha), TWO_PI) == pytest.approx(
            0.0, abs=1e-12)
        assert math.remainder(rocker - (-state.beta - state.gamma), TWO_PI) == pytest.approx(
            0.0, abs=1e-12)
        assert tuple(message.velocity) == (
            state.omega, state.omega_ab - state.omega, state.omega_bc - state.omega_ab)
        if previous is not None:
            assert all(abs(now - before) < math.pi
                       for now, before in zip(message.position, previous))
        previous = message.position

    trajectories = listener.received['/linkage/state']
    assert trajectories, 'no /linkage/state received'
    for message in trajectories:
        assert list(message.joint_names) == list(STATE_JOINT_NAMES)
        point = message.points[0]
        state = solve(PAPER, point.positions[0], drive)
        assert (tuple(point.positions), tuple(point.velocities), tuple(point.accelerations)) == (
            expected_state_point(PAPER, state))
        assert _seconds(point.time_from_start) == pytest.approx(
            drive.time_to(0.0, state.alpha), abs=1e-9)

    for topic in ('/joint_states', '/linkage/state'):
        stamps = [_stamp_ns(message) for message in listener.received[topic]]
        assert all(later > earlier for earlier, later in zip(stamps, stamps[1:])), topic


def test_stop_run_publishes_the_library_state_and_ends_exactly_at_alpha_end(
    listener, nodes, tmp_path
):
    rate_hz = 400.0
    drive = DriveLaw(1.0)
    started = time.monotonic()
    status = _listen_to_run(
        listener, nodes, {**QUIET, 'omega0': drive.omega0, 'rate_hz': rate_hz},
        tmp_path / 'node.log')
    lifetime = time.monotonic() - started

    assert status == 0, (tmp_path / 'node.log').read_text()
    _assert_matches_library(listener, drive)
    first = listener.received['/linkage/state'][0].points[0]
    assert (first.positions[0], _seconds(first.time_from_start)) == (0.0, 0.0)
    assert listener.received['/joint_states'][0].position[0] == 0.0
    final = listener.received['/joint_states'][-1]
    assert final.position[0] == math.pi / 2.0
    assert listener.received['/linkage/state'][-1].points[0].positions[0] == math.pi / 2.0
    # A loose count over the run (a few ticks lost to discovery are fine).
    stamps = [_stamp_ns(message) for message in listener.received['/joint_states']]
    window = (stamps[-1] - stamps[0]) * 1e-9
    assert window > 0.5
    assert 0.25 * rate_hz < (len(stamps) - 1) / window < 1.1 * rate_hz

    markers = listener.received['/linkage/markers'][-1].markers
    assert [(m.ns, m.id) for m in markers] == [('linkage', i) for i in range(6)]
    assert [m.type for m in markers] == [
        Marker.CYLINDER, Marker.LINE_LIST, Marker.SPHERE, Marker.SPHERE, Marker.CUBE,
        Marker.CUBE]
    assert {m.header.frame_id for m in markers} == {'linkage_base'}
    end_state = solve(PAPER, math.pi / 2.0, drive)
    pin_a = markers[messages.PIN_A_ID].pose.position
    pin_b = markers[messages.PIN_B_ID].pose.position
    assert (pin_a.x, pin_a.y, pin_b.x, pin_b.y) == (
        end_state.pin_a_x, end_state.pin_a_y, end_state.pin_b_x, end_state.pin_b_y)
    pivot_c = markers[messages.PIVOT_C_ID].pose.position
    assert (pivot_c.x, pivot_c.y) == (PAPER.ground_x, PAPER.ground_y)

    status_message = listener.received['/diagnostics'][-1].status[0]
    assert status_message.name == 'linkage_node: crank motion'
    assert status_message.level == DiagnosticStatus.OK
    assert 'reached alpha_end' in status_message.message
    values = _values(status_message)
    assert float(values['alpha (rad)']) == math.pi / 2.0
    assert float(values['alpha (deg)']) == pytest.approx(90.0)
    assert float(values['loop closure residual']) < 1e-12
    assert float(values['achieved rate (Hz)']) > 0.0
    # A busy machine may miss any number of the 400 Hz periods, and the count runs over the whole
    # run (the loop before the restart too), so no exact number is known; but it is a whole
    # number in every status, it never goes down, and it cannot pass the periods that fell due
    # while the node lived (less than the test's wait for it; two runs, each due at its start).
    counts = [_values(array.status[0])['missed deadlines']
              for array in listener.received['/diagnostics']]
    assert all(count.isdigit() for count in counts), counts
    assert [int(count) for count in counts] == sorted(int(count) for count in counts)
    assert int(values['missed deadlines']) <= rate_hz * lifetime + 2
    assert values['log file'] == 'disabled'
    for key in ('dead point distance (deg)', 'transmission angle (deg)'):
        assert key in values


def test_fixed_step_publishes_exact_steps_and_drive_law_times(listener, nodes, tmp_path):
    drive = DriveLaw(0.10, 2.3)
    step = math.radians(0.5)
    status = _listen_to_run(
        listener, nodes,
        {**QUIET, 'mode': 'fixed_step', 'omega0': drive.omega0, 'k': drive.k, 'rate_hz': 200.0},
        tmp_path / 'node.log',
    )

    assert status == 0, (tmp_path / 'node.log').read_text()
    _assert_matches_library(listener, drive)
    alphas = [message.position[0] for message in listener.received['/joint_states']]
    assert alphas[-1] == math.pi / 2.0
    for alpha in alphas[:-1]:
        assert alpha == round(alpha / step) * step
    assert len(set(alphas)) == len(alphas)


@pytest.mark.parametrize(
    ('alpha_end', 'expected_status', 'expected_level'),
    [(math.radians(-1.5), 0, DiagnosticStatus.WARN), (DEAD_POINT, 1, DiagnosticStatus.ERROR)],
    ids=['near-dead-point', 'at-dead-point'],
)
def test_diagnostics_near_and_at_a_dead_point(
    listener, nodes, tmp_path, alpha_end, expected_status, expected_level
):
    # Slow enough that the listener has long joined before the crank gets there.
    drive = DriveLaw(-0.02)
    status = _listen_to_run(
        listener, nodes,
        {**QUIET, 'omega0': drive.omega0, 'alpha_end': alpha_end, 'rate_hz': 500.0},
        tmp_path / 'node.log',
    )

    output = (tmp_path / 'node.log').read_text()
    assert status == expected_status, output
    _assert_matches_library(listener, drive)
    final = listener.received['/diagnostics'][-1].status[0]
    assert final.level == expected_level
    assert 'dead point' in final.message
    alphas = [message.position[0] for message in listener.received['/joint_states']]
    assert all(math.isfinite(alpha) and alpha > DEAD_POINT for alpha in alphas)
    if expected_level == DiagnosticStatus.ERROR:
        assert alphas[-1] - DEAD_POINT < 1e-3
        assert 'cannot go on' in output
    else:
        assert alphas[-1] == alpha_end


@pytest.mark.parametrize(
    'signal_number', [signal.SIGINT, signal.SIGTERM], ids=['SIGINT', 'SIGTERM'])
def test_signal_ends_a_logging_run_cleanly(listener, nodes, tmp_path, signal_number):
    bags = tmp_path / 'bags'
    process = nodes.start(
        {'end_behavior': 'loop', 'rate_hz': 200.0, 'log.folder': str(bags)},
        tmp_path / 'node.log',
    )
    # Every topic is in the bag once the listener has heard it (markers come at the display
    # rate, diagnostics once a second).
    assert listener.wait_for_every_topic(), (tmp_path / 'node.log').read_text()
    # A subscriber that joins late still gets the description (transient local).
    listener.subscribe('/robot_description', String, transient_local=True)
    assert listener.spin_until(lambda: listener.received['/robot_description'])
    assert listener.received['/robot_description'][0].data == urdf_text(PAPER)
    status = nodes.interrupt(process, signal_number)

    assert status == 0, (tmp_path / 'node.log').read_text()
    assert listener.received['/diagnostics'][-1].status[0].level == DiagnosticStatus.OK
    (bag,) = bags.iterdir()
    metadata = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    with open(bag / metadata['relative_file_paths'][0], 'rb') as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        assert reader.get_summary() is not None, 'the bag was not finalized'
        recorded = {}
        for _, channel, _, message in reader.iter_decoded_messages():
            recorded.setdefault(channel.topic, []).append(message)
        run_metadata = {record.name: record.metadata for record in reader.iter_metadata()}
    # and the TF robot_state_publisher would publish (test_bag_transforms.py)
    assert set(recorded) == {*DATA_TOPICS, '/robot_description', '/tf', '/tf_static'}
    assert recorded['/robot_description'][0].data == urdf_text(PAPER)
    assert sum(map(len, recorded.values())) == metadata['message_count']
    parameters = next(
        value['parameters'] for value in run_metadata.values() if 'parameters' in value)
    assert '"end_behavior": "loop"' in parameters
    diagnostics = _values(recorded['/diagnostics'][-1].status[0])
    assert diagnostics['log file'] == str(bag)


def _limit_file_size() -> None:
    """
    In the node process.

    Files may not grow past 100 kB (writes fail with EFBIG, as on a full disk, instead of the
    default SIGXFSZ killing the process).
    """
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (100_000, 100_000))


def test_failed_recording_turns_diagnostics_to_error_and_publishing_goes_on(
    listener, nodes, tmp_path
):
    bags = tmp_path / 'bags'
    process = nodes.start(
        {'end_behavior': 'loop', 'rate_hz': 1000.0, 'log.folder': str(bags)},
        tmp_path / 'node.log', preexec_fn=_limit_file_size,
    )
    diagnostics = listener.received['/diagnostics']
    assert listener.spin_until(
        lambda: diagnostics and diagnostics[-1].status[0].level == DiagnosticStatus.ERROR)
    assert 'recording stopped' in diagnostics[-1].status[0].message
    count = len(listener.received['/joint_states'])
    assert listener.spin_until(lambda: len(listener.received['/joint_states']) > count + 50)
    status = nodes.interrupt(process)

    assert status == 0, (tmp_path / 'node.log').read_text()
    (bag,) = bags.iterdir()
    metadata = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    mcap_file = bag / metadata['relative_file_paths'][0]
    assert mcap_file.stat().st_size <= 100_000
    assert mcap_file.read_bytes()[:8] == b'\x89MCAP0\r\n'


# --- pure motion functions --------------------------------------------------------------------


def _configuration(**overrides):
    return build_configuration(configuration_values(**{'log.enabled': False, **overrides}))


def test_loop_over_whole_turns_keeps_counting_alpha():
    crank_rocker = preset('grashof_crank_rocker').geometry
    config = _configuration(
        preset='grashof_crank_rocker', rocker_length=crank_rocker.rocker_length,
        ground_x=crank_rocker.ground_x, alpha_end=2.0 * TWO_PI, end_behavior='loop', k=0.1)
    assert config.motion.whole_turns
    duration = config.motion.segment_duration
    sample = sample_at_time(config, 2.25 * duration)
    assert sample.turn_offset == 2.0 * 2.0 * TWO_PI
    assert sample.alpha == config.motion.drive.alpha_at(0.0, 2.25 * duration - 2.0 * duration)
    state = solve_sample(config, sample)
    assert state.alpha == sample.alpha + 4.0 * TWO_PI
    assert state.omega == config.motion.drive.angular_velocity(sample.alpha)

    steps = sample_at_step(config, config.motion.step_count + 3)
    assert steps.alpha == 3 * config.motion.alpha_step
    assert steps.turn_offset == 2.0 * TWO_PI


def test_loop_over_part_of_a_turn_restarts_at_alpha_start():
    config = _configuration(end_behavior='loop')
    assert not config.motion.whole_turns
    sample = sample_at_time(config, config.motion.segment_duration * 1.5)
    assert sample.alpha == pytest.approx(math.pi / 4.0, abs=1e-15)
    assert sample.turn_offset == 0.0
    assert sample_at_step(config, config.motion.step_count + 1).alpha == 0.0


def test_bounce_plays_the_pass_backwards_with_negated_rates():
    config = _configuration(end_behavior='bounce', k=0.3)
    duration = config.motion.segment_duration
    forward = sample_at_time(config, 0.25 * duration)
    backward = sample_at_time(config, 1.75 * duration)
    assert not forward.is_reversed and backward.is_reversed
    assert backward.alpha == pytest.approx(forward.alpha, abs=1e-15)
    ahead = solve_sample(config, forward)
    back = solve_sample(config, replace(backward, alpha=forward.alpha))
    assert back.omega == -ahead.omega
    assert back.omega_ab == -ahead.omega_ab and back.velocity_b_x == -ahead.velocity_b_x
    assert back.omega_dot == pytest.approx(ahead.omega_dot, rel=1e-15)
    assert back.acceleration_b_y == pytest.approx(ahead.acceleration_b_y, rel=1e-12)
    # Fixed steps: out to alpha_end, back towards alpha_start, out again.
    end_index, alpha_step = config.motion.step_count, config.motion.alpha_step
    assert sample_at_step(config, end_index).alpha == math.pi / 2.0
    assert sample_at_step(config, end_index + 1).alpha == (end_index - 1) * alpha_step
    assert sample_at_step(config, end_index + 1).is_reversed
    assert sample_at_step(config, 2 * end_index).alpha == 0.0


def test_stop_ends_exactly_at_alpha_end_or_not_at_all_at_a_dead_point():
    config = _configuration(end_behavior='stop')
    final = sample_at_time(config, 10.0)
    assert final.final and final.alpha == math.pi / 2.0
    assert final.motion_time == config.motion.segment_duration
    last = sample_at_step(config, config.motion.step_count)
    assert last.final and last.alpha == math.pi / 2.0
    assert config.motion.step_count == 180
    assert sample_at_step(config, 179).alpha == 179 * math.radians(0.5)

    blocked = _configuration(end_behavior='stop', omega0=-1.0, alpha_end=-0.5)
    assert blocked.motion.blocked_at == pytest.approx(DEAD_POINT, abs=1e-15)
    assert sample_at_time(blocked, blocked.motion.segment_duration) is None
    assert sample_at_step(blocked, blocked.motion.step_count) is None
    assert not sample_at_step(blocked, blocked.motion.step_count - 1).final


# --- URDF -----------------------------------------------------------------------------------


def _planar_chain(urdf: str, positions: dict[str, float]) -> dict[str, tuple[float, float, float]]:
    """Each link's frame (x, y, heading) from the URDF's joints: origin then rotation about z."""
    root = ElementTree.fromstring(urdf)
    frames = {root.find('link').get('name'): (0.0, 0.0, 0.0)}
    joints = root.findall('joint')
    while len(frames) < len(joints) + 1:
        for joint in joints:
            parent = joint.find('parent').get('link')
            child = joint.find('child').get('link')
            if parent not in frames or child in frames:
                continue
            assert joint.find('axis').get('xyz') == '0 0 1'
            assert joint.find('origin').get('rpy') == '0 0 0'
            x, y, _ = (float(v) for v in joint.find('origin').get('xyz').split())
            px, py, heading = frames[parent]
            frames[child] = (
                px + x * math.cos(heading) - y * math.sin(heading),
                py + x * math.sin(heading) + y * math.cos(heading),
                heading + positions[joint.get('name')],
            )
    return frames


def _point_in(frame: tuple[float, float, float], x: float) -> tuple[float, float]:
    fx, fy, heading = frame
    return fx + x * math.cos(heading), fy + x * math.sin(heading)


@pytest.mark.parametrize('alpha', [-0.03, 0.0, 0.7, math.pi / 2.0, 2.5, 3.17])
def test_urdf_forward_kinematics_lands_on_the_library_pins(alpha):
    state = solve(PAPER, alpha, DriveLaw(2.0))
    positions = dict(zip(DEFAULT_JOINT_NAMES.values(), tree_values(state, Driver.CRANK)[0]))
    urdf = urdf_text(PAPER)
    frames = _planar_chain(urdf, positions)
    assert set(frames) == {'linkage_base', 'disk', 'coupler', 'rocker'}
    assert frames['coupler'][:2] == pytest.approx((state.pin_a_x, state.pin_a_y), abs=1e-12)
    assert frames['rocker'][:2] == pytest.approx((state.pin_b_x, state.pin_b_y), abs=1e-12)
    rocker_end = _point_in(frames['rocker'], PAPER.rocker_length)
    assert rocker_end == pytest.approx((PAPER.ground_x, PAPER.ground_y), abs=1e-12)
    # The disk frame carries A at (0, −OA).
    disk_x, disk_y, heading = frames['disk']
    assert heading == alpha
    assert (disk_x + PAPER.crank_length * math.sin(heading),
            disk_y - PAPER.crank_length * math.cos(heading)) == pytest.approx(
                (state.pin_a_x, state.pin_a_y), abs=1e-12)


def test_installed_urdf_is_the_generated_paper_urdf():
    assert (REPOSITORY / 'urdf' / 'linkage.urdf').read_text() == urdf_text(PAPER)


def test_launch_configs_hold_the_seed_scenarios():
    for name, omega0, k in (('constant', 2.0, 0.0), ('variable', 0.10, 2.3)):
        text = (REPOSITORY / 'config' / f'seed_{name}.yaml').read_text()
        parameters = yaml.safe_load(text)['/**/linkage_node']['ros__parameters']
        config = _configuration(**parameters)
        motion = config.motion
        assert (motion.drive, motion.alpha_start, motion.alpha_end, motion.end_behavior) == (
            DriveLaw(omega0, k), 0.0, math.pi / 2.0, 'stop')
