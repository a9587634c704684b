# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Start one linkage_node per mechanism of a parameters file.

``mechanisms:=FILE`` (default config/two_mechanisms.yaml).

Each top-level key of the file, ``/<namespace>/linkage_node``, is one mechanism: a node named
linkage_node in that namespace, which takes its own entry of the file. Plain launch actions
only, so that every Jazzy release of launch (3.4.0 and later) loads it.
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
from linkage_kinematics.parameters import mechanism_namespaces, NODE_NAME


def _start_mechanisms(context):
    parameters_file = LaunchConfiguration('mechanisms').perform(context)
    return [
        Node(
            package='linkage_kinematics',
            executable='linkage_node',
            name=NODE_NAME,
            namespace=namespace,
            parameters=[parameters_file],
            output='screen',
        )
        for namespace in mechanism_namespaces(parameters_file)
    ]


def generate_launch_description() -> LaunchDescription:
    default_file = os.path.join(
        get_package_share_directory('linkage_kinematics'), 'config', 'two_mechanisms.yaml'
    )
    return LaunchDescription([
        DeclareLaunchArgument(
            'mechanisms',
            default_value=default_file,
            description='parameters file with one /<namespace>/linkage_node entry per mechanism',
        ),
        OpaqueFunction(function=_start_mechanisms),
    ])
