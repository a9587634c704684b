# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The node's own URDF as a ``<constraint>`` loop, read by ``loops.plan`` as a lab's would be.

For each preset, each driver and each joint mapping: one four-bar loop without a problem, whose
dimensions are the four-bar's; its constraint frames parallel at the zero pose and coinciding
(urchin's forward kinematics, independent of the package) wherever the tree is assembled; and
the element is the only thing robot_state_publisher's reading of the text does not see.
"""

from __future__ import annotations

from dataclasses import replace
import math
import re

from linkage_kinematics.kinematics.geometry import FourBar, preset, PRESETS, TWO_PI
from linkage_kinematics.kinematics.solver import CrankRates, DeadPointError, solve
from linkage_kinematics.loops.intake import DropReason
from linkage_kinematics.loops.plan import find_loops
from linkage_kinematics.model.joints import (
    Driver,
    JointMap,
    JointMapping,
    JointStream,
    Link,
    TREE_ORDER,
    tree_values,
)
from linkage_kinematics.model.robot_transforms import RobotTransforms
from linkage_kinematics.model.urdf import node_description, urdf_text
from linkage_kinematics.model.urdf_reader import read_urdf
from linkage_kinematics.run.configuration import build_configuration, RunConfiguration
from linkage_kinematics.run.measured import FollowedSample, MeasuredFollower
from linkage_kinematics.run.parameter_specs import parameter_specs
import loop_reference
import numpy as np
import pytest
import urchin
from urdf_parser_py import urdf as urdf_parser

# The kite (a change-point linkage) is solved from its URDF, whose link vectors are rounded
# components at the zero pose: within a few degrees of its change point the rates amplify that
# rounding, and the two paths' velocities differ by up to 1.0e-12 there (1° from it; each is
# within 7e-13 of the 50-digit reference of the parameters' kite).
KITE_VELOCITY_TOLERANCE = 4e-12
TOLERANCE = 1e-12
# config/measured_lab.yaml's knee, and the same with its rocker joint reversed
LAB = JointMap(JointMapping('knee_motor', -1, 0.4), JointMapping('knee_link', 1, -0.2),
               JointMapping('knee_output', 1, 1.1))
LAB_REVERSED = JointMap(LAB.crank, LAB.coupler, JointMapping('knee_output', -1, 1.1))
MAPPINGS = {'default': JointMap(), 'lab': LAB, 'lab_reversed': LAB_REVERSED}
CASES = [(name, driver, mapping) for name in PRESETS for driver in Driver
         for mapping in MAPPINGS]


def angle_gap(value: float, expected: float) -> float:
    return abs(math.remainder(value - expected, TWO_PI))


def _node_urdf(name: str, driver: Driver, mapping: str) -> str:
    return urdf_text(preset(name).geometry, 'linkage_base', MAPPINGS[mapping], driver)


def _lengths_in_loop_order(linkage: FourBar, driver: Driver) -> tuple[float, ...]:
    """Return the four-bar's lengths from the cut pivot round the tree: pivot → … → pivot."""
    ground = math.hypot(linkage.ground_x, linkage.ground_y)
    if driver is Driver.CRANK:  # C → O → A → B → C
        return (ground, linkage.crank_length, linkage.coupler_length, linkage.rocker_length)
    return (ground, linkage.rocker_length, linkage.coupler_length, linkage.crank_length)


@pytest.mark.parametrize(('name', 'driver', 'mapping'), CASES)
def test_the_nodes_urdf_has_one_four_bar_loop_of_the_linkages_dimensions(
        name: str, driver: Driver, mapping: str) -> None:
    urdf = _node_urdf(name, driver, mapping)
    loops = find_loops(read_urdf(urdf))
    assert (loops.problems, loops.parser_messages) == ((), ())
    (loop,) = loops.loops
    assert loop.constraint == ('pivot_c' if driver is Driver.CRANK else 'pivot_o')
    joints = MAPPINGS[mapping]
    order = TREE_ORDER[driver]
    assert loop.names == tuple(joints[link].name for link in order)
    # the loop turns about +z, each joint about direction·z
    assert [joint.sign for joint in loop.joints] == [joints[link].direction for link in order]
    assert [math.hypot(*link) for link in loop.planar.links] == pytest.approx(
        _lengths_in_loop_order(preset(name).geometry, driver), abs=TOLERANCE)
    plan = loops.plan([loop.names[0]])
    assert plan.passive == loop.names[1:]


@pytest.mark.parametrize(('name', 'driver', 'mapping'), CASES)
def test_the_constraint_frames_are_parallel_at_zero_and_meet_where_the_tree_is_assembled(
        name: str, driver: Driver, mapping: str) -> None:
    urdf = _node_urdf(name, driver, mapping)
    robot = loop_reference.parse(urdf)
    (constraint,) = robot.constraints.values()

    def frames(values: dict[str, float]) -> list[np.ndarray]:
        poses = loop_reference.link_poses(urdf, values)
        return [poses[link] @ urchin.utils.xyz_rpy_to_matrix(np.array(frame.xyz + frame.rpy))
                for link, frame in ((constraint.parent, constraint.parent_origin),
                                    (constraint.child, constraint.child_origin))]

    parent, child = frames({})
    assert child[:3, :3] == pytest.approx(parent[:3, :3], abs=TOLERANCE)
    linkage = preset(name).geometry
    joints = MAPPINGS[mapping]
    order = TREE_ORDER[driver]
    low, high = linkage.reachability.intervals[0]
    for alpha in np.linspace(low, min(high, low + 2.0 * math.pi), 7)[1:-1]:
        for branch in (-1, 1):
            state = solve(linkage, float(alpha), CrankRates(1.0, 0.0), branch)
            node_values, _ = tree_values(state, driver)
            values = {joints[link].name: joints[link].to_lab(value)
                      for link, value in zip(order, node_values)}
            assert loop_reference.closure_residuals(urdf, values)[constraint.name] < TOLERANCE


@pytest.mark.parametrize('driver', list(Driver))
def test_robot_state_publishers_reading_is_that_of_the_text_without_the_constraint(
        driver: Driver) -> None:
    urdf = urdf_text(preset('paper').geometry, 'linkage_base', LAB, driver)
    (element,) = re.findall(r'  <constraint .*?</constraint>\n', urdf, flags=re.DOTALL)
    without = urdf.replace(element, '')
    assert without.endswith('  </joint>\n</robot>\n')
    values = {name: 0.3 for name in LAB.names(TREE_ORDER[driver])}
    with_constraint = RobotTransforms(read_urdf(urdf))
    plain = RobotTransforms(read_urdf(without))
    assert with_constraint.fixed_transforms() == plain.fixed_transforms()
    names = list(values)
    moving, plain_moving = with_constraint.moving(names), plain.moving(names)
    assert moving.frames == plain_moving.frames
    assert moving.values(values.values()) == plain_moving.values(values.values())


# --- the measured follower's passive joints: the general loop path against the four-bar's ------

PARALLELOGRAM = {'preset': '', 'crank_length': 0.3, 'coupler_length': 1.0,
                 'rocker_length': 0.3, 'ground_x': 1.0, 'ground_y': 0.0}
# a kite: one change point per turn of its crank, so its smooth motion repeats every two turns
KITE = {'preset': '', 'crank_length': 0.3, 'coupler_length': 1.0, 'rocker_length': 1.0,
        'ground_x': 0.3, 'ground_y': 0.0}
GEOMETRIES = {**{name: {'preset': name} for name in PRESETS}, 'parallelogram': PARALLELOGRAM,
              'kite': KITE}


def _config(geometry: str, driver: Driver, mapping: str, branch: int) -> RunConfiguration:
    values = GEOMETRIES[geometry]
    defaults = {spec.name: spec.default for spec in parameter_specs(values['preset'])}
    joints = {}
    for link in TREE_ORDER[driver]:
        joint = MAPPINGS[mapping][link]
        joints.update({f'joints.{link}.name': joint.name, f'joints.{link}.direction':
                       joint.direction, f'joints.{link}.offset': joint.offset})
    return build_configuration({**defaults, **values, **joints, 'source': 'measured',
                                'driver': driver.value, 'branch': branch})


def _sweep(config: RunConfiguration) -> list[float]:
    """Return driver angles (node convention) to and fro over its range, two turns if it turns."""
    low, high = config.geometry.driven_linkage.reachability.intervals[0]
    if high - low >= TWO_PI:  # a full turn: two turns forwards, through any change points
        return [low + 2.0 * TWO_PI * index / 720 for index in range(721)]
    # close to both dead points (where the closed forms' own error grows as 1/√distance)
    forwards = [low + (high - low) * (0.5 - 0.499 * math.cos(math.pi * index / 200))
                for index in range(201)]
    return forwards + forwards[-2::-1]


@pytest.mark.parametrize('branch', (-1, 1))
@pytest.mark.parametrize(('geometry', 'driver', 'mapping'),
                         [(geometry, driver, mapping) for geometry in GEOMETRIES
                          for driver in Driver for mapping in MAPPINGS])
def test_the_followers_loop_joints_are_the_four_bar_mappings(
        geometry: str, driver: Driver, mapping: str, branch: int) -> None:
    """
    The follower's passive joints, solved by the node's loop, are the four-bar mapping's.

    Solved through ``loops.solver``, they are what ``JointStream`` gives of the closed-form
    state, to 1e-12: over the driver's whole range (to 0.1 % of it from a dead point) on both
    branches, the driver's lab value wrapping at ±π; the velocities relative to their size
    (they grow without bound at the dead points).
    """
    config = _config(geometry, driver, mapping, branch)
    driver_mapping = config.joints.lab[Link(driver.value)]
    follower = MeasuredFollower(config)
    stream = JointStream(config.joints.lab, driver, include_driver=True)
    angles = _sweep(config)
    for index, angle in enumerate(angles):
        omega = 0.7 + 0.3 * math.cos(index)
        lab_angle = math.remainder(driver_mapping.to_lab(angle), TWO_PI)
        followed = follower.follow(index + 1, [driver_mapping.name], [lab_angle],
                                   [driver_mapping.direction * omega])
        if followed is DropReason.DRIVER_UNREACHABLE:
            # the kite's pin A on C: the closed form refuses it too (the motion is undetermined)
            with pytest.raises(DeadPointError, match='undetermined'):
                solve(config.geometry.driven_linkage, angle, CrankRates(omega, 0.0), branch)
            continue
        assert isinstance(followed, FollowedSample), (angle, followed)
        positions, velocities = stream.values(followed.state)
        turns = [round((solved - mapped) / TWO_PI)
                 for solved, mapped in zip(followed.joints[0][1:], positions[1:])]
        if index == 0:
            first_turns = turns
            # Both unwrap near the node's zero: only at a tie (±π exactly) may they choose
            # differently, and then the whole stream is those whole turns apart.
            for node_value, shift in zip(tree_values(followed.state, driver)[0][1:], turns):
                assert shift == 0 or abs(abs(node_value) - math.pi) < 1e-9
        assert turns == first_turns
        for solved, mapped, shift in zip(followed.joints[0][1:], positions[1:], turns):
            assert solved - shift * TWO_PI == pytest.approx(mapped, abs=TOLERANCE)
        velocity_tolerance = KITE_VELOCITY_TOLERANCE if geometry == 'kite' else TOLERANCE
        for solved, mapped in zip(followed.joints[1], velocities):
            assert solved == pytest.approx(mapped, abs=velocity_tolerance * max(1.0, abs(mapped)))
        assert followed.joints[1][0] == velocities[0]
        assert angle_gap(followed.joints[0][0], positions[0]) < TOLERANCE


def test_a_new_geometry_is_a_new_loop_and_a_restart_keeps_the_joints_continuous() -> None:
    """
    The follower reads a new geometry's loop, and its joints go on across a restart.

    After the restart (on ``branch`` again) the joints go on from where they were, whole turns
    included, as the four-bar's stream does.
    """
    config = _config('grashof_crank_rocker', Driver.CRANK, 'lab', 1)
    follower = MeasuredFollower(config)
    stream = JointStream(config.joints.lab, Driver.CRANK, include_driver=True)
    name = config.joints.lab.crank.name

    def check(stamp: int, lab_angle: float) -> None:
        followed = follower.follow(stamp, [name], [lab_angle], [-1.0])
        positions, _ = stream.values(followed.state)
        assert followed.joints[0][1:] == pytest.approx(positions[1:], abs=TOLERANCE)

    for index in range(1, 80):  # a turn and a half of the crank, unwrapped by the stream
        check(index, math.remainder(0.4 - 0.12 * index, TWO_PI))
    smaller = build_configuration({**{spec.name: spec.default for spec in parameter_specs(
        'grashof_crank_rocker')}, **{f'joints.{link}.{key}': getattr(config.joints.lab[link], key)
                                     for link in TREE_ORDER[Driver.CRANK]
                                     for key in ('name', 'direction', 'offset')},
        'source': 'measured', 'crank_length': 0.25})
    follower.reconfigure(smaller)
    follower.restart()
    # the state is the new geometry's: the joints match it only if they come from its loop
    for index in range(80, 100):
        check(index, math.remainder(0.4 - 0.12 * index, TWO_PI))


def test_the_nodes_description_is_parsed_once_for_its_loop_and_its_tf(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """
    The measured mode's loop and the log's TF read one parse of the node's URDF text.

    A follower, a second follower of the same joints, a new threshold and the outputs'
    ``node_description`` (its tree gives /tf_static and /tf) parse the text once in all; a new
    geometry is a new text, parsed once more.
    """
    parses = []
    parse = urdf_parser.Robot.from_xml
    monkeypatch.setattr(urdf_parser.Robot, 'from_xml',
                        lambda *arguments: parses.append(arguments) or parse(*arguments))
    node_description.cache_clear()
    config = _config('grashof_crank_rocker', Driver.CRANK, 'lab', 1)
    follower = MeasuredFollower(config)
    MeasuredFollower(config)
    follower.reconfigure(replace(config, measured=replace(config.measured, max_jump=0.5)))
    parts = (config.geometry.linkage, config.outputs.frame_id, config.joints.lab,
             config.joints.driver)
    description = node_description(*parts)
    assert description.text == urdf_text(*parts)
    assert description.tree.joints.keys() == {'knee_motor', 'knee_link', 'knee_output'}
    assert len(parses) == 1
    MeasuredFollower(_config('kite', Driver.CRANK, 'lab', 1))
    assert len(parses) == 2
