"""The ``ros2_control`` rules (issue 31): <ros2_control> blocks, the controllers YAML the
simulator plugin names (located at its lines), launch files passing xacro output."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

from tests.conftest import run_urdftool

ROBOT = """<?xml version="1.0"?>
<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <link name="base"/><link name="a"/><link name="b"/><link name="tip"/>
  <joint name="joint1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="joint2" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="tool" type="fixed"><parent link="b"/><child link="tip"/></joint>
  <ros2_control name="arm_system" type="system">
    <hardware>
      <plugin>gz_ros2_control/GazeboSimSystem</plugin>
    </hardware>
    <joint name="joint1"><command_interface name="position"/><state_interface name="position"/></joint>
    <joint name="joint2"><command_interface name="position"/><state_interface name="position"/></joint>
  </ros2_control>
  <gazebo>
    <plugin filename="gz_ros2_control-system" name="gz_ros2_control::GazeboSimROS2ControlPlugin">
      <parameters>$(find arm_bringup)/config/controllers.yaml</parameters>
    </plugin>
  </gazebo>
</robot>
"""

CONTROLLERS = """controller_manager:
  ros__parameters:
    update_rate: 100
    arm_controller:
      type: joint_trajectory_controller/JointTrajectoryController
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster

arm_controller:
  ros__parameters:
    joints:
      - joint1
      - joint2
    command_interfaces:
      - position
    state_interfaces:
      - position

joint_state_broadcaster:
  ros__parameters:
    extra_joints: [not_a_urdf_joint]
