# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
urdf/humanoid_ankle.urdf: the package's parallel ankle, closed from its two motors.

The file is installed (setup.py's urdf/*.urdf), reads as a URDF, can be given to the node with
``-p robot_description:="$(cat …)"`` (no comment holds a colon: rcl reads -p values as YAML,
where a colon and a space start a mapping), is drawn assembled with realistic dimensions,
and every answer of the closure closes its loops by urchin's forward kinematics. Pitch and roll
known, each leg's motor comes back by the leg's closed form, and forward again to the same
pitch and roll.
"""

from __future__ import annotations

from glob import glob
import itertools
import math
from pathlib import Path
import re
import tempfile

import closure_robots
from linkage_kinematics.model.urdf_reader import read_urdf
import numpy as np
import pytest
import urchin

REPOSITORY = Path(__file__).resolve().parent.parent
URDF = REPOSITORY / 'urdf' / 'humanoid_ankle.urdf'


def test_the_urdf_is_installed_readable_and_safe_to_pass_with_p():
    setup = (REPOSITORY / 'setup.py').read_text(encoding='utf-8')
    assert "glob('urdf/*.urdf')" in setup
    assert str(URDF.relative_to(REPOSITORY)) in glob('urdf/*.urdf', root_dir=REPOSITORY)
    text = URDF.read_text(encoding='utf-8')
    tree = read_urdf(text)
    assert tree.name == 'humanoid_ankle' and tree.parser_messages == ()
    comments = re.findall(r'<!--(.*?)-->', text, re.DOTALL)
    assert len(comments) == 2 and not any(':' in comment for comment in comments)
    constraints = [(c.get('name'), c.get('type')) for c in tree.element.findall('constraint')]
    assert constraints == [('ball_left', 'spherical'), ('ball_right', 'spherical')]


def test_it_has_the_common_dimensions_and_is_drawn_assembled():
    planned = closure_robots.plan(closure_robots.ankle())
    tree = planned.tree
    crank = [tree.link_pose(f'rod_{s}_cross', [0.0] * 8).position for s in ('left', 'right')]
    motor = [tree.link_pose(f'crank_{s}', [0.0] * 8).position for s in ('left', 'right')]
    assert [math.dist(a, b) for a, b in zip(crank, motor)] == [0.045, 0.045]
    assert [rod.length for rod in (r[1] for r in planned.solver._rods.rods)] == [0.23, 0.23]
    assert [round(p[1], 12) for p in crank] == [0.035, -0.035]
    assert max(gap.position for gap in planned.assembly.start_gaps) <= 1e-16


def urchin_gaps(text: str, values: dict[str, float]) -> list[float]:
    """Return each ball's gap (m) by urchin's forward kinematics of the URDF."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / 'ankle.urdf'
        path.write_text(text, encoding='utf-8')
        robot = urchin.URDF.load(str(path), lazy_load_meshes=True)
    poses = robot.link_fk(cfg=values, use_names=True)
    gaps = []
    for side, sign in (('left', 1.0), ('right', -1.0)):
        ball = poses[f'rod_{side}'] @ np.array([0.0, 0.0, -0.23, 1.0])
        foot = poses['foot'] @ np.array([-0.065, sign * 0.035, 0.02, 1.0])
        gaps.append(float(np.linalg.norm(ball[:3] - foot[:3])))
    return gaps


def test_every_answer_closes_the_loops_by_urchins_forward_kinematics():
    planned = closure_robots.plan(closure_robots.ankle())
    text = planned.mechanism.urdf
    worst = 0.0
    # a motion through a grid of motor angles, ±0.5 rad
    path = [(a, b) for a, b in itertools.product(np.linspace(-0.5, 0.5, 11), repeat=2)]
    for left, right in path:
        state = planned.solver.solve([left, right], [0.0, 0.0])
        values = dict(zip(planned.structure.solved, state.positions))
        values |= {'motor_left': left, 'motor_right': right}
        worst = max([worst] + urchin_gaps(text, values))
    assert worst <= 2e-16


@pytest.mark.parametrize(('pitch', 'roll'), [(0.0, 0.0), (0.3, -0.2), (-0.45, 0.25),
                                             (0.2, 0.3)])
def test_pitch_and_roll_to_motors_and_back(pitch, roll):
    forward = closure_robots.plan(closure_robots.ankle())
    legs = [closure_robots.plan(closure_robots.ankle(), ('ankle_pitch', 'ankle_roll'),
                                place=place) for place in (0, 1)]
    steps = 20
    for step in range(1, steps + 1):
        foot = [pitch * step / steps, roll * step / steps]
        motors = [leg.solver.solve(foot, [0.0, 0.0]).positions[0] for leg in legs]
        back = forward.solver.solve(motors, [0.0, 0.0]).positions[:2]
        assert back == pytest.approx(foot, abs=1e-14)
