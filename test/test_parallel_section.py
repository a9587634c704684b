# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The parallel section's own parts, none of which needs the peers.

The humanoid ankle as a model (bench/parallel_models.py), the package's follower
(parallel_ours.py), the 50-digit reference path (parallel_reference.py) and the rows and table
(parallel_bench.py).
"""

from pathlib import Path
import sys

from loop_reference import link_poses
from mpmath import mpf
import numpy as np
import pytest

# the bench's modules, as bench/run.py imports them
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / 'bench'))

import parallel_bench  # noqa: E402, I100
from parallel_models import ANKLE, section_model  # noqa: E402
from parallel_ours import PackageClosure, StartRefused  # noqa: E402
from parallel_peers import Answer  # noqa: E402
from parallel_reference import ReferencePath  # noqa: E402


def test_the_ankle_is_read_from_its_urdf_its_continuous_joints_revolute_for_the_peers() -> None:
    model = section_model(ANKLE)
    assert model.actuated == ('motor_left', 'motor_right')
    assert [closure.name for closure in model.closures] == ['ball_left', 'ball_right']
    assert set(model.passive) == {'ankle_pitch', 'ankle_roll', 'rod_left_u1', 'rod_left_u2',
                                  'rod_right_u1', 'rod_right_u2'}
    assert 'type="continuous"' not in model.urdf
    values = dict(zip(model.coordinates, np.linspace(-0.3, 0.4, len(model.coordinates))))
    original, rewritten = link_poses(model.source_urdf, values), link_poses(model.urdf, values)
    for link, pose in original.items():
        np.testing.assert_allclose(rewritten[link], pose, atol=1e-15)


@pytest.fixture(scope='module')
def ankle():
    model = section_model(ANKLE)
    trajectory = parallel_bench.load_trajectories()[ANKLE]
    return model, trajectory, trajectory.samples(model, parallel_bench.SAMPLES)


def test_the_package_follows_the_ankle_within_1e_12_of_the_50_digit_reference(ankle) -> None:
    model, trajectory, samples = ankle
    follower = PackageClosure(model)
    follower.start(trajectory.pose)
    path = ReferencePath(model, trajectory.pose)
    checked = 0
    for index, sample in enumerate(samples[:61]):
        answer = follower.follow(sample)
        assert answer.converged
        # the actuated joints are the sample's, in the model's order of coordinates
        assert [answer.positions[model.coordinates.index(name)]
                for name in model.actuated] == list(sample)
        if index % 20 == 0:
            exact = path.solve(sample, answer.positions)
            assert max(abs(float(value - wanted)) for value, wanted
                       in zip(answer.positions, exact)) <= 1e-12, index
            checked += 1
    assert checked == 4
    assert 1.0 < follower.conditioning < 10.0
    # started again at the pose, it answers as a new one does
    follower.start(trajectory.pose)
    fresh = PackageClosure(model)
    fresh.start(trajectory.pose)
    assert follower.follow(samples[30]) == fresh.follow(samples[30])


def test_the_package_refuses_to_start_where_the_actuated_joints_leave_free_motion() -> None:
    model = section_model('disney_like')
    trajectory = parallel_bench.load_trajectories()['disney_like']
    follower = PackageClosure(model)
    with pytest.raises(StartRefused, match=r'under-determined, a free motion moves .*; 8 known '
                                           r'joints are needed$'):
        follower.start(trajectory.pose)


def test_a_row_takes_errors_at_the_reference_samples_only_and_the_idle_joints_apart() -> None:
    model = section_model('5bar_linkage')
    trajectory = parallel_bench.load_trajectories()['5bar_linkage']
    idle = set(trajectory.idle)
    assert idle == {'closedloop1_A', 'closedloop1_B'}
    exact_positions = tuple(mpf(index) / 10 for index in range(len(model.coordinates)))

    def answer(offset: float, idle_offset: float, converged: bool = True) -> Answer:
        return Answer(tuple(float(value) + (idle_offset if name in idle else offset)
                            for name, value in zip(model.coordinates, exact_positions)),
                      converged)

    nan = Answer((float('nan'),) * len(model.coordinates), False)
    answers = [answer(1e-13, 1e-3), answer(5.0, 5.0), nan, answer(2e-13, 0.0, False),
               answer(2.0 * np.pi + 3e-14, 0.0)]
    exact = {0: exact_positions, 2: exact_positions, 3: exact_positions, 4: exact_positions}
    row = parallel_bench.follower_row(model, trajectory, 'a follower', answers, exact,
                                      [1e-6, 2e-6, 3e-6, 4e-6, 5e-6])
    # sample 1 has no reference, sample 2 no answer; a whole turn is the same angle
    assert row.error == pytest.approx(2e-13, rel=1e-3)
    assert row.idle_difference == pytest.approx(1e-3, rel=1e-9)
    assert (row.samples, row.failures, row.median_time) == (5, 2, 3e-6)


def test_the_table_shows_a_follower_that_refused_to_start_without_figures() -> None:
    refused = parallel_bench.Row('m', 'ours', 100, float('nan'), float('nan'), float('nan'),
                                 float('nan'), 100)
    answered = parallel_bench.Row('m', 'peer', 100, 2e-15, 0.0, 1.5e-5, 2e-5, 0)
    text = parallel_bench.table([refused, answered], {'m': ['a note']}, 10)
    assert text.splitlines()[0] == ('Errors against the 50-digit reference at every 10-th '
                                    'sample; times over every sample.')
    assert '| m | ours | – | – | – | – | 100 of 100 |' in text
    assert '| m | peer | 2.0e-15 | – | 15.0 µs | 20.0 µs | 0 of 100 |' in text
    assert text.endswith('\n- m: a note')
