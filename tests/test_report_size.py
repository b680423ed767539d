"""Reports proportional to the findings, not to the file (issue 21.3, 22.5): hostile inputs
under 1 MB (one huge line, many findings, long names, long values quoted in hints, a macro
called thousands of times) give a report under 1 MB in every format, quoted lines are a window
around the column, and the text lists a bounded number of findings per rule and file."""

from __future__ import annotations

import json

import pytest
from conftest import run_urdftool

from urdftool.cli.check import FORMATS  # every format of check (one registry, issue 33)

LIMIT = 1 << 20


def _link(name: str, extra: str = "") -> str:
    return (f'<link name="{name}"><inertial><mass value="1"/><inertia ixx="1" iyy="1" '
            f'izz="1" ixy="0" ixz="0" iyz="0"/></inertial>{extra}</link>')


def one_huge_line() -> str:
    """~900 KB on one line: thousands of links with a bad number each."""
    links = "".join(_link(f"l{i}", '<visual><geometry><box size="1 1 x"/></geometry></visual>')
                    for i in range(4500))
    return f'<robot name="r">{links}</robot>'


def many_findings() -> str:
    """Small elements, each a finding: joints of an unknown type to missing links."""
    joints = "\n".join(f'<joint name="j{i}" type="bogus"><parent link="p{i}"/>'
                       f'<child link="c{i}"/></joint>' for i in range(9000))
    return f'<robot name="r">\n{_link("base")}\n{joints}\n</robot>'


def long_names() -> str:
    """Names of 200 KB, used where messages and hints quote them."""
    name = "n" * 200_000
    return (f'<robot name="r">\n{_link(name)}\n{_link(name)}\n'
            f'<joint name="{name}" type="fixed"><parent link="{name}"/>'
            f'<child link="{name}x"/></joint>\n</robot>')


def long_values() -> str:
    """A 400 KB attribute value that a message and its hint quote, twice."""
    value = "1 " * 200_000
    return (f'<robot name="r">\n<link name="a"><visual><geometry><box size="{value}"/>'
            f'</geometry></visual></link>\n<link name="b"><visual><geometry>'
            f'<box size="{value[:-2]}"/></geometry></visual></link>\n</robot>')


def macro_instances() -> str:
    """A macro with a defect in its body, called 6000 times."""
    calls = "\n".join(f'<xacro:wheel name="w{i}"/>' for i in range(6000))
    return ('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
            '<xacro:macro name="wheel" params="name">\n'
            '<link name="${name}"><inertial><mass value="1"/><inertia ixx="-1" iyy="1" '
            'izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>\n'
            '</xacro:macro>\n' + calls + '\n</robot>')


CASES = {"one huge line": (one_huge_line, "robot.urdf"),
         "many findings": (many_findings, "robot.urdf"),
         "long names": (long_names, "robot.urdf"),
         "long values": (long_values, "robot.urdf"),
         "macro instances": (macro_instances, "robot.urdf.xacro")}


@pytest.mark.parametrize("case", CASES)
def test_a_hostile_file_under_1_mb_gives_a_report_under_1_mb(case, write, tmp_path):
    """One run writes every format: text on stdout, the others through --extra-output (the
    same rendering as --format, test_extra_outputs_are_the_formats)."""
    make, name = CASES[case]
    text = make()
    assert len(text.encode()) < LIMIT
    path = write(text, name)
    reports = {fmt: tmp_path / f"report.{fmt}" for fmt in FORMATS if fmt != "text"}
    result = run_urdftool("check", "--timeout", "60", str(path),
                          *(f"--extra-output={fmt}:{target}" for fmt, target in reports.items()))
    assert result.code == 1, result.err[-500:]
    assert "Traceback" not in result.err
    sizes = {"text": len(result.out.encode())}
    sizes.update((fmt, target.stat().st_size) for fmt, target in reports.items())
    assert all(size > 0 for size in sizes.values()), sizes
    assert all(size < LIMIT for size in sizes.values()), sizes
    # text: no line of the report is longer than a clipped message plus its location
    longest = max(map(len, result.out.splitlines()))
    assert longest < 1000 + len(str(path)), longest


def test_extra_outputs_are_the_formats(write, tmp_path):
    """--extra-output FORMAT:FILE writes what --format FORMAT prints (the hostile-file test above
    measures the formats through it)."""
    path = write(many_findings()[:3000].rsplit("\n", 1)[0] + "\n</robot>")
    reports = {fmt: tmp_path / f"report.{fmt}" for fmt in FORMATS if fmt != "text"}
    both = run_urdftool("check", str(path), *(f"--extra-output={fmt}:{target}"
                                              for fmt, target in reports.items()))
    assert both.code == 1, both.err
    assert both.out == run_urdftool("check", str(path)).out
    for fmt, target in reports.items():
        alone = run_urdftool("check", "--format", fmt, str(path))
        assert alone.code == 1 and alone.out, (fmt, alone.err)
        assert target.read_text(encoding="utf-8") == alone.out, fmt
        assert run_urdftool("check", "--output-format", fmt, str(path)).out == alone.out, fmt


