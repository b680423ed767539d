"""`urdftool compare A B` (issue 32): URDF against the MJCF MuJoCo makes of it, seeded single
differences of every kind on either side, MuJoCo's silent losses.

What decides: MuJoCo itself (the test loads the MJCF and reads ``data.xpos``/``xquat``,
``body_mass``/``body_inertia``) against the test's own forward kinematics and lumping from the
URDF text (xml.etree and numpy here, nothing of urdftool), and the seeds themselves (each
mutation is one known difference)."""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pytest

from tests.conftest import run_urdftool

# a massless base (welded to the world by MuJoCo's import: nothing to lose), a fixed link with
# mass on a moving link (lumped by MuJoCo: kept), off-diagonal inertias, a continuous joint, a
# prismatic mimic, damping and friction
ARM = """<robot name="arm">
  <link name="base_link">
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="link1">
    <inertial><origin xyz="0 0 0.2" rpy="0.1 0.2 0.3"/><mass value="1.5"/>
      <inertia ixx="0.03" ixy="0.001" ixz="0.002" iyy="0.03" iyz="0.003" izz="0.02"/></inertial>
    <collision><geometry><cylinder radius="0.05" length="0.4"/></geometry></collision>
  </link>
  <joint name="j1" type="revolute"><parent link="base_link"/><child link="link1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="50" velocity="3"/><dynamics damping="0.5" friction="0.1"/>
  </joint>
  <link name="tool">
    <inertial><origin xyz="0 0 0.02"/><mass value="0.1"/>
      <inertia ixx="0.0001" ixy="0" ixz="0" iyy="0.0002" iyz="0" izz="0.0001"/></inertial>
  </link>
  <joint name="tool_joint" type="fixed"><parent link="link1"/><child link="tool"/>
    <origin xyz="0 0.05 0.4" rpy="0.5 0 0"/></joint>
  <link name="link2">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><geometry><sphere radius="0.05"/></geometry></collision>
  </link>
  <joint name="j2" type="revolute"><parent link="link1"/><child link="link2"/>
    <origin xyz="0 0 0.4" rpy="1.5707963 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1.5" effort="20" velocity="2"/></joint>
  <link name="link3">
    <inertial><mass value="0.5"/><inertia ixx="0.005" ixy="0" ixz="0" iyy="0.005" iyz="0" izz="0.005"/></inertial>
  </link>
  <joint name="j3" type="continuous"><parent link="link2"/><child link="link3"/>
    <origin xyz="0.3 0 0"/><axis xyz="1 0 0"/><limit effort="5" velocity="4"/></joint>
  <link name="finger">
    <inertial><mass value="0.05"/><inertia ixx="0.0001" ixy="0" ixz="0" iyy="0.0001" iyz="0" izz="0.0001"/></inertial>
  </link>
  <joint name="j4" type="prismatic"><parent link="link3"/><child link="finger"/>
    <origin xyz="0.1 0 0"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" effort="10" velocity="0.1"/>
    <mimic joint="j3" multiplier="0.01" offset="0.001"/></joint>
</robot>
"""


def mujoco_import(urdf_path, out_path) -> str:
    """The MJCF MuJoCo makes of a URDF (its own import, saved by MuJoCo)."""
    model = mujoco.MjModel.from_xml_path(str(urdf_path))
    mujoco.mj_saveLastXML(str(out_path), model)
    return out_path.read_text()


@pytest.fixture
def pair(tmp_path):
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(ARM)
    mjcf = tmp_path / "arm.xml"
    mujoco_import(urdf, mjcf)
    return urdf, mjcf


def compare_json(a, b, *extra):
    result = run_urdftool("compare", str(a), str(b), "--format", "json", *extra)
    assert result.code in (0, 1), result.err
    data = json.loads(result.out)
    assert data["verdict"] == ("equivalent" if result.code == 0 else "different")
    return data


# -- the test's own kinematics and lumping (from the URDF text) -----------------------------------


def _rpy(r, p, y):
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def _origin(element):
    t = np.eye(4)
    if element is not None:
        t[:3, :3] = _rpy(*map(float, element.get("rpy", "0 0 0").split()))
        t[:3, 3] = [float(v) for v in element.get("xyz", "0 0 0").split()]
    return t


