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


def test_a_changed_launch_file_is_said_to_pass_the_arguments(tmp_path, monkeypatch):
    """Issue 29: a changed launch file re-checks the entry it passes arguments to, and the
    note said the reverse ("checked because it reads launch/display.launch")."""
    root = _package(tmp_path, "display.launch", XML_LAUNCH.format(model="blackfly"))
    monkeypatch.chdir(tmp_path)
    result = run_urdftool("check", "--jobs", "1", "--changed", "--",
                          f"{root.name}/launch/display.launch")
    assert result.code == 1, result.err
    assert "display.urdf.xacro: checked because cam_description/launch/display.launch passes its " \
           "xacro arguments" in result.err, result.err
    assert "reads launch/" not in result.err


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


@pytest.mark.parametrize("fmt", ["text", "json", "sarif", "github", "junit"])
def test_a_launch_file_over_the_limit_is_one_located_finding(tmp_path, monkeypatch, fmt):
    """Refused unread for its size (issue 21): one ``xacro.limit-exceeded`` warning at the
    launch file, in every format; the package's robots are still checked."""
    from urdftool.launch import MAX_BYTES

    big = XML_LAUNCH.format(model="blackfly") + "<!--" + "x" * MAX_BYTES + "-->\n"
    root = _package(tmp_path, "display.launch", big)
    monkeypatch.chdir(tmp_path)
    result = run_urdftool("check", "--format", fmt, "--jobs", "1", root.name)
    assert "Traceback" not in result.err
    assert result.out.count("display.launch") >= 1
    if fmt == "json":
        report = json.loads(result.out)
        found = [(f["path"], d["rule"], d["severity"], d["line"]) for f in report["files"]
                 for d in f["diagnostics"] if d["path"].endswith(".launch")]
        assert found == [("cam_description/launch/display.launch", "xacro.limit-exceeded",
                          "warning", None)]
        message = next(d["message"] for f in report["files"] for d in f["diagnostics"]
                       if d["path"].endswith(".launch"))
        size = (root / "launch" / "display.launch").stat().st_size
        assert f"{size >> 10} KB, larger than the {MAX_BYTES >> 10} KB" in message
        # the entry went on, checked without the launch file's model:=blackfly
        entry = next(f for f in report["files"] if f["path"].endswith("display.urdf.xacro"))
        assert any("$(arg model)" in d["message"] for d in entry["diagnostics"])
    elif fmt == "sarif":
        results = json.loads(result.out)["runs"][0]["results"]
        assert [r["ruleId"] for r in results
                if r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"]
                .endswith("display.launch")] == ["xacro.limit-exceeded"]
    else:
        assert result.out.count("larger than the 256 KB urdftool reads") == 1, result.out


def test_refused_launch_files_reach_the_language_server_engine(tmp_path):
    """The editor plans a package as ``check DIR`` does: the same finding at the launch file,
    and at the launch directory when it holds more files than are read."""
    from urdftool.launch import MAX_BYTES, MAX_FILES
    from urdftool.lsp.engine import Engine, Settings

    big = XML_LAUNCH.format(model="blackfly") + "<!--" + "x" * MAX_BYTES + "-->\n"
    root = _package(tmp_path, "display.launch", big)
    for i in range(MAX_FILES):
        (root / "launch" / f"extra{i:02d}.launch").write_text("<launch/>")
    settings, problems = Settings().updated({"trusted": True}, trust=True)
    assert problems == []
    engine = Engine(settings)
    engine.refresh([str(root / "urdf" / "display.urdf.xacro")])
    result = engine.snapshot[next(iter(engine.snapshot))]
    at = {Path(path).name: [(d.rule, d.severity) for d in found]
          for path, found in result.diagnostics.items()}
    # sorted: display.launch comes before extra00..extra63, so it is among those read
    assert at["display.launch"] == [("xacro.limit-exceeded", "warning")]
    assert at["launch"] == [("xacro.limit-exceeded", "warning")]
    message = next(d.message for path, found in result.diagnostics.items()
                   if path.endswith("launch") for d in found)
    assert f"{MAX_FILES + 1} launch files, more than the {MAX_FILES}" in message
    assert "1 not read, from launch/extra63.launch on" in message


