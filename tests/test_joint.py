"""The `joint` rules: each one fires on a file that has the problem and stays quiet on the same
file without it; bad input (text where numbers belong, empty attributes) never crashes them."""

from __future__ import annotations

import math

import pytest

from urdftool.check import CheckOptions, check_file


def diagnostics(write, text: str, select: str = "joint", name: str = "robot.urdf"):
    return check_file(write(text, name), CheckOptions(select=[select])).diagnostics


def rules(write, text: str, select: str = "joint") -> list[str]:
    return [d.rule for d in diagnostics(write, text, select)]


def robot(*joints: str, extra: str = "") -> str:
    """A robot with one joint per argument, each from l0 to its own link: joint i on line
    3 + 3i, its inner XML on the line after.
    An argument is the joint's inner XML, optionally preceded by "TYPE=<type> " (default
    revolute)."""
    links = "".join(f'<link name="l{i}"/>' for i in range(len(joints) + 1))
    body = f'<robot name="r">\n  {links}\n'
    for i, joint in enumerate(joints):
        joint_type = "revolute"
        if joint.startswith("TYPE="):
            joint_type, _, joint = joint[len("TYPE="):].partition(" ")
        body += (f'  <joint name="j{i}" type="{joint_type}"><parent link="l0"/>'
                 f'<child link="l{i + 1}"/>\n    {joint}\n  </joint>\n')
    return body + extra + "</robot>\n"


GOOD = '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="2"/>'


def test_a_good_joint_is_quiet(write):
    assert rules(write, robot(GOOD)) == []


def test_missing_limit_on_revolute_and_prismatic_but_not_continuous(write):
    text = robot("TYPE=revolute <axis xyz='0 0 1'/>", "TYPE=prismatic <axis xyz='0 0 1'/>",
                 "TYPE=continuous <axis xyz='0 0 1'/>")
    found = diagnostics(write, text)
    assert [(d.rule, d.line) for d in found] == [("joint.missing-limit", 3),
                                                 ("joint.missing-limit", 6)]
    assert "continuous" in found[0].hint and "metres" in found[1].hint


def test_type_and_limit_attributes_are_left_to_schema(write):
    # an unknown type and a <limit> without effort/velocity are schema findings, not joint ones
    text = robot("TYPE=revolut " + GOOD, '<limit lower="-1" upper="1"/>')
    assert rules(write, text) == []


def test_lower_above_upper(write):
    found = diagnostics(write, robot('<limit lower="1" upper="-1" effort="1" velocity="1"/>'))
    assert [d.rule for d in found] == ["joint.lower-above-upper"]
    assert found[0].severity == "error" and 'lower="-1" upper="1"' in found[0].hint


def test_frozen_range_explicit_and_defaulted(write):
    text = robot('<limit lower="0.5" upper="0.5" effort="1" velocity="1"/>',
                 '<limit effort="1" velocity="1"/>',
                 'TYPE=prismatic <limit effort="1" velocity="1"/>')
    found = diagnostics(write, text)
    assert [d.rule for d in found] == ["joint.frozen-range"] * 3
    assert "lower = upper = 0.5" in found[0].message and 'type="fixed"' in found[0].hint
    assert "no lower/upper" in found[1].message and "continuous" in found[1].hint
    assert "continuous" not in found[2].hint  # a prismatic joint cannot be continuous


@pytest.mark.parametrize(("lower", "upper", "rule"), [
    ("-170", "170", "joint.range-in-degrees"),
    ("0", "90", "joint.range-in-degrees"),
    ("-6.28318530718", "6.28318530718", "joint.multi-turn-range"),  # UR / xArm: info only
    ("-1e16", "1e16", "joint.multi-turn-range"),
    ("-3.1416", "3.1416", None),  # one turn written with rounded pi
    ("-12", "12", None),  # under two turns each way: could be a multi-turn joint, never degrees
])
def test_wide_ranges(write, lower, upper, rule):
    found = diagnostics(write, robot(f'<limit lower="{lower}" upper="{upper}" effort="1" '
                                     'velocity="1"/>'))
    found = [d for d in found if d.rule != "joint.frozen-range"]
    if rule is None:
        assert [d.rule for d in found] in ([], ["joint.multi-turn-range"])
        assert all(d.severity == "info" for d in found)
    else:
        assert [d.rule for d in found] == [rule]
    if rule == "joint.range-in-degrees":
        assert found[0].severity == "warning"
        lo, hi = float(lower), float(upper)
        assert f'lower="{math.radians(lo):.6g}"' in found[0].hint
        assert f'upper="{math.radians(hi):.6g}"' in found[0].hint
    if rule == "joint.multi-turn-range":
        assert found[0].severity == "info"


def test_continuous_with_limits_only_when_narrower_than_a_turn(write):
    text = robot('TYPE=continuous <limit lower="-1" upper="1" effort="1" velocity="1"/>',
                 'TYPE=continuous <limit lower="-6.2832" upper="6.2832" effort="1" velocity="1"/>',
                 'TYPE=continuous <limit effort="1" velocity="1"/>')
    assert [(d.rule, d.line) for d in diagnostics(write, text)] == \
        [("joint.continuous-with-limits", 4)]  # the <limit> of the first joint


