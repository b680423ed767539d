"""`sim` accepts what `check` accepts (issue 23.7): a massless, shapeless link on a fixed joint
(UR's flange and tool0, UR's ROS 1 base_link root, Franka's link8 between the arm and the hand) is
lumped as Gazebo, Drake and MuJoCo lump fixed links, instead of getting PyBullet's default 1 kg,
and nothing moves (pinocchio's forward kinematics of the copy PyBullet loads equals the file's);
a link with a shape and no <inertial> still gets 1 kg (a real missing mass); a description
without any <inertial> is not simulated, as check says (inertia.kinematics-only)."""

from __future__ import annotations

import json

import pybullet  # noqa: F401 - the test extra has it: missing, this fails
import pytest

from tests.conftest import run_urdftool

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
    assert any("lumped" in note and "'tool0'" in note and "'flange'" in note
               for note in model["notes"])


def test_a_shaped_link_without_inertial_is_not_merged(tmp_path):
    path = tmp_path / "arm.urdf"
    path.write_text(ARM.replace('<link name="tool0"/>', '<link name="tool0"><collision><geometry>'
                                '<box size="0.05 0.05 0.05"/></geometry></collision></link>'))
    code, model = _model(path)
    mass = next(c for c in model["checks"] if c["check"] == "sim.mass")
    assert code == 1 and mass["status"] == "fail"
    # flange (a frame between upper and tool0) is lumped; tool0 has a shape and no mass
    assert mass["values"]["default_mass_links"] == ["tool0"]


# UR's ROS 1 layout (a bare root frame fixed to the body that carries the mass) and Franka's
# (a bare link8 between the last moving link and the hand, turned about z), rotations included
FRAMES = """<?xml version="1.0"?>
<robot name="frames">
  <link name="base_link"/>
  <link name="base_body">
    <inertial><mass value="4"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><geometry><cylinder radius="0.1" length="0.1"/></geometry></collision>
  </link>
  <joint name="base_fixed" type="fixed"><parent link="base_link"/><child link="base_body"/>
    <origin xyz="0.01 0 0.05" rpy="0 0 3.141592653589793"/></joint>
  <link name="link7">
    <inertial><origin xyz="0 0 0.1"/><mass value="1.5"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.002"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><cylinder radius="0.04" length="0.2"/></geometry></collision>
  </link>
  <joint name="joint7" type="revolute"><parent link="base_body"/><child link="link7"/>
    <origin xyz="0 0 0.05" rpy="0.3 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="50" velocity="2"/></joint>
  <link name="link8"/>
  <joint name="joint8" type="fixed"><parent link="link7"/><child link="link8"/><origin xyz="0 0 0.207" rpy="0 0 -0.7853981633974483"/></joint>
  <link name="hand">
    <inertial><origin xyz="0 0 0.03"/><mass value="0.7"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>
    <collision><origin xyz="0 0 0.03"/><geometry><box size="0.05 0.2 0.06"/></geometry></collision>
  </link>
  <joint name="hand_joint" type="fixed"><parent link="link8"/><child link="hand"/><origin xyz="0.01 0 0.002" rpy="0 0.2 0"/></joint>
  <link name="finger">
    <inertial><origin xyz="0 0 0.02"/><mass value="0.02"/><inertia ixx="2.8e-6" ixy="0" ixz="0" iyy="2.8e-6" iyz="0" izz="3.3e-7"/></inertial>
    <collision><origin xyz="0 0 0.02"/><geometry><box size="0.01 0.01 0.04"/></geometry></collision>
  </link>
  <joint name="finger_joint" type="prismatic"><parent link="hand"/><child link="finger"/>
    <origin xyz="0 0.05 0.06"/><axis xyz="0 1 0"/><limit lower="0" upper="0.04" effort="20" velocity="0.2"/></joint>
  <link name="tcp"/>
  <joint name="tcp_joint" type="fixed"><parent link="hand"/><child link="tcp"/><origin xyz="0 0 0.1034" rpy="0 0 0.5"/></joint>
</robot>
"""


def _placements(urdf_text: str, frames, q_of) -> dict:
    """World placements (4x4) of links by pinocchio, at the joint values q_of(model) gives."""
    import numpy as np
    import pinocchio as pin

    model = pin.buildModelFromXML(urdf_text)
    data = model.createData()
    q = q_of(model)
    pin.framesForwardKinematics(model, data, q)
    return {name: np.array(data.oMf[model.getFrameId(name)].homogeneous) for name in frames}


def test_root_and_inner_frames_are_lumped_and_nothing_moves(tmp_path):
    import numpy as np

    from urdftool.sim import SimOptions
    from urdftool.sim.prepare import prepare

    path = tmp_path / "frames.urdf"
    path.write_text(FRAMES)
    assert run_urdftool("check", path).code == 0
    code, model = _model(path)
    assert code == 0 and model["verdict"] == "pass", model["checks"]
    mass = next(c for c in model["checks"] if c["check"] == "sim.mass")
    assert mass["values"]["pybullet_kg"] == pytest.approx(4 + 1.5 + 0.7 + 0.02, abs=1e-12)
    prepared = prepare(str(path), SimOptions())
    try:
        lumped = prepared.urdf_text
        assert prepared.root_link == "base_body"
        for gone in ("base_link", "link8", "tcp"):
            assert f'name="{gone}"' not in lumped
    finally:
        prepared.cleanup()
    # the lumped copy's root is base_body: compare placements relative to it, at random joints
    rng = np.random.default_rng(7)
    for _ in range(5):
        values = {"joint7": rng.uniform(-3, 3), "finger_joint": rng.uniform(0, 0.04)}

        def q_of(model, values=values):
            q = np.zeros(model.nq)
            for name, value in values.items():
                q[model.idx_qs[model.getJointId(name)]] = value
            return q

        before = _placements(FRAMES, ("base_body", "link7", "hand", "finger"), q_of)
        after = _placements(lumped, ("base_body", "link7", "hand", "finger"), q_of)
        for name in ("link7", "hand", "finger"):
            relative_before = np.linalg.inv(before["base_body"]) @ before[name]
            relative_after = np.linalg.inv(after["base_body"]) @ after[name]
            assert np.allclose(relative_before, relative_after, atol=1e-12), name


def test_a_kinematics_only_description_is_not_simulated(tmp_path):
    path = tmp_path / "bare.urdf"
    path.write_text(ARM.replace(ARM[ARM.index("<inertial>"):ARM.index("</inertial>") + 11], "")
                    .replace('<inertial><origin xyz="0 0 0.2"/><mass value="2"/><inertia ixx="0.03" '
                             'ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.002"/></inertial>', ""))
    assert "<inertial>" not in path.read_text()
    check = run_urdftool("check", "--format", "json", path)
    assert check.code == 0
    assert [d["rule"] for f in json.loads(check.out)["files"] for d in f["diagnostics"]
            if d["severity"] != "info"] == ["inertia.kinematics-only"]
    code, model = _model(path)
    assert code == 0 and model["verdict"] == "skip"
    assert all(c["status"] == "skip" and "kinematics only" in c["message"]
               for c in model["checks"])
