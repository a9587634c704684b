# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A URDF's <constraint> loops read, checked, ordered and solved (loops: description to solver).

The test robots (test/loop_robots.py) are drawn with derived, non-aligned frames; their
solutions are checked against test/loop_reference.py (mpmath Newton on all constraints at once,
closure by urchin), which shares nothing with the package. Each refusal has its own small URDF.
"""

from __future__ import annotations

import math

from linkage_kinematics.kinematics.continuation import continued_branch
from linkage_kinematics.kinematics.geometry import FourBar
from linkage_kinematics.kinematics.planar_loop import JointKind, known_joint_range
from linkage_kinematics.kinematics.solver import CrankRates, solve
from linkage_kinematics.loops.description import LoopError
from linkage_kinematics.loops.plan import find_loops
from linkage_kinematics.loops.solver import LoopSampleError, LoopSolver
from linkage_kinematics.loops.structure import GroupKind
from linkage_kinematics.model.urdf import urdf_text
from linkage_kinematics.model.urdf_reader import read_urdf, UrdfError
import loop_reference
from loop_robots import DEPTH_1, ROBOTS
import numpy as np
import pytest
from urdf_parser_py import urdf as urdf_parser
from urdf_parser_py.xml_reflection import core as xml_reflection_core

SAMPLES = 9
TOLERANCE = 1e-12


# --- a small four-bar written here: O (0, 0), A (0, 1), B (2, 1.5), C (2, 0) -----------------

def four_bar(crank_axis: str = '0 0 1', coupler_axis: str = '0 0 1', rocker_axis: str = '0 0 1',
             rocker_type: str = 'revolute', crank_type: str = 'revolute',
             coupler_type: str = 'revolute', constraint_type: str = 'revolute',
             child_link: str = 'rocker', parent_axis: str = '0 0 1', child_axis: str = '0 0 1',
             rocker_xyz: str = '2 0 0', extra: str = '') -> str:
    """Return a crank-rocker four-bar's URDF, with any one part changed to break it."""
    return f"""<?xml version="1.0" encoding="utf-8"?>
<robot name="test_four_bar">
  <link name="base"/><link name="crank"/><link name="coupler"/><link name="rocker"/>
  <joint name="crank_joint" type="{crank_type}">
    <parent link="base"/><child link="crank"/><axis xyz="{crank_axis}"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="coupler_joint" type="{coupler_type}">
    <parent link="crank"/><child link="coupler"/><origin xyz="0 1 0"/><axis xyz="{coupler_axis}"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="rocker_joint" type="{rocker_type}">
    <parent link="base"/><child link="rocker"/><origin xyz="{rocker_xyz}"/>
    <axis xyz="{rocker_axis}"/><limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <constraint name="pin" type="{constraint_type}">
    <parent link="coupler"/><parent_origin xyz="2 0.5 0"/><parent_axis xyz="{parent_axis}"/>
    <child link="{child_link}"/><child_origin xyz="0 1.5 0"/><child_axis xyz="{child_axis}"/>
  </constraint>{extra}
</robot>
"""


def refusal(urdf: str) -> str:
    """Return the one problem ``find_loops`` finds in ``urdf``."""
    loops = find_loops(read_urdf(urdf))
    assert not loops.loops
    assert len(loops.problems) == 1
    return loops.problems[0]


# --- reading -------------------------------------------------------------------------------------

def test_good_urdfs_are_read_without_a_word_on_stderr(capfd: pytest.CaptureFixture[str]) -> None:
    """urdf_parser_py's complaint about <constraint> is dropped; its other notes are kept."""
    for robot in ROBOTS.values():
        assert find_loops(read_urdf(robot.urdf())).parser_messages == ()
    noted = find_loops(read_urdf(four_bar(extra='\n  <lab_extension/>')))
    assert capfd.readouterr().err == ''
    assert len(noted.parser_messages) == 1
    assert noted.parser_messages[0].startswith('Unknown tag "lab_extension" in /robot')
    # only a <constraint> directly under <robot> is expected: one inside a <joint> is noted
    misplaced = four_bar().replace('<origin xyz="0 1 0"/>', '<origin xyz="0 1 0"/><constraint/>')
    assert find_loops(read_urdf(misplaced)).parser_messages == (
        'Unknown tag "constraint" in '
        "/robot[@name='test_four_bar']/joint[@name='coupler_joint']",)


