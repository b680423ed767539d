"""`urdftool dh`: the DH table against published tables (UR5, Panda), the deterministic choices
for degenerate geometry, the output formats, and bad input. The FK equality with pinocchio for
every subject is in test_kinematics_pinocchio.py."""

from __future__ import annotations

import csv
import io
import json
import math

import pytest

from tests.conftest import ROBOTS, example_robot_data_dir, pybullet_data_dir, run_urdftool
from tests.test_kinematics_pinocchio import (
    COLLINEAR,
    INTERSECTING,
    NEARLY_PARALLEL,
    PARALLEL,
    PRISMATIC_FIXED,
    _robot,
)
from urdftool.cli import load_robot
from urdftool.kinematics.chain import extract_chain
from urdftool.kinematics.dh import extract_dh, self_check

DUAL_ARM = ROBOTS / "dual_arm" / "corrected" / "test.xacro"
HALF_PI = math.pi / 2


def ur5():
    return example_robot_data_dir() / "robots" / "ur_description" / "urdf" / "ur5_robot.urdf"


def panda():
    return example_robot_data_dir() / "robots" / "panda_description" / "urdf" / "panda.urdf"


def _dh_json(*args) -> dict:
    result = run_urdftool("dh", *args, "--format", "json")
    assert result.code == 0, result.err
    return json.loads(result.out)


def _table(path, tip=None, convention="standard", base=None):
    chain = extract_chain(load_robot(str(path)), base, tip)
    return chain, extract_dh(chain, convention)


# -- against published tables ------------------------------------------------------------------


def test_ur5_standard_matches_the_published_table():
    """Universal Robots' UR5 DH (standard): d1 0.089159, a2 -0.425, a3 -0.39225, d4 0.10915,
    d5 0.09465, d6 0.0823 (ee_link), alpha pi/2 0 0 pi/2 -pi/2 0. Signs of a and alpha depend on
    the choice of x (ours: a >= 0, x = z_prev x z_next), magnitudes do not."""
    _, result = _table(ur5(), "ee_link")
    rows = result.rows
    assert [r.d for r in rows] == pytest.approx([0.089159, 0, 0, 0.10915, 0.09465, 0.0823],
                                                abs=1e-12)
    assert [abs(r.a) for r in rows] == pytest.approx([0, 0.425, 0.39225, 0, 0, 0], abs=1e-12)
    assert [abs(r.alpha) for r in rows] == pytest.approx(
        [HALF_PI, 0, 0, HALF_PI, HALF_PI, 0], abs=1e-10)


def test_panda_modified_matches_the_published_table():
    """Franka's Craig table: a(i-1) 0 0 0 0.0825 -0.0825 0 0.088, d 0.333 0 0.316 0 0.384 0 0,
    alpha(i-1) 0 -pi/2 pi/2 pi/2 -pi/2 pi/2 pi/2; the flange's d 0.107 lands in row 7 because our
    last frame sits at the tip (panda_link8)."""
    _, result = _table(panda(), "panda_link8", "modified")
    rows = result.rows
    assert [r.d for r in rows] == pytest.approx([0.333, 0, 0.316, 0, 0.384, 0, 0.107], abs=1e-12)
    assert [abs(r.a) for r in rows] == pytest.approx([0, 0, 0, 0.0825, 0.0825, 0, 0.088],
                                                     abs=1e-12)
    assert [abs(r.alpha) for r in rows] == pytest.approx([0] + [HALF_PI] * 6, abs=1e-12)


def test_dual_arm_table():
    """One 3-DoF arm of the seed: joint 1 vertical, joints 2 and 3 horizontal and parallel."""
    _, result = _table(DUAL_ARM, "link_03")
    (r1, r2, r3) = result.rows
    assert (r1.d, r1.a, r1.alpha) == pytest.approx((0.4, 0, HALF_PI))  # 0.25 + 0.15 up
    assert (r2.d, r2.a, r2.alpha) == pytest.approx((0, 0.6, 0))  # the 0.6 m upper arm
    assert (r3.d, r3.a, r3.alpha) == pytest.approx((0, 0, 0))
    assert result.base[0][3] == -0.25  # the arm stands at x = -0.25 on the base box


# -- degenerate geometry, chosen deterministically and reported ------------------------------


def test_parallel_axes_take_the_normal_through_the_previous_origin(write):
    chain, result = _table(write(PARALLEL))  # j1 | j2 | j3 (antiparallel), then j4 across
    assert result.rows[0].d == 0.0 and result.rows[1].d == 0.0 and result.rows[2].d != 0.0
    assert sum("parallel axes" in n for n in result.notes) == 2
    assert self_check(chain, result) < 1e-12
    again = extract_dh(chain, "standard")
    assert again.as_dict() == result.as_dict()  # deterministic


