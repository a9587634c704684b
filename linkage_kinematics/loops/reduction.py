# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A group's closures rewritten smaller where the joints at their ends allow; those joints follow.

Exporters close a loop by welding two frames that sit at the end of joints, and Newton then
carries unknowns and rows that a smaller closure does without (Gepetto's
example-parallel-robots weld every loop so):

* **Two collinear pins welded.** Each side's path ends in a plain turn carrying the side's frame
  (no mimic), the two turns' axes on one line, and the combination of the two that moves
  nothing is an idle freedom (the five-bar, the delta): the weld is a pin closure between the
  links above the two turns, on that line. Of the two angles, θ_a − s·θ_b = φ (s = ±1 as the
  axes point the same way or not) is the links' relative turn about the line, and the other
  combination is the idle freedom's, held by its equation k_a·(θ_a − θ_a,ref) + k_b·(θ_b −
  θ_b,ref) = 0: two linear equations (``PinPair``). Rates likewise: φ̇ = ω·(Ω_b − Ω_a), ω the
  line's direction, Ω the two links' angular velocities.

``reduce_group`` returns the group with its closures rewritten (``Reduction``): the
coordinates a rewritten closure no longer moves leave the group's Newton system, and so do the
idle freedoms they held. Each is recognised from the tree at the assembled pose, where the
rewritten closure must coincide with the weld to ``COINCIDENT`` (of the group's size): an
exporter's printed digits leave some 1e-16, and a closure further off is kept as it was. The
rewritten closures are closures of the tree (``Closure``), so the closed forms recognise them
as any other (a welded five-bar becomes the planar five-bar). Plan time, then per sample
``PinPair.solve``: plain floats. Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Sequence
import dataclasses
from dataclasses import dataclass
import math

from linkage_kinematics.loops.closures import Closure, ClosureKind, ClosureSide
from linkage_kinematics.loops.equations import Evaluation, LoopEquations
from linkage_kinematics.loops.spatial import (
    apply,
    cross,
    dot,
    multiply,
    norm,
    perpendicular_pair,
    subtract,
    transpose,
    Vector,
)
from linkage_kinematics.loops.structure import ClosureGroup, GroupStructure
from linkage_kinematics.loops.tree import IDENTITY_POSE, KinematicTree, Loop, MotionKind, Pose

# How near (of the group's size, or rad) a rewritten closure must hold where the weld does.
COINCIDENT = 1e-12


@dataclass(frozen=True)
class EndTurn:
    """A plain turn at the end of a closure side's path, the side's frame on its link."""

    step: int
    coordinate: int
    # the moving frame above the turn, the turn's joint frame in it and its unit axis there
    socket: int
    origin: Pose
    axis: Vector
    # the closure side's frame in the turn's moving frame
    offset: Pose


class PinPair:
    """The two angles of two collinear pins welded (module docstring), continued per sample."""

    def __init__(self, closure: str, turns: tuple[EndTurn, EndTurn], sign: float,
                 coefficients: tuple[float, float], reference: tuple[float, float]) -> None:
        first, second = turns
        self.closure = closure
        self.coordinates = (first.coordinate, second.coordinate)
        self.sign = sign
        self.coefficients = coefficients
        self.reference = reference
        self.origins = (first.origin.rotation, second.origin.rotation)
        self.axis = first.axis
        self.perpendicular = perpendicular_pair(first.axis)[0]
        # the second side's frame relative to the first's, both on the welded link
        self.weld = multiply(second.offset.rotation, transpose(first.offset.rotation))
        self.place = 0
        self.angles = (0.0, 0.0)

    def reset(self, equations: LoopEquations, values: Sequence[float]) -> None:
        """Take the angles at an assembled pose (all the tree's coordinates)."""
        self.place = [name for name, _, _ in equations.closure_rows].index(self.closure)
        self.angles = (values[self.coordinates[0]], values[self.coordinates[1]])

    def solve(self, equations: LoopEquations, evaluation: Evaluation,
              rates: Sequence[float]) -> tuple[tuple[float, float], tuple[float, float], float]:
        """Return the two angles (continued from the last), their rates and conditioning 1."""
        rotation_a, _ = equations.frame(self.place, 0, evaluation)
        rotation_b, _ = equations.frame(self.place, 1, evaluation)
        joint_a = multiply(rotation_a, self.origins[0])
        # G·H: the turn θ_a − s·θ_b about the first axis (module docstring)
        turn = multiply(multiply(transpose(joint_a), multiply(rotation_b, self.origins[1])),
                        self.weld)
        p = self.perpendicular
        q = apply(turn, p)
        angle = math.atan2(dot(self.axis, cross(p, q)), dot(p, q))
        (a, b), s = self.angles, self.sign
        last = a - s * b
        angle = last + math.remainder(angle - last, 2.0 * math.pi)
        (k_a, k_b), (r_a, r_b) = self.coefficients, self.reference
        determinant = k_a * s + k_b
        second = (k_a * r_a + k_b * r_b - k_a * angle) / determinant
        axis = apply(joint_a, self.axis)
        spin = subtract(equations.spin(self.place, 1, evaluation, rates),
                        equations.spin(self.place, 0, evaluation, rates))
        turning = dot(axis, spin)
        second_rate = -k_a * turning / determinant
        return ((angle + s * second, second), (turning + s * second_rate, second_rate), 1.0)


@dataclass(frozen=True)
class Reduction:
    """
    A group with its closures rewritten (module docstring).

    ``group`` moves only the coordinates the rewritten closures move (the same known ones);
    ``structure`` has the idle freedoms without those the followers hold; ``followers`` give
    the coordinates taken out, per sample.
    """

    group: ClosureGroup
    structure: GroupStructure
    followers: tuple[PinPair, ...]

    @property
    def coordinates(self) -> frozenset[int]:
        """Return the coordinates the followers give."""
        return frozenset(c for follower in self.followers for c in follower.coordinates)


def reduce_group(tree: KinematicTree, group: ClosureGroup, structure: GroupStructure,
                 values: Sequence[float]) -> Reduction:
    """Return the group with the closures rewritten that can be, at the assembled ``values``."""
    loops = [tree.loop(closure) for closure in group.closures]
    # coordinates moved by more than one step of the group's loops: never taken out
    count: dict[int, int] = {}
    for loop in loops:
        for path in loop.paths:
            for step in path:
                coordinate = tree.steps[step].coordinate
                count[coordinate] = count.get(coordinate, 0) + 1
    frames = tree.frames(values)
    links = {frame: link for link, (frame, offset) in tree.links.items()
             if offset == IDENTITY_POSE}
    closures: list[Closure] = []
    followers: list[PinPair] = []
    held: set[int] = set()
    for closure, loop in zip(group.closures, loops):
        pair = None
        if closure.kind is ClosureKind.WELD:
            turns = [_end_turn(tree, loop, side, group, count) for side in (0, 1)]
            if None not in turns:
                pair = _pin_pair(tree, structure, closure, turns, frames, links, values)
        if pair is None:
            closures.append(closure)
            continue
        pin, follower, idle = pair
        closures.append(pin)
        followers.append(follower)
        held.add(idle)
    taken = {c for follower in followers for c in follower.coordinates}
    reduced = ClosureGroup(tuple(closures),
                           tuple(c for c in group.coordinates if c not in taken), group.known)
    kept = tuple(idle for place, idle in enumerate(structure.idle) if place not in held)
    return Reduction(reduced, dataclasses.replace(structure, idle=kept), tuple(followers))


def _end_turn(tree: KinematicTree, loop: Loop, side: int, group: ClosureGroup,
              count: dict[int, int]) -> EndTurn | None:
    """Return the plain unknown turn a closure side's path ends in, its frame on its link."""
    path = loop.paths[side]
    frame, offset = loop.sides[side]
    if not path or frame != path[-1] + 1:
        return None
    step = tree.steps[path[-1]]
    if (step.kind is not MotionKind.TURN or step.multiplier != 1.0 or step.offset != 0.0
            or step.coordinate in group.known or count[step.coordinate] != 1):
        return None
    return EndTurn(path[-1], step.coordinate, step.parent, step.origin, step.axis, offset)


def _pin_pair(tree: KinematicTree, structure: GroupStructure, closure: Closure,
              turns: list[EndTurn], frames: Sequence[Pose], links: dict[int, str],
              values: Sequence[float]) -> tuple[Closure, PinPair, int] | None:
    """Return a weld's pin closure, its follower and the idle freedom it holds, or None."""
    first, second = turns
    if first.socket not in links or second.socket not in links:
        return None
    names = {tree.coordinates[first.coordinate].name, tree.coordinates[second.coordinate].name}
    idle = next((place for place, freedom in enumerate(structure.idle)
                 if set(freedom.joints) == names), None)
    if idle is None:
        return None
    # the first turn's origin, carried through the weld to the second's link, then (on its
    # axis, which its turn does not move) into the second's socket
    through = multiply(second.offset.rotation, transpose(first.offset.rotation))
    point = subtract(second.offset.position, apply(through, first.offset.position))
    point = tuple(o + x for o, x in zip(second.origin.position,
                                        apply(second.origin.rotation, point)))
    axes = (apply(first.origin.rotation, first.axis), apply(second.origin.rotation, second.axis))
    world = [frames[turn.socket] for turn in turns]
    directions = [apply(pose.rotation, axis) for pose, axis in zip(world, axes)]
    points = [world[0].then(Pose(first.origin.rotation, first.origin.position)).position,
              world[1].then(Pose(second.origin.rotation, point)).position]
    if (norm(cross(*directions)) > COINCIDENT
            or norm(subtract(points[0], points[1])) > COINCIDENT * structure.size):
        return None
    sign = 1.0 if dot(*directions) > 0.0 else -1.0
    solved = list(structure.solved)
    direction = structure.idle[idle].direction
    coefficients = tuple(direction[solved.index(tree.coordinates[turn.coordinate].name)]
                         for turn in turns)
    if abs(coefficients[0] * sign + coefficients[1]) < 0.5:
        return None
    pin = Closure(closure.name, ClosureKind.PIN,
                  ClosureSide(links[first.socket], first.origin.position, axis=axes[0]),
                  ClosureSide(links[second.socket], point, axis=axes[1]), closure.encoding)
    reference = (values[first.coordinate], values[second.coordinate])
    return pin, PinPair(closure.name, (first, second), sign, coefficients, reference), idle