def test_the_parser_alone_would_complain_and_its_hook_is_restored(
        capfd: pytest.CaptureFixture[str]) -> None:
    """The premise of the silencing: urdf_parser_py on its own writes to stderr."""
    before = xml_reflection_core.on_error
    urdf_parser.URDF.from_xml_string(four_bar().encode())
    assert capfd.readouterr().err.startswith('Unknown tag "constraint" in /robot')
    find_loops(read_urdf(four_bar()))
    assert xml_reflection_core.on_error is before
    assert capfd.readouterr().err == ''


def test_loops_found_in_each_test_robot() -> None:
    for name, robot in ROBOTS.items():
        loops = find_loops(read_urdf(robot.urdf()))
        assert loops.problems == (), name
        assert {loop.constraint: frozenset(loop.names) for loop in loops.loops} == robot.loops
        for loop in loops.loops:
            # the drawings close at zero up to float64 rounding of their written numbers
            assert loop.closure_residual < 1e-15, (name, loop.constraint)
            assert loop.planar.closure_gap < 1e-15, (name, loop.constraint)
            assert loop.names == loop_reference.loop_joints(robot.urdf(), loop.constraint)


def test_joint_kinds_and_signs_follow_the_axes_and_the_path() -> None:
    """Sign = axis sense along the normal, × −1 where the path runs from child to parent."""
    expected = {
        # normal +z (the pin's parent_axis): rear_link → thigh (child to parent, axis +z),
        # → front_link (+z), → shank (axis −z)
        'knee_rear_pin': {'knee_rear': -1, 'knee_front': 1, 'knee_shank': -1},
        # normal −z: coupler → crank (child to parent, axis −z), → base (child to parent, +z),
        # → slider (parent to child)
        'slider_pin': {'coupler_joint': -1, 'crank_joint': 1, 'slider_joint': 1},
        # normal −x: arm → base (child to parent, axis −x), → barrel (+x), → rod
        'balancer_pin': {'arm_joint': -1, 'balancer_pivot': -1, 'balancer_rod_joint': 1},
        # normal −z: coupler → crank (child to parent, axis −z), → base (child to parent, +z),
        # → follower (axis −z)
        'follower_pin': {'coupler_joint': -1, 'crank_joint': 1, 'follower_joint': 1},
    }
    for name in ('four_bar_knee', 'slider_crank', 'balancer', 'parallelogram'):
        for loop in find_loops(read_urdf(ROBOTS[name].urdf())).loops:
            assert {joint.name: joint.sign for joint in loop.joints} == expected[loop.constraint]
            assert loop.planar.kinds[0] is JointKind.REVOLUTE
            for joint in loop.joints:
                assert loop.planar.kinds[joint.index] is (
                    JointKind.PRISMATIC if joint.name.endswith(('slider_joint', 'rod_joint'))
                    else JointKind.REVOLUTE)


def _lengths(constraint_points: list[tuple[float, float]]) -> list[float]:
    return [math.dist(constraint_points[k], constraint_points[(k + 1) % 4]) for k in range(4)]


