# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The kinematics of the planar four-bar: a pure library, numpy only (no ROS).

Its public names are imported from here (``from linkage_kinematics.kinematics import solve,
FourBar``), as they were when this was one module. Modules, one concern each: ``geometry`` (the
four-bar, its presets, the factors of its loop closure and where its crank can go:
``Reachability``, which a loop's known joint shares), ``drive`` (the drive law ω = ω0 + k·α and
its exact flow in time), ``solver`` (exact positions, rates and accelerations, and the refusals
at dead points) over ``closed_form``, ``singular_points`` and ``continuation``, ``inversion``
(the four-bar driven by its rocker), ``planar_loop`` (a loop of four joints solved from one,
a four-bar or, through ``prismatic_loop``, a loop with a slider) and ``decimal_arithmetic``
(the 60-digit decimals the singular points are found in, once per loop).
"""

from linkage_kinematics.kinematics.closed_form import (
    CrankRates,
    LinkagePose,
    LinkageState,
    STATE_FIELDS,
)
from linkage_kinematics.kinematics.continuation import continued_branch
from linkage_kinematics.kinematics.drive import DriveError, DriveLaw
from linkage_kinematics.kinematics.geometry import (
    DIMENSIONS,
    FourBar,
    GeometryError,
    Preset,
    preset,
    PRESETS,
    Reachability,
    TWO_PI,
    UnreachableError,
    wrap_angle,
)
from linkage_kinematics.kinematics.inversion import seen_from_rocker, solve_from_rocker
from linkage_kinematics.kinematics.solver import (
    DeadPointError,
    loop_closure_residual,
    reachable_mask,
    solve,
    solve_many,
    solve_pose,
    unwrap_near,
)

__all__ = [
    'continued_branch', 'CrankRates', 'DeadPointError', 'DIMENSIONS', 'DriveError', 'DriveLaw',
    'FourBar', 'GeometryError', 'LinkagePose', 'LinkageState', 'loop_closure_residual',
    'preset', 'Preset', 'PRESETS', 'Reachability', 'reachable_mask', 'seen_from_rocker',
    'solve', 'solve_from_rocker', 'solve_many', 'solve_pose', 'STATE_FIELDS', 'TWO_PI',
    'UnreachableError', 'unwrap_near', 'wrap_angle',
]
