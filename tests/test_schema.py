"""The `schema` family: unknown, misplaced, SDF-only and missing elements and attributes, and
values that do not parse, each at the line where it is written."""

from __future__ import annotations

import json

import pytest

from tests.conftest import ROOT
from urdftool.check import CheckOptions, check_file
from urdftool.rules.schema import SCHEMA_PATH, number_problem, rgba_problem, vector_problem


def diagnostics(path, family="schema"):
    return check_file(path, CheckOptions(select=[family])).diagnostics


def fired(path, rule_id):
    return [d for d in diagnostics(path, rule_id) if d.rule == rule_id]


def robot(body: str, attrs: str = 'name="r"') -> str:
    """A valid two-link robot with ``body`` added inside <robot>; body starts on line 3."""
    return (f'<?xml version="1.0"?>\n<robot {attrs}>\n{body}\n'
            '  <link name="base"/>\n  <link name="tool"/>\n'
            '  <joint name="tool_joint" type="fixed">\n    <parent link="base"/>\n'
            '    <child link="tool"/>\n  </joint>\n</robot>\n')


# -- the spec as data ---------------------------------------------------------------------------


def test_schema_is_data_visible_at_the_repository_root():
    assert (ROOT / "schemas" / "urdf.json").resolve() == SCHEMA_PATH.resolve()
    table = json.loads(SCHEMA_PATH.read_text(encoding="utf-8"))
    elements = table["elements"]
    # Every reference points at a definition.
    for definition in elements.values():
        for spec in definition.get("children", {}).values():
            ref = spec if isinstance(spec, str) else spec["ref"]
            assert ref in elements
    joint = elements["joint"]
    assert set(joint["children"]) >= {"origin", "parent", "child", "axis", "calibration",
                                      "dynamics", "limit", "safety_controller", "mimic"}
    assert joint["attributes"]["type"]["values"] == ["revolute", "continuous", "prismatic",
                                                     "fixed", "floating", "planar"]
    assert set(elements["geometry"]["children"]) >= {"box", "cylinder", "sphere", "mesh",
                                                     "capsule"}
    assert elements["gazebo"]["open"] is True
    assert {"hardware", "joint", "sensor", "gpio"} <= set(elements["ros2_control"]["children"])


# -- value syntax (as urdfdom reads it: see test_check_urdf_differential.py) --------------------


@pytest.mark.parametrize("text", ["1", "-1.5", "+2", "5.", ".5", "1e-3", "1E+3", "  0.5"])
def test_numbers_urdfdom_accepts(text):
    assert number_problem(text) is None


@pytest.mark.parametrize("text, why", [
    ("nan", "finite"), ("-inf", "finite"), ("Infinity", "finite"), ("1 ", "trailing"),
    ("", "empty"), ("0,5", "comma"), ("-1.57.", "not a number"), ("${pi}", "xacro"),
    ("0x10", "not a number"), ("1f", "not a number"),
])
def test_numbers_urdfdom_rejects(text, why):
    assert why in number_problem(text)


def test_vectors_and_colours():
    assert vector_problem("1 0 0", 3) is None
    assert vector_problem("  1  0 0 ", 3) is None
    assert "2 numbers, 3 expected" in vector_problem("1 0", 3)
    assert "4 numbers, 3 expected" in vector_problem("-3.14159 1.57079 0 0", 3)
    assert "comma" in vector_problem("0.07, 0, -0.69", 3)
    assert "finite" in vector_problem("nan 0 0", 3)
    assert rgba_problem("1 0.5 0 1") is None
    assert "outside [0, 1]" in rgba_problem("255 128 0 1")
    assert "3 numbers, 4 expected" in rgba_problem("1 0 0")


# -- unknown attributes and elements, with did-you-mean -----------------------------------------


