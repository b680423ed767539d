"""Oracle for `urdftool convert`, independent of the converter: every SDF model PyBullet can
load is loaded by PyBullet (`loadSDF`) and its conversion by pinocchio; at random joint
configurations the world pose of every link (relative to the base link), and the mass, world COM
and inertia about the COM of every rigid body, must agree to 1e-6.

What PyBullet gives and what it does not: link frames, link masses, COM positions and the
orientation of each inertial frame come from PyBullet. PyBullet replaces the inertia tensor by
one computed from the collision shapes (`loadSDF` takes no URDF_USE_INERTIA_FROM_FILE), so the
tensor values are read from the SDF file by this test and rotated with PyBullet's inertial frame.
Pinocchio merges links hung on fixed joints into one body, so masses and inertias are compared
per rigid body (the links sharing a pinocchio joint), poses per link. The URDF is loaded
with a free-flyer root left at identity, so the root links' inertias are kept.

PyBullet ignores a joint's <pose> and use_parent_model_frame and has no relative_to, nested
models or loops: those cases are in test_sdf_frames.py with closed-form expectations.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin  # the test extra has both oracles: a missing one fails
import pybullet
import pytest
from conftest import pybullet_data_dir, run_urdftool
from lxml import etree

TOLERANCE = 1e-6
DATA = Path(__file__).parent / "data" / "sdf"


def loads_in_pybullet(path: Path) -> bool:
    """Whether PyBullet loads the file, asked in a child process: some files crash it
    (gripper/wsg50_one_motor_gripper_free_base.sdf segfaults), others name missing meshes."""
    code = ("import sys, pybullet as p; p.connect(p.DIRECT); "
            "sys.exit(0 if p.loadSDF(sys.argv[1]) else 1)")
    try:
        result = subprocess.run([sys.executable, "-c", code, str(path)], check=False,
                                capture_output=True, timeout=60)
    except subprocess.TimeoutExpired:
        return False
    return result.returncode == 0


def pybullet_models() -> list[tuple[Path, str]]:
    found = []
    for path in sorted(pybullet_data_dir().rglob("*.sdf")):
        root = etree.parse(str(path)).getroot()
        for model in root.iter("model"):
            found.append((path, model.get("name")))
    return found


# -- small maths, written here (not urdftool's) ------------------------------------------------


def quat_matrix(q) -> np.ndarray:
    x, y, z, w = q
    n = np.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def homogeneous(rotation, translation) -> np.ndarray:
    t = np.eye(4)
    t[:3, :3] = rotation
    t[:3, 3] = translation
    return t


def pose_error(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """(metres, radians) between two homogeneous transforms."""
    delta = np.linalg.inv(a) @ b
    angle = np.arccos(np.clip((np.trace(delta[:3, :3]) - 1) / 2, -1.0, 1.0))
    return float(np.linalg.norm(delta[:3, 3])), float(angle)


def composite(bodies):
    """(mass, COM, inertia about the COM) of rigidly joined (mass, com, inertia) bodies."""
    mass = sum(m for m, _, _ in bodies)
    if mass <= 0:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    com = sum(m * c for m, c, _ in bodies) / mass
    inertia = np.zeros((3, 3))
    for m, c, i in bodies:
        d = c - com
        inertia += i + m * (d @ d * np.eye(3) - np.outer(d, d))
    return mass, com, inertia


# -- the SDF side: PyBullet ------------------------------------------------------------------


def sdf_tensor(path: Path, model: str, link: str) -> np.ndarray | None:
    """The inertia tensor written in the SDF file (None: the link has no <inertial>)."""
    root = etree.parse(str(path)).getroot()
    for m in root.iter("model"):
        if m.get("name") != model:
            continue
        for l in m.iter("link"):
            if l.get("name") == link:
                if l.find("inertial") is None:
                    return None
                inertia = l.find("inertial/inertia")

                def get(tag, default, inertia=inertia):
                    return float(inertia.findtext(tag, str(default))) if inertia is not None \
                        else float(default)

                ixx, ixy, ixz = get("ixx", 1), get("ixy", 0), get("ixz", 0)
                iyy, iyz, izz = get("iyy", 1), get("iyz", 0), get("izz", 1)
                return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    raise KeyError(link)


class Bullet:
    def __init__(self, path: Path):
        self.client = pybullet.connect(pybullet.DIRECT)
        self.bodies = pybullet.loadSDF(str(path), physicsClientId=self.client)

    def close(self):
        pybullet.disconnect(self.client)

    def joints(self, body) -> list[tuple[int, str, int, float, float]]:
        out = []
        for index in range(pybullet.getNumJoints(body, physicsClientId=self.client)):
            info = pybullet.getJointInfo(body, index, physicsClientId=self.client)
            out.append((index, info[1].decode(), info[2], info[8], info[9]))
        return out

    def set(self, body, values: dict[str, float]) -> None:
        for index, name, _, _, _ in self.joints(body):
            if name in values:
                pybullet.resetJointState(body, index, values[name], physicsClientId=self.client)

    def links(self, body):
        """name -> (link frame 4x4, mass, world COM, inertial frame rotation)."""
        c = self.client
        out = {}
        base_name = pybullet.getBodyInfo(body, physicsClientId=c)[0].decode()
        position, orientation = pybullet.getBasePositionAndOrientation(body, physicsClientId=c)
        dynamics = pybullet.getDynamicsInfo(body, -1, physicsClientId=c)
        com_frame = homogeneous(quat_matrix(orientation), position)
        local = homogeneous(quat_matrix(dynamics[4]), dynamics[3])
        out[base_name] = (com_frame @ np.linalg.inv(local), dynamics[0], np.array(position),
                          quat_matrix(orientation))
        for index, _, _, _, _ in self.joints(body):
            name = pybullet.getJointInfo(body, index, physicsClientId=c)[12].decode()
            state = pybullet.getLinkState(body, index, computeForwardKinematics=True,
                                          physicsClientId=c)
            mass = pybullet.getDynamicsInfo(body, index, physicsClientId=c)[0]
            out[name] = (homogeneous(quat_matrix(state[5]), state[4]), mass, np.array(state[0]),
                         quat_matrix(state[1]))
        return base_name, out


# -- the URDF side: pinocchio ---------------------------------------------------------------


class Pinocchio:
    def __init__(self, urdf: Path):
        # a free-flyer root (left at identity) makes pinocchio keep the root links' inertias
        self.model = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
        self.data = self.model.createData()

    def configuration(self, values: dict[str, float]) -> np.ndarray:
        q = pin.neutral(self.model)
        for joint_id in range(1, self.model.njoints):
            name = self.model.names[joint_id]
            joint = self.model.joints[joint_id]
            if name not in values:
                continue
            if joint.nq == 1:
                q[joint.idx_q] = values[name]
            elif joint.nq == 2:  # continuous: cos, sin
                q[joint.idx_q:joint.idx_q + 2] = np.cos(values[name]), np.sin(values[name])
        return q

    def update(self, values: dict[str, float]) -> None:
        q = self.configuration(values)
        pin.forwardKinematics(self.model, self.data, q)
        pin.updateFramePlacements(self.model, self.data)

    def frame(self, name: str) -> np.ndarray:
        index = self.model.getFrameId(name, pin.FrameType.BODY)
        assert index < len(self.model.frames), f"no link frame {name!r} in the URDF"
        return self.data.oMf[index].homogeneous

    def body_of(self, name: str) -> int:
        return self.model.frames[self.model.getFrameId(name, pin.FrameType.BODY)].parentJoint

    def body(self, joint_id: int):
        """(mass, world COM, world inertia about the COM) of a pinocchio body."""
        return self._world(self.model.inertias[joint_id], self.data.oMi[joint_id])

    @staticmethod
    def _world(inertia, placement):
        rotation = placement.rotation
        com = placement.act(inertia.lever)
        return inertia.mass, np.array(com), rotation @ inertia.inertia @ rotation.T


def convert(path: Path, model: str, out: Path) -> Path:
    result = run_urdftool("convert", path, "--model", model, "-o", out)
    assert result.code == 0, result.err
    return out


def compare_model(path: Path, model: str, tmp_path: Path, seed: int = 0) -> dict:
    """Run the oracle on one model; returns the largest errors seen."""
    urdf = convert(path, model, tmp_path / f"{model.replace('/', '_')}.urdf")
    names = [m.get("name") for m in etree.parse(str(path)).getroot().iter("model")]
    bullet = Bullet(path)
    try:
        body = bullet.bodies[names.index(model)]
        robot = Pinocchio(urdf)
        rng = np.random.default_rng(seed)
        worst = {"position": 0.0, "angle": 0.0, "mass": 0.0, "com": 0.0, "inertia": 0.0,
                 "links": 0, "configurations": 0}
        for trial in range(4):
            values = {}
            for _, name, kind, lower, upper in bullet.joints(body):
                if kind in (pybullet.JOINT_REVOLUTE, pybullet.JOINT_PRISMATIC) and trial:
                    lo, hi = (lower, upper) if lower < upper else (-np.pi, np.pi)
                    lo, hi = max(lo, -np.pi), min(hi, np.pi)
                    values[name] = float(rng.uniform(lo, hi))
            bullet.set(body, values)
            robot.update(values)
            base, links = bullet.links(body)
            reference_sdf = links[base][0]
            reference_urdf = robot.frame(base)
            groups: dict[int, list] = {}
            for name, (frame, mass, com, inertial_rotation) in links.items():
                expected = np.linalg.inv(reference_sdf) @ frame
                got = np.linalg.inv(reference_urdf) @ robot.frame(name)
                position, angle = pose_error(expected, got)
                worst["position"] = max(worst["position"], position)
                worst["angle"] = max(worst["angle"], angle)
                tensor = sdf_tensor(path, model, name)
                if tensor is None:
                    # no <inertial>: the SDFormat default (mass 1, unit inertia at the link
                    # origin); PyBullet gives such links mass 0 instead, against the spec
                    mass, com, tensor = 1.0, frame[:3, 3], np.eye(3)
                    inertial_rotation = frame[:3, :3]
                world_inertia = inertial_rotation @ tensor @ inertial_rotation.T
                groups.setdefault(robot.body_of(name), []).append((mass, com, world_inertia))
            for joint_id, parts in groups.items():
                mass, com, inertia = composite(parts)
                got_mass, got_com, got_inertia = robot.body(joint_id)
                # both sides relative to the base link frame
                r_s, r_u = reference_sdf[:3, :3], reference_urdf[:3, :3]
                com_s = r_s.T @ (com - reference_sdf[:3, 3])
                com_u = r_u.T @ (got_com - reference_urdf[:3, 3])
                worst["mass"] = max(worst["mass"], abs(mass - got_mass))
                if mass > 0:
                    worst["com"] = max(worst["com"], float(np.linalg.norm(com_s - com_u)))
                    worst["inertia"] = max(worst["inertia"], float(np.abs(
                        r_s.T @ inertia @ r_s - r_u.T @ got_inertia @ r_u).max()))
            worst["links"] = len(links)
            worst["configurations"] += 1
        return worst
    finally:
        bullet.close()


# The pybullet_data SDF files PyBullet itself cannot load (pybullet 3.2.x, its own data): no
# reference to compare with. Asserted, never skipped: test_pybullet_still_refuses_these fails
# when one loads (then it joins the compared models). Their conversion is checked in
# test_sdf_convert.py.
UNLOADABLE = {
    "gripper/wsg50_one_motor_gripper_free_base.sdf": "PyBullet crashes (segfault) on it",
    "kuka_iiwa/kuka_world.sdf": "PyBullet: 'failed to parse link' (Cannot load SDF file)",
    "kuka_iiwa/model2.sdf": "PyBullet: 'failed to parse link' (Cannot load SDF file)",
}


def _relative(path: Path) -> str:
    return path.relative_to(pybullet_data_dir()).as_posix()


COMPARED = [(path, model) for path, model in pybullet_models() if _relative(path) not in UNLOADABLE]


def test_the_oracle_compares_most_models():
    """How many of pybullet_data's SDF models are compared (issue 33: skips used to hide it)."""
    every = pybullet_models()
    assert {_relative(path) for path, _ in every} >= set(UNLOADABLE)
    assert len(every) == 20 and len(COMPARED) == 16, (len(COMPARED), len(every))


