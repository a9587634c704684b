# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Complete a lab's joint states from its measured joint: linkage_node with ``source: measured``.

``params_file:=`` the node's parameters (default config/measured_lab.yaml), ``joint_states:=``
the topic the encoder or joint_state_broadcaster publishes the driver on (default
/joint_states: the node listens there, ignores its own output and publishes the passive joints
there too, for robot_state_publisher). The lab's robot_state_publisher, with its own URDF, runs
beside it as usual.

Plain launch actions only (no nested substitution lists), so that every Jazzy release of
launch (3.4.0 and later) loads it.
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def _start_completer(context):
    parameters = LaunchConfiguration('params_file').perform(context) or os.path.join(
        get_package_share_directory('linkage_kinematics'), 'config', 'measured_lab.yaml')
    return [
        Node(
            package='linkage_kinematics',
            executable='linkage_node',
            name='linkage_node',
            parameters=[parameters],
            remappings=[
                ('measured_joint_states', LaunchConfiguration('joint_states').perform(context))],
            output='screen',
        )
    ]


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription([
        DeclareLaunchArgument(
            'params_file', default_value='',
            description="linkage_node's parameters (default: the package's "
            'config/measured_lab.yaml)'),
        DeclareLaunchArgument(
            'joint_states', default_value='/joint_states',
            description='topic on which the measured driver joint arrives'),
        OpaqueFunction(function=_start_completer),
    ])
