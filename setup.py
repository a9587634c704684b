# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

from glob import glob

from setuptools import find_packages, setup

package_name = 'linkage_kinematics'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test', 'bench']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/launch', glob('launch/*.launch.*')),
        ('share/' + package_name + '/config', glob('config/*.yaml')),
        ('share/' + package_name + '/urdf', glob('urdf/*.urdf')),
        ('share/' + package_name + '/foxglove', glob('foxglove/*.json')),
        ('share/' + package_name + '/interfaces/tf2_msgs/msg',
         glob('interfaces/tf2_msgs/msg/*')),
    ],
    install_requires=['setuptools', 'numpy', 'urdfdom-py'],
    # The test suite's own dependencies (requirements.txt pins them; package.xml names them for
    # rosdep). Naming pytest here makes `colcon test` run the suite with pytest.
    extras_require={
        'test': [
            'pytest', 'hypothesis', 'mpmath', 'rosbags', 'colcon-core', 'colcon-ros',
            'colcon-python-setup-py', 'ament-flake8', 'ament-pep257',
        ],
    },
    zip_safe=True,
    maintainer='linkage_kinematics maintainers',
    maintainer_email='linkage-kinematics@example.org',
    description='Exact kinematics of a planar four-bar linkage, published by a ROS 2 node',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'linkage_node = linkage_kinematics.ros.node:main',
            'linkage_command_node = linkage_kinematics.ros.command_node:main',
            'linkage-sweep = linkage_kinematics.cli.sweep:main',
            'linkage-replay = linkage_kinematics.cli.replay:main',
            'linkage-demo = linkage_kinematics.cli.demo:main',
            'linkage-check-loops = linkage_kinematics.cli.check_loops:main',
        ],
    },
)
