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
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare


def generate_launch_description() -> LaunchDescription:
    """Return the launch description: the simulator node and an optional RViz."""
    share = FindPackageShare('ttb_sim')
    return LaunchDescription([
        DeclareLaunchArgument(
            'params_file', default_value=PathJoinSubstitution([share, 'config',
                                                               'simulator.yaml']),
            description='ROS parameters file of the ttb_sim node (ros__parameters).'),
        DeclareLaunchArgument(
            'scenario', default_value='moving_force_beam',
            description='Scenario: a YAML path or a built-in name (ttb-sim scenarios).'),
        DeclareLaunchArgument('rviz', default_value='false',
                              description='Start RViz with config/ttb_sim.rviz.'),
        Node(package='ttb_sim', executable='simulator', name='ttb_sim', output='screen',
             emulate_tty=True,
             parameters=[LaunchConfiguration('params_file'),
                         {'scenario': LaunchConfiguration('scenario')}]),
        Node(package='rviz2', executable='rviz2', name='rviz2', output='screen',
             arguments=['-d', PathJoinSubstitution([share, 'config', 'ttb_sim.rviz'])],
             condition=IfCondition(LaunchConfiguration('rviz'))),
    ])
