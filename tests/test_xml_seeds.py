"""The seeds' broken XML (robots/*/published, transcribed with their defects): each breakage is
reported with the right rule at the line and column of the broken text, the repaired document
has the right structure, and `check --fix` writes it.

Expected positions are found by searching the published text for the broken line, so the tests
do not depend on line numbers that a re-transcription may shift."""

from __future__ import annotations

import json
import re

import pytest
from conftest import ROBOTS, run_urdftool
from lxml import etree

from urdftool.check import CheckOptions, check_file
from urdftool.loader import load
from urdftool.model import build_robot
from urdftool.xmlrepair import repair, secure_parser

M2WR = ROBOTS / "m2wr" / "published" / "m2wr.xacro"
OPEN_MANIPULATOR = ROBOTS / "open_manipulator" / "published" / "open_manipulator.urdf.xacro"
DUAL_ARM = ROBOTS / "dual_arm" / "published" / "test.xacro"
DD_ROBOT = ROBOTS / "dd_robot" / "published" / "diff_robot.urdf"


def where(path, pattern: str, group: int = 0) -> list[tuple[int, int]]:
    """(line, column) of every match of ``pattern`` (of its ``group``) in the file."""
    text = path.read_text(encoding="utf-8")
    places = []
    for match in re.finditer(pattern, text):
        offset = match.start(group)
        places.append((text.count("\n", 0, offset) + 1, offset - text.rfind("\n", 0, offset)))
    assert places, f"{pattern!r} not found in {path}"
    return places


def xml_findings(path):
    _, problems = repair(path.read_text(encoding="utf-8"), str(path))
    return problems


def positions(problems, rule: str) -> set[tuple[int, int]]:
    return {(f.loc.line, f.loc.column) for r, f in problems if r == rule}


def test_m2wr_all_three_breakages_exactly():
    problems = xml_findings(M2WR)
    expected = {
        ("xml.unclosed-tag", *where(M2WR, r"<material>Gazebo/Orange/material>")[0]),
        ("xml.unclosed-tag", *where(M2WR, r"<robotBaseFrame>link_chassis/robotBaseFrame>")[0]),
        ("xml.stray-text", *where(M2WR, r"\n\s*(imit) effort=", 1)[0]),
    }
    assert {(r, f.loc.line, f.loc.column) for r, f in problems} == expected
    by_rule = {(r, f.loc.line): f for r, f in problems}
    material = by_rule[("xml.unclosed-tag", where(M2WR, "Gazebo/Orange/")[0][0])]
    assert material.message == "<material> opened here is never closed"
    assert material.hint == "write </material> after 'Gazebo/Orange'"
    assert material.loc.element == "/robot/gazebo[1]/material"
    frame = next(f for r, f in problems if "robotBaseFrame" in f.message)
    assert frame.hint == "write </robotBaseFrame> after 'link_chassis'"
    limit = next(f for r, f in problems if r == "xml.stray-text")
    assert "<limit>" in limit.message and limit.hint.startswith("write <limit effort=")


def test_m2wr_json_report_matches_the_contract():
    result = run_urdftool("check", "--format", "json", "--select", "xml", M2WR)
    assert result.code == 1
    diagnostics = json.loads(result.out)["files"][0]["diagnostics"]
    line, column = where(M2WR, r"<material>Gazebo/Orange/material>")[0]
    assert {"rule": "xml.unclosed-tag", "severity": "error",
            "message": "<material> opened here is never closed", "path": str(M2WR),
            "line": line, "column": column, "element": "/robot/gazebo[1]/material",
            "hint": "write </material> after 'Gazebo/Orange'",
            # the fix: the '<' the end tag lost, inserted in the line as written
            "fix": {"applicability": "safe", "edits": [
                {"path": str(M2WR), "line": line, "column": column + 23, "end_line": line,
                 "end_column": column + 23, "text": "<"}]}} in diagnostics


