"""The SDF cases PyBullet cannot judge (it ignores joint poses and use_parent_model_frame, and has
no relative_to, nested models, includes, split joints or loops), checked against closed-form
transforms written here from the numbers in each file: the converted URDF is loaded by
pinocchio and every SDF link frame, world COM and inertia is compared at random configurations.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from conftest import run_urdftool
from scipy.spatial.transform import Rotation

DATA = Path(__file__).parent / "data" / "sdf"
TOL = 1e-9  # closed form against pinocchio: both in double precision
HALF_PI = np.pi / 2


def T(x=0.0, y=0.0, z=0.0, roll=0.0, pitch=0.0, yaw=0.0) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = Rotation.from_euler("xyz", [roll, pitch, yaw]).as_matrix()  # Rz Ry Rx
    out[:3, 3] = (x, y, z)
    return out


def R(axis, angle) -> np.ndarray:
    axis = np.asarray(axis, dtype=float)
    out = np.eye(4)
    out[:3, :3] = Rotation.from_rotvec(axis / np.linalg.norm(axis) * angle).as_matrix()
    return out


def shift(axis, distance) -> np.ndarray:
    out = np.eye(4)
    out[:3, 3] = np.asarray(axis, dtype=float) * distance
    return out


class Urdf:
    def __init__(self, path: Path):
        self.model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
        self.data = self.model.createData()

    def set(self, values: dict[str, float]) -> None:
        q = pin.neutral(self.model)
        for name, value in values.items():
            joint = self.model.joints[self.model.getJointId(name)]
            assert self.model.existJointName(name), name
            if joint.nq == 1:
                q[joint.idx_q] = value
            else:
                q[joint.idx_q:joint.idx_q + 2] = np.cos(value), np.sin(value)
        pin.forwardKinematics(self.model, self.data, q)
        pin.updateFramePlacements(self.model, self.data)

    def frame(self, name: str) -> np.ndarray:
        assert self.model.existFrame(name), f"no frame {name!r}"
        return self.data.oMf[self.model.getFrameId(name)].homogeneous


def convert(tmp_path: Path, name: str, *extra: str) -> tuple[Path, str]:
    out = tmp_path / (Path(name).stem + ".urdf")
    result = run_urdftool("convert", DATA / name, "-o", out, *extra)
    assert result.code == 0, result.err
    return out, result.err


def check_pose(got: np.ndarray, expected: np.ndarray) -> None:
    assert np.abs(got - expected).max() < TOL, f"\n{got}\n!=\n{expected}"


def sweep(n: int = 5, seed: int = 3, size: int = 2):
    rng = np.random.default_rng(seed)
    yield np.zeros(size)
    for _ in range(n):
        yield rng.uniform(-1.0, 1.0, size)


def world_inertial(link_pose, inertial_pose, mass, tensor):
    pose = link_pose @ inertial_pose
    return mass, pose[:3, 3], pose[:3, :3] @ tensor @ pose[:3, :3].T


def pin_body(urdf: Urdf, joint: str):
    index = urdf.model.getJointId(joint)
    inertia = urdf.model.inertias[index]
    placement = urdf.data.oMi[index]
    rot = placement.rotation
    return inertia.mass, placement.act(inertia.lever), rot @ inertia.inertia @ rot.T


def test_joint_pose_relative_to_child(tmp_path):
    """joint_pose_child.sdf: arm at (0.5 0 0.2 | 0 0.3 0.2); the joint 0.2 0.1 0 | 0 0 0.5 in the
    arm's frame; axis y of the joint frame."""
    urdf_path, _ = convert(tmp_path, "joint_pose_child.sdf")
    urdf = Urdf(urdf_path)
    model_arm = T(0.5, 0, 0.2, 0, 0.3, 0.2)
    arm_joint = T(0.2, 0.1, 0, 0, 0, 0.5)
    model_joint = model_arm @ arm_joint
    tensor = np.array([[0.003, 0.0001, -0.0002], [0.0001, 0.002, 0.0003],
                       [-0.0002, 0.0003, 0.0025]])
    for q in sweep(size=1):
        q = float(q[0])
        urdf.set({"j": q})
        arm = model_joint @ R([0, 1, 0], q) @ np.linalg.inv(arm_joint)
        # the URDF frame of 'arm' is the joint frame; the SDF arm frame sits at arm_joint^-1 in it
        check_pose(urdf.frame("arm") @ np.linalg.inv(arm_joint), arm)
        mass, com, inertia = world_inertial(arm, T(0.1, 0.05, 0, 0.4, 0.2, 0.1), 1.5, tensor)
        got_mass, got_com, got_inertia = pin_body(urdf, "j")
        assert abs(got_mass - mass) < TOL
        assert np.abs(got_com - com).max() < TOL
        assert np.abs(got_inertia - inertia).max() < TOL


