# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A robot's closed loops: read from its description, structured, closed sample by sample, followed.

Pure (numpy, urdf_parser_py, lxml, PyYAML; no ROS); every description comes in parsed
(``model.urdf_reader.UrdfTree``). Imports only ``kinematics`` and ``model``. Modules:

- reading: ``closures`` (the one closure model: pin, ball, weld, its two sides, its encoding),
  one reader per encoding, ``constraint_element`` (urdfdom PR #264's ``<constraint>``),
  ``loop_joint_element`` (Isaac Sim's ``<loop_joint>``) and ``closure_file``
  (toolbox-parallel-robots' YAML side file), with ``xml_values`` (the two elements' links and
  numbers); ``encodings`` (a description's closures in all three); ``description`` (the URDF's
  tree at the zero pose);
- planar loops: ``planar`` (a pin's four-joint loop as a ``PlanarLoop``), ``plan`` (the robot's
  closures grouped and planned from the measured joints), ``solver`` (the plan closed sample by
  sample);
- the general closure: ``tree`` (the kinematic tree: coordinates, overrides, mimics),
  ``frames`` (its moving frames per sample), ``spatial`` (rigid motions in plain floats),
  ``equations`` (the closures' residuals, exact Jacobian and its rate), ``batch_equations``
  (the same Jacobian at many configurations at once, numpy), ``rods`` (a rod written as one
  distance: a universal joint's rod found in the tree, or any ``Distance``), ``linear`` (small
  LU factors), ``structure`` (groups, degrees of freedom, idle freedoms, determinacy),
  ``reduction`` (welded rods and collinear pins rewritten smaller), ``assembly`` (the assembled
  pose nearest a start), ``square_system`` (the square system Newton solves: independent rows,
  idle rows, scales, residual bounds), ``continuation`` (Newton to rounding, continued from the
  last solution in predicted substeps), ``refusals`` (why a group refuses a sample or a plan,
  and the conditioning limit), ``newton`` (a group closed per sample: a closed form or the
  continuation, velocities, refusals), ``derivatives`` (on request: the sensitivity,
  accelerations, the distance to a singular configuration), ``closed_forms`` (the planar
  five-bar, a crank–rod–ball leg's inverse, the delta's three spheres, a universal joint's and
  a ball's angles) and ``reach`` (each known joint's reach, for the checker);
- the transmission: ``transmission`` (a group between its actuators and output joints: M =
  ∂m/∂o, efforts), ``robot_transmission`` (a robot's, with names: the output joints' efforts),
  ``transmission_range`` (the mechanical advantage over the reachable range, for the checker),
  ``command`` (a group's command direction, its refusals), ``command_parts`` (one command group
  by its method), ``command_batch`` (a trajectory's points for one group at once, numpy) and
  ``robot_command`` (a robot's command direction, with names: what the relay converts);
- following: ``intake`` (the one sample intake of both measured modes, and the one set of
  reasons a message is dropped for) and ``follower`` (a JointState in, every passive loop joint
  out, or why the message was dropped).
"""
