# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Test robots with planar kinematic loops, written as URDF with ``<constraint>`` cut joints.

The constraint syntax is the one proposed for URDF (urdfdom PR #264): a direct child of
``<robot>`` naming two links, a frame on each (``parent_origin``, ``child_origin``) and an axis
in each frame; for ``type="revolute"`` the two frames' origins coincide and the links may turn
about the axis. The loop is the tree path between the two links.

Every robot is drawn at a closed configuration and written so that the all-zero joint pose *is*
that configuration, as exporters draw it: pivots are chosen as world points, each joint's
``origin`` is computed from its parent link's pose as a reader of the text computes it (float64
forward kinematics of the written, ``repr()``'d numbers) and each constraint frame is placed at
its pin from both links' poses. So every constraint closes at zero up to float64 rounding.

Frames are deliberately not aligned with the links: joint ``rpy`` values are arbitrary, some
axes are ``-1`` along the loop normal, some frames are tilted so that their ``z`` axis is the
pin axis of an ``x``–``z`` loop, and links are stacked in depth (offsets along the pin axes,
chosen as binary fractions so the depth sums are exact in float64). A solver therefore has to
derive each joint's zero and direction from the frames; nothing can be read off the text.

Each robot function returns the URDF text; :data:`ROBOTS` names each robot's measured and
passive joints, a range of the measured joints over which the loops close on the zero pose's
assembly branch, and for each constraint the tree joints of its loop and the order in which the
loops can be solved one at a time.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Callable

import numpy as np

# Binary fractions of a metre for the depth offsets: sums and differences of these are exact in
# float64, so a loop's depth closes exactly (only its in-plane geometry carries rounding).
DEPTH_1 = 0.0078125    # 2**-7 m
DEPTH_2 = 0.015625     # 2**-6 m
DEPTH_4 = 0.03125      # 2**-5 m
HALF_PI = math.pi / 2  # the float64 nearest π/2, as an exporter writes a tilted frame

Point = tuple[float, float, float]
Triple = tuple[float, float, float]


def _rpy_matrix(rpy: Triple) -> np.ndarray:
    """
    Return the rotation of URDF roll–pitch–yaw: Rz(yaw)·Ry(pitch)·Rx(roll).

    Written here, not taken from ``loops.description``: the robots the tests check the package on
    are not placed by the package's own code.
    """
    roll, pitch, yaw = rpy
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])


def _turn_rpy(axis: Triple, angle: float) -> Triple:
    """Return the rpy of a turn by ``angle`` about a frame's coordinate axis (±x, ±y, ±z)."""
    index = [abs(component) for component in axis].index(1.0)
    rpy = [0.0, 0.0, 0.0]
    rpy[index] = math.copysign(angle, axis[index])
    return (rpy[0], rpy[1], rpy[2])


def _triple(values: Triple) -> str:
    """Write three floats as URDF attribute text, each so that it reads back exactly."""
    return ' '.join(repr(float(value)) for value in values)


def _unit(vector: np.ndarray) -> np.ndarray:
    """Scale ``vector`` to length 1."""
    return vector / np.linalg.norm(vector)