def test_parallel_axes_modified(write):
    chain, result = _table(write(PARALLEL), convention="modified")
    assert result.rows[0].d == 0.0 and result.rows[1].d == 0.0
    assert any("where the previous normal meets" in n for n in result.notes)
    assert self_check(chain, result) < 1e-12


def test_intersecting_axes_have_zero_a(write):
    chain, result = _table(write(INTERSECTING))
    assert result.rows[0].a == 0.0 and result.rows[1].a == 0.0
    assert sum("intersecting axes" in n for n in result.notes) == 2
    assert self_check(chain, result) < 1e-12


def test_collinear_axes(write):
    for convention in ("standard", "modified"):
        chain, result = _table(write(COLLINEAR), convention=convention)
        assert any("collinear axes" in n for n in result.notes)
        assert self_check(chain, result) < 1e-12


def test_nearly_parallel_axes_stay_exact_with_a_warning_note(write):
    chain, result = _table(write(NEARLY_PARALLEL))
    assert any("nearly parallel" in n and "rounded" in n for n in result.notes)
    assert self_check(chain, result) < 1e-9


def test_prismatic_row_puts_the_variable_in_d(write):
    chain, result = _table(write(PRISMATIC_FIXED))
    assert [r.type for r in result.rows] == ["revolute", "prismatic", "revolute"]
    assert any("fix" in n and "tool_joint" in n for n in result.notes)  # folded fixed joints
    assert self_check(chain, result) < 1e-12


def test_mimic_joint_variable(write):
    from tests.test_kinematics_pinocchio import MIMIC

    chain, result = _table(write(MIMIC), "l4")
    assert [r.variable for r in result.rows] == ["q_j1", "0.5*q_other + 0.1", "-2*q_j1", "q_j4"]
    assert self_check(chain, result) < 1e-12


# -- output formats ----------------------------------------------------------------------------


def test_json_is_exact_and_full_precision():
    table = _dh_json(str(ur5()), "--tip", "ee_link")
    assert list(table) == ["convention", "base", "tool", "rows"]
    assert len(table["base"]) == 4 and all(len(r) == 4 for r in table["base"])
    _, result = _table(ur5(), "ee_link")
    for written, row in zip(table["rows"], result.rows):
        assert (written["theta"], written["d"], written["a"], written["alpha"]) == (
            row.theta, row.d, row.a, row.alpha)  # exact: repr round trip, never rounded
    assert table["rows"][2]["a"] == 0.39225000000000004  # a sum of URDF values, not rounded
    assert table["rows"][1]["theta"] == 3.1415926535848966  # the URDF's 1.57079632679, honestly


def test_text_table(tmp_path):
    path = pybullet_data_dir() / "kuka_iiwa" / "model.urdf"
    result = run_urdftool("dh", str(path))
    assert result.code == 0, result.err
    assert "lbr_iiwa_joint_7" in result.out  # long names are not truncated
    for header in ("θ offset", "d (m)", "a (m)", "α (rad)", "variable", "θ + q1"):
        assert header in result.out
    assert "self-check" in result.out and "(ok)" in result.out
    assert "base (" in result.out and "tool (" in result.out


def test_text_modified_headers():
    result = run_urdftool("dh", str(DUAL_ARM), "--tip", "link_03", "--convention", "modified")
    assert result.code == 0, result.err
    assert "α(i-1)" in result.out and "a(i-1)" in result.out
    assert "parallel axes" in result.out


def test_csv_matches_json():
    args = (str(DUAL_ARM), "--tip", "link_eeleft", "--convention", "modified")
    table = _dh_json(*args)
    result = run_urdftool("dh", *args, "--format", "csv")
    assert result.code == 0, result.err
    rows = list(csv.DictReader(io.StringIO(result.out)))
    assert [r["joint"] for r in rows] == [r["joint"] for r in table["rows"]]
    for written, row in zip(rows, table["rows"]):
        for key in ("theta", "d", "a", "alpha"):
            assert float(written[key]) == row[key]


def test_latex():
    result = run_urdftool("dh", str(DUAL_ARM), "--tip", "link_03", "--format", "latex")
    assert result.code == 0, result.err
    assert r"\begin{tabular}" in result.out and r"\end{tabular}" in result.out
    assert r"$q_{1} + \frac{\pi}{2}$" in result.out
    assert r"T_\mathrm{base}" in result.out and r"T_\mathrm{tool}" in result.out


