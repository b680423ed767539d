"""`urdftool diff`'s comparison of two robots (issue 30), against independent computations:
the test's own element-by-element comparison of the two URDFs (lxml), forward kinematics from
pinocchio for the effect of an origin (within 1e-6 m), numpy for inertia tensors in another
form. Random robots and random single changes (seeded), and rewrites that change nothing."""

from __future__ import annotations

import math
import random

import numpy as np
import pinocchio as pin
import pytest
from lxml import etree

from tests.conftest import run_urdftool

# -- random robots ---------------------------------------------------------------------------


def _num(rng: random.Random, low: float, high: float) -> float:
    return round(rng.uniform(low, high), 4)


def random_robot(seed: int, links: int = 7) -> etree._Element:
    """A tree of ``links`` links: revolute, prismatic and fixed joints, rpy origins, boxes,
    cylinders and spheres, full inertias with inertial rpy."""
    rng = random.Random(seed)
    robot = etree.Element("robot", name=f"r{seed}")
    for i in range(links):
        link = etree.SubElement(robot, "link", name=f"link{i}")
        inertial = etree.SubElement(link, "inertial")
        etree.SubElement(inertial, "origin", xyz=" ".join(str(_num(rng, -0.1, 0.1)) for _ in range(3)),
                         rpy=" ".join(str(_num(rng, -1, 1)) for _ in range(3)))
        etree.SubElement(inertial, "mass", value=str(_num(rng, 0.5, 5)))
        a, b, c = (_num(rng, 0.01, 0.05) for _ in range(3))
        etree.SubElement(inertial, "inertia", ixx=str(a + b), iyy=str(b + c), izz=str(a + c),
                         ixy="0", ixz="0", iyz="0")
        visual = etree.SubElement(link, "visual")
        geometry = etree.SubElement(visual, "geometry")
        kind = rng.choice(["box", "cylinder", "sphere"])
        if kind == "box":
            etree.SubElement(geometry, "box", size=" ".join(str(_num(rng, 0.05, 0.3)) for _ in range(3)))
        elif kind == "cylinder":
            etree.SubElement(geometry, "cylinder", radius=str(_num(rng, 0.02, 0.1)),
                             length=str(_num(rng, 0.1, 0.4)))
        else:
            etree.SubElement(geometry, "sphere", radius=str(_num(rng, 0.02, 0.1)))
    for i in range(1, links):
        parent = rng.randrange(i)
        kind = rng.choice(["revolute", "revolute", "prismatic", "fixed"])
        joint = etree.SubElement(robot, "joint", name=f"joint{i}", type=kind)
        etree.SubElement(joint, "parent", link=f"link{parent}")
        etree.SubElement(joint, "child", link=f"link{i}")
        etree.SubElement(joint, "origin", xyz=" ".join(str(_num(rng, -0.3, 0.3)) for _ in range(3)),
                         rpy=" ".join(str(_num(rng, -1.5, 1.5)) for _ in range(3)))
        if kind != "fixed":
            axis = rng.choice(["1 0 0", "0 1 0", "0 0 1"])
            etree.SubElement(joint, "axis", xyz=axis)
            etree.SubElement(joint, "limit", lower=str(_num(rng, -3, -0.5)),
                             upper=str(_num(rng, 0.5, 3)), effort=str(_num(rng, 1, 100)),
                             velocity=str(_num(rng, 0.5, 5)))
            etree.SubElement(joint, "dynamics", damping=str(_num(rng, 0, 1)))
    return robot


def text(robot) -> str:
    return etree.tostring(robot, pretty_print=True, encoding="unicode")


def diff_json(write, before: str, after: str) -> list[dict]:
    a = write(before, "a/robot.urdf")
    b = write(after, "b/robot.urdf")
    result = run_urdftool("diff", a, b, "--format", "json", "--trusted", "--timeout", "120")
    assert result.code == 0, result.err
    import json

    [robot] = json.loads(result.out)["robots"]
    return robot["changes"]


# -- the test's own comparison ---------------------------------------------------------------


def _floats(value: str | None):
    return None if value is None else [float(v) for v in value.split()]


