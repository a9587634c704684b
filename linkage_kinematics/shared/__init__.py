# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
What the layers above share, one owner for each contract; beneath them all, importing none.

- ``cdr``: the CDR bytes of a message, both ways (``encode_cdr``, ``FixedShapeEncoder``,
  ``JointStateDecoder``): the live node's output and input (``ros``) and what the bag logs
  (``bag``) are the same bytes;
- ``command_cdr``: the command relay's messages as CDR bytes (``JointTrajectory`` both ways,
  ``Float64MultiArray`` in), which ``linkage_command_node`` subscribes and publishes raw and
  its bag logs;
- ``rosbag2_split``: rosbag2's numbers for splitting a bag, which ``run`` checks the node's
  parameters against and ``bag.writer`` applies;
- ``affinity``: a process's threads held to a set of CPUs, for the node (``run.placement``) and
  for its bag writer process (``bag.writer_process``).

Only ``cdr`` loads a ROS module (rosidl_parser, for the message field types; ``command_cdr``
builds on it); ``rosbag2_split`` and ``affinity`` are plain Python, so that ``run`` stays free of
ROS and the bag writer process of rclpy.
"""
