# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
loops.reduction: welds rewritten as smaller closures on models others wrote, at the floor.

Gepetto's example-parallel-robots (test/models/example_parallel_robots) close every loop by a
weld; the package rewrites it where the joints at its ends allow and gives those joints in
closed form. Checked on the parallel section's stored motions (bench/parallel_trajectories.json)
against the 50-digit reference (test/closure_reference.py through bench/parallel_reference.py),
which solves the welds as written, every coordinate (idle ones too, held by the same
convention) within 1e-12.
"""

from __future__ import annotations

from pathlib import Path
import sys

from linkage_kinematics.loops.structure import GroupKind
import pytest

# the bench's modules, as bench/run.py imports them
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / 'bench'))

import parallel_bench  # noqa: E402, I100
from parallel_models import section_model  # noqa: E402
from parallel_ours import PackageClosure  # noqa: E402
from parallel_reference import ReferencePath  # noqa: E402

# model: how each group is solved, the coordinates its rewritten loops move (was: the weld's),
# the samples checked against the reference (of the first 100; robot_delta's motion crosses a
# singular configuration at sample 14.88)
MODELS = {
    # the two collinear pins at the weld are a pin (was 6): a planar five-bar, in closed form
    '5bar_linkage': ([GroupKind.FIVE_BAR], [4], (1, 99)),
    # three welds of collinear pins (14)
    'robot_delta': ([GroupKind.NEWTON], [8], (1, 14)),
    # a rod of two halves, each on a ball of three turns: the last turns, about the rod, are
    # collinear pins (8)
    'cassie_like': ([GroupKind.NEWTON, GroupKind.NEWTON], [6, 6], (1, 99)),
    'digit_like': ([GroupKind.NEWTON, GroupKind.NEWTON], [7, 12], (1, 99)),
}


@pytest.mark.parametrize('name', list(MODELS))
def test_a_rewritten_model_follows_its_motion_within_1e_12_of_the_reference(name):
    kinds, sizes, checked = MODELS[name]
    model = section_model(name)
    trajectory = parallel_bench.load_trajectories()[name]
    samples = trajectory.samples(model, parallel_bench.SAMPLES)
    follower = PackageClosure(model)
    follower.start(trajectory.pose)
    assert [planned.kind for planned in follower.planned] == kinds
    assert [len(planned.solver.equations.coordinates) for planned in follower.planned] == sizes
    path = ReferencePath(model, trajectory.pose)
    for index, sample in enumerate(samples[:max(checked) + 1]):
        answer = follower.follow(sample)
        assert answer.converged, index
        if index in checked:
            exact = path.solve(sample, answer.positions)
            assert max(abs(float(a) - float(b)) for a, b in zip(answer.positions, exact)) <= \
                1e-12, index
