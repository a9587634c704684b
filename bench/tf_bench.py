# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Section "tf": the bytes of one state's /tf, prepared against the generic forward kinematics.

The node logs, for every state, the /tf robot_state_publisher would publish for its URDF
(``messages.RobotStateTransforms.message``): per state only the motion's terms of each movable
joint, written into a prepared message. The alternative, the package's code before it (kept
here as ``GenericTF``), computed every joint's transform afresh from its parameters
(``quaternion_product`` and ``rotate`` per joint and state, a ``Transform`` per joint), checked
each transform's frames and encoded them. Both give the same bytes (checked here too). Timed on
the node's URDF (3 joints) and on a 30-joint chain with skew axes, rpy origins, prismatic and
mimic joints, as a lab's whole robot would be: time per state (medians of interleaved runs) and
the ratio (median of back-to-back pairs).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
import math
import random

from linkage_kinematics.kinematics.geometry import preset
from linkage_kinematics.model.robot_transforms import (
    quaternion_product,
    RobotTransforms,
    rotate,
    Transform,
)
from linkage_kinematics.model.urdf import urdf_text
from linkage_kinematics.model.urdf_reader import read_urdf, UrdfTree
from linkage_kinematics.ros import messages
from linkage_kinematics.shared.cdr import FixedShapeEncoder
from timing import format_seconds, interleaved_medians, markdown_table, paired_ratio

STAMP_NS = 1_790_000_000_123_456_789
CHAIN_JOINTS = 30
# The ratio is the median of back-to-back pairs of this many states each (timing.paired_ratio).
PAIRS = 41
PAIR_STATES = 100