@pytest.mark.parametrize("line, wrong, right", [
    (('  <link name="a"><visual><origin xyz="0 0 1" ryp="0 0 1"/>'
     '<geometry><box size="1 1 1"/></geometry></visual></link>'), "ryp", "rpy"),
    (('  <link name="a"><visual><origin xvz="0 0 1"/>'
     '<geometry><box size="1 1 1"/></geometry></visual></link>'), "xvz", "xyz"),
    (('  <link name="a"><inertial><mass value="1"/><inertia ixx="1" ixv="0" ixz="0" iyy="1" '
     'iyz="0" izz="1"/></inertial></link>'), "ixv", "ixy"),
])
def test_attribute_typo_is_named_with_the_right_spelling(write, line, wrong, right):
    path = write(robot(line + '\n  <joint name="ja" type="fixed"><parent link="tool"/>'
                       '<child link="a"/></joint>'))
    found = fired(path, "schema.unknown-attribute")
    assert len(found) == 1
    d = found[0]
    assert d.severity == "warning" and d.line == 3
    assert f"'{wrong}'" in d.message and f"did you mean '{right}'" in d.message
    assert d.column == line.index(wrong) + 1  # points at the attribute itself
    # The ixy typo also leaves <inertia> without its required ixy.
    if right == "ixy":
        assert [m.line for m in fired(path, "schema.missing-attribute")] == [3]


def test_unknown_geometry_is_an_error_with_did_you_mean(write):
    path = write(robot('  <link name="wheel">\n    <collision>\n      <geometry>\n'
                       '        <cvlinder radius="0.1" length="0.05"/>\n'
                       '      </geometry>\n    </collision>\n  </link>\n'
                       '  <joint name="jw" type="continuous"><parent link="base"/>'
                       '<child link="wheel"/></joint>'))
    [d] = fired(path, "schema.unknown-element")
    assert (d.severity, d.line) == ("error", 6)
    assert "did you mean <cylinder>" in d.message


def test_unknown_element_typo_warns_and_foreign_element_is_info(write):
    path = write(robot('  <link name="a">\n    <inertal>\n      <mass value="1"/>\n'
                       '    </inertal>\n    <self_filter/>\n  </link>\n'
                       '  <joint name="ja" type="fixed"><parent link="tool"/>'
                       '<child link="a"/></joint>'))
    found = {d.line: d for d in fired(path, "schema.unknown-element")}
    assert found[4].severity == "warning" and "did you mean <inertial>" in found[4].message
    assert found[7].severity == "info" and "self_filter" in found[7].message


def test_no_suggestion_for_a_name_already_present(write):
    # command_effort is close to effort, but effort is there: not a typo of it.
    path = write(robot('  <link name="a"/>\n  <joint name="ja" type="revolute">\n'
                       '    <parent link="tool"/><child link="a"/>\n'
                       '    <limit lower="-1" upper="1" effort="2" velocity="1" '
                       'command_effort="2"/>\n  </joint>'))
    [d] = fired(path, "schema.unknown-attribute")
    assert d.severity == "info" and "did you mean" not in d.message


def test_extensions_and_prefixed_names_are_not_reported(write):
    text = robot(
        '  <link name="a" drake:flag="1">\n'
        '    <contact><lateral_friction value="1"/><rolling_friction value="0.1"/>'
        '<friction_anchor/></contact>\n'
        '    <collision group="1" mask="2" concave="yes"><geometry><mesh filename="a.obj"/>'
        '</geometry></collision>\n'
        '    <visual><geometry><box size="1 1 1"/></geometry>\n'
        '      <material name="m"><color rgba="1 0 0 1"/><specular rgb="1 1 1"/></material>\n'
        '    </visual>\n'
        '    <drake:proximity_properties><drake:mu_static value="0.5"/>'
        '</drake:proximity_properties>\n'
        '  </link>\n'
        '  <joint name="ja" type="fixed"><parent link="tool"/><child link="a"/></joint>\n'
        '  <gazebo reference="a"><mu1>0.5</mu1><pose>0 0 0 0 0 0</pose>'
        '<plugin name="p" filename="x.so"><anything/></plugin></gazebo>\n'
        '  <drake:collision_filter_group name="g"/>',
        attrs='name="r" xmlns:drake="http://drake.mit.edu"')
    path = write(text)
    assert [d for d in diagnostics(path) if d.severity != "info"] == []
    assert diagnostics(path) == []


def test_transmissions_in_both_formats_are_valid(write):
    path = write(robot(
        '  <link name="a"/>\n'
        '  <joint name="ja" type="continuous"><parent link="tool"/><child link="a"/></joint>\n'
        '  <transmission name="old" type="pr2_mechanism_model/SimpleTransmission">\n'
        '    <joint name="ja"/>\n    <actuator name="motor"/>\n'
        '    <mechanicalReduction>50</mechanicalReduction>\n  </transmission>\n'
        '  <transmission name="new">\n'
        '    <type>transmission_interface/SimpleTransmission</type>\n'
        '    <joint name="ja"><hardwareInterface>hardware_interface/EffortJointInterface'
        '</hardwareInterface></joint>\n'
        '    <actuator name="motor2"><hardwareInterface>EffortJointInterface</hardwareInterface>'
        '<mechanicalReduction>1</mechanicalReduction></actuator>\n  </transmission>'))
    assert diagnostics(path) == []