def test_dimensions_match_the_construction() -> None:
    """The knee's and the parallelogram's links, the slider's line: loop_robots' numbers."""
    knee = find_loops(read_urdf(ROBOTS['four_bar_knee'].urdf())).loops[0]
    # pin (shank's rear pivot) → knee_rear → knee_front → knee_shank, depth dropped
    expected = _lengths([(-0.022, -0.060), (-0.018, -0.008), (0.020, 0.000), (0.028, -0.055)])
    assert [math.hypot(*link) for link in knee.planar.links] == pytest.approx(expected, abs=1e-15)
    assert np.allclose(knee.normal, (0.0, 0.0, 1.0), rtol=0.0, atol=1e-15)
    parallelogram = find_loops(read_urdf(ROBOTS['parallelogram'].urdf())).loops[0]
    assert [math.hypot(*link) for link in parallelogram.planar.links] == pytest.approx(
        [math.hypot(0.12, 0.01), 0.08, math.hypot(0.12, 0.01), 0.08], abs=1e-15)
    slider = find_loops(read_urdf(ROBOTS['slider_crank'].urdf())).loops[0]
    assert np.allclose(slider.slide_world, (math.cos(-0.15), math.sin(-0.15), 0.0), atol=1e-15)
    # pin → coupler_joint → crank_joint: links[1] is the crank
    assert math.hypot(*slider.planar.links[1]) == pytest.approx(0.05, abs=1e-15)
    excavator = find_loops(read_urdf(ROBOTS['excavator'].urdf()))
    for loop in excavator.loops:
        assert abs(abs(loop.normal[1]) - 1.0) < 1e-15, loop.constraint


def test_depth_offsets_are_dropped() -> None:
    """The knee's links sit at depths DEPTH_1 apart; the loop is the same without them."""
    flat = find_loops(read_urdf(ROBOTS['four_bar_knee'].urdf().replace(repr(DEPTH_1), '0.0')))
    deep = find_loops(read_urdf(ROBOTS['four_bar_knee'].urdf())).loops[0]
    assert np.allclose(flat.loops[0].planar.links, deep.planar.links, rtol=0.0, atol=1e-15)


# --- refusals ------------------------------------------------------------------------------------

@pytest.mark.parametrize('kind', ['universal', 'prismatic'])
def test_constraint_types_other_than_revolute_spherical_and_fixed_are_refused(kind: str) -> None:
    assert refusal(four_bar(constraint_type=kind)) == (
        f"constraint 'pin': type '{kind}' is not supported: a constraint is 'revolute' (a pin), "
        "'spherical' (a ball) or 'fixed' (a weld)")


def test_a_ball_closes_the_four_bar_as_its_pin_does_and_a_weld_makes_it_rigid() -> None:
    """A ball in place of the pin: the general closure, the same joints as the planar loop's."""
    ball = find_loops(read_urdf(four_bar(constraint_type='spherical')))
    assert ball.problems == () and ball.loops == ()
    (group,) = ball.plan(('crank_joint',)).groups
    assert (group.kind, group.known, group.solved) == (
        GroupKind.NEWTON, ('crank_joint',), ('coupler_joint', 'rocker_joint'))
    assert (group.zero.structure.dof, group.zero.structure.idle) == (1, ())
    balls = LoopSolver(ball.plan(('crank_joint',)))
    pins = LoopSolver(find_loops(read_urdf(four_bar())).plan(('crank_joint',)))
    for crank in np.linspace(-0.5, 0.5, 11):
        positions, velocities = balls.solve({'crank_joint': crank}, {'crank_joint': 0.7})
        expected, expected_rates = pins.solve({'crank_joint': crank}, {'crank_joint': 0.7})
        assert positions == pytest.approx(expected, abs=TOLERANCE)
        assert velocities == pytest.approx(expected_rates, abs=TOLERANCE)
    weld = find_loops(read_urdf(four_bar(constraint_type='fixed')))
    with pytest.raises(LoopError) as rigid:
        weld.plan(('crank_joint',))
    assert str(rigid.value) == (
        "group pin (joints ['crank_joint', 'coupler_joint', 'rocker_joint']): 0 degrees of "
        "freedom (0 idle), known ['crank_joint']: over-determined, 1 known joints for 0 "
        'determining freedoms')


def test_unknown_links_are_refused() -> None:
    assert refusal(four_bar(child_link='rocket')) == (
        "constraint 'pin': child link 'rocket' is not a <link> of the robot")


