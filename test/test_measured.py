# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
linkage_node following a measured joint (``source:=measured``), over real DDS.

An encoder process (``encoder_process.py``) publishes a lab's JointState samples; the node
completes the closed chain. Its outputs are checked against the independent mpmath reference
(``reference.py``) to 1e-12, stamp by stamp; a lab-style URDF's forward kinematics at the
measured driver and the published passive joints closes the loop within 1e-12 m; bad samples
are dropped, counted and named, and nothing published or logged holds NaN.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
import json
import math
from pathlib import Path
import subprocess
import sys
from typing import Any
import xml.etree.ElementTree as ElementTree

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from linkage_kinematics.kinematics.geometry import FourBar, preset, TWO_PI
from linkage_kinematics.kinematics.solver import CrankRates
from linkage_kinematics.loops.intake import DropReason, FOUR_BAR_DROPS
from linkage_kinematics.model.joints import Driver, JointStream, Link, TREE_ORDER
from linkage_kinematics.model.urdf import urdf_text
from linkage_kinematics.run.configuration import build_configuration, SourceKind
from linkage_kinematics.run.measured import MeasuredFollower
from linkage_kinematics.run.parameter_specs import parameter_specs
from node_process import (
    Listener,
    NodeProcesses,
    PROCESS_TIMEOUT,
    REPOSITORY,
    ros_context,
    ros_environment,
    stamp_ns,
)
import pytest
from rclpy.qos import QoSProfile
from reference import reference_rocker_driven, reference_state
from rosbags.rosbag2 import Reader
from rosbags.typesys import get_typestore, Stores
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from std_srvs.srv import Trigger
from trajectory_msgs.msg import JointTrajectory
from visualization_msgs.msg import MarkerArray
import yaml

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
PAPER = preset('paper').geometry
CRANK_ROCKER = preset('grashof_crank_rocker').geometry
PARALLELOGRAM = FourBar(0.3, 1.0, 0.3, 1.0, 0.0)
TOLERANCE = 1e-12

# A lab's names and conventions: its crank frame has x along O→A and turns about −z, so
# lab crank = −α + 0.4 (its origin turned by 0.4 − π/2); its coupler and rocker turn about +z
# from origins turned by π/2 + 0.2 and −1.1 (see ``lab_urdf``).
LAB_JOINTS = {
    'joints.crank.name': 'knee_motor', 'joints.crank.direction': -1, 'joints.crank.offset': 0.4,
    'joints.coupler.name': 'knee_link', 'joints.coupler.direction': 1,
    'joints.coupler.offset': -0.2,
    'joints.rocker.name': 'knee_output', 'joints.rocker.direction': 1,
    'joints.rocker.offset': 1.1,
}


@pytest.fixture(scope='module')
def context(domain_id):
    with ros_context(domain_id) as ros:
        yield ros


@dataclass
class Run:
    """What a measured run published (by topic), its node's exit status and its bag."""

    received: dict[str, list[Any]]
    status: int
    bag: Path
    output: str


def sample(stamp: int, names: list[str], positions: list[float], velocities: list[float],
           answered: bool = True) -> dict[str, Any]:
    """One encoder message (stamp in ns) for ``encoder_process.py``."""
    return {'stamp_ns': stamp, 'name': names, 'position': positions, 'velocity': velocities,
            'answered': answered}


@contextmanager
def measured_node(context, nodes: NodeProcesses, tmp_path: Path, parameters: Mapping[str, Any],
                  topic: str = '/measured_joint_states') -> Iterator[tuple[Listener, Any]]:
    """Start a measured node (remapped to ``topic``) and a listener on all its topics."""
    listener = Listener('measured_listener', context)
    for name, msg_type in (('/joint_states', JointState), ('/linkage/state', JointTrajectory),
                           ('/linkage/markers', MarkerArray), ('/diagnostics', DiagnosticArray)):
        listener.subscribe(name, msg_type)
    listener.subscribe('/robot_description', String, transient_local=True)
    remap = [] if topic == '/measured_joint_states' else ['-r', f'measured_joint_states:={topic}']
    process = nodes.start({'source': 'measured', 'log.folder': str(tmp_path / 'bags'),
                           **parameters}, tmp_path / 'node.log', ros_arguments=remap)
    try:
        assert listener.wait_for_publisher('/linkage/state'), (tmp_path / 'node.log').read_text()
        yield listener, process
    finally:
        listener.destroy()


