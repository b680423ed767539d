"""Fixes attached to findings (issue 17): look-through checking, ``check --fix``/``--diff``,
edits written where the text was written, and a property test over real robots."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from lxml import etree

from tests.conftest import example_robot_urdfs, pybullet_urdfs, run_urdftool
from urdftool.check import CheckOptions, check_file
from urdftool.edits import Edit, apply, value_edit
from urdftool.fix import fix_file
from urdftool.model import Loc

ROBOTS = Path(__file__).resolve().parent.parent / "robots"


def _keys(report) -> set[tuple[str, int | None]]:
    return {(d.rule, d.line) for d in report.diagnostics}


# -- look-through: the published seeds' defects hidden behind their breakages --------------


def test_open_manipulator_mimic_behind_lost_brackets_and_missing_includes():
    """The gripper's <limit>s lost their '<' and the property files are missing: the mimic that
    drives joint8 outside its limits, and joint9's chained mimic, are found anyway."""
    path = ROBOTS / "open_manipulator" / "published" / "open_manipulator.urdf.xacro"
    text = path.read_text()
    line8 = text[:text.index('<mimic joint="id_7"')].count("\n") + 1
    line9 = text[:text.index('<mimic joint="joint8"')].count("\n") + 1
    hidden = check_file(path, CheckOptions(look_through=False)).diagnostics
    assert not [d for d in hidden if d.rule.startswith("mimic.")]  # today: never checked
    diagnostics = check_file(path).diagnostics
    out_of_range = {d.line: d for d in diagnostics if d.rule == "mimic.out-of-range"}
    assert set(out_of_range) == {line8, line9}
    # id_7's range [-pi, -1.5] maps through -0.01 q - 0.0110133334 onto [0.00399, 0.0204]
    assert "[0.00398667, 0.0204026]" in out_of_range[line8].message
    assert "entirely outside its limits [-0.033, 0]" in out_of_range[line8].message
    assert any(d.rule == "mimic.chained" and d.line == line9 for d in diagnostics)
    # the mistakes looked through are still reported, at their lines as written
    # the missing includes are the one cause of the undefined ${bl_mass}... (issue 22.3): they
    # are reported, the properties they would define are held back until they are read
    assert [d.line for d in diagnostics if d.rule == "xacro.error"
            and "cannot include" in d.message] == [6, 8, 10, 12]
    assert not any(d.rule == "xacro.error" and "bl_mass" in d.message for d in diagnostics)
    assert sum(d.rule == "xml.missing-open-bracket" for d in diagnostics) == sum(
        d.rule == "xml.missing-open-bracket" for d in hidden)
    assert out_of_range[line8].message.endswith("(found by reading past the xacro errors)")


def test_smartcar_body_checked_through_unprefixed_macro_calls():
    """The unprefixed include and macro calls left the robot empty: once they are read as
    meant, the body's impossible wheel inertias and offset collisions are found."""
    path = ROBOTS / "smartcar" / "published" / "smartcar.urdf.xacro"
    hidden = check_file(path, CheckOptions(look_through=False)).diagnostics
    assert any(d.rule == "structure.no-links" for d in hidden)
    diagnostics = check_file(path).diagnostics
    assert not any(d.rule == "structure.no-links" for d in diagnostics)
    body = [d for d in diagnostics if d.path.endswith("smartcar_body.urdf.xacro")]
    inertia = {d.message.split("'")[1] for d in body if d.rule == "inertia.exceeds-geometry"}
    assert inertia == {"base_link", "left_front_wheel", "right_front_wheel", "left_back_wheel",
                       "right_back_wheel", "head"}  # ixx = iyy = izz = 1 on every part
    offset = {d.message.split("'")[1] for d in body
              if d.rule == "geometry.visual-collision-mismatch"}
    assert {"left_front_wheel", "right_front_wheel", "left_back_wheel",
            "right_back_wheel"} <= offset
    text = (path.parent / "urdf" / "smartcar_body.urdf.xacro").read_text().splitlines()
    for d in body:  # positions are in the body file as written
        if d.rule == "inertia.exceeds-geometry":
            assert "<inertia " in text[d.line - 1]
    fixed = [d for d in diagnostics if d.fix is not None]
    assert {d.rule for d in fixed} >= {"xacro.unprefixed-tag", "xacro.unprefixed-macro-call"}


