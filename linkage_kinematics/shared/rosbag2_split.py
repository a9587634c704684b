# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
rosbag2's numbers for splitting a bag into files, as ``ros2 bag record`` takes them.

``run.parameter_specs`` checks the node's ``log.max_bag_size`` and ``log.max_bag_duration``
against them, and ``bag.writer`` applies the same rule to what it is given.
"""

# rosbag2's smallest max_bagfile_size for its MCAP storage (get_minimum_split_file_size), in
# bytes, and its value for "never split" (of both max_bagfile_size and max_bagfile_duration).
MIN_SPLIT_SIZE = 1024
NO_SPLIT = 0