def test_pybullet_still_refuses_these():
    for name, why in UNLOADABLE.items():
        assert not loads_in_pybullet(pybullet_data_dir() / name), f"PyBullet now loads {name} " \
            f"(listed: {why}): remove it from UNLOADABLE, the oracle compares it"


@pytest.mark.slow  # 16 models through pybullet (~5 s of CPU): CI; make test keeps our own below
@pytest.mark.parametrize("path,model", COMPARED,
                         ids=lambda v: v if isinstance(v, str) else v.name)
def test_pybullet_data_sdf_against_pybullet(path, model, tmp_path):
    assert loads_in_pybullet(path), f"PyBullet cannot load {_relative(path)}: list it in " \
        "UNLOADABLE with the reason, or find what broke"
    worst = compare_model(path, model, tmp_path)
    assert worst["links"] >= 1
    for key in ("position", "angle", "mass", "com", "inertia"):
        assert worst[key] < TOLERANCE, f"{model}: {key} error {worst[key]:.3g} ({worst})"


# our own files whose features PyBullet reads: a rotated inertial with off-diagonal inertia,
# SDF 1.4 with a rotated chain, several models in a world
OWN = ["inertia_rotated.sdf", "chain_1_4.sdf", "two_models.sdf"]


@pytest.mark.parametrize("name", OWN)
def test_own_sdf_against_pybullet(name, tmp_path):
    path = DATA / name
    models = [m.get("name") for m in etree.parse(str(path)).getroot().iter("model")]
    for model in models:
        worst = compare_model(path, model, tmp_path, seed=7)
        for key in ("position", "angle", "mass", "com", "inertia"):
            assert worst[key] < TOLERANCE, f"{name}/{model}: {key} error {worst[key]:.3g}"