# -- check --fix / --diff ------------------------------------------------------------------


def _copy(name: str, tmp_path: Path) -> Path:
    target = tmp_path / name
    shutil.copytree(ROBOTS / name / "published", target)
    return target


def test_diff_writes_nothing_and_in_place_lists_included_files(tmp_path):
    root = _copy("smartcar", tmp_path)
    main = root / "smartcar.urdf.xacro"
    body = root / "urdf" / "smartcar_body.urdf.xacro"
    before = {p: p.read_bytes() for p in (main, body)}
    result = run_urdftool("check", "--diff", main)
    assert result.code == 1
    assert "+  <xacro:smartcar_body/>" in result.out and "+  <xacro:property" in result.out
    assert {p: p.read_bytes() for p in (main, body)} == before
    # -o fixes a single file only: the include would change too
    refused = run_urdftool("check", "--fix", "-o", tmp_path / "out.xacro", main)
    assert refused.code == 2 and "smartcar_body.urdf.xacro" in refused.err
    done = run_urdftool("check", "--fix", "--in-place", main)
    assert f"fixed {main}" in done.err and "smartcar_body.urdf.xacro" in done.err
    assert "fixed, " in done.err and " remaining" in done.err
    assert "<xacro:smartcar_body/>" in main.read_text()
    assert body.read_text().count("<xacro:property") == 3
    assert body.read_text().count("<dynamics ") == 4  # <joint_properties>, seen once expanded
    # nothing left to fix: idempotent
    assert run_urdftool("check", "--diff", main).code == 0


@pytest.mark.parametrize("name", ["smartcar", "open_manipulator"])
def test_untrusted_fix_reads_in_the_sandbox_and_writes_only_the_files_listed(
        name, tmp_path, monkeypatch):
    """Under --untrusted the look-through and every round of --fix read the xacro (the texts
    fixed so far given in memory) in the sandboxed reader, never here; the result is the
    trusted run's, and only the files listed as fixed change."""
    from urdftool import sandbox, xacro_expand

    trusted, untrusted = _copy(name, tmp_path / "t"), _copy(name, tmp_path / "u")
    main = next(trusted.glob("*.urdf.xacro")).name
    done = run_urdftool("check", "--trusted", "--fix", "--unsafe-fixes", "--in-place",
                        trusted / main)
    before = {p: p.read_bytes() for p in untrusted.rglob("*") if p.is_file()}

    def no_expansion_here(*args):
        raise AssertionError("xacro expanded outside the sandboxed reader")

    monkeypatch.setattr(xacro_expand, "_xacro_pass", no_expansion_here)
    monkeypatch.setenv("CI", "true")  # untrusted by default
    fixed = run_urdftool("check", "--fix", "--unsafe-fixes", "--in-place", untrusted / main)
    assert sandbox.available() and fixed.code == done.code, fixed.err
    assert fixed.err.replace(str(untrusted), "") == done.err.replace(str(trusted), "")
    changed = {p for p in before if p.read_bytes() != before[p]}
    assert changed and {f"fixed {p}" for p in changed} == {
        line for line in fixed.err.splitlines() if line.startswith("fixed ")}
    for path in changed:
        assert path.read_bytes() == (trusted / path.relative_to(untrusted)).read_bytes()
    assert {p for p in untrusted.rglob("*") if p.is_file()} == set(before)


def test_untrusted_fix_never_reaches_an_include_outside_the_package(tmp_path):
    """An unprefixed include naming a file outside the package (its repository: no VCS here):
    neither read nor changed, in both modes (one trust model, issue 20)."""
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "package.xml").write_text("<package><name>pkg</name></package>")
    outside = tmp_path / "outside.xacro"
    outside.write_text('<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                       '  <property name="w" value="1"/>\n</robot>\n')
    path = package / "r.urdf.xacro"
    path.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                    '  <include filename="../outside.xacro"/>\n  <link name="a"/>\n</robot>\n')
    for mode in ("--trusted", "--untrusted"):
        result = run_urdftool("check", mode, "--diff", path)
        assert result.code == 1 and result.out.count("+++ b/") == 1
        assert '+  <xacro:include filename="../outside.xacro"/>' in result.out
        assert run_urdftool("check", mode, "--fix", "--in-place", path).code in (0, 1)
        assert "<property" in outside.read_text()
        path.write_text(path.read_text().replace("<xacro:include", "<include"))


