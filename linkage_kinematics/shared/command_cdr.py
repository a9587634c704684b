# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The command relay's messages as CDR bytes: JointTrajectory both ways, Float64MultiArray in.

``trajectory_msgs/JointTrajectory`` is decoded and encoded, ``std_msgs/Float64MultiArray``
decoded (its bytes out are a ``cdr.FixedShapeEncoder``'s).

The relay subscribes and publishes raw bytes, as the loops source does (``cdr``'s
``JointStateDecoder``): rclpy's ``deserialize_message`` and ``serialize_message`` would build
Python messages, a point object per trajectory point. ``decode_joint_trajectory`` and
``decode_float64_array`` read both endiannesses of XCDR1 and raise ValueError naming what is
wrong with the bytes (a length past the end, a string without its NUL or not UTF-8, a count
larger than the bytes could hold); bytes after the message are allowed (rclpy's serializer can
leave some). ``encode_joint_trajectory`` writes little-endian XCDR1, the bytes ``cdr.encode_cdr``
writes for the same message (padding zero, the length exact): one ``struct.pack``, each point's
format prepared once per shape and alignment.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
import functools
import struct

from linkage_kinematics.shared.cdr import (
    add_string,
    cdr_body,
    ENCAPSULATION_HEADER,
    PADDING,
    read_strings,
    string_end,
)

# a point's float64 sequences, in the message's order (JointTrajectoryPoint)
POINT_ARRAYS = ('positions', 'velocities', 'accelerations', 'effort')
# the least bytes a trajectory point takes: four counts and a Duration
_POINT_MINIMUM = 4 * 4 + 8


@dataclass(frozen=True)
class TrajectoryPoint:
    """One ``JointTrajectoryPoint``: its four arrays (rad, m, …) and ``time_from_start``."""

    positions: tuple[float, ...]
    velocities: tuple[float, ...]
    accelerations: tuple[float, ...]
    efforts: tuple[float, ...]
    sec: int
    nanosec: int


@dataclass(frozen=True)
class TrajectoryMessage:
    """A ``JointTrajectory``'s fields: header stamp and frame, joint names, points."""

    sec: int
    nanosec: int
    frame_id: str
    joint_names: tuple[str, ...]
    points: tuple[TrajectoryPoint, ...]


def _doubles(body: bytes, order: str, offset: int, field: str
             ) -> tuple[tuple[float, ...], int]:
    """Return the float64 sequence at ``offset`` and where it ends."""
    offset += -offset & 3
    if offset + 4 > len(body):
        raise ValueError(f'{field} ends before its length')
    count = struct.unpack_from(order + 'I', body, offset)[0]
    offset += 4
    if not count:
        return (), offset
    offset += -offset & 7  # the elements align to 8
    if offset + 8 * count > len(body):
        raise ValueError(f'{field} of {count} values goes past the end ({len(body)} bytes)')
    return struct.unpack_from(f'{order}{count}d', body, offset), offset + 8 * count


def decode_float64_array(data: bytes) -> tuple[float, ...]:
    """
    Return a ``Float64MultiArray``'s ``data``; its layout is checked, not used.

    As forward_command_controller reads it: the values in order, one per joint.
    """
    order, body = cdr_body(data)
    if len(body) < 4:
        raise ValueError(f'Float64MultiArray of {len(body)} bytes ends within its layout')
    count = struct.unpack_from(order + 'I', body)[0]
    offset = 4
    if count * 12 > len(body) - offset:  # a label's length and NUL, a size and a stride
        raise ValueError(f'Float64MultiArray layout claims {count} dimensions in '
                         f'{len(body) - offset} bytes')
    for index in range(count):
        field = f'Float64MultiArray layout.dim[{index}]'
        offset += -offset & 3
        if offset + 4 > len(body):
            raise ValueError(f'{field} ends before its label')
        length = struct.unpack_from(order + 'I', body, offset)[0]
        offset = string_end(body, offset + 4, length, f'{field}.label')
        offset += -offset & 3
        offset += 8  # size, stride
    offset += -offset & 3
    if offset + 4 > len(body):
        raise ValueError('Float64MultiArray ends before its layout.data_offset')
    values, _ = _doubles(body, order, offset + 4, 'Float64MultiArray data')
    return values


def decode_joint_trajectory(data: bytes) -> TrajectoryMessage:
    """Return a ``JointTrajectory``'s fields; ValueError naming what is wrong with the bytes."""
    order, body = cdr_body(data)
    if len(body) < 12:
        raise ValueError(f'JointTrajectory of {len(body)} bytes ends within its header')
    sec, nanosec, length = struct.unpack_from(order + 'iII', body)
    offset = string_end(body, 12, length, 'JointTrajectory header.frame_id')
    try:
        frame_id = str(body[12:offset - 1], 'utf-8')
    except UnicodeDecodeError as error:
        raise ValueError(f'JointTrajectory header.frame_id is not UTF-8: {error}') from None
    names, offset = read_strings(body, order, offset, 'JointTrajectory joint_names')
    offset += -offset & 3
    if offset + 4 > len(body):
        raise ValueError('JointTrajectory ends before the length of its points')
    count = struct.unpack_from(order + 'I', body, offset)[0]
    offset += 4
    if count * _POINT_MINIMUM > len(body) - offset:
        raise ValueError(f'JointTrajectory claims {count} points in {len(body) - offset} '
                         'bytes')
    points = []
    lengths: tuple[int, ...] | None = None  # the last point's array lengths
    for index in range(count):
        # a trajectory's points are alike: read one as the last one's layout in one call, and
        # field by field (which names what is wrong) where it is not
        point = None if lengths is None else _point_like(body, order, offset, lengths)
        if point is None:
            point, end = _point(body, order, offset, index)
            lengths = tuple(map(len, (point.positions, point.velocities, point.accelerations,
                                      point.efforts)))
        else:
            end = offset + _point_format(offset & 7, lengths)[1]
        points.append(point)
        offset = end
    return TrajectoryMessage(sec, nanosec, frame_id, names, tuple(points))


def _point(body: bytes, order: str, offset: int, index: int) -> tuple[TrajectoryPoint, int]:
    """Return the point at ``offset`` read field by field, and where it ends; or ValueError."""
    arrays = []
    for field in POINT_ARRAYS:
        values, offset = _doubles(body, order, offset, f'JointTrajectory points[{index}].{field}')
        arrays.append(values)
    offset += -offset & 3
    if offset + 8 > len(body):
        raise ValueError(f'JointTrajectory points[{index}] ends within its time_from_start')
    point_sec, point_nanosec = struct.unpack_from(order + 'iI', body, offset)
    return TrajectoryPoint(*arrays, point_sec, point_nanosec), offset + 8


def _point_like(body: bytes, order: str, offset: int,
                lengths: tuple[int, ...]) -> TrajectoryPoint | None:
    """Return the point at ``offset`` if its arrays have ``lengths``, else None."""
    code, size = _point_format(offset & 7, lengths)
    if offset + size > len(body):
        return None
    fields = struct.unpack_from(order + code, body, offset)
    arrays = []
    place = 0
    for length in lengths:
        if fields[place] != length:
            return None
        arrays.append(fields[place + 1:place + 1 + length])
        place += 1 + length
    return TrajectoryPoint(*arrays, fields[place], fields[place + 1])


@functools.cache
def _point_format(phase: int, lengths: tuple[int, int, int, int]) -> tuple[str, int]:
    """
    Return the struct codes of a point of these array lengths, and the bytes it takes.

    From its start at ``phase`` (its offset mod 8).
    """
    codes, offset = [], phase
    for count in lengths:
        padding = -offset % 4
        codes.append(PADDING[padding] + 'I')
        offset += padding + 4
        if count:
            padding = -offset % 8
            codes.append(f'{PADDING[padding]}{count}d')
            offset += padding + 8 * count
    padding = -offset % 4
    codes.append(PADDING[padding] + 'iI')
    offset += padding + 8
    return ''.join(codes), offset - phase


def encode_joint_trajectory(sec: int, nanosec: int, frame_id: str, joint_names: Sequence[str],
                            points: Sequence[TrajectoryPoint]) -> bytes:
    """Return the little-endian XCDR1 bytes of a ``JointTrajectory`` (with its header)."""
    codes = ['<iI']
    values: list = [sec, nanosec]
    offset = add_string(frame_id, codes, values, 8)
    padding = -offset % 4
    codes.append(PADDING[padding] + 'I')
    values.append(len(joint_names))
    offset += padding + 4
    for name in joint_names:
        offset = add_string(name, codes, values, offset)
    padding = -offset % 4
    codes.append(PADDING[padding] + 'I')
    values.append(len(points))
    offset += padding + 4
    for point in points:
        arrays = (point.positions, point.velocities, point.accelerations, point.efforts)
        code, length = _point_format(offset & 7, tuple(map(len, arrays)))
        codes.append(code)
        for array in arrays:
            values.append(len(array))
            values.extend(array)
        values.extend((point.sec, point.nanosec))
        offset += length
    return ENCAPSULATION_HEADER + struct.pack(''.join(codes), *values)
