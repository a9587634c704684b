# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The parallel benchmark's models and peer adapters (bench/parallel_models.py, parallel_peers.py).

The models' URDF rewriting is pure and always tested, against urchin's forward kinematics of the
original URDF. The adapters need the peers (pin, placo, toolbox-parallel-robots), which the
tests' venv does not carry: ``./dev bench --only parallel`` installs them into .bench-peers/, and
these tests then run on them; without it they are skipped.
"""

from pathlib import Path
import sys

from loop_reference import link_poses
import numpy as np
import pytest

# the bench's modules, as bench/run.py imports them
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / 'bench'))

import parallel_models  # noqa: E402, I100
from parallel_models import (  # noqa: E402
    example_model, EXAMPLE_MODELS, ModelError, MODELS, parallel_model, section_model)
import peers  # noqa: E402

ROD = """<robot name="rods">
  <link name="base"/><link name="crank"/><link name="rod"/>
  <joint name="motor" type="revolute"><parent link="base"/><child link="crank"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="knuckle" type="revolute"><origin xyz="0.1 0 0" rpy="0.1 0.2 0.3"/>
    <parent link="crank"/><child link="rod"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <loop_joint name="tip" type="{kind}"><link1 link="rod" xyz="0 0 0.2" rpy="0 0 0.5"/>
    <link2 link="base" xyz="0.1 0 0.2"/></loop_joint>
</robot>"""
ROD_FILE = "name_mot: ['motor']\njoint_name: ['knuckle']\njoint_type: ['{override}']\n"


def _poses(urdf: str, values: dict[str, float]) -> dict[str, np.ndarray]:
    """Return every link's pose by urchin's forward kinematics (test/loop_reference.py)."""
    return link_poses(urdf, values)


def test_an_override_is_its_joints_about_the_joint_frame_axes_in_order() -> None:
    model = parallel_model('rod', ROD.format(kind='spherical'),
                           ROD_FILE.format(override='UJOINT_ZY'))
    assert model.coordinates == ('motor', 'knuckle_Z', 'knuckle_Y')
    assert model.actuated == ('motor',) and model.passive == ('knuckle_Z', 'knuckle_Y')
    original = _poses(model.source_urdf, {'motor': 0.4})
    rewritten = _poses(model.urdf, {'motor': 0.4, 'knuckle_Z': 0.0, 'knuckle_Y': 0.0})
    for link in ('base', 'crank', 'rod'):
        np.testing.assert_allclose(rewritten[link], original[link], atol=1e-15)
    # about z of the joint frame, then about the turned y: Rz(a)·Ry(b) at the joint's origin
    turned = _poses(model.urdf, {'motor': 0.4, 'knuckle_Z': 0.3, 'knuckle_Y': -0.7})['rod']
    expected = original['rod'] @ _rotation('z', 0.3) @ _rotation('y', -0.7)
    np.testing.assert_allclose(turned, expected, atol=1e-15)


def _rotation(axis: str, angle: float) -> np.ndarray:
    cosine, sine = np.cos(angle), np.sin(angle)
    first, second = {'x': (1, 2), 'y': (2, 0), 'z': (0, 1)}[axis]
    matrix = np.eye(4)
    matrix[first, first] = matrix[second, second] = cosine
    matrix[first, second], matrix[second, first] = -sine, sine
    return matrix


def test_a_closure_side_off_its_link_is_a_frame_of_its_own() -> None:
    model = parallel_model('rod', ROD.format(kind='spherical'),
                           ROD_FILE.format(override='SPHERICAL'))
    assert model.coordinates == ('motor', 'knuckle_X', 'knuckle_Y', 'knuckle_Z')
    (closure,) = model.closures
    assert (closure.parent_frame, closure.child_frame) == ('tip/parent', 'tip/child')
    poses = _poses(model.urdf, dict.fromkeys(model.coordinates, 0.0))
    expected = poses['rod'] @ _translation(0.0, 0.0, 0.2) @ _rotation('z', 0.5)
    np.testing.assert_allclose(poses['tip/parent'], expected, atol=1e-15)
    np.testing.assert_allclose(poses['tip/child'], _translation(0.1, 0.0, 0.2), atol=1e-15)


def _translation(x: float, y: float, z: float) -> np.ndarray:
    matrix = np.eye(4)
    matrix[:3, 3] = (x, y, z)
    return matrix


def test_what_the_peers_cannot_hold_is_refused_by_name() -> None:
    with pytest.raises(ModelError, match="^rod: closure 'tip' is a pin, which no peer holds$"):
        parallel_model('rod', ROD.format(kind='revolute'), ROD_FILE.format(override='FIXED'))
    mimic = ROD.format(kind='spherical').replace(
        '<axis xyz="0 1 0"/>', '<axis xyz="0 1 0"/><mimic joint="motor"/>')
    with pytest.raises(ModelError, match="joint 'knuckle' is a mimic joint"):
        parallel_model('rod', mimic, "name_mot: ['motor']\n")


def test_the_example_models_read_as_the_loader_reads_them() -> None:
    battobot = example_model('battobot_6d')
    assert len(battobot.coordinates) == 30 + 4 * 1 + 2 * 1 + 6 * 2
    assert 'left_spherical_ankle_1_Z' in battobot.coordinates
    assert 'left_spherical_ankle_1' not in battobot.coordinates
    assert {closure.kind.value for name in EXAMPLE_MODELS
            for closure in example_model(name).closures} == {'weld'}
    assert example_model('5bar_linkage').closures[0].parent_frame == 'sphere'
    assert parallel_models.EXAMPLE_FOLDER.is_dir()


needs_peers = pytest.mark.skipif(
    not peers.peers_available(),
    reason='the peers are not installed (./dev bench --only parallel installs them into '
           ".bench-peers/, outside the tests' venv)")


@pytest.fixture(scope='module')
def peer_modules():
    peers.activate(install=False)
    import parallel_bench
    import parallel_peers

    return parallel_peers, parallel_bench


@needs_peers
@pytest.mark.parametrize('name', MODELS)
def test_each_adapter_closes_the_first_sample_of_each_model(peer_modules, name: str) -> None:
    parallel_peers, parallel_bench = peer_modules
    trajectory = parallel_bench.load_trajectories().get(name)
    if name == 'kangaroo_like':
        # no assembly: every start found by Levenberg–Marquardt leaves 0.08 (m, rad)
        assert trajectory is None
        _, residual = parallel_peers.assemble(example_model(name))
        assert 0.07 < residual < 0.09
        return
    model = section_model(name)
    tree = parallel_peers.PinocchioTree(model)
    first = trajectory.samples(model, parallel_bench.SAMPLES)[0]
    followers = [parallel_peers.PinocchioGaussNewton(model),
                 parallel_peers.PlacoClosure(model, steps=10), parallel_peers.ToolboxSlsqp(model)]
    for follower in followers:
        follower.start(trajectory.pose)
        answer = follower.follow(first)
        values, _ = tree.residual(
            tree.configuration(dict(zip(model.coordinates, answer.positions))), False)
        if isinstance(follower, parallel_peers.ToolboxSlsqp) and tree.rows > len(model.passive):
            # SLSQP refuses more equations than free coordinates (exit mode 2: a planar weld's
            # redundant rows, the five-bar's 6 on 4, the delta's 18 on 12) and hands its start
            # back, here already closed
            assert (follower.slsqp.mode, answer.converged) == (2, False)
        else:
            assert answer.converged, follower.label
        assert float(np.max(np.abs(values))) < 1e-12, follower.label
