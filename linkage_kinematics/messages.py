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
from geometry_msgs.msg import Point, TransformStamped
from linkage_kinematics.bag_reader import STATE_JOINT_NAMES
from linkage_kinematics.geometry import FourBar
from linkage_kinematics.kinematics import LinkageState, unwrap_near
from linkage_kinematics.recording import encode_cdr, FixedShapeEncoder
from linkage_kinematics.robot_transforms import RobotTransforms, Transform
from rosidl_parser.definition import NamespacedType, UnboundedSequence
from sensor_msgs.msg import JointState
from std_msgs.msg import ColorRGBA
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint
from visualization_msgs.msg import Marker, MarkerArray

JOINT_NAMES = ('crank_joint', 'coupler_joint', 'rocker_joint')
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


def joint_positions(
    state: LinkageState, previous: Sequence[float] = (0.0, 0.0, 0.0)
) -> tuple[float, float, float]:
    """
    URDF joint positions (crank, coupler, rocker) = (α, γ − α, −β − γ) in rad.

    The coupler and rocker positions are shifted by whole turns to lie within π of
    ``previous`` (the last published positions), so a stream of them is continuous.
    """
    return (
        state.alpha,
        unwrap_near(state.gamma - state.alpha, previous[1]),
        unwrap_near(-state.beta - state.gamma, previous[2]),
    )


def joint_velocities(state: LinkageState) -> tuple[float, float, float]:
    """URDF joint velocities (ω, ω_AB − ω, ω_BC − ω_AB) in rad/s."""
    return (state.omega, state.omega_ab - state.omega, state.omega_bc - state.omega_ab)


def joint_state(
    state: LinkageState,
    stamp: Time,
    previous_positions: Sequence[float] = (0.0, 0.0, 0.0),
) -> JointState:
    """/joint_states: the URDF's three joints; frame_id stays empty as joint_state_publisher's."""
    message = JointState(name=list(JOINT_NAMES))
    message.header.stamp = stamp
    message.position = joint_positions(state, previous_positions)
    message.velocity = joint_velocities(state)
    return message


class JointStateEncoder:
    """The bytes of ``joint_state`` (encode_cdr), straight from a state."""

    def __init__(self) -> None:
        template = JointState(name=list(JOINT_NAMES), position=[0.0] * 3, velocity=[0.0] * 3)
        self._encoder = FixedShapeEncoder(template, [*_stamp_paths(''), 'position', 'velocity'])

    def encode(self, state: LinkageState, stamp_ns: int, positions: Sequence[float]) -> bytes:
        """
        ``positions`` are ``joint_positions`` of ``state``.

        Unwrapped as the caller keeps them.
        """
        return self._encoder.encode(
            (*divmod(stamp_ns, 1_000_000_000), *positions, *joint_velocities(state))
        )


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


class TFMessage:
    """
    tf2_msgs/msg/TFMessage for ``encode_cdr`` and ``FixedShapeEncoder``.

    tf2_msgs has no Python package on PyPI, so rclpy's generated class cannot be imported
    everywhere the node runs. This class has what the encoders and the recorder read of a
    generated one: its field, the field's rosidl type and the module name ``tf2_msgs.msg`` by
    which ``recording.ros_type_name`` names the type. Its .msg text and RIHS01 hash are shipped
    with the package (``interfaces/tf2_msgs``). The node logs /tf and /tf_static but never
    publishes them (robot_state_publisher does that live), so no type support is needed.
    """

    __module__ = 'tf2_msgs.msg'
    __slots__ = ('transforms',)
    SLOT_TYPES = (UnboundedSequence(NamespacedType(['geometry_msgs', 'msg'], 'TransformStamped')),)

    def __init__(self, transforms: Sequence[TransformStamped] = ()) -> None:
        self.transforms = list(transforms)

    @classmethod
    def get_fields_and_field_types(cls) -> dict[str, str]:
        return {'transforms': 'sequence<geometry_msgs/TransformStamped>'}


def tf_message(transforms: Sequence[Transform], stamp: Time) -> TFMessage:
    """/tf or /tf_static: ``transforms``, each stamped ``stamp``."""
    message = TFMessage()
    for transform in transforms:
        stamped = TransformStamped(child_frame_id=transform.child_frame)
        stamped.header.stamp = stamp
        stamped.header.frame_id = transform.parent_frame
        translation = stamped.transform.translation
        translation.x, translation.y, translation.z = transform.translation
        rotation = stamped.transform.rotation
        rotation.x, rotation.y, rotation.z, rotation.w = transform.rotation
        message.transforms.append(stamped)
    return message


class TFMessageEncoder:
    """
    The bytes of ``tf_message`` (encode_cdr) for one list of parent and child frames.

    Straight from the transforms.
    """

    def __init__(self, frames: Sequence[tuple[str, str]]) -> None:
        self.frames = tuple(frames)
        template = tf_message(
            [Transform(parent, child, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
             for parent, child in self.frames],
            time_msg(0),
        )
        varying = []
        for index in range(len(self.frames)):
            varying += _stamp_paths(f'transforms[{index}].')
            varying += [f'transforms[{index}].transform.{part}.{axis}'
                        for part, axes in (('translation', 'xyz'), ('rotation', 'xyzw'))
                        for axis in axes]
        self._encoder = FixedShapeEncoder(template, varying)

    def encode(self, transforms: Sequence[Transform], stamp_ns: int) -> bytes:
        """Return the message of ``transforms`` (between ``frames``, in that order)."""
        stamp = divmod(stamp_ns, 1_000_000_000)
        values: list[float] = []
        for (parent, child), transform in zip(self.frames, transforms, strict=True):
            if (transform.parent_frame, transform.child_frame) != (parent, child):
                raise ValueError(f'{transform.parent_frame} → {transform.child_frame} is not '
                                 f'the encoder’s {parent} → {child}')
            values += (*stamp, *transform.translation, *transform.rotation)
        return self._encoder.encode(tuple(values))


class RobotStateTransforms:
    """
    The /tf_static and /tf messages robot_state_publisher publishes for one URDF, as bytes.

    With robot_state_publisher's ``frame_prefix``; see ``robot_transforms``. Raises
    robot_transforms.UrdfError for a URDF it cannot read.
    """

    def __init__(self, urdf: str, frame_prefix: str) -> None:
        self._robot = RobotTransforms(urdf, frame_prefix)
        moving = self._robot.moving_transforms(
            {name: 0.0 for name, joint in self._robot.joints.items() if joint.movable})
        self._encoder = TFMessageEncoder(
            [(transform.parent_frame, transform.child_frame) for transform in moving])

    def static_message(self, stamp_ns: int) -> bytes:
        """Return /tf_static: the fixed joints, stamped ``stamp_ns``."""
        return encode_cdr(tf_message(self._robot.fixed_transforms(), time_msg(stamp_ns)))

    def message(self, positions: Mapping[str, float], stamp_ns: int) -> bytes:
        """
        Return /tf for a joint state of every movable joint, stamped ``stamp_ns``.

        ``positions`` maps each movable joint's name to its position (rad or m).
        """
        return self._encoder.encode(self._robot.moving_transforms(positions), stamp_ns)
