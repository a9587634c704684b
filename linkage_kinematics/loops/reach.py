# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
How far each known joint of a closure group reaches from its assembly, the others held there.

A group of the general closure has no closed-form range as a planar loop has (its reachable
set is a region in several known joints at once). ``reach`` gives what a lab can read: each
known joint's interval on the assembly's branch with the other known joints held at their
assembled values, found by continuation from the assembly both ways with the group's own
solver, in steps of at most ``STEP`` (rad, or ``STEP`` of the group's size for a slide), each
step that is refused retried four times shorter, until a step of ``RESOLUTION`` of that is
still refused. Each end says why it ends (``refusals.Refusal``: no assembly reaches further, a
singular configuration, the answer would jump to another assembly); a turn that goes round
whole without a refusal is a full turn. The checker prints it for groups of one and two known
joints. Plan time: a few hundred solves per joint. Pure: no ROS.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from linkage_kinematics.loops.newton import GroupSolver, PlannedGroup
from linkage_kinematics.loops.refusals import Refusal, SampleRefused
from linkage_kinematics.loops.tree import KinematicTree, MotionKind

STEP = math.radians(1.0)
RESOLUTION = 1e-6
SHRINK = 4.0


@dataclass(frozen=True)
class JointReach:
    """
    A known joint's interval from the assembly (rad or m), and why each end ends.

    ``ends``: the refusal at the low end and at the high end; ``conditioning``: the solver's
    conditioning at each end (large where the end is a singular configuration, the workspace's
    boundary); ``full_turn``: a turn continued a whole turn both ways without a refusal (then
    ``low`` and ``high`` are a turn either side).
    """

    joint: str
    low: float
    high: float
    ends: tuple[Refusal | None, Refusal | None]
    conditioning: tuple[float, float]
    full_turn: bool


def _continue(solver: GroupSolver, known: list[float], place: int, direction: float,
              step: float, limit: float) -> tuple[float, Refusal | None, float]:
    """
    Return how far the known joint ``place`` goes in ``direction``, why it stops, and κ there.

    The solver starts at the assembly (``known``).
    """
    start = known[place]
    rates = [0.0] * len(known)
    last, length = start, step
    conditioning = solver.solve(known, rates).conditioning
    while abs(last - start) < limit:
        trial = list(known)
        trial[place] = last + direction * min(length, limit - abs(last - start))
        try:
            conditioning = solver.solve(trial, rates).conditioning
        except SampleRefused as error:
            if length <= RESOLUTION * step:
                return last, error.reason, conditioning
            length /= SHRINK
            continue
        last = trial[place]
        length = min(length * 2.0, step)
    return last, None, conditioning


def reach(tree: KinematicTree, planned: PlannedGroup) -> tuple[JointReach, ...]:
    """
    Return each known joint's reach from the group's assembly (module docstring).

    ``planned`` has a solver (``newton.plan_group``); it is left at the assembly.
    """
    solver, assembly = planned.solver, planned.assembly
    values = dict(zip(tree.names, assembly.values))
    known = [values[name] for name in solver.known]
    reaches = []
    for place, name in enumerate(solver.known):
        turn = tree.coordinates[tree.index[name]].kind is MotionKind.TURN
        step = STEP if turn else STEP * planned.structure.size
        limit = 2.0 * math.pi if turn else 10.0 * planned.structure.size
        ends = []
        for direction in (-1.0, 1.0):
            solver.reset(assembly.values)
            ends.append(_continue(solver, known, place, direction, step, limit))
        (low, low_end, low_conditioning), (high, high_end, high_conditioning) = ends
        reaches.append(JointReach(name, low, high, (low_end, high_end),
                                  (low_conditioning, high_conditioning),
                                  turn and low_end is None and high_end is None))
    solver.reset(assembly.values)
    return tuple(reaches)