"""


def _repo(tmp_path, robot: str = ROBOT, controllers: str = CONTROLLERS) -> Path:
    repo = tmp_path / "repo"
    for name, sub in (("arm_description", "urdf"), ("arm_bringup", "config")):
        (repo / name / sub).mkdir(parents=True)
        (repo / name / "package.xml").write_text(f"<package><name>{name}</name></package>")
    (repo / "arm_description" / "urdf" / "arm.urdf.xacro").write_text(robot, encoding="utf-8")
    (repo / "arm_bringup" / "config" / "controllers.yaml").write_text(controllers,
                                                                      encoding="utf-8")
    subprocess.run(["git", "init", "-q", str(repo)], check=True)
    return repo


def _findings(result, family: str = "ros2_control") -> list[tuple[str, str, int, str]]:
    assert result.code in (0, 1), result.err
    return [(Path(d["path"]).name, d["rule"], d["line"], d["severity"])
            for f in json.loads(result.out)["files"] for d in f["diagnostics"]
            if d["rule"].startswith(family)]


def test_a_consistent_robot_and_controllers_give_nothing(tmp_path):
    repo = _repo(tmp_path)
    assert _findings(run_urdftool("check", str(repo), "--format", "json")) == []


def test_controllers_yaml_named_by_the_simulator_plugin_is_checked_at_its_lines(tmp_path):
    # a joint the robot's <ros2_control> lacks, a substituted name, an interface it lacks
    controllers = CONTROLLERS.replace("      - joint2\n", "      - joint3\n"
                                      "      - $(var prefix)joint2\n").replace(
        "    state_interfaces:\n      - position\n",
        "    state_interfaces:\n      - position\n      - velocity\n")
    repo = _repo(tmp_path, controllers=controllers)
    found = _findings(run_urdftool("check", str(repo), "--format", "json"))
    assert found == [("controllers.yaml", "ros2_control.controller-joint", 13, "error"),
                     ("controllers.yaml", "ros2_control.controller-joint", 19, "error")], found


def test_two_sections_of_one_node_are_merged_as_ros_reads_them(tmp_path):
    controllers = "/**:\n" + "".join("  " + line + "\n" if line else "\n"
                                     for line in CONTROLLERS.split("arm_controller:\n  ros")[0]
                                     .splitlines()) + "/**:\n  arm_controller:\n" \
        "    ros__parameters:\n      joints: [joint1, jiont2]\n"
    repo = _repo(tmp_path, controllers=controllers)
    found = _findings(run_urdftool("check", str(repo), "--format", "json"))
    assert found == [("controllers.yaml", "ros2_control.controller-joint", 13, "error")], found


def test_a_missing_parameters_file_is_found_at_the_plugin(tmp_path):
    repo = _repo(tmp_path, robot=ROBOT.replace("config/controllers.yaml", "config/nope.yaml"))
    found = _findings(run_urdftool("check", str(repo), "--format", "json"))
    assert found == [("arm.urdf.xacro", "ros2_control.parameters-missing", 18, "error")]


def test_blocks_misplaced_broken_plugin_fixed_joint_and_interfaces(tmp_path):
    robot = ROBOT.replace("      <plugin>gz_ros2_control/GazeboSimSystem</plugin>",
                          "      <plugin>gz_ros2_control/GazeboSimSystem\n      </plugin>")
    robot = robot.replace('<joint name="joint2"><command_interface name="position"/>',
                          '<joint name="joint2"><command_interface name="positon"/>')
    robot = robot.replace("  </ros2_control>\n", '    <joint name="tool"/>\n  </ros2_control>\n'
                          '  <gazebo><ros2_control name="other" type="system"><hardware>'
                          '<plugin>mock_components/GenericSystem</plugin></hardware>'
                          '</ros2_control></gazebo>\n')
    repo = _repo(tmp_path, robot=robot)
    found = _findings(run_urdftool("check", str(repo), "--format", "json"))
    assert ("arm.urdf.xacro", "ros2_control.plugin-name", 11, "error") in found
    assert ("arm.urdf.xacro", "ros2_control.interface", 15, "error") in found
    assert ("arm.urdf.xacro", "ros2_control.fixed-joint", 16, "error") in found
    assert ("arm.urdf.xacro", "ros2_control.misplaced", 18, "error") in found
    assert len(found) == 4, found


def test_custom_hardware_may_have_its_own_interfaces(tmp_path):
    robot = ROBOT.replace("gz_ros2_control/GazeboSimSystem", "my_robot_driver/MyHardware")
    robot = robot.replace('<joint name="joint1"><command_interface name="position"/>',
                          '<joint name="joint1"><command_interface name="position"/>'
                          '<command_interface name="motor_enable"/>'
                          '<state_interface name="postion"/>')
    repo = _repo(tmp_path, robot=robot)
    found = _findings(run_urdftool("check", str(repo), "--format", "json"))
    assert found == [("arm.urdf.xacro", "ros2_control.interface", 13, "warning")], found


LAUNCH = '''from launch import LaunchDescription
from launch.substitutions import Command, FindExecutable, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue
from launch_ros.substitutions import FindPackageShare


def generate_launch_description():
    content = Command([FindExecutable(name="xacro"), " ", PathJoinSubstitution(
        [FindPackageShare("arm_description"), "urdf", "arm.urdf.xacro"])])
    description = {"robot_description": VALUE}
    return LaunchDescription([Node(package="robot_state_publisher",
                                   executable="robot_state_publisher",
                                   parameters=[description])])
'''


def test_a_launch_file_passing_xacro_output_without_a_string_type(tmp_path):
    repo = _repo(tmp_path)
    launch = repo / "arm_bringup" / "launch"
    launch.mkdir()
    (launch / "bad.launch.py").write_text(LAUNCH.replace("VALUE", "content"))
    (launch / "untyped.launch.py").write_text(LAUNCH.replace("VALUE", "ParameterValue(content)"))
    (launch / "good.launch.py").write_text(
        LAUNCH.replace("VALUE", "ParameterValue(content, value_type=str)"))
    found = _findings(run_urdftool("check", str(repo), "--format", "json"))
    assert found == [("bad.launch.py", "ros2_control.description-not-string", 11, "warning"),
                     ("untyped.launch.py", "ros2_control.description-not-string", 11,
                      "warning")], found


def test_one_description_passed_to_several_nodes_is_one_finding(tmp_path):
    """One cause, one finding: a description variable given to three nodes without a string
    type (open_manipulator's launch files: three findings per file, 9 files) is one finding at
    its first use naming the other lines."""
    repo = _repo(tmp_path)
    launch = repo / "arm_bringup" / "launch"
    launch.mkdir()
    three = LAUNCH.replace(
        "                                   parameters=[description])])",
        "                                   parameters=[description]),\n"
        "        Node(package=\"a\", parameters=[{\"robot_description\": content}]),\n"
        "        Node(package=\"b\", parameters=[{\"robot_description\": content}])])")
    (launch / "bad.launch.py").write_text(three.replace("VALUE", "content"))
    lines = [n for n, t in enumerate(three.splitlines(), 1) if '"robot_description"' in t]
    assert len(lines) == 3
    found = [d for f in json.loads(run_urdftool("check", str(repo), "--format", "json").out)
             ["files"] for d in f["diagnostics"]
             if d["rule"] == "ros2_control.description-not-string"]
    assert [d["line"] for d in found] == [lines[0]], found
    assert f"(also given so at lines {lines[1]}, {lines[2]})" in found[0]["message"]


def test_changed_controllers_yaml_rechecks_the_robot(tmp_path, monkeypatch):
    repo = _repo(tmp_path)
    monkeypatch.setenv("URDFTOOL_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.chdir(repo)
    assert _findings(run_urdftool("check", ".", "--format", "json")) == []
    yaml = Path("arm_bringup/config/controllers.yaml")
    yaml.write_text(CONTROLLERS.replace("      - joint2\n", "      - joint9\n"))
    found = _findings(run_urdftool("check", "--format", "json", "--changed", str(yaml)))
    assert found == [("controllers.yaml", "ros2_control.controller-joint", 13, "error")], found


def test_a_yaml_given_with_its_robot(tmp_path):
    repo = _repo(tmp_path)
    yaml = repo / "arm_bringup" / "config" / "controllers.yaml"
    yaml.write_text(CONTROLLERS.replace("      - joint2\n", "      - joint22\n"))
    result = run_urdftool("check", str(yaml), "--robot",
                          str(repo / "arm_description" / "urdf" / "arm.urdf.xacro"),
                          "-P", f"arm_bringup={repo / 'arm_bringup'}", "--format", "json")
    assert _findings(result) == [("controllers.yaml", "ros2_control.controller-joint", 13,
                                  "error")]
