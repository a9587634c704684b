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
same two robots: ``RobotLoopsFollower.follow`` and the ``joint_states`` bytes through the prepared
``JointStateEncoder``, against the path before it (test/loops_per_call.py's per-call follower,
and a rclpy ``JointState`` through ``encode_cdr``), checking that both give the same bytes.
"""

from __future__ import annotations

from collections.abc import Callable
import math
import re

from builtin_interfaces.msg import Time
from linkage_kinematics.bag.cdr import encode_cdr
from linkage_kinematics.model.loops import find_loops
from linkage_kinematics.ros.messages import JointStateEncoder
from linkage_kinematics.run.robot_loops import LoopSample, read_loops, RobotLoopsFollower
from loop_robots import excavator, four_bar_knee, ROBOTS
from loops_per_call import ReferenceFollower
import measured_bench
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
            frozenset(find_loops(urdf).plan(list(measured)).passive))
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


def path_workloads(measured: tuple[str, ...], urdf: str, inputs: list[Message]
                   ) -> tuple[dict[str, Callable[[], int]], bool]:
    """
    Return the workloads (follow, encode and both; before and now) and whether bytes agree.

    Each follow workload restarts its follower first, so that every run follows the same motion.
    """
    follower = RobotLoopsFollower(read_loops(urdf), measured, {}, math.pi / 2)
    reference = ReferenceFollower(follower)
    now = [follower.follow(*message) for message in inputs]
    before = [reference.follow(*message) for message in inputs]
    encoder = JointStateEncoder(now[0].names)
    identical = all(encoder.encode(new.stamp_ns, new.positions, new.velocities)
                    == encode_before(old) for new, old in zip(now, before))

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

    def both_now() -> int:
        follower.restart()
        for message in inputs:
            sample = follower.follow(*message)
            encoder.encode(sample.stamp_ns, sample.positions, sample.velocities)
        return len(inputs)

    def both_before() -> int:
        reference.restart()
        for message in inputs:
            encode_before(reference.follow(*message))
        return len(inputs)

    return {'follow now': follow_now, 'follow before': follow_before,
            'encode now': encode_now, 'encode before': encode_old,
            'both now': both_now, 'both before': both_before}, identical


def path_run(quick: bool, repetitions: int) -> str:
    """Return the in-process table: µs per sample before and now, and now ÷ before."""
    count = 1_000 if quick else 5_000
    rows = []
    for robot, (urdf, joints, measured) in robots().items():
        workloads, identical = path_workloads(measured, urdf, messages(joints, count))
        medians = interleaved_medians(workloads, repetitions)
        pair_inputs = messages(joints, PAIR_SAMPLES)
        pairs, _ = path_workloads(measured, urdf, pair_inputs)
        for stage, label in (('follow', 'RobotLoopsFollower.follow'),
                             ('encode', 'joint_states bytes'), ('both', 'both')):
            ratio = paired_ratio(pairs[f'{stage} now'], pairs[f'{stage} before'], PAIRS)
            rows.append([robot, label, format_seconds(medians[f'{stage} before']),
                         format_seconds(medians[f'{stage} now']), f'{ratio:.2f}×',
                         'yes' if identical else '**no**'])
    return markdown_table(
        ['robot', 'per sample', 'per-call path (before)', 'prepared path (now)',
         f'now ÷ before (median of {PAIRS} back-to-back pairs)', 'bytes identical'], rows)
