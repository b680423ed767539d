"""`urdftool inertia`: table, corrected blocks, --link, --density, JSON precision, exit codes;
and `check` on a primitive robot never imports numpy or trimesh."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import run_urdftool

ROBOTS = Path(__file__).resolve().parent.parent / "robots"
M2WR = ROBOTS / "m2wr" / "published" / "m2wr.xacro"

WHEEL = ('<robot name="car"><link name="wheel"><inertial><mass value="0.1"/><inertia ixx="1" '
         'ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial><collision><geometry>'
         '<cylinder radius="0.025" length="0.02"/></geometry></collision></link></robot>')
CUBE = ('<robot name="c"><link name="cube"><visual><geometry><box size="0.1 0.1 0.1"/>'
        '</geometry></visual></link></robot>')


def test_table_and_corrected_block_for_the_flagged_link():
    result = run_urdftool("inertia", M2WR)
    assert result.code == 0, result.err  # a warning, no error
    out = result.out
    for name in ("link_chassis", "link_left_wheel", "link_right_wheel"):
        assert name in out
    assert "inertia.com-outside-geometry" in out
    assert "Corrected <inertial> blocks" in out
    # only the chassis is flagged, so only it gets a block
    assert out.count("<mass value=") == 1
    assert '<mass value="5"/>' in out


def test_error_exits_1_and_the_block_fits_the_geometry(write):
    result = run_urdftool("inertia", write(WHEEL))
    assert result.code == 1
    assert "error inertia.exceeds-geometry" in result.out
    m, r, h = 0.1, 0.025, 0.02
    side, axial = m * (3 * r * r + h * h) / 12, m * r * r / 2
    assert f'ixx="{side:.6g}"' in result.out and f'izz="{axial:.6g}"' in result.out


def test_link_option_and_unknown_link(write):
    result = run_urdftool("inertia", M2WR, "--link", "link_left_wheel")
    assert result.code == 0
    assert "link_chassis" not in result.out and "link_left_wheel" in result.out
    assert "<mass value=" in result.out  # the block is always shown for --link
    missing = run_urdftool("inertia", M2WR, "--link", "nope")
    assert missing.code == 2 and "no link 'nope'" in missing.err


def test_density_gives_mass_from_volume(write):
    result = run_urdftool("inertia", write(CUBE), "--link", "cube", "--density", "1000",
                          "--format", "json")
    assert result.code == 0, result.err
    block = json.loads(result.out)["links"][0]["corrected"]
    mass = 1000 * 0.1 ** 3
    assert block["mass"] == pytest.approx(mass, rel=1e-15)
    assert block["ixx"] == pytest.approx(mass * (0.01 + 0.01) / 12, rel=1e-15)
    assert block["from"] == "visual"
    bad = run_urdftool("inertia", write(CUBE), "--density", "-3")
    assert bad.code == 2 and "--density" in bad.err


def test_json_keeps_full_precision():
    result = run_urdftool("inertia", M2WR, "--format", "json")
    data = json.loads(result.out)
    wheel = next(row for row in data["links"] if row["link"] == "link_left_wheel")
    assert wheel["declared"]["ixx"] == 0.000526666666667  # exactly as written
    m, r = 0.2, 0.1
    assert wheel["geometry"]["principal"][2] == pytest.approx(m * r * r / 2, rel=1e-14)
    assert wheel["findings"] == []
    chassis = next(row for row in data["links"] if row["link"] == "link_chassis")
    assert [f["rule"] for f in chassis["findings"]] == ["inertia.com-outside-geometry"]
    assert chassis["findings"][0]["line"] == 57
    assert data["summary"] == {"links": 3, "errors": 0, "warnings": 1, "infos": 0}


def test_xacro_arguments_and_file_count(write):
    path = write('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                 '<xacro:arg name="m" default="1"/><link name="a"><inertial>'
                 '<mass value="$(arg m)"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" '
                 'izz="0.1"/></inertial></link></robot>', "r.urdf.xacro")
    data = json.loads(run_urdftool("inertia", path, "m:=2.5", "--format", "json").out)
    assert data["links"][0]["mass"] == 2.5
    assert run_urdftool("inertia", path, path).code == 2


def test_check_on_a_primitive_robot_imports_neither_numpy_nor_trimesh(write):
    path = write('<robot name="r"><link name="a"><inertial><mass value="1"/><inertia ixx="0.1" '
                 'ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial><visual><geometry>'
                 '<box size="1 1 1"/></geometry></visual><collision><geometry>'
                 '<cylinder radius="0.5" length="1"/></geometry></collision></link>'
                 '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
                 '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
                 '</joint><link name="b"><inertial><mass value="1"/><inertia ixx="1" ixy="0" '
                 'ixz="0" iyy="1" iyz="0" izz="1"/></inertial><visual><geometry>'
                 '<sphere radius="0.1"/></geometry></visual></link></robot>')
    code = ("import sys\nfrom urdftool.cli import main\ntry:\n    main(['check', sys.argv[1]])\n"
            "except SystemExit as exc:\n    code = exc.code\n"
            "print(code, sorted(m for m in ('numpy', 'trimesh', 'scipy') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True,
                         text=True, check=True).stdout.strip().splitlines()[-1]
    assert out == "1 []", out  # exit 1: link b's 1 kg·m² exceeds its 0.1 m sphere
