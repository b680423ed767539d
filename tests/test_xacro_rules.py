"""The `xacro` rules: xacro's own errors explained and located, and old unprefixed tags that
xacro 2 copies through silently (the smartcar seed is the real case: its macros are never
expanded and the robot comes out empty)."""

from __future__ import annotations

from pathlib import Path

import pytest

from urdftool.check import CheckOptions, check_file

ROOT = Path(__file__).resolve().parent.parent
SMARTCAR = ROOT / "robots" / "smartcar"
HEAD = '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'


def found(path, select="xacro", look_through=True):
    return check_file(path, CheckOptions(select=[select], look_through=look_through)).diagnostics


@pytest.mark.parametrize(("body", "line", "message", "hint"), [
    ('  <link name="${base}"/>\n', 2, "undefined property 'base'", '<xacro:property name="base"'),
    ('  <xacro:property name="wheel_radius" value="1"/>\n  <link name="${wheel_radus}"/>\n', 3,
     "undefined property 'wheel_radus'", "did you mean 'wheel_radius'?"),
    ('  <link name="${late}"/>\n  <xacro:property name="late" value="x"/>\n', 2,
     "property 'late' is used before it is defined", "move its <xacro:property> above"),
    ('  <link name="$(arg prefix)"/>\n', 2, ("$(arg prefix) is used but the argument is not "
     "defined"), '<xacro:arg name="prefix" default="..."/>, or pass prefix:=VALUE'),
    ("  <xacro:wheel/>\n", 2, "macro 'wheel' is called but never defined", "<xacro:macro"),
    ('  <link name="${1 +* 2}"/>\n', 2, "invalid syntax", "fix the expression"),
    ('  <link name="${1/0}"/>\n', 2, "division by zero in ${1/0}", "fix the expression"),
    ('  <xacro:include filename="nowhere.xacro"/>\n  <link name="a"/>\n', 2, "nowhere.xacro",
     "relative to the including file"),
    ('  <link name="$(find no_such_pkg)"/>\n', 2, "package 'no_such_pkg' not found",
     "-P no_such_pkg=DIR"),
    (('  <xacro:macro name="m" params="a b"><link name="${a}${b}"/></xacro:macro>\n'
     '  <xacro:m a="1"/>\n'), 3, "Undefined parameters [b]", "params"),
    (('  <xacro:macro name="m" params="a"><link name="${a}"/></xacro:macro>\n'
     '  <xacro:m a="1" c="2"/>\n'), 3, 'Invalid parameter "c"', "params"),
])
def test_xacro_errors_are_explained(write, body, line, message, hint):
    diagnostics = found(write(HEAD + body + "</robot>\n", "robot.urdf.xacro"))
    errors = [d for d in diagnostics if d.rule == "xacro.error"]
    assert errors, diagnostics
    assert (errors[0].line, errors[0].severity) == (line, "error")
    assert message in errors[0].message
    assert hint in errors[0].hint


def test_unprefixed_tags_with_exact_rewrites(write):
    text = (HEAD + '  <property name="width" value="0.3"/>\n'
            '  <include filename="parts.xacro"/>\n'
            '  <macro name="leg" params="side">\n    <link name="leg"/>\n  </macro>\n'
            '  <link name="a"/>\n'
            '  <gazebo><plugin name="p" filename="x.so"><arg>ignored</arg></plugin></gazebo>\n'
            "</robot>\n")
    diagnostics = found(write(text, "robot.urdf.xacro"))
    # looking through the prefixed tags: the include names a file that does not exist
    assert [(d.rule, d.severity, d.line) for d in diagnostics] == [
        ("xacro.unprefixed-tag", "warning", 2), ("xacro.error", "error", 3),
        ("xacro.unprefixed-tag", "warning", 3), ("xacro.unprefixed-tag", "warning", 4)]
    assert "parts.xacro" in diagnostics[1].message
    assert diagnostics[1].message.endswith("(found once the safe fixes are applied)")
    diagnostics = [d for d in diagnostics if d.rule == "xacro.unprefixed-tag"]
    assert diagnostics[0].hint == 'write <xacro:property name="width" value="0.3"/>'
    assert diagnostics[1].hint == 'write <xacro:include filename="parts.xacro"/>'
    assert diagnostics[2].hint == 'write <xacro:macro name="leg" params="side"> ... </xacro:macro>'


