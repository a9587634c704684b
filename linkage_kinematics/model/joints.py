# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The URDF joints of the linkage, in the node's convention and in a lab's.

URDF cannot close a loop, so the URDF is an open chain cut at one ground pivot, rooted at the
driver's: for the ``crank`` driver base → crank (at O) → coupler (at A) → rocker (at B), which
ends on C; for the ``rocker`` driver base → rocker (at C) → coupler (at B) → crank (at A), which
ends on O. Each joint is named after the link it moves. In the node's convention every joint
turns counterclockwise about +z and a link's frame has its x axis along the link, from the
joint towards the next one, except the disk's (pin A at (0, −OA) in it, as α counts from A's
lowest position):

* crank driver: crank = α, coupler = γ − α, rocker = −β − γ;
* rocker driver: rocker = θ_BC = π − β, coupler = γ + β, crank = α − γ − π/2.

A lab's URDF may name and orient its joints otherwise: its value of a joint is
``direction · node value + offset`` (``JointMapping``), and a measured driver is mapped back
the same way. No ROS.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
import math

from linkage_kinematics.kinematics.solver import LinkageState, unwrap_near


class Driver(StrEnum):
    """The joint that moves the linkage: the crank at O, or the rocker at C."""

    CRANK = 'crank'
    ROCKER = 'rocker'


class Link(StrEnum):
    """The moving links; each URDF joint is named after the link it moves."""

    CRANK = 'crank'
    COUPLER = 'coupler'
    ROCKER = 'rocker'


DEFAULT_JOINT_NAMES = {
    Link.CRANK: 'crank_joint', Link.COUPLER: 'coupler_joint', Link.ROCKER: 'rocker_joint'
}
# The joints of each driver's tree, root first: the driver, then the passive joints.
TREE_ORDER = {
    Driver.CRANK: (Link.CRANK, Link.COUPLER, Link.ROCKER),
    Driver.ROCKER: (Link.ROCKER, Link.COUPLER, Link.CRANK),
}


@dataclass(frozen=True)
class JointMapping:
    """One joint of a lab's URDF: its name, and lab value = direction · node value + offset."""

    name: str
    direction: int = 1
    offset: float = 0.0

    def to_lab(self, node_value: float) -> float:
        """Return the lab's joint position (rad) for the node's."""
        return self.direction * node_value + self.offset

    def from_lab(self, lab_value: float) -> float:
        """Return the node's joint position (rad) for the lab's."""
        return self.direction * (lab_value - self.offset)


@dataclass(frozen=True)
class JointMap:
    """The lab's three joints, by link."""

    crank: JointMapping = JointMapping(DEFAULT_JOINT_NAMES[Link.CRANK])
    coupler: JointMapping = JointMapping(DEFAULT_JOINT_NAMES[Link.COUPLER])
    rocker: JointMapping = JointMapping(DEFAULT_JOINT_NAMES[Link.ROCKER])

    def __getitem__(self, link: Link) -> JointMapping:
        return getattr(self, link.value)

    def names(self, links: tuple[Link, ...]) -> tuple[str, ...]:
        """Return the lab's names of ``links``, in that order."""
        return tuple(self[link].name for link in links)


# A tree's joint positions (rad) and velocities (rad/s), root first.
TreeValues = tuple[tuple[float, float, float], tuple[float, float, float]]


def tree_values(state: LinkageState, driver: Driver) -> TreeValues:
    """
    Return the joint positions (rad) and velocities (rad/s) of ``driver``'s tree, root first.

    In the node's convention (module docstring); the passive joints' positions are within
    (−2π, 2π); ``unwrap_positions`` makes a stream of them continuous.
    """
    if driver is Driver.CRANK:
        return (
            (state.alpha, state.gamma - state.alpha, -state.beta - state.gamma),
            (state.omega, state.omega_ab - state.omega, state.omega_bc - state.omega_ab),
        )
    return (
        (math.pi - state.beta, state.gamma + state.beta,
         state.alpha - state.gamma - 0.5 * math.pi),
        (state.omega_bc, state.omega_ab - state.omega_bc, state.omega - state.omega_ab),
    )


def unwrap_positions(
    positions: tuple[float, float, float],
    previous: tuple[float, float, float] = (0.0, 0.0, 0.0),
) -> tuple[float, float, float]:
    """
    Shift the passive joints (the last two) by whole turns to lie within π of ``previous``.

    ``previous`` are the last published positions (at first zeros), so a stream of them is
    continuous; the driver's (first) is kept as it is.
    """
    return (
        positions[0],
        unwrap_near(positions[1], previous[1]),
        unwrap_near(positions[2], previous[2]),
    )


class JointStream:
    """
    The joint states one run publishes, in the lab's names and values.

    The driver's tree (``TREE_ORDER``), with or without the driver itself (a measured driver
    stays with its own source, so that robot_state_publisher never sees two values for one
    joint); the passive joints are kept continuous across calls (``unwrap_positions``).
    """

    def __init__(self, joints: JointMap, driver: Driver, include_driver: bool) -> None:
        self._mappings = tuple(joints[link] for link in TREE_ORDER[driver])
        # the whole tree's names, root first, and the part of it that is published
        self.tree_names = tuple(mapping.name for mapping in self._mappings)
        self.published = slice(0 if include_driver else 1, None)
        self.names = self.tree_names[self.published]
        self._driver = driver
        self._previous = (0.0, 0.0, 0.0)
        # each joint's direction and offset, read once: ``values`` runs at every tick
        self._coefficients = tuple((mapping.direction, mapping.offset)
                                   for mapping in self._mappings)

    def values(self, state: LinkageState) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """
        Return the lab's positions (rad) and velocities (rad/s) at ``state``.

        Of the whole tree (``tree_names``); ``published`` slices out those in ``names``. Each
        is ``JointMapping.to_lab`` of the node's position, and the velocity times its direction.
        """
        positions, velocities = tree_values(state, self._driver)
        self._previous = positions = unwrap_positions(positions, self._previous)
        (root, first, second), (root_rate, first_rate, second_rate) = positions, velocities
        (d0, o0), (d1, o1), (d2, o2) = self._coefficients
        return ((d0 * root + o0, d1 * first + o1, d2 * second + o2),
                (d0 * root_rate, d1 * first_rate, d2 * second_rate))
