# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The colours and sizes the mechanism is drawn with, in the marker scene and in the URDF.

One source for both, so that the scene of ``linkage/markers`` and the robot model of
``robot_description`` look alike. Colours are RGBA in [0, 1]; sizes in m. Plain Python.
"""

from __future__ import annotations

from typing import NamedTuple


class Rgba(NamedTuple):
    """A colour: red, green, blue and opacity, each in [0, 1]."""

    red: float
    green: float
    blue: float
    alpha: float = 1.0


DISK_COLOR = Rgba(0.55, 0.6, 0.7)
# The marker scene draws the disk translucent, so that the grid and the crank bar over it show
# through; the URDF's materials are all opaque.
DISK_MARKER_ALPHA = 0.6
CRANK_COLOR = Rgba(0.2, 0.3, 0.9)
COUPLER_COLOR = Rgba(0.95, 0.55, 0.1)
ROCKER_COLOR = Rgba(0.15, 0.7, 0.3)
PIN_COLOR = Rgba(0.85, 0.1, 0.1)
PIVOT_COLOR = Rgba(0.15, 0.15, 0.15)
GROUND_COLOR = Rgba(0.5, 0.5, 0.5)  # the ground link OC, drawn in the URDF only

DISK_THICKNESS = 0.01  # the disk is drawn this far below the plane of the bars
BAR_WIDTH = 0.02
BAR_HEIGHT = 0.01  # of the URDF's box-shaped bars
PIN_DIAMETER = 0.05
PIVOT_SIZE = 0.07  # edge of the cube at each ground pivot
