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
"""

from __future__ import annotations

import re

from linkage_kinematics.model.loops import find_loops
from loop_robots import excavator, four_bar_knee, ROBOTS
import measured_bench
import yaml

# Each leg's hip on the body: the legs stand apart along x and in depth (z, the knee pins'
# axis), so that every knee loop lies in its own plane parallel to the others.
LEGS = {'front_left': (0.3, 0.1), 'front_right': (0.3, -0.1),
        'rear_left': (-0.3, 0.1), 'rear_right': (-0.3, -0.1)}
KNEE = ROBOTS['four_bar_knee']


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
