"""ruff's habits (issue 23): `rule` beside `rules`, `--output-format`, `--config`, `check`
without a path checks `.`, a folder without robot files is exit 0 with a note, colour control,
did-you-mean for a mistyped command or option (one line, exit 2), JUnit output."""

from __future__ import annotations

import json

import pytest
from lxml import etree

from tests.conftest import run_urdftool

ZERO_AXIS = """<?xml version="1.0"?>
<robot name="r">
  <link name="a"/>
  <link name="b"/>
  <joint name="j" type="continuous"><parent link="a"/><child link="b"/><axis xyz="0 0 0"/></joint>
</robot>
"""


@pytest.mark.parametrize(("argv", "expected"), [
    (["chek", "x.urdf"], "urdftool: no command 'chek'; did you mean 'check'?"),
    (["rulez"], "urdftool: no command 'rulez'; did you mean 'rules'?"),
    (["check", "--frmat", "json"], "urdftool check: No such option '--frmat'"),
])
def test_mistyped_commands_and_options_are_one_line_with_a_suggestion(argv, expected):
    result = run_urdftool(*argv)
    assert result.code == 2 and result.out == ""
    assert result.err.count("\n") == 1 and result.err.startswith(expected), result.err
    assert "Usage:" not in result.err


def test_rule_is_rules():
    one, other = run_urdftool("rule", "joint.zero-axis"), run_urdftool("rules", "joint.zero-axis")
    assert one.code == other.code == 0 and one.out == other.out and "joint.zero-axis" in one.out


def test_check_defaults_to_the_current_directory(tmp_path, monkeypatch):
    (tmp_path / "r.urdf").write_text(ZERO_AXIS)
    monkeypatch.chdir(tmp_path)
    result = run_urdftool("check", "--output-format", "json")
    assert result.code == 1
    [file] = json.loads(result.out)["files"]
    assert file["path"] == "r.urdf"
    assert "joint.zero-axis" in [d["rule"] for d in file["diagnostics"]]


def test_a_folder_without_robot_files_is_exit_0_with_a_note(tmp_path):
    (tmp_path / "notes.txt").write_text("x")
    result = run_urdftool("check", tmp_path)
    assert result.code == 0 and "no robot files" in result.err and "nothing to check" in result.err
    assert result.out == "0 file(s): 0 error(s), 0 warning(s), 0 info\n"
    assert run_urdftool("check", tmp_path / "missing").code == 2  # a typo is still an error


def test_config_option_chooses_the_configuration(tmp_path):
    robot = tmp_path / "r.urdf"
    robot.write_text(ZERO_AXIS)
    (tmp_path / "urdftool.toml").write_text('ignore = ["joint"]\n')  # the nearest one
    chosen = tmp_path / "ci.toml"
    chosen.write_text('select = ["joint.zero-axis"]\n')
    assert run_urdftool("check", robot).code == 0
    result = run_urdftool("check", "--config", chosen, "--format", "json", robot)
    assert result.code == 1
    rules = [d["rule"] for f in json.loads(result.out)["files"] for d in f["diagnostics"]]
    assert rules == ["joint.zero-axis"]
    bad = run_urdftool("check", "--config", tmp_path / "nope.toml", robot)
    assert bad.code == 2 and bad.err.count("\n") == 1


@pytest.mark.parametrize(("args", "env", "coloured"), [
    ((), {}, False),  # not a terminal
    (("--color", "always"), {}, True),
    (("--color", "always"), {"NO_COLOR": "1"}, True),  # the option wins
    ((), {"FORCE_COLOR": "1"}, True),
    ((), {"FORCE_COLOR": "1", "NO_COLOR": "1"}, False),
    (("--color", "never"), {"FORCE_COLOR": "1"}, False),
])
def test_colour_control(tmp_path, monkeypatch, args, env, coloured):
    for name in ("NO_COLOR", "FORCE_COLOR"):
        monkeypatch.delenv(name, raising=False)
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    robot = tmp_path / "r.urdf"
    robot.write_text(ZERO_AXIS)
    result = run_urdftool("check", *args, robot)
    assert result.code == 1 and ("\x1b[" in result.out) is coloured, result.out
    before = run_urdftool(*args, "check", robot)  # also before the command, as ruff
    assert ("\x1b[" in before.out) is coloured


