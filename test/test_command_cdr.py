# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
``shared.command_cdr``: the relay's JointTrajectory and Float64MultiArray bytes.

As rclpy and rosbags read and write them.

Random messages (no points, points of unequal array lengths, arrays empty, non-ASCII names and
frames of every length mod 8, NaN and ±inf, layouts with dimensions) serialized by rclpy (little
endian) and rosbags (both byte orders) decode to the fields rosbags reads, float bits too; the
encoder writes the bytes rclpy's ``serialize_message`` and the package's ``encode_cdr`` write.
Malformed and truncated bytes raise ValueError naming the problem.
"""

from __future__ import annotations

import math
import random
import struct
from typing import Any

from builtin_interfaces.msg import Duration
from linkage_kinematics.shared.cdr import encode_cdr, FixedShapeEncoder
from linkage_kinematics.shared.command_cdr import (
    decode_float64_array,
    decode_joint_trajectory,
    encode_joint_trajectory,
    TrajectoryPoint,
)
import numpy as np
import pytest
from rclpy.serialization import serialize_message
from rosbags.typesys import get_typestore, Stores
from std_msgs.msg import Float64MultiArray, MultiArrayDimension
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
TRAJECTORY = 'trajectory_msgs/msg/JointTrajectory'
ARRAY = 'std_msgs/msg/Float64MultiArray'
NAMES = ('ankle_pitch', 'ankle_roll', 'knee', 'ひざ', 'x', 'Gelenk_ä')
SPECIAL = (math.nan, math.inf, -math.inf, -0.0, 5e-324, 1.7976931348623157e308)
MESSAGES = 150


def values(rng: random.Random, count: int) -> list[float]:
    return [rng.choice(SPECIAL) if rng.random() < 0.1 else rng.uniform(-1e3, 1e3)
            for _ in range(count)]


def random_trajectory(rng: random.Random) -> JointTrajectory:
    names = [rng.choice(NAMES) + str(rng.randrange(10)) * rng.randrange(2)
             for _ in range(rng.randrange(5))]
    message = JointTrajectory(joint_names=names)
    message.header.stamp.sec, message.header.stamp.nanosec = (rng.randrange(-2**31, 2**31),
                                                              rng.randrange(10**9))
    message.header.frame_id = 'f' * rng.randrange(17) + rng.choice(('', 'ä'))
    for _ in range(rng.choice((0, 1, rng.randrange(12)))):
        lengths = [rng.choice((0, len(names), rng.randrange(5))) for _ in range(4)]
        message.points.append(JointTrajectoryPoint(
            positions=values(rng, lengths[0]), velocities=values(rng, lengths[1]),
            accelerations=values(rng, lengths[2]), effort=values(rng, lengths[3]),
            time_from_start=Duration(sec=rng.randrange(-5, 100), nanosec=rng.randrange(10**9))))
    return message


def random_array(rng: random.Random) -> Float64MultiArray:
    message = Float64MultiArray(data=values(rng, rng.randrange(13)))
    for _ in range(rng.choice((0, 0, 1, 3))):
        message.layout.dim.append(MultiArrayDimension(
            label='l' * rng.randrange(9), size=rng.randrange(99), stride=rng.randrange(99)))
    message.layout.data_offset = rng.randrange(7)
    return message


def bits(array: Any) -> bytes:
    array = list(array)
    return struct.pack(f'<{len(array)}d', *array)


def to_rosbags(message: Any) -> Any:
    """Return an rclpy message as rosbags' class of the same type (recursively)."""
    name = f'{type(message).__module__.split(".")[0]}/msg/{type(message).__name__}'
    cls = TYPESTORE.types[name]
    fields = {}
    for field, kind in message.get_fields_and_field_types().items():
        value = getattr(message, field)
        if kind.startswith('sequence<double') or kind.startswith('double['):
            fields[field] = np.array(value, dtype=np.float64)
        elif kind.startswith('sequence<') and '/' in kind:
            fields[field] = [to_rosbags(element) for element in value]
        elif '/' in kind:
            fields[field] = to_rosbags(value)
        elif kind.startswith('sequence<'):
            fields[field] = list(value)
        else:
            fields[field] = value
    return cls(**fields)


def trajectory_fields(message: Any) -> tuple:
    """Return a trajectory's fields with float bits, from rclpy's, rosbags' or the decoder's."""
    if hasattr(message, 'header'):
        header = (message.header.stamp.sec, message.header.stamp.nanosec,
                  message.header.frame_id)
        points = tuple((bits(p.positions), bits(p.velocities), bits(p.accelerations),
                        bits(p.effort), p.time_from_start.sec, p.time_from_start.nanosec)
                       for p in message.points)
        return header, tuple(message.joint_names), points
    points = tuple((bits(p.positions), bits(p.velocities), bits(p.accelerations),
                    bits(p.efforts), p.sec, p.nanosec) for p in message.points)
    return (message.sec, message.nanosec, message.frame_id), message.joint_names, points


