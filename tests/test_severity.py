"""Severity from consequence (issue 14): an impossible tensor judged through the body a
simulator builds (fixed links lumped into their parent), one finding for a kinematics-only
robot, Gazebo's dropping of massless moving links. Merged-body numbers against pinocchio, which
lumps fixed links into their parent joint's body the same way."""

from __future__ import annotations

import pytest

from urdftool.check import CheckOptions, check_file
from urdftool.physics.links import RigidBodies

BASE = """<robot name="r">
  <link name="base_link">
    <inertial><origin xyz="0.01 -0.02 0.03" rpy="0.1 0.2 0.3"/><mass value="5"/>
      <inertia ixx="0.05" ixy="0.001" ixz="0" iyy="0.06" iyz="-0.002" izz="0.07"/></inertial>
    <collision><geometry><box size="0.4 0.3 0.2"/></geometry></collision></link>
  <joint name="cam_joint" type="{joint}"><parent link="{parent}"/><child link="camera"/>
    <origin xyz="0.2 0.05 0.1" rpy="0 0.5 1.0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="camera">
    <inertial><origin xyz="0.003 0 0.001" rpy="0.3 0 0"/><mass value="0.03"/>
      <inertia ixx="{moment}" ixy="0" ixz="0" iyy="{moment}" iyz="0" izz="{moment}"/></inertial>
    <collision><geometry><box size="0.02 0.02 0.02"/></geometry></collision></link>
  <joint name="mount" type="fixed"><parent link="base_link"/><child link="mount"/>
    <origin xyz="-0.1 0 0.15" rpy="0.4 0 0"/></joint>
  <link name="mount">
    <inertial><origin xyz="0 0.01 0"/><mass value="0.5"/>
      <inertia ixx="0.0004" ixy="0" ixz="0" iyy="0.0005" iyz="0" izz="0.0006"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
{extra}</robot>
"""


def robot_text(joint="fixed", parent="base_link", moment="0.0001", extra=""):
    return BASE.format(joint=joint, parent=parent, moment=moment, extra=extra)


def findings(write, text, select=("inertia",)):
    report = check_file(write(text), CheckOptions(select=list(select)))
    return [(d.rule, d.severity, d.message) for d in report.diagnostics]


def test_merged_body_matches_pinocchio(write):
    import pinocchio as pin

    from urdftool.loader import load
    from urdftool.model import build_robot

    path = write(robot_text(moment="0.0001"))
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    body = model.inertias[1]  # the free-flyer body: base_link with camera and mount lumped
    robot = build_robot(load(path))
    merged = RigidBodies(robot).merged("camera")
    assert merged.root == "base_link" and merged.links == 3
    assert merged.mass == pytest.approx(body.mass, rel=1e-12)
    assert merged.com == pytest.approx(tuple(body.lever), abs=1e-12)
    expected = sorted(float(v) for v in __import__("numpy").linalg.eigvalsh(body.inertia))
    assert merged.principal == pytest.approx(expected, rel=1e-9)


def test_placeholder_on_a_fixed_sensor_is_a_warning_with_its_effect(write):
    import numpy as np
    import pinocchio as pin

    (rule, severity, message), = findings(write, robot_text())
    assert (rule, severity) == ("inertia.exceeds-geometry", "warning")
    assert "joins 'base_link'" in message and "negligible" in message
    # the change quoted is the merged body's, with the tensor against a point mass: pinocchio
    moments = []
    for moment in ("0.0001", "0"):
        model = pin.buildModelFromUrdf(str(write(robot_text(moment=moment), f"m{moment}.urdf")),
                                       pin.JointModelFreeFlyer())
        moments.append(np.linalg.eigvalsh(model.inertias[1].inertia))
    change = max(abs(a - b) / b for a, b in zip(*moments))
    assert 0 < change < 0.01
    assert f"{100 * change:.3g}%" in message