def test_relative_to_frames_and_expressed_in(tmp_path):
    urdf_path, _ = convert(tmp_path, "relative_to.sdf")
    urdf = Urdf(urdf_path)
    base = T(0, 0, 0.1)
    mount = base @ T(0.3, 0, 0.2, 0, 0, HALF_PI)
    arm0 = mount @ T(0.1, 0, 0)
    joint0 = mount  # <pose relative_to="mount"/>
    axis_in_joint = np.linalg.inv(joint0[:3, :3]) @ base[:3, :3] @ [1, 0, 0]  # expressed_in base
    for q in sweep(size=1):
        q = float(q[0])
        urdf.set({"j": q})
        joint = joint0 @ R(axis_in_joint, q)
        arm = joint @ np.linalg.inv(joint0) @ arm0
        tool = arm @ T(0.2, 0, 0, 0, HALF_PI, 0)
        tip = tool @ T(0, 0, 0.05)
        # the URDF root is the base link's frame: compare everything relative to it
        to_base = np.linalg.inv(base)
        check_pose(urdf.frame("base"), np.eye(4))
        check_pose(urdf.frame("arm") @ np.linalg.inv(joint0) @ arm0, to_base @ arm)
        check_pose(urdf.frame("tool"), to_base @ tool)
        check_pose(urdf.frame("tip"), to_base @ tip)
        check_pose(urdf.frame("mount"), to_base @ mount)


def test_nested_model_scoped_names(tmp_path):
    urdf_path, _ = convert(tmp_path, "nested.sdf")
    text = urdf_path.read_text()
    assert "link 'arm_module::upper' -> 'arm_module__upper'" in text
    urdf = Urdf(urdf_path)
    module = T(1, 0, 0, 0, 0, HALF_PI)
    upper0, lower0 = module @ T(0, 0, 0.5), module @ T(0.2, 0, 1.0)
    for q in sweep():
        urdf.set({"mount": q[0], "arm_module__elbow": q[1]})
        # mount: axis x of the model frame, about the upper link's origin
        mount_axis = np.linalg.inv(upper0[:3, :3]) @ [1, 0, 0]
        upper = upper0 @ R(mount_axis, q[0])
        lower = upper @ np.linalg.inv(upper0) @ lower0 @ R([0, 1, 0], q[1])
        check_pose(urdf.frame("arm_module__upper"), upper)
        check_pose(urdf.frame("arm_module__lower"), lower)