class _Drawing:
    """A robot drawn in world coordinates at its closed zero pose, written out as URDF."""

    def __init__(self, name: str, root: str, normal: Triple) -> None:
        self._name = name
        self._normal = np.array(normal, dtype=float)
        # World pose (rotation, position) of every link frame at the zero pose, computed from
        # the written numbers exactly as a float64 reader of the URDF computes it.
        self._poses: dict[str, tuple[np.ndarray, np.ndarray]] = {root: (np.eye(3), np.zeros(3))}
        self._elements: list[str] = [f'  <link name="{root}"/>']

    def _origin(self, parent: str, at: Point,
                rpy: Triple) -> tuple[str, tuple[np.ndarray, np.ndarray]]:
        """
        Return the origin text for a frame at world point ``at`` turned by ``rpy`` from ``parent``.

        Also returns the frame's world pose as a reader of the text computes it (the written
        floats read back exactly, so only the reader's own float64 products round).
        """
        rotation, position = self._poses[parent]
        xyz = rotation.T @ (np.array(at) - position)
        text = f'<origin xyz="{_triple(tuple(xyz))}" rpy="{_triple(rpy)}"/>'
        return text, (rotation @ _rpy_matrix(rpy), rotation @ xyz + position)

    def _check_along_normal(self, name: str, direction: np.ndarray) -> None:
        """Fail the drawing if a pin axis does not lie along the loop normal."""
        if np.linalg.norm(np.cross(direction, self._normal)) > 1e-12:
            raise ValueError(f'{name}: axis {direction} is not along the normal {self._normal}')

    def revolute(self, name: str, parent: str, child: str, at: Point, rpy: Triple,
                 axis: Triple, mimic: tuple[str, float] | None = None) -> None:
        """Add a revolute joint at world point ``at``; ``axis`` is in the joint frame."""
        origin, self._poses[child] = self._origin(parent, at, rpy)
        self._check_along_normal(name, self._poses[child][0] @ np.array(axis, dtype=float))
        mimic_text = '' if mimic is None else (
            f'\n    <mimic joint="{mimic[0]}" multiplier="{mimic[1]!r}" offset="0.0"/>')
        self._elements += [
            f'  <link name="{child}"/>',
            f'  <joint name="{name}" type="revolute">\n'
            f'    <parent link="{parent}"/>\n    <child link="{child}"/>\n    {origin}\n'
            f'    <axis xyz="{_triple(axis)}"/>\n'
            f'    <limit lower="-3.14" upper="3.14" effort="1000.0" velocity="10.0"/>'
            f'{mimic_text}\n  </joint>']

    def prismatic(self, name: str, parent: str, child: str, at: Point, rpy: Triple,
                  direction: Triple) -> None:
        """Add a prismatic joint at ``at`` sliding along the world ``direction`` (in plane)."""
        origin, self._poses[child] = self._origin(parent, at, rpy)
        world = _unit(np.array(direction, dtype=float))
        if abs(world @ self._normal) > 1e-12:
            raise ValueError(f'{name}: slide direction {world} leaves the loop plane')
        axis = self._poses[child][0].T @ world
        self._elements += [
            f'  <link name="{child}"/>',
            f'  <joint name="{name}" type="prismatic">\n'
            f'    <parent link="{parent}"/>\n    <child link="{child}"/>\n    {origin}\n'
            f'    <axis xyz="{_triple(tuple(axis))}"/>\n'
            f'    <limit lower="-0.5" upper="0.5" effort="100000.0" velocity="1.0"/>\n'
            f'  </joint>']

    def pin(self, name: str, parent: str, child: str, at: Point,
            parent_turn: tuple[Triple, float], child_turn: tuple[Triple, float]) -> None:
        """
        Add a revolute constraint joining ``parent`` and ``child`` at world point ``at``.

        Each side's frame is the link frame moved to ``at`` and turned by an angle about the
        link's own coordinate axis that lies along the loop normal (``(axis, angle)``); that
        axis is the constraint's axis on that side.
        """
        sides = []
        for side, link, (axis, angle) in (('parent', parent, parent_turn),
                                          ('child', child, child_turn)):
            origin, (rotation, _) = self._origin(link, at, _turn_rpy(axis, angle))
            self._check_along_normal(name, rotation @ np.array(axis, dtype=float))
            sides.append(f'    <{side} link="{link}"/>\n'
                         f'    {origin.replace("<origin", f"<{side}_origin")}\n'
                         f'    <{side}_axis xyz="{_triple(axis)}"/>')
        self._elements.append(f'  <constraint name="{name}" type="revolute">\n'
                              + '\n'.join(sides) + '\n  </constraint>')

    def urdf(self) -> str:
        """Return the URDF text."""
        return ('<?xml version="1.0"?>\n'
                f'<robot name="{self._name}">\n' + '\n'.join(self._elements) + '\n</robot>\n')


def _in_plane(origin: Point, direction_angle: float, distance: float, depth: float,
              plane: str) -> Point:
    """Return the point ``distance`` from ``origin`` at ``direction_angle`` in a plane."""
    u, v = math.cos(direction_angle) * distance, math.sin(direction_angle) * distance
    if plane == 'xy':
        return (origin[0] + u, origin[1] + v, depth)
    return (depth, origin[1] + u, origin[2] + v)


