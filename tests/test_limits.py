"""`urdftool limits`: the table's numbers (checked by independent arithmetic), its verdicts,
JSON at full precision, and the exit codes."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from conftest import run_urdftool

from urdftool.limits import limits_data
from urdftool.loader import load
from urdftool.model import build_robot
from urdftool.ranges import chain_joints, composed, image, mimic_chain, mimic_image

ROOT = Path(__file__).resolve().parent.parent
OPEN_MANIPULATOR = ROOT / "robots" / "open_manipulator"

ROBOT = """<robot name="gripper">
  <link name="base"/><link name="a"/><link name="b"/><link name="c"/><link name="d"/>
  <joint name="arm" type="revolute"><parent link="base"/><child link="a"/>
    <limit lower="-0.1234567890123" upper="2.2" effort="3.1" velocity="2.8"/></joint>
  <joint name="finger" type="prismatic"><parent link="base"/><child link="b"/>
    <limit lower="-0.033" upper="0" effort="0.1" velocity="0.1"/>
    <mimic joint="arm" multiplier="-0.01" offset="0.0001"/></joint>
  <joint name="wheel" type="continuous"><parent link="base"/><child link="c"/>
    <limit effort="5" velocity="10"/></joint>
  <joint name="bolt" type="fixed"><parent link="base"/><child link="d"/></joint>
