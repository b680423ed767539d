"""Portable baselines (issue 23): a baseline written in one clone matches in a copy at another
path, run from another working directory; nothing in it names the machine; with ``--changed``
only the recorded findings of the files the run saw are compared."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

from tests.conftest import run_urdftool

PACKAGES = Path(__file__).parent / "data" / "packages"


def _clone(where: Path) -> Path:
    """A repository holding realsense2_description (its meshes absent: mesh.not-found findings
    whose messages name paths) and demo_description."""
    where.mkdir(parents=True)
    for name in ("realsense2_description", "demo_description"):
        shutil.copytree(PACKAGES / name, where / name)
    (where / ".git").mkdir()  # the repository root, as `git init` marks it
    return where


def _check(*args) -> tuple[int, list[dict], str]:
    result = run_urdftool("check", "--format", "json", "--jobs", "1", *args)
    assert result.code in (0, 1), result.err
    return result.code, [d for f in json.loads(result.out)["files"] for d in f["diagnostics"]], \
        result.err


def test_a_baseline_written_in_one_clone_passes_in_another(tmp_path, monkeypatch):
    first = _clone(tmp_path / "laptop" / "work" / "repo")
    monkeypatch.chdir(first / "realsense2_description")  # written from a subdirectory
    code, before, _ = _check(".")
    assert code == 1 and len(before) >= 4
    assert {d["rule"] for d in before} >= {"mesh.not-found"}
    written = run_urdftool("check", "--write-baseline", "../baseline.json", ".", "../demo_description")
    assert written.code == 0, written.err
    text = (first / "baseline.json").read_text()
    # no machine-specific text: neither the clone's path nor the working directory
    assert str(tmp_path) not in text and "laptop" not in text and os.sep + "tmp" not in text
    records = json.loads(text)["findings"]
    assert len(records) == len(before)
    assert all(r["path"].startswith("realsense2_description/urdf/") for r in records)
    mesh = [r for r in records if r["rule"] == "mesh.not-found"]
    assert mesh and all("realsense2_description/meshes/" in r["message"] for r in mesh)

    # the repository moved (a CI runner), checked from its root and from elsewhere
    second = tmp_path / "runner" / "checkout"
    shutil.copytree(first, second)
    shutil.rmtree(first)
    for cwd, args in ((second, ("--baseline", "baseline.json", ".")),
                      (second / "demo_description", ("--baseline", "../baseline.json", "..")),
                      (tmp_path, ("--baseline", str(second / "baseline.json"), str(second)))):
        monkeypatch.chdir(cwd)
        code, found, err = _check(*args)
        assert (code, found) == (0, []), (cwd, found)
        assert f"0 new finding(s), {len(records)} recorded one(s) still present, " \
               "0 recorded one(s) gone" in err

    # one new defect: exactly one finding
    monkeypatch.chdir(second)
    camera = second / "demo_description" / "urdf" / "camera.xacro"
    camera.write_text(camera.read_text().replace('<mass value="0.1"/>', '<mass value="0"/>', 1))
    code, found, err = _check("--baseline", "baseline.json", ".")
    assert code == 1 and [(d["rule"], d["path"]) for d in found] == \
        [("inertia.mass-not-positive", "demo_description/urdf/camera.xacro")]


def test_changed_files_compare_only_what_the_run_saw(tmp_path, monkeypatch):
    repo = _clone(tmp_path / "repo")
    monkeypatch.chdir(repo)
    assert run_urdftool("check", "--write-baseline", "baseline.json", ".").code == 0
    recorded = json.loads((repo / "baseline.json").read_text())["findings"]
    in_d435 = [r for r in recorded if r["path"] == "realsense2_description/urdf/_d435.urdf.xacro"]
    assert 0 < len(in_d435) < len(recorded)
    code, found, err = _check("--baseline", "baseline.json", "--changed",
                              "realsense2_description/urdf/_d435.urdf.xacro")
    assert (code, found) == (0, [])
    # never "N recorded ones gone" for the findings of files the run did not look at
    assert f"0 new finding(s), {len(in_d435)} recorded one(s) still present, " \
           "0 recorded one(s) gone" in err
    # a changed file no check reads: nothing compared, nothing gone
    (repo / "notes.txt").write_text("x")
    code, found, err = _check("--baseline", "baseline.json", "--changed", "notes.txt")
    assert (code, found) == (0, []) and "0 recorded one(s) gone" in err


@pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")
def test_baseline_root_is_the_git_repository(tmp_path, monkeypatch):
    """A real `git init` marks the root; a baseline under a subdirectory of it names files
    from the root, as one at the root does."""
    repo = tmp_path / "repo"
    shutil.copytree(PACKAGES / "demo_description", repo / "demo_description")
    subprocess.run(["git", "init", "-q"], cwd=repo, check=True)
    camera = repo / "demo_description" / "urdf" / "camera.xacro"
    camera.write_text(camera.read_text().replace('<mass value="0.1"/>', '<mass value="0"/>', 1))
    (repo / "ci").mkdir()
    monkeypatch.chdir(repo / "demo_description")
    assert run_urdftool("check", "--write-baseline", "../ci/baseline.json", ".").code == 0
    records = json.loads((repo / "ci" / "baseline.json").read_text())["findings"]
    assert [r["path"] for r in records] == ["demo_description/urdf/camera.xacro"]


def test_a_baseline_keeps_uris_in_messages_and_relativises_paths(tmp_path):
    """Messages are recorded with the repository's paths made relative; a ``package://`` or
    ``file://`` URI is text, not a path (it was recorded as ``package:<outside>/name``)."""
    from urdftool.baseline import _Paths

    root = tmp_path / "repo"
    (root / "d_description" / "meshes").mkdir(parents=True)
    paths = _Paths(root)
    mesh = root / "d_description" / "meshes" / "base.stl"
    message = (f"link 'base' visual mesh 'package://d_description/meshes/base.stl': "
               f"no file at {mesh}")
    assert paths.message(message) == ("link 'base' visual mesh "
                                      "'package://d_description/meshes/base.stl': no file at "
                                      "d_description/meshes/base.stl")
    assert paths.message(f"file://{mesh}") == "d_description/meshes/base.stl"


