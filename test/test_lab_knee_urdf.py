# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
urdf/lab_knee.urdf, docs/following_loops.md's worked example: the knee closed by ``<constraint>``.

The URDF is config/measured_lab.yaml's knee drawn assembled at the zero pose; the loop solver
must give the passive joints the reference gives, with no direction or offset written by hand,
and the document must show what ``linkage-check-loops`` prints for it.
"""

from __future__ import annotations

import contextlib
import io
import math
from pathlib import Path
import xml.etree.ElementTree as ElementTree

from linkage_kinematics.cli import check_loops
from linkage_kinematics.kinematics.geometry import preset, TWO_PI
from linkage_kinematics.kinematics.solver import CrankRates
from linkage_kinematics.loops.plan import find_loops
from linkage_kinematics.loops.solver import LoopSolver
from linkage_kinematics.model.urdf_reader import read_urdf
import pytest
from reference import reference_state

REPOSITORY = Path(__file__).resolve().parent.parent
URDF = REPOSITORY / 'urdf' / 'lab_knee.urdf'
DOCUMENT = REPOSITORY / 'docs' / 'following_loops.md'
# The motor's zero of config/measured_lab.yaml: knee_motor = −α + 0.4.
ALPHA_AT_ZERO = 0.4
COMMAND = 'linkage-check-loops urdf/lab_knee.urdf --measured knee_motor'


def reference_passive(alpha: float) -> tuple[float, float]:
    """Return (γ − α, −β − γ) of the Grashof crank-rocker at ``alpha`` (branch +1, rad)."""
    state = reference_state(preset('grashof_crank_rocker').geometry, alpha, CrankRates(1.0, 0.0))
    gamma, beta = float(state['gamma']), float(state['beta'])
    return gamma - alpha, -beta - gamma


def foot_end(text: str, positions: dict[str, float]) -> tuple[float, float]:
    """Return where the foot's end (0.6 m along its x) lands in the hip frame (planar FK)."""
    joints = {joint.find('parent').get('link'): joint
              for joint in ElementTree.fromstring(text).iter('joint')}
    link, x, y, heading = 'hip', 0.0, 0.0, 0.0
    while link in joints:
        joint = joints[link]
        ox, oy, _ = map(float, joint.find('origin').get('xyz').split())
        yaw = float(joint.find('origin').get('rpy').split()[2])
        axis = float(joint.find('axis').get('xyz').split()[2])
        x += ox * math.cos(heading) - oy * math.sin(heading)
        y += ox * math.sin(heading) + oy * math.cos(heading)
        heading += yaw + axis * positions[joint.get('name')]
        link = joint.find('child').get('link')
    return x + 0.6 * math.cos(heading), y + 0.6 * math.sin(heading)


def test_the_loop_solver_completes_the_knee_as_the_reference_does() -> None:
    text = URDF.read_text(encoding='utf-8')
    solver = LoopSolver(find_loops(read_urdf(text)).plan(['knee_motor']))
    link_zero, output_zero = reference_passive(ALPHA_AT_ZERO)
    # a whole turn of the motor in small steps, as an encoder reports it (wrapped at ±π)
    for index in range(-180, 181):
        motor = math.remainder(index * TWO_PI / 360.0, TWO_PI)
        alpha = ALPHA_AT_ZERO - motor
        positions, _ = solver.solve({'knee_motor': motor}, {'knee_motor': 1.0})
        link, output = reference_passive(alpha)
        assert math.remainder(positions['knee_link'] - (link - link_zero), TWO_PI) == (
            pytest.approx(0.0, abs=1e-12))
        assert math.remainder(positions['knee_output'] - (output - output_zero), TWO_PI) == (
            pytest.approx(0.0, abs=1e-12))
        end = foot_end(text, {'knee_motor': motor, **positions})
        assert math.dist(end, (1.0, 0.0)) < 1e-12


def test_the_documented_sample_and_printout_are_what_the_package_gives() -> None:
    document = DOCUMENT.read_text(encoding='utf-8')
    solver = LoopSolver(
        find_loops(read_urdf(URDF.read_text(encoding='utf-8'))).plan(['knee_motor']))
    positions, _ = solver.solve({'knee_motor': -0.1}, {'knee_motor': 1.0})
    assert f"`knee_link` = {positions['knee_link']:.4f} rad".replace('-', '−') in document
    assert f"{positions['knee_output']:.4f} rad".replace('-', '−') in document
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert check_loops.main([str(URDF), '--measured', 'knee_motor']) == 0
    shown = document.split(f'$ ./dev run {COMMAND}\n', 1)[1].split('```', 1)[0]
    assert shown == printed.getvalue()
