"""Start linkage_node with one of the seed's scenarios: ``scenario:=constant`` (default) or
``scenario:=variable`` (config/seed_<scenario>.yaml)."""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare


def generate_launch_description() -> LaunchDescription:
    scenario = LaunchConfiguration("scenario")
    parameters = PathJoinSubstitution(
        [FindPackageShare("linkage_kinematics"), "config", ["seed_", scenario, ".yaml"]]
    )
    return LaunchDescription([
        DeclareLaunchArgument(
            "scenario",
            default_value="constant",
            choices=["constant", "variable"],
            description="drive law of the seed's 90° turn: constant (ω = 2 rad/s) or "
            "variable (ω = 0.10 + 2.3·α)",
        ),
        Node(
            package="linkage_kinematics",
            executable="linkage_node",
            name="linkage_node",
            parameters=[parameters],
            output="screen",
        ),
    ])
