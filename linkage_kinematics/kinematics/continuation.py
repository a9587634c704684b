# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Continuation through change points: which assembly a smooth motion is in at a crank angle.

``branch`` is the side of B relative to the directed line A→C at the α solved for (+1 left, −1
right; at a change point itself, the side just counterclockwise of it). Away from change points
B never changes sides. A real mechanism driven through a change point continues on the smooth
(analytic) branch, on which B crosses that line, so its side flips at every change point passed.
With an odd number of change points per turn the smooth motion repeats only every two turns;
``turns`` lets a caller that keeps α within one pass (the node) get the branch of any later turn.
The count of change points passed (``turns_past``) serves the slider loops too
(``prismatic_loop``).
"""

from __future__ import annotations

from linkage_kinematics.kinematics.geometry import FourBar, TWO_PI
from linkage_kinematics.kinematics.singular_points import FloatOrArray, offset
import numpy as np


def check_branch(branch: int) -> None:
    """Raise ValueError unless ``branch`` is +1 or −1."""
    if branch not in (1, -1):
        raise ValueError(f'branch must be +1 or -1, got {branch!r}')


def continued_branch(
    linkage: FourBar, alpha_from: float, branch: int, alpha_to: FloatOrArray, turns: int = 0
) -> int | np.ndarray:
    """
    Return the branch at ``alpha_to`` + 2π·``turns`` of a smooth motion.

    The motion has ``branch`` at ``alpha_from`` and turns the crank smoothly from there.

    Away from change points B stays on its side of the line A→C; through a change point the
    mechanism continues on the analytic branch (a parallelogram stays a parallelogram), and
    there B crosses to the other side, so the branch flips at every change point passed.
    Branches follow ``solve``'s convention: at a change point itself, the side just
    counterclockwise of it. ``alpha_to`` may be a float or an array (then so is the result);
    ``turns`` counts whole turns to add, so that a caller that keeps α within one pass (as the
    node does) gets the branch of any later turn without losing α's precision. For a linkage
    with an odd number of change points per turn the branch flips with every turn: its smooth
    motion repeats only every two turns.
    """
    check_branch(branch)
    points = linkage.closure.change_points
    if not points:
        return np.full(np.shape(alpha_to), branch) if isinstance(alpha_to, np.ndarray) else branch
    flips = abs(turns) * len(points)
    for point in points:
        flips = flips + np.abs(turns_past(alpha_to, point) - turns_past(alpha_from, point))
    if isinstance(alpha_to, np.ndarray):
        return np.where(flips % 2 == 0, branch, -branch)
    return branch if flips % 2 == 0 else -branch


def turns_past(alpha: FloatOrArray, point: tuple[float, float]) -> FloatOrArray:
    """
    Return the largest k with point + 2π·k ≤ α.

    How many images of the point lie at or below α, up to a constant. Exact near the images, where
    a rounded (α − point)/2π could be off by one.
    """
    turns = np.floor((alpha - point[0]) / TWO_PI)
    if isinstance(alpha, np.ndarray):
        turns = turns + (offset(alpha, point, turns + 1.0) >= 0.0)
        return turns - (offset(alpha, point, turns) < 0.0)
    turns = float(turns)
    if offset(alpha, point, turns + 1.0) >= 0.0:
        turns += 1.0
    elif offset(alpha, point, turns) < 0.0:
        turns -= 1.0
    return int(turns)