def test_m2wr_after_repair_links_and_joints_are_at_the_top_level():
    # what lxml's recover=True alone does: everything after the first break is nested wrongly
    recovered = etree.parse(str(M2WR), etree.XMLParser(recover=True)).getroot()
    assert recovered.find("link") is None and recovered.find("joint") is None
    robot = build_robot(load(M2WR))
    assert [link.name for link in robot.links] == ["link_chassis", "link_right_wheel",
                                                   "link_left_wheel"]
    assert [joint.name for joint in robot.joints] == ["joint_right_wheel", "joint_left_wheel"]
    right = robot.joint("joint_right_wheel")
    assert right.limit is not None and right.limit.effort == 10000.0  # the repaired <limit>
    # later elements keep their original lines
    line = where(M2WR, r'<joint name="joint_left_wheel"')[0][0]
    assert robot.joint("joint_left_wheel").loc.line == line


def test_broken_gazebo_block_does_not_hide_a_broken_joint_limit(tmp_path):
    text = M2WR.read_text(encoding="utf-8").replace(
        '<limit effort="10000" velocity="1000"/>',
        '<limit effort="10000" velocity="1000" lower="1" upper="-1"/>')
    path = tmp_path / "m2wr.xacro"
    path.write_text(text.replace('type="continuous">\n    <origin rpy="0 0 0" xyz="-0.05 -0.15',
                                 'type="revolute">\n    <origin rpy="0 0 0" xyz="-0.05 -0.15'),
                    encoding="utf-8")
    rules = {d.rule for d in check_file(path).diagnostics}
    assert {"xml.unclosed-tag", "xml.stray-text", "joint.lower-above-upper"} <= rules


def test_open_manipulator_tags_that_lost_their_bracket():
    problems = xml_findings(OPEN_MANIPULATOR)
    missing = positions(problems, "xml.missing-open-bracket")
    assert set(where(OPEN_MANIPULATOR, r'\n\s*(link) name="link1">', 1)) <= missing
    assert set(where(OPEN_MANIPULATOR, r'\n\s*(link) name="world">', 1)) <= missing
    stray = [f for r, f in problems if r == "xml.stray-text"
             and (f.loc.line, f.loc.column) in where(OPEN_MANIPULATOR, r"\n\s*(!) velocity=", 1)]
    assert stray and stray[0].hint.startswith("write <limit velocity=")
    unclosed = positions(problems, "xml.unclosed-tag")
    assert set(where(OPEN_MANIPULATOR, r"<hardwareInterface>[\w/]*/hardwareInterface>")) <= unclosed
    assert not positions(problems, "xml.syntax")


def test_open_manipulator_repaired_structure():
    """(Its includes are not in published/, so xacro cannot expand it: look at the document.)"""
    fixed, _ = repair(OPEN_MANIPULATOR.read_text(encoding="utf-8"), str(OPEN_MANIPULATOR))
    root = etree.fromstring(fixed.encode(), secure_parser())
    links = [link.get("name") for link in root.findall("link")]
    assert {"world", "link1", "link2", "link7", "gripper_l"} <= set(links)
    joints = root.findall("joint")
    assert len(joints) >= 10 and all(j.find("limit") is not None for j in joints
                                     if j.get("type") in ("revolute", "prismatic"))
    for transmission in root.iter("transmission"):
        for joint in transmission.iter("joint"):
            assert [child.tag for child in joint] in (["hardwareInterface"], [])


def test_dual_arm_hardware_interfaces_without_end_tag():
    problems = xml_findings(DUAL_ARM)
    unclosed = positions(problems, "xml.unclosed-tag")
    broken = where(DUAL_ARM, r"<hardwareInterface>[\w/ ]*?/hardwareInterface *\n")
    assert broken and set(broken) <= unclosed
    hints = {f.hint for r, f in problems if r == "xml.unclosed-tag"}
    assert "write </hardwareInterface> after 'hardware_interface/EffortJointInterface'" in hints


def test_dd_robot_link_that_lost_lin():
    problems = xml_findings(DD_ROBOT)
    line, column = where(DD_ROBOT, r'\n\s*(k) name="base_link">', 1)[0]
    stray = [f for r, f in problems if r == "xml.stray-text" and f.loc.line == line]
    assert stray and stray[0].loc.column == column and stray[0].hint.startswith("write <link ")


@pytest.mark.parametrize("path", sorted(p for p in ROBOTS.glob("*/published/*")
                                        if p.suffix in (".urdf", ".xacro")),
                         ids=lambda p: p.parent.parent.name + "/" + p.name)
