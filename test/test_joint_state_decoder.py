# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
``shared.cdr.JointStateDecoder`` reads a JointState's bytes as rclpy and rosbags do.

Many random messages (empty and unequal name/position/velocity/effort lengths, non-ASCII names,
NaN and ±inf, frame_ids of every length mod 8 so that each sequence starts at another alignment,
names repeated at shifted starts) are serialized by rclpy (little endian) and by rosbags (both
byte orders), and one decoder's fields equal what rclpy's ``deserialize_message`` and rosbags'
``deserialize_cdr`` read from the same bytes, float bits too: the efforts by a decoder made to
read them, none by one that is not. Malformed and truncated bytes raise ValueError naming the
problem.
"""

from __future__ import annotations

import math
import random
import struct
from typing import Any

from builtin_interfaces.msg import Time
from linkage_kinematics.shared.cdr import encode_cdr, JointStateDecoder
import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message
from rosbags.typesys import get_typestore, Stores
from sensor_msgs.msg import JointState

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
TYPE_NAME = 'sensor_msgs/msg/JointState'
NAME_POOL = ('knee', 'hip_front_left', 'Gelenk_ä', 'ひざ', 'x', 'joint_with_a_longer_name_0',
             'ü', 'crank')
SPECIAL = (math.nan, math.inf, -math.inf, -0.0, 0.0, 5e-324, 1.7976931348623157e308,
           struct.unpack('<d', struct.pack('<Q', 0x7ff8_0000_dead_beef))[0])  # NaN with payload
MESSAGES = 400


def random_message(rng: random.Random, names_pool: list[list[str]]) -> JointState:
    """Return a JointState of random lengths and values; names often repeat an earlier list."""
    if names_pool and rng.random() < 0.6:
        names = rng.choice(names_pool)
    else:
        names = [rng.choice(NAME_POOL) + str(rng.randrange(100)) * rng.randrange(2)
                 for _ in range(rng.randrange(7))]
        names_pool.append(names)

    def values() -> list[float]:
        count = rng.choice((0, len(names), len(names), rng.randrange(9)))
        return [rng.choice(SPECIAL) if rng.random() < 0.2 else rng.uniform(-1e3, 1e3)
                for _ in range(count)]

    message = JointState(name=names, position=values(), velocity=values(), effort=values())
    message.header.stamp = Time(sec=rng.randrange(-2**31, 2**31), nanosec=rng.randrange(10**9))
    message.header.frame_id = 'f' * rng.randrange(17) + rng.choice(('', 'ä'))
    return message


def float_bits(values: Any) -> bytes:
    """Return the float64 bits of ``values`` (NaN payloads, −0.0 kept)."""
    values = list(values)
    return struct.pack(f'<{len(values)}d', *values)


def fields_of(message: Any, efforts: bool = True) -> tuple[int, tuple[str, ...], bytes, bytes,
                                                           bytes]:
    """
    Return a decoded message's stamp (ns), names and float bits (rclpy's or rosbags').

    The efforts' bits, or none where a decoder does not read them (``efforts`` False).
    """
    stamp = message.header.stamp
    return (stamp.sec * 1_000_000_000 + stamp.nanosec, tuple(message.name),
            float_bits(message.position), float_bits(message.velocity),
            float_bits(message.effort if efforts else ()))


def rosbags_message(message: JointState) -> Any:
    """Return ``message`` as rosbags' own JointState class."""
    types = TYPESTORE.types
    header = types['std_msgs/msg/Header'](
        stamp=types['builtin_interfaces/msg/Time'](sec=message.header.stamp.sec,
                                                   nanosec=message.header.stamp.nanosec),
        frame_id=message.header.frame_id)
    return types[TYPE_NAME](header=header, name=list(message.name),
                            position=np.array(message.position, dtype=np.float64),
                            velocity=np.array(message.velocity, dtype=np.float64),
                            effort=np.array(message.effort, dtype=np.float64))


def test_decoded_fields_equal_rclpys_and_rosbags_in_both_byte_orders() -> None:
    """Each message's bytes, by either serializer and byte order, decode as both libraries do."""
    rng = random.Random(23)
    decoders = {False: JointStateDecoder(), True: JointStateDecoder(efforts=True)}
    names_pool: list[list[str]] = []
    orders = set()
    for _ in range(MESSAGES):
        message = random_message(rng, names_pool)
        independent = rosbags_message(message)
        # rclpy's bytes can end in a few more than the encoding (rosbags refuses those)
        for data, rosbags_reads in (
                (serialize_message(message), False), (encode_cdr(message), True),
                (bytes(TYPESTORE.serialize_cdr(independent, TYPE_NAME)), True),
                (bytes(TYPESTORE.serialize_cdr(independent, TYPE_NAME, little_endian=False)),
                 True)):
            orders.add(data[:2])
            for efforts, decoder in decoders.items():
                stamp_ns, names, positions, velocities, read = decoder.decode(data)
                got = (stamp_ns, names, float_bits(positions), float_bits(velocities),
                       float_bits(read))
                assert got == fields_of(deserialize_message(data, JointState), efforts)
                if rosbags_reads:
                    assert got == fields_of(TYPESTORE.deserialize_cdr(data, TYPE_NAME), efforts)
                assert got == fields_of(message, efforts)
                assert isinstance(names, tuple) and isinstance(positions, tuple)
                assert isinstance(read, tuple)
    assert orders == {b'\x00\x00', b'\x00\x01'}


