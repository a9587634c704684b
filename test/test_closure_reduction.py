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
    # a rod of two halves, each on a ball of three turns whose third spins the rod: a distance
    # between the balls' centres (8 coordinates; 1 row, was 6)
    'cassie_like': ([GroupKind.NEWTON, GroupKind.NEWTON], [2, 2], (1, 99)),
    'digit_like': ([GroupKind.NEWTON, GroupKind.NEWTON], [3, 4], (1, 99)),
    # a rod on a universal joint welded to a ball of three turns (7 and 14)
    'battobot_6d': ([GroupKind.NEWTON] * 4, [2, 2, 4, 4], (1, 99)),
    # five legs of a hexapod, each a ball, a motor's slide and a ball: rods their motors
    # lengthen (42; Newton is left the sixth leg's two balls, 6 unknowns, was 36)
    'wl16_like': ([GroupKind.NEWTON], [12], (1, 99)),
}


def follow(name: str, count: int):
    """Return the model, its trajectory, samples, reference and follower after ``count``."""
    model = section_model(name)
    trajectory = parallel_bench.load_trajectories()[name]
    samples = trajectory.samples(model, parallel_bench.SAMPLES)
    follower = PackageClosure(model)
    follower.start(trajectory.pose)
    return model, trajectory, samples, ReferencePath(model, trajectory.pose), follower


@pytest.mark.parametrize('name', list(MODELS))
def test_a_rewritten_model_follows_its_motion_within_1e_12_of_the_reference(name):
    kinds, sizes, checked = MODELS[name]
    model, trajectory, samples, path, follower = follow(name, 0)
    assert [planned.kind for planned in follower.planned] == kinds
    assert [len(planned.solver.equations.coordinates) for planned in follower.planned] == sizes
    for index, sample in enumerate(samples[:max(checked) + 1]):
        answer = follower.follow(sample)
        assert answer.converged, index
        if index in checked:
            exact = path.solve(sample, answer.positions)
            assert max(abs(float(a) - float(b)) for a, b in zip(answer.positions, exact)) <= \
                1e-12, index
    # the velocities, from the rewritten closures' Jacobian and the joints' closed forms,
    # against the reference's from the welds as written (at the first sample checked: the
    # delta's last is near its singular configuration, κ 5.6e4)
    follower.start(trajectory.pose)
    for sample in samples[:checked[0] + 1]:
        answer = follower.follow(sample)
    values = dict(zip(model.coordinates, path.solve(sample, answer.positions)))
    for planned, (reference, unknown, basis, _) in zip(follower.planned, path.groups):
        solver = planned.solver
        known = [sample[model.actuated.index(name)] for name in solver.known]
        rates = [0.3 + 0.1 * k for k in range(len(known))]
        state = solver.solve(known, rates)
        exact_rates = reference.velocities(values, dict(zip(solver.known, rates)), unknown,
                                           basis)
        size = max(abs(float(rate)) for rate in exact_rates.values())
        assert max(abs(float(exact_rates[name]) - rate) for name, rate in
                   zip(solver.solved, state.velocities)) <= 1e-12 * size
