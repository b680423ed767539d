"""The `gazebo` rules, on small robots and on the m2wr seed: its diff-drive plugin's
wheelSeparation (0.2) disagrees with the wheel joints (0.3 m apart), and its left wheel joint
sits on the robot's right side."""

from __future__ import annotations

from pathlib import Path

from urdftool.check import CheckOptions, check_file
from urdftool.rules.gazebo import gazebo_materials

ROOT = Path(__file__).resolve().parent.parent
M2WR = ROOT / "robots" / "m2wr"

BASE = """<robot name="r">
  <link name="base"/>
  <link name="wl"><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry>
    </collision></link>
  <link name="wr"><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry>
    </collision></link>
  <joint name="left" type="continuous"><parent link="base"/><child link="wl"/>
    <origin xyz="0 0.1 0" rpy="-1.5708 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="right" type="continuous"><parent link="base"/><child link="wr"/>
    <origin xyz="0 -0.1 0" rpy="-1.5708 0 0"/><axis xyz="0 0 1"/></joint>
"""


def found(write, text: str, name="robot.urdf"):
    report = check_file(write(text, name), CheckOptions(select=["gazebo"]))
    return report.diagnostics


def test_references_to_links_and_joints(write):
    text = BASE + ('  <gazebo reference="wl"><mu1>1</mu1></gazebo>\n'
                   '  <gazebo reference="left"><provideFeedback>true</provideFeedback></gazebo>\n'
                   '  <gazebo reference="wll"><mu1>1</mu1></gazebo>\n'
                   "  <gazebo><static>false</static></gazebo>\n</robot>\n")
    diagnostics = found(write, text)
    assert [(d.rule, d.severity, d.line) for d in diagnostics] == \
        [("gazebo.unknown-reference", "warning", 13)]
    assert "did you mean 'wl'" in diagnostics[0].hint


def test_plugin_joint_and_link_parameters(write):
    text = BASE + """  <gazebo>
    <plugin name="jsp" filename="libgazebo_ros_joint_state_publisher.so">
      <jointName>left, rigth</jointName></plugin>
    <plugin name="p3d" filename="libgazebo_ros_p3d.so"><bodyName>left</bodyName></plugin>
    <plugin name="ros2" filename="libgazebo_ros_joint_state_publisher.so">
      <joint_name>wl</joint_name><joint_name>right</joint_name></plugin>
    <plugin name="gz" filename="gz-sim-diff-drive-system">
      <left_joint>left</left_joint><right_joint>right</right_joint>
      <wheel_separation>0.2</wheel_separation><wheel_radius>0.05</wheel_radius></plugin>
  </gazebo>
</robot>
"""
    diagnostics = found(write, text)
    assert [(d.rule, d.line) for d in diagnostics] == [
        ("gazebo.plugin-unknown-joint", 13), ("gazebo.plugin-unknown-link", 14),
        ("gazebo.plugin-unknown-joint", 16)]
    assert "'rigth'" in diagnostics[0].message and "'right'" in diagnostics[0].hint
    assert "a joint, not a link" in diagnostics[1].message and "'wl'" in diagnostics[1].hint
    assert "a link, not a joint" in diagnostics[2].message and "'left'" in diagnostics[2].hint


def diff_drive(separation="0.2", diameter="0.1", left="left", right="right") -> str:
    return (f'  <gazebo><plugin name="dd" filename="libgazebo_ros_diff_drive.so">\n'
            f"    <leftJoint>{left}</leftJoint><rightJoint>{right}</rightJoint>\n"
            f"    <wheelSeparation>{separation}</wheelSeparation>\n"
            f"    <wheelDiameter>{diameter}</wheelDiameter>\n"
            f"    <robotBaseFrame>base</robotBaseFrame></plugin></gazebo>\n</robot>\n")


def test_drive_geometry_agrees(write):
    assert found(write, BASE + diff_drive()) == []


