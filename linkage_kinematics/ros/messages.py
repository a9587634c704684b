# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The node's messages, from a LinkageState: one way to make each.

The per-tick messages and the scene are never built as rclpy messages: their encoders
(``JointStateEncoder``, ``LinkageStateEncoder``, ``MarkerArrayEncoder``) write their CDR bytes
straight from the state into a layout prepared once per geometry from a template message
(``shared.cdr.FixedShapeEncoder``), the bytes ``encode_cdr`` would write of the message they
describe; the diagnostics (``diagnostics_message``) are written straight from their texts the
same way. None of this computes any kinematics: the values come from the value functions here
(``joints.JointStream``, ``disk_orientation``) and from ``bag.state_layout``. Colours and sizes
come from ``scene``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
import math
import struct
from typing import NamedTuple

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Point, TransformStamped
from linkage_kinematics.bag.state_layout import state_coordinates, STATE_JOINT_NAMES
from linkage_kinematics.kinematics.geometry import FourBar
from linkage_kinematics.kinematics.solver import LinkageState
from linkage_kinematics.model import scene
from linkage_kinematics.model.robot_transforms import (
    MovingTransforms,
    RobotTransforms,
    Transform,
)
from linkage_kinematics.model.urdf_reader import UrdfTree
from linkage_kinematics.run.diagnostics import Status
from linkage_kinematics.shared.cdr import ENCAPSULATION_HEADER, encode_cdr, FixedShapeEncoder
from rosidl_parser.definition import NamespacedType, UnboundedSequence
from sensor_msgs.msg import JointState
from std_msgs.msg import ColorRGBA
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint
from visualization_msgs.msg import Marker, MarkerArray

MARKER_NAMESPACE = 'linkage'
# Marker ids are fixed so that every MarkerArray updates the same markers in place.
DISK_ID, BARS_ID, PIN_A_ID, PIN_B_ID, PIVOT_O_ID, PIVOT_C_ID = range(6)


def _color(color: scene.Rgba, alpha: float | None = None) -> ColorRGBA:
    return ColorRGBA(r=color.red, g=color.green, b=color.blue,
                     a=color.alpha if alpha is None else alpha)


def duration_fields(seconds: float) -> tuple[int, int]:
    """(sec, nanosec) of a builtin_interfaces/Duration of (non-negative) ``seconds``."""
    return divmod(round(seconds * 1e9), 1_000_000_000)


def _stamp_paths(prefix: str) -> list[str]:
    return [f'{prefix}header.stamp.sec', f'{prefix}header.stamp.nanosec']


class JointStateEncoder:
    """
    The bytes of ``joint_states`` for fixed joint names, straight from their values.

    Positions and velocities as ``joints.JointStream`` gives them; frame_id stays empty, as
    joint_state_publisher's.
    """

    def __init__(self, names: Sequence[str]) -> None:
        count = len(names)
        template = JointState(name=list(names), position=[0.0] * count, velocity=[0.0] * count)
        self._encoder = FixedShapeEncoder(template, [*_stamp_paths(''), 'position', 'velocity'])

    def encode(
        self, stamp_ns: int, positions: Sequence[float], velocities: Sequence[float]
    ) -> bytes:
        """Return the message of the joints at ``positions`` and ``velocities``."""
        return self._encoder.encode((*divmod(stamp_ns, 1_000_000_000), *positions, *velocities))


class JointStateEffortEncoder:
    """``JointStateEncoder``'s bytes with one effort per joint (N·m or N)."""

    def __init__(self, names: Sequence[str]) -> None:
        count = len(names)
        template = JointState(name=list(names), position=[0.0] * count, velocity=[0.0] * count,
                              effort=[0.0] * count)
        self._encoder = FixedShapeEncoder(template, [*_stamp_paths(''), 'position', 'velocity',
                                                     'effort'])

    def encode(self, stamp_ns: int, positions: Sequence[float], velocities: Sequence[float],
               efforts: Sequence[float]) -> bytes:
        """Return the message of the joints at ``positions``, ``velocities``, ``efforts``."""
        return self._encoder.encode((*divmod(stamp_ns, 1_000_000_000), *positions, *velocities,
                                     *efforts))