def test_zero_effort_and_velocity_graded_by_what_drives_the_joint(write):
    transmission = ('  <transmission name="t"><type>transmission_interface/SimpleTransmission'
                    '</type><joint name="j0"><hardwareInterface>hardware_interface/'
                    'EffortJointInterface</hardwareInterface></joint><actuator name="m"/>'
                    "</transmission>\n")
    zero = '<limit lower="-1" upper="1" effort="0" velocity="0"/>'
    passive = diagnostics(write, robot(zero))
    assert {(d.rule, d.severity) for d in passive} == {("joint.zero-effort", "info"),
                                                      ("joint.zero-velocity", "info")}
    driven = diagnostics(write, robot(zero, extra=transmission))
    assert {(d.rule, d.severity) for d in driven} == {("joint.zero-effort", "warning"),
                                                     ("joint.zero-velocity", "warning")}
    negative = diagnostics(write, robot('<limit lower="-1" upper="1" effort="-1" velocity="1"/>'))
    assert [(d.rule, d.severity) for d in negative] == [("joint.zero-effort", "warning")]


def test_zero_effort_on_a_mimic_follower_is_fine(write):
    text = robot(GOOD, '<limit lower="-1" upper="1" effort="0" velocity="0"/><mimic joint="j0"/>')
    assert rules(write, text) == []


def test_gazebo_plugin_joints_count_as_driven(write):
    plugin = ('  <gazebo><plugin name="dd" filename="libgazebo_ros_diff_drive.so">'
              "<leftJoint>j0</leftJoint></plugin></gazebo>\n")
    found = diagnostics(write, robot('TYPE=continuous <limit effort="0" velocity="5"/>',
                                     extra=plugin))
    assert [(d.rule, d.severity) for d in found] == [("joint.zero-effort", "warning")]


def test_axes(write):
    text = robot('<axis xyz="0 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>',
                 '<axis xyz="0 1 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>',
                 '<axis xyz="0 0.707107 0.707107"/><limit lower="-1" upper="1" effort="1" '
                 'velocity="1"/>',
                 'TYPE=fixed <axis xyz="0 0 0"/>')
    found = diagnostics(write, text)
    assert [(d.rule, d.severity, d.line) for d in found] == [
        ("joint.zero-axis", "error", 4), ("joint.axis-not-unit", "warning", 7),
        ("joint.fixed-with-axis", "info", 13)]
    assert 'xyz="0 0.707107 0.707107"' in found[1].hint
    assert found[0].column == 5  # the <axis> element, not the joint


def test_safety_controller(write):
    limit = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
    text = robot(
        limit + '<safety_controller soft_lower_limit="-0.9" soft_upper_limit="0.9"/>',
        limit + '<safety_controller soft_lower_limit="-1.5" soft_upper_limit="0.9" '
                'k_position="100" k_velocity="10"/>',
        limit + '<safety_controller soft_lower_limit="0.5" soft_upper_limit="0.5" '
                'k_position="100" k_velocity="10"/>',
        limit + '<safety_controller soft_lower_limit="-0.9" soft_upper_limit="0.9" '
                'k_position="0" k_velocity="10"/>',
        limit + '<safety_controller soft_lower_limit="-0.9" soft_upper_limit="0.9" '
                'k_position="100" k_velocity="10"/>')
    found = [(d.rule, d.severity, d.line) for d in diagnostics(write, text)]
    assert found == [("joint.safety-gains", "error", 4), ("joint.safety-gains", "warning", 4),
                     ("joint.safety-limits", "warning", 7), ("joint.safety-limits", "warning", 10),
                     ("joint.safety-gains", "info", 13)]


def test_negative_dynamics_and_calibration(write):
    limit = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
    text = robot(limit + '<dynamics damping="-0.5" friction="-1"/>',
                 limit + '<calibration rising="1.5" falling="0.2"/>',
                 limit + '<dynamics damping="0.5"/><calibration rising="0.5"/>')
    found = [(d.rule, d.line) for d in diagnostics(write, text)]
    assert found == [("joint.negative-dynamics", 4), ("joint.negative-dynamics", 4),
                     ("joint.calibration-outside-limits", 7)]


@pytest.mark.parametrize("limit", [
    '<limit lower="abc" upper="" effort="x" velocity=""/>',
    '<limit lower="nan" upper="inf" effort="inf" velocity="nan"/>',
    '<limit/>',
    '<limit lower="1e999" upper="-1e999" effort="1" velocity="1"/>',
])
def test_bad_values_never_crash(write, limit):
    text = robot(f'<axis xyz="a b c"/>{limit}<mimic joint=""/><dynamics damping="?"/>'
                 '<safety_controller soft_lower_limit="x" k_velocity="y"/>'
                 '<calibration rising="z"/>')
    report = check_file(write(text), CheckOptions())
    assert not [d for d in report.diagnostics if "internal error" in d.message]


def test_values_from_xacro_expressions_are_reported_at_the_source_line(write):
    text = ('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            '  <xacro:property name="deg" value="180"/>\n'
            '  <link name="a"/><link name="b"/>\n'
            '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
            '    <limit lower="${-deg}" upper="${deg}" effort="1" velocity="1"/>\n'
            '  </joint>\n</robot>\n')
    found = diagnostics(write, text, name="robot.urdf.xacro")
    assert [(d.rule, d.line, d.column) for d in found] == [("joint.range-in-degrees", 5, 5)]
    assert found[0].path.endswith("robot.urdf.xacro")


def test_inside_a_macro_the_call_site_is_named(write):
    text = ('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            '  <link name="a"/>\n'
            '  <xacro:macro name="arm" params="n">\n'
            '    <link name="l${n}"/>\n'
            '    <joint name="j${n}" type="revolute"><parent link="a"/><child link="l${n}"/>\n'
            '      <limit lower="${n}" upper="${-n}" effort="1" velocity="1"/>\n'
            '    </joint>\n  </xacro:macro>\n'
            '  <xacro:arm n="1"/>\n</robot>\n')
    found = diagnostics(write, text, name="robot.urdf.xacro")
    assert [(d.rule, d.line) for d in found] == [("joint.lower-above-upper", 6)]
    assert ":9" in found[0].message  # the macro call site