def run_encoder(nodes: NodeProcesses, tmp_path: Path, samples: list[dict[str, Any]],
                listener: Listener, topic: str = '/measured_joint_states') -> None:
    """Run the encoder process over ``samples`` to its end, spinning the listener meanwhile."""
    plan = tmp_path / 'samples.json'
    plan.write_text(json.dumps({'topic': topic, 'state_topic': '/linkage/state',
                                'samples': samples}))
    with open(tmp_path / 'encoder.log', 'w') as log:
        encoder = nodes.add(subprocess.Popen(
            [sys.executable, str(REPOSITORY / 'test' / 'encoder_process.py'), str(plan)],
            env=ros_environment(nodes.domain_id), stdout=log, stderr=subprocess.STDOUT),
            tmp_path / 'encoder.log')
    assert listener.spin_until(lambda: encoder.poll() is not None)
    assert encoder.returncode == 0, (tmp_path / 'encoder.log').read_text()


def follow(context, nodes: NodeProcesses, tmp_path: Path, parameters: Mapping[str, Any],
           samples: list[dict[str, Any]], topic: str = '/measured_joint_states') -> Run:
    """Run a measured node over the encoder's ``samples``, then end it with SIGINT."""
    with measured_node(context, nodes, tmp_path, parameters, topic) as (listener, process):
        run_encoder(nodes, tmp_path, samples, listener, topic)
        answered = sum(item['answered'] for item in samples)
        assert listener.spin_until(lambda: len(listener.received['/linkage/state']) >= answered)
        status = nodes.interrupt(process)
        listener.drain()
    (bag,) = (tmp_path / 'bags').iterdir()
    return Run(listener.received, status, bag, (tmp_path / 'node.log').read_text())


def completed(run: Run, names: tuple[str, ...]) -> list[JointState]:
    """Return the node's joint states: those with exactly the passive joints ``names``."""
    return [message for message in run.received['/joint_states']
            if tuple(message.name) == names]


def assert_stamps_are_the_inputs(run: Run, samples: list[dict[str, Any]],
                                 names: tuple[str, ...]) -> None:
    """Every output is stamped as its input: one joint state and one state per answered one."""
    inputs = [item['stamp_ns'] for item in samples if item['answered']]
    assert [stamp_ns(message) for message in completed(run, names)] == inputs
    assert [stamp_ns(message) for message in run.received['/linkage/state']] == inputs
    assert {stamp_ns(message.markers[0]) for message in run.received['/linkage/markers']} <= (
        set(inputs))


def angle_gap(value: float, expected: float) -> float:
    return abs(math.remainder(value - float(expected), TWO_PI))


def assert_no_nan(value: Any) -> None:
    """Every float in a message (nested) is finite."""
    if isinstance(value, float):
        assert math.isfinite(value)
    elif isinstance(value, (list, tuple)) or type(value).__name__ == 'ndarray':
        for item in value:
            assert_no_nan(item)
    elif hasattr(value, 'get_fields_and_field_types'):
        for field in value.get_fields_and_field_types():
            assert_no_nan(getattr(value, field))
    elif hasattr(value, '__dataclass_fields__'):
        for field in value.__dataclass_fields__:
            assert_no_nan(getattr(value, field))


def bag_messages(bag: Path) -> dict[str, list[Any]]:
    """Every message of a bag, decoded by rosbags (an independent reader), by topic."""
    recorded: dict[str, list[Any]] = {}
    with Reader(bag) as reader:
        for connection, _, raw in reader.messages():
            recorded.setdefault(connection.topic, []).append(
                TYPESTORE.deserialize_cdr(raw, connection.msgtype))
    return recorded


# --- a lab's URDF and its forward kinematics (robot_state_publisher's math, in the plane) ------