class GenericTF:
    """The per-state /tf of the package before the prepared path, as it was written."""

    def __init__(self, tree: UrdfTree, frame_prefix: str, names: Sequence[str]) -> None:
        self._robot = RobotTransforms(tree, frame_prefix)
        moving = self.moving_transforms(dict.fromkeys(names, 0.0))
        self._frames = [(transform.parent_frame, transform.child_frame) for transform in moving]
        template = messages.tf_message(
            [Transform(parent, child, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
             for parent, child in self._frames], 0)
        varying = []
        for index in range(len(self._frames)):
            varying += [f'transforms[{index}].header.stamp.sec',
                        f'transforms[{index}].header.stamp.nanosec']
            varying += [f'transforms[{index}].transform.{part}.{axis}'
                        for part, axes in (('translation', 'xyz'), ('rotation', 'xyzw'))
                        for axis in axes]
        self._encoder = FixedShapeEncoder(template, varying)

    def moving_transforms(self, positions: Mapping[str, float]) -> list[Transform]:
        positions = dict(positions)
        joints = self._robot.joints
        for name, joint in joints.items():
            if (joint.mimic is not None and joint.mimic.joint in positions
                    and name not in positions):
                positions[name] = (joint.mimic.multiplier * positions[joint.mimic.joint]
                                   + joint.mimic.offset)
        prefix = self._robot.frame_prefix
        transforms = []
        for name, joint in joints.items():
            if not joint.movable or name not in positions:
                continue
            position = positions[name]
            translation, rotation = joint.origin_translation, joint.origin_rotation
            if joint.revolute:
                half = 0.5 * position
                sine = math.sin(half)
                rotation = quaternion_product(rotation, (
                    joint.axis[0] * sine, joint.axis[1] * sine, joint.axis[2] * sine,
                    math.cos(half)))
            else:
                along = rotate(rotation, joint.axis)
                translation = (translation[0] + along[0] * position,
                               translation[1] + along[1] * position,
                               translation[2] + along[2] * position)
            transforms.append(Transform(prefix + joint.parent, prefix + joint.child,
                                        translation, rotation))
        return transforms

    def message(self, positions: Mapping[str, float], stamp_ns: int) -> bytes:
        stamp = divmod(stamp_ns, 1_000_000_000)
        values: list[float] = []
        for (parent, child), transform in zip(self._frames, self.moving_transforms(positions),
                                              strict=True):
            if (transform.parent_frame, transform.child_frame) != (parent, child):
                raise ValueError(f'{transform.child_frame} is not {child}')
            values += (*stamp, *transform.translation, *transform.rotation)
        return self._encoder.encode(tuple(values))


def chain_urdf(joints: int, seed: int = 3) -> str:
    """
    Return a serial chain of ``joints`` joints on skew axes and rpy origins.

    Revolute joints, every fifth prismatic, every seventh a mimic of the joint before it.
    """
    generator = random.Random(seed)
    parts = ['<?xml version="1.0"?>\n<robot name="chain">\n  <link name="l0"/>\n']
    for index in range(1, joints + 1):
        kind = 'prismatic' if index % 5 == 0 else 'revolute'
        xyz = ' '.join(f'{generator.uniform(-0.3, 0.3):.4f}' for _ in range(3))
        rpy = ' '.join(f'{generator.uniform(-math.pi, math.pi):.4f}' for _ in range(3))
        axis = ' '.join(f'{generator.uniform(-1.0, 1.0):.3f}' for _ in range(3))
        mimic = (f'    <mimic joint="j{index - 1:02d}" multiplier="0.5" offset="0.1"/>\n'
                 if index % 7 == 0 else '')
        parts.append(
            f'  <link name="l{index}"/>\n'
            f'  <joint name="j{index:02d}" type="{kind}">\n'
            f'    <parent link="l{index - 1}"/><child link="l{index}"/>\n'
            f'    <origin xyz="{xyz}" rpy="{rpy}"/>\n    <axis xyz="{axis}"/>\n{mimic}'
            '    <limit lower="-3" upper="3" effort="1" velocity="1"/>\n  </joint>\n')
    parts.append('</robot>\n')
    return ''.join(parts)


def workload(path: messages.RobotStateTransforms | GenericTF,
             samples: list[dict[str, float]]) -> Callable[[], int]:
    """Return a workload for ``interleaved_medians``: /tf of every sample, each its own stamp."""
    def encode_all() -> int:
        for index, positions in enumerate(samples):
            path.message(positions, STAMP_NS + index)
        return len(samples)
    return encode_all


def run(quick: bool, repetitions: int) -> str:
    """Return the section's table: ns per state of each path, and new ÷ old."""
    states = 2_000 if quick else 10_000
    generator = random.Random(5)
    rows = []
    for label, urdf in (("the node's URDF (3 revolute joints)",
                         urdf_text(preset('paper').geometry)),
                        (f'a {CHAIN_JOINTS}-joint chain (every 5th prismatic, every 7th a '
                         'mimic)', chain_urdf(CHAIN_JOINTS))):
        tree = read_urdf(urdf)
        robot = RobotTransforms(tree)
        names = [name for name, joint in robot.joints.items() if joint.mimic is None]
        samples = [dict(zip(names, (generator.uniform(-math.pi, math.pi) for _ in names)))
                   for _ in range(states)]
        prepared = messages.RobotStateTransforms(tree, 'robot_1/')
        generic = GenericTF(tree, 'robot_1/', names)
        identical = all(prepared.message(positions, STAMP_NS + index)
                        == generic.message(positions, STAMP_NS + index)
                        for index, positions in enumerate(samples))

        medians = interleaved_medians({'prepared': workload(prepared, samples),
                                       'generic': workload(generic, samples)}, repetitions)
        ratio = paired_ratio(workload(prepared, samples[:PAIR_STATES]),
                             workload(generic, samples[:PAIR_STATES]), PAIRS)
        rows.append([label, format_seconds(medians['generic']),
                     format_seconds(medians['prepared']), f'{ratio:.2f}×',
                     'yes' if identical else '**no**'])
    return markdown_table(
        ['URDF', 'generic forward kinematics (before)', 'prepared (RobotStateTransforms)',
         f'prepared ÷ generic (median of {PAIRS} back-to-back pairs)', 'bytes identical'], rows)