def test_drive_geometry_separation_diameter_and_sides(write):
    diagnostics = found(write, BASE + diff_drive("0.35", "0.2", "right", "left"))
    assert [(d.rule, d.line) for d in diagnostics] == [("gazebo.drive-geometry", 10),
                                                       ("gazebo.drive-geometry", 13),
                                                       ("gazebo.drive-geometry", 14)]
    sides, separation, diameter = diagnostics  # sides: at the <origin> of the "left" joint
    assert "right side" in sides.message
    assert "0.2 m apart" in separation.message and "<wheelSeparation>0.2<" in separation.hint
    assert "radius 0.05" in diameter.message and "<wheelDiameter>0.1<" in diameter.hint


def test_drive_geometry_through_a_base_footprint_and_rotated_frames(write):
    # the wheels hang off a rotated intermediate link; robotBaseFrame is base
    text = BASE.replace('<link name="base"/>', '<link name="base"/><link name="mid"/>').replace(
        '<parent link="base"/><child link="wl"/>', '<parent link="mid"/><child link="wl"/>'
    ).replace('<parent link="base"/><child link="wr"/>', '<parent link="mid"/><child link="wr"/>'
              ).replace('xyz="0 0.1 0"', 'xyz="0.1 0 0"').replace('xyz="0 -0.1 0"',
                                                                 'xyz="-0.1 0 0"')
    text += ('  <joint name="m" type="fixed"><parent link="base"/><child link="mid"/>\n'
             '    <origin rpy="0 0 1.5707963267948966"/></joint>\n')
    assert found(write, text + diff_drive()) == []


def test_gazebo_materials(write):
    text = BASE + ('  <gazebo reference="wl"><material>Gazebo/Gray</material></gazebo>\n'
                   '  <gazebo reference="wr"><material>Gazebo/orange</material></gazebo>\n'
                   '  <gazebo reference="base"><material>Gazebo/Zzzzzz</material></gazebo>\n'
                   '  <gazebo reference="left"><material>MyRobot/Skin</material></gazebo>\n'
                   "</robot>\n")
    diagnostics = found(write, text)
    assert [(d.rule, d.severity, d.line) for d in diagnostics] == [
        ("gazebo.unknown-material", "warning", 11), ("gazebo.unknown-material", "warning", 12),
        ("gazebo.unknown-material", "info", 13)]
    assert "'Gazebo/Grey'" in diagnostics[0].message
    assert "'Gazebo/Orange'" in diagnostics[1].message


def test_material_list_is_packaged():
    names = gazebo_materials()
    assert {"Gazebo/Orange", "Gazebo/Blue", "Gazebo/FlatBlack", "Gazebo/Grey"} <= names
    assert all(name.startswith("Gazebo/") for name in names)


def _seed(kind: str) -> Path:
    path = M2WR / kind / "m2wr.xacro"
    return path


def test_m2wr_published_diff_drive():
    path = _seed("published")
    diagnostics = check_file(path, CheckOptions(select=["gazebo"])).diagnostics
    lines = path.read_text().splitlines()
    separation = next(i for i, line in enumerate(lines, 1) if "<wheelSeparation>" in line)
    left_joint = next(i for i, line in enumerate(lines, 1) if 'joint name="joint_left_wheel"'
                      in line)
    left_origin = next(i for i, line in enumerate(lines[left_joint:], left_joint + 1)
                       if "<origin" in line)  # README: 117 / 144, the swapped origins
    assert [(d.rule, d.line) for d in diagnostics] == [("gazebo.drive-geometry", separation),
                                                       ("gazebo.drive-geometry", left_origin)]
    assert "is 0.2 but" in diagnostics[0].message and "0.3 m apart" in diagnostics[0].message
    assert "right side" in diagnostics[1].message


def test_m2wr_corrected_is_clean():
    path = _seed("corrected")
    assert check_file(path, CheckOptions(select=["gazebo"])).diagnostics == []