def test_pins_of_other_than_three_moving_joints_are_the_general_closures() -> None:
    """Not a planar loop's: a pin of two moving joints is rigid, one of four may be idle."""
    # a fixed joint on the path is rigid: two moving joints are left, and no motion
    rigid = find_loops(read_urdf(four_bar(rocker_type='fixed')))
    assert rigid.problems == () and rigid.loops == ()
    with pytest.raises(LoopError, match=r"^group pin \(joints \['crank_joint', 'coupler_joint'\]"
                                        r'\): 0 degrees of freedom \(0 idle\), known '
                                        r"\['crank_joint'\]: over-determined"):
        rigid.plan(('crank_joint',))
    # a pin on the rocker's own axis: the tip turns with it, idle, held where it was assembled
    five_bar = four_bar(child_link='tip', extra="""
  <link name="tip"/>
  <joint name="tip_joint" type="revolute"><parent link="rocker"/><child link="tip"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>""")
    (group,) = find_loops(read_urdf(five_bar)).plan(('crank_joint',)).groups
    assert group.zero.structure.dof == 2
    assert [idle.joints for idle in group.zero.structure.idle] == [('rocker_joint', 'tip_joint')]


def test_fixed_joints_on_the_path_are_rigid() -> None:
    """A fixed joint splits the rocker in two: still a four-bar with the same links."""
    # B = (0, 1.5, 0) in the rocker's frame, seen from the weld's frame (0, 0.5, 0.25), yaw 0.3
    pin = f'{math.sin(0.3)!r} {math.cos(0.3)!r} -0.25'
    split = four_bar(child_link='rocker_end', extra="""
  <link name="rocker_end"/>
  <joint name="rocker_weld" type="fixed"><parent link="rocker"/><child link="rocker_end"/>
    <origin xyz="0 0.5 0.25" rpy="0 0 0.3"/></joint>""").replace(
        '<child link="rocker_end"/><child_origin xyz="0 1.5 0"/>',
        f'<child link="rocker_end"/><child_origin xyz="{pin}" rpy="0 0 -0.3"/>')
    loops = find_loops(read_urdf(split))
    assert loops.problems == ()
    assert loops.loops[0].names == ('coupler_joint', 'crank_joint', 'rocker_joint')
    assert loops.loops[0].closure_residual < 1e-15
    # B − A, O − A, C − O, B − C
    assert [math.hypot(*link) for link in loops.loops[0].planar.links] == pytest.approx(
        [math.hypot(2.0, 0.5), 1.0, 2.0, 1.5], abs=1e-15)


def test_floating_joints_on_the_path_are_refused() -> None:
    floating = four_bar(rocker_type='floating')
    assert "floating or planar joints ['rocker_joint']" in refusal(floating)


def test_non_parallel_axes_are_refused() -> None:
    tilt = f'0 {math.sin(1e-7)!r} {math.cos(1e-7)!r}'
    assert "joint 'rocker_joint' is not parallel to the loop normal" in refusal(
        four_bar(rocker_axis=tilt))
    assert 'its child_axis is not parallel' in refusal(four_bar(child_axis='1 0 0'))
    # opposite senses are parallel, and a tilt far below 1e-9 rad is rounding
    for axes in ({'rocker_axis': '0 0 -1', 'child_axis': '0 0 -1'},
                 {'rocker_axis': f'0 {math.sin(1e-12)!r} 1'}):
        assert find_loops(read_urdf(four_bar(**axes))).problems == ()


def test_a_prismatic_joint_must_slide_in_the_plane_and_two_are_the_general_closures() -> None:
    assert "joint 'rocker_joint' slides out of the plane" in refusal(
        four_bar(rocker_type='prismatic', rocker_axis='0.6 0 0.8'))
    # a slide along x, a pin, a slide along y: the planar closed forms take one slide only (the
    # crank's slide reaches -0.06 m, where the coupler lies along x)
    urdf = four_bar(rocker_type='prismatic', crank_type='prismatic', rocker_axis='0 1 0',
                    crank_axis='1 0 0')
    loops = find_loops(read_urdf(urdf))
    assert loops.problems == () and loops.loops == ()
    plan = loops.plan(('crank_joint',))
    assert [group.kind for group in plan.groups] == [GroupKind.NEWTON]
    solver = LoopSolver(plan)
    for crank in np.linspace(0.0, 0.3, 7):
        positions, _ = solver.solve({'crank_joint': crank}, {'crank_joint': 0.0})
        gaps = loop_reference.closure_residuals(urdf, {'crank_joint': crank, **positions})
        assert gaps['pin'] < TOLERANCE