def test_ros2_control_structure(write):
    good = robot(
        '  <ros2_control name="sys" type="system">\n'
        '    <hardware><plugin>mock_components/GenericSystem</plugin>'
        '<param name="rate">100</param></hardware>\n'
        '    <joint name="tool_joint">\n'
        '      <command_interface name="position"><param name="min">-1</param>'
        '<param name="max">1</param></command_interface>\n'
        '      <state_interface name="position"><param name="initial_value">0</param>'
        '</state_interface>\n    </joint>\n'
        '    <sensor name="ft"><state_interface name="force.x"/><param name="frame_id">'
        'tool</param></sensor>\n'
        '    <gpio name="io"><command_interface name="out"/><state_interface name="in"/></gpio>\n'
        '  </ros2_control>')
    assert diagnostics(write(good, "good.urdf")) == []
    bad = robot('  <ros2_control name="sys" type="sytem">\n'
                '    <joint name="tool_joint"><comand_interface name="position"/></joint>\n'
                '    <gpio><state_interface/></gpio>\n  </ros2_control>')
    found = {(d.rule, d.line) for d in diagnostics(write(bad, "bad.urdf"))}
    assert ("schema.bad-value", 3) in found  # type="sytem"
    assert ("schema.missing-element", 3) in found  # no <hardware>
    assert ("schema.unknown-element", 4) in found  # comand_interface
    assert ("schema.missing-attribute", 5) in found  # gpio and its interface need a name


# -- SDF in URDF, misplaced and duplicated elements ---------------------------------------------


def test_pose_in_a_link_says_to_use_origin(write):
    path = write(robot('  <link name="a">\n    <pose>0 0 0.1 0 0 0</pose>\n  </link>\n'
                       '  <joint name="ja" type="fixed"><parent link="tool"/>'
                       '<child link="a"/></joint>'))
    [d] = fired(path, "schema.sdf-element")
    assert (d.severity, d.line) == ("warning", 4)
    assert d.hint.startswith("URDF has no <pose>; use <origin xyz=")
    assert "inertial/visual/collision" in d.hint


def test_misplaced_elements_name_where_they_belong(write):
    path = write(robot('  <link name="a">\n    <origin xyz="0 0 1"/>\n'
                       '    <visual><geometry><mesh filename="a.stl"/><material name="red"/>'
                       '</geometry></visual>\n    <collision><material name="red"/>'
                       '<geometry><box size="1 1 1"/></geometry></collision>\n  </link>\n'
                       '  <joint name="ja" type="fixed"><parent link="tool"/>'
                       '<child link="a"/></joint>'))
    found = {d.line: d for d in fired(path, "schema.misplaced-element")}
    assert found[4].severity == "warning" and "belongs in" in found[4].message
    assert "<visual>" in found[5].message and found[5].severity == "warning"
    assert found[6].severity == "info"  # a colour on a collision: harmless


def test_second_origin_and_second_shape_are_ignored(write):
    path = write(robot('  <link name="a">\n    <visual><geometry><box size="1 1 1"/>\n'
                       '      <sphere radius="1"/></geometry></visual>\n  </link>\n'
                       '  <joint name="ja" type="fixed"><origin xyz="1 0 0"/>\n'
                       '    <origin rpy="0 0 1"/><parent link="tool"/><child link="a"/></joint>'))
    assert sorted(d.line for d in fired(path, "schema.duplicate-element")) == [5, 8]


# -- required elements and attributes -----------------------------------------------------------


def test_missing_required_attributes_and_elements(write):
    path = write(robot('  <link>\n    <visual><geometry><mesh/></geometry></visual>\n'
                       '    <collision><origin xyz="0 0 0"/></collision>\n'
                       '    <inertial><mass>2</mass></inertial>\n  </link>\n'
                       '  <joint name="ja" type="revolute"><parent link="tool"/>\n'
                       '    <limit lower="0" upper="1"/>\n  </joint>\n'
                       '  <material name="plain"/>'))
    attributes = {(d.line, d.message.split("'")[1]) for d in
                  fired(path, "schema.missing-attribute")}
    assert (3, "name") in attributes  # <link> without name
    assert (4, "filename") in attributes  # <mesh>
    assert (6, "value") in attributes  # SDF-style <mass>2</mass>
    assert {(9, "effort"), (9, "velocity")} <= attributes
    mass = next(d for d in fired(path, "schema.missing-attribute") if d.line == 6)
    assert 'value="2"' in mass.hint
    elements = {(d.line, d.message) for d in fired(path, "schema.missing-element")}
    assert any(line == 5 and "<geometry>" in m for line, m in elements)
    assert any(line == 6 and "<inertia>" in m for line, m in elements)
    assert any(line == 8 and "<child>" in m for line, m in elements)


