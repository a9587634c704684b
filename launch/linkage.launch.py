# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Start linkage_node with one of the paper's runs, or with a parameters file of your own.

``scenario:=constant`` (default) or ``scenario:=variable`` picks config/seed_<scenario>.yaml;
``params_file:=FILE`` replaces it. The other arguments are those of robot_state_publisher's and
nav2's launch files (``namespace``, ``use_sim_time``, ``autostart``, ``log_level``) and the
node's bag recording (``log_enabled``, ``log_folder``), with the node's defaults; they are set
after the parameters file, so they win over it. ``ros2 launch linkage_kinematics
linkage.launch.py --show-args`` lists them.

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
            'scenario',
            default_value='constant',
            choices=['constant', 'variable'],
            description="drive law of the paper's 90° turn: constant (ω = 2 rad/s) or "
            'variable (ω = 0.10 + 2.3·α)',
        ),
        DeclareLaunchArgument(
            'params_file',
            default_value=[os.path.join(config, 'seed_'), LaunchConfiguration('scenario'),
                           '.yaml'],
            description="parameters file of the node (default: the scenario's)",
        ),
        DeclareLaunchArgument('namespace', default_value='',
                              description="the node's namespace (e.g. /left)"),
        DeclareLaunchArgument('use_sim_time', default_value='false',
                              description='use the /clock topic as time if true'),
        DeclareLaunchArgument('autostart', default_value='true',
                              description='start the motion at once; false: wait for '
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
            ros_arguments=['--log-level', LaunchConfiguration('log_level')],
            output='screen',
        ),
    ])
