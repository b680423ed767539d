"""Issue 20 item 5, attacked: every output goes through the one writer (``urdftool.output``), in
both modes. A write through a symbolic link (the file, or a directory inside the repository),
over any file the run read (a YAML file the expansion loaded, a checked file, a mesh, the
configuration, a hard link of an input), and an untrusted run's cache are each refused with one
line on stderr and exit 2, and nothing is written: the target, the directory a link points to
and the cache directory are compared byte for byte before and after."""

from __future__ import annotations

import os
import shutil
import struct
from pathlib import Path

import pytest

from tests.conftest import run_urdftool

MODES = ["--trusted", "--untrusted"]
XACRO = """<?xml version="1.0"?>
<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="d" value="${xacro.load_yaml('data.yaml')}"/>
  <link name="base"><visual><geometry><box size="${d['length']} 1 1"/></geometry></visual>
  </link>
</robot>
"""
BROKEN = '<?xml version="1.0"?>\n<robot name="r"><link name="base"></robot>\n'
SLOW = ("--timeout", "60")  # the sandboxed reader parses the mesh in time on a loaded machine


def _stl(path: Path) -> None:
    """A binary STL tetrahedron (written by hand: no mesh library involved)."""
    points = [(0, 0, 0), (0.1, 0, 0), (0, 0.1, 0), (0, 0, 0.1)]
    faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    data = b"\0" * 80 + struct.pack("<I", len(faces))
    for face in faces:
        data += struct.pack("<3f", 0, 0, 0)
        for index in face:
            data += struct.pack("<3f", *points[index])
        data += b"\0\0"
    path.write_bytes(data)


def snapshot(*roots: Path) -> dict[str, bytes | str]:
    """Every entry under ``roots``: file bytes, link targets, directories."""
    seen = {}
    for root in roots:
        for directory, dirs, files in os.walk(root):
            for name in dirs + files:
                path = Path(directory) / name
                if path.is_symlink():
                    seen[str(path)] = "-> " + os.readlink(path)
                elif path.is_file():
                    seen[str(path)] = path.read_bytes()
                else:
                    seen[str(path)] = "dir"
    return seen


@pytest.fixture
def repo(tmp_path, monkeypatch) -> Path:
    """A git checkout (a `.git` directory marks the repository) with a xacro reading YAML, a
    broken URDF, a URDF with a mesh and a configuration file; the working directory."""
    root = tmp_path / "repo"
    (root / ".git").mkdir(parents=True)
    (root / "data.yaml").write_text("length: 0.5\n")
    (root / "robot.urdf.xacro").write_text(XACRO)
    (root / "broken.urdf").write_text(BROKEN)
    _stl(root / "part.stl")
    (root / "mesh.urdf").write_text(
        '<robot name="m"><link name="a"><visual><geometry><mesh filename="part.stl"/>'
        "</geometry></visual></link></robot>\n")
    (root / "urdftool.toml").write_text("strict = false\n")
    monkeypatch.chdir(root)
    return root


def refused(result, *words: str, before: int = 0) -> None:
    """Exit 2 with one line on stderr (after ``before`` lines the run printed first)."""
    assert result.code == 2, (result.code, result.out, result.err)
    lines = result.err.strip().splitlines()
    assert len(lines) == 1 + before and "Traceback" not in result.err, result.err
    for word in words:
        assert word in lines[-1], lines[-1]


@pytest.mark.parametrize("mode", MODES)
def test_expand_never_writes_over_the_yaml_it_read(repo, mode):
    before = snapshot(repo)
    refused(run_urdftool("expand", mode, "robot.urdf.xacro", "-o", "data.yaml"),
            "data.yaml", "refusing to overwrite")
    assert snapshot(repo) == before
    # a file it did not read is written, atomically
    assert run_urdftool("expand", mode, "robot.urdf.xacro", "-o", "robot.urdf").code == 0
    assert 'size="0.5 1 1"' in (repo / "robot.urdf").read_text()
    assert not list(repo.glob(".*.tmp"))


OPTIONS = ["-o", "--output-file", "--write-baseline", "--extra-output"]
VICTIMS = ["broken.urdf", "robot.urdf.xacro", "data.yaml", "part.stl", "urdftool.toml"]


