"""Every file of a repository has a role before its findings are judged (issue 22.1): entries,
fragments (read by an entry, named by an include line, definitions only, a `.urdf` that is
xacro, an add-on), fixtures (test folders, roots that are no robot), and what is excluded
(issue 23.3: `exclude`/`--exclude`/`--extend-exclude`, COLCON_IGNORE & co., .gitignore)."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

from tests.conftest import run_urdftool

XACRO_NS = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'
LINK = """  <link name="{name}">
    <inertial><mass value="1"/>
      <inertia ixx="0.0016666667" ixy="0" ixz="0" iyy="0.0016666667" iyz="0" izz="0.0016666667"/>
    </inertial>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
"""
JOINT = """  <joint name="{name}" type="fixed"><parent link="{parent}"/><child link="{child}"/>
  </joint>
"""
# one true defect, that every role must keep reporting: a revolute joint with swapped limits
BAD_JOINT = """  <joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>
    <axis xyz="0 0 1"/><limit lower="1" upper="-1" effort="1" velocity="1"/></joint>
"""


def robot(name: str, body: str, xacro: bool = False) -> str:
    ns = f" {XACRO_NS}" if xacro else ""
    return f'<?xml version="1.0"?>\n<robot name="{name}"{ns}>\n{body}</robot>\n'


def check(*args) -> tuple[int, dict, str]:
    result = run_urdftool("check", "--format", "json", "--jobs", "1", *args)
    assert result.code in (0, 1), result.err
    return result.code, json.loads(result.out), result.err


def findings(report: dict) -> list[tuple[str, str]]:
    return sorted((d["path"], d["rule"]) for f in report["files"] for d in f["diagnostics"]
                  if d["severity"] != "info")


def roles(err: str) -> str:
    return next(line for line in err.splitlines() if line.startswith("roles: "))


@pytest.fixture
def repo(tmp_path, monkeypatch) -> Path:
    """A description package with one entry holding one true defect."""
    root = tmp_path / "arm_description"
    (root / "urdf").mkdir(parents=True)
    (root / "package.xml").write_text("<package><name>arm_description</name></package>")
    (root / "urdf" / "arm.urdf").write_text(robot("arm", LINK.format(name="base")
                                                  + LINK.format(name="tip")
                                                  + BAD_JOINT.format(name="j", parent="base",
                                                                     child="tip")))
    monkeypatch.chdir(root)
    return root


def vendored(root: Path, folder: str) -> None:
    """Another description, with defects of its own, vendored under ``folder``."""
    other = root / folder / "gripper_description" / "urdf"
    other.mkdir(parents=True)
    (other / "gripper.urdf").write_text(robot("gripper", LINK.format(name="palm")
                                              + BAD_JOINT.format(name="g", parent="palm",
                                                                 child="nowhere")))
    (other.parent / "package.xml").write_text("<package><name>gripper_description</name>"
                                              "</package>")


@pytest.mark.parametrize("marker", ["COLCON_IGNORE", "AMENT_IGNORE", "CATKIN_IGNORE"])
def test_a_vendored_description_under_an_ignore_marker_reports_nothing(repo, marker):
    vendored(repo, "third_party")
    _, before, _ = check(".")
    assert any(path.startswith("third_party/") for path, _ in findings(before))
    (repo / "third_party" / marker).write_text("")
    code, report, err = check(".")
    assert findings(report) == [("urdf/arm.urdf", "joint.lower-above-upper")]
    assert code == 1
    assert roles(err) == ("roles: 1 entry, 0 fragments, 0 fixtures, 0 excluded, "
                          "1 under COLCON_IGNORE/AMENT_IGNORE/CATKIN_IGNORE")


def test_exclude_in_the_configuration_and_on_the_command_line(repo):
    vendored(repo, "vendor")
    vendored(repo, "extra")
    vendored(repo, ".backup")
    (repo / "urdftool.toml").write_text('exclude = ["vendor", ".*"]\n')
    _, report, err = check(".")
    assert {p.split("/")[0] for p, _ in findings(report)} == {"urdf", "extra"}
    assert "2 excluded" in roles(err) and "warning" not in err
    # --extend-exclude adds to the configuration's; an anchored pattern names one place
    _, report, _ = check(".", "--extend-exclude", "extra/gripper_description/urdf/*.urdf")
    assert {p.split("/")[0] for p, _ in findings(report)} == {"urdf"}
    # --exclude replaces it
    _, report, _ = check(".", "--exclude", "extra")
    assert {p.split("/")[0] for p, _ in findings(report)} == {"urdf", "vendor", ".backup"}


def test_an_exclude_pattern_that_matches_nothing_is_a_warning(repo):
    (repo / "urdftool.toml").write_text('extend-exclude = ["vendr"]\n')
    code, report, err = check(".", "--extend-exclude", "*.sdf")
    assert "warning: urdftool.toml: extend-exclude pattern 'vendr' matches nothing" in err
    assert "warning: --extend-exclude pattern '*.sdf' matches nothing" in err
    assert findings(report) == [("urdf/arm.urdf", "joint.lower-above-upper")] and code == 1


@pytest.mark.parametrize("value", ['"vendor"', '[1]', '[""]'])
def test_a_malformed_exclude_exits_2(repo, value):
    (repo / "urdftool.toml").write_text(f"exclude = {value}\n")
    result = run_urdftool("check", ".")
    assert result.code == 2 and "exclude must be a list of glob patterns" in result.err


def test_git_ignored_files_are_skipped_unless_told(repo):
    if shutil.which("git") is None:
        pytest.fail("git is needed for this test")
    subprocess.run(["git", "init", "-q", str(repo)], check=True)
    vendored(repo, "generated")
    (repo / ".gitignore").write_text("generated/\n")
    _, report, err = check(".")
    assert findings(report) == [("urdf/arm.urdf", "joint.lower-above-upper")]
    assert "1 excluded (1 by .gitignore)" in roles(err)
    _, report, _ = check(".", "--no-respect-gitignore")
    assert any(p.startswith("generated/") for p, _ in findings(report))
    # a negation in a deeper .gitignore wins, as in git
    (repo / "generated" / ".gitignore").write_text("!*\n")
    (repo / ".gitignore").write_text("generated/*.urdf\n")
    _, report, _ = check(".")
    assert any(p.startswith("generated/") for p, _ in findings(report))


def test_test_fixtures_and_files_that_are_no_robot_are_not_checked(repo):
    fixtures = repo / "test" / "data"
    fixtures.mkdir(parents=True)
    (fixtures / "broken.urdf").write_text(robot("broken", LINK.format(name="a")
                                                + LINK.format(name="b")
                                                + BAD_JOINT.format(name="j", parent="a",
                                                                   child="b")))
    (repo / "urdf" / "case.xacro").write_text(
        f'<test {XACRO_NS}><xacro:property name="x" value="1"/><a b="${{x}}"/></test>\n')
    # an old-style macro file (root <root>) is a fragment, not a fixture
    (repo / "urdf" / "macros.xacro").write_text(
        f'<root {XACRO_NS}><xacro:macro name="m"><link name="l"/></xacro:macro></root>\n')
    code, report, err = check(".")
    assert findings(report) == [("urdf/arm.urdf", "joint.lower-above-upper")] and code == 1
    assert roles(err) == "roles: 1 entry, 1 fragment, 2 fixtures, 0 excluded"
    # a fixture given by name is checked
    _, report, _ = check("test/data/broken.urdf")
    assert findings(report) == [("test/data/broken.urdf", "joint.lower-above-upper")]


def test_a_urdf_file_that_is_a_xacro_fragment(repo):
    # materials and ${} only, no link, included by nothing (turtlebot3's common_properties)
    (repo / "urdf" / "common_properties.urdf").write_text(
        f'<?xml version="1.0"?>\n<robot name="props" {XACRO_NS}>\n'
        '  <material name="orange"><color rgba="${255/255} ${108/255} ${10/255} 1.0"/>'
        '</material>\n</robot>\n')
    code, report, err = check(".")
    assert findings(report) == [("urdf/arm.urdf", "joint.lower-above-upper")] and code == 1
    assert "1 fragment" in roles(err)


ARM = robot("arm", LINK.format(name="base") + LINK.format(name="flange")
            + JOINT.format(name="j", parent="base", child="flange")
            + '  <xacro:include filename="tool.xacro"/>\n'
            + '  <xacro:tool parent="flange"/>\n', xacro=True)
TOOL = robot("tool", '  <xacro:macro name="tool" params="parent">\n'
             + LINK.format(name="tool") + JOINT.format(name="t", parent="${parent}",
                                                       child="tool")
             + '    <xacro:include filename="tool_gazebo.xacro"/>\n'
             + '  </xacro:macro>\n', xacro=True)
# uses the macro's parameter: it only expands inside the macro that includes it
TOOL_GAZEBO = robot("tool_gazebo", '  <gazebo reference="${parent}"><mu1>0.5</mu1></gazebo>\n',
                    xacro=True)
# an end effector for a robot defined elsewhere: its links hang from the robot's
ADD_ON = robot("hand", LINK.format(name="palm") + LINK.format(name="finger")
               + JOINT.format(name="mount", parent="left_hand", child="palm")
               + BAD_JOINT.format(name="f", parent="palm", child="finger"))


def test_fragments_and_add_ons_are_judged_for_what_they_hold(repo):
    urdf = repo / "urdf"
    (urdf / "arm.urdf").unlink()
    (urdf / "arm.urdf.xacro").write_text(ARM)
    (urdf / "tool.xacro").write_text(TOOL)
    (urdf / "tool_gazebo.xacro").write_text(TOOL_GAZEBO)
    (urdf / "hand.urdf").write_text(ADD_ON)
    code, report, err = check(".")
    # the add-on keeps its own defect, without 'parent link left_hand is not defined'
    assert findings(report) == [("urdf/hand.urdf", "joint.lower-above-upper")] and code == 1
    assert roles(err) == "roles: 1 entry, 3 fragments, 0 fixtures, 0 excluded"
    # a typo'd parent in a robot is still an error: it has a root link of its own
    (urdf / "hand.urdf").write_text(ADD_ON.replace('"left_hand"', '"bse"').replace(
        '<joint name="mount"', LINK.format(name="base") + '<joint name="mount"'))
    _, report, _ = check(".")
    assert ("urdf/hand.urdf", "structure.missing-link") in findings(report)


def test_a_fragment_no_entry_reaches_is_not_blamed_for_its_includers_names(repo):
    urdf = repo / "urdf"
    (urdf / "tool.xacro").write_text(TOOL)  # a macro file nothing calls
    (urdf / "tool_gazebo.xacro").write_text(TOOL_GAZEBO)
    # calls a macro of its includer (an extension chosen by an environment variable)
    (urdf / "extras.urdf").write_text(robot("s", '  <xacro:sensor_mount prefix="front"/>\n'
                                            + JOINT.format(name="m", parent="front_mount",
                                                           child="front_sensor"), xacro=True))
    _, report, err = check(".")
    assert findings(report) == [("urdf/arm.urdf", "joint.lower-above-upper")]
    assert "1 entry, 3 fragments" in roles(err)


# -- launch arguments (issue 22.2) -------------------------------------------------------------

MODEL = robot("$(arg model)", '  <xacro:arg name="prefix" default=""/>\n'
              + LINK.format(name="$(arg prefix)base") + LINK.format(name="$(arg prefix)tip")
              + BAD_JOINT.format(name="$(arg prefix){joint}", parent="$(arg prefix)base",
                                 child="$(arg prefix)tip"), xacro=True)


def _launch_package(tmp_path: Path, launch_name: str, launch_text: str) -> Path:
    root = tmp_path / "bot_description"
    (root / "urdf").mkdir(parents=True)
    (root / "launch").mkdir()
    (root / "package.xml").write_text("<package><name>bot_description</name></package>")
    for model in ("small", "large"):
        (root / "urdf" / f"robot_{model}.urdf.xacro").write_text(
            MODEL.replace("{joint}", f"{model}_joint"))
    (root / "launch" / launch_name).write_text(launch_text)
    return root


XML_LAUNCH = """<launch>
  <arg name="model"/>
  <arg name="prefix" default='""'/>
  <param name="robot_description" command="$(find xacro)/xacro
      $(find bot_description)/urdf/robot_$(arg model).urdf.xacro model:=$(arg model)
      prefix:=$(arg prefix)"/>