def four_bar_knee() -> str:
    """
    Return a polycentric knee: a four-bar between thigh and shank, loop in the x–y plane.

    Joints: ``knee_front`` (thigh→front_link, measured), ``knee_shank`` (front_link→shank,
    axis ``0 0 -1``), ``knee_rear`` (thigh→rear_link); constraint ``knee_rear_pin`` joins
    rear_link and shank. Links sit at different depths (z).
    """
    front_pivot = (0.020, 0.000, DEPTH_1)
    shank_front_pivot = (0.028, -0.055, DEPTH_2)
    rear_pivot = (-0.018, -0.008, -DEPTH_1)
    shank_rear_pivot = (-0.022, -0.060, DEPTH_1 / 2)
    robot = _Drawing('four_bar_knee', 'thigh', (0.0, 0.0, 1.0))
    robot.revolute('knee_front', 'thigh', 'front_link', front_pivot, (0.0, 0.0, 0.7),
                   (0.0, 0.0, 1.0))
    robot.revolute('knee_shank', 'front_link', 'shank', shank_front_pivot, (0.0, 0.0, -2.6),
                   (0.0, 0.0, -1.0))
    robot.revolute('knee_rear', 'thigh', 'rear_link', rear_pivot, (0.0, 0.0, 2.3),
                   (0.0, 0.0, 1.0))
    robot.pin('knee_rear_pin', 'rear_link', 'shank', shank_rear_pivot,
              ((0.0, 0.0, 1.0), 0.5), ((0.0, 0.0, -1.0), 1.1))
    return robot.urdf()


def slider_crank() -> str:
    """
    Return an offset slider-crank in the x–y plane.

    Joints: ``crank_joint`` (base→crank, measured), ``coupler_joint`` (crank→coupler, axis
    ``0 0 -1``), ``slider_joint`` (base→slider, prismatic along a line 2 cm from the crank
    pivot, tilted −0.15 rad); constraint ``slider_pin`` joins coupler and slider.
    """
    slide_angle = -0.15
    slide_direction = (math.cos(slide_angle), math.sin(slide_angle), 0.0)
    line_start = (0.0, -0.02, 0.0)
    robot = _Drawing('slider_crank', 'base', (0.0, 0.0, 1.0))
    robot.revolute('crank_joint', 'base', 'crank', (0.0, 0.0, 0.0), (0.0, 0.0, 0.3),
                   (0.0, 0.0, 1.0))
    robot.revolute('coupler_joint', 'crank', 'coupler',
                   _in_plane((0.0, 0.0, 0.0), 0.7, 0.05, DEPTH_2, 'xy'), (0.0, 0.0, 2.0),
                   (0.0, 0.0, -1.0))
    robot.prismatic('slider_joint', 'base', 'slider',
                    _in_plane(line_start, slide_angle, 0.12, -DEPTH_1, 'xy'), (0.0, 0.0, 1.1),
                    slide_direction)
    robot.pin('slider_pin', 'coupler', 'slider',
              _in_plane(line_start, slide_angle, 0.17, DEPTH_1 / 2, 'xy'),
              ((0.0, 0.0, -1.0), 0.4), ((0.0, 0.0, 1.0), -0.8))
    return robot.urdf()


def balancer() -> str:
    """
    Return an arm with a passive balancer cylinder, loop in the y–z plane (axes along ±x).

    Joints: ``arm_joint`` (base→arm, measured, axis ``-1 0 0``), ``balancer_pivot``
    (base→balancer_barrel), ``balancer_rod_joint`` (balancer_barrel→balancer_rod, prismatic);
    constraint ``balancer_pin`` joins arm and balancer_rod 0.25 m out along the arm.
    """
    barrel_pivot = (DEPTH_4, -0.05, 0.35)
    rod_end = _in_plane((0.0, 0.0, 0.0), 0.35, 0.25, DEPTH_2, 'yz')
    cylinder_angle = math.atan2(rod_end[2] - barrel_pivot[2], rod_end[1] - barrel_pivot[1])
    robot = _Drawing('balancer', 'base', (1.0, 0.0, 0.0))
    robot.revolute('arm_joint', 'base', 'arm', (0.0, 0.0, 0.0), (0.4, 0.0, 0.0),
                   (-1.0, 0.0, 0.0))
    robot.revolute('balancer_pivot', 'base', 'balancer_barrel', barrel_pivot, (-1.2, 0.0, 0.0),
                   (1.0, 0.0, 0.0))
    robot.prismatic('balancer_rod_joint', 'balancer_barrel', 'balancer_rod',
                    _in_plane(barrel_pivot, cylinder_angle, 0.12, DEPTH_4, 'yz'),
                    (0.9, 0.0, 0.0),
                    (0.0, math.cos(cylinder_angle), math.sin(cylinder_angle)))
    robot.pin('balancer_pin', 'arm', 'balancer_rod', rod_end,
              ((-1.0, 0.0, 0.0), 0.3), ((1.0, 0.0, 0.0), 2.1))
    return robot.urdf()