def _axis_motion(kind, axis, q):
    t = np.eye(4)
    axis = np.asarray(axis) / np.linalg.norm(axis)
    if kind == "prismatic":
        t[:3, 3] = axis * q
    else:
        k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        t[:3, :3] = np.eye(3) + math.sin(q) * k + (1 - math.cos(q)) * k @ k
    return t


def own_fk(urdf_text, q):
    """link -> 4x4 pose in the root link's frame, ``q``: joint name -> value."""
    root = ET.fromstring(urdf_text)
    joints = {j.find("child").get("link"): j for j in root.findall("joint")}
    poses = {}

    def pose(link):
        if link not in poses:
            joint = joints.get(link)
            if joint is None:
                poses[link] = np.eye(4)
            else:
                axis = [float(v) for v in (joint.find("axis").get("xyz") if joint.find("axis")
                                           is not None else "1 0 0").split()]
                motion = (_axis_motion(joint.get("type"), axis, q.get(joint.get("name"), 0.0))
                          if joint.get("type") != "fixed" else np.eye(4))
                poses[link] = pose(joint.find("parent").get("link")) @ _origin(joint.find("origin")) @ motion
        return poses[link]

    for link in root.findall("link"):
        pose(link.get("name"))
    return poses


def own_inertial(urdf_text, link):
    """(mass, com, inertia about com) of a link in its own frame."""
    element = ET.fromstring(urdf_text).find(f"link[@name='{link}']/inertial")
    origin = _origin(element.find("origin"))
    i = element.find("inertia")
    v = {k: float(i.get(k)) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
    tensor = np.array([[v["ixx"], v["ixy"], v["ixz"]], [v["ixy"], v["iyy"], v["iyz"]],
                       [v["ixz"], v["iyz"], v["izz"]]])
    r = origin[:3, :3]
    return float(element.find("mass").get("value")), origin[:3, 3], r @ tensor @ r.T


def lumped(urdf_text, members):
    """Own parallel-axis lumping of ``members`` ({link: pose in the group frame})."""
    parts = []
    for link, pose in members.items():
        m, c, inertia = own_inertial(urdf_text, link)
        r = pose[:3, :3]
        parts.append((m, r @ c + pose[:3, 3], r @ inertia @ r.T))
    mass = sum(m for m, _, _ in parts)
    com = sum(m * c for m, c, _ in parts) / mass
    tensor = sum(i + m * ((c - com) @ (c - com) * np.eye(3) - np.outer(c - com, c - com))
                 for m, c, i in parts)
    return mass, com, tensor


def mujoco_bodies(mjcf_path, q):
    """body -> (pos, rotation) from MuJoCo's own kinematics, and the compiled model."""
    model = mujoco.MjModel.from_xml_path(str(mjcf_path))
    data = mujoco.MjData(model)
    for name, value in q.items():
        data.qpos[model.jnt_qposadr[model.joint(name).id]] = value
    mujoco.mj_kinematics(model, data)
    found = {}
    for b in range(model.nbody):
        rotation = np.zeros(9)
        mujoco.mju_quat2Mat(rotation, data.xquat[b])
        found[model.body(b).name] = (data.xpos[b].copy(), rotation.reshape(3, 3))
    return found, model


def body_inertia(model, name):
    b = model.body(name).id
    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, model.body_iquat[b])
    rotation = rotation.reshape(3, 3)
    return float(model.body_mass[b]), model.body_ipos[b].copy(), rotation @ np.diag(model.body_inertia[b]) @ rotation.T


def sampled_q(rng):
    q = {"j1": rng.uniform(-2, 2), "j2": rng.uniform(-1, 1.5), "j3": rng.uniform(-3, 3)}
    q["j4"] = 0.01 * q["j3"] + 0.001
    return q


# -- equivalent pairs -----------------------------------------------------------------------------