@pytest.mark.parametrize("name", ["use_parent_model_frame.sdf", "axis_1_4.sdf"])
def test_axis_in_model_frame(name, tmp_path):
    """j: axis x of the model frame (use_parent_model_frame in 1.6; always in 1.4).
    k: axis z in the joint frame in 1.6, in the model frame in 1.4."""
    urdf_path, _ = convert(tmp_path, name)
    urdf = Urdf(urdf_path)
    arm0, hand0 = T(0, 0, 0.5, 0, 0, HALF_PI), T(0.4, 0, 0.5, 0.3, 0, HALF_PI)
    for q in sweep():
        urdf.set({"j": q[0], "k": q[1]})
        arm = arm0 @ R(np.linalg.inv(arm0[:3, :3]) @ [1, 0, 0], q[0])
        k_axis = [0, 0, 1] if "1_4" not in name else np.linalg.inv(hand0[:3, :3]) @ [0, 0, 1]
        hand = arm @ np.linalg.inv(arm0) @ hand0 @ R(k_axis, q[1])
        check_pose(urdf.frame("arm"), arm)
        check_pose(urdf.frame("hand"), hand)


def test_loop_cut_and_refused(tmp_path):
    urdf_path, err = convert(tmp_path, "loop.sdf")
    assert ": warning sdf.kinematic-loop: joint 'close' closes the kinematic loop" in err
    urdf = Urdf(urdf_path)
    assert not urdf.model.existJointName("close")
    for q in sweep(size=3):
        urdf.set({"drive": q[0], "crank_coupler": q[1], "ground_rocker": q[2]})
        crank = T(0, 0, 0.1) @ R([0, 1, 0], q[0])
        coupler = crank @ T(0, 0, 0.2) @ R([0, 1, 0], q[1])
        rocker = T(0.4, 0, 0.1) @ R([0, 1, 0], q[2])
        check_pose(urdf.frame("crank"), crank)
        check_pose(urdf.frame("coupler"), coupler)
        check_pose(urdf.frame("rocker"), rocker)
    refused = run_urdftool("convert", DATA / "loop.sdf", "--no-cut", "-o", tmp_path / "no.urdf")
    assert refused.code == 1
    assert "closes the kinematic loop" in refused.err and not (tmp_path / "no.urdf").exists()
    assert "Traceback" not in refused.err


def test_ball_universal_screw(tmp_path):
    urdf_path, err = convert(tmp_path, "special_joints.sdf")
    for kind in ("ball", "universal", "screw"):
        assert f"{kind} joint" in err
    urdf = Urdf(urdf_path)
    ball_child0, ball_joint = T(0.5, 0, 0, 0, 0, 0.3), T(-0.1, 0, 0)
    cross0, cross_joint = T(0, 0.5, 0, 0.2, 0, 0), T(0, -0.05, 0)
    nut0, nut_joint = T(0, 0, 0.5), T(0, 0, -0.1)
    for q in sweep(size=6):
        urdf.set({"shoulder": q[0], "shoulder__y": q[1], "shoulder__z": q[2],
                  "cardan": q[3], "cardan__axis2": q[4], "lead_screw": q[5] * 50,
                  "lead_screw__translation": q[5] * 50 * 0.01 / (2 * np.pi)})
        j = ball_child0 @ ball_joint
        ball = j @ R([1, 0, 0], q[0]) @ R([0, 1, 0], q[1]) @ R([0, 0, 1], q[2])
        check_pose(urdf.frame("ball_child") @ np.linalg.inv(ball_joint), ball @ np.linalg.inv(ball_joint))
        j = cross0 @ cross_joint
        cross = j @ R([1, 0, 0], q[3]) @ R([0, 0, 1], q[4]) @ np.linalg.inv(cross_joint)
        check_pose(urdf.frame("cross_child") @ np.linalg.inv(cross_joint), cross)
        j = nut0 @ nut_joint
        turn = q[5] * 50
        nut = j @ R([0, 0, 1], turn) @ shift([0, 0, 1], turn * 0.01 / (2 * np.pi))
        check_pose(urdf.frame("nut") @ np.linalg.inv(nut_joint), nut @ np.linalg.inv(nut_joint))
    text = urdf_path.read_text()
    assert 'mimic joint="lead_screw" multiplier="0.0015915494309189536"' in text