def test_geometry_without_shape(write):
    path = write(robot('  <link name="a"><visual><geometry/></visual></link>\n'
                       '  <joint name="ja" type="fixed"><parent link="tool"/>'
                       '<child link="a"/></joint>'))
    [d] = fired(path, "schema.missing-element")
    assert d.line == 3 and "no shape" in d.message


# -- values -------------------------------------------------------------------------------------


def test_bad_values_are_located(write):
    path = write(robot(
        '  <link name="a">\n'
        '    <inertial><mass value="nan"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" '
        'izz="inf"/></inertial>\n'
        '    <visual><origin xyz="0.07, 0, 0"/><geometry><box size="1 1"/></geometry>\n'
        '      <material name="o"><color rgba="255 128 0 1"/></material></visual>\n'
        '  </link>\n'
        '  <joint name="ja" type="revolut"><parent link="tool"/><child link="a"/>\n'
        '    <limit lower="-1.57." upper="1.57" effort="1" velocity="1"/></joint>'))
    by_rule: dict[str, list[int]] = {}
    for d in diagnostics(path):
        by_rule.setdefault(d.rule, []).append(d.line)
    assert sorted(by_rule["schema.bad-number"]) == [4, 4, 9]
    assert sorted(by_rule["schema.bad-vector"]) == [5, 5]
    assert by_rule["schema.bad-rgba"] == [6]
    assert by_rule["schema.bad-value"] == [8]
    [typo] = fired(path, "schema.bad-value")
    assert "did you mean 'revolute'" in typo.message


def test_pybullet_spherical_joint_is_an_error_that_names_pybullet(write):
    path = write(robot('  <link name="a"/>\n  <joint name="ja" type="spherical">'
                       '<parent link="tool"/><child link="a"/></joint>'))
    [d] = fired(path, "schema.bad-value")
    assert d.severity == "error" and "PyBullet" in d.message


@pytest.mark.parametrize("attrs, fires", [
    ('name="r"', True), ('name="r" version="1.0"', True), ('name="r" version="1.1"', False)])
def test_capsule_needs_version_1_1(write, attrs, fires):
    path = write(robot('  <link name="a"><collision><geometry><capsule radius="0.1" '
                       'length="0.5"/></geometry></collision></link>\n'
                       '  <joint name="ja" type="fixed"><parent link="tool"/>'
                       '<child link="a"/></joint>', attrs=attrs))
    assert bool(fired(path, "schema.needs-version")) == fires


def test_unsupported_version_is_rejected(write):
    path = write(robot("", attrs='name="r" version="2.0"'))
    [d] = fired(path, "schema.bad-value")
    assert d.line == 2 and "1.0, 1.1, 1.2" in d.message


def test_pybullet_plane_is_a_vendor_extension(write):
    path = write(robot('  <link name="floor"><collision><geometry><plane normal="0 0 1"/>'
                       '</geometry></collision></link>\n'
                       '  <joint name="jf" type="fixed"><parent link="tool"/>'
                       '<child link="floor"/></joint>'))
    [d] = diagnostics(path)
    assert (d.rule, d.severity, d.line) == ("schema.vendor-extension", "info", 3)


def test_root_that_is_not_robot(write):
    path = write('<?xml version="1.0"?>\n<model name="x">\n  <link name="a"/>\n</model>\n')
    [d] = fired(path, "schema.unknown-element")
    assert (d.severity, d.line) == ("error", 2)


# -- xacro: findings point into the .xacro file -------------------------------------------------