def test_urdf_and_mujocos_import_are_equivalent(pair):
    urdf, mjcf = pair
    # the test's own check that the pair is equivalent: MuJoCo's kinematics of the MJCF against
    # our FK of the URDF, and the lumped link1+tool against MuJoCo's body
    rng = np.random.default_rng(7)
    for _ in range(5):
        q = sampled_q(rng)
        ours = own_fk(ARM, q)
        theirs, model = mujoco_bodies(mjcf, q)
        for link in ("link1", "link2", "link3", "finger"):
            assert np.allclose(ours[link][:3, 3], theirs[link][0], atol=1e-6)
            assert np.allclose(ours[link][:3, :3], theirs[link][1], atol=1e-5)
    tool = own_fk(ARM, {})
    mass, com, tensor = lumped(ARM, {"link1": np.eye(4),
                                     "tool": np.linalg.inv(tool["link1"]) @ tool["tool"]})
    m, c, i = body_inertia(model, "link1")
    assert m == pytest.approx(mass) and np.allclose(c, com, atol=1e-6)
    # (MuJoCo's saved XML keeps 6 significant digits: the tensor as a whole, to 1e-5)
    assert np.linalg.norm(i - tensor) <= 1e-5 * np.linalg.norm(tensor)
    assert "tool" not in {model.body(b).name for b in range(model.nbody)}  # lumped by MuJoCo
    data = compare_json(urdf, mjcf)
    assert data["differences"] == [], data
    assert data["samples"] == 20 and data["largest_error"] < 1e-5
    # and the other way round
    assert compare_json(mjcf, urdf)["differences"] == []


def test_same_file_is_equivalent_with_zero_error(pair):
    urdf, mjcf = pair
    data = compare_json(urdf, urdf)
    assert data["differences"] == [] and data["largest_error"] == 0.0
    data = compare_json(mjcf, mjcf)
    assert data["differences"] == [] and data["largest_error"] == 0.0


# -- seeded single differences ---------------------------------------------------------------------


def _edit_mjcf(text, change):
    root = ET.fromstring(text)
    change(root)
    return ET.tostring(root, encoding="unicode")


def _find(root, tag, name):
    return next(e for e in root.iter(tag) if e.get("name") == name)


def _set(tag, name, **attributes):
    def change(root):
        element = _find(root, tag, name)
        for key, value in attributes.items():
            element.set(key, value)
    return change


def _inertial(body, **attributes):
    def change(root):
        element = _find(root, "body", body).find("inertial")
        for key, value in attributes.items():
            element.set(key, value)
    return change


def _remove_finger(root):
    link3 = _find(root, "body", "link3")
    link3.remove(_find(root, "body", "finger"))
    root.remove(root.find("equality"))


def _add_body(root):
    body = ET.SubElement(_find(root, "body", "link3"), "body", name="extra", pos="0 0.1 0")
    ET.SubElement(body, "inertial", pos="0 0 0", mass="0.1", diaginertia="0.001 0.001 0.001")
    ET.SubElement(body, "joint", name="j_extra", axis="0 0 1")


def _drop_collision(root):
    body = _find(root, "body", "link1")
    body.remove(body.find("geom"))


def _velocity_actuators(changed):
    def change(root):
        actuator = ET.SubElement(root, "actuator")
        for joint, limit in (("j1", 3), ("j2", 2), ("j3", 4), ("j4", 0.1)):
            limit = changed if joint == "j1" else limit
            ET.SubElement(actuator, "velocity", joint=joint, kv="1", ctrlrange=f"{-limit} {limit}")
    return change


MJCF_SEEDS = {
    "missing-body": (_remove_finger, "finger"),
    "extra-body": (_add_body, "extra"),
    "pose": (_set("body", "link2", pos="0 0 0.41"), "link2"),
    "joint-type": (_set("joint", "j4", type="hinge"), "j4"),
    "axis": (_set("joint", "j3", axis="0 0 1"), "j3"),
    "range": (_set("joint", "j1", range="-2 1.9"), "j1"),
    "mimic": (lambda root: root.find("equality/joint").set("polycoef", "0.001 0.02 0 0 0"), "j4"),
    "mass": (_inertial("link3", mass="0.6"), "link3"),
    "com": (_inertial("link2", pos="0.01 0 0"), "link2"),
    "inertia": (_inertial("link3", diaginertia="0.005 0.006 0.005"), "link3"),
    "damping": (_set("joint", "j1", damping="0.7"), "j1"),
    "friction": (_set("joint", "j1", frictionloss="0.2"), "j1"),
    "armature": (_set("joint", "j2", armature="0.01"), "j2"),
    "effort": (_set("joint", "j3", actuatorfrcrange="-6 6"), "j3"),
    "velocity": (_velocity_actuators(3.5), "j1"),
    "collision": (_drop_collision, "link1"),
}


