"""Issue 20 item 3: one verdict. On real repositories checked out as a CI job sees them (a git
repository, its dependencies on ROS_PACKAGE_PATH, no -P), ``--untrusted`` (what ``CI=true``
implies) and ``--trusted`` give the same findings (rule, file, line), per entry and in package
mode (``check DIR``); every entry that expands in one mode expands in the other.

The fast sample runs in ``make test``; CI (``slow``, ``make test-slow``) runs every robot of
``shared/realworld-dev`` (about a minute of CPU)."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest
from conftest import run_urdftool

ROOT = Path(__file__).resolve().parent.parent
SHARED = ROOT.parent.parent / "shared"
for candidate in (ROOT.parent / "shared", Path("/work/shared")):
    if (candidate / "realworld-dev").is_dir():
        SHARED = candidate
        break
REALWORLD = SHARED / "realworld-dev"
REAL_PACKAGES = SHARED / "real-packages"
# (repository in realworld-dev/src, entry inside it, xacro args, repositories it depends on)
SAMPLE = [
    ("ROBOTIS-GIT+turtlebot3", "turtlebot3_description/urdf/turtlebot3_waffle.urdf", [], []),
    ("husky+husky", "husky_description/urdf/husky.urdf.xacro", [], []),
    ("Kinovarobotics+ros2_kortex", "kortex_description/robots/gen3_robotiq_2f_85.xacro", [],
     ["PickNikRobotics+ros2_robotiq_gripper"]),
]


def _checkout(tmp_path: Path, source: Path, name: str) -> Path:
    """``source`` as a fresh git checkout (what actions/checkout leaves)."""
    repo = tmp_path / name
    shutil.copytree(source, repo, symlinks=True)
    subprocess.run(["git", "init", "-q", str(repo)], check=True)
    return repo


def _findings(result) -> set[tuple]:
    assert result.code in (0, 1), result
    report = json.loads(result.out)
    return {(d["rule"], d["path"], d["line"]) for f in report["files"]
            for d in f["diagnostics"]}


def _both(*args) -> tuple[set, set]:
    # a generous time limit: what is compared is what each mode reads, not how fast a loaded
    # machine expands (a limit hit in one mode only is a difference of load, not of trust)
    common = ("--no-cache", "--format", "json", "--timeout", "60")
    untrusted = _findings(run_urdftool("check", "--untrusted", *common, *args))
    trusted = _findings(run_urdftool("check", "--trusted", *common, *args))
    return untrusted, trusted


def _same(untrusted: set, trusted: set, what: str) -> None:
    assert untrusted == trusted, (what, sorted(untrusted - trusted), sorted(trusted - untrusted))


def _realworld(tmp_path, monkeypatch, repository, entry, args, deps):
    if not (REALWORLD / "src" / repository).is_dir():
        pytest.fail(f"{REALWORLD} is missing {repository}")
    repo = _checkout(tmp_path, REALWORLD / "src" / repository, repository.split("+")[1])
    if deps:  # installed elsewhere on the runner: a workspace on ROS_PACKAGE_PATH
        workspace = tmp_path / "deps"
        for dep in deps:
            shutil.copytree(REALWORLD / "src" / dep, workspace / dep, symlinks=True)
        monkeypatch.setenv("ROS_PACKAGE_PATH", str(workspace))
    monkeypatch.chdir(repo)
    untrusted, trusted = _both(entry, *args)
    _same(untrusted, trusted, entry)
    return repo, untrusted


@pytest.mark.parametrize(("repository", "entry", "args", "deps"), SAMPLE,
                         ids=[s[0] for s in SAMPLE])
def test_same_findings_per_entry_on_real_repositories(repository, entry, args, deps, tmp_path,
                                                      monkeypatch):
    _, findings = _realworld(tmp_path, monkeypatch, repository, entry, args, deps)
    assert findings  # real robots: there is something to compare


def test_same_findings_in_package_mode_on_real_packages(tmp_path, monkeypatch):
    repo = _checkout(tmp_path, REAL_PACKAGES, "description_packages")
    monkeypatch.chdir(repo)
    for package in ("realsense2_description", "flir_camera_description"):
        untrusted, trusted = _both(package)
        _same(untrusted, trusted, package)
        assert not [f for f in untrusted if f[0] == "xacro.error"], untrusted


def test_same_findings_on_the_seed_robots(tmp_path, monkeypatch):
    repo = _checkout(tmp_path, ROOT / "robots", "robots")
    monkeypatch.chdir(repo)
    paths = sorted(str(p.relative_to(repo)) for p in repo.glob("*/published"))
    untrusted, trusted = _both(*paths)
    _same(untrusted, trusted, "robots/*/published")


def test_a_mesh_beside_the_file_without_package_xml(tmp_path, monkeypatch):
    """A repository without package.xml: ``../meshes/x.stl`` from ``urdf/`` is inside the
    repository, found in both modes (it was a false mesh.not-found under CI)."""
    repo = tmp_path / "bare_robot"
    (repo / "urdf").mkdir(parents=True)
    (repo / "meshes").mkdir()
    shutil.copy(ROOT / "urdftool" / "physics" / "examples" / "open_box.stl",
                repo / "meshes" / "box.stl")
    (repo / "urdf" / "robot.urdf").write_text(
        '<robot name="r"><link name="a"><visual><geometry><mesh filename="../meshes/box.stl"/>'
        '</geometry></visual></link></robot>')
    subprocess.run(["git", "init", "-q", str(repo)], check=True)
    monkeypatch.chdir(repo)
    untrusted, trusted = _both("urdf/robot.urdf")
    _same(untrusted, trusted, "urdf/robot.urdf")
    assert not [f for f in untrusted if f[0] == "mesh.not-found"]


@pytest.mark.slow  # the whole realworld-dev corpus: about a minute of CPU, CI (make test-slow)
def test_same_findings_on_every_realworld_robot(tmp_path, monkeypatch):
    manifest = json.loads((REALWORLD / "MANIFEST.json").read_text(encoding="utf-8"))
    differences = []
    for number, robot in enumerate(manifest["robots"]):
        entry = Path(robot["entry"])
        repository = entry.parts[1]
        inner = str(Path(*entry.parts[2:]))
        deps = sorted({Path(d).parts[1] for d in robot.get("packages", {}).values()}
                      - {repository})
        try:
            _realworld(tmp_path / str(number), monkeypatch, repository, inner,
                       robot.get("args", []), deps)
        except AssertionError as exc:
            differences.append(str(exc)[:2000])
        monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    assert differences == []
