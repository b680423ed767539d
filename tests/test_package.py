"""Packages as a CI gate (issue 13): entries and fragments from what the expansion read, the
configuration (entries with arguments, strict keys), changed-files mode, baselines, and one
finding per written line."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from tests.conftest import ROOT, run_urdftool

PACKAGES = Path(__file__).parent / "data" / "packages"


@pytest.fixture
def demo(tmp_path, monkeypatch) -> Path:
    """A copy of demo_description, the working directory (paths in findings are relative)."""
    root = tmp_path / "demo_description"
    shutil.copytree(PACKAGES / "demo_description", root)
    monkeypatch.chdir(root)
    return root


def check(*args) -> tuple[int, dict, str]:
    result = run_urdftool("check", "--format", "json", "--jobs", "1", *args)
    assert result.code in (0, 1), result.err
    return result.code, json.loads(result.out), result.err


def findings(report: dict) -> list[dict]:
    return [d for f in report["files"] for d in f["diagnostics"]]


def line_of(path: Path, text: str, occurrence: int = 1) -> int:
    """The 1-based line of the ``occurrence``-th line containing ``text``."""
    lines = [n for n, line in enumerate(path.read_text().splitlines(), 1) if text in line]
    return lines[occurrence - 1]


def edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))


# -- entries and fragments --------------------------------------------------------------------


def test_fragments_are_checked_through_their_entry(demo):
    # the fragments are included through $(find), a ${...} path and a $(arg ...) path; checked
    # alone, wheel.xacro would have a gazebo reference to a missing link, the others no links
    code, report, _ = check(".")
    assert code == 0 and findings(report) == []
    assert [f["path"] for f in report["files"]] == ["urdf/lidar.xacro", "urdf/robot.urdf.xacro",
                                                    "urdf/unused.xacro"]


def test_a_defect_in_a_macro_is_one_finding_with_its_instances(demo):
    wheel = demo / "urdf" / "wheel.xacro"
    edit(wheel, '<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>')
    code, report, _ = check(".")
    assert code == 1
    [finding] = findings(report)
    assert finding["rule"] == "joint.zero-axis"
    assert (finding["path"], finding["line"]) == ("urdf/wheel.xacro", line_of(wheel, "<axis"))
    entry = demo / "urdf" / "robot.urdf.xacro"
    calls = [line_of(entry, "<xacro:wheel ", n) for n in range(1, 5)]
    assert finding["instances"] == 4
    assert finding["call_sites"] == [[f"urdf/robot.urdf.xacro:{n}"] for n in calls]
    text = run_urdftool("check", "--jobs", "1", ".").out
    assert text.count("joint.zero-axis") == 1 and "in 4 instances: urdf/robot.urdf.xacro:" in text


def test_a_fragment_nothing_includes_is_checked_for_what_it_holds(demo):
    unused = demo / "urdf" / "unused.xacro"
    edit(unused, "<mu1>0.1</mu1>", "<mu1>0.1</mu>")
    code, report, _ = check(".")
    assert code == 1
    assert [(d["rule"], d["path"], d["line"]) for d in findings(report)] == \
        [("xml.mismatched-tag", "urdf/unused.xacro", line_of(unused, "</mu>"))]


def test_configured_entries_are_expanded_with_each_argument_set(demo):
    (demo / "urdftool.toml").write_text(
        'entries = [{ file = "urdf/robot.urdf.xacro" },\n'
        '           { file = "urdf/robot.urdf.xacro", args = { sensor = "lidar" } }]\n')
    lidar = demo / "urdf" / "lidar.xacro"
    edit(lidar, '<mass value="0.1"/>', '<mass value="-0.1"/>')
    code, report, _ = check(".")
    assert [(f["path"], f.get("args")) for f in report["files"]] == [
        ("urdf/robot.urdf.xacro", None), ("urdf/robot.urdf.xacro", {"sensor": "lidar"}),
        ("urdf/unused.xacro", None)]  # lidar.xacro: a fragment of the second entry now
    assert code == 1
    assert {(d["rule"], d["path"], d["line"]) for d in findings(report)} == \
        {("inertia.mass-not-positive", "urdf/lidar.xacro", line_of(lidar, "<mass"))}


def test_packages_key_resolves_find(tmp_path, monkeypatch):
    root = tmp_path / "somewhere"
    shutil.copytree(PACKAGES / "demo_description", root)
    (root / "package.xml").unlink()  # $(find demo_description) now needs the configuration
    monkeypatch.chdir(root)
    assert run_urdftool("check", "urdf/robot.urdf.xacro").code == 1
    (root / "urdftool.toml").write_text('packages = { demo_description = "." }\n')
    assert run_urdftool("check", "urdf/robot.urdf.xacro").code == 0


@pytest.mark.parametrize(("config", "message"), [
    ('entrie = []', "entrie: unknown key (did you mean 'entries'?)"),
    ('strict = "no"', "strict must be true or false"),
    ('ignore = ["xml.declaraton"]', ("unknown rule 'xml.declaraton' (did you mean "
                                     "'xml.declaration'?)")),
    ('severity = { "joint.zero-axes" = "info" }', "did you mean 'joint.zero-axis'?"),
    ('severity = { "joint.zero-axis" = "warn" }', "did you mean 'warning'?"),
    ('entries = [{ file = "urdf/robot.urdf.xacro", arg = {} }]', "did you mean 'args'?"),
    ('entries = [{ file = "urdf/missing.xacro" }]', "urdf/missing.xacro: no such file"),
    ('packages = ["x"]', "packages must be a table"),
])
def test_configuration_mistakes_exit_2(demo, config, message):
    (demo / "urdftool.toml").write_text(config + "\n")
    result = run_urdftool("check", ".")
    assert result.code == 2 and message in result.err, result.err


def test_pyproject_table_is_validated_too(demo):
    (demo / "pyproject.toml").write_text('[tool.urdftool]\nselct = ["xml"]\n')
    result = run_urdftool("check", ".")
    assert result.code == 2 and "tool.urdftool.selct: unknown key (did you mean 'select'?)" \
        in result.err


def test_unknown_rule_ids_on_the_command_line_and_in_comments_exit_2(demo):
    result = run_urdftool("check", "--select", "joint,mimic.cylce", ".")
    assert result.code == 2 and "did you mean 'mimic.cycle'?" in result.err
    assert run_urdftool("check", "--ignore", "jont", ".").code == 2
    wheel = demo / "urdf" / "wheel.xacro"
    edit(wheel, "<axis", "<!-- urdftool: ignore joint.zero-axes --><axis")
    result = run_urdftool("check", ".")
    assert result.code == 2
    assert f"urdf/wheel.xacro:{line_of(wheel, 'zero-axes')}: urdftool: ignore: unknown rule " \
        "'joint.zero-axes' (did you mean 'joint.zero-axis'?)" in result.err


# -- changed-files mode -----------------------------------------------------------------------


def test_changed_fragment_rechecks_its_entry_and_reports_only_its_findings(demo):
    wheel, entry = demo / "urdf" / "wheel.xacro", demo / "urdf" / "robot.urdf.xacro"
    edit(wheel, '<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>')
    edit(entry, '<mass value="2.0"/>', '<mass value="0"/>')
    code, report, err = check("--changed", "urdf/wheel.xacro")
    assert code == 1
    assert [f["path"] for f in report["files"]] == ["urdf/robot.urdf.xacro"]
    assert [(d["rule"], d["path"]) for d in findings(report)] == \
        [("joint.zero-axis", "urdf/wheel.xacro")]
    assert "1 finding(s) in files that were not given are not shown" in err
    # the entry's own finding when the entry is the changed file; none for an unrelated file
    code, report, _ = check("--changed", "urdf/robot.urdf.xacro")
    assert {d["path"] for d in findings(report)} == {"urdf/robot.urdf.xacro"}
    code, report, _ = check("--changed", "urdf/unused.xacro")
    assert code == 0 and [f["path"] for f in report["files"]] == ["urdf/unused.xacro"]


def test_changed_file_given_from_outside_the_package(demo, monkeypatch):
    edit(demo / "urdf" / "wheel.xacro", '<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>')
    monkeypatch.chdir(demo.parent)
    code, report, _ = check("--changed", "demo_description/urdf/wheel.xacro")
    assert code == 1 and [d["path"] for d in findings(report)] == \
        ["demo_description/urdf/wheel.xacro"]


def test_seed_robots_file_by_file_as_pre_commit_calls_it():
    corrected = sorted(p for p in (ROOT / "robots").glob("*/corrected/**/*")
                       if p.suffix in (".urdf", ".xacro"))
    assert len(corrected) >= 10
    for path in corrected:
        for mode in ((), ("--changed",)):
            result = run_urdftool("check", *mode, path)
            assert result.code == 0, (path, mode, result.out)
    for robot in sorted((ROOT / "robots").glob("*/published")):
        files = sorted(p for p in robot.rglob("*") if p.suffix in (".urdf", ".xacro"))
        assert run_urdftool("check", "--changed", *files).code == 1, robot


# -- baseline ---------------------------------------------------------------------------------


def test_baseline_round_trip(demo):
    wheel, entry = demo / "urdf" / "wheel.xacro", demo / "urdf" / "robot.urdf.xacro"
    edit(wheel, '<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>')
    edit(entry, '<mass value="2.0"/>', '<mass value="-0.5"/>')
    assert run_urdftool("check", "--write-baseline", "baseline.json", ".").code == 0
    recorded = json.loads((demo / "baseline.json").read_text())["findings"]
    assert sorted(r["rule"] for r in recorded) == ["inertia.mass-not-positive", "joint.zero-axis"]
    code, report, err = check("--baseline", "baseline.json", ".")
    assert code == 0 and findings(report) == [] and "2 recorded one(s) still present" in err
    # lines move, values are retouched: still the recorded findings
    edit(entry, "<robot", "<!-- a comment -->\n\n<robot")
    edit(entry, '<mass value="-0.5"/>', '<mass value="-0.25"/>')
    code, report, err = check("--baseline", "baseline.json", ".")
    assert code == 0 and findings(report) == [], findings(report)
    # one new defect: exactly that one is reported
    camera = demo / "urdf" / "camera.xacro"
    edit(camera, '<mass value="0.1"/>', '<mass value="0"/>')
    code, report, err = check("--baseline", "baseline.json", ".")
    assert code == 1
    assert [(d["rule"], d["path"], d["line"]) for d in findings(report)] == \
        [("inertia.mass-not-positive", "urdf/camera.xacro", line_of(camera, "<mass"))]
    # an old one fixed: said to be gone; the configuration's baseline key does the same
    edit(wheel, '<axis xyz="0 0 0"/>', '<axis xyz="0 0 1"/>')
    (demo / "urdftool.toml").write_text('baseline = "baseline.json"\n')
    code, report, err = check(".")
    assert code == 1 and len(findings(report)) == 1
    assert "1 new finding(s), 1 recorded one(s) still present, 1 recorded one(s) gone" in err


# -- real packages ----------------------------------------------------------------------------


def _keys(report: dict) -> set[tuple]:
    return {(d["rule"], d["path"], d["line"]) for d in findings(report)}


@pytest.mark.parametrize("package", ["realsense2_description", "flir_camera_description"])
def test_real_package_directory_check(package, tmp_path, monkeypatch):
    root = tmp_path / package
    shutil.copytree(PACKAGES / package, root)
    monkeypatch.chdir(root)
    _, report, _ = check(".")
    found = _keys(report)
    # the fragments (macro files) give no structure finding of their own
    structure = {k for k in found if k[0].startswith("structure.")}
    assert structure == set()
    # every finding of the entries checked one by one is found (once) by the directory check
    entries = sorted(Path("urdf").glob("test_*.urdf.xacro")) or [Path("urdf/demo.urdf.xacro")]
    for entry in entries:
        _, alone, _ = check(str(entry))
        assert _keys(alone) <= found, entry
    if package == "flir_camera_description":  # its entry needs model:=...; configured, it
        # reads the camera macro file, which is then checked through it
        (root / "urdftool.toml").write_text(
            'entries = [{ file = "urdf/demo.urdf.xacro", args = { model = "flir_blackfly_s" } }]\n')
        _, report, _ = check(".")
        assert [f["path"] for f in report["files"]] == ["urdf/demo.urdf.xacro"]
        assert [f["robot"] for f in report["files"]] == ["flir_blackfly_s"]


def test_changed_mode_checks_only_what_reads_the_files_once_it_knows(demo, monkeypatch):
    from urdftool import check as check_module

    (demo / "urdf" / "other.urdf.xacro").write_text(
        '<?xml version="1.0"?>\n<robot name="other" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:include filename="materials.xacro"/>\n'
        '  <link name="base"/>\n</robot>\n')
    checked: list[str] = []
    real = check_module.check_file

    def counting(path, options=None, target=None):
        checked.append(Path(path).name)
        return real(path, options, target)

    monkeypatch.setattr(check_module, "check_file", counting)
    check("--changed", "urdf/wheel.xacro")  # nothing known yet: every file is expanded
    assert sorted(checked) == ["camera.xacro", "lidar.xacro", "materials.xacro",
                               "other.urdf.xacro", "robot.urdf.xacro", "unused.xacro",
                               "wheel.xacro"]
    checked.clear()
    check("--changed", "urdf/wheel.xacro")  # known: only the entry that reads it
    assert checked == ["robot.urdf.xacro"]
    checked.clear()
    _, report, _ = check("--changed", "urdf/materials.xacro")
    assert sorted(checked) == ["other.urdf.xacro", "robot.urdf.xacro"]
    assert [f["path"] for f in report["files"]] == ["urdf/other.urdf.xacro",
                                                     "urdf/robot.urdf.xacro"]
    # a file changed since is expanded again (it may read other files now)
    other = demo / "urdf" / "other.urdf.xacro"
    other.write_text(other.read_text().replace("materials.xacro", "wheel.xacro"))
    checked.clear()
    _, report, _ = check("--changed", "urdf/wheel.xacro")
    assert sorted(checked) == ["other.urdf.xacro", "robot.urdf.xacro"]
    assert [f["path"] for f in report["files"]] == ["urdf/other.urdf.xacro",
                                                     "urdf/robot.urdf.xacro"]


def test_a_fragment_read_by_several_entries_reports_once(tmp_path, monkeypatch):
    root = tmp_path / "realsense2_description"
    shutil.copytree(PACKAGES / "realsense2_description", root)
    monkeypatch.chdir(root)
    _, report, _ = check(".")
    [missing] = [d for d in findings(report)
                 if d["rule"] == "mesh.not-found" and d["path"] == "urdf/_d435.urdf.xacro"]
    # the d435 macro is called by three entries (once, twice, and through the d435i macro)
    calls = {name: (root / "urdf" / name).read_text().count("<xacro:sensor_d435 ")
             for name in ("test_d435_camera.urdf.xacro", "test_d435_multiple_cameras.urdf.xacro",
                          "_d435i.urdf.xacro")}
    assert calls == {"test_d435_camera.urdf.xacro": 1,
                     "test_d435_multiple_cameras.urdf.xacro": 2, "_d435i.urdf.xacro": 1}
    assert missing["instances"] == 4
    outermost = sorted(chain[-1].rsplit(":", 1)[0] for chain in missing["call_sites"])
    assert outermost == sorted(["urdf/test_d435_camera.urdf.xacro",
                                "urdf/test_d435i_camera.urdf.xacro",
                                "urdf/test_d435_multiple_cameras.urdf.xacro",
                                "urdf/test_d435_multiple_cameras.urdf.xacro"])


@pytest.mark.parametrize("absolute", [False, True])
def test_included_files_are_named_as_the_entry_was(demo, monkeypatch, absolute):
    # wheel.xacro is reached through $(find demo_description), which resolves to an absolute
    # path: its findings are still named the way the package was given on the command line
    edit(demo / "urdf" / "wheel.xacro", '<mass value="0.5"/>', '<mass value="-0.5"/>')
    monkeypatch.chdir(demo.parent)
    given = str(demo) if absolute else demo.name
    _, report, _ = check(given)
    paths = {d["path"] for d in findings(report)} | {f["path"] for f in report["files"]}
    assert any(p.endswith("urdf/wheel.xacro") for p in paths), paths
    for path in paths:
        assert Path(path).is_absolute() == absolute, paths
        assert (demo.parent / path).resolve().is_file(), path
    text = run_urdftool("check", "--jobs", "1", given).out
    shown = [line.split(":")[0] for line in text.splitlines() if ".xacro:" in line]
    assert shown and all(Path(p).is_absolute() == absolute for p in shown), text
    # changed-files mode finds the package's entries itself: named the same way
    _, report, _ = check("--changed", str(Path(given) / "urdf" / "wheel.xacro"))
    paths = {d["path"] for d in findings(report)} | {f["path"] for f in report["files"]}
    assert paths and all(Path(p).is_absolute() == absolute for p in paths), paths


def test_changed_fragment_is_checked_through_its_entries_only(demo, monkeypatch):
    """Issue 23.8: with what each check read known from the last run, an edited macro file
    re-checks the entries that include it, and not itself alone (its findings come through
    them); the findings are those of a cold run."""
    from urdftool import check as check_module

    wheel = demo / "urdf" / "wheel.xacro"
    assert check("--changed", "urdf/wheel.xacro")[0] == 0  # cold: every file of the package
    edit(wheel, '<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>')
    checked = []
    real = check_module.check_file
    monkeypatch.setattr(check_module, "check_file",
                        lambda path, *rest: checked.append(str(path)) or real(path, *rest))
    code, report, _ = check("--changed", "urdf/wheel.xacro")
    assert checked == ["urdf/robot.urdf.xacro"]
    line = line_of(wheel, "<axis")
    assert code == 1 and [(d["rule"], d["path"], d["line"]) for d in findings(report)] == \
        [("joint.zero-axis", "urdf/wheel.xacro", line)]
    # the same findings as without the cache
    monkeypatch.setattr(check_module, "check_file", real)
    _, cold, _ = check("--no-cache", "--changed", "urdf/wheel.xacro")
    assert findings(cold) == findings(report)