def expected_changes(a, b) -> set[tuple[str, str, str]]:
    """(element, name, aspect) the test finds itself, element by element, for the kinds of
    change ``mutate`` makes (same names on both sides)."""
    found = set()
    links_a = {e.get("name"): e for e in a.iter("link")}
    links_b = {e.get("name"): e for e in b.iter("link")}
    joints_a = {e.get("name"): e for e in a.iter("joint")}
    joints_b = {e.get("name"): e for e in b.iter("joint")}
    for kind, ea, eb in (("link", links_a, links_b), ("joint", joints_a, joints_b)):
        found |= {(kind, n, "removed") for n in set(ea) - set(eb)}
        found |= {(kind, n, "added") for n in set(eb) - set(ea)}
    for name in set(joints_a) & set(joints_b):
        ja, jb = joints_a[name], joints_b[name]
        if ja.get("type") != jb.get("type"):
            found.add(("joint", name, "type"))
        if ja.find("origin").attrib != jb.find("origin").attrib:
            found.add(("joint", name, "origin"))
        if ja.find("axis") is not None and jb.find("axis") is not None and \
                _floats(ja.find("axis").get("xyz")) != _floats(jb.find("axis").get("xyz")):
            found.add(("joint", name, "axis"))
        la, lb = ja.find("limit"), jb.find("limit")
        if la is not None and lb is not None:
            for field in ("lower", "upper", "effort", "velocity"):
                if float(la.get(field)) != float(lb.get(field)):
                    found.add(("joint", name, f"limit.{field}"))
        da, db = ja.find("dynamics"), jb.find("dynamics")
        if da is not None and db is not None and da.attrib != db.attrib:
            found.add(("joint", name, "dynamics"))
    for name in set(links_a) & set(links_b):
        la, lb = links_a[name], links_b[name]
        if float(la.find("inertial/mass").get("value")) != float(lb.find("inertial/mass").get("value")):
            found.add(("link", name, "mass"))
        if la.find("inertial/inertia").attrib != lb.find("inertial/inertia").attrib:
            found.add(("link", name, "inertia"))
        if la.find("inertial/origin").get("xyz") != lb.find("inertial/origin").get("xyz"):
            found.add(("link", name, "com"))
        ga, gb = la.find("visual/geometry")[0], lb.find("visual/geometry")[0]
        if ga.tag != gb.tag or ga.attrib != gb.attrib:
            found.add(("link", name, "visual"))
    return found


def mutate(robot, rng: random.Random) -> str:
    """One random change of a kind a description commit makes; returns its kind."""
    joints = [j for j in robot.iter("joint") if j.get("type") != "fixed"]
    kind = rng.choice(["limit", "origin", "axis", "type", "mass", "inertia", "com", "box",
                       "dynamics", "remove-leaf", "add-leaf"])
    if kind == "limit":
        limit = rng.choice(joints).find("limit")
        field = rng.choice(["lower", "upper", "effort", "velocity"])
        limit.set(field, str(float(limit.get(field)) * 0.9 + 0.01))
    elif kind == "origin":
        origin = rng.choice(list(robot.iter("joint"))).find("origin")
        xyz = _floats(origin.get("xyz"))
        xyz[rng.randrange(3)] += 0.001
        origin.set("xyz", " ".join(map(str, xyz)))
    elif kind == "axis":
        axis = rng.choice(joints).find("axis")
        axis.set("xyz", {"1 0 0": "0 1 0", "0 1 0": "0 0 1", "0 0 1": "1 0 0"}[axis.get("xyz")])
    elif kind == "type":
        joint = rng.choice([j for j in joints if j.get("type") == "revolute"] or joints)
        joint.set("type", "prismatic" if joint.get("type") == "revolute" else "revolute")
    elif kind == "mass":
        mass = rng.choice(list(robot.iter("mass")))
        mass.set("value", str(float(mass.get("value")) + 0.25))
    elif kind == "inertia":
        inertia = rng.choice(list(robot.iter("inertia")))
        inertia.set("izz", str(float(inertia.get("izz")) * 1.5))
    elif kind == "com":
        origin = rng.choice(list(robot.iter("inertial"))).find("origin")
        origin.set("xyz", "0.01 0.02 0.03")
    elif kind == "box":
        geometry = rng.choice(list(robot.iter("geometry")))
        geometry.remove(geometry[0])
        etree.SubElement(geometry, "box", size="0.11 0.12 0.13")
    elif kind == "dynamics":
        dynamics = rng.choice(joints).find("dynamics")
        dynamics.set("damping", str(float(dynamics.get("damping")) + 0.5))
    elif kind == "remove-leaf":
        parents = {j.find("parent").get("link") for j in robot.iter("joint")}
        leaf = next(j for j in reversed(list(robot.iter("joint")))
                    if j.find("child").get("link") not in parents)
        link = next(l for l in robot.iter("link") if l.get("name") == leaf.find("child").get("link"))
        robot.remove(leaf)
        robot.remove(link)
    else:
        link = etree.SubElement(robot, "link", name="extra_link")
        joint = etree.SubElement(robot, "joint", name="extra_joint", type="fixed")
        etree.SubElement(joint, "parent", link="link0")
        etree.SubElement(joint, "child", link="extra_link")
        etree.SubElement(joint, "origin", xyz="0 0 0.5", rpy="0 0 0")
        inertial = etree.SubElement(link, "inertial")
        etree.SubElement(inertial, "origin", xyz="0 0 0", rpy="0 0 0")
        etree.SubElement(inertial, "mass", value="1")
        etree.SubElement(inertial, "inertia", ixx="0.1", iyy="0.1", izz="0.1", ixy="0", ixz="0",
                         iyz="0")
        geometry = etree.SubElement(etree.SubElement(link, "visual"), "geometry")
        etree.SubElement(geometry, "sphere", radius="0.05")
    return kind


