# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Section "loops": linkage_node closing a URDF's four loops at 1 kHz, against the hand relay.

Two runs of the measured section's side-by-side run (``measured_bench.follow_side_by_side``),
each with its own robot: a quadruped whose four knees are test/loop_robots.py's four-bar knee
(four loops, each from its measured ``<leg>_knee_front``) and test/loop_robots.py's excavator
(three cylinder loops and the bucket's four-bar, from the three cylinder lengths). The node
follows ``source:=measured`` with ``loops:=robot_description``, the URDF given as its
``robot_description`` parameter, logging on; ``minimal_relay.py`` follows the same encoder at
the same time and is the baseline. The encoder's messages carry the robot's measured joints
(each swinging over the range in which its loops close), its hip joints where it has them, and
the relay's crank.

Before the nodes, ``path_run`` times the node's per-sample loops path in this process on the
same two robots: the input's bytes read by ``JointStateDecoder`` (against rclpy's
``deserialize_message``), ``RobotLoopsFollower.follow`` and the ``joint_states`` bytes through
the prepared ``JointStateEncoder``, against the path before it (test/loops_per_call.py's per-call
follower, and a rclpy ``JointState`` through ``encode_cdr``), and the /tf of the whole robot
(``TreePositions`` and ``RobotStateTransforms.tree_message``, against a mapping of every tree
joint per sample through ``RobotStateTransforms.message``), checking that both give the same
fields and bytes.
"""

from __future__ import annotations

from collections.abc import Callable
import math
import re

from builtin_interfaces.msg import Time
from linkage_kinematics.loops.follower import LoopSample, RobotLoopsFollower
from linkage_kinematics.loops.plan import find_loops, read_loops
from linkage_kinematics.model.urdf_reader import read_urdf
from linkage_kinematics.ros.loop_source import TreePositions
from linkage_kinematics.ros.messages import JointStateEncoder, RobotStateTransforms
from linkage_kinematics.shared.cdr import encode_cdr, JointStateDecoder
from loop_robots import excavator, four_bar_knee, ROBOTS
from loops_per_call import ReferenceFollower
import measured_bench
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import JointState
from timing import format_seconds, interleaved_medians, markdown_table, paired_ratio
import yaml

# Each leg's hip on the body: the legs stand apart along x and in depth (z, the knee pins'
# axis), so that every knee loop lies in its own plane parallel to the others.
LEGS = {'front_left': (0.3, 0.1), 'front_right': (0.3, -0.1),
        'rear_left': (-0.3, 0.1), 'rear_right': (-0.3, -0.1)}
KNEE = ROBOTS['four_bar_knee']
# The ratios are medians of back-to-back pairs of this many samples each (timing.paired_ratio).
PAIRS = 41
PAIR_SAMPLES = 100
STAMP_NS = 1_790_000_000_000_000_000
PERIOD_NS = 1_000_000


def quadruped() -> str:
    """
    Return a quadruped's URDF: a body and four legs, each a hip and the four-bar knee.

    Every name of the knee (links, joints, its constraint) is prefixed with the leg's; the hip
    (``<leg>_hip``, body → ``<leg>_thigh``) is a revolute joint outside the loops.
    """
    knee = four_bar_knee()
    body = knee.split('<robot name="four_bar_knee">\n', 1)[1].rsplit('</robot>', 1)[0]
    parts = ['<?xml version="1.0"?>\n<robot name="quadruped">\n  <link name="body"/>\n']
    for leg, (x, z) in LEGS.items():
        parts.append(re.sub(r'\b(name|link)="', rf'\1="{leg}_', body))
        parts.append(
            f'  <joint name="{leg}_hip" type="revolute">\n'
            f'    <parent link="body"/>\n    <child link="{leg}_thigh"/>\n'
            f'    <origin xyz="{x!r} 0.0 {z!r}" rpy="0 0 0"/>\n    <axis xyz="0 0 1"/>\n'
            '    <limit lower="-1.0" upper="1.0" effort="100.0" velocity="10.0"/>\n'
            '  </joint>\n')
    return ''.join(parts) + '</robot>\n'


def robots() -> dict[str, tuple[str, dict[str, tuple[float, float]], tuple[str, ...]]]:
    """Return each benchmarked robot: its URDF, encoder joints with ranges, measured joints."""
    low, high = KNEE.measured_ranges['knee_front']
    knees = {f'{leg}_knee_front': (0.9 * low, 0.9 * high) for leg in LEGS}
    hips = {f'{leg}_hip': (-0.5, 0.5) for leg in LEGS}
    digger = ROBOTS['excavator']
    cylinders = {name: (0.9 * low, 0.9 * high)
                 for name, (low, high) in digger.measured_ranges.items()}
    return {
        'quadruped': (quadruped(), {**hips, **knees}, tuple(knees)),
        'excavator': (excavator(), cylinders, digger.measured_joints),
    }


def run(quick: bool, ros_domain: int) -> str:
    """Return the section as markdown (domain ``ros_domain`` + 4, one robot after the other)."""
    seconds = 10.0 if quick else 30.0
    lines = [f'encoder at {measured_bench.RATE_HZ:g} Hz for {seconds:g} s per robot, the node '
             'and the relay following it at once, latency to a third process']
    for robot, (urdf, joints, measured) in robots().items():
        parameters = {'/**': {'ros__parameters': {
            'loops': 'robot_description', 'loops.measured_joints': list(measured),
            'robot_description': urdf}}}
        node = (f'linkage_node ({robot}, 4 loops, logging)', f'/{robot}',
                ['--params-file', f'{{folder}}/{robot}.yaml'])
        figures = measured_bench.follow_side_by_side(
            node, seconds, ros_domain + 4, joints,
            {f'{robot}.yaml': yaml.safe_dump(parameters)},
            frozenset(find_loops(read_urdf(urdf)).plan(list(measured)).passive))
        # the encoder's messages also carry the relay's crank and an unrelated joint
        lines += ['', f'**{robot}** ({len(measured)} measured of the {len(joints) + 2} joints '
                      'in each message)', '', measured_bench.report(figures)]
    return '\n'.join(lines)


Message = tuple[int, list[str], list[float], list[float]]


def messages(joints: dict[str, tuple[float, float]], count: int) -> list[Message]:
    """Return ``count`` messages at 1 kHz, each joint swinging over its range, with velocities."""
    names = list(joints)
    return [(STAMP_NS + index * PERIOD_NS, names,
             [low + (high - low) * (0.5 + 0.5 * math.sin(0.01 * index + k))
              for k, (low, high) in enumerate(joints.values())],
             [0.5 * math.cos(0.01 * index + k) for k in range(len(names))])
            for index in range(count)]


def encode_before(sample: LoopSample) -> bytes:
    """Return the output as ``NodeOutputs.publish_joint_states`` encoded it before: encode_cdr."""
    message = JointState(name=list(sample.names), position=list(sample.positions),
                         velocity=list(sample.velocities))
    message.header.stamp = Time(sec=sample.stamp_ns // 1_000_000_000,
                                nanosec=sample.stamp_ns % 1_000_000_000)
    return encode_cdr(message)


def input_bytes(message: Message) -> bytes:
    """Return one input message as the measured source receives it: its CDR bytes."""
    stamp_ns, names, positions, velocities = message
    joint_state = JointState(name=names, position=positions, velocity=velocities)
    joint_state.header.stamp = Time(sec=stamp_ns // 1_000_000_000,
                                    nanosec=stamp_ns % 1_000_000_000)
    return encode_cdr(joint_state)


def decode_before(data: bytes) -> Message:
    """Return an input's fields as ``RobotLoopsSubscription`` read them before: rclpy."""
    message = deserialize_message(data, JointState)
    stamp = message.header.stamp
    return (stamp.sec * 1_000_000_000 + stamp.nanosec, message.name, message.position,
            message.velocity)