@pytest.mark.parametrize("kind", sorted(MJCF_SEEDS))
def test_seeded_difference_in_the_mjcf(pair, kind):
    urdf, mjcf = pair
    change, name = MJCF_SEEDS[kind]
    seeded = mjcf.with_name("seeded.xml")
    seeded.write_text(_edit_mjcf(mjcf.read_text(), change))
    mujoco.MjModel.from_xml_path(str(seeded))  # MuJoCo loads the seeded model
    data = compare_json(urdf, seeded)
    found = [(d["kind"], d["name"] if kind != "extra-body" else d["other"])
             for d in data["differences"]]
    assert found == [(kind, name)], data
    difference = data["differences"][0]
    if kind != "extra-body":  # located in A, the URDF
        assert difference["path"] == str(urdf) and difference["line"] >= 1
        line = ARM.splitlines()[difference["line"] - 1]
        tag = {"range": "<limit", "effort": "<limit", "velocity": "<limit", "mimic": "<mimic",
               "damping": "<dynamics", "friction": "<dynamics", "mass": "<mass",
               "com": "<inertial", "inertia": "<inertia", "collision": "<collision"}.get(kind)
        assert (tag or name) in line, line


def test_velocity_actuators_that_agree_are_no_difference(pair):
    urdf, mjcf = pair
    agreeing = mjcf.with_name("velocity.xml")
    agreeing.write_text(_edit_mjcf(mjcf.read_text(), _velocity_actuators(3)))
    data = compare_json(urdf, agreeing)
    assert data["differences"] == [] and data["notes"] == []


URDF_SEEDS = {
    "missing-body": (lambda s: s.replace("</robot>", """<link name="extra">
      <inertial><mass value="0.1"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
      <joint name="j_extra" type="continuous"><parent link="link3"/><child link="extra"/></joint></robot>"""), "extra"),
    "pose": (lambda s: s.replace('<origin xyz="0.3 0 0"/>', '<origin xyz="0.3 0 0" rpy="0 0 0.01"/>'), "link3"),
    "joint-type": (lambda s: s.replace('name="j4" type="prismatic"', 'name="j4" type="revolute"'), "j4"),
    "axis": (lambda s: s.replace('<axis xyz="0 1 0"/>\n    <limit lower="-1"', '<axis xyz="0 -1 0"/>\n    <limit lower="-1"'), "j2"),
    "range": (lambda s: s.replace('lower="-1" upper="1.5"', 'lower="-1" upper="1.4"'), "j2"),
    "mimic": (lambda s: s.replace('<mimic joint="j3" multiplier="0.01" offset="0.001"/>', ''), "j4"),
    "mass": (lambda s: s.replace('<mass value="0.1"/>', '<mass value="0.2"/>'), "link1"),
    "com": (lambda s: s.replace('<origin xyz="0 0 0.02"/>', '<origin xyz="0 0 0.03"/>'), "link1"),
    "inertia": (lambda s: s.replace('ixx="0.03" ixy="0.001"', 'ixx="0.03" ixy="0.0015"'), "link1"),
    "damping": (lambda s: s.replace('damping="0.5"', 'damping="0.4"'), "j1"),
    "friction": (lambda s: s.replace('friction="0.1"', 'friction="0"'), "j1"),
    "effort": (lambda s: s.replace('effort="20"', 'effort="25"'), "j2"),
    "collision": (lambda s: s.replace('<collision><geometry><sphere radius="0.05"/></geometry></collision>', ''), "link2"),
}


@pytest.mark.parametrize("kind", sorted(URDF_SEEDS))
def test_seeded_difference_in_the_urdf(pair, kind):
    urdf, mjcf = pair
    change, name = URDF_SEEDS[kind]
    text = change(ARM)
    assert text != ARM
    seeded = urdf.with_name("seeded.urdf")
    seeded.write_text(text)
    data = compare_json(seeded, mjcf)
    assert [(d["kind"], d["name"]) for d in data["differences"]] == [(kind, name)], data
    assert data["differences"][0]["path"] == str(seeded)


# -- MuJoCo's silent losses ------------------------------------------------------------------------