@pytest.mark.parametrize("seed", range(12))
def test_random_changes_match_the_tests_own_comparison(write, seed):
    rng = random.Random(1000 + seed)
    before = random_robot(seed)
    after = random_robot(seed)
    kinds = [mutate(after, rng) for _ in range(rng.randint(1, 3))]
    expected = expected_changes(before, after)
    changes = diff_json(write, text(before), text(after))
    found = {(c["element"], c["name"], c["aspect"]) for c in changes}
    assert found == expected, kinds
    for change in changes:  # located at both sides (where the element exists there)
        if change["aspect"] != "removed":
            assert change["path"] == "robot.urdf" and change["line"] > 0
        if change["aspect"] != "added":
            assert change["base_path"] == "robot.urdf" and change["base_line"] > 0


def _rewritten(robot, rng: random.Random) -> str:
    """The same robot written again as a generator would: numbers with more digits (the same
    floats), attributes in another order, a tensor given about rotated axes with the rotated
    values, another indentation."""
    robot = etree.fromstring(etree.tostring(robot))
    for element in robot.iter():
        items = list(element.attrib.items())
        rng.shuffle(items)
        element.attrib.clear()
        for key, value in items:
            if key in ("xyz", "rpy", "size", "value", "lower", "upper", "effort", "velocity",
                       "radius", "length", "damping"):
                value = " ".join(repr(float(v) * (1 + 1e-13)) for v in value.split())
            element.set(key, value)
    for inertial in robot.iter("inertial"):  # the tensor about axes turned by an extra yaw
        origin, inertia = inertial.find("origin"), inertial.find("inertia")
        rpy = _floats(origin.get("rpy"))
        r = pin.rpy.rpyToMatrix(*rpy)
        tensor = np.array([[float(inertia.get("ixx")), float(inertia.get("ixy")), float(inertia.get("ixz"))],
                           [float(inertia.get("ixy")), float(inertia.get("iyy")), float(inertia.get("iyz"))],
                           [float(inertia.get("ixz")), float(inertia.get("iyz")), float(inertia.get("izz"))]])
        turn = pin.rpy.rpyToMatrix(0.3, -0.2, 0.7)
        new_r = r @ turn  # the new frame; the same physical tensor expressed in it
        new_tensor = new_r.T @ (r @ tensor @ r.T) @ new_r
        origin.set("rpy", " ".join(repr(float(v)) for v in pin.rpy.matrixToRpy(new_r)))
        for (i, j), name in {(0, 0): "ixx", (0, 1): "ixy", (0, 2): "ixz", (1, 1): "iyy",
                             (1, 2): "iyz", (2, 2): "izz"}.items():
            inertia.set(name, repr(float(new_tensor[i, j])))
    for element in robot.iter():
        element.text = element.tail = None
    etree.indent(robot, space="\t")
    return etree.tostring(robot, encoding="unicode")


@pytest.mark.parametrize("seed", range(6))
def test_a_rewritten_robot_is_no_change(write, seed):
    robot = random_robot(50 + seed)
    assert diff_json(write, text(robot), _rewritten(robot, random.Random(seed))) == []


