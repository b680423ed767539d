"""The `material` rules follow urdfdom: top-level materials first (names unique), then links in
document order; a visual's name-only material must already be defined."""

from __future__ import annotations

from pathlib import Path

from urdftool.check import CheckOptions, check_file

ROOT = Path(__file__).resolve().parent.parent


def found(write, text: str):
    report = check_file(write(text), CheckOptions(select=["material"]))
    return [(d.rule, d.severity, d.line) for d in report.diagnostics], report.diagnostics


def link(name: str, material: str) -> str:
    return (f'  <link name="{name}"><visual><geometry><box size="1 1 1"/></geometry>'
            f"{material}</visual></link>\n")


GREY = '<material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>'


def test_defined_at_top_level_or_earlier_inline_is_fine(write):
    text = ('<robot name="r">\n' + link("a", '<material name="red"><color rgba="1 0 0 1"/>'
                                             "</material>")
            + link("b", '<material name="red"/>') + link("c", '<material name="grey"/>')
            + f"  {GREY}\n" + link("d", '<material name="red"><color rgba="1 0 0 1"/>'
                                        "</material>") + "</robot>\n")
    assert found(write, text)[0] == []


def test_undefined_and_defined_only_later(write):
    text = ('<robot name="r">\n' + link("a", '<material name="blue"/>')
            + link("b", '<material name="orange"/>')
            + link("c", '<material name="orange"><color rgba="1 0.5 0 1"/></material>')
            + "</robot>\n")
    result, diagnostics = found(write, text)
    assert result == [("material.undefined", "warning", 2), ("material.undefined", "warning", 3)]
    assert "never defined" in diagnostics[0].message
    assert "only later, in link 'c'" in diagnostics[1].message


def test_empty_material_names_are_not_references(write):
    # SolidWorks exporters write name="" with a colour in every visual: each keeps its own
    text = ('<robot name="r">\n' + link("a", '<material name=""><color rgba="1 0 0 1"/>'
                                             "</material>")
            + link("b", '<material name=""><color rgba="0 1 0 1"/></material>') + "</robot>\n")
    assert found(write, text)[0] == []


def test_not_unique_redefined_and_no_color(write):
    text = ('<robot name="r">\n' f"  {GREY}\n"
            '  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>\n'
            '  <material name="plain"/>\n'
            + link("a", '<material name="grey"><color rgba="0.9 0.9 0.9 1"/></material>')
            + link("b", '<material name="grey"><color rgba="0.5 0.5 0.5 1.0"/></material>')
            + "</robot>\n")
    result, diagnostics = found(write, text)
    assert result == [("material.not-unique", "error", 3), ("material.no-color", "warning", 4),
                      ("material.redefined", "warning", 5)]
    assert "first at line 2" in diagnostics[0].message
    assert "rgba '0.9 0.9 0.9 1'" in diagnostics[2].message and "line 2" in diagnostics[2].message


def test_a_colour_within_one_8_bit_step_is_no_redefinition(write):
    # 230/255 = 0.90196: the colour 0.9 once drawn (a 0-255 colour put back on 0-1, say)
    text = ('<robot name="r">\n'
            + link("a", '<material name="c"><color rgba="0 0.9 0.9 1"/></material>')
            + link("b", '<material name="c"><color rgba="0 0.9019607843 0.9019607843 1"/>'
                        "</material>")
            + link("c", '<material name="c"><color rgba="0 0.905 0.9 1"/></material>')
            + "</robot>\n")
    assert found(write, text)[0] == [("material.redefined", "warning", 4)]


def test_bad_colours_are_left_to_schema(write):
    text = ('<robot name="r">\n  <material name="m"><color rgba="255 0 0 1"/></material>\n'
            '  <material name="n"><color rgba="red"/></material>\n</robot>\n')
    assert found(write, text)[0] == []


def test_seed_robots_material_findings():
    smartcar = ROOT / "robots" / "smartcar" / "published" / "smartcar.urdf"
    # every wheel redefines 'black' with the same colour: legal, no finding
    report = check_file(smartcar, CheckOptions(select=["material"]))
    assert report.diagnostics == []