def test_trajectories_decode_as_rosbags_reads_them_in_both_byte_orders():
    rng = random.Random(30)
    for _ in range(MESSAGES):
        message = random_trajectory(rng)
        expected = trajectory_fields(message)
        theirs = to_rosbags(message)
        for data in (bytes(TYPESTORE.serialize_cdr(theirs, TRAJECTORY)),
                     bytes(TYPESTORE.serialize_cdr(theirs, TRAJECTORY, little_endian=False))):
            assert trajectory_fields(TYPESTORE.deserialize_cdr(data, TRAJECTORY)) == expected
            assert trajectory_fields(decode_joint_trajectory(data)) == expected
        # rclpy's bytes, which may hold a few more (rosbags refuses those)
        assert trajectory_fields(decode_joint_trajectory(serialize_message(message))) == expected


def test_trajectories_encode_to_the_bytes_rosbags_and_encode_cdr_write():
    rng = random.Random(31)
    for _ in range(MESSAGES):
        message = random_trajectory(rng)
        points = [TrajectoryPoint(tuple(p.positions), tuple(p.velocities),
                                  tuple(p.accelerations), tuple(p.effort),
                                  p.time_from_start.sec, p.time_from_start.nanosec)
                  for p in message.points]
        data = encode_joint_trajectory(message.header.stamp.sec, message.header.stamp.nanosec,
                                       message.header.frame_id, message.joint_names, points)
        assert data == encode_cdr(message)
        assert data == bytes(TYPESTORE.serialize_cdr(to_rosbags(message), TRAJECTORY))


def test_arrays_decode_as_rosbags_reads_them_and_the_relay_encoder_writes_their_bytes():
    rng = random.Random(32)
    for _ in range(MESSAGES):
        message = random_array(rng)
        theirs = to_rosbags(message)
        for data in (serialize_message(message), bytes(TYPESTORE.serialize_cdr(theirs, ARRAY)),
                     bytes(TYPESTORE.serialize_cdr(theirs, ARRAY, little_endian=False))):
            assert bits(decode_float64_array(data)) == bits(message.data)
        count = len(message.data)
        if not count:  # the relay has joints: nothing to encode
            continue
        encoder = FixedShapeEncoder(Float64MultiArray(data=[0.0] * count), ['data'])
        plain = Float64MultiArray(data=list(message.data))
        assert encoder.encode(tuple(message.data)) == encode_cdr(plain) == bytes(
            TYPESTORE.serialize_cdr(to_rosbags(plain), ARRAY))


def little(body: bytes) -> bytes:
    return b'\x00\x01\x00\x00' + body


EMPTY_HEADER = struct.pack('<iII', 0, 0, 1) + b'\x00'


@pytest.mark.parametrize(('data', 'problem'), [
    (b'', 'unknown CDR encapsulation'),
    (little(bytes(8)), 'ends within its header'),
    (little(struct.pack('<iII', 0, 0, 0)), 'header.frame_id has length 0'),
    (little(EMPTY_HEADER + bytes(3) + struct.pack('<I', 10**6)),
     'joint_names claims 1000000 strings'),
    (little(EMPTY_HEADER + bytes(3) + struct.pack('<II', 0, 10**6)),
     'claims 1000000 points in 0 bytes'),
    (little(EMPTY_HEADER + bytes(3) + struct.pack('<III', 0, 1, 10**6) + bytes(20)),
     r'points\[0\].positions of 1000000 values goes past the end'),
    (little(EMPTY_HEADER + bytes(3) + struct.pack('<III', 0, 1, 1) + bytes(4)
            + struct.pack('<dIII', 0.5, 0, 0, 0) + bytes(4)),
     r'points\[0\] ends within its time_from_start'),
])
def test_malformed_trajectories_are_refused_naming_the_problem(data, problem):
    with pytest.raises(ValueError, match=problem):
        decode_joint_trajectory(data)


@pytest.mark.parametrize(('data', 'problem'), [
    (b'\x00\x07\x00\x00', 'unknown CDR encapsulation 0007'),
    (little(b'\x00\x00'), 'ends within its layout'),
    (little(struct.pack('<I', 1000)), 'layout claims 1000 dimensions'),
    (little(struct.pack('<II', 1, 5) + b'abcde' + bytes(11)),
     r'layout.dim\[0\].label does not end in a NUL'),
    (little(struct.pack('<I', 0)), 'ends before its layout.data_offset'),
    (little(struct.pack('<III', 0, 0, 3) + bytes(8)), 'data of 3 values goes past the end'),
])
def test_malformed_arrays_are_refused_naming_the_problem(data, problem):
    with pytest.raises(ValueError, match=problem):
        decode_float64_array(data)