def test_diff_cannot_inject_ci_commands_or_terminal_escapes(tmp_path):
    """The diff shows the user's file on stdout (a CI log): a control character in a changed
    line or a file name is shown escaped and no line becomes a workflow command; tabs and CRLF
    endings stay as they are."""
    directory = tmp_path / "x\n::error file=a::pwned"
    directory.mkdir()
    path = directory / "r.urdf"
    path.write_bytes(b'<robot name="r">\r\n\t<link name="a"/><link name="b"/>\r\n'
                     b'<joint name="j" type="fixed"><parent link="a"/><child link="b"/>\r\n'
                     b'<origin ryp="0 0 0" xyz="0 0 0"/><!-- \x1b]0;t\x07 \r::warning::w'
                     b' ##vso[task.setvariable variable=v]1 --></joint>\r\n</robot>\r\n')
    result = run_urdftool("check", "--diff", path)
    assert result.code == 1 and '+<origin rpy="0 0 0"' in result.out
    assert "\x1b" not in result.out and "##vso[" not in result.out
    assert "\\x1b]0;t\\x07 \\r::warning::w" in result.out
    assert not [line for line in result.out.split("\n") if line.lstrip().startswith("::")]
    assert result.out.count("\r\n") == result.out.count("\n") - 3  # headers and hunk: LF


def test_fix_keeps_every_byte_outside_the_edits(tmp_path):
    text = ('<?xml version="1.0"?>\r\n<!-- keep me -->\r\n<robot name="r">\r\n'
            '  <link name="a"/>  <link name="b"/>\r\n'
            '\t<joint type="revolute"   name="j" ><parent link="a"/><child link="b"/>\r\n'
            '    <origin xyz="0 0 1"  ryp="0 0 1"/><axis xyz="0 2 0"/>\r\n'
            '    <limit effort="1" velocity="1" lower="0" upper="1"/></joint>\r\n'
            "</robot>\r\n")
    path = tmp_path / "r.urdf"
    path.write_bytes(b"\xef\xbb\xbf" + text.encode())
    out = tmp_path / "out.urdf"
    assert run_urdftool("check", "--fix", "-o", out, path).code in (0, 1)
    expected = text.replace("ryp=", "rpy=").replace('axis xyz="0 2 0"', 'axis xyz="0 1 0"')
    assert out.read_bytes() == b"\xef\xbb\xbf" + expected.encode()


def test_unsafe_fixes_only_when_asked(tmp_path, write):
    path = write('<robot name="r"><link name="a"/><link name="b"/>\n'
                 '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
                 '    <limit lower="1" upper="-1" effort="1" velocity="1"/></joint>\n</robot>\n')
    assert run_urdftool("check", "--diff", path).code == 0  # a swap is not safe
    result = run_urdftool("check", "--diff", "--unsafe-fixes", path)
    assert result.code == 1
    assert '+    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>' in result.out


# -- written where the text was written -----------------------------------------------------


MACRO = """<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="arm" params="lo hi">
    <link name="a_${lo}"/>
    <joint name="j_${lo}" type="revolute"><parent link="base"/><child link="a_${lo}"/>
      <limit lower="${lo}" upper="${hi}" effort="1" velocity="1"/>
      <axis xyz="0 0 2"/>
    </joint>
  </xacro:macro>
  <link name="base"/>
  <xacro:arm lo="1" hi="-1"/>
  <xacro:arm lo="${2*1}" hi="0"/>
</robot>
"""


def test_edits_go_to_the_macro_body_and_the_call_site(write):
    path = write(MACRO, "robot.urdf.xacro")
    diagnostics = check_file(path).diagnostics
    axis = [d for d in diagnostics if d.rule == "joint.axis-not-unit"]
    # a literal in the body: one edit in the body, the same for both instances
    assert {e for d in axis for e in d.fix.edits} == {
        Edit(str(path), 6, 18, 6, 23, "0 0 1")}
    (swapped,) = [d for d in diagnostics if d.rule == "joint.lower-above-upper"]
    assert swapped.instances == 2  # one finding for the two instances of the body's line
    # the parameters given as literals: fixed at that call site; ${2*1} is not edited
    assert set(swapped.fix.edits) == {Edit(str(path), 10, 18, 10, 19, "-1"),
                                      Edit(str(path), 10, 25, 10, 27, "1")}


