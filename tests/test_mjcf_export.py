"""`urdftool convert ROBOT --to mjcf` (issue 32): every export verified by the TEST's own
forward kinematics and inertia check (MuJoCo's ``mj_kinematics`` on the exported file against
pinocchio, or the test's own transforms, on the URDF; link masses and tensors against the URDF
text read here), whatever urdftool's own verification said."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pytest

from tests.conftest import example_robot_data_dir, pybullet_data_dir, run_urdftool
from tests.test_compare import ARM, body_inertia, mujoco_bodies, own_fk, own_inertial


def export(tmp_path, source, *extra):
    out = tmp_path / "out" / "robot.xml"
    out.parent.mkdir(exist_ok=True)
    result = run_urdftool("convert", str(source), "--to", "mjcf", "-o", str(out), *extra)
    return result, out


def check_links(urdf_text, mjcf_path, q, tolerance=1e-9):
    """Every link's pose (MuJoCo's kinematics of the export vs the test's own FK of the URDF)
    and every link's mass, COM and inertia tensor (MuJoCo's compiled body vs the URDF text)."""
    ours = own_fk(urdf_text, q)
    theirs, model = mujoco_bodies(mjcf_path, q)
    root = ET.fromstring(urdf_text)
    for link in root.findall("link"):
        name = link.get("name")
        assert np.allclose(ours[name][:3, 3], theirs[name][0], atol=tolerance), name
        assert np.allclose(ours[name][:3, :3], theirs[name][1], atol=tolerance), name
        inertial = link.find("inertial")
        m, c, tensor = body_inertia(model, name)
        if inertial is None:
            assert m == 0
            continue
        mass, com, inertia = own_inertial(urdf_text, name)
        assert m == pytest.approx(mass, rel=1e-12) and np.allclose(c, com, atol=1e-12)
        assert np.linalg.norm(tensor - inertia) <= 1e-9 * np.linalg.norm(inertia) + 1e-15, name
    return model


def test_export_is_verified_and_independently_right(tmp_path):
    source = tmp_path / "arm.urdf"
    source.write_text(ARM)
    result, out = export(tmp_path, source)
    assert result.code == 0, result.err
    assert "verified:" in result.err and "not verified" not in result.err
    rng = np.random.default_rng(3)
    for _ in range(4):
        q = {"j1": rng.uniform(-2, 2), "j2": rng.uniform(-1, 1.5), "j3": rng.uniform(-3, 3)}
        q["j4"] = 0.01 * q["j3"] + 0.001
        model = check_links(ARM, out, q)
    # limits, dynamics and the mimic, as MuJoCo compiled them
    j = {name: model.joint(name).id for name in ("j1", "j2", "j3", "j4")}
    assert model.jnt_limited[j["j1"]] and tuple(model.jnt_range[j["j1"]]) == (-2, 2)
    assert model.jnt_limited[j["j4"]] and tuple(model.jnt_range[j["j4"]]) == (0, 0.04)
    assert not model.jnt_limited[j["j3"]]  # continuous
    assert tuple(model.jnt_actfrcrange[j["j2"]]) == (-20, 20) and model.jnt_actfrclimited[j["j2"]]
    assert model.dof_damping[model.jnt_dofadr[j["j1"]]] == 0.5
    assert model.dof_frictionloss[model.jnt_dofadr[j["j1"]]] == 0.1
    assert model.neq == 1 and model.eq_obj1id[0] == j["j4"] and model.eq_obj2id[0] == j["j3"]
    assert list(model.eq_data[0][:5]) == [0.001, 0.01, 0, 0, 0]
    # every link is a body: the fixed "tool" too, at full precision (no 6-digit rounding)
    assert {model.body(b).name for b in range(model.nbody)} == \
        {"world"} | {link.get("name") for link in ET.fromstring(ARM).findall("link")}
    assert "0.9689124217106447" in out.read_text()  # tool's quaternion, written with repr


def test_export_json_and_stdout(tmp_path):
    source = tmp_path / "arm.urdf"
    source.write_text(ARM)
    result = run_urdftool("convert", str(source), "--to", "mjcf", "--format", "json")
    assert result.code == 0, result.err
    data = json.loads(result.out)
    assert data["verified"] and data["lost"] == [] and data["comparison"]["verdict"] == "equivalent"
    assert mujoco.MjModel.from_xml_string(data["mjcf"]).nbody == 7
    assert any("velocity" in note for note in data["notes"])  # MuJoCo has no joint velocity limit
    result = run_urdftool("convert", str(source), "--to", "mjcf")
    assert result.code == 0 and result.out.startswith("<mujoco")
    assert mujoco.MjModel.from_xml_string(result.out).njnt == 4


def test_what_mujoco_cannot_hold_is_listed_and_not_verified(tmp_path):
    """A point mass on a moving link (no rotational inertia: MuJoCo refuses the body) and an
    empty joint range: written so that MuJoCo loads the file, listed as lost, exit 1."""
    text = ARM.replace('<inertia ixx="0.005" ixy="0" ixz="0" iyy="0.005" iyz="0" izz="0.005"/>',
                       '<inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/>').replace(
        'lower="-2" upper="2"', 'lower="0" upper="0"')
    source = tmp_path / "arm.urdf"
    source.write_text(text)
    result, out = export(tmp_path, source)
    assert result.code == 1
    assert "lost: link 'link3' moves with no rotational inertia" in result.err
    assert "lost: range of joint 'j1'" in result.err and "not verified" in result.err
    mujoco.MjModel.from_xml_path(str(out))  # loads


REAL = [
    ("pybullet", "kuka_iiwa/model.urdf"),
    ("pybullet", "r2d2.urdf"),
    ("pybullet", "franka_panda/panda.urdf"),
    ("example-robot-data", "solo_description/robots/solo12.urdf"),
]


@pytest.mark.parametrize("where, name", REAL)
def test_real_robots_export_verified_against_pinocchio(tmp_path, where, name):
    import pinocchio
    base = pybullet_data_dir() if where == "pybullet" else example_robot_data_dir() / "robots"
    source = base / name
    packages = () if where == "pybullet" else ("-P", f"example-robot-data={example_robot_data_dir()}")
    result, out = export(tmp_path, source, *packages)
    assert result.code == 0, result.err
    assert "verified:" in result.err
    model = pinocchio.buildModelFromUrdf(str(source))
    data = model.createData()
    pinocchio.seed(11)  # deterministic random configurations
    mj = mujoco.MjModel.from_xml_path(str(out))
    mjdata = mujoco.MjData(mj)
    urdf_text = source.read_text()
    for _ in range(3):
        q = pinocchio.randomConfiguration(model, np.maximum(model.lowerPositionLimit, -3),
                                          np.minimum(model.upperPositionLimit, 3))
        pinocchio.framesForwardKinematics(model, data, q)
        mjdata.qpos[:] = 0
        for joint_id in range(1, model.njoints):
            joint = model.names[joint_id]
            if model.nqs[joint_id] == 1:
                mjdata.qpos[mj.jnt_qposadr[mj.joint(joint).id]] = q[model.idx_qs[joint_id]]
            else:  # continuous joints: (cos, sin) in pinocchio
                c, s = q[model.idx_qs[joint_id]], q[model.idx_qs[joint_id] + 1]
                mjdata.qpos[mj.jnt_qposadr[mj.joint(joint).id]] = np.arctan2(s, c)
        mujoco.mj_kinematics(mj, mjdata)
        checked = 0
        for frame in model.frames:
            if frame.type != pinocchio.FrameType.BODY:
                continue
            b = mj.body(frame.name).id
            placement = data.oMf[model.getFrameId(frame.name)]
            assert np.allclose(placement.translation, mjdata.xpos[b], atol=1e-9), frame.name
            assert np.allclose(placement.rotation, mjdata.xmat[b].reshape(3, 3), atol=1e-9)
            checked += 1
        assert checked == len(ET.fromstring(urdf_text).findall("link"))
    for link in ET.fromstring(urdf_text).findall("link"):  # masses and tensors, link by link
        if link.find("inertial") is None:
            continue
        mass, com, inertia = own_inertial(urdf_text, link.get("name"))
        m, c, tensor = body_inertia(mj, link.get("name"))
        if mass == 0:  # no mass: no centre of mass either
            assert m == 0
            continue
        assert m == pytest.approx(mass, rel=1e-12) and np.allclose(c, com, atol=1e-12)
        assert np.linalg.norm(tensor - inertia) <= 1e-9 * np.linalg.norm(inertia) + 1e-15


def test_mujoco_warnings_are_notes_not_a_log_file(tmp_path):
    """MuJoCo's default warning handler appends to MUJOCO_LOG.TXT in the current directory.
    (A process of its own: MuJoCo caches decoded meshes, and warns only when it decodes.)"""
    import subprocess
    import sys

    out = tmp_path / "panda.xml"
    result = subprocess.run([sys.executable, "-m", "urdftool", "convert",
                             str(pybullet_data_dir() / "franka_panda" / "panda.urdf"), "--to",
                             "mjcf", "-o", str(out)], check=False, cwd=tmp_path,
                            capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert "note: MuJoCo warned: obj_decoder" in result.stderr
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


def test_collada_meshes_are_converted_beside_the_output(tmp_path):
    """A COLLADA mesh (MuJoCo reads none) becomes an STL beside OUT, written by urdftool."""
    import trimesh
    box = trimesh.creation.box((0.1, 0.2, 0.3))
    (tmp_path / "part.dae").write_bytes(box.export(file_type="dae"))
    text = ARM.replace('<collision><geometry><sphere radius="0.05"/></geometry></collision>',
                       '<collision><geometry><mesh filename="part.dae"/></geometry></collision>')
    source = tmp_path / "arm.urdf"
    source.write_text(text)
    result, out = export(tmp_path, source)
    assert result.code == 0, result.err
    converted = list((out.parent / "robot_meshes").glob("*.stl"))
    assert len(converted) == 1
    model = mujoco.MjModel.from_xml_path(str(out))
    geom = next(g for g in range(model.ngeom) if model.geom_bodyid[g] == model.body("link2").id)
    assert model.geom_type[geom] == mujoco.mjtGeom.mjGEOM_MESH
    vertices = model.mesh_vert[model.mesh_vertadr[0]:model.mesh_vertadr[0] + model.mesh_vertnum[0]]
    extent = vertices.max(axis=0) - vertices.min(axis=0)  # about MuJoCo's centred mesh frame
    assert sorted(extent) == pytest.approx([0.1, 0.2, 0.3])


def test_output_refused_over_the_input(tmp_path):
    source = tmp_path / "arm.urdf"
    source.write_text(ARM)
    result = run_urdftool("convert", str(source), "--to", "mjcf", "-o", str(source))
    assert result.code == 2 and source.read_text() == ARM
