# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A rod written as one distance, |x − P| = L: what the closure equations read in its place.

``Rod``: a ball closure's side that hangs from a universal joint (two plain turns whose axes
meet at P, the ball at L from P), found in the tree by ``universal_rod``; its two angles
follow from x in closed form (newton.py, closed_forms.TurnChain). ``Distance``: any closure
written as that one row, a ``Rod``'s (``rod_distance``) or a welded rod's (reduction.py):
which point replaces each side's frame, the steps no longer in the loop, and known slides
that stretch the rod. Plan time. Pure: no ROS.
"""

from __future__ import annotations

from dataclasses import dataclass

from linkage_kinematics.loops.closures import ClosureKind
from linkage_kinematics.loops.spatial import (
    add,
    apply,
    apply_transposed,
    cross,
    dot,
    multiply,
    norm,
    Rotation,
    scale,
    subtract,
    Vector,
)
from linkage_kinematics.loops.tree import KinematicTree, Loop, MotionKind

# Two universal-joint axes meet where their lines pass within this fraction of the rod's length
# of each other (an exporter's printed digits leave some 1e-7), and are not parallel.
CONCURRENT_TOLERANCE = 1e-9


@dataclass(frozen=True)
class Rod:
    """
    A ball closure's rod: a body hung from a universal joint, its ball at L from the joint.

    The joint's two turns have axes that meet at P. The closure is |x − P| = L; the two angles
    follow from x.

    Frames: the socket is the moving frame above the joint; ``first``/``second`` the joint's
    steps, ``origins`` their fixed rotations, ``axes`` their unit axes; ``center`` is P in the
    socket frame, ``rod`` the vector from P to the ball in the rod's frame.
    """

    closure: str
    side: int  # 0: the closure's parent side is the rod, 1: its child side
    socket: int
    steps: tuple[int, int]
    coordinates: tuple[int, int]
    origins: tuple[Rotation, Rotation]
    axes: tuple[Vector, Vector]
    center: Vector
    rod: Vector
    length: float


@dataclass(frozen=True)
class Distance:
    """
    A closure written as one distance, |x − P| = L: what a rod (``Rod``) or a welded rod is.

    ``points`` gives per side of the closure (parent, child) the moving frame and the point on
    it that replaces the side's frame, or None to keep the side's frame's origin; ``trimmed``
    are the steps that no longer move the loop (the rod's joints, whose angles follow in closed
    form); P is on side ``center``, x on the other.
    """

    closure: str
    points: tuple[tuple[int, Vector] | None, tuple[int, Vector] | None]
    trimmed: frozenset[int]
    center: int
    length: float
    # known slides inside the rod: L = |span + Σ (m·q + o)·u| over (coordinate, m, o, unit u),
    # span and u in one frame of the rod (empty: L = ``length``)
    stretch: tuple[tuple[int, float, float, Vector], ...] = ()
    span: Vector = (0.0, 0.0, 0.0)


def rod_distance(rod: Rod) -> Distance:
    """Return the distance a rod's closure becomes: P at the universal joint, x the ball."""
    points: list[tuple[int, Vector] | None] = [None, None]
    points[rod.side] = (rod.socket, rod.center)
    return Distance(rod.closure, (points[0], points[1]), frozenset(rod.steps), rod.side,
                    rod.length)


def universal_rod(tree: KinematicTree, loop: Loop, side: int) -> Rod | None:
    """
    Return the rod of a ball closure's ``side`` if it hangs from a universal joint, else None.

    The side's path must end in two plain turns (no mimic) whose axes meet, the side's frame on
    the second one's body, and the ball away from the meeting point.
    """
    path = loop.paths[side]
    frame, offset = loop.sides[side]
    if loop.closure.kind is not ClosureKind.BALL or len(path) < 2 or frame != path[-1] + 1:
        return None
    first, second = tree.steps[path[-2]], tree.steps[path[-1]]
    if (second.parent != path[-2] + 1 or first.coordinate == second.coordinate
            or any(step.kind is not MotionKind.TURN or step.multiplier != 1.0
                   or step.offset != 0.0 for step in (first, second))):
        return None
    # both lines in the socket frame, at the first turn's zero (P is on its axis: it stays)
    o1, d1 = first.origin.position, apply(first.origin.rotation, first.axis)
    turned = first.origin.rotation
    o2 = add(o1, apply(turned, second.origin.position))
    rod_rotation = multiply(turned, second.origin.rotation)
    d2 = apply(rod_rotation, second.axis)
    normal = cross(d1, d2)
    if norm(normal) < 1e-6:
        return None
    # closest points of the two lines: o1 + s·d1 and o2 + t·d2
    gap = subtract(o2, o1)
    square = dot(normal, normal)
    s = dot(cross(gap, d2), normal) / square
    t = dot(cross(gap, d1), normal) / square
    on_first, on_second = add(o1, scale(s, d1)), add(o2, scale(t, d2))
    center = scale(0.5, add(on_first, on_second))
    rod = subtract(offset.position, apply_transposed(rod_rotation, subtract(center, o2)))
    length = norm(rod)
    if length == 0.0 or norm(subtract(on_first, on_second)) > CONCURRENT_TOLERANCE * length:
        return None
    return Rod(loop.closure.name, side, first.parent, (path[-2], path[-1]),
               (first.coordinate, second.coordinate),
               (first.origin.rotation, second.origin.rotation), (first.axis, second.axis),
               center, rod, length)