def lab_urdf(linkage: FourBar) -> str:
    """
    Return a lab's URDF of the crank-driven chain, in its own conventions (``LAB_JOINTS``).

    Its crank frame has x along O→A (A at (OA, 0)), the coupler's along A→B, the rocker's along
    B→C; the crank joint turns about −z.
    """
    def joint(name, parent, child, xyz, yaw, axis):
        return (f'<joint name="{name}" type="continuous"><parent link="{parent}"/>'
                f'<child link="{child}"/><origin xyz="{xyz}" rpy="0 0 {yaw!r}"/>'
                f'<axis xyz="0 0 {axis}"/></joint>')

    return (
        '<robot name="lab_knee"><link name="hip"/><link name="thigh"/><link name="shank"/>'
        '<link name="foot"/>'
        + joint('knee_motor', 'hip', 'thigh', '0 0 0', 0.4 - math.pi / 2.0, -1)
        + joint('knee_link', 'thigh', 'shank', f'{linkage.crank_length!r} 0 0',
                math.pi / 2.0 + 0.2, 1)
        + joint('knee_output', 'shank', 'foot', f'{linkage.coupler_length!r} 0 0', -1.1, 1)
        + '</robot>'
    )


def chain_end(urdf: str, positions: Mapping[str, float], end: float) -> tuple[float, float]:
    """
    Return where the point (``end``, 0, 0) of the chain's last link lands in the root frame.

    robot_state_publisher's transform of each joint: origin (xyz, then rpy) times the rotation
    about its axis by the joint position; here every axis is ±z and every rpy a yaw.
    """
    robot = ElementTree.fromstring(urdf)
    joints = {joint.find('parent').get('link'): joint for joint in robot.iter('joint')}
    children = {joint.find('child').get('link') for joint in joints.values()}
    (link,) = set(joints) - children
    x = y = heading = 0.0
    while link in joints:
        joint = joints[link]
        origin = joint.find('origin')
        ox, oy, _ = map(float, origin.get('xyz').split())
        yaw = float(origin.get('rpy').split()[2])
        axis = float(joint.find('axis').get('xyz').split()[2])
        x += ox * math.cos(heading) - oy * math.sin(heading)
        y += ox * math.sin(heading) + oy * math.cos(heading)
        heading += yaw + axis * positions[joint.get('name')]
        link = joint.find('child').get('link')
    return x + end * math.cos(heading), y + end * math.sin(heading)


# --- the crank measured under a lab's names and conventions --------------------------------