def test_every_format_is_offered_by_every_option():
    """One registry (issue 33): `--extra-output junit:FILE` was refused while `--format junit`
    worked (issue 29). Each format is in --format's choices and --extra-output's help, and
    --extra-output refuses a name that is no format, naming them all."""
    assert {"text", "json", "sarif", "github", "junit"} <= set(FORMATS)
    helped = run_urdftool("check", "--help").out
    listed = " ".join(helped.split())
    assert "[" + "|".join(FORMATS) + "]" in listed
    assert "FORMAT (" + ", ".join(FORMATS) + ")" in listed
    refused = run_urdftool("check", "--extra-output", "yaml:out.yaml", ".")
    assert refused.code == 2 and all(fmt in refused.err for fmt in FORMATS), refused.err


def test_a_quoted_line_is_a_window_around_the_column(write):
    """One line of 3.5 KB (a column is found on lines up to 4 KB) with a defect in its
    middle: the excerpt shows about 160 characters around it, with an ellipsis at both ends,
    and the caret under the defect."""
    padding = "".join(_link(f"pad{i}") for i in range(12))
    text = (f'<robot name="r">\n{padding}<link name="x"><visual><geometry><box size="1 1 QQQ"/>'
            f'</geometry></visual></link>{padding}</robot>')
    path = write(text)
    out = run_urdftool("check", "--select", "schema.bad-vector", str(path)).out.splitlines()
    found = next(i for i, line in enumerate(out) if "schema.bad-vector" in line)
    column = int(out[found].split(":")[2])
    line = text.splitlines()[1]
    assert len(line) > 1500 and line[column - 1:].startswith("size=")  # as written
    quoted, caret = out[found + 1], out[found + 2]
    excerpt = quoted.split(" | ", 1)[1]
    assert excerpt.startswith("…") and excerpt.endswith("…")
    assert 150 <= len(excerpt) <= 170
    assert excerpt[1:-1] in line
    offset = caret.index("^") - (len(quoted) - len(excerpt))
    assert excerpt[offset:].startswith('size="1 1 QQQ"')


def test_text_lists_a_bounded_number_per_rule_and_file_json_all(write):
    joints = "\n".join(f'<joint name="j{i}" type="bogus"><parent link="base"/>'
                       f'<child link="c{i}"/></joint>' for i in range(50))
    links = "\n".join(f'<link name="c{i}"/>' for i in range(50))
    path = write(f'<robot name="r">\n<link name="base"/>\n{links}\n{joints}\n</robot>')
    data = json.loads(run_urdftool("check", "--format", "json", str(path)).out)
    listed = [d for d in data["files"][0]["diagnostics"] if d["rule"] == "schema.bad-value"]
    assert len(listed) == 50  # every finding in JSON
    text = run_urdftool("check", str(path)).out
    assert text.count("error schema.bad-value") == 20
    summary = text.splitlines()[-1]
    errors = sum(d["severity"] == "error" for d in data["files"][0]["diagnostics"])
    assert f"{errors} error(s)" in summary
    assert "30 more not listed (at most 20 per rule and file" in summary


def test_macro_instances_are_a_count_and_three_call_sites(write):
    calls = "\n".join(f'<xacro:wheel name="w{i}"/>' for i in range(12))
    path = write('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                 '<xacro:macro name="wheel" params="name">\n'
                 '<link name="${name}"><inertial><mass value="1"/><inertia ixx="-1" iyy="1" '
                 'izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>\n'
                 '</xacro:macro>\n' + calls + '\n</robot>', "robot.urdf.xacro")
    data = json.loads(run_urdftool("check", "--format", "json", str(path)).out)
    grouped = [d for d in data["files"][0]["diagnostics"] if d.get("instances") == 12]
    assert grouped, data
    for d in grouped:
        assert len(d["call_sites"]) == 12  # JSON keeps every call site
        assert "in 12 instances:" in d["message"] and d["message"].count(":") < 12
        assert d["message"].endswith(", and 9 more)")
    for fmt in ("text", "github", "sarif"):
        out = run_urdftool("check", "--format", fmt, str(path)).out
        assert "in 12 instances:" in out and ", and 9 more)" in out
        assert f"{path.name}:{6 + 11}" not in out  # the twelfth call's line is not named


def test_a_tag_across_lines_is_located_at_the_offending_attribute(write):
    path = write('<?xml version="1.0"?>\n<robot name="r">\n  <link name="a">\n'
                 '    <inertial>\n      <mass value="1"/>\n'
                 '      <inertia ixx="0.15" ixy="0" ixz="0"\n'
                 '               iyy="0.15" iyz="0"\n'
                 '               izz="0.2" />\n    </inertial>\n'
                 '    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>\n'
                 '  </link>\n  <link name="b"><visual><geometry>\n      <box\n'
                 '        size="0.1 0.1 q"/>\n    </geometry></visual></link>\n</robot>\n')
    for fmt in ("json", "sarif", "github"):
        out = run_urdftool("check", "--format", fmt, str(path)).out
        if fmt == "json":
            found = {d["rule"]: (d["line"], d["column"])
                     for d in json.loads(out)["files"][0]["diagnostics"]}
            # izz on line 8, column 16; size= on line 14, column 9: as written
            assert found["inertia.exceeds-geometry"] == (8, 16), found
            assert found["schema.bad-vector"] == (14, 9), found
        else:
            assert ("line=8" in out and "col=16" in out) if fmt == "github" else (
                '"startLine": 8' in out and '"startColumn": 16' in out)