def test_frame_parameters_name_tf_frames_not_links(write):
    # issue 14: frame ids are TF frames (a leading "/" is old tf style, `odom` is no link);
    # only the parameters a plugin looks up in the model (bodyName...) must name links
    text = BASE + """  <gazebo>
    <plugin name="skid" filename="libgazebo_ros_skid_steer_drive.so">
      <robotBaseFrame>/base</robotBaseFrame><odometryFrame>odom</odometryFrame></plugin>
    <plugin name="imu" filename="libgazebo_ros_imu.so">
      <bodyName>base</bodyName><frameName>imu_frame</frameName></plugin>
    <plugin name="ros2" filename="libgazebo_ros_diff_drive.so">
      <odometry_frame>odom</odometry_frame><robot_base_frame>base_footprint</robot_base_frame>
      <frame_id>/camera_optical</frame_id></plugin>
    <plugin name="p3d" filename="libgazebo_ros_p3d.so"><bodyName>/base</bodyName></plugin>
  </gazebo>
</robot>
"""
    diagnostics = found(write, text)
    assert [(d.rule, d.line) for d in diagnostics] == [("gazebo.plugin-unknown-link", 19)]
    assert "'/base'" in diagnostics[0].message  # GetLink("/base") finds no link


# -- issue 22.3: an include that cannot be read is one finding, not one per name in it ----------

ROVER = """<?xml version="1.0"?>
<sdf version="1.6">
  <model name="rover">
    <link name="chassis">
      <inertial><mass>10</mass><inertia><ixx>0.5</ixx><ixy>0</ixy><ixz>0</ixz><iyy>0.5</iyy>
        <iyz>0</iyz><izz>0.5</izz></inertia></inertial>
    </link>
    <include><uri>model://rover_wheel</uri><name>left_wheel</name></include>
    <include><uri>model://rover_wheel</uri><name>right_wheel</name></include>
    <joint name="left_wheel_hinge" type="revolute">
      <parent>chassis</parent><child>left_wheel::wheel</child><axis><xyz>0 1 0</xyz></axis>
    </joint>
    <joint name="right_wheel_hinge" type="revolute">
      <parent>chassis</parent><child>right_wheel::wheel</child><axis><xyz>0 1 0</xyz></axis>
    </joint>
    <plugin name="diff_drive" filename="libgazebo_ros_diff_drive.so">
      <left_joint>left_wheel_hinge</left_joint><right_joint>right_wheel_hinge</right_joint>
    </plugin>
    <plugin name="p3d" filename="libgazebo_ros_p3d.so"><body_name>left_wheel::wheel</body_name>
    </plugin>
    <plugin name="jsp" filename="libgazebo_ros_joint_state_publisher.so">
      <joint_name>left_wheel::wheel_joint</joint_name><joint_name>{typo}</joint_name>
    </plugin>
  </model>
</sdf>
"""
WHEEL = """<?xml version="1.0"?>
<sdf version="1.6"><model name="rover_wheel">
  <link name="wheel"><inertial><mass>1</mass><inertia><ixx>0.01</ixx><ixy>0</ixy><ixz>0</ixz>
    <iyy>0.01</iyy><iyz>0</iyz><izz>0.01</izz></inertia></inertial></link>
  <joint name="wheel_joint" type="fixed"><parent>wheel</parent><child>tyre</child></joint>
  <link name="tyre"><inertial><mass>0.1</mass><inertia><ixx>0.001</ixx><ixy>0</ixy><ixz>0</ixz>
    <iyy>0.001</iyy><iyz>0</iyz><izz>0.001</izz></inertia></inertial></link>
</model></sdf>
"""


