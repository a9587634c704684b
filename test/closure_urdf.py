# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""A small URDF tree for the closure readers' tests: links, a fixed frame, a mimic pair."""

from linkage_kinematics.model.urdf_reader import read_urdf, UrdfTree

LIMIT = '<limit effort="1" velocity="1" lower="-3" upper="3"/>'
TREE = f"""<robot name="closures">
  <link name="base"/><link name="crank"/><link name="rod"/><link name="foot"/>
  <link name="tip"/><link name="toe"/><link name="heel"/>
  <joint name="motor" type="revolute"><parent link="base"/><child link="crank"/>
    <axis xyz="0 0 1"/>{LIMIT}</joint>
  <joint name="elbow" type="continuous"><parent link="crank"/><child link="rod"/>
    <origin xyz="1 0 0"/></joint>
  <joint name="ankle" type="revolute"><parent link="base"/><child link="foot"/>
    <origin xyz="0 2 0"/>{LIMIT}</joint>
  <joint name="tip_mount" type="fixed"><parent link="foot"/><child link="tip"/>
    <origin xyz="0 1 0" rpy="0 0 1.5"/></joint>
  <joint name="toe_joint" type="continuous"><parent link="foot"/><child link="toe"/>
    <mimic joint="ankle" multiplier="2"/></joint>
  <joint name="heel" type="prismatic"><parent link="foot"/><child link="heel"/>{LIMIT}</joint>
{{extra}}
</robot>
"""


def tree(extra: str = '') -> UrdfTree:
    """Return the small tree read by ``read_urdf``, ``extra`` elements added under <robot>."""
    return read_urdf(TREE.format(extra=extra))