</launch>
"""
XML2_LAUNCH = """<launch>
  <arg name="model"/>
  <arg name="prefix" default='""'/>
  <node pkg="robot_state_publisher" exec="robot_state_publisher">
    <param name="robot_description" value="$(command 'xacro $(find-pkg-share bot_description)/urdf/robot_$(var model).urdf.xacro model:=$(var model) prefix:=$(var prefix)')"/>
  </node>
</launch>
"""
PYTHON_LAUNCH = """
from launch.substitutions import Command, LaunchConfiguration, PathJoinSubstitution
from launch_ros.substitutions import FindPackageShare

MODEL = "model"

def generate_launch_description():
    model = LaunchConfiguration(MODEL)
    prefix = LaunchConfiguration("prefix")
    file = PathJoinSubstitution([FindPackageShare("bot_description"), "urdf",
                                 ["robot_", model, ".urdf.xacro"]])
    args = [DeclareLaunchArgument(MODEL), DeclareLaunchArgument("prefix", default_value="''")]
    description = Command(["xacro ", file, " model:=", model, " prefix:=", prefix])
    return LaunchDescription(args + [Node(parameters=[{"robot_description": description}])])
"""


@pytest.mark.parametrize("launch_name, text", [("bot.launch", XML_LAUNCH),
                                               ("bot.launch.xml", XML2_LAUNCH),
                                               ("bot.launch.py", PYTHON_LAUNCH)])
def test_a_substitution_in_the_file_name_makes_each_match_an_entry(tmp_path, monkeypatch,
                                                                    launch_name, text):
    root = _launch_package(tmp_path, launch_name, text)
    monkeypatch.chdir(root)
    code, report, err = check(".")
    # (the launch file's own report, issue 31: it passes xacro output without a string type)
    files = {f["path"]: f for f in report["files"] if not f["path"].endswith(".py")}
    assert {p: f["args"] for p, f in files.items()} == {
        "urdf/robot_large.urdf.xacro": {"model": "large", "prefix": ""},
        "urdf/robot_small.urdf.xacro": {"model": "small", "prefix": ""}}
    # the quoted empty default is empty: link names carry no quotes
    messages = [d["message"] for f in files.values() for d in f["diagnostics"]]
    assert sorted(m.split(":")[0] for m in messages) == ["joint 'large_joint'",
                                                        "joint 'small_joint'"], messages
    assert not any('"' in m.split(":")[0] or "'''" in m for m in messages)
    assert code == 1 and roles(err).startswith("roles: 2 entries, 0 fragments")


def test_an_entry_without_its_arguments_is_one_warning_naming_them(tmp_path, monkeypatch):
    root = _launch_package(tmp_path, "bot.launch", "<launch/>")
    monkeypatch.chdir(root)
    code, report, _ = check(".")
    found = [d for f in report["files"] for d in f["diagnostics"]]
    assert [(d["rule"], d["severity"]) for d in found] == [("xacro.error", "warning")] * 2
    for d in found:
        assert "needs the argument 'model'" in d["message"]
        assert "entries = [{ file = \"urdf/robot_" in d["hint"] and 'model = "..."' in d["hint"]
    assert code == 0
    # given in the configuration, each is checked
    (root / "urdftool.toml").write_text(
        'entries = [{ file = "urdf/robot_small.urdf.xacro", args = { model = "s" } }]\n')
    _, report, _ = check(".")
    rules = {f["path"]: [d["rule"] for d in f["diagnostics"]] for f in report["files"]}
    assert rules["urdf/robot_small.urdf.xacro"] == ["joint.lower-above-upper"]


def test_a_transmission_fragment_using_its_includers_property(repo):
    # read past the undefined ${prefix}: still a fragment (was: no-links, no-name,
    # transmission.unknown-joint and the xacro error, 4 errors)
    (repo / "urdf" / "arm.transmission.xacro").write_text(robot("t", """
  <transmission name="${prefix}trans1">
    <type>transmission_interface/SimpleTransmission</type>
    <joint name="${prefix}joint1"><hardwareInterface>EffortJointInterface</hardwareInterface>
    </joint>
    <actuator name="${prefix}motor1"><mechanicalReduction>1</mechanicalReduction></actuator>
  </transmission>