def tf_before(transforms: RobotStateTransforms, heard: dict[str, float], message: Message,
              sample: LoopSample, loop_joints: frozenset[str]) -> bytes:
    """Return the robot's /tf as ``RobotLoopsSubscription`` made it before: a mapping a sample."""
    _, names, positions, _ = message
    for name, position in zip(names, positions):
        if name not in loop_joints and math.isfinite(position):
            heard[name] = position
    return transforms.message({name: sample.joints.get(name, heard.get(name, 0.0))
                               for name in transforms.driven_joints}, sample.stamp_ns)


def path_workloads(measured: tuple[str, ...], urdf: str, inputs: list[Message]
                   ) -> tuple[dict[str, Callable[[], int]], bool]:
    """
    Return the workloads (decode, follow, encode, /tf and all; before and now), whether agreed.

    Each follow workload restarts its follower first, so that every run follows the same motion.
    """
    description = read_urdf(urdf)
    follower = RobotLoopsFollower(read_loops(description), measured, {}, math.pi / 2)
    reference = ReferenceFollower(follower)
    received = [input_bytes(message) for message in inputs]
    decoder = JointStateDecoder()
    now = [follower.follow(*message) for message in inputs]
    before = [reference.follow(*message) for message in inputs]
    encoder = JointStateEncoder(now[0].names)
    transforms = RobotStateTransforms(description, '')
    tree = TreePositions(transforms.driven_joints, follower.loop_joints, {})
    heard: dict[str, float] = {}

    def tf_now(message: Message, sample: LoopSample) -> bytes:
        tree.note_input(message[1], message[2])
        return transforms.tree_message(tree.at_sample(sample.joints), sample.stamp_ns)

    def fields_before(data: bytes) -> tuple:
        stamp_ns, names, positions, velocities = decode_before(data)
        return stamp_ns, tuple(names), tuple(positions), tuple(velocities), ()

    loop_joints = follower.loop_joints
    identical = all(
        encoder.encode(new.stamp_ns, new.positions, new.velocities) == encode_before(old)
        and decoder.decode(data) == fields_before(data)
        and tf_now(message, new) == tf_before(transforms, heard, message, new, loop_joints)
        for new, old, data, message in zip(now, before, received, inputs))

    def decode_now() -> int:
        for data in received:
            decoder.decode(data)
        return len(received)

    def decode_old() -> int:
        for data in received:
            decode_before(data)
        return len(received)

    def follow_now() -> int:
        follower.restart()
        for message in inputs:
            follower.follow(*message)
        return len(inputs)

    def follow_before() -> int:
        reference.restart()
        for message in inputs:
            reference.follow(*message)
        return len(inputs)

    def encode_now() -> int:
        for sample in now:
            encoder.encode(sample.stamp_ns, sample.positions, sample.velocities)
        return len(now)

    def encode_old() -> int:
        for sample in before:
            encode_before(sample)
        return len(before)

    def tf_new() -> int:
        for message, sample in zip(inputs, now):
            tf_now(message, sample)
        return len(now)

    def tf_old() -> int:
        for message, sample in zip(inputs, before):
            tf_before(transforms, heard, message, sample, loop_joints)
        return len(before)

    def all_now() -> int:
        follower.restart()
        for data in received:
            message = decoder.decode(data)
            sample = follower.follow(*message)
            encoder.encode(sample.stamp_ns, sample.positions, sample.velocities)
            tf_now(message, sample)
        return len(received)

    def all_before() -> int:
        reference.restart()
        for data in received:
            message = decode_before(data)
            sample = reference.follow(*message)
            encode_before(sample)
            tf_before(transforms, heard, message, sample, loop_joints)
        return len(received)

    return {'decode now': decode_now, 'decode before': decode_old,
            'follow now': follow_now, 'follow before': follow_before,
            'encode now': encode_now, 'encode before': encode_old,
            'tf now': tf_new, 'tf before': tf_old,
            'all now': all_now, 'all before': all_before}, identical