def test_a_value_computed_by_an_expression_is_fixed_by_hand(write):
    path = write(MACRO.replace('  <xacro:arm lo="1" hi="-1"/>\n', ""), "robot.urdf.xacro")
    (swapped,) = [d for d in check_file(path).diagnostics if d.rule == "joint.lower-above-upper"]
    assert swapped.fix is None
    assert "fix by hand: lower= is computed from `${2*1}` (to become 0)" in swapped.hint


def test_value_edit_refuses_expressions_and_adds_missing_attributes():
    texts = {"r.urdf": '<robot name="r">\n  <axis xyz="${v}"/>\n  <mimic joint="a"/>\n</robot>\n'}
    made = value_edit(texts, Loc("r.urdf", 2, 3), ("axis",), "xyz", "0 0 1")
    assert str(made).startswith("fix by hand: xyz= is computed from `${v}`")
    added = value_edit(texts, Loc("r.urdf", 3, 3), ("mimic",), "offset", "0.5")
    assert apply(texts["r.urdf"], [added])[0].splitlines()[2] == \
        '  <mimic joint="a" offset="0.5"/>'


# -- property: --fix --unsafe-fixes on real robots ------------------------------------------


def _sample() -> list[Path]:
    seeds = sorted(p for p in ROBOTS.glob("*/published/*") if p.suffix in (".urdf", ".xacro"))
    bullet = pybullet_urdfs()
    erd = example_robot_urdfs()
    return seeds + bullet[:: max(1, len(bullet) // 8)][:8] + erd[:: max(1, len(erd) // 4)][:4]


def _elements(text: str) -> list:
    root = etree.fromstring(text.encode(), etree.XMLParser(recover=True))
    if root is None:
        return []
    return [(e.tag, dict(e.attrib), e.sourceline) for e in root.iter()
            if isinstance(e.tag, str)]


@pytest.mark.parametrize("path", _sample(), ids=lambda p: f"{p.parent.name}/{p.name}")
def test_fixing_real_robots_never_makes_them_worse(path, tmp_path):
    result = fix_file(path, CheckOptions(), unsafe=True)
    before = check_file(path)  # what look-through finds: the robot as meant
    for name in result.changed():
        original, fixed = result.originals[name], result.texts[name]
        assert original.count("\n") == fixed.count("\n")
    if not result.changed():
        return
    # the fixed files, in a copy of the tree (includes and packages resolve the same)
    package = path.parent.parent if path.parent.name in ("published", "urdf") else path.parent
    copy = tmp_path / package.name
    shutil.copytree(package, copy, ignore=shutil.ignore_patterns("*.stl", "*.STL", "*.dae",
                                                                  "*.obj"), symlinks=True)
    for name in result.changed():
        target = copy / Path(name).resolve().relative_to(package.resolve())
        target.write_text(result.texts[name], encoding="utf-8")
    fixed_path = copy / path.resolve().relative_to(package.resolve())
    after = check_file(fixed_path, CheckOptions(look_through=False))
    xml_before = sum(d.rule.startswith("xml.") for d in before.diagnostics)
    assert sum(d.rule.startswith("xml.") for d in after.diagnostics) <= xml_before
    relative = {(d.rule, Path(d.path).name, d.line) for d in before.diagnostics}
    new = {(d.rule, Path(d.path).name, d.line) for d in after.diagnostics} - relative
    new = {k for k in new if not k[0].startswith("mesh.")}  # meshes were not copied
    assert not new, f"fixing {path.name} brings {new}"
    # the model differs from the original only on the lines the edits changed
    for name in result.changed():
        original, fixed = result.originals[name], result.texts[name]
        changed = {i for i, (a, b) in enumerate(zip(original.split("\n"), fixed.split("\n")), 1)
                   if a != b}
        old, new_elements = _elements(original), _elements(fixed)
        if len(old) == len(new_elements):
            for a, b in zip(old, new_elements):
                if a[:2] != b[:2]:
                    assert b[2] in changed, f"{name}:{b[2]} changed but was not edited"


def test_did_you_mean_names_one_slip_or_nothing():
    from urdftool.rules import did_you_mean

    assert did_you_mean("whel", ["wheel", "wheel_joint", "base"]) == "wheel"
    assert did_you_mean("base_link__lnk_01", ["base_link__link_01", "base_link__link_001"]) \
        == "base_link__link_01"  # one edit against two
    assert did_you_mean("joint7", [f"joint{i}" for i in range(1, 7)]) is None  # six at one edit
    assert did_you_mean("link_right_wheel", ["joint_right_wheel", "link_left_wheel"]) is None
    assert did_you_mean("a", ["b"]) is None  # a one-letter name is no typo of another


def test_a_link_typo_is_not_fixed_into_a_loop_or_a_second_parent(write):
    """link_1 is gone (renamed link_0 by mistake): link_7 is as near as link_2..6, and naming
    any of them would close a loop; no edit, the finding stays."""
    links = "".join(f'  <link name="l_{i}"/>\n' for i in (0, 0, 2, 3))
    joints = ('  <joint name="j1" type="fixed"><parent link="l_0"/><child link="l_1"/></joint>\n'
              '  <joint name="j2" type="fixed"><parent link="l_1"/><child link="l_2"/></joint>\n'
              '  <joint name="j3" type="fixed"><parent link="l_2"/><child link="l_3"/></joint>\n')
    path = write('<robot name="r">\n' + links + joints + "</robot>\n")
    result = run_urdftool("check", "--diff", "--unsafe-fixes", path)
    assert result.code == 0 and result.out == ""


def test_derived_tensor_is_written_in_the_inertial_frame_as_rotated(write):
    """A wheel whose inertial and collision share a rotated frame (the cylinder's axis is the
    frame's z): the fix writes the closed-form cylinder moments in that frame,
    m(3r^2 + h^2)/12 across and m r^2/2 along the axis, not the link frame's."""
    half_pi = "1.5707963267948966"
    path = write('<robot name="r"><link name="base"/>\n'
                 '  <link name="wheel"><inertial><mass value="0.2"/>\n'
                 f'    <origin rpy="0 {half_pi} {half_pi}" xyz="0 0 0"/>\n'
                 '    <inertia ixx="0.5" ixy="0" ixz="0" iyy="0.0005" iyz="0" izz="0.001"/>\n'
                 f'  </inertial><collision><origin rpy="0 {half_pi} {half_pi}"/>\n'
                 '    <geometry><cylinder radius="0.1" length="0.04"/></geometry></collision>\n'
                 '  </link>\n  <joint name="j" type="continuous"><parent link="base"/>'
                 '<child link="wheel"/><axis xyz="0 1 0"/></joint>\n</robot>\n')
    result = fix_file(path, CheckOptions(), unsafe=True)
    line = result.texts[str(path)].splitlines()[3]
    values = dict(part.split("=") for part in line.strip("<>/ ").split()[1:])
    values = {k: float(v.strip('"')) for k, v in values.items()}
    across, along = 0.2 * (3 * 0.1**2 + 0.04**2) / 12, 0.2 * 0.1**2 / 2
    assert values["ixx"] == pytest.approx(across, rel=1e-5)
    assert values["iyy"] == pytest.approx(across, rel=1e-5)
    assert values["izz"] == pytest.approx(along, rel=1e-5)
    assert values["ixy"] == values["ixz"] == values["iyz"] == 0


def test_fixing_one_named_file_plans_it_as_check_does(tmp_path, monkeypatch):
    """``check --fix -o`` / ``--diff`` on one named file give the verdict ``check`` gives on it:
    a macro-only file is a fragment (no false structure.no-links, exit 0, as plain check)."""
    package = tmp_path / "cam_description"
    (package / "urdf").mkdir(parents=True)
    (package / "package.xml").write_text("<package><name>cam_description</name></package>")
    macros = package / "urdf" / "camera.xacro"
    macros.write_text(
        '<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:macro name="camera" params="parent">\n'
        '    <link name="lens"><inertial><mass value="0.1"/>\n'
        '      <inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>\n'
        '      <collision><geometry><box size="0.03 0.03 0.03"/></geometry></collision></link>\n'
        '  </xacro:macro>\n</robot>\n')
    monkeypatch.chdir(tmp_path)
    plain = run_urdftool("check", str(macros))
    fixed = run_urdftool("check", "--fix", "-o", str(tmp_path / "out.xacro"), str(macros))
    diff = run_urdftool("check", "--diff", str(macros))
    assert plain.code == 0, plain.out + plain.err
    assert fixed.code == 0 and "structure.no-links" not in fixed.out + fixed.err, fixed
    assert diff.code == 0 and "nothing to change" in diff.err, diff