class LinkageStateEncoder:
    """
    The bytes of ``linkage/state`` of one linkage and frame, straight from a state.

    The full state as one trajectory point (docs/parameters.md, "Topics"): the coordinates of
    ``bag.state_layout``, and as ``time_from_start`` the drive-law time since the motion left
    alpha_start.
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
        """Return the message of ``state`` stamped ``stamp_ns``, ``motion_time`` s in."""
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


class MarkerArrayEncoder:
    """
    The bytes of ``linkage/markers`` of one linkage and frame, straight from a state.

    Disk (CYLINDER at O, turned by α), the three bars (one LINE_LIST coloured per bar), pins A
    and B (SPHEREs) and the ground pivots O and C (CUBEs), in namespace ``linkage``, every
    marker stamped with the state's time.
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
        """Return the scene of ``state`` stamped ``stamp_ns``."""
        pin_a = (state.pin_a_x, state.pin_a_y)
        pin_b = (state.pin_b_x, state.pin_b_y)
        return self._encoder.encode((
            *divmod(stamp_ns, 1_000_000_000) * self._marker_count,
            *pin_a * len(self._PIN_A_PATHS), *pin_b * len(self._PIN_B_PATHS),
            *disk_orientation(state),
        ))


def _new_marker_array(linkage: FourBar, frame_id: str) -> MarkerArray:
    crank, coupler, rocker = (
        _color(scene.CRANK_COLOR), _color(scene.COUPLER_COLOR), _color(scene.ROCKER_COLOR))
    disk = _marker(DISK_ID, Marker.CYLINDER, frame_id,
                   _color(scene.DISK_COLOR, scene.DISK_MARKER_ALPHA))
    disk.pose.position.z = -scene.DISK_THICKNESS
    disk.scale.x = disk.scale.y = 2.0 * linkage.crank_length
    disk.scale.z = scene.DISK_THICKNESS

    bars = _marker(BARS_ID, Marker.LINE_LIST, frame_id, crank)
    bars.scale.x = scene.BAR_WIDTH
    ground_c = Point(x=linkage.ground_x, y=linkage.ground_y)
    # O→A, A→B, B→C; points 1–4 are replaced with A and B on every update.
    bars.points = [Point(), Point(), Point(), Point(), Point(), ground_c]
    bars.colors = [crank, crank, coupler, coupler, rocker, rocker]

    pins = []
    for marker_id in (PIN_A_ID, PIN_B_ID):
        pin = _marker(marker_id, Marker.SPHERE, frame_id, _color(scene.PIN_COLOR))
        pin.scale.x = pin.scale.y = pin.scale.z = scene.PIN_DIAMETER
        pins.append(pin)

    pivots = []
    for marker_id, position in ((PIVOT_O_ID, Point()), (PIVOT_C_ID, ground_c)):
        pivot = _marker(marker_id, Marker.CUBE, frame_id, _color(scene.PIVOT_COLOR))
        pivot.pose.position = position
        pivot.scale.x = pivot.scale.y = pivot.scale.z = scene.PIVOT_SIZE
        pivots.append(pivot)
    return MarkerArray(markers=[disk, bars, *pins, *pivots])


class DiagnosticEntry(NamedTuple):
    """One diagnostic_msgs/DiagnosticStatus, in diagnostic_updater's layout."""

    name: str  # "<node>: <task>"
    hardware_id: str
    level: int  # a diagnostic_msgs/DiagnosticStatus level
    message: str
    values: Mapping[str, str]


# A DiagnosticArray up to its statuses: the header's stamp, its empty frame_id (a length of 1,
# the NUL) and three bytes that align the statuses' count to 4, the count.
_DIAGNOSTICS_HEADER = struct.Struct('<iII4xI')
_STRING_LENGTH = struct.Struct('<I')
_ALIGN_4 = (b'', b'\0', b'\0\0', b'\0\0\0')  # by the offset's -offset & 3


def diagnostics_message(stamp_ns: int, statuses: Sequence[DiagnosticEntry]) -> bytes:
    """
    Return /diagnostics (a DiagnosticArray of ``statuses``, stamped ``stamp_ns``) as bytes.

    The bytes ``encode_cdr`` writes of that message with an empty frame_id, written straight
    from the texts: a status goes out with the states ten times a second of mechanism time, and
    building the rclpy messages to walk them took longer than a timer period at 5 kHz.
    """
    sec, nanosec = divmod(stamp_ns, 1_000_000_000)
    body = bytearray(_DIAGNOSTICS_HEADER.pack(sec, nanosec, 1, len(statuses)))
    for status in statuses:
        body.append(status.level)
        _add_string(body, status.name)
        _add_string(body, status.message)
        _add_string(body, status.hardware_id)
        body += _ALIGN_4[-len(body) & 3]
        body += _STRING_LENGTH.pack(len(status.values))
        for key, value in status.values.items():
            _add_string(body, key)
            _add_string(body, value)
    return ENCAPSULATION_HEADER + body


