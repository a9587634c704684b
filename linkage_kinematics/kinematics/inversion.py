# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The four-bar driven by its rocker: the same mechanism seen from C.

Driven at C, the rocker BC is the input crank, the coupler is BA and the old crank AO is the
output, with its fixed pivot at O. In a frame at C turned by −90° (a point C + (x, y) of the
mechanism's frame is (y, −x) there: an exact change of coordinates for floats) the mechanism is
the ``FourBar`` (BC, AB, OA, −y_C, x_C), and its crank angle, measured from the lowest position
of its pin as α is, *is* the rocker angle θ_BC = π − β of ``linkage/state``. So the library's
exact solve of that linkage is the rocker-driven solve, with the same accuracy, its dead points
(where crank and coupler are collinear, ``seen_from_rocker(linkage).reachability``) and its
continuation through change points (the same configurations as the crank's). ``branch`` of the
rocker-driven chain is the side of pin A relative to the directed line B→O (+1 left, −1 right),
as the crank's is the side of B relative to A→C. No ROS.
"""

from __future__ import annotations

import math

from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import FourBar, wrap_angle
from linkage_kinematics.kinematics.solver import CrankRates, LinkageState, solve


def seen_from_rocker(linkage: FourBar) -> FourBar:
    """Return the mechanism with the rocker as its crank, in the frame at C (module docstring)."""
    return FourBar(linkage.rocker_length, linkage.coupler_length, linkage.crank_length,
                   -linkage.ground_y, linkage.ground_x)


def solve_from_rocker(
    linkage: FourBar, inverted: FourBar, theta: float, drive: DriveLaw | CrankRates,
    branch: int = 1,
) -> LinkageState:
    """
    Return the exact state of ``linkage`` at rocker angle ``theta`` = θ_BC (rad).

    ``inverted`` is ``seen_from_rocker(linkage)``; ``drive`` gives the rocker's rates ω_BC and
    ω̇_BC; ``branch`` is the side of A relative to B→O. Raises as ``kinematics.solve`` does for
    the inverted linkage: at and past its dead points, where crank and coupler are collinear.
    The crank angle α returned lies in (−π, π].
    """
    seen = solve(inverted, theta, drive, branch)
    ground_x = linkage.ground_x
    ground_y = linkage.ground_y
    state = LinkageState(
        # The inverted linkage's rocker is the crank OA: its β' makes A = O + OA·(−cos β',
        # sin β') in the turned frame, which is α = −β' in the mechanism's.
        alpha=wrap_angle(-seen.beta),
        beta=wrap_angle(math.pi - theta),
        gamma=wrap_angle(seen.gamma - 0.5 * math.pi),
        omega=seen.omega_bc,
        omega_dot=seen.omega_dot_bc,
        omega_ab=seen.omega_ab,
        omega_bc=seen.omega,
        omega_dot_ab=seen.omega_dot_ab,
        omega_dot_bc=seen.omega_dot,
        # Back from the turned frame: (x', y') is (−y', x') about C.
        pin_a_x=ground_x - seen.pin_b_y,
        pin_a_y=ground_y + seen.pin_b_x,
        pin_b_x=ground_x - seen.pin_a_y,
        pin_b_y=ground_y + seen.pin_a_x,
        velocity_a_x=-seen.velocity_b_y,
        velocity_a_y=seen.velocity_b_x,
        velocity_b_x=-seen.velocity_a_y,
        velocity_b_y=seen.velocity_a_x,
        acceleration_a_x=-seen.acceleration_b_y,
        acceleration_a_y=seen.acceleration_b_x,
        acceleration_b_x=-seen.acceleration_a_y,
        acceleration_b_y=seen.acceleration_a_x,
        # The chain's own: between the coupler and the driven crank, at A.
        transmission_angle=seen.transmission_angle,
    )
    return state