def test_repeated_names_are_one_tuple_until_they_change() -> None:
    """The same names at the same place give the same tuple; other names are read afresh."""
    decoder = JointStateDecoder()
    first = decoder.decode(encode_cdr(JointState(name=['a', 'b'], position=[1.0, 2.0])))
    again = decoder.decode(encode_cdr(JointState(name=['a', 'b'], position=[3.0])))
    assert again[1] is first[1] and again[2] == (3.0,)
    shifted = JointState(name=['a', 'b'])
    shifted.header.frame_id = 'abcd'  # the names start 4 bytes later: read there
    assert decoder.decode(encode_cdr(shifted))[1] == ('a', 'b')
    assert decoder.decode(encode_cdr(JointState(name=['a', 'c'])))[1] == ('a', 'c')
    assert decoder.decode(encode_cdr(JointState(name=['a'])))[1] == ('a',)


def test_every_truncation_is_refused() -> None:
    """Every strict prefix of an exact encoding lacks a length or values: ValueError."""
    message = JointState(name=['knee', 'hip'], position=[1.0, 2.0], velocity=[0.5],
                         effort=[3.0])
    message.header.frame_id = 'base'
    for data in (encode_cdr(message), bytes(TYPESTORE.serialize_cdr(
            rosbags_message(message), TYPE_NAME, little_endian=False))):
        assert JointStateDecoder().decode(data)[1] == ('knee', 'hip')
        assert JointStateDecoder(efforts=True).decode(data)[4] == (3.0,)
        for length in range(len(data)):
            for decoder in (JointStateDecoder(), JointStateDecoder(efforts=True)):
                with pytest.raises(ValueError, match='JointState|encapsulation'):
                    decoder.decode(data[:length])


def little_endian(frame_id: bytes, names: list[bytes], tail: bytes = b'') -> bytes:
    """Return hand-written XCDR1 bytes: a stamp, ``frame_id`` and ``names`` as given, ``tail``."""
    body = bytearray(struct.pack('<iII', 1, 2, len(frame_id)) + frame_id)
    body += bytes(-len(body) % 4) + struct.pack('<I', len(names))
    for name in names:
        body += bytes(-len(body) % 4) + struct.pack('<I', len(name)) + name
    return b'\x00\x01\x00\x00' + bytes(body) + tail


EMPTY_SEQUENCES = bytes(3) + struct.pack('<III', 0, 0, 0)  # padding, then three empty sequences


@pytest.mark.parametrize(('data', 'problem'), [
    (b'', 'unknown CDR encapsulation \\(none\\)'),
    (b'\x00\x07\x00\x00' + bytes(40), 'unknown CDR encapsulation 0007'),
    (b'\x00\x02\x00\x00' + bytes(40), 'unknown CDR encapsulation 0002'),
    (b'\x00\x01\x00\x00' + bytes(8), 'ends within its header'),
    (little_endian(b'', [b'a\x00'], EMPTY_SEQUENCES), 'header.frame_id has length 0'),
    (little_endian(b'base', [b'a\x00'], EMPTY_SEQUENCES), 'header.frame_id does not end in'),
    (little_endian(b'\x00', [b'knee'], EMPTY_SEQUENCES), r'name\[0\] does not end in a NUL'),
    (little_endian(b'\x00', [b'\xff\xfe\x00'], EMPTY_SEQUENCES), r'name\[0\] is not UTF-8'),
    (little_endian(b'\x00', [b'a\x00', b''], EMPTY_SEQUENCES), r'name\[1\] has length 0'),
    (little_endian(b'\x00', [b'a\x00'] * 3)[:-1], r'name\[2\] of 2 bytes .* past the end'),
    (little_endian(b'\x00', [])[:-4] + struct.pack('<I', 1_000_000) + bytes(40),
     'name claims 1000000 strings in 40 bytes'),
    (little_endian(b'\x00', [b'a\x00'], bytes(2) + struct.pack('<I', 10**9) + bytes(8)),
     'position of 1000000000 values goes past the end'),
    (little_endian(b'\x00', [b'a\x00'], bytes(2) + struct.pack('<I', 0)),
     'ends before the length of its velocity'),
    (little_endian(b'\x00', [b'a\x00'], bytes(2) + struct.pack('<III', 0, 0, 5) + bytes(32)),
     'effort of 5 values goes past the end'),
])
def test_malformed_bytes_are_refused_naming_the_problem(data: bytes, problem: str) -> None:
    """An unknown encapsulation, a bad length, a string without NUL or UTF-8: ValueError."""
    for decoder in (JointStateDecoder(), JointStateDecoder(efforts=True)):
        with pytest.raises(ValueError, match=problem):
            decoder.decode(data)


def test_the_hand_written_bytes_are_a_joint_state_when_well_formed() -> None:
    """The malformed cases above differ from bytes rclpy reads by their one defect."""
    data = little_endian(b'\x00', [b'a\x00', 'ä'.encode() + b'\x00'], EMPTY_SEQUENCES)
    assert JointStateDecoder().decode(data) == (1_000_000_002, ('a', 'ä'), (), (), ())
    assert list(deserialize_message(data, JointState).name) == ['a', 'ä']