BALL_PENDULUM = """<sdf version="1.7"><model name="pendulum">
  <link name="a"><inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz>
    </inertia></inertial></link>
  <link name="b"><pose>0 0 0.5 0 0 0</pose>
    <inertial><pose>0 0 0.3 0 0 0</pose><mass>2</mass>
      <inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial></link>
  <joint name="j" type="ball"><parent>a</parent><child>b</child></joint>
</model></sdf>
"""


def test_ball_joint_links_are_massless_in_pybullet(tmp_path):
    """A ball joint becomes three joints through two links that must add no mass: PyBullet
    gives a link without <inertial> 1 kg and 1 kg·m², which freezes this pendulum."""
    sdf = tmp_path / "pendulum.sdf"
    sdf.write_text(BALL_PENDULUM)
    urdf = tmp_path / "pendulum.urdf"
    assert run_urdftool("convert", sdf, "-o", urdf).code == 0
    checked = run_urdftool("check", "--format", "json", "--select", "inertia", sdf)
    assert checked.code == 0 and '"diagnostics": []' in checked.out
    client = pybullet.connect(pybullet.DIRECT)
    try:
        pybullet.setGravity(0, 0, -9.81, physicsClientId=client)
        body = pybullet.loadURDF(str(urdf), useFixedBase=True, physicsClientId=client,
                                 flags=pybullet.URDF_USE_INERTIA_FROM_FILE)
        masses = [pybullet.getDynamicsInfo(body, i, physicsClientId=client)[0] for i in range(3)]
        assert masses == [0.0, 0.0, 2.0]
        for i in range(3):
            pybullet.setJointMotorControl2(body, i, pybullet.VELOCITY_CONTROL, force=0,
                                           physicsClientId=client)
        pybullet.resetJointState(body, 0, 0.3, physicsClientId=client)
        steps, dt = 24, 1 / 240
        for _ in range(steps):
            pybullet.stepSimulation(physicsClientId=client)
        angle = pybullet.getJointState(body, 0, physicsClientId=client)[0]
    finally:
        pybullet.disconnect(client)
    # closed form: a rigid pendulum about the x axis, m = 2, d = 0.3, I = 0.01 + m d²
    theta, omega, h = 0.3, 0.0, dt / 100
    for _ in range(steps * 100):
        omega += 2 * 9.81 * 0.3 * np.sin(theta) / (0.01 + 2 * 0.09) * h
        theta += omega * h
    assert abs((angle - 0.3) - (theta - 0.3)) < 0.1 * (theta - 0.3)