def test_impossible_tensor_that_matters_stays_an_error(write):
    # the same placeholder a thousand times larger dominates the merged body
    (rule, severity, message), = findings(write, robot_text(moment="0.1"))
    assert (rule, severity) == ("inertia.exceeds-geometry", "error")
    assert "joins 'base_link'" in message and "negligible" not in message
    # on a moving joint the link is a body of its own: an error
    (rule, severity, message), = findings(write, robot_text(joint="revolute"))
    assert (rule, severity) == ("inertia.exceeds-geometry", "error")
    assert "joins" not in message
    # fixed to a link without mass, the camera is the whole body
    extra = ('  <link name="bracket"/>\n  <joint name="b" type="revolute"><parent '
             'link="base_link"/><child link="bracket"/><axis xyz="0 0 1"/>'
             '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n')
    assert ("inertia.exceeds-geometry", "error") in [
        (r, s) for r, s, _ in findings(write, robot_text(parent="bracket", extra=extra))]


def test_body_welded_to_the_world_never_moves(write):
    extra = ('  <link name="world"/>\n  <joint name="w" type="fixed"><parent link="world"/>'
             '<child link="base_link"/></joint>\n')
    (rule, severity, message), = findings(write, robot_text(moment="0.1", extra=extra))
    assert (rule, severity) == ("inertia.exceeds-geometry", "warning")
    assert "fixed to 'world'" in message


KINEMATIC = """<robot name="arm">
  <link name="base"/><link name="a"/><link name="b"/><link name="tool0"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="t" type="fixed"><parent link="b"/><child link="tool0"/></joint>
{extra}</robot>
"""


def test_kinematics_only_robot_is_one_finding(write):
    assert findings(write, KINEMATIC.format(extra="")) == [
        ("inertia.kinematics-only", "warning",
         ("robot 'arm': no link has an <inertial> (4 links, 2 moving joints): kinematics only, "
          "it cannot be simulated as is (PyBullet gives every link 1 kg, Gazebo drops every "
          "moving link)"))]
    # one link with an inertial: the others are reported one by one again
    one = KINEMATIC.replace('<link name="a"/>', '<link name="a"><inertial><mass value="1"/>'
                            '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>'
                            '</inertial></link>').format(extra="")
    assert [(r, s) for r, s, _ in findings(write, one)] == [
        ("inertia.massless-moving-link", "warning")]


def test_massless_link_between_joints_is_dropped_by_gazebo(write):
    inertial = ('<inertial><mass value="{0}"/><inertia ixx="{1}" ixy="0" ixz="0" iyy="{1}" '
                'iyz="0" izz="{1}"/></inertial>')
    text = (KINEMATIC
            .replace('<link name="base"/>', f'<link name="base">{inertial.format(2, 0.01)}</link>')
            .replace('<link name="a"/>', f'<link name="a">{inertial.format(0, 0)}</link>')
            .replace('<link name="b"/>', f'<link name="b">{inertial.format(1, 0.001)}</link>'))
    # a massless hip link is fine for PyBullet, pinocchio, Drake: nothing said
    assert findings(write, text.format(extra="")) == []
    gazebo = text.format(extra='  <gazebo><plugin name="p" filename="libp.so"/></gazebo>\n')
    (rule, severity, message), = findings(write, gazebo)
    assert (rule, severity) == ("inertia.massless-moving-link", "warning")
    assert "Gazebo's URDF reader drops it" in message and "(1 kg)" in message


def test_inertia_on_a_massless_static_root_is_a_warning(write):
    # pybullet_data writes static objects as mass 0 with a placeholder tensor: PyBullet keeps
    # them static and the tensor never acts; on a fixed link of a body with mass it does
    table = ('<robot name="t"><link name="top"><inertial><mass value="0"/><inertia ixx="1" '
             'ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>')
    assert [(r, s) for r, s, _ in findings(write, table)] == [
        ("inertia.mass-not-positive", "warning")]
    flange = robot_text().replace('<mass value="0.03"/>', '<mass value="0"/>')
    assert ("inertia.mass-not-positive", "error") in [
        (r, s) for r, s, _ in findings(write, flange)]
    # a base with a negative mass is no static massless body: the error stands
    negative = ('<robot name="t"><link name="base"><inertial><mass value="-1"/><inertia ixx="1" '
                'ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link><joint name="j" '
                'type="fixed"><parent link="base"/><child link="cam"/></joint><link name="cam">'
                '<inertial><mass value="0"/><inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" '
                'iyz="0" izz="1e-3"/></inertial></link></robot>')
    assert ("inertia.mass-not-positive", "error") in [
        (r, s) for r, s, m in findings(write, negative) if "'cam'" in m]


