"""``urdftool lsp`` end to end (pytest-lsp: the server started as editors start it, over
stdio): its diagnostics are ``check --format json``'s, its quick fixes remove what they fix,
its "fix all" is ``check --fix``, bad input gives diagnostics and never a crash."""

from __future__ import annotations

import functools
import math
import re
import shutil
from pathlib import Path

import pytest
import pytest_lsp
from lsprotocol import types as lsp
from pytest_lsp import LanguageClient

from tests.conftest import IN_CI, ROBOTS, ROOT, SHARED
from tests.lsp_client import (
    SERVER,
    apply_edits,
    change,
    check_fix,
    check_json,
    check_report,
    checked,
    open_file,
    published,
    start,
    uri,
)
from urdftool.lsp.server import UNNECESSARY

REAL = SHARED / "real-packages"
SEEDS = sorted(p for p in ROBOTS.glob("*/*") if p.is_dir())
REAL_PACKAGES = sorted(p for p in REAL.glob("*") if p.is_dir()) if REAL.is_dir() else []

pytestmark = pytest.mark.asyncio(loop_scope="module")


@pytest_lsp.fixture(config=SERVER, scope="module", loop_scope="module")
async def client(lsp_client: LanguageClient):
    await start(lsp_client)
    yield
    await lsp_client.shutdown_session()


@functools.cache
def _all_checked() -> frozenset:
    """`check --format json` on every seed and real package directory (one run)."""
    return frozenset(check_json("--trusted", *map(str, SEEDS + REAL_PACKAGES)))


def first_robot_file(directory):
    return min(p for p in directory.rglob("*")
               if p.suffix in (".xacro", ".urdf", ".sdf") and p.is_file())


@pytest.mark.parametrize("directory", SEEDS + REAL_PACKAGES,
                         ids=[f"{p.parent.name}/{p.name}" for p in SEEDS + REAL_PACKAGES])
async def test_diagnostics_are_the_findings_of_check(client, directory):
    """Opening one file of a package publishes the findings of `check DIR` on every file of
    it, at the same rule, file, line, column and severity."""
    await open_file(client, first_robot_file(directory))
    expected = {f for f in _all_checked() if f[1].startswith(str(directory.resolve()) + "/")}
    assert expected or directory.name == "corrected"
    assert published(client, directory) == expected


def _copy(tmp_path, directory):
    target = tmp_path / directory.name
    shutil.copytree(directory, target)
    return target


async def _actions(client, path, line: int, only=None):
    return await client.text_document_code_action_async(lsp.CodeActionParams(
        lsp.TextDocumentIdentifier(uri(path)),
        lsp.Range(lsp.Position(line - 1, 0), lsp.Position(line - 1, 0)),
        lsp.CodeActionContext(diagnostics=[], only=only)))


def _at(client, path, rule: str) -> list[int]:
    return sorted(d.range.start.line + 1 for d in client.diagnostics.get(uri(path), [])
                  if d.code == rule)


async def test_a_quick_fix_removes_its_diagnostic(client, tmp_path):
    robot = _copy(tmp_path, ROBOTS / "m2wr" / "published") / "m2wr.xacro"
    text = robot.read_text(encoding="utf-8")
    await open_file(client, robot)
    lines = _at(client, robot, "xml.unclosed-tag")
    assert lines, client.diagnostics.get(uri(robot))
    actions = await _actions(client, robot, lines[0], [lsp.CodeActionKind.QuickFix])
    fix = next(a for a in actions if a.title.startswith("Fix xml.unclosed-tag"))
    assert fix.is_preferred and fix.kind == lsp.CodeActionKind.QuickFix
    fixed = apply_edits(text, fix.edit.changes[uri(robot)])
    assert fixed != text and fixed.count("\n") == text.count("\n")
    await change(client, robot, fixed)
    assert lines[0] not in _at(client, robot, "xml.unclosed-tag")
    assert len(_at(client, robot, "xml.unclosed-tag")) == len(lines) - 1
    # the server's findings on the unsaved buffer are check's on the same text saved
    robot.write_text(fixed, encoding="utf-8")
    assert published(client, robot.parent) == check_json("--trusted", str(robot.parent))


