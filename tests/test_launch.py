"""Xacro arguments read from a package's launch files (urdftool.launch): an entry that needs
``model:=...`` is checked the way its launch file expands it, and what its fragments hold is
found; launch files are read, never run."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.conftest import run_urdftool
from urdftool.launch import launch_arguments

ENTRY = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="$(arg model)">
  <xacro:include filename="$(find cam_description)/urdf/$(arg model).urdf.xacro"/>
  <link name="base"/>
  <xacro:camera parent="base"/>
</robot>
"""
FRAGMENT = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="camera" params="parent">
    <joint name="mount" type="revolute"><parent link="${parent}"/><child link="lens"/>
      <axis xyz="0 0 1"/><limit lower="1" upper="-1" effort="1" velocity="1"/></joint>
    <link name="lens"><inertial><mass value="0.1"/>
      <inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>
      <collision><geometry><box size="0.03 0.03 0.03"/></geometry></collision></link>
  </xacro:macro>
</robot>
"""
PYTHON_LAUNCH = """
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import Command, LaunchConfiguration, PathJoinSubstitution
open({marker!r}, "w").write("ran")  # a launch file is never run

def generate_launch_description():
    xacro_file = PathJoinSubstitution([FindPackageShare('cam_description'), 'urdf',
                                       'display.urdf.xacro'])
    return LaunchDescription([
        DeclareLaunchArgument('model', default_value='{model}', description='camera model'),
        DeclareLaunchArgument('name', default_value=LaunchConfiguration('model')),
        Node(parameters=[{{'robot_description': Command(
            ['xacro', ' ', xacro_file, ' ', 'model:=', LaunchConfiguration('model'),
             ' ', 'frame:=', LaunchConfiguration('unset')])}}]),
    ])
"""
XML_LAUNCH = """<launch>
  <arg name="model" default="{model}"/>
  <param name="robot_description"
         command="$(find xacro)/xacro $(find cam_description)/urdf/display.urdf.xacro model:=$(arg model) frame:=$(arg unset)"/>
</launch>
"""


def _package(tmp_path: Path, launch_name: str, launch_text: str) -> Path:
    root = tmp_path / "cam_description"
    (root / "urdf").mkdir(parents=True)
    (root / "launch").mkdir()
    (root / "package.xml").write_text("<package><name>cam_description</name></package>")
    (root / "urdf" / "display.urdf.xacro").write_text(ENTRY)
    (root / "urdf" / "blackfly.urdf.xacro").write_text(FRAGMENT)
    (root / "launch" / launch_name).write_text(launch_text)
    return root


@pytest.mark.parametrize("launch_name, template", [("display.launch.py", PYTHON_LAUNCH),
                                                   ("display.launch", XML_LAUNCH)])
def test_entry_is_expanded_with_its_launch_arguments(tmp_path, monkeypatch, launch_name,
                                                      template):
    marker = tmp_path / "marker"
    root = _package(tmp_path, launch_name, template.format(model="blackfly", marker=str(marker)))
    monkeypatch.chdir(tmp_path)
    result = run_urdftool("check", "--format", "json", "--jobs", "1", root.name)
    report = json.loads(result.out)
    entry = next(f for f in report["files"] if f["path"].endswith("display.urdf.xacro"))
    # only model: the unset argument has no value a launch file gives without running
    assert entry["args"] == {"model": "blackfly"}
    found = {(Path(d["path"]).name, d["rule"]) for d in entry["diagnostics"]}
    assert ("blackfly.urdf.xacro", "joint.lower-above-upper") in found, found
    assert not any(d["rule"] == "xacro.error" for f in report["files"] for d in f["diagnostics"])
    assert result.code == 1
    assert f"model:=blackfly, as launch/{launch_name} passes them" in result.err
    assert not marker.exists()


def test_without_a_launch_file_the_missing_argument_is_reported(tmp_path, monkeypatch):
    root = _package(tmp_path, "other.launch", "<launch/>")
    monkeypatch.chdir(tmp_path)
    report = json.loads(run_urdftool("check", "--format", "json", "--jobs", "1", root.name).out)
    messages = [d["message"] for f in report["files"] for d in f["diagnostics"]
                if d["rule"] == "xacro.error"]
    assert any("$(arg model)" in m for m in messages), messages


def test_configured_entries_win_over_launch_files(tmp_path, monkeypatch):
    root = _package(tmp_path, "display.launch", XML_LAUNCH.format(model="no_such_model"))
    (root / "urdftool.toml").write_text(
        'entries = [{ file = "urdf/display.urdf.xacro", args = { model = "blackfly" } }]\n')
    monkeypatch.chdir(tmp_path)
    result = run_urdftool("check", "--format", "json", "--jobs", "1", root.name)
    entry = next(f for f in json.loads(result.out)["files"]
                 if f["path"].endswith("display.urdf.xacro"))
    assert entry["args"] == {"model": "blackfly"} and "passes them" not in result.err


def test_hostile_launch_files_are_bounded(tmp_path):
    root = tmp_path / "pkg"
    (root / "launch").mkdir(parents=True)
    # deeply nested, huge, not Python, not XML, an entity bomb: no arguments, no exception
    (root / "launch" / "deep.launch.py").write_text("x = " + "[" * 5000 + "]" * 5000)
    (root / "launch" / "huge.launch.py").write_text("'a.xacro', 'k:=v'\n" * 40000)
    (root / "launch" / "bad.launch.py").write_text("def (:\n 'a.xacro' 'k:=v'")
    (root / "launch" / "bomb.launch").write_text(
        '<!DOCTYPE l [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">]>'
        '<launch><param command="xacro a.xacro k:=&b;"/></launch>')
    assert launch_arguments(root) == {}