def test_gearbox_becomes_mimic(tmp_path):
    urdf_path, err = convert(tmp_path, "gearbox.sdf")
    assert "gearbox joint 'mesh'" in err
    text = urdf_path.read_text()
    assert '<mimic joint="hinge1" multiplier="-2.0" offset="0.0"/>' in text
    assert 'name="mesh"' not in text


def test_include_with_model_path_and_env(tmp_path, monkeypatch):
    out, _err = convert(tmp_path, "with_include.sdf", "--model-path", str(DATA / "models"))
    urdf = Urdf(out)
    for q in sweep():
        urdf.set({"left_axle": q[0], "right_axle": q[1]})
        tyre = T(0, 0, 0, HALF_PI, 0, 0)
        check_pose(urdf.frame("left__tyre"), T(0, 0.2, 0) @ tyre @ R([0, 0, 1], q[0]))
        check_pose(urdf.frame("right__tyre"),
                   T(0, -0.2, 0, 0, 0, np.pi) @ tyre @ R([0, 0, 1], q[1]))
    text = out.read_text()
    mesh = (DATA / "models" / "wheel" / "meshes" / "tyre.stl").resolve()
    import os

    assert f'filename="{os.path.relpath(mesh, tmp_path)}"' in text
    packaged = run_urdftool("convert", DATA / "with_include.sdf", "--model-path",
                            DATA / "models", "--package-uri", "package://cart_description/models")
    assert 'filename="package://cart_description/models/wheel/meshes/tyre.stl"' in packaged.out
    # the same through the environment; the data folder is not searched without it
    monkeypatch.setenv("GZ_SIM_RESOURCE_PATH", str(DATA / "models"))
    assert run_urdftool("convert", DATA / "with_include.sdf").code == 0
    monkeypatch.delenv("GZ_SIM_RESOURCE_PATH")
    missing = tmp_path / "elsewhere.sdf"
    missing.write_text((DATA / "with_include.sdf").read_text())
    result = run_urdftool("check", missing, "--format", "json")
    assert "sdf.include" in result.out


def test_pose_formats_and_mimic(tmp_path):
    urdf_path, err = convert(tmp_path, "pose_formats.sdf")
    urdf = Urdf(urdf_path)
    a0 = T(0.1, 0.2, 0.3, np.radians(30), 0, np.radians(90))
    b0 = np.eye(4)
    b0[:3, :3] = Rotation.from_quat([0, 0, 0.7071067811865476, 0.7071067811865476]).as_matrix()
    b0[:3, 3] = (0, 0.5, 0)
    for q in sweep():
        urdf.set({"ja": q[0], "jb": 2 * (q[0] - 0.05) + 0.1})
        check_pose(urdf.frame("a"), a0 @ R([1, 0, 0], q[0]))
        check_pose(urdf.frame("b"), b0 @ R([0, 0, 1], 2 * (q[0] - 0.05) + 0.1))
    text = urdf_path.read_text()
    # SDF: follower = 2 (leader - 0.05) + 0.1; URDF: follower = 2 leader + 0.0
    assert '<mimic joint="ja" multiplier="2.0" offset="0.0"/>' in text
    assert "sdf.default-inertial" in err  # link b: SDF's mass 1 written out