def _parallelogram(mimic: bool) -> str:
    """Parallelogram four-bar; with ``mimic`` its passive joints mimic the crank, no cut."""
    crank = 0.08
    crank_angle = 1.2
    follower_pivot = (0.12, 0.01, -DEPTH_2)
    robot = _Drawing('parallelogram_mimic' if mimic else 'parallelogram', 'base',
                     (0.0, 0.0, 1.0))
    robot.revolute('crank_joint', 'base', 'crank', (0.0, 0.0, 0.0), (0.0, 0.0, 0.9),
                   (0.0, 0.0, 1.0))
    # The coupler turns about −z relative to the crank: keeping it parallel to the ground link
    # takes +1 × the crank angle. The follower turns about −z from the base: −1 × the crank.
    robot.revolute('coupler_joint', 'crank', 'coupler',
                   _in_plane((0.0, 0.0, 0.0), crank_angle, crank, DEPTH_2, 'xy'),
                   (0.0, 0.0, -0.4), (0.0, 0.0, -1.0),
                   mimic=('crank_joint', 1.0) if mimic else None)
    robot.revolute('follower_joint', 'base', 'follower', follower_pivot, (0.0, 0.0, 2.2),
                   (0.0, 0.0, -1.0), mimic=('crank_joint', -1.0) if mimic else None)
    if not mimic:
        robot.pin('follower_pin', 'coupler', 'follower',
                  _in_plane(follower_pivot, crank_angle, crank, 0.0, 'xy'),
                  ((0.0, 0.0, -1.0), -0.25), ((0.0, 0.0, -1.0), 0.6))
    return robot.urdf()


def parallelogram() -> str:
    """
    Return a parallelogram four-bar in the x–y plane.

    Joints: ``crank_joint`` (base→crank, measured), ``coupler_joint`` (crank→coupler, axis
    ``0 0 -1``), ``follower_joint`` (base→follower, axis ``0 0 -1``); constraint
    ``follower_pin`` joins coupler and follower. Crank and follower are 8 cm, equal and
    parallel, so the exact answer is linear: coupler_joint = crank_joint and
    follower_joint = −crank_joint.
    """
    return _parallelogram(mimic=False)


def parallelogram_mimic() -> str:
    """
    Return :func:`parallelogram` as labs fake it today: passive joints as ``<mimic>``, no cut.

    ``coupler_joint`` mimics ``crank_joint`` with multiplier 1 and ``follower_joint`` with
    multiplier −1 (both exact for this parallelogram's frames); there is no ``<constraint>``.
    """
    return _parallelogram(mimic=True)


