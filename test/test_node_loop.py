# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The node's own URDF as a ``<constraint>`` loop, read by ``model.loops`` as a lab's would be.

For each preset, each driver and each joint mapping: one four-bar loop without a problem, whose
dimensions are the four-bar's; its constraint frames parallel at the zero pose and coinciding
(urchin's forward kinematics, independent of the package) wherever the tree is assembled; and
the element is the only thing robot_state_publisher's reading of the text does not see.
"""

from __future__ import annotations

import math
import re

from linkage_kinematics.kinematics.geometry import FourBar, preset, PRESETS
from linkage_kinematics.kinematics.solver import CrankRates, solve
from linkage_kinematics.model.joints import (
    Driver,
    JointMap,
    JointMapping,
    TREE_ORDER,
    tree_values,
)
from linkage_kinematics.model.loops import find_loops
from linkage_kinematics.model.robot_transforms import RobotTransforms
from linkage_kinematics.model.urdf import urdf_text
import loop_reference
import numpy as np
import pytest
import urchin

TOLERANCE = 1e-12
# config/measured_lab.yaml's knee, and the same with its rocker joint reversed
LAB = JointMap(JointMapping('knee_motor', -1, 0.4), JointMapping('knee_link', 1, -0.2),
               JointMapping('knee_output', 1, 1.1))
LAB_REVERSED = JointMap(LAB.crank, LAB.coupler, JointMapping('knee_output', -1, 1.1))
MAPPINGS = {'default': JointMap(), 'lab': LAB, 'lab_reversed': LAB_REVERSED}
CASES = [(name, driver, mapping) for name in PRESETS for driver in Driver
         for mapping in MAPPINGS]


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
    loops = find_loops(urdf)
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
    with_constraint = RobotTransforms(urdf)
    plain = RobotTransforms(without)
    assert with_constraint.fixed_transforms() == plain.fixed_transforms()
    assert with_constraint.moving_transforms(values) == plain.moving_transforms(values)
