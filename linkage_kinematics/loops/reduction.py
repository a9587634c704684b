# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A group's closures rewritten smaller where the joints at their ends allow; those joints follow.

Exporters close a loop by welding two frames that sit at the end of joints, and Newton then
carries unknowns and rows that a smaller closure does without (Gepetto's
example-parallel-robots weld every loop so; a welded rod on two balls of three turns is six
unknowns and six rows where a distance is one row):

* **A welded rod.** Each side's path ends in turns about axes through one point (a universal
  joint of two, or a ball of three: Gepetto's ``_rev0``–``_rev2`` and the closure file's
  SPHERICAL and UJOINT overrides), carrying the side's frame, the two points apart: the two
  links welded are one rod between the two points, and the weld is the distance between
  them, |x − P| = L (one row; rods.Distance). The joints follow from the rod's
  direction (``WeldRod``): a universal end points the rod (closed_forms.TurnChain.pointing),
  the rod's rotation is then known and the ball at the other end turns to it
  (closed_forms.TurnChain.ball). Two balls leave the rod free to spin about its line: rewritten
  only where each ball's third turn is that spin and the two are an idle freedom, σ and s·σ
  (s = ±1 as the axes point), held by its equation; the first ball's first two turns then
  point the rod. Known slides along the rod between a ball and the weld (wl16_like's legs,
  which motors lengthen) make L = |span + Σ (m·q + o)·u|, per sample. Rates: the pointing
  turns from ḋ = (Ω_socket + θ̇₁ω₁ + θ̇₂ω₂) × d + L̇·d/L as a reduced rod's (its normal
  equations see only the part across d), the ball's from Ω_rod − Ω_socket = Σ θ̇ᵢωᵢ (its
  three world axes; their κ is the ball's closeness to its gimbal lock, refused as any
  conditioning).
* **Two collinear pins welded.** Each side's path ends in a plain turn carrying the side's frame
  (no mimic), the two turns' axes on one line, and the combination of the two that moves
  nothing is an idle freedom (the five-bar, the delta; a welded rod's two spins where the rod
  is not rewritten): the weld is a pin closure between the links above the two turns, on that
  line. Of the two angles, θ_a − s·θ_b = φ is the links' relative turn about the line, and
  the other combination is the idle freedom's, held by its equation k_a·(θ_a − θ_a,ref) +
  k_b·(θ_b − θ_b,ref) = 0: two linear equations (``PinPair``). Rates likewise: φ̇ = ω·(Ω_b −
  Ω_a), ω the line's direction, Ω the two links' angular velocities.

