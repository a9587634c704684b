# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Start one linkage_node per mechanism of a parameters file.

``params_file:=FILE`` (default config/two_mechanisms.yaml).

Each top-level key of the file, ``/<namespace>/linkage_node``, is one mechanism: a node named
linkage_node in that namespace, which takes that entry's parameters; ``namespace:=/robot``
puts every mechanism under it (/robot/left, …). ``use_sim_time``, ``autostart``,
``log_enabled`` and ``log_level`` apply to every node and win over the file, as in
linkage.launch.py; ``log_folder`` too when given (by default each mechanism keeps its own).
Plain launch actions only, so that every Jazzy release of launch (3.4.0 and later) loads it.
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
from linkage_kinematics.run.configuration import mechanism_entries, NODE_NAME


def _start_mechanisms(context):
    parameters_file = LaunchConfiguration('params_file').perform(context)
    namespace = LaunchConfiguration('namespace').perform(context).rstrip('/')
    common = {
        'use_sim_time': LaunchConfiguration('use_sim_time'),
        'autostart': LaunchConfiguration('autostart'),
        'log.enabled': LaunchConfiguration('log_enabled'),
    }
    if LaunchConfiguration('log_folder').perform(context):
        common['log.folder'] = LaunchConfiguration('log_folder')
    # The entries' parameters are passed by value: under a namespace argument the file's keys
    # would no longer match the nodes' names.
    return [
        Node(
            package='linkage_kinematics',
            executable='linkage_node',
            name=NODE_NAME,
            namespace=namespace + mechanism,
            parameters=[parameters, common],
            ros_arguments=['--log-level', LaunchConfiguration('log_level')],
            output='screen',
        )
        for mechanism, parameters in mechanism_entries(parameters_file).items()
    ]


def generate_launch_description() -> LaunchDescription:
    default_file = os.path.join(
        get_package_share_directory('linkage_kinematics'), 'config', 'two_mechanisms.yaml'
    )
    return LaunchDescription([
        DeclareLaunchArgument(
            'params_file',
            default_value=default_file,
            description='parameters file with one /<namespace>/linkage_node entry per mechanism',
        ),
        DeclareLaunchArgument('namespace', default_value='',
                              description="namespace above every mechanism's own (e.g. /robot)"),
        DeclareLaunchArgument('use_sim_time', default_value='false',
                              description='use the /clock topic as time if true'),
        DeclareLaunchArgument('autostart', default_value='true',
                              description='start the motions at once; false: each waits for '
                              'its ~/resume'),
        DeclareLaunchArgument('log_enabled', default_value='true',
                              description='record every published message to a bag'),
        DeclareLaunchArgument('log_folder', default_value='',
                              description='folder for every bag (relative to the working '
                              "directory); empty: each mechanism's log.folder from the file"),
        DeclareLaunchArgument('log_level', default_value='info',
                              description="the nodes' ROS log level"),
        OpaqueFunction(function=_start_mechanisms),
    ])