@pytest.mark.parametrize("rpy", ["inf 0 0", "nan 0 0", "1e308 0 0"])
def test_merged_body_of_unusable_poses_is_no_verdict_and_no_crash(write, rpy):
    text = robot_text().replace('<origin xyz="-0.1 0 0.15" rpy="0.4 0 0"/>',
                                f'<origin xyz="-0.1 0 0.15" rpy="{rpy}"/>')
    assert "inertia.exceeds-geometry" in [r for r, _, _ in findings(write, text)]


def test_sdf_ball_joint_is_reported_once(tmp_path):
    # the two massless links the URDF conversion puts into a ball joint are the converter's,
    # named by sdf.unsupported-joint; Gazebo reads the SDF itself, with no massless link (the
    # plugin is carried into the URDF as a <gazebo> block)
    from urdftool.check import CheckOptions, check_file

    inertial = ("<inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz>"
                "</inertia></inertial>")
    box = "<collision name='c'><geometry><box><size>0.1 0.1 0.1</size></box></geometry></collision>"
    path = tmp_path / "m.sdf"
    path.write_text(f"<sdf version='1.7'><model name='m'><link name='a'>{inertial}{box}</link>"
                    f"<link name='b'><pose>0 0 0.2 0 0 0</pose>{inertial}{box}</link>"
                    "<joint name='j' type='ball'><parent>a</parent><child>b</child></joint>"
                    "<plugin name='p' filename='libp.so'/></model></sdf>")
    rules = [d.rule for d in check_file(path, CheckOptions()).diagnostics
             if d.severity != "info"]
    assert "sdf.unsupported-joint" in rules
    assert "inertia.massless-moving-link" not in rules, rules


# -- issue 22.4: what urdftool's own look-through makes read was read by no consumer -----------

LOOK = """<robot name="r">
  <link name="base"/>
  <link name="arm"/>
  <joint name="j" type="revolute">
    <parent link="base"/>
    <child link="arm"/>
    <axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
    {element}
  </joint>
</robot>
"""


def test_look_through_on_text_no_consumer_reads_is_never_an_error(write):
    """<joint_properties> is not URDF: every parser ignores it, and with it its unparsable
    friction. urdftool's safe fix renames it <dynamics>; looking through that fix finds the bad
    number, which would matter only once the fix is applied."""
    path = write(LOOK.format(element='<joint_properties damping="0.0" friction="{x}"/>'))
    report = check_file(path, CheckOptions(select=["schema"]))
    found = {d.rule: d for d in report.diagnostics}
    assert found["schema.unknown-element"].fix is not None  # the rename urdftool looks through
    bad = found["schema.bad-number"]
    assert (bad.severity, bad.line) == ("warning", 9)
    assert "as written, <joint_properties> is read by no consumer" in bad.message
    # written where consumers read it, the same number is an error
    path = write(LOOK.format(element='<dynamics damping="0.0" friction="{x}"/>'), "read.urdf")
    [bad] = check_file(path, CheckOptions(select=["schema"])).diagnostics
    assert (bad.rule, bad.severity, bad.line) == ("schema.bad-number", "error", 9)


