# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The parallel section's reference: each model's loops closed at 50 digits (closure_reference.py).

The digits are the independent reference's own: it reads the model's URDF itself, writes the
closure equations its own way and iterates in 50-digit mpmath; nothing of the package computes a
number of it. What it is handed, as the package's tests hand it (test/closure_robots.py):

* **the groups and their unknowns**: the closures the package solves together and the joints it
  solves (``loops.structure``), which only partition the work; the known joints are the sample's
  actuated ones, every other coordinate stays at the trajectory's pose;
* **the idle freedoms' convention**: the reference's own null space of its Jacobian of the
  unknowns at the trajectory's assembled pose, held there (N_refᵀ·(q_U − q_ref) = 0, as the
  package holds them);
* **the branch**: its Newton starts at Pinocchio's Gauss–Newton answer to the same sample
  (bench/parallel_peers.py, continued sample by sample from the assembled pose and iterated to
  stagnation: the assembly a continuation keeps), so that it polishes to 50 digits the
  assembly every follower is meant to stay on. An answer whose determined joints (those in no
  idle freedom: Gauss–Newton's minimum-norm steps let the idle ones drift) are more than
  ``SAME_BRANCH`` from that start is not taken: the sample then has no reference and is left
  out of the errors.

The models are exporters' drawings, exact only to their printed digits: a planar loop welded in
3D, whose rows are redundant when drawn exactly, closes at 50 digits only to about 1e-16, and
its idle freedoms' singular values are about 1e-16 rather than 0. So the null space is taken
below ``NULL`` and the closure accepted below ``RESIDUAL`` (test/closure_reference.py's module
text): the reference is then the least-squares closure, which differs from an exact closure of
the rounded drawing by that residual times the conditioning, float64's floor for these inputs.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from closure_reference import Reference
from linkage_kinematics.loops.encodings import read_closures
from linkage_kinematics.loops.newton import plan_group
from linkage_kinematics.loops.structure import closure_groups, Determinacy
from linkage_kinematics.loops.tree import KinematicTree
from linkage_kinematics.model.urdf_reader import read_urdf
from mpmath import mp, mpf
from parallel_models import ParallelModel

# Singular values of the unknowns' Jacobian (m or rad per rad or m) below this span the idle
# freedoms: an exporter's digits leave them near 1e-16; the smallest determining ones of the
# section's models at their assembled poses are above 1e-4.
NULL = mpf('1e-12')
# The largest closure residual (m, rad) the reference accepts: these drawings close to 1e-16.
RESIDUAL = mpf('1e-13')
# An answer farther than this (rad or m) from the start it was polished from left that assembly.
SAME_BRANCH = 1e-6


class ReferencePath:
    """A model's loops at 50 digits, sample by sample (module docstring)."""

    def __init__(self, model: ParallelModel, pose: Mapping[str, float]) -> None:
        """Set up the reference's groups at the assembled ``pose`` (every coordinate by name)."""
        urdf = read_urdf(model.source_urdf)
        description = read_closures(urdf, model.closure_file)
        tree = KinematicTree(urdf, description.overrides)
        overrides = {joint: override.value for joint, override in description.overrides.items()}
        start = [float(pose[name]) for name in tree.names]
        self.model = model
        self.pose = dict(pose)
        self.groups = []
        # the package's own verdict, for the section's notes: the groups whose actuated joints
        # leave free motions, which the reference holds by its convention only
        self.undetermined: list[str] = []
        for group in closure_groups(tree, description.closures, model.actuated):
            structure = plan_group(tree, group, start).structure
            if structure.determinacy is Determinacy.UNDER:
                self.undetermined.append(group.name)
            reference = Reference(model.source_urdf, group.closures, overrides)
            unknown = list(structure.solved)
            basis = reference.idle_basis(self.pose, unknown, NULL)
            determined = [name for row, name in enumerate(unknown)
                          if all(abs(basis[row, column]) <= SAME_BRANCH
                                 for column in range(basis.cols))]
            self.groups.append((reference, unknown, basis, determined))

    def solve(self, actuated: Sequence[float], guess: Sequence[float]) -> tuple | None:
        """
        Return every coordinate (``model.coordinates``' order) for the actuated joints' values.

        The solved ones as 50-digit mpf, the others as given (floats). ``guess``: every
        coordinate's start for Newton, in the same order. None where the reference does not
        close the sample on the guess's assembly.
        """
        values = dict(self.pose)
        values.update(zip(self.model.actuated, actuated))
        start = dict(zip(self.model.coordinates, guess))
        for reference, unknown, basis, determined in self.groups:
            known = {name: value for name, value in values.items() if name not in unknown}
            try:
                solved = reference.solve(known, start, unknown, (basis, self.pose), RESIDUAL)
            except RuntimeError:
                return None
            with mp.workdps(50):
                if any(abs(solved[name] - mpf(start[name])) > SAME_BRANCH
                       for name in determined):
                    return None
            values.update(solved)
        return tuple(values[name] for name in self.model.coordinates)