def test_the_command_lines_arguments_replace_the_launch_files_choices(tmp_path, monkeypatch):
    """``check DIR model:=blackfly`` where the launch file offers three models: one expansion,
    reported with the argument it was expanded with (not three, labelled with the launch
    file's choices while every one used blackfly)."""
    launch = PYTHON_LAUNCH.replace(  # a required argument: one expansion per choice
        "default_value='{model}', description='camera model'",
        "description='camera model', choices=['a', 'b', 'blackfly']")
    root = _package(tmp_path, "display.launch.py",
                    launch.format(model="a", marker=str(tmp_path / "marker")))
    monkeypatch.chdir(tmp_path)
    first = run_urdftool("check", "--format", "json", "--jobs", "1", root.name)
    plain = json.loads(first.out)
    assert sorted(f["args"].get("model") for f in plain["files"]
                  if f["path"].endswith("display.urdf.xacro")) == ["a", "b", "blackfly"]
    # said once, the choices listed (not a line per expansion)
    said = [line for line in first.err.splitlines() if "display.urdf.xacro: expanded" in line]
    assert len(said) == 1 and "expanded 3 times with model:= a, b, blackfly" in said[0], said
    result = run_urdftool("check", "--format", "json", "--jobs", "1", root.name,
                          "model:=blackfly")
    entries = [f for f in json.loads(result.out)["files"]
               if f["path"].endswith("display.urdf.xacro")]
    assert [e["args"] for e in entries] == [{"model": "blackfly"}]
    assert ("blackfly.urdf.xacro", "joint.lower-above-upper") in {
        (Path(d["path"]).name, d["rule"]) for d in entries[0]["diagnostics"]}


CONDITIONAL_XML = """<launch>
  <arg name="arm" default="gen3"/>
  <arg name="dof" default="7" if="$(eval arg('arm') == 'gen3')"/>
  <arg name="dof" default="6" if="$(eval arm == 'gen3_lite')"/>
  <arg name="dof" default="5" unless="true"/>
  <arg name="sim" default="false"/>
  <param name="robot_description" command="$(find xacro)/xacro $(find cam_description)/urdf/display.urdf.xacro model:=arm$(arg dof)"/>
  <group if="$(arg sim)">
    <param name="robot_description" command="xacro $(find cam_description)/urdf/display.urdf.xacro model:=sim$(arg dof)"/>
  </group>
</launch>
"""
CONDITIONAL_PYTHON = """
from launch.conditions import IfCondition, UnlessCondition
from launch.substitutions import PythonExpression

def generate_launch_description():
    arm = LaunchConfiguration('arm')
    file = PathJoinSubstitution([FindPackageShare('cam_description'), 'urdf', 'display.urdf.xacro'])
    seven = Command(['xacro ', file, ' model:=arm7'])
    six = Command(['xacro ', file, ' model:=arm6'])
    return LaunchDescription([
        DeclareLaunchArgument('arm', default_value='gen3'),
        DeclareLaunchArgument('gripper', default_value='false'),
        Node(parameters=[{'robot_description': seven}],
             condition=IfCondition(PythonExpression(["'", arm, "' == 'gen3'"]))),
        Node(parameters=[{'robot_description': six}],
             condition=UnlessCondition(PythonExpression(["'", arm, "' == 'gen3'"]))),
        Node(parameters=[{'robot_description': Command(['xacro ', file, ' model:=grip'])}],
             condition=IfCondition(LaunchConfiguration('gripper'))),
        Node(parameters=[{'robot_description': Command(['xacro ', file, ' model:=unknown'])}],
             condition=IfCondition(LaunchConfiguration('not_declared'))),
    ])
"""


@pytest.mark.parametrize("launch_name, text, expected", [
    ("arm.launch", CONDITIONAL_XML, [{"model": "arm7"}]),
    ("arm.launch.py", CONDITIONAL_PYTHON, [{"model": "arm7"}, {"model": "unknown"}]),
])
def test_conditions_choose_the_arguments_a_launch_file_passes(tmp_path, launch_name, text,
                                                              expected):
    """Issue 29: `<arg if=...>` and IfCondition/UnlessCondition were ignored: the 6-DOF
    variant was checked while the launch file passes dof:=7 (the last declaration won). A
    condition that cannot be known (an undeclared argument) holds."""
    root = _package(tmp_path, launch_name, text)
    found = launch_arguments(root)["urdf/display.urdf.xacro"]
    assert [args for args, _ in found] == expected


def test_an_included_launch_file_s_conditions_see_what_its_includer_passes(tmp_path):
    root = _package(tmp_path, "arm.launch", CONDITIONAL_XML)
    (root / "launch" / "lite.launch").write_text(
        '<launch><include file="$(find cam_description)/launch/arm.launch">'
        '<arg name="arm" value="gen3_lite"/><arg name="sim" value="true"/></include></launch>')
    found = launch_arguments(root)["urdf/display.urdf.xacro"]
    assert sorted(args["model"] for args, _ in found) == ["arm6", "sim6"]


def test_an_include_under_a_false_condition_passes_nothing(tmp_path):
    root = _package(tmp_path, "arm.launch", CONDITIONAL_XML)
    (root / "launch" / "lite.launch").write_text(
        '<launch><arg name="lite" default="false"/>'
        '<include file="$(find cam_description)/launch/arm.launch" if="$(arg lite)">'
        '<arg name="arm" value="gen3_lite"/></include>'
        '<include file="$(find cam_description)/launch/arm.launch" unless="$(arg lite)">'
        '<arg name="sim" value="true"/></include></launch>')
    found = launch_arguments(root)["urdf/display.urdf.xacro"]
    assert sorted(args["model"] for args, _ in found) == ["arm7", "sim7"]