YAML_ENTRY = """<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="p" value="${xacro.load_yaml('data.yaml')}"/>
  <link name="base">
    <inertial>
      <mass value="${p['mass']}"/>
      <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/>
    </inertial>
  </link>
</robot>
"""


async def test_an_unsaved_yaml_edit_is_seen_by_the_xacro_that_loads_it(client, tmp_path):
    """The YAML a xacro reads with xacro.load_yaml is read from its open buffer (the
    overlay), not from the disk: an edit is checked before it is saved, as check sees it
    saved."""
    (tmp_path / "package.xml").write_text("<package><name>y</name></package>\n",
                                          encoding="utf-8")
    robot, data = tmp_path / "r.urdf.xacro", tmp_path / "data.yaml"
    robot.write_text(YAML_ENTRY, encoding="utf-8")
    data.write_text("mass: 1.0\n", encoding="utf-8")
    await open_file(client, robot)
    await open_file(client, data)
    assert _at(client, robot, "inertia.mass-not-positive") == []
    await change(client, data, "mass: -2.0\n")
    assert data.read_text(encoding="utf-8") == "mass: 1.0\n"  # not saved
    assert _at(client, robot, "inertia.mass-not-positive") == [5]
    data.write_text("mass: -2.0\n", encoding="utf-8")
    assert published(client, tmp_path) == check_json("--trusted", str(tmp_path))
    await change(client, data, "mass: 1.0\n", version=3)  # and back, still unsaved
    assert _at(client, robot, "inertia.mass-not-positive") == []


async def test_ignore_here_writes_the_suppression_comment(client, tmp_path):
    robot = _copy(tmp_path, ROBOTS / "m2wr" / "published") / "m2wr.xacro"
    text = robot.read_text(encoding="utf-8")
    await open_file(client, robot)
    rule = "gazebo.drive-geometry"
    _at_lines = _at(client, robot, rule)
    line = _at_lines[0]
    actions = await _actions(client, robot, line)
    ignore = next(a for a in actions if a.title.startswith(f"Ignore {rule}"))
    edited = apply_edits(text, ignore.edit.changes[uri(robot)])
    assert f"<!-- urdftool: ignore {rule} -->" in edited.split("\n")[line - 1]
    await change(client, robot, edited)
    after = _at(client, robot, rule)  # the lines below the comment moved down by one
    assert line not in after and len(after) == len(_at_lines) - 1
    robot.write_text(edited, encoding="utf-8")
    assert published(client, robot.parent) == check_json("--trusted", str(robot.parent))


async def test_fix_all_is_check_fix(client, tmp_path):
    robot = _copy(tmp_path, ROBOTS / "smartcar" / "published")
    path = first_robot_file(robot)
    text = path.read_text(encoding="utf-8")
    await open_file(client, path)
    actions = await _actions(client, path, 1, ["source.fixAll"])
    assert [a.kind for a in actions] == ["source.fixAll.urdftool"]
    fixed = apply_edits(text, actions[0].edit.changes[uri(path)])
    assert fixed == check_fix(path, tmp_path / "fixed.xacro") != text


async def test_bad_input_is_a_diagnostic_never_a_crash(client, tmp_path):
    lone = tmp_path / "lone"
    lone.mkdir()
    broken = lone / "broken.urdf"
    broken.write_text("this is not XML at all", encoding="utf-8")
    await open_file(client, broken)
    assert published(client, lone) == check_json("--trusted", str(lone))
    assert published(client, lone)
    bad = lone / "bad.xacro"
    bad.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                   '  <link name="${undefined_thing}"/>\n</robot>\n', encoding="utf-8")
    await open_file(client, bad)
    assert any(d.code == "xacro.error" and d.range.start.line == 1
               for d in client.diagnostics[uri(bad)])
    # the buffer becomes binary junk, then empty: still diagnostics, still answering
    await change(client, bad, "\x00\x01<<<>>>")
    await change(client, bad, "", version=3)
    assert client.diagnostics[uri(bad)]
    assert await checked(client) is None


