# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Complete a lab's joint states from its measured joint: linkage_node with ``source: measured``.

``params_file:=`` the node's parameters (default config/measured_lab.yaml, a lab's knee);
``joint_states:=`` the topic on which the encoder or joint_state_broadcaster publishes the
driver (default /joint_states: the node listens there, ignores its own output and publishes the
passive joints there too, for the lab's robot_state_publisher). The other arguments are those of
linkage.launch.py (``namespace``, ``use_sim_time``, ``autostart``, ``log_enabled``,
``log_folder``, ``log_level``), set after the parameters file, so they win over it.

Plain launch actions only (no nested substitution lists), so that every Jazzy release of
launch (3.4.0 and later) loads it.
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description() -> LaunchDescription:
    config = os.path.join(get_package_share_directory('linkage_kinematics'), 'config')
    return LaunchDescription([
        DeclareLaunchArgument(
            'params_file', default_value=os.path.join(config, 'measured_lab.yaml'),
            description="parameters file of the node (default: a lab's knee, "
            'config/measured_lab.yaml)'),
        DeclareLaunchArgument(
            'joint_states', default_value='/joint_states',
            description='topic on which the measured driver joint arrives'),
        DeclareLaunchArgument('namespace', default_value='',
                              description="the node's namespace (e.g. /left)"),
        DeclareLaunchArgument('use_sim_time', default_value='false',
                              description='use the /clock topic as time if true'),
        DeclareLaunchArgument('autostart', default_value='true',
                              description='follow the driver at once; false: wait for '
                              '~/resume'),
        DeclareLaunchArgument('log_enabled', default_value='true',
                              description='record every published message to a bag'),
        DeclareLaunchArgument('log_folder', default_value='bags',
                              description='folder for the bags (relative to the working '
                              'directory)'),
        DeclareLaunchArgument('log_level', default_value='info',
                              description="the node's ROS log level"),
        Node(
            package='linkage_kinematics',
            executable='linkage_node',
            name='linkage_node',
            namespace=LaunchConfiguration('namespace'),
            parameters=[LaunchConfiguration('params_file'), {
                'use_sim_time': LaunchConfiguration('use_sim_time'),
                'autostart': LaunchConfiguration('autostart'),
                'log.enabled': LaunchConfiguration('log_enabled'),
                'log.folder': LaunchConfiguration('log_folder'),
            }],
            remappings=[('measured_joint_states', LaunchConfiguration('joint_states'))],
            ros_arguments=['--log-level', LaunchConfiguration('log_level')],
            output='screen',
        ),
    ])
