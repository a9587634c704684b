# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
loops.assembly: the assembled pose nearest a start, from far, and how far the start was open.

Starts open by up to 0.35 m and welded frames turned by a half turn, as exported models are
at their zero pose; the gaps reported against the 50-digit reference's residual; a seed that
picks the other assembly of a five-bar; a weld that no pose of a planar loop can close.
"""

from __future__ import annotations

import math

from closure_reference import Reference
import closure_robots
from linkage_kinematics.loops.assembly import assemble, AssemblyError
from linkage_kinematics.loops.structure import analyse, closure_groups
from linkage_kinematics.loops.tree import KinematicTree
from linkage_kinematics.model.urdf_reader import read_urdf
from mpmath import mp
import pytest


def group_of(mechanism, known=None):
    tree = KinematicTree(read_urdf(mechanism.urdf), mechanism.overrides)
    (group,) = closure_groups(tree, mechanism.closures,
                              mechanism.measured if known is None else known)
    return tree, group


def reference_gaps(mechanism, tree, values) -> list[float]:
    """Return each closure's position gap at ``values`` by the reference (m)."""
    reference = Reference(mechanism.urdf, mechanism.closures, mechanism.reference_overrides)
    with mp.workdps(30):
        rows = reference.residual(dict(zip(tree.names, values)))
    gaps, row = [], 0
    for closure in mechanism.closures:
        gaps.append(float(mp.sqrt(sum(value ** 2 for value in rows[row:row + 3]))))
        row += {'ball': 3, 'pin': 6, 'weld': 12}[closure.kind.value]
    return gaps


def test_the_ankle_comes_back_to_its_drawn_pose_from_far():
    mechanism = closure_robots.ankle()
    tree, group = group_of(mechanism)
    start = [0.0] * len(tree.names)
    for name, value in (('ankle_pitch', 0.6), ('ankle_roll', -0.3), ('rod_left_u1', 1.0),
                        ('rod_right_u2', -0.8)):
        start[tree.index[name]] = value
    assembly = assemble(tree, group, start)
    assert max(abs(value) for value in assembly.values) <= 4e-15
    assert [gap.position for gap in assembly.start_gaps] == pytest.approx(
        reference_gaps(mechanism, tree, start), rel=1e-14)
    assert [gap.angle for gap in assembly.start_gaps] == [None, None]
    assert max(gap.position for gap in assembly.gaps) <= 1e-16
    assert assembly.restart == 0


def test_a_five_bar_drawn_open_by_a_third_of_a_metre_closes():
    mechanism = closure_robots.five_bar()
    drawn = mechanism.urdf.replace('<joint name="j4"', '<joint name="j4_"')
    head, tail = drawn.split('<joint name="j4_"')
    yaw = tail.split('rpy="')[1].split('"')[0].split()
    tail = tail.replace(f'rpy="{" ".join(yaw)}"', f'rpy="0.0 0.0 {float(yaw[2]) + 2.0!r}"', 1)
    opened = closure_robots.Mechanism('open', head + '<joint name="j4"' + tail,
                                      mechanism.closures, mechanism.measured)
    tree, group = group_of(opened)
    start = [0.0] * 4
    assembly = assemble(tree, group, start)
    (gap,) = assembly.start_gaps
    assert gap.position == pytest.approx(reference_gaps(opened, tree, start)[0], rel=1e-14)
    assert gap.position > 0.3
    assert max(abs(r) for r in Reference(opened.urdf, opened.closures).residual(
        dict(zip(tree.names, assembly.values)))) <= 1e-15
    # the cranks held (they are known), the distal joint turned back by its drawn offset
    assert assembly.values[:1] == (0.0,) and assembly.values[2] == 0.0
    assert assembly.values[3] == pytest.approx(-2.0, abs=1e-12)