def test_old_style_file_that_fails_to_expand_says_why(write):
    text = (HEAD + '  <macro name="leg" params="side">\n    <link name="${side}_leg"/>\n'
            "  </macro>\n</robot>\n")
    diagnostics = found(write(text, "robot.urdf.xacro"), look_through=False)
    assert [(d.rule, d.line) for d in diagnostics] == [("xacro.error", 3)]
    assert "undefined property 'side'" in diagnostics[0].message
    assert "<macro> without the xacro: prefix" in diagnostics[0].hint
    # read past the error, the unprefixed <macro> is found with its fix
    diagnostics = found(write(text, "robot.urdf.xacro"))
    assert [(d.rule, d.line) for d in diagnostics] == [("xacro.unprefixed-tag", 2),
                                                      ("xacro.error", 3)]
    assert diagnostics[0].fix.applicability == "safe"


def test_unprefixed_tags_without_a_xacro_namespace(write):
    text = '<robot name="r">\n  <property name="w" value="${1+1}"/>\n  <link name="a"/>\n</robot>\n'
    diagnostics = found(write(text, "robot.urdf.xacro"))
    assert [d.rule for d in diagnostics] == ["xacro.unprefixed-tag"]
    assert 'declare xmlns:xacro="http://www.ros.org/wiki/xacro"' in diagnostics[0].hint


def test_unprefixed_macro_call_warning_and_empty_robot_error(write):
    macro = '  <xacro:macro name="body"><link name="base"/></xacro:macro>\n'
    with_links = found(write(HEAD + macro + '  <link name="world"/>\n  <body/>\n</robot>\n',
                             "a.urdf.xacro"))
    assert [(d.rule, d.severity, d.line) for d in with_links] == \
        [("xacro.unprefixed-macro-call", "warning", 4)]
    assert with_links[0].hint == "write <xacro:body/>"
    empty = found(write(HEAD + macro + "  <body/>\n</robot>\n", "b.urdf.xacro"))
    assert [(d.rule, d.severity) for d in empty] == [("xacro.unprefixed-macro-call", "error")]
    assert "comes out with no links at all" in empty[0].message


def test_macros_named_like_urdf_elements_do_not_make_urdf_elements_calls(write):
    text = (HEAD + '  <xacro:macro name="inertial" params="m"><inertial><mass value="${m}"/>'
            '<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>'
            "</xacro:macro>\n"
            '  <link name="a"><xacro:inertial m="1"/></link>\n'
            '  <link name="b"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" '
            'ixy="0" ixz="0" iyz="0"/></inertial></link>\n'
            '  <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>\n'
            "</robot>\n")
    assert found(write(text, "robot.urdf.xacro")) == []


def test_macro_defined_in_a_never_included_file(write, tmp_path):
    write(HEAD + '  <xacro:macro name="wheel"><link name="w"/></xacro:macro>\n</robot>\n',
          "parts/wheels.xacro")
    main = write(HEAD + '  <include filename="parts/wheels.xacro"/>\n  <link name="a"/>\n'
                 "  <wheel/>\n</robot>\n", "robot.urdf.xacro")
    diagnostics = found(main)
    assert [(d.rule, d.line) for d in diagnostics] == [("xacro.unprefixed-tag", 2),
                                                       ("xacro.unprefixed-macro-call", 4)]
    assert "defined in wheels.xacro" in diagnostics[1].message


def _smartcar(kind: str) -> Path:
    path = SMARTCAR / kind / "smartcar.urdf.xacro"
    assert path.is_file(), f"{path} is committed"
    return path


def test_smartcar_published_comes_out_empty():
    main = _smartcar("published")
    diagnostics = found(main, look_through=False)
    # the included file's own unprefixed tags too: xacro never reads it, they are found anyway
    assert [(Path(d.path).name, d.rule, d.severity, d.line) for d in diagnostics] == [
        ("smartcar.urdf.xacro", "xacro.unprefixed-tag", "warning", 16),
        ("smartcar.urdf.xacro", "xacro.unprefixed-macro-call", "error", 18),
        ("smartcar.urdf.xacro", "xacro.unprefixed-macro-call", "error", 19),
        *[("smartcar_body.urdf.xacro", "xacro.unprefixed-tag", "warning", n)
          for n in (3, 5, 6, 7)]]
    assert diagnostics[0].hint.startswith(
        'write <xacro:include filename="$(find smartcar_description)/urdf/'
        'smartcar_body.urdf.xacro" />')
    assert "robot 'smartcar' comes out with no links at all" in diagnostics[1].message
    assert diagnostics[1].hint == "write <xacro:smartcar_body/>"
    assert "defined in gazebo.urdf.xacro" in diagnostics[2].message
    body = found(main.parent / "urdf" / "smartcar_body.urdf.xacro", look_through=False)
    assert [(d.rule, d.line) for d in body] == [("xacro.unprefixed-tag", n) for n in (3, 5, 6, 7)]
    assert body[0].hint == 'write <xacro:property name="M_PI" value="3.14159"/>'