def statuses_message(stamp_ns: int, node_name: str, statuses: Sequence[Status]) -> bytes:
    """Return /diagnostics of a node's ``statuses``, each named '<node>: <task>'."""
    return diagnostics_message(stamp_ns, [
        DiagnosticEntry(f'{node_name}: {status.task}', status.hardware_id, status.level,
                        status.message, status.values)
        for status in statuses])


def _add_string(body: bytearray, text: str) -> None:
    """Append a CDR string (its length aligned to 4, counting the NUL, then its UTF-8 bytes)."""
    encoded = text.encode('utf-8')
    body += _ALIGN_4[-len(body) & 3]
    body += _STRING_LENGTH.pack(len(encoded) + 1)
    body += encoded
    body += b'\0'


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


def tf_message(transforms: Sequence[Transform], stamp_ns: int) -> TFMessage:
    """/tf or /tf_static: ``transforms``, each stamped ``stamp_ns``."""
    sec, nanosec = divmod(stamp_ns, 1_000_000_000)
    message = TFMessage()
    for transform in transforms:
        stamped = TransformStamped(child_frame_id=transform.child_frame)
        stamped.header.stamp = Time(sec=sec, nanosec=nanosec)
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

    Straight from the transforms' values, as ``MovingTransforms.values`` gives them.
    """

    def __init__(self, frames: Sequence[tuple[str, str]]) -> None:
        self.frames = tuple(frames)
        template = tf_message(
            [Transform(parent, child, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
             for parent, child in self.frames],
            0,
        )
        # every stamp first, then every transform, so that a message's values are the stamp
        # repeated and the transforms' values as they come
        indices = range(len(self.frames))
        varying = [path for index in indices for path in _stamp_paths(f'transforms[{index}].')]
        varying += [f'transforms[{index}].transform.{part}.{axis}' for index in indices
                    for part, axes in (('translation', 'xyz'), ('rotation', 'xyzw'))
                    for axis in axes]
        self._encoder = FixedShapeEncoder(template, varying)

    def encode(self, values: tuple[float, ...], stamp_ns: int) -> bytes:
        """
        Return the message of the transforms between ``frames``, each stamped ``stamp_ns``.

        ``values``: translation xyz and rotation xyzw of each transform in turn.
        """
        return self._encoder.encode(
            divmod(stamp_ns, 1_000_000_000) * len(self.frames) + values)


class RobotStateTransforms:
    """
    The /tf_static and /tf messages robot_state_publisher publishes for one URDF, as bytes.

    Of a parsed URDF, with robot_state_publisher's ``frame_prefix``; see ``robot_transforms``.
    The /tf of a joint state is written from the joints' prepared transforms
    (``RobotTransforms.moving``) and a prepared message, both made again only when the joint
    state's names change; the /tf of the whole robot (``tree_message``) from ones made once.
    """

    def __init__(self, tree: UrdfTree, frame_prefix: str) -> None:
        self._robot = RobotTransforms(tree, frame_prefix)
        self._names: tuple[str, ...] | None = None
        self._tree: tuple[MovingTransforms, TFMessageEncoder] | None = None

    @property
    def driven_joints(self) -> tuple[str, ...]:
        """Return the movable joints a joint state sets (``RobotTransforms.driven_joints``)."""
        return self._robot.driven_joints

    def static_message(self, stamp_ns: int) -> bytes:
        """Return /tf_static: the fixed joints, stamped ``stamp_ns``."""
        return encode_cdr(tf_message(self._robot.fixed_transforms(), stamp_ns))

    def message(self, positions: Mapping[str, float], stamp_ns: int) -> bytes:
        """
        Return /tf for a joint state, stamped ``stamp_ns``.

        ``positions`` maps joint names to positions (rad or m); the transforms are those of
        ``RobotTransforms.moving`` for its names.
        """
        names = tuple(positions)
        if names != self._names:
            self._moving = self._robot.moving(names)
            self._encoder = TFMessageEncoder(self._moving.frames)
            self._names = names
        return self._encoder.encode(self._moving.values(positions.values()), stamp_ns)

    def tree_message(self, positions: Sequence[float], stamp_ns: int) -> bytes:
        """
        Return /tf for every driven joint at ``positions``, in ``driven_joints``' order.

        The bytes ``message`` gives for those joints by name, without a mapping per state.
        """
        if self._tree is None:
            moving = self._robot.moving(self._robot.driven_joints)
            self._tree = moving, TFMessageEncoder(moving.frames)
        moving, encoder = self._tree
        return encoder.encode(moving.values(positions), stamp_ns)
