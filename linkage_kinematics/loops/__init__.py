# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A robot's closed loops: read from its URDF, ordered, closed sample by sample and followed (no ROS).

``description`` (a URDF's tree at the zero pose and its ``<constraint>`` elements), ``planar``
(one constraint's loop as a ``PlanarLoop``, with its joints' signs), ``plan`` (the robot's loops
ordered from the measured joints), ``solver`` (the plan closed sample by sample), ``intake``
(the one sample intake of both measured modes, and the one set of reasons a message is dropped
for) and ``follower`` (a JointState in, every passive loop joint out, or why the message was
dropped). Imports only ``kinematics`` and ``model`` (and numpy, lxml); every description comes
in parsed (``model.urdf_reader.UrdfTree``).
"""