def test_xacro_typo_is_located_in_the_macro_body(write):
    path = write(
        '<?xml version="1.0"?>\n'
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:macro name="leg" params="side">\n'
        '    <link name="${side}_leg">\n'
        '      <visual><origin xyz="0 0 0" ryp="0 0 1"/>\n'
        '        <geometry><box size="0.1 0.1 0.5"/></geometry></visual>\n'
        '    </link>\n'
        '    <joint name="${side}_hip" type="fixed"><parent link="base"/>'
        '<child link="${side}_leg"/></joint>\n'
        '  </xacro:macro>\n'
        '  <link name="base"/>\n'
        '  <xacro:leg side="left"/>\n'
        '  <xacro:leg side="right"/>\n'
        '</robot>\n', "robot.urdf.xacro")
    found = fired(path, "schema.unknown-attribute")
    assert [d.line for d in found] == [5]  # one finding per written line (issue 13)...
    assert found[0].instances == 2  # ...with the two instances' call sites
    assert [[site.rsplit(":", 1)[1] for site in chain] for chain in found[0].call_sites] == \
        [["11"], ["12"]]
    assert all(d.path.endswith("robot.urdf.xacro") for d in found)
    assert all("did you mean 'rpy'" in d.message for d in found)


# -- the seed robots ----------------------------------------------------------------------------


def test_dual_arm_published_ryp_typos_are_found():
    published = ROOT / "robots" / "dual_arm" / "published" / "test.xacro"
    found = fired(published, "schema.unknown-attribute")
    assert found and all("'ryp'" in d.message and "'rpy'" in d.message for d in found)
    corrected = ROOT / "robots" / "dual_arm" / "corrected" / "test.xacro"
    assert [d for d in diagnostics(corrected) if d.severity != "info"] == []


def test_rpy_and_quaternion_together(write):
    path = write(robot('  <link name="a"/>\n  <joint name="ja" type="fixed">\n'
                       '    <origin rpy="0 0 1" quat_xyzw="0 0 0 1"/>\n'
                       '    <parent link="tool"/><child link="a"/>\n  </joint>',
                       attrs='name="r" version="1.1"'))
    [d] = fired(path, "schema.bad-value")
    assert d.line == 5 and "rpy and quat_xyzw" in d.message


@pytest.mark.parametrize("version, joint_type, fires", [
    ("1.2", "revolute", True), ("1.2", "prismatic", True), ("1.2", "continuous", False),
    ("1.1", "revolute", False)])
def test_urdf_1_2_needs_both_position_limits(write, version, joint_type, fires):
    path = write(robot('  <link name="a"/>\n  <joint name="ja" type="' + joint_type + '">\n'
                       '    <parent link="tool"/><child link="a"/>\n'
                       '    <limit upper="1" effort="1" velocity="1"/>\n  </joint>',
                       attrs=f'name="r" version="{version}"'))
    found = fired(path, "schema.missing-attribute")
    assert [(d.line, "'lower'" in d.message) for d in found] == ([(6, True)] if fires else [])


def test_old_unprefixed_xacro_is_left_to_the_xacro_family(write):
    write('<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
          '  <xacro:macro name="body"><link name="base"/></xacro:macro>\n</robot>\n',
          "body.urdf.xacro")
    path = write('<?xml version="1.0"?>\n'
                 '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                 '  <xacro:include filename="body.urdf.xacro"/>\n'
                 '  <body/>\n  <link name="tool"/>\n</robot>\n', "robot.urdf.xacro")
    report = check_file(path, CheckOptions(select=["schema", "xacro"]))
    assert any(d.rule == "xacro.unprefixed-macro-call" and d.line == 4
               for d in report.diagnostics)
    assert not [d for d in report.diagnostics if d.rule.startswith("schema.")]


def test_urdf_frame_names_the_consumer_that_reads_it(tmp_path):
    """issue 22.4: Drake's URDF parser reads <robot><frame>; the finding says so (checked here
    with Drake itself) instead of 'URDF parsers ignore it'."""
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    from urdftool.check import CheckOptions, check_file

    text = ('<robot name="r"><link name="a"/>'
            '<frame name="tip" link="a" xyz="0 0 0.1" rpy="0 0 0"/></robot>')
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModelsFromString(text, "urdf")
    plant.Finalize()
    assert list(plant.GetFrameByName("tip").GetFixedPoseInBodyFrame().translation()) == \
        [0.0, 0.0, 0.1]
    path = tmp_path / "r.urdf"
    path.write_text(text)
    [d] = [d for d in check_file(path, CheckOptions(select=["schema"])).diagnostics]
    assert d.rule == "schema.sdf-element"
    assert "Drake's URDF parser reads it" in d.message and "ignore it" in d.message
    assert "URDF parsers ignore it" not in d.message