def test_fix_and_failed_expansions_count_only_what_was_computed_as_gone(tmp_path, monkeypatch):
    """Issue 29: `check --fix` of one package with a repository's baseline said the findings
    of every entry it never looked at were "gone", and an entry whose expansion failed had its
    uncomputed findings counted as gone: the advice "write the baseline again" would have
    dropped them."""
    repo = _clone(tmp_path / "repo")
    monkeypatch.chdir(repo)
    camera = repo / "demo_description" / "urdf" / "camera.xacro"
    camera.write_text(camera.read_text().replace('<mass value="0.1"/>', '<mass value="0"/>', 1))
    assert run_urdftool("check", "--write-baseline", "baseline.json", ".").code == 0
    recorded = json.loads((repo / "baseline.json").read_text())["findings"]
    demo = [r for r in recorded if r["path"].startswith("demo_description/")]
    others = [r for r in recorded if not r["path"].startswith("demo_description/")]
    assert [r["rule"] for r in demo] == ["inertia.mass-not-positive"] and others
    # --fix of one package: the other package's records are neither compared nor gone
    result = run_urdftool("check", "--fix", "--in-place", "--baseline", "baseline.json",
                          "demo_description")
    assert result.code in (0, 1), result.err
    assert "recorded one(s) still present, 0 recorded one(s) gone" in result.err, result.err

    # the entry's expansion now fails: what it could not compute is not "gone"
    robot = repo / "demo_description" / "urdf" / "robot.urdf.xacro"
    good = robot.read_text()
    robot.write_text(good.replace("</robot>", "<xacro:no_such_macro/></robot>"))
    code, found, err = _check("--baseline", "baseline.json", ".")
    assert code == 1 and {d["rule"] for d in found} == {"xacro.error"}, found
    assert f"{len(others)} recorded one(s) still present, 0 recorded one(s) gone" in err, err
    # a recorded finding that disappears for real is still counted as gone
    robot.write_text(good)
    camera.write_text(camera.read_text().replace('<mass value="0"/>', '<mass value="0.1"/>', 1))
    code, found, err = _check("--baseline", "baseline.json", ".")
    assert (code, found) == (0, []) and "1 recorded one(s) gone" in err, err