def test_smartcar_corrected_is_clean():
    main = _smartcar("corrected")
    assert found(main) == []
    assert found(main.parent / "urdf" / "smartcar_body.urdf.xacro") == []


def test_a_missing_package_is_one_finding_with_a_count(tmp_path):
    """issue 22.3: a dependency package no check finds stopped each of the package's entries:
    one finding per entry, all the same. It is one, at the first, counting the others."""
    import json

    from tests.conftest import run_urdftool

    (tmp_path / "package.xml").write_text(
        '<package format="3"><name>my_desc</name><version>0.0.1</version><description>d'
        '</description><maintainer email="a@b.c">a</maintainer><license>BSD</license></package>')
    (tmp_path / "urdf").mkdir()
    for name in ("a", "b", "c", "d", "e"):
        (tmp_path / "urdf" / f"robot_{name}.urdf.xacro").write_text(
            f'<robot name="{name}" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            '  <xacro:include filename="$(find dep_pkg)/urdf/common.xacro"/>\n'
            '  <link name="base"/>\n</robot>\n')
    result = run_urdftool("check", "--format", "json", tmp_path)
    found = [(f["path"], d["line"], d["message"]) for f in json.loads(result.out)["files"]
             for d in f["diagnostics"]]
    assert result.code == 1 and len(found) == 1, found
    path, line, message = found[0]
    assert (Path(path).name, line) == ("robot_a.urdf.xacro", 2)
    assert message.startswith("xacro: $(find dep_pkg): package 'dep_pkg' not found; "
                              "4 other expansion(s) need it too: ")
    assert "robot_b.urdf.xacro:2" in message and " and 1 more; skipped, the rest is " \
        "expanded without it" in message  # (an include: each read past it, issue 29)


def test_a_missing_include_holds_back_what_it_may_define(tmp_path):
    """issue 22.3: an include that cannot be read is the one cause of the undefined property,
    link and joint after it (they were 3 more findings); with the include found, the names
    are checked again and a real mistake among them is reported."""
    text = ('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            '  <xacro:include filename="common.xacro"/>\n'
            '  <link name="base"><inertial><mass value="${base_mass}"/>'
            '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>\n'
            '  <joint name="k" type="fixed"><parent link="base"/><child link="tool"/></joint>\n'
            '  <gazebo reference="tool"><mu1>1</mu1></gazebo>\n'
            '  <transmission name="t"><type>transmission_interface/SimpleTransmission</type>'
            '<joint name="{joint}"><hardwareInterface>hardware_interface/EffortJointInterface'
            '</hardwareInterface></joint><actuator name="m"><mechanicalReduction>1'
            '</mechanicalReduction></actuator></transmission>\n</robot>\n')
    path = tmp_path / "robot.urdf.xacro"
    path.write_text(text.replace("{joint}", "tool_joint"))
    report = check_file(path, CheckOptions())
    errors = [(d.rule, d.line) for d in report.diagnostics if d.severity in ("error", "warning")]
    assert errors == [("xacro.error", 2)], errors
    assert "what it may define is not checked until it is read" in report.diagnostics[0].message
    (tmp_path / "common.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:property name="base_mass" value="2"/>\n'
        '  <link name="tool"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" '
        'iyy="0.1" iyz="0" izz="0.1"/></inertial></link>\n</robot>\n')
    report = check_file(path, CheckOptions())
    errors = [(d.rule, d.line) for d in report.diagnostics if d.severity == "error"]
    assert errors == [("transmission.unknown-joint", 6)], errors  # no joint 'tool_joint': k


FINGERS = HEAD + """  <xacro:property name="color" value="red"/>
  <xacro:macro name="finger" params="side parent:=base *origin">
    <link name="${side}_finger"><visual><geometry><box size="1 1 1"/></geometry>
      <material name="{color}"/></visual></link>
    <joint name="${side}_joint" type="fixed"><parent link="${parent}"/><child link="{side}_finger"/>
    </joint>
    <!-- {side} in a comment is nothing --><gazebo><note>{side} {other} {{side}}</note></gazebo>
  </xacro:macro>
  <link name="base"/>
  <xacro:finger side="left"><origin/></xacro:finger>
  <xacro:finger side="right"><origin/></xacro:finger>
</robot>
"""