def test_a_lab_crank_wrapping_at_pi_is_completed_to_the_reference(context, nodes, tmp_path):
    """
    Three full turns of a crank-rocker, the encoder wrapping at ±π, next to an unrelated joint.

    Published under the lab's names with a reversed axis and offsets, on /joint_states itself
    (the node hears its own output there and ignores it).
    """
    linkage = CRANK_ROCKER
    samples = []
    crank_inputs = {}
    for index in range(300):
        stamp = 1_000_000_000 + index * 10_000_000
        alpha = 0.3 + 0.065 * index + 0.2 * math.sin(0.05 * index)
        omega = 6.5 + 1.0 * math.cos(0.05 * index)
        lab_angle = math.remainder(-alpha + 0.4, TWO_PI)  # the lab's encoder wraps at ±π
        samples.append(sample(stamp, ['gripper_finger', 'knee_motor'], [0.01 * index, lab_angle],
                              [0.0, -omega]))
        crank_inputs[stamp] = (-(lab_angle - 0.4), omega, lab_angle, alpha)
    run = follow(context, nodes, tmp_path, {'preset': 'grashof_crank_rocker',
                                            'measured.timeout': PROCESS_TIMEOUT, **LAB_JOINTS},
                 samples, topic='/joint_states')
    assert run.status == 0, run.output
    names = ('knee_link', 'knee_output')
    assert_stamps_are_the_inputs(run, samples, names)
    urdf = lab_urdf(linkage)
    (description,) = run.received['/robot_description']
    previous = None
    for message in completed(run, names):
        alpha, omega, lab_angle, _ = crank_inputs[stamp_ns(message)]
        reference = reference_state(linkage, alpha, CrankRates(omega, 0.0))
        coupler, rocker = message.position
        assert angle_gap(coupler, reference['gamma'] - reference['alpha'] - 0.2) < TOLERANCE
        assert angle_gap(rocker, -reference['beta'] - reference['gamma'] + 1.1) < TOLERANCE
        coupler_rate = float(reference['omega_ab'] - reference['omega'])
        rocker_rate = float(reference['omega_bc'] - reference['omega_ab'])
        assert message.velocity[0] == pytest.approx(coupler_rate, abs=TOLERANCE * omega)
        assert message.velocity[1] == pytest.approx(rocker_rate, abs=TOLERANCE * omega)
        if previous is not None:  # continuous across the encoder's wraps
            assert all(abs(now - before) < 1.0
                       for now, before in zip(message.position, previous))
        previous = message.position
        # Forward kinematics at the measured driver and the published passive joints closes
        # the loop on C, in the lab's URDF and in the node's own.
        positions = {'knee_motor': lab_angle, 'knee_link': coupler, 'knee_output': rocker}
        for model in (urdf, description.data):
            end = chain_end(model, positions, linkage.rocker_length)
            assert end == pytest.approx((linkage.ground_x, linkage.ground_y), abs=TOLERANCE)
    # α in linkage/state is the crank's, unwrapped over the three turns.
    alphas = [message.points[0].positions[0] for message in run.received['/linkage/state']]
    assert alphas[-1] - alphas[0] > 3.0 * TWO_PI
    for message, alpha in zip(run.received['/linkage/state'], alphas):
        assert alpha == pytest.approx(crank_inputs[stamp_ns(message)][3], abs=TOLERANCE)


# --- the rocker as the driver -----------------------------------------------------------------


def test_the_seed_mechanism_driven_by_its_rocker_matches_the_reference(context, nodes, tmp_path):
    """The seed's rocker turned through β = 0 … 86° in 0.5° steps (θ_BC = π − β), measured."""
    samples = []
    rocker_inputs = {}
    for index in range(173):
        stamp = 2_000_000_000 + index * 5_000_000
        theta = math.pi - math.radians(0.5 * index)
        omega_bc = -1.7
        samples.append(sample(stamp, ['rocker_joint'], [theta], [omega_bc]))
        rocker_inputs[stamp] = (theta, omega_bc)
    run = follow(context, nodes, tmp_path,
                 {'driver': 'rocker', 'measured.timeout': PROCESS_TIMEOUT}, samples)
    assert run.status == 0, run.output
    names = ('coupler_joint', 'crank_joint')
    assert_stamps_are_the_inputs(run, samples, names)
    (description,) = run.received['/robot_description']
    for message, state in zip(completed(run, names), run.received['/linkage/state']):
        theta, omega_bc = rocker_inputs[stamp_ns(message)]
        reference = reference_rocker_driven(PAPER, theta, CrankRates(omega_bc, 0.0))
        coupler, crank = message.position
        assert angle_gap(coupler, reference['gamma'] + reference['beta']) < TOLERANCE
        assert angle_gap(crank, reference['alpha'] - reference['gamma'] - math.pi / 2) < (
            TOLERANCE)
        scale = TOLERANCE * max(1.0, abs(float(reference['omega'])))
        assert message.velocity[0] == pytest.approx(
            float(reference['omega_ab'] - reference['omega_bc']), abs=scale)
        assert message.velocity[1] == pytest.approx(
            float(reference['omega'] - reference['omega_ab']), abs=scale)
        positions, velocities = state.points[0].positions, state.points[0].velocities
        assert angle_gap(positions[0], reference['alpha']) < TOLERANCE
        assert angle_gap(positions[7], theta) < TOLERANCE  # rocker_angle is the measured θ_BC
        assert velocities[7] == omega_bc
        # The node's URDF is the rocker-rooted tree: it closes the loop on O.
        end = chain_end(description.data, {'rocker_joint': theta, 'coupler_joint': coupler,
                                           'crank_joint': crank}, PAPER.crank_length)
        assert end == pytest.approx((0.0, 0.0), abs=TOLERANCE)
    first = run.received['/linkage/state'][0].points[0].positions
    last = run.received['/linkage/state'][-1].points[0].positions
    assert (math.degrees(first[1]), math.degrees(last[1])) == pytest.approx((0.0, 86.0))