def test_published_seeds_repair_to_well_formed_xml_with_the_same_lines(path):
    text = path.read_text(encoding="utf-8")
    fixed, problems = repair(text, str(path))
    assert fixed.count("\n") == text.count("\n")
    etree.fromstring(fixed.encode(), secure_parser())  # raises if not well-formed
    assert not [r for r, _ in problems if r == "xml.syntax"]


@pytest.mark.parametrize("path", sorted(p for p in ROBOTS.glob("*/corrected/**/*")
                                        if p.suffix in (".urdf", ".xacro")),
                         ids=lambda p: str(p.relative_to(ROBOTS)))
def test_corrected_copies_have_no_xml_findings(path):
    assert xml_findings(path) == []


def test_fix_writes_the_repaired_file(tmp_path):
    out = tmp_path / "m2wr_fixed.xacro"
    result = run_urdftool("check", "--fix", "-o", out, M2WR)
    assert result.code == 0  # what remains is warnings: reported, not failing
    assert "warning" in result.out and "fixed, " in result.err
    original = M2WR.read_text(encoding="utf-8")
    fixed = out.read_text(encoding="utf-8")
    assert fixed.count("\n") == original.count("\n")
    etree.fromstring(fixed.encode(), secure_parser())
    changed = [i for i, (a, b) in enumerate(zip(original.splitlines(), fixed.splitlines()), 1)
               if a != b]
    legacy = [line for line, _ in where(M2WR, "<joint_properties")]  # -> <dynamics>
    assert len(legacy) == 2
    assert changed == sorted([where(M2WR, "Gazebo/Orange/material>")[0][0],
                              where(M2WR, "link_chassis/robotBaseFrame>")[0][0],
                              where(M2WR, r"\n\s*imit effort")[0][0] + 1, *legacy])
    assert all("<dynamics " in fixed.splitlines()[line - 1] for line in legacy)
    assert xml_findings(out) == []
    assert check_file(out, CheckOptions(select=["xml"])).diagnostics == []


def test_fix_refuses_to_overwrite_its_input(tmp_path):
    path = tmp_path / "m2wr.xacro"
    path.write_text(M2WR.read_text(encoding="utf-8"), encoding="utf-8")
    before = path.read_bytes()
    result = run_urdftool("check", "--fix", "-o", path, path)
    assert result.code == 2 and "refusing to overwrite" in result.err
    assert path.read_bytes() == before


def test_fix_of_a_non_utf8_declaration_keeps_it_and_its_bytes(tmp_path):
    """A file is read in the encoding its declaration names (6b48929: here ISO-8859-1, so the
    UTF-8 bytes of 'caf\u00e9' are two Latin-1 characters): --fix writes it back in that
    encoding, declaration kept, only the fixed quotes changed, and a parser reads the same
    name from the written file as from its declaration."""
    path = tmp_path / "r.urdf"
    original = ('<?xml version="1.0" encoding="ISO-8859-1"?>\n<robot name="r">\n'
                '<link name="caf\u00e9" a=1/>\n</robot>\n').encode("utf-8")
    path.write_bytes(original)
    out = tmp_path / "out.urdf"
    run_urdftool("check", "--fix", "-o", out, path)
    fixed = out.read_bytes()
    assert fixed == original.replace(b"a=1", b'a="1"')
    assert etree.fromstring(fixed, secure_parser())[0].get("name") == \
        "caf\u00e9".encode("utf-8").decode("latin-1")


def test_broken_xacro_include_is_reported_in_the_included_file(tmp_path):
    (tmp_path / "part.xacro").write_text(
        '<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <link name="b">\n    <visual><geometry><box size="1 1 1"/></geometry></visual>\n'
        '  /link>\n</robot>\n', encoding="utf-8")
    main = tmp_path / "main.urdf.xacro"
    main.write_text('<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                    '  <link name="a"/>\n  <xacro:include filename="$(cwd)/part.xacro"/>\n'
                    '</robot>\n'.replace("$(cwd)", str(tmp_path)), encoding="utf-8")
    report = check_file(main)
    xml = [d for d in report.diagnostics if d.rule.startswith("xml.")]
    assert [(d.rule, d.path.endswith("part.xacro"), d.line, d.column) for d in xml] == [
        ("xml.missing-open-bracket", True, 5, 3)]
    assert {link.name for link in build_robot(load(main)).links} == {"a", "b"}
