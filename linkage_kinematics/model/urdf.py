# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
URDF of a four-bar linkage: an open chain rooted at the driver's ground pivot.

For the ``crank`` driver the closed loop is cut at the fixed pivot C: base → disk → coupler →
rocker, whose end lands on C. With the node's joint positions (α, γ − α, −β − γ, see
``joints``) the frames turn by α, γ and −β in the plane, so

* the crank joint at O turns the ``disk``; pin A is at (0, −OA, 0) in the disk frame;
* the coupler joint at A: the ``coupler`` frame's x axis points from A to B;
* the rocker joint at B, (AB, 0, 0) in the coupler frame: the ``rocker`` frame's x axis points
  from B to C, which is therefore at (BC, 0, 0) in the rocker frame.

For the ``rocker`` driver it is cut at O: base → rocker (joint at C, x axis from C to B) →
coupler (joint at B, x axis from B to A) → disk (joint at A, x axis from A to O, which lands at
(OA, 0, 0)), with the node's positions (θ_BC, γ + β, α − γ − π/2).

Each joint carries the lab's name, and its lab value q = direction · node value + offset turns
it: the joint's axis is direction·z and its origin is turned by −direction·offset about z, so
that the child frame turns by direction·(q − offset), the node's value, as above.

The pivot the tree leaves open is written as the loop's cut joint, a revolute ``<constraint>``
(urdfdom PR #264, as ``loops.description`` reads it; robot_state_publisher's parser ignores it)
named ``pivot_c`` or ``pivot_o``: its parent frame is the pivot on the root link, its child frame
the chain's end, (BC, 0, 0) in the rocker or (OA, 0, 0) in the disk, turned so that the two
frames are parallel at the zero pose. They coincide wherever the loop closes; the zero pose (every
joint at 0) is in general not such a pose, so there they differ by its closure gap.

The root link (``frame_id``, by default ``linkage_base``) shows both ground pivots.
``node_description`` is the text of one geometry, frame, set of joints and driver, read once
(``urdf_reader``) for every reader of it: the measured mode's loop and the log's TF.
Regenerate the installed file with ``python -m linkage_kinematics.model.urdf > urdf/linkage.urdf``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property, lru_cache
import math

from linkage_kinematics.kinematics.geometry import FourBar, preset
from linkage_kinematics.model.joints import Driver, JointMap, JointMapping
from linkage_kinematics.model.scene import (
    BAR_HEIGHT,
    BAR_WIDTH,
    COUPLER_COLOR,
    DISK_COLOR,
    DISK_THICKNESS,
    GROUND_COLOR,
    PIN_COLOR,
    PIN_DIAMETER,
    PIVOT_COLOR,
    PIVOT_SIZE,
    Rgba,
    ROCKER_COLOR,
)
from linkage_kinematics.model.urdf_reader import read_urdf, UrdfTree

DEFAULT_FRAME_ID = 'linkage_base'
_PIN_RADIUS = 0.5 * PIN_DIAMETER


def _number(value: float) -> str:
    # repr round-trips a float exactly, so the URDF's kinematics match the library's to the bit.
    return repr(float(value))


def _xyz(x: float, y: float, z: float) -> str:
    return f'{_number(x)} {_number(y)} {_number(z)}'


def _visual(geometry: str, xyz: str, material: str, rpy: str = '0 0 0') -> str:
    return (
        '    <visual>\n'
        f'      <origin xyz="{xyz}" rpy="{rpy}"/>\n'
        f'      <geometry>{geometry}</geometry>\n'
        f'      <material name="{material}"/>\n'
        '    </visual>\n'
    )


def _box(length: float, width: float, height: float) -> str:
    return f'<box size="{_xyz(length, width, height)}"/>'


def _cylinder(radius: float, length: float) -> str:
    return f'<cylinder radius="{_number(radius)}" length="{_number(length)}"/>'


def _sphere(radius: float) -> str:
    return f'<sphere radius="{_number(radius)}"/>'


def _joint(joint: JointMapping, parent: str, child: str, xyz: str) -> str:
    yaw = _number(-joint.direction * joint.offset) if joint.offset else '0'
    return (
        f'  <joint name="{joint.name}" type="continuous">\n'
        f'    <parent link="{parent}"/>\n'
        f'    <child link="{child}"/>\n'
        f'    <origin xyz="{xyz}" rpy="0 0 {yaw}"/>\n'
        f'    <axis xyz="0 0 {joint.direction}"/>\n'
        '  </joint>\n'
    )


def _constraint(name: str, parent: str, pivot: str, child: str, end: str,
                joints: tuple[JointMapping, ...]) -> str:
    """
    Return the ``<constraint>`` that pins ``end`` of link ``child`` to ``pivot`` on ``parent``.

    ``joints`` are the tree's joints from ``parent`` to ``child``: at the zero pose each origin
    turns the chain by −direction·offset, so the child frame is turned back by their sum to be
    parallel to the parent frame.
    """
    turn = sum(joint.direction * joint.offset for joint in joints)
    yaw = _number(turn) if turn else '0'
    return (
        f'  <constraint name="{name}" type="revolute">\n'
        f'    <parent link="{parent}"/>\n'
        f'    <parent_origin xyz="{pivot}" rpy="0 0 0"/>\n'
        '    <parent_axis xyz="0 0 1"/>\n'
        f'    <child link="{child}"/>\n'
        f'    <child_origin xyz="{end}" rpy="0 0 {yaw}"/>\n'
        '    <child_axis xyz="0 0 1"/>\n'
        '  </constraint>\n'
    )


def _rgba(color: Rgba) -> str:
    return ' '.join(f'{channel:g}' for channel in color)


_MATERIALS = (
    ('pivot', PIVOT_COLOR),
    ('ground', GROUND_COLOR),
    ('disk', DISK_COLOR),
    ('pin', PIN_COLOR),
    ('coupler', COUPLER_COLOR),
    ('rocker', ROCKER_COLOR),
)


def urdf_text(
    linkage: FourBar,
    frame_id: str = DEFAULT_FRAME_ID,
    joints: JointMap = JointMap(),
    driver: Driver = Driver.CRANK,
) -> str:
    """
    Return the URDF (XML text) of ``linkage`` with root link ``frame_id``.

    The tree of ``driver``, its joints named and oriented as ``joints`` (module docstring).
    Primitive shapes only.
    """
    crank = linkage.crank_length
    coupler = linkage.coupler_length
    rocker = linkage.rocker_length
    ground = linkage.ground_length
    ground_heading = math.atan2(linkage.ground_y, linkage.ground_x)
    pivot = _box(PIVOT_SIZE, PIVOT_SIZE, PIVOT_SIZE)
    materials = ''.join(
        f'  <material name="{name}"><color rgba="{_rgba(color)}"/></material>\n'
        for name, color in _MATERIALS
    )
    base = (
        f'  <link name="{frame_id}">\n'
        + _visual(pivot, _xyz(0.0, 0.0, 0.0), 'pivot')
        + _visual(pivot, _xyz(linkage.ground_x, linkage.ground_y, 0.0), 'pivot')
        # The ground link OC, drawn below the moving parts.
        + _visual(
            _box(ground, BAR_WIDTH, BAR_HEIGHT),
            _xyz(0.5 * linkage.ground_x, 0.5 * linkage.ground_y, -2.0 * PIVOT_SIZE),
            'ground',
            rpy=f'0 0 {_number(ground_heading)}',
        )
        + '  </link>\n'
    )
    coupler_link = (
        '  <link name="coupler">\n'
        + _visual(_box(coupler, BAR_WIDTH, BAR_HEIGHT), _xyz(0.5 * coupler, 0.0, 0.0),
                  'coupler')
        + '  </link>\n'
    )
    rocker_link = (
        '  <link name="rocker">\n'
        + _visual(_box(rocker, BAR_WIDTH, BAR_HEIGHT), _xyz(0.5 * rocker, 0.0, 0.0), 'rocker')
        + _visual(_sphere(_PIN_RADIUS), _xyz(0.0 if driver is Driver.CRANK else rocker, 0.0,
                                             0.0), 'pin')
        + '  </link>\n'
    )
    if driver is Driver.CRANK:
        disk = (
            '  <link name="disk">\n'
            + _visual(_cylinder(crank, DISK_THICKNESS), _xyz(0.0, 0.0, -DISK_THICKNESS),
                      'disk')
            + _visual(_sphere(_PIN_RADIUS), _xyz(0.0, -crank, 0.0), 'pin')
            + '  </link>\n'
        )
        chain = (
            _joint(joints.crank, frame_id, 'disk', _xyz(0.0, 0.0, 0.0))
            + _joint(joints.coupler, 'disk', 'coupler', _xyz(0.0, -crank, 0.0))
            + _joint(joints.rocker, 'coupler', 'rocker', _xyz(coupler, 0.0, 0.0))
        )
        # cut at C: the rocker's end meets the ground pivot
        cut = _constraint('pivot_c', frame_id, _xyz(linkage.ground_x, linkage.ground_y, 0.0),
                          'rocker', _xyz(rocker, 0.0, 0.0),
                          (joints.crank, joints.coupler, joints.rocker))
    else:
        # The disk's frame has its x axis from A to O, so O is at (OA, 0, 0) in it.
        disk = (
            '  <link name="disk">\n'
            + _visual(_cylinder(crank, DISK_THICKNESS), _xyz(crank, 0.0, -DISK_THICKNESS),
                      'disk')
            + _visual(_sphere(_PIN_RADIUS), _xyz(0.0, 0.0, 0.0), 'pin')
            + '  </link>\n'
        )
        chain = (
            _joint(joints.rocker, frame_id, 'rocker',
                   _xyz(linkage.ground_x, linkage.ground_y, 0.0))
            + _joint(joints.coupler, 'rocker', 'coupler', _xyz(rocker, 0.0, 0.0))
            + _joint(joints.crank, 'coupler', 'disk', _xyz(coupler, 0.0, 0.0))
        )
        # cut at O: the disk's far end meets the root's origin
        cut = _constraint('pivot_o', frame_id, _xyz(0.0, 0.0, 0.0), 'disk',
                          _xyz(crank, 0.0, 0.0), (joints.rocker, joints.coupler, joints.crank))
    return (
        '<?xml version="1.0"?>\n'
        '<robot name="linkage">\n'
        + materials
        + base
        + disk
        + coupler_link
        + rocker_link
        + chain
        + cut
        + '</robot>\n'
    )


@dataclass(frozen=True)
class NodeDescription:
    """The node's URDF text, and the text as ``urdf_reader`` reads it (parsed at first use)."""

    text: str

    @cached_property
    def tree(self) -> UrdfTree:
        """Return the parsed URDF, the same for every reader (a URDF the package wrote reads)."""
        return read_urdf(self.text)


# The node's description is asked for by its outputs (published, and its TF logged) and by the
# measured mode's loop: the latest few are kept, so that both read one parse of one text. A
# parameter change makes a new one; four cover switching back and forth.
@lru_cache(maxsize=4)
def node_description(linkage: FourBar, frame_id: str, joints: JointMap,
                     driver: Driver) -> NodeDescription:
    """Return the node's description for these (``urdf_text``), the same one for equal values."""
    return NodeDescription(urdf_text(linkage, frame_id, joints, driver))


if __name__ == '__main__':
    print(urdf_text(preset('paper').geometry), end='')