# the rows of path_run: each stage's workloads and what the row says
STAGES = (('decode', 'input bytes → stamp, names, positions, velocities'),
          ('follow', 'RobotLoopsFollower.follow'), ('encode', 'joint_states bytes'),
          ('tf', '/tf bytes of the whole robot'), ('all', 'all four'))


def path_run(quick: bool, repetitions: int) -> str:
    """Return the in-process table: µs per sample before and now, and now ÷ before."""
    count = 1_000 if quick else 5_000
    rows = []
    for robot, (urdf, joints, measured) in robots().items():
        workloads, identical = path_workloads(measured, urdf, messages(joints, count))
        medians = interleaved_medians(workloads, repetitions)
        pair_inputs = messages(joints, PAIR_SAMPLES)
        pairs, _ = path_workloads(measured, urdf, pair_inputs)
        for stage, label in STAGES:
            ratio = paired_ratio(pairs[f'{stage} now'], pairs[f'{stage} before'], PAIRS)
            rows.append([robot, label, format_seconds(medians[f'{stage} before']),
                         format_seconds(medians[f'{stage} now']), f'{ratio:.2f}×',
                         'yes' if identical else '**no**'])
    return markdown_table(
        ['robot', 'per sample', 'before (rclpy, per-call follower, a mapping per /tf)',
         'now (JointStateDecoder, prepared follower, TreePositions)',
         f'now ÷ before (median of {PAIRS} back-to-back pairs)',
         'fields and bytes identical'], rows)