def excavator() -> str:
    """
    Return an excavator's front: boom, stick and bucket driven by three cylinders (x–z plane).

    The pin axes lie along ±y (some joint axes are ``0 -1 0``); the bucket link's frame is
    tilted (roll π/2) so that its own ``z``, and that of the guide link hanging on it, is the
    pin axis. Cylinders and links sit
    at different depths (y). The measured joints are the three cylinder lengths
    (``boom_cylinder``, ``stick_cylinder``, ``bucket_cylinder``, prismatic); every other joint
    is passive.

    Constraints, each with the three tree joints of its loop and the joint known beforehand:

    1. ``boom_cylinder_pin`` (boom ↔ boom_cylinder_rod): ``boom_cylinder`` (known, measured),
       ``boom_cylinder_pivot`` (base→boom_cylinder_barrel), ``boom_joint`` (base→boom).
    2. ``stick_cylinder_pin`` (stick ↔ stick_cylinder_rod): ``stick_cylinder`` (known,
       measured), ``stick_cylinder_pivot`` (boom→stick_cylinder_barrel), ``stick_joint``
       (boom→stick).
    3. ``bucket_cylinder_pin`` (bucket_link ↔ bucket_cylinder_rod): ``bucket_cylinder``
       (known, measured), ``bucket_cylinder_pivot`` (stick→bucket_cylinder_barrel),
       ``bucket_link_joint`` (stick→bucket_link, the side link).
    4. ``bucket_pin`` (bucket ↔ guide_link), the bucket's four-bar: ``guide_link_joint``
       (bucket_link→guide_link, at the bucket cylinder's rod end), ``bucket_link_joint``
       (known: solved by loop 3), ``bucket_joint`` (stick→bucket).

    Solve order: 1, 2 and 3 each need only their measured cylinder (in any order); 4 needs
    ``bucket_link_joint`` from 3, so it comes after 3. The rod end of the bucket cylinder is
    the pin joining the bucket link and the guide link: loop 3 closes it on the bucket link,
    and the guide link's tree joint hangs on the bucket link at the same point.
    """
    y_axis, minus_y_axis = (0.0, 1.0, 0.0), (0.0, -1.0, 0.0)
    z_axis, minus_z_axis = (0.0, 0.0, 1.0), (0.0, 0.0, -1.0)
    boom_foot = (0.20, 0.0, 1.10)
    boom_cylinder_base = (0.60, DEPTH_4 * 8, 0.55)
    boom_cylinder_end = (1.80, DEPTH_4 * 4, 2.05)
    boom_tip = (5.20, 0.0, 2.60)
    stick_cylinder_base = (2.90, -DEPTH_4 * 4, 3.20)
    stick_cylinder_end = (5.35, -DEPTH_4 * 2, 3.35)
    bucket_cylinder_base = (5.55, DEPTH_4, 2.90)
    side_link_pivot = (5.85, DEPTH_4 * 8, 0.65)
    bucket_cylinder_end = (6.15, DEPTH_4 * 4, 0.95)
    bucket_pivot = (5.70, 0.0, 0.25)
    guide_link_end = (6.15, DEPTH_4 * 2, 0.35)

    def cylinder(base: Point, end: Point, barrel_length: float) -> tuple[Point, Triple]:
        """Return the barrel end (where the rod joint sits) and the direction base→end."""
        direction = _unit(np.array([end[0] - base[0], 0.0, end[2] - base[2]]))
        barrel_end = (base[0] + barrel_length * direction[0], base[1],
                      base[2] + barrel_length * direction[2])
        return barrel_end, (direction[0], 0.0, direction[2])

    robot = _Drawing('excavator', 'base', y_axis)
    robot.revolute('boom_joint', 'base', 'boom', boom_foot, (0.0, 0.3, 0.0), y_axis)
    robot.revolute('boom_cylinder_pivot', 'base', 'boom_cylinder_barrel', boom_cylinder_base,
                   (0.0, -0.7, 0.0), minus_y_axis)
    barrel_end, direction = cylinder(boom_cylinder_base, boom_cylinder_end, 0.9)
    robot.prismatic('boom_cylinder', 'boom_cylinder_barrel', 'boom_cylinder_rod', barrel_end,
                    (0.0, 1.4, 0.0), direction)
    robot.pin('boom_cylinder_pin', 'boom', 'boom_cylinder_rod', boom_cylinder_end,
              (y_axis, 0.2), (minus_y_axis, -1.3))

    robot.revolute('stick_joint', 'boom', 'stick', boom_tip, (0.0, 2.1, 0.0), minus_y_axis)
    robot.revolute('stick_cylinder_pivot', 'boom', 'stick_cylinder_barrel', stick_cylinder_base,
                   (0.0, -2.4, 0.0), y_axis)
    barrel_end, direction = cylinder(stick_cylinder_base, stick_cylinder_end, 1.1)
    robot.prismatic('stick_cylinder', 'stick_cylinder_barrel', 'stick_cylinder_rod', barrel_end,
                    (0.0, 0.5, 0.0), direction)
    robot.pin('stick_cylinder_pin', 'stick', 'stick_cylinder_rod', stick_cylinder_end,
              (minus_y_axis, 0.9), (y_axis, 0.0))

    robot.revolute('bucket_cylinder_pivot', 'stick', 'bucket_cylinder_barrel',
                   bucket_cylinder_base, (0.0, -1.0, 0.0), minus_y_axis)
    barrel_end, direction = cylinder(bucket_cylinder_base, bucket_cylinder_end, 1.0)
    robot.prismatic('bucket_cylinder', 'bucket_cylinder_barrel', 'bucket_cylinder_rod',
                    barrel_end, (0.0, 0.8, 0.0), direction)
    # The side link's frame is tilted: its z is the world's −y, the pin axis.
    robot.revolute('bucket_link_joint', 'stick', 'bucket_link', side_link_pivot,
                   (HALF_PI, 0.4, 0.0), z_axis)
    robot.pin('bucket_cylinder_pin', 'bucket_link', 'bucket_cylinder_rod', bucket_cylinder_end,
              (z_axis, -0.6), (y_axis, 1.7))
    robot.revolute('guide_link_joint', 'bucket_link', 'guide_link', bucket_cylinder_end,
                   (0.0, 0.0, 0.9), minus_z_axis)
    robot.revolute('bucket_joint', 'stick', 'bucket', bucket_pivot, (0.0, -0.6, 0.0), y_axis)
    robot.pin('bucket_pin', 'bucket', 'guide_link', guide_link_end,
              (y_axis, 2.8), (minus_z_axis, 0.35))
    return robot.urdf()