def test_braces_without_dollar_are_one_finding_per_place_with_the_fix(write):
    """Issue 29: `{side}` for `${side}` gave a did-you-mean for a joint name, two-parents and
    orphan errors; it is one finding where it is written (a parameter of the macro, or a
    property), and the safe fix makes the robot whole."""
    path = write(FINGERS, "fingers.urdf.xacro")
    report = check_file(path, CheckOptions())
    assert not [d for d in report.diagnostics if d.rule.startswith("structure.")]
    found = sorted((d.rule, d.severity, d.line, d.message.split(":")[0])
                   for d in report.diagnostics if d.rule.startswith("xacro."))
    assert found == [
        ("xacro.missing-dollar", "error", 5, "'{color}' is written where '${color}' is meant"),
        ("xacro.missing-dollar", "error", 6, "'{side}' is written where '${side}' is meant"),
        ("xacro.missing-dollar", "warning", 8, "'{side}' is written where '${side}' is meant"),
    ], found
    from urdftool.edits import apply

    text = Path(path).read_text()
    fixed, _ = apply(text, [e for d in report.diagnostics if d.fix for e in d.fix.edits])
    assert fixed.count("${side}_finger") == 2 and '"${color}"' in fixed
    assert "{other}" in fixed and "{{side}}" in fixed and "<!-- {side}" in fixed


@pytest.mark.parametrize("template", ["arm.urdf.xacro.in", "arm.urdf.xacro.em", None])
def test_an_include_generated_at_build_time_is_a_warning_naming_its_template(tmp_path,
                                                                            template):
    """Issue 29: an include the build generates (from a .in/.em template beside it) failed
    as 'No such file' errors; without a template it stays the error it is."""
    (tmp_path / "robot.urdf.xacro").write_text(
        HEAD + '  <xacro:include filename="arm.urdf.xacro"/>\n  <link name="base"/>\n'
               '  <xacro:arm parent="base"/>\n</robot>\n')
    if template:
        (tmp_path / template).write_text(HEAD + '  <link name="@ARM@"/>\n</robot>\n')
    found = [(d.rule, d.severity, d.message, d.hint)
             for d in check_file(tmp_path / "robot.urdf.xacro", CheckOptions()).diagnostics
             if d.severity in ("error", "warning")]
    ((rule, severity, message, hint),) = found  # the undefined macro is held back
    assert rule == "xacro.error"
    if template:
        assert severity == "warning"
        assert f"generated at build time from {template}" in message
        assert "built package" in hint
    else:
        assert severity == "error" and "generated at build time" not in message


@pytest.mark.parametrize("mode", ["--trusted", "--untrusted"])
@pytest.mark.parametrize("lookup", ["['initial_positions']", ".initial_positions"])
def test_a_missing_yaml_key_names_the_file_and_its_keys(tmp_path, monkeypatch, mode, lookup):
    """Issue 29: `load_yaml(f)['initial_positions']` on a file without that key gave a
    garbled message (the quotes of two expressions crossed), a hint about Python syntax and no
    word of the YAML file."""
    from tests.conftest import run_urdftool

    (tmp_path / "config").mkdir()
    (tmp_path / "config" / "init.yaml").write_text("initial_position:\n  j1: 0.0\nother: 1\n")
    (tmp_path / "r.urdf.xacro").write_text(
        HEAD + '  <xacro:property name="pos" value="${xacro.load_yaml(\'config/init.yaml\')'
        + lookup + '}"/>\n  <link name="base_${pos[\'j1\']}"/>\n</robot>\n')
    monkeypatch.chdir(tmp_path)
    result = run_urdftool("check", mode, "--format", "json", "r.urdf.xacro")
    import json

    (finding,) = [d for f in json.loads(result.out)["files"] for d in f["diagnostics"]]
    assert finding["message"] == (
        "xacro: YAML file config/init.yaml has no key 'initial_positions' (its keys: "
        "initial_position, other; did you mean 'initial_position'?) in "
        "${xacro.load_yaml('config/init.yaml')" + lookup + "} (used in ${pos['j1']})")
    assert "python syntax" not in finding["hint"] and "YAML file" in finding["hint"]
