# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The closure equations' exact Jacobian at many configurations at once: a trajectory's points.

``equations.LoopEquations`` is the per-sample path, in plain floats (a 1 kHz command, a measured
sample). A trajectory of N points needs the same Jacobian N times; in numpy, every scalar of the
per-sample formulas becomes an array over the points, and N points cost about what a few cost
one by one. Same model, same rows and columns (``LoopEquations.coordinates`` order, rows as its
``closure_rows``), same formulas in the same order of operations, but for the frames' turns,
composed here as R_parent·(R₀ + sin θ·R₀K + (1 − cos θ)·R₀K²) for every turn (the per-sample
path mixes two columns of the parent for a turn about a principal axis): the two agree to a few
ulps.

Closures it holds: BALL, PIN and a DISTANCE of fixed length (a rod with a universal joint at
one end, the ankle's legs). A WELD's log-map rows and a rod stretched by known slides are not
written here: ``BatchEquations.supports`` says False and the caller keeps the per-sample path.
Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from linkage_kinematics.loops.closures import Closure, ClosureKind
from linkage_kinematics.loops.rods import Distance, Rod, rod_distance
from linkage_kinematics.loops.spatial import (
    apply,
    cross,
    IDENTITY,
    multiply,
    perpendicular_pair,
    rodrigues_parts,
    Rotation,
    Vector,
    ZERO,
)
from linkage_kinematics.loops.tree import KinematicTree, MotionKind, unit_axis
import numpy as np

# a rotation or a vector whose entries are floats (fixed) or arrays over the points
_Batch = tuple


@dataclass(frozen=True)
class _Side:
    """One side of a closure: its moving frame and the point (and rotation) on it."""

    frame: int
    rotation: Rotation
    point: Vector
    # the steps between the loop's base and the side: (tree step, column, multiplier, turn)
    steps: tuple[tuple[int, int, float, bool], ...]


@dataclass(frozen=True)
class _Closure:
    """What one closure's rows need (``kind``: BALL, PIN, or None for a distance)."""

    kind: ClosureKind | None
    base: int
    sides: tuple[_Side, _Side]
    # a distance's length and the side its centre P is on; a pin's n_a, u₁, u₂
    length: float = 0.0
    center: int = 0
    pin: tuple[Vector, Vector, Vector] = (ZERO, ZERO, ZERO)


@dataclass(frozen=True)
class BatchEvaluation:
    """The frames (per base, per moving frame) and each closure's two points, N rows."""

    count: int
    frames: dict[int, dict[int, tuple]]
    points: list[tuple[_Batch, _Batch]]


class BatchEquations:
    """The Jacobian of ``LoopEquations(tree, closures, rods)`` at many points (module doc)."""

    def __init__(self, tree: KinematicTree, closures: Sequence[Closure],
                 rods: Mapping[str, Rod | Distance], coordinates: Sequence[int]) -> None:
        """``coordinates``: the per-sample equations' columns (``LoopEquations.coordinates``)."""
        self.tree = tree
        self.width = len(coordinates)
        self._column = column = {coordinate: place
                                 for place, coordinate in enumerate(coordinates)}
        self.supports = True
        self._closures: list[_Closure] = []
        # per loop base, the tree steps below it that the closures need, in tree order
        self._steps: dict[int, list[int]] = {}
        for closure in closures:
            loop = tree.loop(closure)
            rod = rods.get(closure.name)
            distance = rod_distance(rod) if isinstance(rod, Rod) else rod
            if closure.kind is ClosureKind.WELD or (distance is not None and distance.stretch):
                self.supports = False
                return
            sides = []
            for index in (0, 1):
                frame, offset = loop.sides[index]
                rotation, point = offset.rotation, offset.position
                path = loop.paths[index]
                if distance is not None:
                    path = tuple(step for step in path if step not in distance.trimmed)
                    if distance.points[index] is not None:
                        frame, point = distance.points[index]
                        rotation = IDENTITY
                steps = tuple((step, column[tree.steps[step].coordinate],
                               tree.steps[step].multiplier,
                               tree.steps[step].kind is MotionKind.TURN) for step in path)
                self._steps.setdefault(loop.base, [])
                self._steps[loop.base] = sorted(set(self._steps[loop.base]) | set(path))
                sides.append(_Side(frame, rotation, point, steps))
            if distance is not None:
                self._closures.append(_Closure(None, loop.base, (sides[0], sides[1]),
                                               distance.length, distance.center))
            elif closure.kind is ClosureKind.PIN:
                n_a = apply(sides[0].rotation, unit_axis(closure.parent))
                u1, u2 = perpendicular_pair(apply(sides[1].rotation, unit_axis(closure.child)))
                self._closures.append(_Closure(ClosureKind.PIN, loop.base,
                                               (sides[0], sides[1]), pin=(n_a, u1, u2)))
            else:
                self._closures.append(_Closure(ClosureKind.BALL, loop.base,
                                               (sides[0], sides[1])))
        # per turning step: R₀ and its Rodrigues parts R₀K, R₀K², entry by entry
        self._turns = {}
        for number in {step for steps in self._steps.values() for step in steps}:
            step = tree.steps[number]
            if step.kind is MotionKind.TURN:
                k1, k2 = rodrigues_parts(step.axis)
                self._turns[number] = (step.origin.rotation, multiply(step.origin.rotation, k1),
                                       multiply(step.origin.rotation, k2))
        self._rows = sum(1 if c.kind is None else 5 if c.kind is ClosureKind.PIN else 3
                         for c in self._closures)

    def _frames(self, values: np.ndarray) -> dict[int, dict[int, tuple]]:
        """
        Return per base, per moving frame below it: (rotation, origin, axis ω, joint origin o).

        In the base's frame; ``values`` (N, width) over the columns, a step's frame from its
        parent's (the base: identity at the origin).
        """
        tree = self.tree
        frames: dict[int, dict[int, tuple]] = {}
        for base, steps in self._steps.items():
            posed: dict[int, tuple] = {base: (IDENTITY, ZERO, ZERO, ZERO)}
            for number in steps:
                step = tree.steps[number]
                rp, pp, _, _ = posed[step.parent]
                shift = apply(rp, step.origin.position)
                o = (pp[0] + shift[0], pp[1] + shift[1], pp[2] + shift[2])
                value = step.multiplier * values[:, self._column[step.coordinate]] + step.offset
                w = apply(rp, apply(step.origin.rotation, step.axis))
                # below the base the parent's rotation is the identity: the child's is its own
                at_base = step.parent == base
                if step.kind is MotionKind.TURN:
                    s, t = np.sin(value), 1.0 - np.cos(value)
                    turned = tuple(_turned_entry(r, s, bi, t, di)
                                   for r, bi, di in zip(*self._turns[number]))
                    posed[number + 1] = (turned if at_base else multiply(rp, turned), o, w, o)
                else:
                    posed[number + 1] = (step.origin.rotation if at_base
                                         else multiply(rp, step.origin.rotation),
                                         (o[0] + value * w[0], o[1] + value * w[1],
                                          o[2] + value * w[2]), w, o)
            frames[base] = posed
        return frames

    def evaluate(self, values: np.ndarray) -> BatchEvaluation:
        """Return the frames and every closure's two points at each row of ``values``."""
        frames = self._frames(values)
        points = []
        for closure in self._closures:
            posed = frames[closure.base]
            pair = []
            for side in closure.sides:
                r, p, _, _ = posed[side.frame]
                shift = apply(r, side.point)
                pair.append((p[0] + shift[0], p[1] + shift[1], p[2] + shift[2]))
            points.append((pair[0], pair[1]))
        return BatchEvaluation(values.shape[0], frames, points)

    def point(self, closure: int, side: int, evaluation: BatchEvaluation) -> _Batch:
        """
        Return a closure side's point in its loop's base frame, per row.

        As ``LoopEquations.point``: for a distance, side 0 is the ball x, side 1 the centre P.
        """
        found = self._closures[closure]
        if found.kind is None and found.center == 0:
            side = 1 - side
        return evaluation.points[closure][side]

    def step_axis(self, step: int, evaluation: BatchEvaluation) -> tuple[_Batch, _Batch]:
        """Return a tree step's world axis ω and joint origin o in its base frame, per row."""
        for posed in evaluation.frames.values():
            if step + 1 in posed:
                _, _, w, o = posed[step + 1]
                return w, o
        raise KeyError(f'step {step} moves none of the closures')

    def jacobian(self, evaluation: BatchEvaluation) -> np.ndarray:
        """Return ∂(residual)/∂(coordinates) at each evaluated row: (N, rows, width)."""
        frames = evaluation.frames
        result = np.zeros((evaluation.count, self._rows, self.width))
        row = 0
        for closure, (p_a, p_b) in zip(self._closures, evaluation.points):
            posed = frames[closure.base]
            if closure.kind is None:
                length = closure.length
                d = ((p_a[0] - p_b[0]) / length, (p_a[1] - p_b[1]) / length,
                     (p_a[2] - p_b[2]) / length)
                if closure.center == 0:  # x is the child side: the residual's d is x − P
                    d = (-d[0], -d[1], -d[2])
                for side, point, sign in ((closure.sides[0], p_a, 1.0),
                                          (closure.sides[1], p_b, -1.0)):
                    if closure.center == 0:
                        sign = -sign
                    for step, col, multiplier, turn in side.steps:
                        _, _, w, o = posed[step + 1]
                        if turn:
                            r = (point[0] - o[0], point[1] - o[1], point[2] - o[2])
                            term = (w[0] * (r[1] * d[2] - r[2] * d[1])
                                    + w[1] * (r[2] * d[0] - r[0] * d[2])
                                    + w[2] * (r[0] * d[1] - r[1] * d[0]))
                        else:
                            term = w[0] * d[0] + w[1] * d[1] + w[2] * d[2]
                        result[:, row, col] += sign * multiplier * term
                row += 1
                continue
            pin = closure.kind is ClosureKind.PIN
            if pin:
                n_a = apply(posed[closure.sides[0].frame][0], closure.pin[0])
                r_b = posed[closure.sides[1].frame][0]
                n0 = cross(n_a, apply(r_b, closure.pin[1]))
                n1 = cross(n_a, apply(r_b, closure.pin[2]))
            for side, point, sign in ((closure.sides[0], p_a, 1.0),
                                      (closure.sides[1], p_b, -1.0)):
                for step, col, multiplier, turn in side.steps:
                    _, _, w, o = posed[step + 1]
                    factor = sign * multiplier
                    if not turn:
                        for axis in range(3):
                            result[:, row + axis, col] += factor * w[axis]
                        continue
                    r = (point[0] - o[0], point[1] - o[1], point[2] - o[2])
                    result[:, row, col] += factor * (w[1] * r[2] - w[2] * r[1])
                    result[:, row + 1, col] += factor * (w[2] * r[0] - w[0] * r[2])
                    result[:, row + 2, col] += factor * (w[0] * r[1] - w[1] * r[0])
                    if pin:
                        result[:, row + 3, col] += factor * (w[0] * n0[0] + w[1] * n0[1]
                                                             + w[2] * n0[2])
                        result[:, row + 4, col] += factor * (w[0] * n1[0] + w[1] * n1[1]
                                                             + w[2] * n1[2])
            row += 5 if pin else 3
        return result


def _turned_entry(r: float, s: np.ndarray, b: float, t: np.ndarray, d: float) -> _Batch:
    """Return r + s·b + t·d, its zero terms left out (the same bits: adding 0 changes none)."""
    entry = r
    if b:
        entry = entry + s * b
    if d:
        entry = entry + t * d
    return entry