# --- through change points, with the velocity estimated ------------------------------------


def test_a_parallelogram_goes_through_its_change_points_with_estimated_velocity(
        context, nodes, tmp_path):
    """
    The parallelogram 0.3/1.0/0.3/1.0 (assembly −1 at α = 0) over two turns, positions only.

    Every 0.5°: the change points (90°, 270°) are samples. It stays a parallelogram (γ = 0, the
    coupler joint −α, the rocker joint α + π/2) and the passive velocities are the exact
    functions of the estimated ω, the backward difference of the angles.
    """
    samples = []
    alphas = {}
    for index in range(1441):
        stamp = 3_000_000_000 + index * 2_000_000
        alpha = math.radians(0.5 * index)
        samples.append(sample(stamp, ['crank_joint'], [math.remainder(alpha, TWO_PI)], []))
        alphas[stamp] = alpha
    run = follow(context, nodes, tmp_path, {
        'preset': '', 'crank_length': 0.3, 'coupler_length': 1.0, 'rocker_length': 0.3,
        'ground_x': 1.0, 'ground_y': 0.0, 'branch': -1,
        'measured.timeout': PROCESS_TIMEOUT}, samples)
    assert run.status == 0, run.output
    names = ('coupler_joint', 'rocker_joint')
    assert_stamps_are_the_inputs(run, samples, names)
    previous = None  # (stamp, unwrapped angle), as the node keeps them
    for message in completed(run, names):
        stamp = stamp_ns(message)
        alpha = alphas[stamp]
        coupler, rocker = message.position
        assert angle_gap(coupler, -alpha) < TOLERANCE
        assert angle_gap(rocker, alpha + math.pi / 2.0) < TOLERANCE
        wrapped = math.remainder(alpha, TWO_PI)
        if previous is None:
            omega, unwrapped = 0.0, wrapped  # a first sample has nothing to difference
        else:
            unwrapped = wrapped + round((previous[1] - wrapped) / TWO_PI) * TWO_PI
            omega = (unwrapped - previous[1]) / ((stamp - previous[0]) * 1e-9)
        assert tuple(message.velocity) == pytest.approx((-omega, omega), abs=TOLERANCE)
        previous = (stamp, unwrapped)
    diagnostics = [status for message in run.received['/diagnostics']
                   for status in message.status]
    values = {item.key: item.value for item in diagnostics[-1].values}
    assert values['estimated'].startswith('crank angular velocity (estimated (backward')


# --- bad samples ----------------------------------------------------------------------------


