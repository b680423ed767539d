"""`sim` accepts what `check` accepts (issue 23.7): a massless, shapeless leaf link on a fixed
joint (UR's flange and tool0) is merged into its parent as Gazebo, Drake and MuJoCo lump fixed
links, instead of getting PyBullet's default 1 kg; a link with a shape and no <inertial> still
does (that is a real missing mass)."""

from __future__ import annotations

import json

import pytest

from tests.conftest import run_urdftool

pytest.importorskip("pybullet")

ARM = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base_link">
    <inertial><mass value="4"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><geometry><cylinder radius="0.1" length="0.1"/></geometry></collision>
  </link>
  <link name="upper">
    <inertial><origin xyz="0 0 0.2"/><mass value="2"/><inertia ixx="0.03" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.002"/></inertial>
    <collision><origin xyz="0 0 0.2"/><geometry><cylinder radius="0.04" length="0.3"/></geometry></collision>
  </link>
  <link name="flange"/>
  <link name="tool0"/>
  <joint name="shoulder" type="revolute"><parent link="base_link"/><child link="upper"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="50" velocity="2"/></joint>
  <joint name="flange_joint" type="fixed"><parent link="upper"/><child link="flange"/><origin xyz="0 0 0.4"/></joint>
  <joint name="tool0_joint" type="fixed"><parent link="flange"/><child link="tool0"/><origin xyz="0 0 0.01"/></joint>
</robot>
"""


def _model(path) -> tuple[int, dict]:
    result = run_urdftool("sim", "--format", "json", "--jobs", "1", path)
    return result.code, json.loads(result.out)["models"][0]


def test_massless_frame_leaves_are_merged(tmp_path):
    path = tmp_path / "arm.urdf"
    path.write_text(ARM)
    assert run_urdftool("check", "--strict", path).code == 0  # check accepts it
    code, model = _model(path)
    assert code == 0 and model["verdict"] == "pass", model["checks"]
    mass = next(c for c in model["checks"] if c["check"] == "sim.mass")
    assert mass["values"]["pybullet_kg"] == 4.0 + 2.0  # the declared masses, nothing added
    assert any("'tool0', 'flange'" in note for note in model["notes"])


def test_a_shaped_link_without_inertial_is_not_merged(tmp_path):
    path = tmp_path / "arm.urdf"
    path.write_text(ARM.replace('<link name="tool0"/>', '<link name="tool0"><collision><geometry>'
                                '<box size="0.05 0.05 0.05"/></geometry></collision></link>'))
    code, model = _model(path)
    mass = next(c for c in model["checks"] if c["check"] == "sim.mass")
    assert code == 1 and mass["status"] == "fail"
    # flange is not a leaf (tool0 hangs from it): both keep PyBullet's 1 kg, and say so
    assert sorted(mass["values"]["default_mass_links"]) == ["flange", "tool0"]