def test_mujocos_silent_losses_are_found(tmp_path):
    """What MuJoCo's URDF import loses without a word: the root link's mass (fused into the
    world), a joint with a half-given <limit> (unlimited). Off-diagonal inertia dropped and a
    mimic lost are what converters do: seeded on MuJoCo's own output."""
    text = ARM.replace('<link name="base_link">', '<link name="base_link">\n    <inertial>'
                       '<mass value="2"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" '
                       'izz="0.02"/></inertial>').replace('lower="-1" upper="1.5"', 'upper="1.5"')
    urdf = tmp_path / "lossy.urdf"
    urdf.write_text(text)
    mjcf = tmp_path / "lossy.xml"
    mujoco_import(urdf, mjcf)
    model = mujoco.MjModel.from_xml_path(str(mjcf))
    assert not model.jnt_limited[model.joint("j2").id]  # MuJoCo's own doing, said by nobody
    assert "base_link" not in {model.body(b).name for b in range(model.nbody)}
    data = compare_json(urdf, mjcf)
    assert {(d["kind"], d["name"]) for d in data["differences"]} == {("mass", "base_link"),
                                                                     ("range", "j2")}
    # a converter that writes principal moments only and drops the mimic
    fixed = tmp_path / "arm.urdf"
    fixed.write_text(ARM)
    full = tmp_path / "arm.xml"
    mujoco_import(fixed, full)

    def lossy(root):
        inertial = _find(root, "body", "link1").find("inertial")
        inertial.attrib.pop("quat", None)  # principal moments kept, their axes dropped
        root.remove(root.find("equality"))

    converted = tmp_path / "converted.xml"
    converted.write_text(_edit_mjcf(full.read_text(), lossy))
    data = compare_json(fixed, converted)
    assert {(d["kind"], d["name"]) for d in data["differences"]} == {("inertia", "link1"),
                                                                     ("mimic", "j4")}


def test_principal_axes_in_another_form_are_no_difference(pair, tmp_path):
    """The same tensor as fullinertia instead of MuJoCo's diaginertia + quat."""
    urdf, mjcf = pair
    model = mujoco.MjModel.from_xml_path(str(mjcf))
    _m, _c, tensor = body_inertia(model, "link1")
    values = [tensor[0, 0], tensor[1, 1], tensor[2, 2], tensor[0, 1], tensor[0, 2], tensor[1, 2]]

    def full(root):
        inertial = _find(root, "body", "link1").find("inertial")
        inertial.attrib.pop("quat")
        inertial.attrib.pop("diaginertia")
        inertial.set("fullinertia", " ".join(repr(float(v)) for v in values))

    other = tmp_path / "full.xml"
    other.write_text(_edit_mjcf(mjcf.read_text(), full))
    assert compare_json(urdf, other)["differences"] == []


def test_text_output_and_exit_codes(pair, tmp_path):
    urdf, mjcf = pair
    result = run_urdftool("compare", str(urdf), str(mjcf))
    assert result.code == 0 and result.out.startswith("equivalent"), result
    result = run_urdftool("compare", str(urdf), str(tmp_path / "missing.xml"))
    assert result.code == 2 and "no such file" in result.err
    broken = tmp_path / "broken.xml"
    broken.write_text('<mujoco><worldbody><body name="a"><joint type="hinge"/></body></worldbody></mujoco>')
    result = run_urdftool("compare", str(urdf), str(broken))
    assert result.code == 2 and "MuJoCo cannot load it" in result.err and "Traceback" not in result.err
    result = run_urdftool("compare", str(urdf))
    assert result.code == 2


def test_mjcf_include_outside_the_roots_is_refused(tmp_path):
    """An MJCF <include> (or mesh file) outside the repository is refused before MuJoCo reads
    anything, as a xacro include is."""
    repo = tmp_path / "repo"
    (repo / ".git").mkdir(parents=True)
    secret = tmp_path / "secret.xml"
    secret.write_text("<mujoco><worldbody/></mujoco>")
    model = repo / "robot.xml"
    for spec in ("../secret.xml", str(secret)):
        model.write_text(f'<mujoco><include file="{spec}"/><worldbody/></mujoco>')
        result = run_urdftool("compare", str(model), str(model))
        assert result.code == 2 and "outside the repository" in result.err, result
    (tmp_path / "outside.stl").write_text("solid x\nendsolid x\n")
    model.write_text('<mujoco><compiler meshdir=".."/><asset><mesh file="outside.stl"/></asset>'
                     '<worldbody/></mujoco>')
    result = run_urdftool("compare", str(model), str(model))
    assert result.code == 2 and "outside the repository" in result.err, result