def test_bad_samples_are_dropped_counted_and_named_and_nothing_is_nan(context, nodes, tmp_path):
    """
    Each kind of bad sample between valid ones; then silence until the timeout.

    Each is dropped (no output at its stamp), counted and named in a WARN status; the node's own
    joint states heard back are ignored; no NaN on any topic or in the bag; after the timeout
    the status is ERROR and the node keeps running until SIGINT.
    """
    ms = 1_000_000
    crank = ['crank_joint']
    samples = [
        sample(1 * ms, crank, [0.0], [1.0]),
        sample(2 * ms, crank, [math.nan], [1.0], answered=False),
        sample(3 * ms, crank, [0.01], [1.0]),
        sample(4 * ms, crank, [0.011], [math.inf], answered=False),
        sample(5 * ms, ['gripper_finger'], [0.2], [], answered=False),
        sample(2 * ms, crank, [0.012], [1.0], answered=False),  # older than the last used
        sample(3 * ms, crank, [0.012], [1.0], answered=False),  # as old as the last used
        sample(8 * ms, crank, [-0.1], [1.0], answered=False),  # past the dead point at −1.94°
        sample(9 * ms, crank, [1.5], [1.0], answered=False),  # a jump of 1.49 rad
        {**sample(9 * ms, crank, [0.02], [1.0], answered=False), 'truncate': 30},  # cut short
        sample(10 * ms, crank, [0.02], [1.0]),
        sample(11 * ms, ['coupler_joint', 'rocker_joint'], [0.0, 0.0], [], answered=False),
        sample(12 * ms, crank, [0.03], [1.0]),
    ]
    with measured_node(context, nodes, tmp_path, {'measured.max_jump': 1.0,
                                                  'measured.timeout': 2.0}) as (listener, process):
        run_encoder(nodes, tmp_path, samples, listener)

        def statuses() -> list[DiagnosticStatus]:
            return [status for message in listener.received['/diagnostics']
                    for status in message.status]

        def timed_out() -> bool:
            return any(status.level == DiagnosticStatus.ERROR
                       and status.message.startswith('no valid sample of crank_joint for')
                       for status in statuses())

        assert listener.spin_until(timed_out)
        assert process.poll() is None, 'the node must keep running'
        assert nodes.interrupt(process) == 0
        listener.drain()
    run = Run(listener.received, 0, next((tmp_path / 'bags').iterdir()),
              (tmp_path / 'node.log').read_text())
    assert_stamps_are_the_inputs(run, samples, ('coupler_joint', 'rocker_joint'))
    warnings = ' '.join(status.message for status in statuses()
                        if status.level == DiagnosticStatus.WARN)
    for rejection in FOUR_BAR_DROPS:
        assert rejection.value in warnings
    values = {item.key: item.value for item in statuses()[-1].values}
    expected = {DropReason.NON_FINITE: 2, DropReason.NO_DRIVER: 1,
                DropReason.STAMP_NOT_NEWER: 2, DropReason.DRIVER_UNREACHABLE: 1,
                DropReason.JUMP: 1, DropReason.MALFORMED: 1}
    for rejection, count in expected.items():
        assert values[f'dropped {rejection.value}'] == str(count)
    assert values['dropped samples'] == '8'
    assert values['valid samples'] == '4'
    for messages in run.received.values():
        for message in messages:
            assert_no_nan(message)
    recorded = bag_messages(run.bag)
    assert len(recorded['/linkage/state']) == 4
    for messages in recorded.values():
        for message in messages:
            assert_no_nan(message)


def test_the_lab_parameters_file_is_the_mapping_tested_here_and_a_valid_configuration():
    entries = yaml.safe_load((REPOSITORY / 'config' / 'measured_lab.yaml').read_text())
    values = entries['/**/linkage_node']['ros__parameters']
    assert {name: values[name] for name in LAB_JOINTS} == LAB_JOINTS
    defaults = {spec.name: spec.default for spec in parameter_specs(values['preset'])}
    config = build_configuration({**defaults, **values})
    joints = config.joints
    assert (joints.source, joints.driver, joints.publish_robot_description) == (
        SourceKind.MEASURED, Driver.CRANK, False)
    # docs/following_loops.md's worked example: at α = 0.5 rad the encoder reads −0.1 rad.
    state = MeasuredFollower(config).follow(1, ['knee_motor'], [-0.1], [1.0]).state
    assert state.alpha == pytest.approx(0.5, abs=1e-15)
    assert math.remainder(state.gamma - state.alpha - 0.2, TWO_PI) == pytest.approx(
        0.2090, abs=1e-4)
    assert math.remainder(-state.beta - state.gamma + 1.1, TWO_PI) == pytest.approx(
        -1.0141, abs=1e-4)