def _world(xml: str) -> dict[str, pin.SE3]:
    model = pin.buildModelFromXML(xml)
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    return {f.name: data.oMf[i].copy() for i, f in enumerate(model.frames)
            if f.type == pin.FrameType.BODY}


@pytest.mark.parametrize("seed", range(8))
def test_origin_effect_agrees_with_pinocchio(write, seed):
    rng = random.Random(seed)
    before = random_robot(200 + seed, links=9)
    after = etree.fromstring(etree.tostring(before))
    joint = rng.choice(list(after.iter("joint")))
    origin = joint.find("origin")
    xyz, rpy = _floats(origin.get("xyz")), _floats(origin.get("rpy"))
    origin.set("xyz", " ".join(str(v + rng.uniform(-0.01, 0.01)) for v in xyz))
    origin.set("rpy", " ".join(str(v + rng.uniform(-0.05, 0.05)) for v in rpy))
    [change] = diff_json(write, text(before), text(after))
    assert (change["element"], change["name"], change["aspect"]) == ("joint", joint.get("name"), "origin")
    world_a, world_b = _world(text(before)), _world(text(after))
    moved = {name: np.linalg.norm(world_b[name].translation - world_a[name].translation)
             for name in world_a}
    below = [name for name in moved if moved[name] > 1e-12 or np.linalg.norm(
        pin.log3(world_a[name].rotation.T @ world_b[name].rotation)) > 1e-12]
    effect = change["effect"]
    assert effect["links_moved"] == len(below)
    assert abs(effect["max_displacement"] - max(moved.values())) < 1e-6
    child = joint.find("child").get("link")
    turn = np.linalg.norm(pin.log3(world_a[child].rotation.T @ world_b[child].rotation))
    assert abs(effect["max_rotation"] - turn) < 1e-6