def test_unresolved_sdf_include_is_the_one_finding(tmp_path, monkeypatch):
    """The wheel model is not on the model path: its include is the one cause. The joints that
    name its link, and the plugins that name those joints or its link, are not findings of
    their own (there were 2 sdf.missing-frame, 3 plugin-unknown-joint, 1 plugin-unknown-link
    and a second sdf.include); a name that the include would not define still is."""
    path = tmp_path / "rover.sdf"
    path.write_text(ROVER.format(typo="chasis_joint"))
    report = check_file(path, CheckOptions())
    errors = [(d.rule, d.line) for d in report.diagnostics if d.severity == "error"]
    assert errors == [("sdf.include", 8), ("gazebo.plugin-unknown-joint", 21)], errors
    include = next(d for d in report.diagnostics if d.rule == "sdf.include")
    assert "model 'left_wheel' is left out" in include.message
    assert "1 more include(s) of it (model(s) 'right_wheel')" in include.message
    # the same through the sandboxed reader (--untrusted, CI): what is left out travels with it
    from urdftool.physics import meshes
    from urdftool.source import LoadOptions

    monkeypatch.setattr(meshes, "PARSER", meshes.PARSER)  # an untrusted run installs its own
    untrusted = check_file(path, CheckOptions(load=LoadOptions(untrusted=True)))
    assert [(d.rule, d.line, d.message) for d in untrusted.diagnostics] == \
        [(d.rule, d.line, d.message) for d in report.diagnostics]
    # with the model found, the same names are checked, and all of them resolve
    (tmp_path / "models" / "rover_wheel").mkdir(parents=True)
    (tmp_path / "models" / "rover_wheel" / "model.sdf").write_text(WHEEL)
    (tmp_path / "models" / "rover_wheel" / "model.config").write_text(
        '<model><name>rover_wheel</name><sdf version="1.6">model.sdf</sdf></model>')
    path.write_text(ROVER.format(typo="left_wheel_hinge"))
    options = CheckOptions()
    options.load = LoadOptions(sdf_model_paths=[str(tmp_path / "models")])
    report = check_file(path, options)
    assert [d.rule for d in report.diagnostics if d.severity == "error"] == []


def test_drive_geometry_on_wheels_that_are_no_axle(write):
    """Issue 29: a diff-drive plugin on two omni wheels 120 degrees apart got a wheel
    separation computed along one wheel's axis. The axes are compared first: one finding says
    the plugin assumes coaxial wheels, with the angle the test computes from the joints."""
    import math

    import numpy as np
    from scipy.spatial.transform import Rotation

    def wheel(name, link, yaw):
        # the wheel's axis is the joint frame's z, turned by rpy (-pi/2, 0, yaw)
        x, y = 0.1 * math.cos(yaw + math.pi / 2), 0.1 * math.sin(yaw + math.pi / 2)
        return (f'  <joint name="{name}" type="continuous"><parent link="base"/>'
                f'<child link="{link}"/>\n    <origin xyz="{x!r} {y!r} 0" '
                f'rpy="-1.5707963267948966 0 {yaw!r}"/><axis xyz="0 0 1"/></joint>\n')

    yaws = (0.0, 2 * math.pi / 3)
    text = BASE.split('  <joint name="left"')[0] + wheel("left", "wl", yaws[0]) + \
        wheel("right", "wr", yaws[1])
    text += diff_drive()
    diagnostics = found(write, text)
    plugin_line = text[:text.index("<leftJoint>")].count("\n") + 1
    assert [(d.rule, d.line) for d in diagnostics] == [("gazebo.drive-geometry", plugin_line)], \
        [d.message for d in diagnostics]
    axes = [Rotation.from_euler("xyz", (-math.pi / 2, 0, yaw)).apply((0, 0, 1)) for yaw in yaws]
    angle = math.degrees(math.acos(float(np.dot(*axes))))
    assert f"{angle:.3g} degrees apart" in diagnostics[0].message
    assert "assumes coaxial wheels" in diagnostics[0].message
    assert "separation" not in diagnostics[0].message.split("assumes")[0]
    # mirrored wheels (one axis the other's opposite) are one axle: compared as before
    mirrored = BASE.replace('rpy="-1.5708 0 0"/><axis xyz="0 0 1"/></joint>\n  <joint name="right"',
                            'rpy="1.5708 0 0"/><axis xyz="0 0 -1"/></joint>\n  <joint name="right"')
    assert found(write, mirrored + diff_drive()) == []