@dataclass(frozen=True)
class LoopRobot:
    """A test robot: its URDF and what the tests need to know about its joints and loops."""

    urdf: Callable[[], str]
    measured_joints: tuple[str, ...]
    passive_joints: tuple[str, ...]
    # Measured joint → (low, high), rad or m: the loops close over the whole box on the zero
    # pose's assembly branch, away from dead points.
    measured_ranges: dict[str, tuple[float, float]]
    # Constraint → the tree joints of its loop (a set: the order along the path is not part
    # of the statement), in an order in which the loops can be solved one at a time.
    loops: dict[str, frozenset[str]]


ROBOTS: dict[str, LoopRobot] = {
    'four_bar_knee': LoopRobot(
        four_bar_knee, ('knee_front',), ('knee_shank', 'knee_rear'),
        {'knee_front': (-0.3, 0.3)},
        {'knee_rear_pin': frozenset({'knee_front', 'knee_shank', 'knee_rear'})}),
    'slider_crank': LoopRobot(
        slider_crank, ('crank_joint',), ('coupler_joint', 'slider_joint'),
        {'crank_joint': (-0.6, 0.6)},
        {'slider_pin': frozenset({'crank_joint', 'coupler_joint', 'slider_joint'})}),
    'balancer': LoopRobot(
        balancer, ('arm_joint',), ('balancer_pivot', 'balancer_rod_joint'),
        {'arm_joint': (-0.5, 0.5)},
        {'balancer_pin': frozenset({'arm_joint', 'balancer_pivot', 'balancer_rod_joint'})}),
    'parallelogram': LoopRobot(
        parallelogram, ('crank_joint',), ('coupler_joint', 'follower_joint'),
        {'crank_joint': (-0.6, 0.6)},
        {'follower_pin': frozenset({'crank_joint', 'coupler_joint', 'follower_joint'})}),
    'excavator': LoopRobot(
        excavator, ('boom_cylinder', 'stick_cylinder', 'bucket_cylinder'),
        ('boom_joint', 'boom_cylinder_pivot', 'stick_joint', 'stick_cylinder_pivot',
         'bucket_cylinder_pivot', 'bucket_link_joint', 'guide_link_joint', 'bucket_joint'),
        {'boom_cylinder': (-0.15, 0.15), 'stick_cylinder': (-0.2, 0.2),
         'bucket_cylinder': (-0.15, 0.15)},
        {'boom_cylinder_pin': frozenset({'boom_cylinder', 'boom_cylinder_pivot', 'boom_joint'}),
         'stick_cylinder_pin': frozenset({'stick_cylinder', 'stick_cylinder_pivot',
                                          'stick_joint'}),
         'bucket_cylinder_pin': frozenset({'bucket_cylinder', 'bucket_cylinder_pivot',
                                           'bucket_link_joint'}),
         'bucket_pin': frozenset({'guide_link_joint', 'bucket_link_joint', 'bucket_joint'})}),
}