def test_latex_prismatic_variable_in_d(write):
    result = run_urdftool("dh", str(write(PRISMATIC_FIXED)), "--format", "latex")
    assert result.code == 0, result.err
    row2 = next(line for line in result.out.splitlines() if line.startswith("2 & "))
    assert "q_{2}" in row2.split("&")[2]  # the d column


# -- inputs: xacro with arguments, SDF, a sub-chain ---------------------------------------------


def test_xacro_with_arguments(write):
    path = write("""<?xml version="1.0"?>
<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="len" default="0.5"/>
  <link name="a"/><link name="b"/><link name="c"/>
  <joint name="j1" type="continuous"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
  </joint>
  <joint name="j2" type="continuous"><parent link="b"/><child link="c"/>
    <origin xyz="$(arg len) 0 0"/><axis xyz="0 0 1"/></joint>
</robot>""", "arm.urdf.xacro")
    assert _dh_json(str(path))["rows"][0]["a"] == 0.5
    assert _dh_json(str(path), "len:=0.75")["rows"][0]["a"] == 0.75


def test_sdf_input():
    path = pybullet_data_dir() / "kuka_iiwa" / "model.sdf"
    result = run_urdftool("dh", str(path))
    assert result.code == 0, result.err
    assert "(ok)" in result.out
    urdf = _dh_json(str(pybullet_data_dir() / "kuka_iiwa" / "model.urdf"))
    sdf = _dh_json(str(path))
    for a, b in zip(urdf["rows"], sdf["rows"]):  # the SDF writes 1.5708 for pi/2
        assert abs(a["d"] - b["d"]) < 1e-6 and abs(abs(a["alpha"]) - abs(b["alpha"])) < 1e-4


def test_sub_chain_with_base():
    table = _dh_json(str(DUAL_ARM), "--base", "link_01", "--tip", "link_03")
    assert [r["joint"] for r in table["rows"]] == ["link_01__link_02", "link_02__link_03"]


# -- bad input: exit 2, one line, no traceback ---------------------------------------------------

TREE = _robot("tree", [
    ("j1", "revolute", "base", "a", "0 0 0.1", "0 0 0", "0 0 1", (-1, 1)),
    ("j2", "revolute", "a", "b", "0 0 0.1", "0 0 0", "0 1 0", (-1, 1)),
    ("j3", "revolute", "a", "c", "0 0 0.1", "0 0 0", "1 0 0", (-1, 1)),
    ("float", "floating", "base", "drone"),
    ("j4", "revolute", "drone", "prop", "0 0 0.1", "0 0 0", "0 0 1", (-1, 1)),
    ("plane", "planar", "base", "puck", "0 0 0", "0 0 0", "0 0 1"),
    ("fixed_only", "fixed", "base", "camera"),
])


@pytest.mark.parametrize(("args", "message"), [
    ([], "has 4 leaves (b, c, prop, puck): not a serial chain; choose one with --tip"),
    (["--tip", "b", "--base", "c"], "link 'b' is not downstream of 'c'"),
    (["--tip", "nope"], "no link named 'nope' (--tip)"),
    (["--base", "nope", "--tip", "b"], "no link named 'nope' (--base)"),
    (["--tip", "prop"], "joint 'float' (floating) lies between 'base' and 'prop'"),
    (["--tip", "puck"], "joint 'plane' (planar) lies between"),
    (["--tip", "camera"], "no moving joint between 'base' and 'camera'"),
    (["--tip", "base"], "the same link 'base'"),
])
def test_bad_selection(write, args, message):
    result = run_urdftool("dh", str(write(TREE)), *args)
    assert result.code == 2
    assert message in result.err
    assert "Traceback" not in result.err and len(result.err.strip().splitlines()) <= 2
    assert result.out == ""


def test_bad_option(write):
    result = run_urdftool("dh", str(write(TREE)), "--convention", "craig")
    assert result.code == 2 and "Invalid value for '--convention'" in result.err
    assert "Traceback" not in result.err


def test_unreadable_and_missing_file(write):
    result = run_urdftool("dh", str(write("<robot name='x'><link name='a'")))
    assert result.code == 2 and "Traceback" not in result.err
    result = run_urdftool("dh", "/nonexistent/robot.urdf")
    assert result.code == 2 and "no such file" in result.err


def test_text_mimic_variable_is_not_wrapped(write):
    from tests.test_kinematics_pinocchio import MIMIC

    result = run_urdftool("dh", str(write(MIMIC)), "--tip", "l4")
    assert result.code == 0, result.err
    assert "θ + q2, q2 = 0.5*q_other + 0.1" in result.out
    assert "θ + q3, q3 = -2*q_j1" in result.out and "d + q4" in result.out
    assert "'j2' mimics 'other'" in result.out