def _writes():
    """Every victim in each mode, every option in each mode, in make test; the rest of
    the matrix (every victim through every option: one writer's check) in CI (slow)."""
    for m, mode in enumerate(MODES):
        for v, victim in enumerate(VICTIMS):
            for o, option in enumerate(OPTIONS):
                marks = () if (v + m) % len(OPTIONS) == o else (pytest.mark.slow,)
                yield pytest.param(mode, option, victim, marks=marks,
                                   id=f"{victim}-{option}-{mode}")


@pytest.mark.parametrize(("mode", "option", "victim"), list(_writes()))
def test_check_never_writes_over_a_file_it_read(repo, mode, option, victim):
    # `check DIR -o DIR/robot.urdf`: the checked files, what they read and the configuration
    before = snapshot(repo)
    target = f"sarif:{victim}" if option == "--extra-output" else victim
    result = run_urdftool("check", mode, "--jobs", "1", str(repo), option, target,
                          *(["-o", "report.txt"] if option == "--extra-output" else []))
    refused(result, victim)
    assert snapshot(repo) == before  # not the report either: nothing is written


@pytest.mark.parametrize("mode", MODES)
def test_check_never_writes_over_the_baseline_it_compared_with(repo, mode):
    assert run_urdftool("check", mode, "broken.urdf", "--write-baseline", "b.json").code == 0
    before = snapshot(repo)
    refused(run_urdftool("check", mode, "broken.urdf", "--baseline", "b.json",
                         "--extra-output", "sarif:new.sarif", "-o", "b.json"), "b.json",
            before=1)  # the baseline's summary
    assert snapshot(repo) == before  # not new.sarif either


@pytest.mark.parametrize("mode", MODES)
def test_check_in_worker_processes_knows_what_they_read(repo, mode):
    for n in range(3):
        shutil.copy(repo / "mesh.urdf", repo / f"mesh{n}.urdf")
    before = snapshot(repo)
    refused(run_urdftool("check", mode, "--jobs", "2", ".", "-o", "part.stl"), "part.stl")
    assert snapshot(repo) == before


@pytest.mark.parametrize("mode", MODES)
def test_no_write_through_a_link(repo, tmp_path, mode):
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "keep.txt").write_text("theirs")
    (repo / "out").symlink_to(outside)  # a directory link committed in the repository
    (repo / "report.sarif").symlink_to(outside / "keep.txt")  # a file link
    (repo / "hard.urdf").hardlink_to(repo / "broken.urdf")  # a second name of an input
    before = snapshot(repo, outside)
    for args in (["-o", "out/report.txt"], ["-o", "report.sarif"],
                 ["--write-baseline", "out/baseline.json"],
                 ["--extra-output", "sarif:report.sarif"], ["-o", "out/new/deeper.txt"]):
        refused(run_urdftool("check", mode, "broken.urdf", *args), "symbolic link")
    refused(run_urdftool("check", mode, "broken.urdf", "-o", "hard.urdf"), "overwrite")
    refused(run_urdftool("expand", mode, "robot.urdf.xacro", "-o", "out/robot.urdf"),
            "symbolic link")
    refused(run_urdftool("check", mode, "--fix", "-o", "out/fixed.urdf", "broken.urdf"),
            "symbolic link")
    (repo / "link.urdf").symlink_to(repo / "broken.urdf")
    before = snapshot(repo, outside)
    refused(run_urdftool("check", mode, "--fix", "--in-place", "link.urdf"), "symbolic link")
    assert snapshot(repo, outside) == before


def test_a_link_above_the_repository_is_the_operators(tmp_path, monkeypatch):
    # the directories above the repository are the operator's: a link there is followed
    real = tmp_path / "real"
    (real / "repo" / ".git").mkdir(parents=True)
    (real / "repo" / "broken.urdf").write_text(BROKEN)
    (tmp_path / "alias").symlink_to(real)
    monkeypatch.chdir(real / "repo")
    result = run_urdftool("check", "--trusted", "broken.urdf",
                          "-o", str(tmp_path / "alias" / "report.txt"))
    assert result.code == 1, result.err
    assert "xml.unclosed-tag" in (real / "report.txt").read_text()


@pytest.mark.parametrize("mode", MODES)
def test_fix_in_place_replaces_only_its_own_files(repo, mode):
    result = run_urdftool("check", mode, "--fix", "--in-place", "broken.urdf")
    assert result.code in (0, 1), result.err
    assert "<link name=\"base\"/>" in (repo / "broken.urdf").read_text()
    assert not list(repo.glob(".*.tmp"))