# -- hover, definition, references, symbols, completion on xacro robots ----------------------

MANIPULATOR = ROBOTS / "open_manipulator" / "corrected"
REALSENSE = REAL / "realsense2_description"


def _line_of(path, needle: str) -> int:
    """1-based line of the first line of ``path`` holding ``needle``."""
    return next(i for i, line in enumerate(path.read_text(encoding="utf-8").split("\n"), 1)
                if needle in line)


def _position(path, needle: str, inside: str | None = None) -> lsp.Position:
    line = _line_of(path, needle)
    text = path.read_text(encoding="utf-8").split("\n")[line - 1]
    return lsp.Position(line - 1, text.index(inside or needle) + 1)


async def _hover(client, path, position) -> str | None:
    found = await client.text_document_hover_async(lsp.HoverParams(
        lsp.TextDocumentIdentifier(uri(path)), position))
    return found.contents.value if found is not None else None


def _numbers(text: str, label: str) -> list[float]:
    found = re.search(re.escape(label) + r"\s*([-+0-9.e, \[\]]+)", text)
    assert found, (label, text)
    return [float(v) for v in re.findall(r"[-+]?\d[\d.e+-]*", found.group(1))]


def _property(directory, name: str) -> float:
    for path in directory.rglob("*.xacro"):
        found = re.search(rf'<xacro:property name="{name}" value="([^"]+)"',
                          path.read_text(encoding="utf-8"))
        if found:
            return float(found.group(1))
    raise AssertionError(name)


async def test_hover_on_a_link_gives_mass_inertia_and_the_geometry_bound(client):
    robot = MANIPULATOR / "open_manipulator.urdf.xacro"
    await open_file(client, robot)
    text = await _hover(client, robot, _position(robot, '<link name="base_link">', "base_link"))
    mass = _property(MANIPULATOR, "bl_mass")
    assert _numbers(text, "mass:") == [mass]
    assert f"izz {_property(MANIPULATOR, 'bl_izz')!r}" in text
    # a cylinder of radius 0.05 about its axis: no point farther than r, so I <= m r^2
    radius = 0.05
    assert 'radius="0.05"' in robot.read_text(encoding="utf-8")
    assert _numbers(text, "allows about z:")[0] == pytest.approx(mass * radius ** 2, rel=1e-12)
    # the same link hovered where a joint names it
    assert await _hover(client, robot, _position(robot, '<child link="base_link"/>',
                                                 "base_link")) == text


async def test_hover_on_a_mimic_gives_the_image_of_the_leaders_range(client):
    robot = MANIPULATOR / "open_manipulator.urdf.xacro"
    await open_file(client, robot)
    source = robot.read_text(encoding="utf-8")
    mimic = re.search(r'<mimic joint="id_7" multiplier="([^"]+)" offset="([^"]+)"', source)
    text = await _hover(client, robot, _position(robot, mimic.group(0), "mimic"))
    leader = re.search(r'<joint\s+name="id_7"\s+type="revolute".*?'
                       r'<limit [^>]*lower="\$\{-pi\}" upper="([^"]+)"', source, re.DOTALL)
    multiplier, offset = float(mimic.group(1)), float(mimic.group(2))
    ends = sorted(multiplier * v + offset for v in (-math.pi, float(leader.group(1))))
    # shown as the CLI's tables show numbers (6 significant digits, display.number)
    assert _numbers(text, "range [")[:2] == [float(f"{v:.6g}") for v in
                                             (-math.pi, float(leader.group(1)))]
    assert _numbers(text, "]:") == [float(f"{v:.6g}") for v in ends]
    assert "inside its limits" in text