@pytest.mark.parametrize("moment", ["0.0012", "0.003", "0.006", "0.02"])
def test_merged_body_error_only_above_the_stated_fraction(write, moment):
    """issue 22.4: a placeholder on a fixed link changes the ~5.5 kg body it joins; urdftool
    calls that an error only above 10% (stated in the message), computed here with pinocchio,
    which lumps the fixed links into one body as Gazebo and Drake do."""
    import numpy as np
    import pinocchio as pin

    [(severity, message)] = [(s, m) for r, s, m in findings(write, robot_text(moment=moment))
                             if r == "inertia.exceeds-geometry"]
    moments = []
    for value in (moment, "0"):
        model = pin.buildModelFromUrdf(str(write(robot_text(moment=value), f"m{value}.urdf")),
                                       pin.JointModelFreeFlyer())
        moments.append(np.linalg.eigvalsh(model.inertias[1].inertia))
    change = max(abs(a - b) / b for a, b in zip(*moments))
    assert f"{100 * change:.3g}%" in message and "10%" in message
    assert severity == ("error" if change > 0.10 else "warning"), (change, message)


# -- issue 22.4: inertias simulation models set on purpose ---------------------------------------

AIRCRAFT = """<robot name="uav">
  <link name="base_link"><inertial><mass value="1.5"/>
    <inertia ixx="0.029" ixy="0" ixz="0" iyy="0.029" iyz="0" izz="0.055"/></inertial>
    <collision><geometry><box size="0.47 0.47 0.11"/></geometry></collision></link>
  <joint name="rotor_0_joint" type="continuous"><parent link="base_link"/><child link="rotor_0"/>
    <origin xyz="0.13 -0.22 0.023"/><axis xyz="0 0 1"/></joint>
  <link name="rotor_0"><inertial><mass value="0.005"/>
    <inertia ixx="9.75e-07" ixy="0" ixz="0" iyy="0.000273104" iyz="0" izz="0.000274004"/>
    </inertial>
    <collision><geometry><cylinder radius="0.128" length="0.005"/></geometry></collision></link>
  <joint name="elevon_joint" type="revolute"><parent link="base_link"/><child link="elevon"/>
    <origin xyz="-0.2 0.1 0"/><axis xyz="0 1 0"/>
    <limit lower="-0.5" upper="0.5" effort="1" velocity="1"/></joint>
  <link name="elevon"><inertial><mass value="{surface_mass}"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>
    <collision><geometry><box size="0.05 0.3 0.005"/></geometry></collision></link>
{plugins}</robot>
"""
PLUGINS = """  <gazebo><plugin name="rotor_0_motor_model" filename="libgazebo_motor_model.so">
    <jointName>rotor_0_joint</jointName><linkName>rotor_0</linkName></plugin></gazebo>
  <gazebo><plugin name="elevon_lift_drag" filename="libLiftDragPlugin.so">
    <link_name>elevon</link_name><control_joint_name>elevon_joint</control_joint_name>
  </plugin></gazebo>
"""


@pytest.mark.parametrize("plugins", [True, False])
def test_rotor_and_control_surface_inertias_are_the_models_convention(write, plugins):
    """PX4's iris rotor: 0.005 kg and izz 2.74e-4 kg·m², 3.3x m r² of its 0.128 m disc (the
    most any mass inside it can have about the axis): impossible, and set on purpose by the
    model that flies in software-in-the-loop. Named by its motor plugin it is a warning that
    says so; the same link without the plugin is the error it is."""
    text = AIRCRAFT.format(surface_mass="1e-05", plugins=PLUGINS if plugins else "")
    found = {m.split("'")[1]: (r, s, m) for r, s, m in findings(write, text)
             if r == "inertia.exceeds-geometry"}
    _, severity, message = found["rotor_0"]
    assert f"is {0.000274004 / (0.005 * 0.128 ** 2):.3g}x the most" in message
    assert severity == ("warning" if plugins else "error")
    assert ("rotor of the multicopter plugin 'libgazebo_motor_model.so'" in message) == plugins
    _, severity, message = found["elevon"]
    assert severity == ("warning" if plugins else "error")
    assert ("control surface of the plugin 'libLiftDragPlugin.so'" in message) == plugins


def test_a_heavy_control_surface_is_no_convention(write):
    text = AIRCRAFT.format(surface_mass="0.4", plugins=PLUGINS)
    found = {m.split("'")[1]: (r, s, m) for r, s, m in findings(write, text)
             if r == "inertia.exceeds-geometry"}
    assert found["elevon"][1] == "error" and "control surface" not in found["elevon"][2]