def test_xacro_with_arguments_and_sdf_on_either_side(tmp_path):
    """xacro (NAME:=VALUE to both sides) and SDF are read through urdftool's loader; the xacro
    side is located in the .xacro file."""
    xacro = tmp_path / "arm.urdf.xacro"
    xacro.write_text(ARM.replace('<robot name="arm">', '<robot name="arm" '
                                 'xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                                 '  <xacro:arg name="reach" default="0.3"/>').replace(
        '<origin xyz="0.3 0 0"/>', '<origin xyz="$(arg reach) 0 0"/>'))
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(ARM)
    assert compare_json(xacro, urdf)["differences"] == []
    data = compare_json(xacro, urdf, "reach:=0.35")
    assert [(d["kind"], d["name"]) for d in data["differences"]] == [("pose", "link3")]
    assert data["differences"][0]["path"] == str(xacro)
    assert data["differences"][0]["max_error"] == pytest.approx(0.05)
    sdf = tmp_path / "arm.sdf"
    sdf.write_text("""<sdf version="1.9"><model name="arm">
      <link name="base_link"/>
      <link name="link1"><pose relative_to="j1"/>
        <inertial><mass>1.5</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial>
      </link>
      <joint name="j1" type="revolute"><parent>base_link</parent><child>link1</child>
        <pose relative_to="base_link">0 0 0.1 0 0 0</pose>
        <axis><xyz>0 0 1</xyz><limit><lower>-2</lower><upper>2</upper></limit></axis></joint>
    </model></sdf>""")
    small = tmp_path / "small.urdf"
    small.write_text("""<robot name="arm"><link name="base_link"/>
      <link name="link1"><inertial><mass value="1.5"/>
        <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
      <joint name="j1" type="revolute"><parent link="base_link"/><child link="link1"/>
        <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
    </robot>""")
    data = compare_json(small, sdf)
    kinds = {(d["kind"], d["name"]) for d in data["differences"]}
    assert ("pose", "link1") not in kinds and ("range", "j1") not in kinds
    assert ("mass", "link1") not in kinds and ("inertia", "link1") not in kinds


def test_missing_mujoco_and_robots_that_are_not_one_tree(pair, tmp_path, monkeypatch):
    urdf, mjcf = pair
    two = tmp_path / "two.urdf"
    two.write_text('<robot name="r"><link name="a"/><link name="b"/></robot>')
    result = run_urdftool("compare", str(two), str(urdf))
    assert result.code == 2 and "2 root links (a, b)" in result.err
    assert compare_json(urdf, urdf)["verdict"] == "equivalent"  # URDF only: no MuJoCo needed
    monkeypatch.setitem(__import__("sys").modules, "mujoco", None)  # not installed
    result = run_urdftool("compare", str(urdf), str(mjcf))
    assert result.code == 2 and "pip install" in result.err and "[mjcf]" in result.err
    assert compare_json(urdf, urdf)["verdict"] == "equivalent"


def test_a_free_root_is_no_difference_a_free_joint_below_is(pair, tmp_path):
    """Whether a URDF's root floats is the simulator's choice: a <freejoint> on the MJCF's top
    body is said in a note; a moving joint added anywhere below is a difference."""
    urdf, mjcf = pair
    heavy = tmp_path / "heavy.urdf"  # a free body needs mass in MuJoCo
    heavy.write_text(ARM.replace('<link name="base_link">', '<link name="base_link">\n    '
                                 '<inertial><mass value="2"/><inertia ixx="0.01" ixy="0" ixz="0" '
                                 'iyy="0.01" iyz="0" izz="0.02"/></inertial>'))
    exported = tmp_path / "heavy.xml"
    assert run_urdftool("convert", str(heavy), "--to", "mjcf", "-o", str(exported)).code == 0

    def free_root(root):
        ET.SubElement(_find(root, "body", "base_link"), "freejoint", name="root")

    floating = tmp_path / "floating.xml"
    floating.write_text(_edit_mjcf(exported.read_text(), free_root))
    model = mujoco.MjModel.from_xml_path(str(floating))
    assert model.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE
    data = compare_json(heavy, floating)
    assert data["differences"] == [] and any("free" in note for note in data["notes"])
    hinged = tmp_path / "hinged.xml"
    hinged.write_text(_edit_mjcf(mjcf.read_text(), lambda root: ET.SubElement(
        _find(root, "body", "finger"), "joint", name="j_more", axis="1 0 0")))
    data = compare_json(urdf, hinged)
    assert [(d["kind"], d["other"]) for d in data["differences"]] == [("joint-type", "j_more")]