def test_inertia_reports_principal_moments_and_relative_change(write):
    before = random_robot(7)
    after = etree.fromstring(etree.tostring(before))
    inertia = after.find("link/inertial/inertia")
    inertia.set("ixy", "0.004")
    [change] = diff_json(write, text(before), text(after))
    assert (change["element"], change["aspect"]) == ("link", "inertia")

    def tensor(robot):
        e = robot.find("link/inertial/inertia")
        v = {k: float(e.get(k)) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
        return np.array([[v["ixx"], v["ixy"], v["ixz"]], [v["ixy"], v["iyy"], v["iyz"]],
                         [v["ixz"], v["iyz"], v["izz"]]])

    ta, tb = tensor(before), tensor(after)
    assert np.allclose(change["before"], np.linalg.eigvalsh(ta), rtol=1e-12)
    assert np.allclose(change["after"], np.linalg.eigvalsh(tb), rtol=1e-12)
    assert math.isclose(change["relative_change"], np.linalg.norm(tb - ta) / np.linalg.norm(ta),
                        rel_tol=1e-9)


def test_a_renamed_chain_is_renamed_not_removed_and_added(write):
    before = random_robot(11, links=6)
    after_text = text(before)
    for i in (3, 4):
        after_text = after_text.replace(f'"link{i}"', f'"renamed_link{i}"')
    after_text = after_text.replace('"joint3"', '"renamed_joint3"')
    changes = diff_json(write, text(before), after_text)
    found = {(c["element"], c["before"], c["after"]) for c in changes}
    assert found == {("link", "link3", "renamed_link3"), ("link", "link4", "renamed_link4"),
                     ("joint", "joint3", "renamed_joint3")}
    assert {c["aspect"] for c in changes} == {"renamed"}


SHIFT = """<robot name="r">
  <link name="{root}"/>
  <link name="{body}"><inertial><mass value="4"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.02"/></inertial>
    <visual><geometry><box size="0.2 0.2 0.1"/></geometry></visual></link>
  <link name="arm"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.001"/></inertial></link>
  <joint name="{root}-{body}" type="fixed"><parent link="{root}"/><child link="{body}"/><origin rpy="0 0 3.141592653589793"/></joint>
  <joint name="pan" type="revolute"><parent link="{body}"/><child link="arm"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""


def test_a_name_moved_to_another_link_is_two_renames(write):
    """UR's 6f4ae5d: base_link_fixed -> base_link and base_link -> base_link_inertia. Matched
    by name, 'base_link' would be a link that lost its geometry and inertia, with one link
    removed and one added; by place, geometry and inertia it is two renames and a joint's."""
    changes = diff_json(write, SHIFT.format(root="base_link_fixed", body="base_link"),
                        SHIFT.format(root="base_link", body="base_link_inertia"))
    assert {(c["element"], c["aspect"], c["before"], c["after"]) for c in changes} == {
        ("link", "renamed", "base_link_fixed", "base_link"),
        ("link", "renamed", "base_link", "base_link_inertia"),
        ("joint", "renamed", "base_link_fixed-base_link", "base_link-base_link_inertia")}


RARE = """<robot name="r">
  <material name="steel"><color rgba="0.5 0.5 0.5 1"/></material>
  <link name="base"><visual><geometry><box size="0.1 0.1 0.1"/></geometry><material name="steel"/></visual></link>
  <link name="a"/><link name="b"/>
  <joint name="ja" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="{effort}" velocity="1"/>
    <safety_controller soft_lower_limit="{soft}" soft_upper_limit="0.9" k_position="10" k_velocity="1"/>
    <calibration rising="{rising}"/></joint>
  <joint name="jb" type="revolute"><parent link="base"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="ja" multiplier="{multiplier}"/></joint>
  <transmission name="t1"><type>transmission_interface/SimpleTransmission</type>
    <joint name="ja"><hardwareInterface>{interface}</hardwareInterface></joint></transmission>
  <gazebo reference="a"><mu1>{mu}</mu1></gazebo>
</robot>
"""
RARE_VALUES = {"effort": "1", "soft": "-0.9", "rising": "0.1", "multiplier": "1",
               "interface": "hardware_interface/EffortJointInterface", "mu": "0.5"}


@pytest.mark.parametrize(("field", "value", "expected"), [
    ("soft", "-0.8", ("joint", "ja", "safety_controller")),
    ("rising", "0.2", ("joint", "ja", "calibration")),
    ("multiplier", "-1", ("joint", "jb", "mimic")),
    ("interface", "hardware_interface/PositionJointInterface", ("transmission", "t1", "changed")),
    ("mu", "0.9", ("gazebo", "a", "changed")),
    ("effort", repr(1 + 2e-9), ("joint", "ja", "limit.effort")),  # beyond the relative 1e-9
    ("effort", repr(1 + 5e-10), None),  # within it: the same number
    ("mu", "5e-1", None),  # written another way
])
def test_each_aspect_and_the_number_equality(write, field, value, expected):
    changes = diff_json(write, RARE.format(**RARE_VALUES),
                        RARE.format(**{**RARE_VALUES, field: value}))
    assert [(c["element"], c["name"], c["aspect"]) for c in changes] == \
        ([expected] if expected else [])
    for change in changes:
        assert change["line"] and change["base_line"]


def test_a_material_redefined_and_a_visual_material_swapped(write):
    before = RARE.format(**RARE_VALUES)
    recoloured = before.replace('rgba="0.5 0.5 0.5 1"', 'rgba="0.6 0.5 0.5 1"')
    assert [(c["element"], c["name"], c["aspect"]) for c in diff_json(write, before, recoloured)] \
        == [("material", "steel", "material")]
    swapped = before.replace('<material name="steel"/>', '<material name="red"><color rgba="1 0 0 1"/></material>')
    found = {(c["element"], c["name"], c["aspect"]) for c in diff_json(write, before, swapped)}
    assert found == {("link", "base", "material"), ("material", "red", "added")}


def test_two_directories_are_two_snapshots(write, tmp_path):
    robot = random_robot(3)
    write(text(robot), "old/urdf/arm.urdf")
    changed = etree.fromstring(etree.tostring(robot))
    changed.find("joint/limit").set("effort", "999")
    write(text(changed), "new/urdf/arm.urdf")
    write(text(random_robot(4)), "new/urdf/second.urdf")
    result = run_urdftool("diff", tmp_path / "old", tmp_path / "new", "--format", "json",
                          "--trusted", "--timeout", "120", "--exit-code")
    assert result.code == 1, result.err  # something changed
    import json

    robots = {r["entry"]: r for r in json.loads(result.out)["robots"]}
    assert {e: r["status"] for e, r in robots.items()} == {"urdf/arm.urdf": "changed",
                                                         "urdf/second.urdf": "added"}
    [change] = robots["urdf/arm.urdf"]["changes"]
    assert (change["aspect"], change["after"]) == ("limit.effort", 999.0)