def test_placement_frame_merge_include_world_joint(tmp_path):
    urdf_path, _ = convert(tmp_path, "composition.sdf", "--model-path", str(DATA / "models"))
    urdf = Urdf(urdf_path)
    world_base = T(0, 0, 1)  # the model's pose, kept because 'anchor' fixes it to the world
    grip_in_tool = T(0, 0, 0.2) @ T(0, 0, 0.1)
    tool = T(1, 0, 0) @ np.linalg.inv(grip_in_tool)  # the pose places the grip frame
    for q in sweep(size=1):
        urdf.set({"axle": float(q[0])})
        world = urdf.frame("world")
        check_pose(np.linalg.inv(world) @ urdf.frame("base"), world_base)
        check_pose(np.linalg.inv(world) @ urdf.frame("tool__body"),
                   world_base @ tool @ T(0, 0, 0.2))
        check_pose(np.linalg.inv(world) @ urdf.frame("tool__grip"), world_base @ T(1, 0, 0))
        # merged include: 'tyre' keeps its own name, placed by the include's pose
        check_pose(np.linalg.inv(world) @ urdf.frame("tyre"),
                   world_base @ T(0, 1, 0) @ T(0, 0, 0, HALF_PI, 0, 0) @ R([0, 0, 1], q[0]))
        # a frame attached to __model__ hangs on the canonical link
        check_pose(np.linalg.inv(world) @ urdf.frame("marker"), world_base @ T(0.5, 0.5, 0))


def _door_models(tmp_path: Path) -> Path:
    door = tmp_path / "models" / "door"
    door.mkdir(parents=True)
    (door / "model.config").write_text('<?xml version="1.0"?>\n<model><name>door</name>'
                                       '<sdf version="1.6">model.sdf</sdf></model>\n')
    (door / "model.sdf").write_text(
        '<?xml version="1.0"?>\n<sdf version="1.6">\n  <model name="door">\n'
        '    <link name="panel">\n      <inertial><mass>2</mass><inertia><ixx>0.7</ixx>'
        '<iyy>0.8</iyy><izz>0.2</izz></inertia></inertial>\n'
        '      <collision name="c"><geometry><box><size>1 0.05 2</size></box></geometry>'
        '</collision>\n    </link>\n  </model>\n</sdf>\n')
    return tmp_path / "models"


def test_a_model_included_twice_without_name_is_reported_at_the_includes(tmp_path):
    """Issue 29: the same model included twice without <name> was reported inside the included
    model (at a line that is fine, "also at line 3" on line 3), once for the model and once
    for each of its links. One finding, at the includer's second <include>, with the name to
    write; in a world, one per later <include>."""
    import json

    models = _door_models(tmp_path)
    include = "    <include>\n      <uri>model://door</uri>\n      <pose>{} 0 0 0 0 0</pose>\n" \
              "    </include>\n"
    house = tmp_path / "house.sdf"
    house.write_text('<?xml version="1.0"?>\n<sdf version="1.6">\n  <model name="house">\n'
                     "    <static>true</static>\n" + include.format(0) + include.format(2)
                     + "  </model>\n</sdf>\n")
    result = run_urdftool("check", "--format", "json", "--model-path", str(models), str(house))
    found = [d for f in json.loads(result.out)["files"] for d in f["diagnostics"]
             if d["rule"] == "sdf.duplicate-name"]
    text = house.read_text().splitlines()
    second = [i for i, line in enumerate(text, 1) if "<include>" in line][1]
    assert [(Path(d["path"]).name, d["line"], d["severity"]) for d in found] == \
        [("house.sdf", second, "error")], found
    assert "<name>door_2</name>" in found[0]["hint"] and "line 5" in found[0]["message"]

    world = tmp_path / "world.sdf"
    world.write_text('<?xml version="1.0"?>\n<sdf version="1.6">\n  <world name="w">\n'
                     + "".join(include.format(x) for x in (0, 2, 4)) + "  </world>\n</sdf>\n")
    result = run_urdftool("check", "--format", "json", "--model-path", str(models), str(world))
    found = [d for f in json.loads(result.out)["files"] for d in f["diagnostics"]
             if d["rule"] == "sdf.duplicate-name"]
    lines = [i for i, line in enumerate(world.read_text().splitlines(), 1) if "<include>" in line]
    assert [(Path(d["path"]).name, d["line"]) for d in found] == \
        [("world.sdf", lines[1]), ("world.sdf", lines[2])], found
    assert ["<name>door_2</name>" in found[0]["hint"], "<name>door_3</name>" in found[1]["hint"]] \
        == [True, True]