@pytest.mark.parametrize('driver', list(Driver))
def test_the_nodes_urdf_closes_the_loop_at_the_published_values_for_each_driver(driver):
    """
    The node's URDF, with the lab's names, reversed axes and offsets, for each driver's tree.

    Forward kinematics at the driver's lab value and the passive joints a JointStream gives
    lands the chain's end on the cut pivot (C for the crank, O for the rocker) within 1e-12 m,
    over two turns of the driver; the URDF's joints are exactly the published ones.
    """
    mapping = {**LAB_JOINTS, 'joints.rocker.direction': -1}
    defaults = {spec.name: spec.default for spec in parameter_specs('grashof_crank_rocker')}
    config = build_configuration({**defaults, **mapping, 'source': 'measured',
                                  'driver': driver.value})
    linkage = config.geometry.linkage
    urdf = urdf_text(linkage, config.outputs.frame_id, config.joints.lab, driver)
    order = TREE_ORDER[driver]
    names = config.joints.lab.names(order)
    assert {joint.get('name') for joint in ElementTree.fromstring(urdf).iter('joint')} == set(
        names)
    stream = JointStream(config.joints.lab, driver, include_driver=False)
    assert stream.names == names[1:]
    driver_mapping = config.joints.lab[Link(driver.value)]
    follower = MeasuredFollower(config)
    interval = config.geometry.driven_linkage.reachability.intervals[0]
    low, high = interval
    span = high - low if high - low < TWO_PI else TWO_PI
    end = (linkage.rocker_length, (linkage.ground_x, linkage.ground_y)) if (
        driver is Driver.CRANK) else (linkage.crank_length, (0.0, 0.0))
    for index in range(1, 200):
        node_angle = low + span * (0.5 - 0.49 * math.cos(math.pi * index / 50.0))
        lab_angle = driver_mapping.to_lab(node_angle)
        followed = follower.follow(index, [names[0]], [lab_angle], [1.0])
        positions, _ = stream.values(followed.state)
        assert math.remainder(positions[0] - lab_angle, TWO_PI) == pytest.approx(0.0, abs=1e-12)
        values = {names[0]: lab_angle, **dict(zip(stream.names, positions[stream.published]))}
        assert chain_end(urdf, values, end[0]) == pytest.approx(end[1], abs=TOLERANCE)


def test_the_services_pause_and_resume_following_and_autostart_false_waits(
        context, nodes, tmp_path):
    """
    With autostart false nothing is followed until ~/resume; ~/pause ignores samples.

    Each sample is published only after the service's answer came back, so the node has acted
    on the call before the sample arrives.
    """
    with measured_node(context, nodes, tmp_path, {'autostart': False, 'log.enabled': False,
                                                  'measured.timeout': PROCESS_TIMEOUT}) as (
            listener, process):
        clients = {name: listener.node.create_client(Trigger, f'/linkage_node/{name}')
                   for name in ('pause', 'resume', 'reset')}
        for client in clients.values():
            assert client.wait_for_service(timeout_sec=PROCESS_TIMEOUT)

        def call(name: str) -> Trigger.Response:
            return listener.result_of(clients[name].call_async(Trigger.Request()))

        encoder = listener.node.create_publisher(JointState, '/measured_joint_states',
                                                 QoSProfile(depth=10))
        assert listener.spin_until(lambda: encoder.get_subscription_count() > 0)

        def publish(stamp: int, angle: float) -> None:
            message = JointState(name=['crank_joint'], position=[angle], velocity=[1.0])
            message.header.stamp.sec, message.header.stamp.nanosec = divmod(
                stamp, 1_000_000_000)
            encoder.publish(message)

        states = listener.received['/linkage/state']
        assert not call('pause').success  # autostart false: paused already
        resumed = call('resume')
        assert (resumed.success, resumed.message) == (
            True, 'following crank_joint again from its next sample')
        publish(1_000_000, 0.1)
        assert listener.spin_until(lambda: len(states) == 1)
        assert call('pause').success
        publish(2_000_000, 0.2)  # ignored
        assert call('resume').success
        publish(3_000_000, 0.3)
        assert listener.spin_until(lambda: len(states) == 2)
        reset = call('reset')
        assert (reset.success, reset.message) == (
            True, 'the motion starts afresh at the next valid sample')
        publish(4_000_000, 0.4)
        assert listener.spin_until(lambda: len(states) == 3)
        assert [stamp_ns(state) for state in states] == [1_000_000, 3_000_000, 4_000_000]
        # After the reset the motion started afresh: its time counts from that sample.
        assert states[2].points[0].time_from_start.sec == 0
        assert states[2].points[0].time_from_start.nanosec == 0
        assert process.poll() is None
