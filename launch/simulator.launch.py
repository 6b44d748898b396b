# Copyright 2026 The ttb_sim Authors
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""
Launch the ttb_sim simulator node with config/simulator.yaml, optionally with RViz.

Examples::

    ros2 launch ttb_sim simulator.launch.py
    ros2 launch ttb_sim simulator.launch.py scenario:=sprung_mass_beam rviz:=true
    ros2 launch ttb_sim simulator.launch.py params_file:=/path/to/my.yaml

``rviz:=true`` where rviz2 is not installed logs a warning and starts the node alone.
"""

from typing import Any

from ament_index_python.packages import get_package_prefix, PackageNotFoundError
from launch import LaunchContext, LaunchDescription
from launch.actions import DeclareLaunchArgument, LogInfo, OpaqueFunction
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare


def rviz_if_installed(context: LaunchContext, *args: Any) -> list[Any]:
    """Return the RViz node, or a warning when the rviz2 package is not installed."""
    try:
        get_package_prefix('rviz2')
    except PackageNotFoundError:
        return [LogInfo(msg='rviz:=true, but rviz2 is not installed (apt install '
                            'ros-jazzy-rviz2); starting without RViz')]
    share = FindPackageShare('ttb_sim')
    return [Node(package='rviz2', executable='rviz2', name='rviz2', output='screen',
                 arguments=['-d', PathJoinSubstitution([share, 'config', 'ttb_sim.rviz'])])]


def generate_launch_description() -> LaunchDescription:
    """Return the launch description: the simulator node and an optional RViz."""
    share = FindPackageShare('ttb_sim')
    return LaunchDescription([
        DeclareLaunchArgument(
            'params_file', default_value=PathJoinSubstitution([share, 'config',
                                                               'simulator.yaml']),
            description='ROS parameters file of the ttb_sim node (ros__parameters).'),
        DeclareLaunchArgument(
            'scenario', default_value='live_coupled',
            description='Scenario: a YAML path or a built-in name (ttb-sim scenarios).'),
        DeclareLaunchArgument('rviz', default_value='false',
                              description='Start RViz with config/ttb_sim.rviz.'),
        Node(package='ttb_sim', executable='simulator', name='ttb_sim', output='screen',
             emulate_tty=True,
             parameters=[LaunchConfiguration('params_file'),
                         {'scenario': LaunchConfiguration('scenario')}]),
        OpaqueFunction(function=rviz_if_installed,
                       condition=IfCondition(LaunchConfiguration('rviz'))),
    ])