def test_junit_output(tmp_path):
    bad, good = tmp_path / "bad.urdf", tmp_path / "good.urdf"
    bad.write_text(ZERO_AXIS)
    good.write_text(ZERO_AXIS.replace('xyz="0 0 0"', 'xyz="0 0 1"'))
    result = run_urdftool("check", "--format", "junit", bad, good)
    assert result.code == 1
    suite = etree.fromstring(result.out.encode())
    assert (suite.tag, suite.get("tests"), suite.get("failures")) == ("testsuite", "2", "1")
    cases = {c.get("name"): c for c in suite.iter("testcase")}
    assert set(cases) == {str(bad), str(good)}
    [failure] = cases[str(bad)].findall("failure")
    line = next(n for n, text in enumerate(ZERO_AXIS.splitlines(), 1) if "<axis" in text)
    column = ZERO_AXIS.splitlines()[line - 1].index("<axis") + 1
    assert failure.text.startswith(f"{bad}:{line}:{column}: error joint.zero-axis: ")
    assert cases[str(good)].find("failure") is None


@pytest.mark.parametrize(("target", "expected"), [
    ("results/", "did you mean results/urdftool.xunit.xml?"),
    ("results/urdftool", "did you mean results/urdftool.xunit.xml?"),
])
def test_ament_entry_point_refuses_a_malformed_xunit_target(tmp_path, monkeypatch, capsys,
                                                            target, expected):
    from urdftool.cli.ament import main

    monkeypatch.chdir(tmp_path)
    (tmp_path / "r.urdf").write_text(ZERO_AXIS)
    assert main(["--xunit-file", target]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and expected in err
    assert main(["--xunit-fil", "x.xml"]) == 2
    assert "Did you mean '--xunit-file'?" in capsys.readouterr().err
    assert main(["--xunit-file", "results/urdftool.xunit.xml"]) == 1
    suite = etree.parse(str(tmp_path / "results" / "urdftool.xunit.xml")).getroot()
    assert (suite.get("name"), suite.get("failures")) == ("results.urdftool", "1")


def test_ament_assert_clean_message_has_no_doubled_space(tmp_path, monkeypatch):
    """Issue 29: `urdftool-ament  exited 1` (two spaces when no arguments were given)."""
    from urdftool.cli.ament import assert_clean

    monkeypatch.chdir(tmp_path)
    (tmp_path / "r.urdf").write_text(ZERO_AXIS)
    with pytest.raises(AssertionError) as raised:
        assert_clean()
    first = str(raised.value).splitlines()[0]
    assert first == "urdftool-ament exited 1", first


def test_reading_commands_read_through_the_safe_fixes_as_check_does():
    """Issue 23.7: the seed OpenManipulator has tags that lost their '<'; check reads it
    through its safe fixes, and so do the reading commands (saying so in one line on
    stderr): the tree is the corrected copy's, but for the mimic the corrected copy fixed."""
    from tests.conftest import ROOT

    published = next((ROOT / "robots" / "open_manipulator" / "published").glob("*.xacro"))
    corrected = next((ROOT / "robots" / "open_manipulator" / "corrected").glob("*.xacro"))
    tree = run_urdftool("tree", "--format", "json", published)
    assert tree.code == 0, tree.err
    [note, *rest] = tree.err.splitlines()
    assert "read through" in note and "safe fix(es)" in note
    # (the published copy's $(find open_manipulator_support_description) includes are not in
    # the seed: each is skipped and said, never in silence; the fixes are said once)
    skipped = [line for line in rest if not line.startswith(" ")]
    assert skipped and all("error xacro.error" in line and "cannot include" in line
                           for line in skipped), tree.err
    expected = run_urdftool("tree", "--format", "json", corrected)
    assert expected.code == 0 and expected.err == ""
    assert tree.out.replace('"mimic": "joint8"', '"mimic": "id_7"') == expected.out
    limits = run_urdftool("limits", "--format", "json", published)
    names = [j["name"] for j in json.loads(limits.out)["joints"]]
    assert "joint8" in names and "joint9" in names