def test_urdfs_that_are_no_tree_are_refused_before_their_loops_are_read() -> None:
    with pytest.raises(UrdfError, match='the URDF is not XML'):
        read_urdf('<robot name="x"><link name="a"></robot>')
    with pytest.raises(UrdfError, match=r"the URDF has 2 root links \['base', 'spare'\]"):
        read_urdf(four_bar(extra='\n  <link name="spare"/>'))


# --- ordering ------------------------------------------------------------------------------------

def test_the_excavator_loops_are_ordered_from_the_cylinders() -> None:
    robot = ROBOTS['excavator']
    loops = find_loops(read_urdf(robot.urdf()))
    plan = loops.plan(robot.measured_joints)
    order = [planned.loop.constraint for planned in plan.loops]
    assert order.index('bucket_cylinder_pin') < order.index('bucket_pin')
    assert set(order) == set(robot.loops)
    known = {planned.loop.constraint: (planned.known.name, planned.measured)
             for planned in plan.loops}
    assert known == {'boom_cylinder_pin': ('boom_cylinder', True),
                     'stick_cylinder_pin': ('stick_cylinder', True),
                     'bucket_cylinder_pin': ('bucket_cylinder', True),
                     'bucket_pin': ('bucket_link_joint', False)}
    assert set(plan.passive) == set(robot.passive_joints)


def test_the_bucket_measured_at_its_pivot_reverses_the_order() -> None:
    """Measuring bucket_joint instead of its cylinder: the four-bar first, then the cylinder."""
    robot = ROBOTS['excavator']
    loops = find_loops(read_urdf(robot.urdf()))
    forward = LoopSolver(loops.plan(robot.measured_joints))
    reverse_measured = ('boom_cylinder', 'stick_cylinder', 'bucket_joint')
    plan = loops.plan(reverse_measured)
    order = [planned.loop.constraint for planned in plan.loops]
    assert order.index('bucket_pin') < order.index('bucket_cylinder_pin')
    reverse = LoopSolver(plan)
    rates = {'boom_cylinder': 0.1, 'stick_cylinder': -0.2, 'bucket_cylinder': 0.3}
    for measured in _sweep('excavator'):
        positions, velocities = forward.solve(measured, rates)
        given = {name: {**measured, **positions}[name] for name in reverse_measured}
        given_rates = {name: {**rates, **velocities}[name] for name in reverse_measured}
        back, back_rates = reverse.solve(given, given_rates)
        assert back['bucket_cylinder'] == pytest.approx(measured['bucket_cylinder'], abs=1e-12)
        assert back_rates['bucket_cylinder'] == pytest.approx(0.3, abs=1e-12)


def test_loops_without_or_with_too_many_known_joints_are_refused() -> None:
    loops = find_loops(read_urdf(ROBOTS['excavator'].urdf()))
    with pytest.raises(LoopError) as missing:
        loops.plan(('boom_cylinder', 'stick_cylinder'))
    assert str(missing.value).split('\n') == [
        "constraint 'bucket_cylinder_pin': none of its joints ['bucket_link_joint', "
        "'bucket_cylinder_pivot', 'bucket_cylinder'] is measured or solved by another loop",
        "constraint 'bucket_pin': none of its joints ['bucket_joint', 'bucket_link_joint', "
        "'guide_link_joint'] is measured or solved by another loop"]
    with pytest.raises(LoopError, match=r"constraint 'bucket_pin': 2 of its joints "
                                        r"\['bucket_joint', 'bucket_link_joint'\] are known"):
        loops.plan(('boom_cylinder', 'stick_cylinder', 'bucket_cylinder', 'bucket_joint'))
    with pytest.raises(LoopError, match="measured joint 'boom' is not a joint of the robot"):
        loops.plan(('boom', 'stick_cylinder', 'bucket_cylinder'))