@pytest.mark.parametrize('turn', [math.pi / 2, 2.0, 2.5, math.pi])
def test_a_weld_turned_by_up_to_a_half_turn_assembles(turn):
    mechanism = closure_robots.planar_weld()
    weld = mechanism.closures[0]
    turned = closure_robots.closure(weld.name, weld.kind, weld.parent,
                                    closure_robots.side('ground', weld.child.xyz, (0, 0, turn)))
    mechanism = closure_robots.Mechanism('turned', mechanism.urdf, (turned,), ('k1',))
    tree, group = group_of(mechanism)
    assembly = assemble(tree, group, [0.0] * 4)
    (start,) = assembly.start_gaps
    assert start.position <= 1e-16 and start.angle == pytest.approx(turn, abs=1e-15)
    (gap,) = assembly.gaps
    assert gap.position <= 1e-15 and gap.angle <= 4e-15
    # The crank is known. One assembly turns only the last pin, by the weld's turn (either way
    # at π); the other flips coupler and rocker, and is nearer the start from 2.5 rad on.
    distance = math.hypot(*assembly.values[1:])
    assert assembly.values[0] == 0.0
    if turn < 2.5:
        assert assembly.values[1:3] == pytest.approx((0.0, 0.0), abs=1e-15)
        assert abs(assembly.values[3]) == pytest.approx(turn, abs=1e-15)
    else:
        assert min(abs(value) for value in assembly.values[1:3]) > 1.0
        assert distance < turn


def test_a_weld_no_pose_of_a_planar_loop_reaches_is_refused_with_its_gaps():
    mechanism = closure_robots.planar_weld()
    weld = mechanism.closures[0]
    tilted = closure_robots.closure(weld.name, weld.kind, weld.parent,
                                    closure_robots.side('ground', weld.child.xyz, (0.3, 0, 0)))
    tree, group = group_of(closure_robots.Mechanism('tilted', mechanism.urdf, (tilted,),
                                                    ('k1',)))
    with pytest.raises(AssemblyError, match=r'group weld_c: no assembled pose found from the '
                       r'start \(open by weld_c 0 m and 0\.3 rad\) in 25 tries'):
        assemble(tree, group, [0.0] * 4)


def mirrored_distal_angles() -> tuple[float, float]:
    """Return (j2, j4) of the five-bar's other assembly at the zero cranks (drawing's math)."""
    t1, t2 = math.radians(100.0), math.radians(80.0)
    b1 = (0.2 * math.cos(t1), 0.2 * math.sin(t1))
    b2 = (0.15 + 0.2 * math.cos(t2), 0.2 * math.sin(t2))
    p = closure_robots._apex(b1, b2, 0.25, 0.25)  # right of b1 → b2: the mirror of the drawing
    drawn = closure_robots._apex(b2, b1, 0.25, 0.25)
    turn = [math.atan2(p[1] - b[1], p[0] - b[0]) - math.atan2(d[1] - b[1], d[0] - b[0])
            for b, d in ((b1, drawn), (b2, drawn))]
    return turn[0], turn[1]


def test_a_seed_picks_the_other_assembly_and_the_solver_keeps_it():
    mechanism = closure_robots.five_bar()
    tree, group = group_of(mechanism)
    j2, j4 = mirrored_distal_angles()
    assembly = assemble(tree, group, [0.0] * 4, seed={'j2': j2 + 0.1, 'j4': j4 - 0.1})
    assert assembly.values[1] == pytest.approx(j2, abs=1e-14)
    assert assembly.values[3] == pytest.approx(j4, abs=1e-14)
    drawn = closure_robots.plan(mechanism)
    other = closure_robots.GroupSolver(tree, group, analyse(tree, group, assembly.values),
                                       assembly, drawn.solver.kind)
    assert other.orientation == -drawn.solver.orientation
    state = other.solve([0.1, -0.1], [0.0, 0.0])
    reference, _ = closure_robots.reference_state(drawn, [0.1, -0.1], [0.0, 0.0],
                                                  state.positions)
    assert state.positions == pytest.approx([float(reference[name]) for name in ('j2', 'j4')],
                                            abs=1e-14)
    with pytest.raises(AssemblyError, match="group tip: seed 'j1' is not a joint it solves"):
        assemble(tree, group, [0.0] * 4, seed={'j1': 0.3})