async def test_hover_on_an_expression_gives_its_value_and_definition_finds_the_property(client):
    robot = MANIPULATOR / "open_manipulator.urdf.xacro"
    await open_file(client, robot)
    where = _position(robot, '<mass value="${bl_mass}" />', "bl_mass")
    assert f"= `{_property(MANIPULATOR, 'bl_mass')!r}`" in await _hover(client, robot, where)
    found = await client.text_document_definition_async(lsp.DefinitionParams(
        lsp.TextDocumentIdentifier(uri(robot)), where))
    masses = MANIPULATOR / "urdf" / "mass_properties.xacro"
    assert [(f.uri, f.range.start.line + 1) for f in found] == [
        (uri(masses), _line_of(masses, 'name="bl_mass"'))]


async def test_definition_of_a_link_name_and_of_an_include(client):
    robot = MANIPULATOR / "open_manipulator.urdf.xacro"
    await open_file(client, robot)
    found = await client.text_document_definition_async(lsp.DefinitionParams(
        lsp.TextDocumentIdentifier(uri(robot)),
        _position(robot, '<child link="base_link"/>', "base_link")))
    assert [(f.uri, f.range.start.line + 1) for f in found] == [
        (uri(robot), _line_of(robot, '<link name="base_link">'))]
    found = await client.text_document_definition_async(lsp.DefinitionParams(
        lsp.TextDocumentIdentifier(uri(robot)),
        _position(robot, 'filename="urdf/mass_properties.xacro"', "mass_properties")))
    assert [f.uri for f in found] == [uri(MANIPULATOR / "urdf" / "mass_properties.xacro")]


@pytest.mark.skipif(not REALSENSE.is_dir() and not IN_CI,  # CI has shared/: there it fails
                    reason="needs shared/real-packages")
async def test_definition_and_hover_of_a_macro_across_find(client):
    entry = REALSENSE / "urdf" / "test_d435_camera.urdf.xacro"
    await open_file(client, entry)
    where = _position(entry, "<xacro:sensor_d435", "sensor_d435")
    macro_file = REALSENSE / "urdf" / "_d435.urdf.xacro"
    params = re.search(r'<xacro:macro name="sensor_d435" params="([^"]*)"',
                       macro_file.read_text(encoding="utf-8")).group(1)
    assert params in await _hover(client, entry, where)
    found = await client.text_document_definition_async(lsp.DefinitionParams(
        lsp.TextDocumentIdentifier(uri(entry)), where))
    assert [(f.uri, f.range.start.line + 1) for f in found] == [
        (uri(macro_file), _line_of(macro_file, '<xacro:macro name="sensor_d435"'))]
    symbols = await client.text_document_document_symbol_async(lsp.DocumentSymbolParams(
        lsp.TextDocumentIdentifier(uri(macro_file))))
    assert "sensor_d435" in {s.name for s in symbols}


async def test_completion_of_link_names_is_the_expanded_robots_links(client):
    import xacro
    from lxml import etree

    robot = MANIPULATOR / "open_manipulator.urdf.xacro"
    await open_file(client, robot)
    found = await client.text_document_completion_async(lsp.CompletionParams(
        lsp.TextDocumentIdentifier(uri(robot)),
        _position(robot, '<child link="base_link"/>', "base_link")))
    # the links of the robot as plain xacro expands it
    document = xacro.process_file(str(robot), mappings={})
    links = {e.get("name") for e in etree.fromstring(document.toxml().encode()).iter("link")}
    assert {item.label for item in found.items} == links


async def test_nothing_at_a_position_is_null(client):
    robot = MANIPULATOR / "open_manipulator.urdf.xacro"
    await open_file(client, robot)
    comment = _position(robot, "<!-- World -->", "World")
    assert await _hover(client, robot, comment) is None
    assert await client.text_document_definition_async(lsp.DefinitionParams(
        lsp.TextDocumentIdentifier(uri(robot)), comment)) is None
    assert await _hover(client, robot, lsp.Position(100000, 3)) is None