``reduce_group`` returns the group with its closures rewritten (``Reduction``): the
coordinates a rewritten closure no longer moves leave the group's Newton system, and so do the
idle freedoms they held. Each is recognised from the tree at the assembled pose, where the
rewritten closure must coincide with the weld to ``COINCIDENT`` (of the group's size): an
exporter's printed digits leave some 1e-16, and a closure further off is kept as it was. The
rewritten pins are closures of the tree (``Closure``), so the closed forms recognise them as
any other (a welded five-bar becomes the planar five-bar). Each follower's closed forms must
give the assembled pose's joints back (newton.py checks, else keeps the weld). Plan time, then
per sample ``solve``: plain floats. Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Sequence
import dataclasses
from dataclasses import dataclass
import math

from linkage_kinematics.loops.closed_forms import OutOfReach, TurnChain
from linkage_kinematics.loops.closures import Closure, ClosureKind, ClosureSide
from linkage_kinematics.loops.equations import Evaluation, LoopEquations
from linkage_kinematics.loops.rods import Distance
from linkage_kinematics.loops.spatial import (
    add,
    apply,
    apply_transposed,
    cross,
    dot,
    IDENTITY,
    multiply,
    norm,
    perpendicular_pair,
    Rotation,
    scale,
    subtract,
    transpose,
    Vector,
    ZERO,
)
from linkage_kinematics.loops.structure import ClosureGroup, GroupStructure
from linkage_kinematics.loops.tree import IDENTITY_POSE, KinematicTree, Loop, MotionKind, Pose

# How near (of the group's size, or rad) a rewritten closure must hold where the weld does.
COINCIDENT = 1e-12


@dataclass(frozen=True)
class Turns:
    """
    Plain turns (no mimic) at the end of a closure side's path, about axes through one point.

    The side's frame is on the last one's link; each after the first has its joint origin at
    the one before's (so all axes pass through the first's joint origin, ``center``).
    """

    steps: tuple[int, ...]
    coordinates: tuple[int, ...]
    # the moving frame above the first turn, and the point in it
    socket: int
    center: Vector
    # each turn's joint frame rotation in the frame above it, and its unit axis there
    origins: tuple[Rotation, ...]
    axes: tuple[Vector, ...]
    # the closure side's frame in the last turn's moving frame, known slides below the turns
    # at 0; each slide as (coordinate, multiplier, offset, unit axis in that frame)
    offset: Pose
    slides: tuple[tuple[int, float, float, Vector], ...] = ()


class PinPair:
    """The two angles of two collinear pins welded (module docstring), continued per sample."""

    def __init__(self, closure: str, turns: tuple[Turns, Turns], sign: float,
                 coefficients: tuple[float, float], reference: tuple[float, float]) -> None:
        first, second = turns
        self.closure = closure
        self.coordinates = (first.coordinates[0], second.coordinates[0])
        self.sign = sign
        self.coefficients = coefficients
        self.reference = reference
        self.origin = first.origins[0]
        self.axis = first.axes[0]
        self.lifted = apply(first.origins[0], first.axes[0])
        self.perpendicular = perpendicular_pair(first.axes[0])[0]
        # a vector p across the first axis, carried through the weld and the second turn's
        # origin: (R_a·O_a)ᵀ·R_b·(this) is p turned by θ_a − s·θ_b about the first axis
        weld = multiply(second.offset.rotation, transpose(first.offset.rotation))
        self.carried = apply(second.origins[0], apply(weld, self.perpendicular))
        self.place = 0
        self.angles = (0.0, 0.0)

    def reset(self, equations: LoopEquations, evaluation: Evaluation,
              values: Sequence[float]) -> float:
        """Take the angles at an assembled pose (all the tree's coordinates); return 0."""
        self.place = [name for name, _, _ in equations.closure_rows].index(self.closure)
        self.angles = (values[self.coordinates[0]], values[self.coordinates[1]])
        return 0.0

    def solve(self, equations: LoopEquations, evaluation: Evaluation,
              rates: Sequence[float]) -> tuple[tuple[float, float], tuple[float, float], float]:
        """Return the two angles (continued from the last), their rates and conditioning 1."""
        rotation_a, _ = equations.frame(self.place, 0, evaluation)
        rotation_b, _ = equations.frame(self.place, 1, evaluation)
        # the links' relative turn about the line, θ_a − s·θ_b: where it takes p
        p = self.perpendicular
        q = apply_transposed(self.origin, apply_transposed(rotation_a,
                                                           apply(rotation_b, self.carried)))
        angle = math.atan2(dot(self.axis, cross(p, q)), dot(p, q))
        (a, b), s = self.angles, self.sign
        last = a - s * b
        angle = last + math.remainder(angle - last, 2.0 * math.pi)
        (k_a, k_b), (r_a, r_b) = self.coefficients, self.reference
        determinant = k_a * s + k_b
        second = (k_a * r_a + k_b * r_b - k_a * angle) / determinant
        axis = apply(rotation_a, self.lifted)
        spin = subtract(equations.spin(self.place, 1, evaluation, rates),
                        equations.spin(self.place, 0, evaluation, rates))
        turning = dot(axis, spin)
        second_rate = -k_a * turning / determinant
        return ((angle + s * second, second), (turning + s * second_rate, second_rate), 1.0)


class WeldRod:
    """
    The joints at the two ends of a welded rod, from the rod's direction (module docstring).

    The *pointing* end (a universal joint, or a ball whose third turn spins the rod about its
    own axis) points the rod from its centre P to the other end's centre x; the *other* end (a
    ball) turns its link to the rod's rotation. With a spin, its angle σ and the other ball's
    third angle (about the same line: it moves by s·σ) are the idle freedom's, held by its
    equation. ``coordinates``: the pointing end's, then the other's.
    """

    def __init__(self, closure: str, pointing: Turns, other: Turns, span: Vector,
                 stretch: tuple[tuple[int, float, float, Vector], ...], weld: Rotation,
                 spin: tuple[float, tuple[float, float], tuple[float, float]] | None) -> None:
        self.closure = closure
        self.pointing = TurnChain(pointing.origins, pointing.axes)
        self.other = TurnChain(other.origins, other.axes)
        self.coordinates = pointing.coordinates + other.coordinates
        # the other end's centre from P in the pointing end's second turn's frame, span + Σ
        # (m·q + o)·u over the known slides in the rod
        self.span, self.stretch = span, stretch
        # the other ball's third axis and a unit vector across it, in its last frame, and both
        # seen in the pointing end's last frame through the weld
        self.welded = (apply(weld, other.axes[2]), apply(weld, self.other.across))
        self.spin = spin
        self.slide_columns: list[int] = []
        self.place = 0
        self.branches = (1, 1)
        self.angles: tuple[float, ...] = ()

    def reset(self, equations: LoopEquations, evaluation: Evaluation,
              values: Sequence[float]) -> float:
        """
        Take the branches and angles of an assembled pose (all the tree's coordinates).

        Returns how far the closed forms' angles are from the pose's (rad): rounding, unless
        the rewriting does not hold (the caller keeps the weld then).
        """
        self.place = [name for name, _, _ in equations.closure_rows].index(self.closure)
        self.slide_columns = [equations.coordinates.index(c) for c, *_ in self.stretch]
        assembled = tuple(values[c] for c in self.coordinates)
        best = math.inf
        for branches in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
            self.branches, self.angles = branches, assembled
            try:
                angles = self.solve(equations, evaluation, None)[0]
            except OutOfReach:
                continue
            gap = max(abs(math.remainder(a - b, 2.0 * math.pi))
                      for a, b in zip(angles, assembled))
            if gap < best:
                best, chosen = gap, branches
        if best < math.inf:
            self.branches = chosen
        self.angles = assembled
        return best

    def solve(self, equations: LoopEquations, evaluation: Evaluation,
              rates: Sequence[float] | None) -> tuple[tuple[float, ...], tuple[float, ...], float]:
        """
        Return the angles (continued from the last), their rates and conditioning.

        Without ``rates``, the angles only (rates 0, conditioning 1). OutOfReach where the
        rod's length is not the distance (beyond rounding).
        """
        pointing, other, place = self.pointing, self.other, self.place
        (xx, xy, xz), (px, py, pz) = evaluation.points[place]
        d = (xx - px, xy - py, xz - pz)
        socket = equations.frame(place, 1, evaluation)[0]
        other_socket = equations.frame(place, 0, evaluation)[0]
        x, y, z = self.span
        for column, (_, multiplier, offset, (ux, uy, uz)) in zip(self.slide_columns,
                                                                 self.stretch):
            travel = multiplier * evaluation.values[column] + offset
            x, y, z = x + travel * ux, y + travel * uy, z + travel * uz
        first, second = pointing.pointing((x, y, z), apply_transposed(socket, d),
                                          self.branches[0])
        last = self.angles
        trig = [(math.cos(first), math.sin(first)), (math.cos(second), math.sin(second))]
        if self.spin is not None:
            trig.append((math.cos(last[2]), math.sin(last[2])))
        # the other ball's third axis and the vector across it, in its socket's frame
        third, across = (apply_transposed(other_socket, apply(socket, pointing.forward(trig, v)))
                         for v in self.welded)
        ball_first, ball_second, ball_third = other.ball(third, across, self.branches[1])
        ball_trig = [(math.cos(ball_first), math.sin(ball_first)),
                     (math.cos(ball_second), math.sin(ball_second))]
        angles = [first, second, *last[2:2 + len(trig) - 2], ball_first, ball_second, ball_third]
        angles = [previous + math.remainder(angle - previous, 2.0 * math.pi)
                  for angle, previous in zip(angles, last)]
        if self.spin is not None:
            sign, (k_p, k_q), (r_p, r_q) = self.spin
            # the other ball's third angle moves by s·σ with the spin σ (at σ = last[2] now)
            base = angles[5] - sign * last[2]
            angles[2] = (k_p * r_p + k_q * (r_q - base)) / (k_p + k_q * sign)
            angles[5] = base + sign * angles[2]
        if rates is None:
            return tuple(angles), (0.0,) * len(angles), 1.0
        # (Ω_socket + θ̇₁ω₁ + θ̇₂ω₂) × d = ḋ by its normal equations, as a reduced rod's
        velocity, spin_rate = equations.relative_motion(place, evaluation, rates)
        w1, w2 = pointing.world_axes(socket, trig)[:2]
        d_rate = subtract(velocity, cross(spin_rate, d))
        c1, c2 = cross(w1, d), cross(w2, d)
        g11, g12, g22 = dot(c1, c1), dot(c1, c2), dot(c2, c2)
        det = g11 * g22 - g12 * g12
        if not det > 0.0:  # the rod along its joint's first axis: refused as singular
            return tuple(angles), (0.0,) * len(angles), math.inf
        r1, r2 = dot(c1, d_rate), dot(c2, d_rate)
        trace = g11 + g22
        spread = math.sqrt(max(trace * trace - 4.0 * det, 0.0))
        conditioning = math.sqrt((trace + spread) / max(trace - spread, 1e-300))
        first_rate, second_rate = (g22 * r1 - g12 * r2) / det, (g11 * r2 - g12 * r1) / det
        turning = add(spin_rate, add(scale(first_rate, w1), scale(second_rate, w2)))
        # the other ball: Ω_rod − Ω_socket = Σ θ̇ᵢωᵢ over its three axes
        relative_rate = subtract(turning, equations.spin(place, 0, evaluation, rates))
        columns = other.world_axes(other_socket, ball_trig)
        ball_rates, ball_conditioning = _solve_columns(columns, relative_rate)
        if ball_rates is None:  # at the ball's gimbal lock: refused as singular
            return tuple(angles), (0.0,) * len(angles), math.inf
        rates_out = [first_rate, second_rate, *([0.0] if self.spin is not None else []),
                     *ball_rates]
        if self.spin is not None:
            sign, (k_p, k_q), _ = self.spin
            rates_out[2] = -k_q * rates_out[5] / (k_p + k_q * sign)
            rates_out[5] += sign * rates_out[2]
        return tuple(angles), tuple(rates_out), max(conditioning, ball_conditioning)


def _solve_columns(columns: Sequence[Vector],
                   rhs: Vector) -> tuple[list[float] | None, float]:
    """Return x with [c₁ c₂ c₃]·x = rhs (Cramer) and the matrix's κ₁, or None if singular."""
    c1, c2, c3 = columns
    rows = (cross(c2, c3), cross(c3, c1), cross(c1, c2))  # the inverse's rows times det
    det = dot(c1, rows[0])
    if det == 0.0:
        return None, math.inf
    norm_matrix = max(abs(c[0]) + abs(c[1]) + abs(c[2]) for c in columns)
    norm_inverse = max(abs(rows[0][k]) + abs(rows[1][k]) + abs(rows[2][k])
                       for k in range(3)) / abs(det)
    return [dot(row, rhs) / det for row in rows], norm_matrix * norm_inverse


@dataclass(frozen=True)
class Reduction:
    """
    A group with its closures rewritten (module docstring).

    ``group`` moves only the coordinates the rewritten closures move (the same known ones);
    ``structure`` has the idle freedoms without those the followers hold; ``distances`` the
    welded rods written as a distance (equations.LoopEquations); ``followers`` give the
    coordinates taken out, per sample.
    """

    group: ClosureGroup
    structure: GroupStructure
    followers: tuple[PinPair | WeldRod, ...]
    distances: dict[str, Distance] = dataclasses.field(default_factory=dict)


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
    followers: list[PinPair | WeldRod] = []
    distances: dict[str, Distance] = {}
    held: set[int] = set()
    for closure, loop in zip(group.closures, loops):
        closures.append(closure)
        if closure.kind is not ClosureKind.WELD:
            continue
        ends = [_end_turns(tree, loop, side, group, count) for side in (0, 1)]
        if None in ends:
            continue
        rod = _weld_rod(tree, structure, closure, ends, values)
        if rod is not None:
            distance, follower, idle = rod
            distances[closure.name] = distance
        else:
            if any(end.slides for end in ends):
                continue
            last = [_last_turn(end) for end in ends]
            pair = _pin_pair(tree, structure, closure, last, frames, links, values)
            if pair is None:
                continue
            closures[-1], follower, idle = pair
        followers.append(follower)
        if idle is not None:
            held.add(idle)
    taken = {c for follower in followers for c in follower.coordinates}
    reduced = ClosureGroup(tuple(closures),
                           tuple(c for c in group.coordinates if c not in taken), group.known)
    kept = tuple(idle for place, idle in enumerate(structure.idle) if place not in held)
    return Reduction(reduced, dataclasses.replace(structure, idle=kept), tuple(followers),
                     distances)


def _end_turns(tree: KinematicTree, loop: Loop, side: int, group: ClosureGroup,
               count: dict[int, int]) -> Turns | None:
    """
    Return the (up to three) plain unknown turns a closure side's path ends in, or None.

    Known slides may follow them (a rod a motor lengthens): the side's frame is then on the
    last slide's link, and moves along the slides' axes.
    """
    path = loop.paths[side]
    frame, offset = loop.sides[side]
    if not path or frame != path[-1] + 1:
        return None
    end = len(path)
    while end > 1 and tree.steps[path[end - 1]].kind is MotionKind.SLIDE and (
            tree.steps[path[end - 1]].coordinate in group.known
            and tree.steps[path[end - 1]].parent == path[end - 2] + 1):
        end -= 1
    steps: list[int] = []
    for index in reversed(path[:end]):
        step = tree.steps[index]
        if (step.kind is not MotionKind.TURN or step.multiplier != 1.0 or step.offset != 0.0
                or step.coordinate in group.known or count[step.coordinate] != 1):
            break
        if steps:
            below = tree.steps[steps[-1]]
            if below.parent != index + 1 or below.origin.position != ZERO:
                break
        steps.append(index)
        if len(steps) == 3:
            break
    if not steps:
        return None
    if end < len(path) and path[end - 1] != steps[0]:
        return None
    steps.reverse()
    # the side's frame through the slides (at 0), in the last turn's frame: a slide turns
    # nothing, so each moves it along its axis as it is seen there
    pose, slides = Pose(IDENTITY, ZERO), []
    for index in path[end:]:
        step = tree.steps[index]
        pose = pose.then(step.origin)
        slides.append((step.coordinate, step.multiplier, step.offset,
                       apply(pose.rotation, step.axis)))
    first = tree.steps[steps[0]]
    return Turns(tuple(steps) + tuple(path[end:]),
                 tuple(tree.steps[i].coordinate for i in steps), first.parent,
                 first.origin.position, tuple(tree.steps[i].origin.rotation for i in steps),
                 tuple(tree.steps[i].axis for i in steps), pose.then(offset), tuple(slides))


def _last_turn(turns: Turns) -> Turns:
    """Return the last of the turns on its own (its socket the frame above it)."""
    if len(turns.steps) == 1:
        return turns
    return Turns(turns.steps[-1:], turns.coordinates[-1:], turns.steps[-2] + 1, ZERO,
                 turns.origins[-1:], turns.axes[-1:], turns.offset)


def _idle_of(tree: KinematicTree, structure: GroupStructure,
             coordinates: Sequence[int]) -> tuple[int, tuple[float, ...]] | None:
    """Return the idle freedom that moves exactly ``coordinates``, and its components there."""
    names = [tree.coordinates[c].name for c in coordinates]
    for place, freedom in enumerate(structure.idle):
        if set(freedom.joints) == set(names):
            solved = list(structure.solved)
            return place, tuple(freedom.direction[solved.index(name)] for name in names)
    return None


def _weld_rod(tree: KinematicTree, structure: GroupStructure, closure: Closure,
              ends: list[Turns], values: Sequence[float]
              ) -> tuple[Distance, WeldRod, int | None] | None:
    """Return a welded rod's distance, its follower and the idle freedom it holds, or None."""
    a, b = ends
    turns = (len(a.axes), len(b.axes))
    if min(turns) < 2 or sum(turns) < 5:
        return None
    # b's last frame in a's last frame: its rotation, and its origin (b's centre) from a's,
    # as the known slides in the rod move it: span + Σ (m·q + o)·u
    weld = multiply(a.offset.rotation, transpose(b.offset.rotation))
    span = subtract(a.offset.position, apply(weld, b.offset.position))
    stretch = a.slides + tuple((c, m, o, scale(-1.0, apply(weld, u))) for c, m, o, u in b.slides)
    length = norm(span)
    if not length > COINCIDENT * structure.size:
        return None
    spin = None
    if turns[0] == 2:
        pointing, other, rotation, into = a, b, weld, IDENTITY
    elif turns[1] == 2:
        # seen from b: a's centre, in b's last frame
        pointing, other, rotation = b, a, transpose(weld)
        into = tuple(-x for x in rotation)
    else:
        # two balls: each third turn must spin the rod about its own line (the known slides
        # along it too), the idle freedom moving just those two
        line = [span] + [u for *_, u in stretch]
        if any(norm(cross(a.axes[2], v)) > COINCIDENT * norm(v) for v in line if norm(v)):
            return None
        if norm(cross(a.axes[2], apply(weld, b.axes[2]))) > COINCIDENT:
            return None
        idle = _idle_of(tree, structure, (a.coordinates[2], b.coordinates[2]))
        if idle is None:
            return None
        sign = 1.0 if dot(a.axes[2], apply(weld, b.axes[2])) > 0.0 else -1.0
        coefficients = idle[1]
        if abs(coefficients[0] + coefficients[1] * sign) < 0.5:
            return None
        spin = (sign, (coefficients[0], coefficients[1]),
                (values[a.coordinates[2]], values[b.coordinates[2]]))
        # the pointing end's third turn leaves the rod's line: seen before it
        pointing, other, rotation, into = a, b, weld, a.origins[2]
    distance = Distance(closure.name, ((a.socket, a.center), (b.socket, b.center)),
                        frozenset(a.steps + b.steps), 0 if pointing is a else 1, length,
                        stretch, span)
    follower = WeldRod(closure.name, pointing, other, apply(into, span),
                       tuple((c, m, o, apply(into, u)) for c, m, o, u in stretch), rotation,
                       spin)
    return distance, follower, None if spin is None else idle[0]


def _pin_pair(tree: KinematicTree, structure: GroupStructure, closure: Closure,
              turns: list[Turns], frames: Sequence[Pose], links: dict[int, str],
              values: Sequence[float]) -> tuple[Closure, PinPair, int] | None:
    """Return a weld's pin closure, its follower and the idle freedom it holds, or None."""
    first, second = turns
    if first.socket not in links or second.socket not in links:
        return None
    idle = _idle_of(tree, structure, (first.coordinates[0], second.coordinates[0]))
    if idle is None:
        return None
    # the first turn's origin, carried through the weld to the second's link, then (on its
    # axis, which its turn does not move) into the second's socket
    through = multiply(second.offset.rotation, transpose(first.offset.rotation))
    point = subtract(second.offset.position, apply(through, first.offset.position))
    point = add(second.center, apply(second.origins[0], point))
    axes = (apply(first.origins[0], first.axes[0]), apply(second.origins[0], second.axes[0]))
    world = [frames[turn.socket] for turn in turns]
    directions = [apply(pose.rotation, axis) for pose, axis in zip(world, axes)]
    points = [world[0].then(Pose(first.origins[0], first.center)).position,
              world[1].then(Pose(second.origins[0], point)).position]
    if (norm(cross(*directions)) > COINCIDENT
            or norm(subtract(points[0], points[1])) > COINCIDENT * structure.size):
        return None
    sign = 1.0 if dot(*directions) > 0.0 else -1.0
    coefficients = idle[1]
    if abs(coefficients[0] * sign + coefficients[1]) < 0.5:
        return None
    pin = Closure(closure.name, ClosureKind.PIN,
                  ClosureSide(links[first.socket], first.center, axis=axes[0]),
                  ClosureSide(links[second.socket], point, axis=axes[1]), closure.encoding)
    reference = (values[first.coordinates[0]], values[second.coordinates[0]])
    return (pin, PinPair(closure.name, (first, second), sign, (coefficients[0], coefficients[1]),
                         reference), idle[0])