""", xacro=True).replace(' name="t"', ""))
    code, report, err = check(".")
    assert findings(report) == [("urdf/arm.urdf", "joint.lower-above-upper")] and code == 1
    assert "1 entry, 1 fragment" in roles(err)


def test_a_file_only_a_pattern_names_keeps_its_robot_rules(repo):
    # a wrapper includes one robot chosen by an argument: the others stay entries
    urdf = repo / "urdf"
    (urdf / "arm.urdf").unlink()
    (urdf / "all.urdf.xacro").write_text(robot("all", '  <xacro:arg name="which" default="a"/>\n'
                                               '  <xacro:include filename="$(arg which).xacro"/>\n',
                                               xacro=True))
    (urdf / "a.xacro").write_text(robot("a", LINK.format(name="a0"), xacro=True))
    (urdf / "b.xacro").write_text(robot("b", LINK.format(name="b0") + LINK.format(name="b1")
                                        + JOINT.format(name="j", parent="b0", child="bl"),
                                        xacro=True))
    _, report, err = check(".")
    assert ("urdf/b.xacro", "structure.missing-link") in findings(report)
    assert "2 entries, 1 fragment" in roles(err)


def test_a_placeholder_named_by_an_arguments_default_is_a_fragment_of_a_failed_includer(
        tmp_path):
    """husky's ``<xacro:arg name="urdf_extras" default="$(optenv HUSKY_URDF_EXTRAS
    empty.urdf)"/>`` + ``<xacro:include filename="$(arg urdf_extras)"/>``: the include names
    empty.urdf (the argument's default), so when the includer stops on a missing package,
    the empty placeholder is not judged as a robot (no false no-links/no-name errors)."""
    package = tmp_path / "r_description"
    (package / "urdf").mkdir(parents=True)
    (package / "package.xml").write_text("<package><name>r_description</name></package>")
    (package / "urdf" / "empty.urdf").write_text("<robot>\n  <!-- placeholder -->\n</robot>\n")
    (package / "urdf" / "robot.urdf.xacro").write_text(
        '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">\n'
        '  <xacro:arg name="urdf_extras" default="$(optenv R_URDF_EXTRAS empty.urdf)"/>\n'
        '  <link name="base_link"/>\n'
        '  <xacro:include filename="$(find some_missing_pkg)/urdf/x.urdf.xacro"/>\n'
        '  <xacro:include filename="$(arg urdf_extras)"/>\n</robot>\n')
    code, report, err = check(str(package))
    assert code == 1
    found = [(Path(d["path"]).name, d["rule"]) for f in report["files"]
             for d in f["diagnostics"] if d["severity"] == "error"]
    assert found == [("robot.urdf.xacro", "xacro.error")], found
    assert "1 entry, 1 fragment" in err


TEMPLATE = f"""<?xml version="1.0"?>
<robot name="tpl" {XACRO_NS}>
  <xacro:arg name="arm_file" default=""/>
  <xacro:arg name="arm_length" default=""/>
  <xacro:arg name="name" default="bot"/>
  <xacro:property name="length" value="$(arg arm_length)"/>
  <xacro:include filename="$(arg arm_file)"/>
  <link name="$(arg name)_base"/>
  <link name="tip"><inertial><mass value="${{float(length) * 2}}"/>
    <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="fixed"><parent link="$(arg name)_base"/><child link="tip"/></joint>
</robot>
"""


def test_an_argument_template_is_one_warning_naming_its_empty_arguments(tmp_path, monkeypatch):
    """Issue 29: a xacro whose arguments default to "" (another package's launch file passes
    them) failed with xacro errors from the empty defaults (an include of '', float(''))."""
    root = tmp_path / "tpl_description"
    (root / "urdf").mkdir(parents=True)
    (root / "package.xml").write_text("<package><name>tpl_description</name></package>")
    (root / "urdf" / "template.urdf.xacro").write_text(TEMPLATE)
    (root / "urdf" / "arm.xacro").write_text(robot("arm", BAD_JOINT.format(
        name="arm_joint", parent="bot_base", child="tip"), xacro=True))
    monkeypatch.chdir(root)
    code, report, _ = check(".")
    found = {f["path"]: [(d["rule"], d["severity"], d["message"], d["hint"])
                         for d in f["diagnostics"]] for f in report["files"]}
    ((rule, severity, message, hint),) = found["urdf/template.urdf.xacro"]
    assert (rule, severity) == ("xacro.error", "warning")
    assert "argument template" in message and "'arm_file', 'arm_length'" in message
    assert 'args = { arm_file = "...", arm_length = "..." }' in hint
    # the file it would include is judged alone for what it holds (its own true defect)
    assert [r for r, *_ in found["urdf/arm.xacro"]] == ["joint.lower-above-upper"]
    # given its arguments, it is the robot it is: the included arm's defect is reported
    (root / "urdftool.toml").write_text(
        'entries = [{ file = "urdf/template.urdf.xacro", '
        'args = { arm_file = "arm.xacro", arm_length = "0.5" } }]\n')
    code, report, _ = check(".")
    rules = sorted(d["rule"] for f in report["files"] for d in f["diagnostics"])
    assert "joint.lower-above-upper" in rules and "xacro.error" not in rules and code == 1


def test_an_error_unrelated_to_the_empty_arguments_stays_an_error(tmp_path, monkeypatch):
    root = tmp_path / "tpl_description"
    (root / "urdf").mkdir(parents=True)
    (root / "package.xml").write_text("<package><name>tpl_description</name></package>")
    (root / "urdf" / "template.urdf.xacro").write_text(TEMPLATE.replace(
        '<xacro:include filename="$(arg arm_file)"/>', '<link name="${undefined_thing}"/>')
        .replace("${float(length) * 2}", "1"))
    monkeypatch.chdir(root)
    code, report, _ = check(".")
    found = [(d["rule"], d["severity"]) for f in report["files"] for d in f["diagnostics"]]
    assert ("xacro.error", "error") in found and code == 1
    assert not any("argument template" in d["message"]
                   for f in report["files"] for d in f["diagnostics"])


ROS2_CONTROL_MACRO = f"""<?xml version="1.0"?>
<robot {XACRO_NS}>
  <xacro:macro name="bot_ros2_control" params="name use_mock">
    <ros2_control name="${{name}}" type="system">
      <hardware><plugin>mock_components/GenericSystem</plugin></hardware>
      <xacro:if value="${{use_mock}}">
        <xacro:include filename="bot_joints.ros2_control.xacro"/>
      </xacro:if>
    </ros2_control>
  </xacro:macro>
</robot>
"""
ROS2_CONTROL_JOINTS = f"""<?xml version="1.0"?>
<robot {XACRO_NS}>
  <joint name="j1">
    <command_interface name="position"/>
    <state_interface name="position"><param name="initial_value">0.0</param></state_interface>
  </joint>
</robot>
"""


@pytest.mark.parametrize("also_at_top", [False, True])
def test_a_fragment_included_inside_ros2_control_is_not_judged_as_urdf_joints(
        tmp_path, monkeypatch, also_at_top):
    """Issue 29: a fragment only ever included inside <ros2_control> (its joints carry
    command/state interfaces) was checked alone as URDF joints: no type, parent, child."""
    root = tmp_path / "bot_description"
    (root / "urdf").mkdir(parents=True)
    (root / "package.xml").write_text("<package><name>bot_description</name></package>")
    (root / "urdf" / "bot.urdf.xacro").write_text(robot("bot", (
        '  <xacro:arg name="use_mock" default="false"/>\n'
        '  <xacro:include filename="bot.ros2_control.xacro"/>\n'
        + LINK.format(name="base") + LINK.format(name="tip")
        + JOINT.format(name="j1", parent="base", child="tip")
        + '  <xacro:bot_ros2_control name="bot" use_mock="$(arg use_mock)"/>\n'
        + ('  <xacro:include filename="bot_joints.ros2_control.xacro"/>\n' if also_at_top
           else "")), xacro=True))
    (root / "urdf" / "bot.ros2_control.xacro").write_text(ROS2_CONTROL_MACRO)
    joints = root / "urdf" / "bot_joints.ros2_control.xacro"
    joints.write_text(ROS2_CONTROL_JOINTS.replace("</joint>", "</joint>\n  <bad a='1' a='2'/>"))
    monkeypatch.chdir(root)
    code, report, _ = check(".")
    rules = sorted(d["rule"] for f in report["files"] for d in f["diagnostics"]
                   if f["path"] == "urdf/bot_joints.ros2_control.xacro")
    if also_at_top:  # read by the entry as robot elements: the joint is a URDF joint there
        assert "schema.missing-attribute" in str(report) and code == 1
        return
    # what the file is wrong about as written is still said
    assert rules and all(r.startswith("xml.") for r in rules), rules
    joints.write_text(ROS2_CONTROL_JOINTS)
    code, report, _ = check(".")
    assert [d for f in report["files"] for d in f["diagnostics"]] == [] and code == 0