</robot>
"""


def _robot(write, text=ROBOT):
    return build_robot(load(write(text)))


def test_image_and_composition_arithmetic():
    assert image((0.0, 1.0), -2.0, 0.5) == (-1.5, 0.5)
    assert image((-1.0, 2.0), 3.0, -1.0) == (-4.0, 5.0)


def test_chain_and_composed(write):
    text = ROBOT.replace('<link name="d"/>', '<link name="d"/><link name="e"/>').replace(
        "</robot>", '  <joint name="tip" type="prismatic"><parent link="base"/>'
                    '<child link="e"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
                    '<mimic joint="finger" multiplier="2" offset="0.5"/></joint>\n</robot>')
    robot = _robot(write, text)
    chain = mimic_chain(robot, robot.joint("tip"))
    assert [j.name for j in chain_joints(robot, chain)] == ["tip", "finger", "arm"]
    assert chain.end == "root" and chain.length == 3
    multiplier, offset = composed(chain)
    # tip = 2*(-0.01*arm + 0.0001) + 0.5
    assert multiplier == pytest.approx(-0.02) and offset == pytest.approx(0.5002)


def test_table_rows_and_numbers(write):
    data = limits_data(_robot(write))
    rows = {row["name"]: row for row in data["joints"]}
    assert list(rows) == ["arm", "finger", "wheel"]  # moving joints only, document order
    arm = rows["arm"]
    assert arm["lower"] == -0.1234567890123  # full precision
    assert arm["range"] == 2.2 - (-0.1234567890123)
    assert arm["range_degrees"] == pytest.approx(math.degrees(2.3234567890123))
    assert arm["unit"] == "rad" and rows["finger"]["unit"] == "m"
    finger = rows["finger"]
    lo, hi = sorted((-0.01 * -0.1234567890123 + 0.0001, -0.01 * 2.2 + 0.0001))
    assert finger["mimic"]["image"] == pytest.approx([lo, hi], rel=1e-15)
    assert finger["verdict"] == "error"
    assert {f["rule"] for f in finger["findings"]} >= {"mimic.out-of-range"}
    assert rows["wheel"]["range"] is None and rows["wheel"]["verdict"] == "ok"
    assert data["summary"]["errors"] == 1


def test_mimic_image_of_leader_without_range(write):
    robot = _robot(write, ROBOT.replace('mimic joint="arm"', 'mimic joint="wheel"'))
    assert mimic_image(robot, robot.joint("finger")) is None


def test_cli_text_shows_the_violation_in_the_verdict_column(write):
    result = run_urdftool("limits", write(ROBOT))
    assert result.code == 1, result.err
    row = next(line for line in result.out.splitlines() if "finger" in line and "│" in line)
    assert "error mimic.out-of-range" in row
    assert "arm" in row and "-0.01" in row
    assert "driven to" in result.out  # the full message under the table


def test_cli_json_full_precision_and_exit_codes(write, tmp_path):
    clean = ROBOT.replace('offset="0.0001"', 'offset="-0.011"')
    result = run_urdftool("limits", "--format", "json", write(clean))
    assert result.code == 0, result.err
    data = json.loads(result.out)
    finger = next(row for row in data["joints"] if row["name"] == "finger")
    expected = sorted((-0.01 * -0.1234567890123 - 0.011, -0.01 * 2.2 - 0.011))
    assert finger["mimic"]["image"] == expected  # exactly the floats, not rounded
    assert finger["verdict"] == "info"  # mimic.mixed-kinds: m per rad
    assert run_urdftool("limits", tmp_path / "missing.urdf").code == 2
    empty = write("<robot name='r'/>", "empty.urdf")
    result = run_urdftool("limits", empty)
    assert result.code == 2 and "Traceback" not in result.err
    assert run_urdftool("limits", write(ROBOT), write(ROBOT, "second.urdf")).code == 2


def test_cli_bad_values_show_dashes_not_tracebacks(write):
    text = ROBOT.replace('lower="-0.033" upper="0"', 'lower="abc" upper=""').replace(
        'multiplier="-0.01"', 'multiplier="x"')
    for fmt in ("text", "json"):
        result = run_urdftool("limits", "--format", fmt, write(text))
        assert result.code in (0, 1) and "Traceback" not in result.err and result.out


def test_open_manipulator_gripper_violation():
    path = OPEN_MANIPULATOR / "published" / "open_manipulator.urdf.xacro"
    package = f"open_manipulator_support_description={OPEN_MANIPULATOR / 'corrected'}"
    result = run_urdftool("limits", "-P", package, path)
    assert result.code == 1, result.err
    row = next(line for line in result.out.splitlines() if line.startswith("│ joint8 "))
    assert "id_7" in row and "-0.0110133334" in row and "error mimic.out-of-range" in row
    assert "[0.0039867, 0.020403]" in row
    data = json.loads(run_urdftool("limits", "-P", package, "--format", "json", path).out)
    joint8 = next(row for row in data["joints"] if row["name"] == "joint8")
    lo, hi = joint8["mimic"]["image"]
    assert lo == pytest.approx(-0.01 * -1.5 - 0.0110133334)
    assert hi == pytest.approx(-0.01 * -math.pi - 0.0110133334)
    assert (joint8["lower"], joint8["upper"]) == (-0.033, 0.0)
    corrected = run_urdftool("limits", OPEN_MANIPULATOR / "corrected" /
                             "open_manipulator.urdf.xacro")
    assert corrected.code == 0, corrected.out


def test_limits_lists_infos_as_check_does():
    """Issue 29: `limits` printed infos with their fix lines where `check` hides them unless
    --show-info: the same findings are listed in both, infos only when asked (and counted)."""
    xacro = next((OPEN_MANIPULATOR / "published").glob("*.xacro"))
    check = run_urdftool("check", "--select", "mimic", str(xacro))
    check_infos = run_urdftool("check", "--select", "mimic", "--show-info", str(xacro))

    def listed(text, severity):
        return sorted(line.split(f" {severity} ")[1].split(":")[0] for line in text.splitlines()
                      if f": {severity} " in line and line.startswith(str(xacro)))

    plain = run_urdftool("limits", str(xacro))
    infos = run_urdftool("limits", "--show-info", str(xacro))
    assert plain.code == infos.code == 1
    assert listed(plain.out, "info") == listed(check.out, "info") == []
    assert listed(infos.out, "info") == listed(check_infos.out, "info") != []
    assert listed(plain.out, "error") == listed(check.out, "error") != []
    assert "info (listed with --show-info)" in plain.out
    assert "listed with --show-info" not in infos.out
