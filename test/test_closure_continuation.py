# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
loops.newton's continuation on models others wrote: never a jump to another assembly.

The parallel section's models (test/models/example_parallel_robots) and stored motions
(bench/parallel_trajectories.json), as bench/parallel_ours.py follows them, without the peers;
the 50-digit reference is test/closure_reference.py (bench/parallel_reference.py hands it the
section's groups), Newton started from the package's answer, which it must agree with to
1e-12. Which assembly is right is the motion's continuation: the same motion followed in many
short substeps, where each joint moves little (checked), which no step can leave.
"""

from __future__ import annotations

from pathlib import Path
import sys

from linkage_kinematics.loops.newton import plan_group
from linkage_kinematics.loops.refusals import Refusal, SampleRefused
import pytest

# the bench's modules, as bench/run.py imports them
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / 'bench'))

import parallel_bench  # noqa: E402, I100
from parallel_models import section_model  # noqa: E402
from parallel_ours import PackageClosure  # noqa: E402
from parallel_reference import ReferencePath  # noqa: E402


def motion(name: str):
    model = section_model(name)
    trajectory = parallel_bench.load_trajectories()[name]
    return model, trajectory, trajectory.samples(model, parallel_bench.SAMPLES)


def worst(first, second) -> float:
    return max(abs(float(a) - float(b)) for a, b in zip(first, second))


def test_a_ball_of_three_turns_near_its_gimbal_lock_stays_on_its_angle_triple():
    # digit_like's toe rods hang from balls written as three turns; near sample 135 one of
    # them passes its gimbal lock, its first angle moving 1.84 rad in a sample where the
    # first-order prediction says 0.49: Newton from there had gone to the ball's other angle
    # triple (refused 135-138, then answered on it from 139 on)
    model, trajectory, samples = motion('digit_like')
    coarse, fine = PackageClosure(model), PackageClosure(model)
    coarse.start(trajectory.pose)
    fine.start(trajectory.pose)
    for sample in samples[:121]:
        assert coarse.follow(sample) == fine.follow(sample)
    answers = {}
    for index in range(121, 151):
        answer = coarse.follow(samples[index])
        assert answer.converged, index
        answers[index] = answer.positions
        # the same motion in 50 substeps: no joint moves more than 0.1 rad in one
        before = samples[index - 1]
        for step in range(1, 51):
            previous = fine.follow([a + (step - 1) / 50 * (b - a)
                                    for a, b in zip(before, samples[index])]).positions
            substep = fine.follow([a + step / 50 * (b - a)
                                   for a, b in zip(before, samples[index])])
            assert substep.converged and worst(substep.positions, previous) < 0.1
        assert worst(answer.positions, substep.positions) <= 1e-12, index
    path = ReferencePath(model, trajectory.pose)
    for index in (135, 139, 150):
        exact = path.solve(samples[index], answers[index])
        assert exact is not None and worst(answers[index], exact) <= 1e-12, index


def test_a_motion_crossing_a_singular_configuration_is_refused_from_there_on():
    # robot_delta's motion passes a configuration where det A changes sign at sample 14.88
    # (κ up to 1e8) while the mechanism moves on; it crosses back at 110.6, again at 264.9 and
    # 284.5. Which assembly the mechanism is in after such a crossing is not known (after the
    # second pair, going on from sample 264 to 365 without crossing reached an assembly 3.1 rad
    # from the one Gauss-Newton followed through the crossings): every later sample is refused
    # until the group is assembled again
    model, trajectory, samples = motion('robot_delta')
    follower = PackageClosure(model)
    follower.start(trajectory.pose)
    (planned,) = follower.planned
    solver = planned.solver

    def known(index: int) -> list[float]:
        return [samples[index][model.actuated.index(name)] for name in solver.known]

    path = ReferencePath(model, trajectory.pose)
    for index in range(15):
        answer = follower.follow(samples[index])
        assert answer.converged, index
        if index in (0, 14):
            assert worst(answer.positions, path.solve(samples[index], answer.positions)) <= 1e-12
    with pytest.raises(SampleRefused, match=r'the answer would jump to another assembly \(det A '
                       r'changes sign 0\.8\d* of the way from the last sample: the motion crosses '
                       r'a singular configuration\)') as refused:
        solver.solve(known(15), [0.0, 0.0])
    assert refused.value.reason is Refusal.ASSEMBLY_CHANGE and solver.lost
    for index in range(16, 401):
        with pytest.raises(SampleRefused, match='an earlier sample crossed a singular '
                           'configuration') as refused:
            solver.solve(known(index), [0.0, 0.0])
        assert refused.value.reason is Refusal.ASSEMBLY_CHANGE
    # assembled again at sample 120 (back across, on the first side), it goes on from there
    tree = follower.tree
    start = [trajectory.pose[name] for name in tree.names]
    for name, value in zip(model.actuated, samples[120]):
        start[tree.index[name]] = value
    solver.reset(plan_group(tree, follower.groups[0], start).assembly.values)
    assert not solver.lost
    for index in range(120, 141):
        state = solver.solve(known(index), [0.0, 0.0])
    positions = dict(trajectory.pose) | dict(zip(model.actuated, samples[140]))
    positions |= dict(zip(solver.solved, state.positions))
    answer = [positions[name] for name in model.coordinates]
    assert worst(answer, path.solve(samples[140], answer)) <= 1e-12
