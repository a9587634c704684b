# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Start linkage_node with one of the seed's scenarios.

``scenario:=constant`` (default) or ``scenario:=variable`` (config/seed_<scenario>.yaml).

Plain launch actions only (no nested substitution lists), so that every Jazzy release of
launch (3.4.0 and later) loads it.
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def _start_scenario(context):
    scenario = LaunchConfiguration('scenario').perform(context)
    parameters = os.path.join(
        get_package_share_directory('linkage_kinematics'), 'config', f'seed_{scenario}.yaml'
    )
    return [
        Node(
            package='linkage_kinematics',
            executable='linkage_node',
            name='linkage_node',
            parameters=[parameters],
            output='screen',
        )
    ]


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription([
        DeclareLaunchArgument(
            'scenario',
            default_value='constant',
            choices=['constant', 'variable'],
            description="drive law of the seed's 90° turn: constant (ω = 2 rad/s) or "
            'variable (ω = 0.10 + 2.3·α)',
        ),
        OpaqueFunction(function=_start_scenario),
    ])
