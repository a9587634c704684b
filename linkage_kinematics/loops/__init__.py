# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A robot's closed loops: read from its description, ordered, closed sample by sample and followed.

Pure (numpy, urdf_parser_py, lxml, PyYAML; no ROS). ``closures`` is the one model of a loop
closure, whichever of the three encodings it was read from: ``constraint_element`` (urdfdom PR
#264's ``<constraint>``), ``loop_joint_element`` (Isaac Sim's ``<loop_joint>``) and
``closure_file`` (toolbox-parallel-robots' YAML side file) read them, ``encodings`` a whole
description's. ``description`` (a URDF's tree at the zero pose and its ``<constraint>``
elements), ``planar`` (one constraint's loop as a ``PlanarLoop``, with its joints' signs),
``plan`` (the robot's loops ordered from the measured joints), ``solver`` (the plan closed
sample by sample), ``intake`` (the one sample intake of both measured modes, and the one set of
reasons a message is dropped for) and ``follower`` (a JointState in, every passive loop joint
out, or why the message was dropped). Imports only ``kinematics`` and ``model``; every
description comes in parsed (``model.urdf_reader.UrdfTree``).
"""
