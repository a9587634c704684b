# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
URDF of a four-bar linkage.

The open chain base → disk → coupler → rocker whose end lands on C.

The closed loop is cut at the fixed pivot C. With the /joint_states positions
(α, γ − α, −β − γ) the frames turn by α, γ and −β in the plane, so

* ``crank_joint`` at O turns the ``disk``; pin A is at (0, −OA, 0) in the disk frame;
* ``coupler_joint`` at A: the ``coupler`` frame's x axis points from A to B;
* ``rocker_joint`` at B, (AB, 0, 0) in the coupler frame: the ``rocker`` frame's x axis points
  from B to C, which is therefore at (BC, 0, 0) in the rocker frame.

The root link (``frame_id``, by default ``linkage_base``) shows both ground pivots.
Regenerate the installed file with ``python -m linkage_kinematics.urdf > urdf/linkage.urdf``.
"""

from __future__ import annotations

import math

from linkage_kinematics.geometry import FourBar, preset
from linkage_kinematics.scene import (
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


def _joint(name: str, parent: str, child: str, xyz: str) -> str:
    return (
        f'  <joint name="{name}" type="continuous">\n'
        f'    <parent link="{parent}"/>\n'
        f'    <child link="{child}"/>\n'
        f'    <origin xyz="{xyz}" rpy="0 0 0"/>\n'
        '    <axis xyz="0 0 1"/>\n'
        '  </joint>\n'
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


def urdf_text(linkage: FourBar, frame_id: str = DEFAULT_FRAME_ID) -> str:
    """
    Return the URDF (XML text) of ``linkage`` with root link ``frame_id``.

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
    disk = (
        '  <link name="disk">\n'
        + _visual(_cylinder(crank, DISK_THICKNESS), _xyz(0.0, 0.0, -DISK_THICKNESS), 'disk')
        + _visual(_sphere(_PIN_RADIUS), _xyz(0.0, -crank, 0.0), 'pin')
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
        + _visual(_sphere(_PIN_RADIUS), _xyz(0.0, 0.0, 0.0), 'pin')
        + '  </link>\n'
    )
    return (
        '<?xml version="1.0"?>\n'
        '<robot name="linkage">\n'
        + materials
        + base
        + disk
        + coupler_link
        + rocker_link
        + _joint('crank_joint', frame_id, 'disk', _xyz(0.0, 0.0, 0.0))
        + _joint('coupler_joint', 'disk', 'coupler', _xyz(0.0, -crank, 0.0))
        + _joint('rocker_joint', 'coupler', 'rocker', _xyz(coupler, 0.0, 0.0))
        + '</robot>\n'
    )


if __name__ == '__main__':
    print(urdf_text(preset('paper').geometry), end='')