async def test_macro_instances_are_related_information(client):
    """A finding in a macro body carries its call sites (`check`'s ``call_sites``) as related
    information, each at the call's file and line."""
    directory = ROBOTS / "smartcar" / "published"
    await open_file(client, first_robot_file(directory))
    expected = {}
    for file in check_report("--trusted", str(directory))["files"]:
        for d in file["diagnostics"]:
            if d.get("call_sites"):
                sites = sorted((str((ROOT / chain[0].rsplit(":", 1)[0]).resolve()),
                                int(chain[0].rsplit(":", 1)[1])) for chain in d["call_sites"])
                expected[(d["rule"], str((ROOT / d["path"]).resolve()), d["line"])] = sites
    assert expected
    got = {}
    for key, found in client.diagnostics.items():
        for d in found:
            if d.related_information:
                got[(d.code, key.removeprefix("file://"), d.range.start.line + 1)] = sorted(
                    (r.location.uri.removeprefix("file://"), r.location.range.start.line + 1)
                    for r in d.related_information)
    assert {k: v for k, v in got.items() if k[1].startswith(str(directory))} == expected


async def test_columns_are_utf16_code_units(client, tmp_path):
    """LSP positions count UTF-16 code units (the default encoding): a character outside the
    BMP before a finding counts two."""
    robot = tmp_path / "wide" / "robot.urdf"
    robot.parent.mkdir()
    robot.write_text('<robot name="r">\n  <link name="a"/>\n  <link name="b"/>\n'
                     '  <!-- \U0001F916 arm --><joint name="j" type="revolute"><parent link="a"/>'
                     '<child link="b"/><axis xyz="0 0 1"/></joint>\n</robot>\n',
                     encoding="utf-8")
    await open_file(client, robot)
    line = robot.read_text(encoding="utf-8").split("\n")[3]
    column = line.index("<joint")
    found = [d for d in client.diagnostics[uri(robot)] if d.code == "joint.missing-limit"]
    assert [(d.range.start.line, d.range.start.character) for d in found] == [
        (3, len(line[:column].encode("utf-16-le")) // 2)]
    assert found[0].range.start.character == column + 1


@pytest.mark.skipif(not REALSENSE.is_dir() and not IN_CI,  # CI has shared/: there it fails
                    reason="needs shared/real-packages")
async def test_completion_of_a_macro_calls_parameters(client):
    entry = REALSENSE / "urdf" / "test_d435_camera.urdf.xacro"
    await open_file(client, entry)
    line = _line_of(entry, "<xacro:sensor_d435")
    text = entry.read_text(encoding="utf-8").split("\n")[line - 1]
    where = lsp.Position(line - 1, text.index("<xacro:sensor_d435") + len("<xacro:sensor_d435 "))
    found = await client.text_document_completion_async(lsp.CompletionParams(
        lsp.TextDocumentIdentifier(uri(entry)), where))
    params = re.search(r'<xacro:macro name="sensor_d435" params="([^"]*)"',
                       (REALSENSE / "urdf" / "_d435.urdf.xacro").read_text(encoding="utf-8"))
    given = set(re.findall(r'(\w+)="', text))
    expected = {p.split(":=")[0] for p in params.group(1).split() if not p.startswith("*")}
    assert {item.label for item in found.items} == expected - given != set()


async def test_random_edits_never_take_the_server_down(client, tmp_path):
    """Typing garbage into a xacro (truncations, stray characters, deleted brackets): every
    state gets diagnostics, no check fails, the server answers after each."""
    import random

    robot = _copy(tmp_path, ROBOTS / "dual_arm" / "published")
    path = next(robot.glob("*.xacro"))
    text = path.read_text(encoding="utf-8")
    await open_file(client, path)
    before = len(client.log_messages)
    chance = random.Random(24)
    for version in range(2, 26):
        at = chance.randrange(max(1, len(text)))
        edit = chance.choice(["cut", "insert", "delete"])
        if edit == "cut":
            text = text[:at]
        elif edit == "insert":
            text = text[:at] + chance.choice(["<", ">", '"', "${", "</", "&", "\x00", "é"]) \
                + text[at:]
        else:
            text = text[:at] + text[at + chance.randrange(1, 40):]
        await change(client, path, text, version)
        hover = await client.text_document_hover_async(lsp.HoverParams(
            lsp.TextDocumentIdentifier(uri(path)), lsp.Position(chance.randrange(60), 5)))
        assert hover is None or hover.contents.value
    failures = [m.message for m in client.log_messages[before:] if "failed" in m.message]
    assert failures == []
    assert uri(path) in client.diagnostics


async def test_old_xacro_syntax_is_tagged_deprecated(client):
    """The unprefixed (pre-ROS-2) xacro tags are struck through as Deprecated; the rule's
    page is linked from the diagnostic."""
    directory = ROBOTS / "smartcar" / "published"
    await open_file(client, first_robot_file(directory))
    found = [d for diagnostics in client.diagnostics.values() for d in diagnostics
             if d.code in ("xacro.unprefixed-tag", "xacro.unprefixed-macro-call")]
    assert found and all(list(d.tags) == [lsp.DiagnosticTag.Deprecated] for d in found)
    page = found[0].code_description.href
    assert page.startswith("file://")
    text = Path(page.removeprefix("file://")).read_text(encoding="utf-8")
    assert text.startswith(f"# {found[0].code}")
    others = [d for diagnostics in client.diagnostics.values() for d in diagnostics
              if d.code and not d.code.startswith("xacro.unprefixed")]
    assert others and not any(d.tags for d in others if d.code not in UNNECESSARY)


@pytest.mark.skipif(not REALSENSE.is_dir() and not IN_CI,  # CI has shared/: there it fails
                    reason="needs shared/real-packages")
async def test_hover_on_a_computed_property_gives_the_value_the_expansion_wrote(client):
    """d435_cam_depth_pz = ${d435_cam_height/2}: its value, read where the expansion wrote it
    (an origin's xyz), equals the height property over two."""
    macro_file = REALSENSE / "urdf" / "_d435.urdf.xacro"
    entry = REALSENSE / "urdf" / "test_d435_camera.urdf.xacro"
    await open_file(client, entry)
    await open_file(client, macro_file)
    text = await _hover(client, macro_file, _position(
        macro_file, 'name="d435_cam_depth_pz"', "d435_cam_depth_pz"))
    height = _property(REALSENSE / "urdf", "d435_cam_height")
    assert "`${d435_cam_height/2}`" in text
    assert float(re.search(r"= `([^`]+)`\s*$", text).group(1)) == pytest.approx(height / 2)


async def test_a_configured_baseline_hides_what_it_records(client, tmp_path):
    """`urdftool.toml`'s baseline applies in the editor as in `check`: recorded findings are
    not shown, a new one is."""
    package = _copy(tmp_path, ROBOTS / "m2wr" / "published")
    (package / "package.xml").write_text("<package><name>m2wr</name></package>",
                                         encoding="utf-8")
    check_report("--trusted", "--write-baseline", str(package / "baseline.json"), str(package),
                 parse=False)
    (package / "urdftool.toml").write_text('baseline = "baseline.json"\n', encoding="utf-8")
    robot = package / "m2wr.xacro"
    text = robot.read_text(encoding="utf-8")
    await open_file(client, robot)
    assert published(client, package) == check_json("--trusted", str(package)) == set()
    # a new mistake (a negative mass) is shown, the recorded ones stay hidden
    broken = re.sub(r'<mass value="[^"]*"', '<mass value="-1"', text, count=1)
    assert broken != text
    await change(client, robot, broken)
    robot.write_text(broken, encoding="utf-8")
    found = published(client, package)
    assert found == check_json("--trusted", str(package)) != set()