def test_branch_overrides_are_checked() -> None:
    loops = find_loops(read_urdf(four_bar()))
    with pytest.raises(LoopError, match="branch given for 'pins'"):
        loops.plan(('crank_joint',), {'pins': 1})
    with pytest.raises(LoopError, match="constraint 'pin': branch 0 is not -1 or 1"):
        loops.plan(('crank_joint',), {'pin': 0})


def test_a_passive_loop_joint_with_a_mimic_is_warned_about() -> None:
    urdf = ROBOTS['parallelogram'].urdf().replace(
        '<axis xyz="0.0 0.0 -1.0"/>',
        '<axis xyz="0.0 0.0 -1.0"/><mimic joint="crank_joint" multiplier="-1.0"/>', 1)
    plan = find_loops(read_urdf(urdf)).plan(('crank_joint',))
    assert plan.warnings == (
        "joint 'coupler_joint' (constraint 'follower_pin') is solved by its loop but also mimics "
        "'crank_joint': robot_state_publisher would pose it from two sources",)
    parallelogram = find_loops(read_urdf(ROBOTS['parallelogram'].urdf()))
    assert parallelogram.plan(('crank_joint',)).warnings == ()


# --- solving -------------------------------------------------------------------------------------

def _sweep(robot_name: str) -> list[dict[str, float]]:
    """Return the measured joints along a sweep out and back over their ranges."""
    ranges = ROBOTS[robot_name].measured_ranges
    fractions = list(np.linspace(0.0, 1.0, SAMPLES)) + list(np.linspace(1.0, 0.0, SAMPLES))[1:]
    return [{name: low + (high - low) * fraction for name, (low, high) in ranges.items()}
            for fraction in fractions]


@pytest.mark.parametrize('robot_name', sorted(ROBOTS))
def test_solving_along_a_sweep_matches_the_reference(robot_name: str) -> None:
    robot = ROBOTS[robot_name]
    urdf = robot.urdf()
    solver = LoopSolver(find_loops(read_urdf(urdf)).plan(robot.measured_joints))
    rates = {name: 0.3 + 0.2 * index for index, name in enumerate(robot.measured_joints)}
    guess: dict[str, float] = {}
    for measured in _sweep(robot_name):
        positions, velocities = solver.solve(measured, rates)
        assert set(positions) == set(velocities) == set(robot.passive_joints)
        exact = loop_reference.solve(urdf, measured, guess)
        exact_rates = loop_reference.velocities(urdf, {**measured, **exact}, rates)
        for name in robot.passive_joints:
            assert abs(positions[name] - float(exact[name])) < TOLERANCE, (name, measured)
            assert abs(velocities[name] - float(exact_rates[name])) < TOLERANCE, (name, measured)
        gaps = loop_reference.closure_residuals(urdf, {**measured, **positions})
        assert max(gaps.values()) < TOLERANCE, gaps
        guess = exact


def test_a_refused_sample_leaves_the_solver_as_it_was() -> None:
    """The rocker reaches −31.4°…58.6° on this assembly: 86° is out of reach."""
    solver = LoopSolver(find_loops(read_urdf(four_bar())).plan(('rocker_joint',)))
    before = solver.solve({'rocker_joint': 0.2}, {'rocker_joint': 1.0})
    with pytest.raises(LoopSampleError, match=r"constraint 'pin' at rocker_joint = 1\.5: .*not "
                                              'reachable'):
        solver.solve({'rocker_joint': 1.5}, {'rocker_joint': 1.0})
    # the end of the rocker's reach: coupler and rocker in line (58.6°, sign +1)
    loop = solver.plan.loops[0].loop
    dead = max(value for value in known_joint_range(loop.planar, 3).dead_points if value < 1.5)
    with pytest.raises(LoopSampleError, match="constraint 'pin' at rocker_joint = 1.02333929: "
                                              '.*dead point'):
        solver.solve({'rocker_joint': dead}, {'rocker_joint': 1.0})
    with pytest.raises(LoopSampleError, match='no position and velocity for measured joint'):
        solver.solve({'rocker_joint': 0.2}, {})
    with pytest.raises(LoopSampleError, match='are not both finite'):
        solver.solve({'rocker_joint': math.nan}, {'rocker_joint': 0.0})
    assert solver.solve({'rocker_joint': 0.2}, {'rocker_joint': 1.0}) == before


