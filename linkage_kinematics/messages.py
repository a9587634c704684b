# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
ROS messages built from a LinkageState: the node's topics, reusable by benchmarks and tools.

Each builder is a plain function of the library's state (plus a stamp); none computes any
kinematics. The node does not build its per-tick messages and the scene: their encoders
(``JointStateEncoder``, ``LinkageStateEncoder``, ``MarkerArrayEncoder``) write the same bytes
as ``encode_cdr`` of the builders' messages straight from the state, from the same value
functions, into a layout prepared once per geometry (``recording.FixedShapeEncoder``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
import math

from builtin_interfaces.msg import Duration, Time
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import Point
from linkage_kinematics.bag_reader import STATE_JOINT_NAMES
from linkage_kinematics.geometry import FourBar
from linkage_kinematics.kinematics import LinkageState
from linkage_kinematics.recording import FixedShapeEncoder
from sensor_msgs.msg import JointState
from std_msgs.msg import ColorRGBA
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint
from visualization_msgs.msg import Marker, MarkerArray

MARKER_NAMESPACE = 'linkage'
# Marker ids are fixed so that every MarkerArray updates the same markers in place.
DISK_ID, BARS_ID, PIN_A_ID, PIN_B_ID, PIVOT_O_ID, PIVOT_C_ID = range(6)

_DISK_THICKNESS = 0.01  # m; the disk is drawn just below the plane of the bars
_BAR_WIDTH = 0.02  # m
_PIN_DIAMETER = 0.05  # m
_PIVOT_SIZE = 0.07  # m


def _color(red: float, green: float, blue: float, alpha: float = 1.0) -> ColorRGBA:
    return ColorRGBA(r=red, g=green, b=blue, a=alpha)


DISK_COLOR = _color(0.55, 0.6, 0.7, 0.6)
CRANK_COLOR = _color(0.2, 0.3, 0.9)
COUPLER_COLOR = _color(0.95, 0.55, 0.1)
ROCKER_COLOR = _color(0.15, 0.7, 0.3)
PIN_COLOR = _color(0.85, 0.1, 0.1)
PIVOT_COLOR = _color(0.15, 0.15, 0.15)


def time_msg(nanoseconds: int) -> Time:
    """Return a builtin_interfaces/Time from integer nanoseconds."""
    return Time(sec=nanoseconds // 1_000_000_000, nanosec=nanoseconds % 1_000_000_000)


def duration_msg(seconds: float) -> Duration:
    """Return a builtin_interfaces/Duration from (non-negative) seconds."""
    sec, nanosec = duration_fields(seconds)
    return Duration(sec=sec, nanosec=nanosec)


def duration_fields(seconds: float) -> tuple[int, int]:
    """(sec, nanosec) of a builtin_interfaces/Duration of (non-negative) ``seconds``."""
    return divmod(round(seconds * 1e9), 1_000_000_000)


def _stamp_paths(prefix: str) -> list[str]:
    return [f'{prefix}header.stamp.sec', f'{prefix}header.stamp.nanosec']


def joint_state(
    names: Sequence[str],
    positions: Sequence[float],
    velocities: Sequence[float],
    stamp: Time,
) -> JointState:
    """/joint_states of ``joints.JointStream`` values, frame_id empty (joint_state_publisher's)."""
    message = JointState(name=list(names), position=list(positions), velocity=list(velocities))
    message.header.stamp = stamp
    return message


class JointStateEncoder:
    """The bytes of ``joint_state`` (encode_cdr) for fixed joint names, straight from values."""

    def __init__(self, names: Sequence[str]) -> None:
        count = len(names)
        template = JointState(name=list(names), position=[0.0] * count, velocity=[0.0] * count)
        self._encoder = FixedShapeEncoder(template, [*_stamp_paths(''), 'position', 'velocity'])

    def encode(
        self, stamp_ns: int, positions: Sequence[float], velocities: Sequence[float]
    ) -> bytes:
        return self._encoder.encode((*divmod(stamp_ns, 1_000_000_000), *positions, *velocities))


def state_coordinates(
    linkage: FourBar, state: LinkageState
) -> tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]:
    """
    Return the positions.

    Velocities and accelerations of ``STATE_JOINT_NAMES`` (see ``linkage_state``).
    """
    crank = linkage.crank_length
    rocker = linkage.rocker_length
    return (
        (
            state.alpha, state.beta, state.gamma,
            state.pin_a_x, state.pin_a_y, state.pin_b_x, state.pin_b_y,
            math.pi - state.beta, crank * state.alpha, rocker * state.beta,
        ),
        (
            state.omega, -state.omega_bc, state.omega_ab,
            state.velocity_a_x, state.velocity_a_y, state.velocity_b_x, state.velocity_b_y,
            state.omega_bc, crank * state.omega, -rocker * state.omega_bc,
        ),
        (
            state.omega_dot, -state.omega_dot_bc, state.omega_dot_ab,
            state.acceleration_a_x, state.acceleration_a_y,
            state.acceleration_b_x, state.acceleration_b_y,
            state.omega_dot_bc, crank * state.omega_dot, -rocker * state.omega_dot_bc,
        ),
    )


def linkage_state(
    linkage: FourBar,
    state: LinkageState,
    stamp: Time,
    motion_time: float,
    frame_id: str,
) -> JointTrajectory:
    """
    /linkage/state: the full state as one trajectory point (see README, "Topics").

    ``positions``, ``velocities`` and ``accelerations`` hold each coordinate of
    ``STATE_JOINT_NAMES`` and its first and second time derivatives: α, β, γ, A_x, A_y, B_x,
    B_y, then the rocker angle θ_BC = π − β (rates ω_BC, ω̇_BC) and the arc coordinates of the
    pins along their circles, OA·α (rate V_A = OA·ω) and BC·β (rate V_B = −BC·ω_BC), so that
    every quantity of the paper is one plain field. ``motion_time`` (s) is the drive-law time
    since the motion left alpha_start.
    """
    positions, velocities, accelerations = state_coordinates(linkage, state)
    point = JointTrajectoryPoint(
        positions=positions,
        velocities=velocities,
        accelerations=accelerations,
        time_from_start=duration_msg(motion_time),
    )
    message = JointTrajectory(joint_names=list(STATE_JOINT_NAMES), points=[point])
    message.header.stamp = stamp
    message.header.frame_id = frame_id
    return message


class LinkageStateEncoder:
    """
    The bytes of ``linkage_state`` (encode_cdr) of one linkage and frame.

    Straight from a state.
    """

    def __init__(self, linkage: FourBar, frame_id: str) -> None:
        self._linkage = linkage
        zeros = [0.0] * len(STATE_JOINT_NAMES)
        point = JointTrajectoryPoint(positions=zeros, velocities=zeros, accelerations=zeros)
        template = JointTrajectory(joint_names=list(STATE_JOINT_NAMES), points=[point])
        template.header.frame_id = frame_id
        self._encoder = FixedShapeEncoder(template, [
            *_stamp_paths(''), 'points[0].positions', 'points[0].velocities',
            'points[0].accelerations', 'points[0].time_from_start.sec',
            'points[0].time_from_start.nanosec',
        ])

    def encode(self, state: LinkageState, stamp_ns: int, motion_time: float) -> bytes:
        positions, velocities, accelerations = state_coordinates(self._linkage, state)
        return self._encoder.encode((
            *divmod(stamp_ns, 1_000_000_000), *positions, *velocities, *accelerations,
            *duration_fields(motion_time),
        ))


def _marker(marker_id: int, marker_type: int, frame_id: str, color: ColorRGBA) -> Marker:
    marker = Marker(ns=MARKER_NAMESPACE, id=marker_id, type=marker_type, action=Marker.ADD)
    marker.header.frame_id = frame_id
    marker.pose.orientation.w = 1.0
    marker.color = color
    return marker


def disk_orientation(state: LinkageState) -> tuple[float, float]:
    """
    (z, w) of the disk's quaternion.

    The disk is symmetric about O, and turning it shows the crank angle on the disk itself.
    """
    return math.sin(0.5 * state.alpha), math.cos(0.5 * state.alpha)


def marker_array(
    linkage: FourBar,
    state: LinkageState,
    stamp: Time,
    frame_id: str,
) -> MarkerArray:
    """
    /linkage/markers.

    Disk (CYLINDER at O), the three bars (one LINE_LIST coloured per bar), pins A and B (SPHEREs)
    and the ground pivots O and C (CUBEs), in namespace ``linkage``.
    """
    message = _new_marker_array(linkage, frame_id)
    disk, bars, pin_a, pin_b, pivot_o, pivot_c = message.markers
    pin_a_point = Point(x=state.pin_a_x, y=state.pin_a_y)
    pin_b_point = Point(x=state.pin_b_x, y=state.pin_b_y)
    bars.points[1] = pin_a_point
    bars.points[2] = pin_a_point
    bars.points[3] = pin_b_point
    bars.points[4] = pin_b_point
    pin_a.pose.position = pin_a_point
    pin_b.pose.position = pin_b_point
    disk.pose.orientation.z, disk.pose.orientation.w = disk_orientation(state)
    for marker in message.markers:
        marker.header.stamp = stamp
    return message


class MarkerArrayEncoder:
    """
    The bytes of ``marker_array`` (encode_cdr) of one linkage and frame.

    Straight from a state.
    """

    _PIN_A_PATHS = (f'markers[{BARS_ID}].points[1]', f'markers[{BARS_ID}].points[2]',
                    f'markers[{PIN_A_ID}].pose.position')
    _PIN_B_PATHS = (f'markers[{BARS_ID}].points[3]', f'markers[{BARS_ID}].points[4]',
                    f'markers[{PIN_B_ID}].pose.position')

    def __init__(self, linkage: FourBar, frame_id: str) -> None:
        template = _new_marker_array(linkage, frame_id)
        self._marker_count = len(template.markers)
        varying = [path for index in range(self._marker_count)
                   for path in _stamp_paths(f'markers[{index}].')]
        varying += [f'{point}.{axis}' for point in self._PIN_A_PATHS + self._PIN_B_PATHS
                    for axis in 'xy']
        varying += [f'markers[{DISK_ID}].pose.orientation.z',
                    f'markers[{DISK_ID}].pose.orientation.w']
        self._encoder = FixedShapeEncoder(template, varying)

    def encode(self, state: LinkageState, stamp_ns: int) -> bytes:
        pin_a = (state.pin_a_x, state.pin_a_y)
        pin_b = (state.pin_b_x, state.pin_b_y)
        return self._encoder.encode((
            *divmod(stamp_ns, 1_000_000_000) * self._marker_count,
            *pin_a * len(self._PIN_A_PATHS), *pin_b * len(self._PIN_B_PATHS),
            *disk_orientation(state),
        ))


def _new_marker_array(linkage: FourBar, frame_id: str) -> MarkerArray:
    disk = _marker(DISK_ID, Marker.CYLINDER, frame_id, DISK_COLOR)
    disk.pose.position.z = -_DISK_THICKNESS
    disk.scale.x = disk.scale.y = 2.0 * linkage.crank_length
    disk.scale.z = _DISK_THICKNESS

    bars = _marker(BARS_ID, Marker.LINE_LIST, frame_id, CRANK_COLOR)
    bars.scale.x = _BAR_WIDTH
    ground_c = Point(x=linkage.ground_x, y=linkage.ground_y)
    # O→A, A→B, B→C; points 1–4 are replaced with A and B on every update.
    bars.points = [Point(), Point(), Point(), Point(), Point(), ground_c]
    bars.colors = [CRANK_COLOR, CRANK_COLOR, COUPLER_COLOR, COUPLER_COLOR,
                   ROCKER_COLOR, ROCKER_COLOR]

    pins = []
    for marker_id in (PIN_A_ID, PIN_B_ID):
        pin = _marker(marker_id, Marker.SPHERE, frame_id, PIN_COLOR)
        pin.scale.x = pin.scale.y = pin.scale.z = _PIN_DIAMETER
        pins.append(pin)

    pivots = []
    for marker_id, position in ((PIVOT_O_ID, Point()), (PIVOT_C_ID, ground_c)):
        pivot = _marker(marker_id, Marker.CUBE, frame_id, PIVOT_COLOR)
        pivot.pose.position = position
        pivot.scale.x = pivot.scale.y = pivot.scale.z = _PIVOT_SIZE
        pivots.append(pivot)
    return MarkerArray(markers=[disk, bars, *pins, *pivots])


def diagnostic_array(
    stamp: Time,
    name: str,
    hardware_id: str,
    level: bytes,
    message: str,
    values: Mapping[str, str],
) -> DiagnosticArray:
    """/diagnostics with one status, in diagnostic_updater's layout (name "<node>: <task>")."""
    status = DiagnosticStatus(
        level=level,
        name=name,
        message=message,
        hardware_id=hardware_id,
        values=[KeyValue(key=key, value=value) for key, value in values.items()],
    )
    array = DiagnosticArray(status=[status])
    array.header.stamp = stamp
    return array
