# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The layout of ``linkage/state``: which coordinate each joint name carries, both ways.

A ``trajectory_msgs/JointTrajectory`` with one point whose ``positions``, ``velocities`` and
``accelerations`` are each coordinate of ``STATE_JOINT_NAMES`` and its first and second time
derivatives (docs/parameters.md, "Topics"): α, β, γ, A_x, A_y, B_x, B_y, then the rocker angle
θ_BC = π − β (rates ω_BC, ω̇_BC) and the pins' arc coordinates OA·α (rate V_A = OA·ω) and
BC·β (rate V_B = −BC·ω_BC), so that every quantity of the paper is one plain field.
``state_coordinates`` maps a state onto them (the node's encoder writes these),
``state_from_coordinates`` maps logged ones back (the reader), ``state_point`` checks a decoded
message against the layout. Bags logged before the last three names were added hold the first
seven (``SEVEN_STATE_JOINT_NAMES``); they map back in the same way.
"""

from __future__ import annotations

import math
from typing import Any

from linkage_kinematics.bag.errors import BagError
from linkage_kinematics.kinematics.geometry import FourBar
from linkage_kinematics.kinematics.solver import LinkageState
import numpy as np

STATE_TOPIC = '/linkage/state'
STATE_TYPE = 'trajectory_msgs/msg/JointTrajectory'
STATE_JOINT_NAMES = (
    'alpha', 'beta', 'gamma', 'pin_a_x', 'pin_a_y', 'pin_b_x', 'pin_b_y',
    'rocker_angle', 'pin_a_arc', 'pin_b_arc',
)
SEVEN_STATE_JOINT_NAMES = STATE_JOINT_NAMES[:7]
# The coordinates a state is read back from; the last three restate them.
READ_COORDINATES = len(SEVEN_STATE_JOINT_NAMES)


def state_coordinates(
    linkage: FourBar, state: LinkageState
) -> tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]:
    """Return the positions, velocities and accelerations of ``STATE_JOINT_NAMES``."""
    crank = linkage.crank_length
    rocker = linkage.rocker_length
    return (
        (
            state.alpha, state.beta, state.gamma,
            state.pin_a_x, state.pin_a_y, state.pin_b_x, state.pin_b_y,
            math.pi - state.beta, crank * state.alpha, rocker * state.beta,
        ),
        (
            state.omega, -state.omega_bc, state.omega_ab,
            state.velocity_a_x, state.velocity_a_y, state.velocity_b_x, state.velocity_b_y,
            state.omega_bc, crank * state.omega, -rocker * state.omega_bc,
        ),
        (
            state.omega_dot, -state.omega_dot_bc, state.omega_dot_ab,
            state.acceleration_a_x, state.acceleration_a_y,
            state.acceleration_b_x, state.acceleration_b_y,
            state.omega_dot_bc, crank * state.omega_dot, -rocker * state.omega_dot_bc,
        ),
    )


def state_from_coordinates(
    positions: np.ndarray, velocities: np.ndarray, accelerations: np.ndarray
) -> LinkageState:
    """
    Return the LinkageState (of arrays) of logged coordinates, one row per message.

    Only the first ``READ_COORDINATES`` columns are read. The message does not carry the
    transmission angle, so ``transmission_angle`` is all NaN.
    """
    return LinkageState(
        alpha=positions[:, 0],
        beta=positions[:, 1],
        gamma=positions[:, 2],
        omega=velocities[:, 0],
        omega_dot=accelerations[:, 0],
        omega_ab=velocities[:, 2],
        omega_bc=-velocities[:, 1],
        omega_dot_ab=accelerations[:, 2],
        omega_dot_bc=-accelerations[:, 1],
        pin_a_x=positions[:, 3],
        pin_a_y=positions[:, 4],
        pin_b_x=positions[:, 5],
        pin_b_y=positions[:, 6],
        velocity_a_x=velocities[:, 3],
        velocity_a_y=velocities[:, 4],
        velocity_b_x=velocities[:, 5],
        velocity_b_y=velocities[:, 6],
        acceleration_a_x=accelerations[:, 3],
        acceleration_a_y=accelerations[:, 4],
        acceleration_b_x=accelerations[:, 5],
        acceleration_b_y=accelerations[:, 6],
        transmission_angle=np.full(len(positions), np.nan),
    )


def state_point(trajectory: Any, where: str) -> Any:
    """
    Return the one point of a decoded ``linkage/state`` message.

    BagError naming ``where`` unless it has the current joint names or the seven of earlier
    bags, one point, and one value per name in each field.
    """
    names = tuple(trajectory.joint_names)
    if names not in (STATE_JOINT_NAMES, SEVEN_STATE_JOINT_NAMES):
        raise BagError(
            f'{where} has joint_names {list(names)}; expected {list(STATE_JOINT_NAMES)} '
            f'(or its first seven, as logged before the last three were added)'
        )
    points = trajectory.points
    if len(points) != 1:
        raise BagError(f'{where} has {len(points)} points; expected exactly 1')
    point = points[0]
    for field_name in ('positions', 'velocities', 'accelerations'):
        count = len(getattr(point, field_name))
        if count != len(names):
            raise BagError(
                f'{where} has {count} {field_name}; expected {len(names)} (one per joint)'
            )
    return point
