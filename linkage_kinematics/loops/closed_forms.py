# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Closed forms of the spatial mechanisms that have them, in plain floats.

* ``TurnChain.pointing``: the two angles of a universal joint that point a rod at a target (the
  angles of a rod reduced to a distance, rods.Rod): the component of the rod along the
  first axis is kept by the first turn, so the second angle solves a·cos θ₂ + b·sin θ₂ = c,
  and the first turns the rod onto the target about the first axis.
* ``TurnChain.ball``: the three angles of a ball written as three turns that make a given
  rotation: the first two point the third axis where the rotation takes it, the third turns
  the rest of the way (the joints of a welded rod's ends, reduction.py).
* ``crank_to_sphere`` / ``slide_to_sphere``: one crank–rod–ball leg's inverse: the ball x known
  (the foot's pose known), the crank angle puts the rod's centre P(θ) at the rod's length L
  from x: |x − P(θ)|² = L² is a·cos φ + b·sin φ = c in the turn φ from the current angle (a
  quadratic in a slide's travel).
* ``circle_intersection``: the third pin of a triangle of known sides in a plane (the planar
  five-bar's distal pin from its two cranks, and its inverse), with Heron's factors so that the
  height loses no digits near the workspace boundary.
* ``turn_to``: the angle about an axis that carries one point onto another (the five-bar's
  joint angles once its pins are placed).
* ``three_spheres``: the point at given distances from three centres (a delta's forward
  kinematics: the platform's centre from the three elbows shifted by the platform's offsets).

Each solution has two assemblies; ``branch`` (±1) names one, as the caller found it at the
assembled pose. Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Sequence
import math

from linkage_kinematics.loops.equations import Evaluation, LoopEquations
from linkage_kinematics.loops.spatial import (
    add,
    apply,
    apply_transposed,
    cross,
    dot,
    IDENTITY,
    norm,
    perpendicular_pair,
    Rotation,
    scale,
    subtract,
    Vector,
)
from linkage_kinematics.loops.structure import ClosureGroup, five_bar_cycle, five_bar_pair
from linkage_kinematics.loops.tree import KinematicTree, MotionKind
import numpy as np

# How far beyond ±1 rounding may push the cosine of a reachable angle: a target farther out
# than this is out of reach (the caller refuses the sample).
COSINE_SLACK = 1e-12


class OutOfReach(ValueError):
    """The target cannot be reached by the mechanism (no real solution)."""


def _acos(ratio: float) -> float:
    if abs(ratio) > 1.0 + COSINE_SLACK or not math.isfinite(ratio):
        raise OutOfReach(f'cosine {ratio!r} is beyond ±1')
    return math.acos(max(-1.0, min(1.0, ratio)))


def turn(axis: Vector, cosine: float, sine: float, v: Vector) -> Vector:
    """Return v turned about the unit ``axis`` by the angle of that cosine and sine."""
    ax, ay, az = axis
    x, y, z = v
    along = (1.0 - cosine) * (ax * x + ay * y + az * z)
    return (cosine * x + sine * (ay * z - az * y) + along * ax,
            cosine * y + sine * (az * x - ax * z) + along * ay,
            cosine * z + sine * (ax * y - ay * x) + along * az)


class TurnChain:
    """
    Two or three turns about axes through one point: a universal joint, or a ball (module text).

    Turn i: its joint frame's rotation Oᵢ in the frame above it, then θᵢ about its unit axis
    aᵢ; the joint's rotation is O₁·R(a₁, θ₁)·O₂·R(a₂, θ₂)·…; the turns' angles enter as their
    (cos, sin), computed once per sample. Plain floats.
    """

    def __init__(self, origins: Sequence[Rotation], axes: Sequence[Vector]) -> None:
        self.origins = [None if origin == IDENTITY else origin for origin in origins]
        self.axes = tuple(axes)
        # each axis in the frame above its turn (its origin rotation applied)
        self.lifted = tuple(apply(origin, axis) for origin, axis in zip(origins, axes))
        # the first axis seen before the second turn (``pointing``)
        self.seen = apply_transposed(origins[1], axes[0])
        # a unit vector across the third axis (``ball``)
        self.across = perpendicular_pair(axes[2])[0] if len(axes) > 2 else None

    def forward(self, trig: Sequence[tuple[float, float]], v: Vector) -> Vector:
        """Return O₁·R₁·O₂·R₂·…·v over the turns ``trig`` gives (cos, sin) for."""
        count = len(trig)
        for place in range(count - 1, -1, -1):
            cosine, sine = trig[place]
            v = turn(self.axes[place], cosine, sine, v)
            if self.origins[place] is not None:
                v = apply(self.origins[place], v)
        return v

    def backward(self, trig: Sequence[tuple[float, float]], v: Vector) -> Vector:
        """Return (O₁·R₁·O₂·R₂·…)ᵀ·v over the turns ``trig`` gives (cos, sin) for."""
        for origin, axis, (cosine, sine) in zip(self.origins, self.axes, trig):
            if origin is not None:
                v = apply_transposed(origin, v)
            v = turn(axis, cosine, -sine, v)
        return v

    def pointing(self, vector: Vector, target: Vector, branch: int) -> tuple[float, float]:
        """
        Return the first two turns' angles carrying ``vector`` (their frame) to ``target``.

        ``target`` as long as ``vector``, in the frame above the first turn: the component
        along the first axis is kept by the first turn, so the second angle solves a·cos θ₂ +
        b·sin θ₂ = c and the first turns the vector onto the target. OutOfReach where no
        angles do (beyond rounding).
        """
        first, second = self.axes[0], self.axes[1]
        w = target if self.origins[0] is None else apply_transposed(self.origins[0], target)
        g = self.seen
        along = dot(g, second) * dot(second, vector)
        a = dot(g, vector) - along
        b = dot(g, cross(second, vector))
        angle2 = math.atan2(b, a) + branch * _acos((dot(first, w) - along) / math.hypot(a, b))
        u = turn(second, math.cos(angle2), math.sin(angle2), vector)
        if self.origins[1] is not None:
            u = apply(self.origins[1], u)
        angle1 = math.atan2(dot(first, cross(u, w)), dot(u, w) - dot(first, u) * dot(first, w))
        return angle1, angle2

    def ball(self, third: Vector, across: Vector,
             branch: int) -> tuple[float, float, float]:
        """
        Return a ball's three angles for a rotation R, from R·a₃ and R·``self.across``.

        The first two point the third axis where R takes it (the third turn leaves it), the
        third turns the rest of the way. ``branch`` (±1) picks one of the two triples.
        """
        angle1, angle2 = self.pointing(self.lifted[2], third, branch)
        trig = ((math.cos(angle1), math.sin(angle1)), (math.cos(angle2), math.sin(angle2)))
        rest = self.backward(trig, across)
        if self.origins[2] is not None:
            rest = apply_transposed(self.origins[2], rest)
        p = self.across
        return angle1, angle2, math.atan2(dot(self.axes[2], cross(p, rest)), dot(p, rest))

    def world_axes(self, socket: Rotation, trig: Sequence[tuple[float, float]]) -> list[Vector]:
        """Return the turns' axes in the frame ``socket`` maps from (the one above the first)."""
        return [apply(socket, self.forward(trig[:place], self.lifted[place]))
                for place in range(len(self.axes))]


def crank_to_sphere(origin: Vector, axis: Vector, point: Vector, center: Vector,
                    radius: float, branch: int) -> float:
    """
    Return the turn φ (rad) about ``axis`` through ``origin`` putting ``point`` on the sphere.

    The sphere: ``radius`` about ``center``; a·cos φ + b·sin φ = c. OutOfReach where no turn
    reaches it.
    """
    v = subtract(point, origin)
    along = scale(dot(axis, v), axis)
    radial = subtract(v, along)
    normal = cross(axis, v)
    g = subtract(center, add(origin, along))
    a = 2.0 * dot(g, radial)
    b = 2.0 * dot(g, normal)
    c = dot(g, g) + dot(radial, radial) - radius * radius
    return math.atan2(b, a) + branch * _acos(c / math.hypot(a, b))


def crank_to_sphere_many(origin: tuple, axis: tuple, point: tuple, center: tuple,
                         radius: float, branch: int) -> np.ndarray:
    """
    Return ``crank_to_sphere`` at many poses: each vector a tuple of arrays over them.

    The same formulas; NaN where no turn reaches the sphere (the caller refuses those).
    """
    v = subtract(point, origin)
    along = scale(dot(axis, v), axis)
    radial = subtract(v, along)
    normal = cross(axis, v)
    g = subtract(center, add(origin, along))
    a = 2.0 * dot(g, radial)
    b = 2.0 * dot(g, normal)
    c = dot(g, g) + dot(radial, radial) - radius * radius
    with np.errstate(divide='ignore', invalid='ignore'):
        ratio = c / np.hypot(a, b)
    ratio = np.where(np.abs(ratio) > 1.0 + COSINE_SLACK, np.nan, np.clip(ratio, -1.0, 1.0))
    return np.arctan2(b, a) + branch * np.arccos(ratio)


def slide_to_sphere(point: Vector, axis: Vector, center: Vector, radius: float,
                    branch: int) -> float:
    """
    Return the travel δ (m) along the unit ``axis`` putting ``point`` on the sphere.

    The sphere: ``radius`` L about ``center``; δ² − 2(g·axis)δ + |g|² − L² = 0 with g = center −
    point. OutOfReach where the slide misses it.
    """
    g = subtract(center, point)
    half = dot(g, axis)
    discriminant = half * half - dot(g, g) + radius * radius
    if discriminant < 0.0:
        if discriminant < -COSINE_SLACK * radius * radius:
            raise OutOfReach('the slide does not meet the sphere')
        discriminant = 0.0
    root = math.sqrt(discriminant)
    # the larger root without cancellation, the other from the product of the roots
    large = half + math.copysign(root, half) if half != 0.0 else branch * root
    small = (dot(g, g) - radius * radius) / large if large != 0.0 else 0.0
    upper, lower = max(large, small), min(large, small)
    return upper if branch > 0 else lower


def circle_intersection(p: Vector, q: Vector, radius_p: float, radius_q: float,
                        normal: Vector, branch: int) -> Vector:
    """
    Return the point at ``radius_p`` from p and ``radius_q`` from q in their plane.

    The plane has the unit ``normal``; branch +1 is on the left of p → q about it. OutOfReach
    where the circles do not meet.
    """
    pq = subtract(q, p)
    distance = norm(pq)
    if distance == 0.0:  # concentric: the third pin could be anywhere on the circle
        raise OutOfReach('the two circles have one centre')
    u = scale(1.0 / distance, pq)
    along = (radius_p * radius_p - radius_q * radius_q + distance * distance) / (2.0 * distance)
    # 4d²h² = ((r_p + r_q)² − d²)(d² − (r_p − r_q)²): Heron's factors, each exact to rounding
    outer = (radius_p + radius_q - distance) * (radius_p + radius_q + distance)
    inner = (distance - radius_p + radius_q) * (distance + radius_p - radius_q)
    product = outer * inner
    if product < 0.0:
        if product < -COSINE_SLACK * (radius_p + radius_q) ** 4:
            raise OutOfReach('the circles do not meet')
        product = 0.0
    height = math.sqrt(product) / (2.0 * distance)
    return add(add(p, scale(along, u)), scale(branch * height, cross(normal, u)))


def turn_to(axis: Vector, origin: Vector, point: Vector, target: Vector) -> float:
    """Return the angle (rad) about the unit ``axis`` through ``origin`` taking point → target."""
    u, w = subtract(point, origin), subtract(target, origin)
    return math.atan2(dot(axis, cross(u, w)), dot(u, w) - dot(axis, u) * dot(axis, w))


def three_spheres(centers: tuple[Vector, Vector, Vector], radii: tuple[float, float, float],
                  branch: int) -> Vector:
    """
    Return the point at ``radii`` from the three ``centers``.

    Branch +1 is on the side of (c₂ − c₁) × (c₃ − c₁). OutOfReach where the spheres do not meet.
    """
    c1, c2, c3 = centers
    r1, r2, r3 = radii
    d12 = subtract(c2, c1)
    d = norm(d12)
    ex = scale(1.0 / d, d12)
    d13 = subtract(c3, c1)
    i = dot(ex, d13)
    ey_raw = subtract(d13, scale(i, ex))
    j = norm(ey_raw)
    ey = scale(1.0 / j, ey_raw)
    ez = cross(ex, ey)
    x = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d)
    y = (r1 * r1 - r3 * r3 + i * i + j * j - 2.0 * i * x) / (2.0 * j)
    square = r1 * r1 - x * x - y * y
    if square < 0.0:
        if square < -COSINE_SLACK * r1 * r1:
            raise OutOfReach('the three spheres do not meet')
        square = 0.0
    return add(add(c1, scale(x, ex)), add(scale(y, ey), scale(branch * math.sqrt(square), ez)))


def _wrap(angle: float) -> float:
    return math.remainder(angle, 2.0 * math.pi)


class LegPositions:
    """
    One crank–rod–ball leg's inverse: the crank's value in closed form (closed_forms).

    ``equations`` hold the leg's closure, its rod reduced to a distance, as closure number
    ``closure``: the leg's own, or a group's with both legs (a transmission's, posed once).
    """

    def __init__(self, tree: KinematicTree, group: ClosureGroup, equations: LoopEquations,
                 rod, closure: int = 0) -> None:
        loop = tree.loop(group.closures[0])
        crank = next(step for step in loop.paths[rod.side] if step not in rod.steps
                     and tree.steps[step].coordinate not in group.known)
        self.equations = equations
        self.step = crank
        self.column = equations.coordinates.index(tree.steps[crank].coordinate)
        self.multiplier = tree.steps[crank].multiplier
        self.turn = tree.steps[crank].kind is MotionKind.TURN
        self.length = rod.length
        self.closure = closure
        self.branch = 1

    def move(self, values: list[float], branch: int) -> None:
        """Set the crank's value in ``values`` to the solution on ``branch``."""
        self.move_at(values, self.equations.evaluate(values), branch)

    def move_at(self, values: list[float], evaluation: Evaluation, branch: int) -> None:
        """As ``move``, from ``evaluation``: the equations' at ``values``."""
        axis, origin = self.equations.step_axis(self.step, evaluation)
        ball = self.equations.point(self.closure, 0, evaluation)
        center = self.equations.point(self.closure, 1, evaluation)
        if self.turn:
            change = crank_to_sphere(origin, axis, center, ball, self.length, branch)
        else:
            change = slide_to_sphere(center, axis, ball, self.length, branch)
        values[self.column] += change / self.multiplier

    def reset(self, values: Sequence[float]) -> None:
        """Take the branch the assembled ``values`` lie on."""
        def moved(branch: int) -> float:
            trial = list(values)
            self.move(trial, branch)
            return abs(trial[self.column] - values[self.column])
        self.branch = min((1, -1), key=moved)

    def __call__(self, values: list[float]) -> tuple[int, Evaluation, list]:
        """Move ``values`` to the solution; return 0 iterations, its evaluation and Jacobian."""
        self.move(values, self.branch)
        evaluation = self.equations.evaluate(values)
        return 0, evaluation, self.equations.jacobian(evaluation)


class FiveBarPositions:
    """
    A planar five-bar with two adjacent pins known, placed pin by pin.

    The two pins next to the known pair are placed by the known joints alone, the fifth (the
    apex) where circles about them meet, and each unknown joint then turns its next pin onto
    its place (closed_forms).
    """

    def __init__(self, tree: KinematicTree, group: ClosureGroup,
                 equations: LoopEquations, values: Sequence[float]) -> None:
        """Place the pins at the assembled ``values`` (all the tree's coordinates)."""
        self.equations = equations
        self.cycle = five_bar_cycle(tree, group.closures[0])
        first = five_bar_pair(tree, group, values)
        # the pins next to the known pair, and the apex opposite it
        self.ends = (self.cycle[(first - 1) % 5], self.cycle[(first + 2) % 5])
        self.apex = self.cycle[(first + 3) % 5]
        loop = tree.loop(group.closures[0])
        # the closure's pin as a neighbour: taken on the side whose joints are all known
        self.known_side = 0 if all(tree.steps[step].coordinate in group.known
                                   for step in loop.paths[0]) else 1
        # the unknown joints down each path: its column, multiplier, side, the pin below it
        # (the next joint's, or the closure's on that side) and the columns of the joints
        # above it on its path
        self.unknown = []
        for side, path in enumerate(loop.paths):
            for place, step in enumerate(path):
                if tree.steps[step].coordinate in group.known:
                    continue
                self.unknown.append((
                    step, equations.coordinates.index(tree.steps[step].coordinate),
                    tree.steps[step].multiplier, side,
                    path[place + 1] if place + 1 < len(path) else None,
                    {equations.coordinates.index(tree.steps[above].coordinate)
                     for above in path[:place]}))
        evaluation = equations.evaluate([values[i] for i in equations.coordinates])
        # the first step below the base turns about the plane's normal, fixed in the base
        self.normal = evaluation.frames[0][2][0]
        apex = self.pin(self.apex, evaluation, None)
        # in the plane: the pins may sit at different heights along the axes
        self.radii = tuple(norm(self.planar(subtract(apex, self.pin(end, evaluation,
                                                                    self.known_side))))
                           for end in self.ends)
        self.branch = 1

    def planar(self, vector: Vector) -> Vector:
        """Return ``vector`` without its component along the plane's normal."""
        return subtract(vector, scale(dot(self.normal, vector), self.normal))

    def pin(self, step: int | None, evaluation: Evaluation, side: int | None) -> tuple:
        """Return a pin's position: a joint's origin, or the closure's point on ``side``."""
        if step is None:
            return self.equations.point(0, 0 if side is None else side, evaluation)
        return self.equations.step_axis(step, evaluation)[1]

    def apex_position(self, evaluation: Evaluation, branch: int) -> tuple:
        """Return the apex pin's position on ``branch``."""
        p, q = (self.pin(end, evaluation, self.known_side) for end in self.ends)
        # in the plane through p: each joint turns its pin about its axis, whatever its height
        q = add(p, self.planar(subtract(q, p)))
        return circle_intersection(p, q, self.radii[0], self.radii[1], self.normal, branch)

    def reset(self, values: Sequence[float]) -> None:
        """Take the branch the assembled ``values`` lie on."""
        evaluation = self.equations.evaluate(values)
        apex = self.pin(self.apex, evaluation, None)
        self.branch = min((1, -1), key=lambda branch: norm(subtract(
            self.apex_position(evaluation, branch), apex)))

    def __call__(self, values: list[float]) -> tuple[int, Evaluation, list]:
        """Move ``values`` to the solution; return 0 iterations, its evaluation and Jacobian."""
        evaluation = self.equations.evaluate(values)
        places = {self.apex: self.apex_position(evaluation, self.branch)}
        for pin in self.cycle:  # the known pins and the two next to them
            if pin != self.apex:
                places[pin] = self.pin(pin, evaluation, self.known_side)
        turned: set[int] = set()
        for step, column, multiplier, side, following, above in self.unknown:
            if turned & above:  # a joint above this one has turned: pose it again
                evaluation = self.equations.evaluate(values, evaluation, turned)
            axis, origin = self.equations.step_axis(step, evaluation)
            values[column] += turn_to(axis, origin, self.pin(following, evaluation, side),
                                      places[following]) / multiplier
            turned.add(column)
        evaluation = self.equations.evaluate(values, evaluation, turned)
        return 0, evaluation, self.equations.jacobian(evaluation)