def test_continuous_joints_stay_continuous_and_the_branch_holds_through_change_points() -> None:
    """A parallelogram O, A (0, 1), B (2, 1), C (2, 0) turning twice: coupler = −crank."""
    urdf = four_bar(crank_type='continuous', coupler_type='continuous',
                    rocker_type='continuous').replace(
        '<parent_origin xyz="2 0.5 0"/>', '<parent_origin xyz="2 0 0"/>').replace(
        '<child_origin xyz="0 1.5 0"/>', '<child_origin xyz="0 1 0"/>')
    solver = LoopSolver(find_loops(read_urdf(urdf)).plan(('crank_joint',)))
    # steps of 3°, landing exactly on the change points at 90° and 270° (all four pins in line)
    for step in range(1, 241):
        crank = math.radians(3.0 * step)
        positions, velocities = solver.solve({'crank_joint': crank}, {'crank_joint': 2.0})
        assert positions['coupler_joint'] == pytest.approx(-crank, abs=1e-12)
        assert positions['rocker_joint'] == pytest.approx(crank, abs=1e-12)
        assert velocities['coupler_joint'] == pytest.approx(-2.0, abs=1e-9)


def test_a_wrapping_encoder_keeps_the_branch_where_a_turn_has_one_change_point() -> None:
    """
    A kite (OA = OC, AB = BC) turned twice by its crank, read wrapped at ±π.

    A turn of its crank passes one change point, so its smooth motion repeats every two turns:
    the solver goes the short way between samples and stays on the branch the four-bar's closed
    form continues to over whole turns.
    """
    kite = FourBar(0.3, 1.0, 1.0, 0.3, 0.0)
    start = -1.5
    # the zero pose's branch from which the solver reaches +1 at the first sample
    zero_branch = int(continued_branch(kite, start, 1, 0.0))
    solver = LoopSolver(find_loops(read_urdf(urdf_text(kite))).plan(
        ('crank_joint',), {'pivot_c': zero_branch}))
    for step in range(240):
        alpha = start + math.radians(3.0 * step)
        wrapped = math.remainder(alpha, 2.0 * math.pi)
        turns = round((alpha - wrapped) / (2.0 * math.pi))
        positions, velocities = solver.solve({'crank_joint': wrapped}, {'crank_joint': 1.0})
        branch = int(continued_branch(kite, start, 1, wrapped, turns=turns))
        state = solve(kite, wrapped, CrankRates(1.0, 0.0), branch)
        coupler = math.remainder(positions['coupler_joint'] - (state.gamma - state.alpha),
                                 2.0 * math.pi)
        assert coupler == pytest.approx(0.0, abs=TOLERANCE)
        assert velocities['coupler_joint'] == pytest.approx(state.omega_ab - state.omega,
                                                            abs=TOLERANCE)


def test_the_branch_override_picks_the_other_assembly() -> None:
    urdf = four_bar()
    loops = find_loops(read_urdf(urdf))
    default = LoopSolver(loops.plan(('crank_joint',))).solve({'crank_joint': 0.0},
                                                             {'crank_joint': 0.0})[0]
    assert default == pytest.approx({'coupler_joint': 0.0, 'rocker_joint': 0.0}, abs=1e-12)
    branch = loops.plan(('crank_joint',)).loops[0].branch
    other = LoopSolver(loops.plan(('crank_joint',), {'pin': -branch})).solve(
        {'crank_joint': 0.0}, {'crank_joint': 0.0})[0]
    assert abs(other['rocker_joint']) > 0.1
    gaps = loop_reference.closure_residuals(urdf, {'crank_joint': 0.0, **other})
    assert gaps['pin'] < TOLERANCE