@pytest.mark.parametrize("mode", MODES)
def test_sim_render_refuses_links_and_inputs_before_simulating(repo, tmp_path, mode):
    import pybullet  # noqa: F401 - the test extra has it: missing, this fails
    outside = tmp_path / "outside"
    outside.mkdir()
    (repo / "pictures").symlink_to(outside)
    (repo / "shot.png").symlink_to(outside / "shot.png")
    before = snapshot(repo, outside)
    for target in ("pictures", "pictures/", "pictures/new/", "shot.png"):
        refused(run_urdftool("sim", mode, "mesh.urdf", "--render", target), target)
    assert snapshot(repo, outside) == before


def test_sim_render_writes_a_picture_in_a_new_directory(repo):
    import pybullet  # noqa: F401 - the test extra has it: missing, this fails
    result = run_urdftool("sim", "--trusted", "mesh.urdf", "--render", "pictures/new/")
    assert result.code in (0, 1), result.err
    picture = repo / "pictures" / "new" / "mesh.png"
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (repo / "pictures" / "new" / "mesh-collision.png").is_file()


def test_untrusted_runs_write_no_cache(repo, tmp_path, monkeypatch):
    from urdftool.physics import meshes

    monkeypatch.delenv("URDFTOOL_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    for args in (["mesh.urdf"], ["--changed", "mesh.urdf", "robot.urdf.xacro"], ["."]):
        meshes.clear_cache()  # each run as a new process: the mesh is parsed
        result = run_urdftool("check", "--untrusted", "--jobs", "1", *args)
        assert result.code in (0, 1), result.err
        monkeypatch.setenv("CI", "true")  # the same as --untrusted
        meshes.clear_cache()
        result = run_urdftool("check", "--jobs", "1", *args)
        assert result.code in (0, 1), result.err
        monkeypatch.delenv("CI")
    assert not (tmp_path / "xdg").exists() and not (tmp_path / "home").exists()
    # a trusted run writes both kinds of entries; so does an untrusted one told where
    meshes.clear_cache()
    assert run_urdftool("check", "--trusted", "--changed", "mesh.urdf").code in (0, 1)
    assert {p.name for p in (tmp_path / "xdg" / "urdftool").iterdir()} == {"mesh", "reads"}
    monkeypatch.setenv("URDFTOOL_CACHE_DIR", str(tmp_path / "named"))
    meshes.clear_cache()
    assert run_urdftool("check", "--untrusted", *SLOW, "--changed", "mesh.urdf").code in (0, 1)
    assert {p.name for p in (tmp_path / "named").iterdir()} == {"mesh", "reads"}


def test_cache_directory_link_inside_the_repository_is_not_followed(repo, tmp_path,
                                                                    monkeypatch):
    outside = tmp_path / "outside"
    outside.mkdir()
    (repo / "cache").symlink_to(outside)
    monkeypatch.setenv("URDFTOOL_CACHE_DIR", str(repo / "cache" / "urdftool"))
    assert run_urdftool("check", "--trusted", "mesh.urdf").code in (0, 1)
    assert list(outside.iterdir()) == []  # the cache is only ever skipped


def test_names_after_the_separator_are_files(repo):
    # issue 20.4 on the command line itself: after `--` (and after `--changed`) every argument
    # is a file name, an option's value stays its value, a file named --debug turns nothing on
    (repo / "--exit-zero").write_text(BROKEN)
    (repo / "x:=y.urdf").write_text(BROKEN)
    result = run_urdftool("check", "--trusted", "--", "--exit-zero", "x:=y.urdf")
    assert result.code == 1 and "--exit-zero:2:" in result.out and "x:=y.urdf:2:" in result.out
    (repo / "--exit-zero.urdf").write_text(BROKEN)
    result = run_urdftool("check", "--trusted", "--changed", "--exit-zero", "--exit-zero.urdf")
    assert result.code == 1 and "--exit-zero.urdf:2:" in result.out, result.out + result.err
    result = run_urdftool("check", "--trusted", "-o", "--changed", "broken.urdf")
    assert result.code == 1 and "xml.unclosed-tag" in (repo / "--changed").read_text()
    refused(run_urdftool("check", "--trusted", "--", "--debug"), "--debug")
