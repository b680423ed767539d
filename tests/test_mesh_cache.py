"""The persistent mesh-summary cache (``urdftool.cache``, issue 2): a warm run gives the cold
run's findings without parsing a mesh; changed files are re-read; corrupt entries, unwritable
cache directories and concurrent writers fall back to loading; ``--no-cache`` reads and writes
nothing. Every test gets its own empty cache directory (tests/conftest.py)."""

from __future__ import annotations

import json
import multiprocessing
import os
from pathlib import Path

import numpy as np
import pytest
import trimesh

from tests.conftest import example_robot_urdfs, pybullet_urdfs, run_urdftool
from urdftool import cache
from urdftool.physics import links, meshes

# the sandboxed reader parses meshes within --timeout: on a loaded machine the default 3 s timed
# them out (not cached: a transient error), which is not what these tests are about
UNTRUSTED = ("--untrusted", "--timeout", "60")


def fresh_process():
    """What a new ``urdftool`` process starts with: no summaries in memory."""
    meshes.clear_cache()
    links._last = None


def check_json(*args) -> tuple[dict, int]:
    """(JSON report, meshes parsed) of one ``check`` run in a fresh process state."""
    fresh_process()
    result = run_urdftool("check", "--format", "json", *map(str, args))
    assert result.code in (0, 1), result.err
    return json.loads(result.out), meshes.LOADS


def entries() -> list[Path]:
    return sorted((cache.directory() / "mesh").glob("*"))


def box_robot(directory: Path, extents=(0.2, 0.1, 0.05), role="collision") -> Path:
    """A robot whose one link is a box mesh with unit inertia (so its findings quote the mesh's
    size)."""
    trimesh.creation.box(extents=extents).export(directory / "box.stl")
    path = directory / "robot.urdf"
    path.write_text('<robot name="r"><link name="a"><inertial><mass value="2"/><inertia ixx="1" '
                    'ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'
                    f'<{role}><geometry><mesh filename="box.stl"/></geometry></{role}></link>'
                    '</robot>')
    return path


def messages(report: dict) -> list[str]:
    return [d["message"] for f in report["files"] for d in f["diagnostics"]]


def test_cache_location(monkeypatch, tmp_path):
    monkeypatch.setenv("URDFTOOL_CACHE_DIR", str(tmp_path / "explicit"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache.directory() == tmp_path / "explicit"
    monkeypatch.delenv("URDFTOOL_CACHE_DIR")
    assert cache.directory() == tmp_path / "xdg" / "urdftool"
    monkeypatch.delenv("XDG_CACHE_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert cache.directory() == tmp_path / "home" / ".cache" / "urdftool"


def corpus_robots() -> list[Path]:
    """Real robots with DAE (with units and up axes), STL and OBJ meshes, visual-only meshes
    and meshes whose volume is needed."""
    names = {"talos_full_v2.urdf", "ur5_robot.urdf", "solo12.urdf", "kuka_iiwa/model.urdf",
             "r2d2.urdf", "husky/husky.urdf", "pr2_gripper.urdf"}
    robots = [p for p in example_robot_urdfs() + pybullet_urdfs()
              if p.name in names or f"{p.parent.name}/{p.name}" in names]
    assert len(robots) == len(names)
    return robots


def test_warm_run_parses_nothing_and_finds_the_same_on_real_robots():
    robots = corpus_robots()
    cold = [check_json(robot) for robot in robots]  # one file: checked in-process
    # one entry per file (a file first met as a visual, then needed for its volume, is
    # parsed twice)
    assert sum(loads for _, loads in cold) >= len(entries()) > 50
    warm = [check_json(robot) for robot in robots]
    assert [loads for _, loads in warm] == [0] * len(robots)
    assert [report for report, _ in warm] == [report for report, _ in cold]
    assert sum(len(f["diagnostics"]) for r, _ in cold for f in r["files"]) > 10


def test_warm_run_over_a_pool_of_workers(tmp_path, monkeypatch):
    """Several files are checked in forked workers (which share the cache directory): count
    the parses in a file, since LOADS only counts those of this process."""
    log = tmp_path / "parses"
    original = meshes._load

    def logged(path, need_volume):
        with open(log, "a") as handle:
            handle.write(f"{path}\n")
        return original(path, need_volume)

    monkeypatch.setattr(meshes, "_load", logged)
    robots = corpus_robots()
    cold, _ = check_json(*robots)
    parsed = log.read_text().splitlines()
    assert len(parsed) >= len(set(parsed)) == len(entries()) > 50
    stored = {entry: entry.read_bytes() for entry in entries()}
    warm, _ = check_json(*robots)
    assert warm == cold
    assert log.read_text().splitlines() == parsed  # nothing parsed
    assert {entry: entry.read_bytes() for entry in entries()} == stored  # nor written


def test_a_changed_file_is_read_again(tmp_path):
    path = box_robot(tmp_path)
    first, loads = check_json(path)
    assert loads == 1
    assert check_json(path) == (first, 0)
    # a different size: the new box's numbers, not the stored ones
    box_robot(tmp_path, extents=(0.2, 0.3, 0.05))
    second, loads = check_json(path)
    assert loads == 1 and messages(second) != messages(first)
    # same size, new mtime, other content: read again
    box_robot(tmp_path, extents=(0.2, 0.3, 0.06))
    stat = os.stat(tmp_path / "box.stl")
    os.utime(tmp_path / "box.stl", ns=(stat.st_atime_ns, stat.st_mtime_ns + 10**9))
    third, loads = check_json(path)
    assert loads == 1 and messages(third) != messages(second)
    assert check_json(path) == (third, 0)
    assert len(entries()) == 1  # one entry per file: a change replaces it
    # new mtime, same content (a fresh checkout, a cache restored in CI): its SHA-256 matches,
    # nothing parsed, and the entry now holds the new time
    os.utime(tmp_path / "box.stl", ns=(stat.st_atime_ns, stat.st_mtime_ns + 5 * 10**9))
    assert check_json(path) == (third, 0)
    header = json.loads(entries()[0].read_bytes().split(b"\n", 1)[0])
    assert header["key"]["mtime_ns"] == stat.st_mtime_ns + 5 * 10**9
    assert check_json(path) == (third, 0)


@pytest.mark.parametrize("damage", ["truncated", "extended", "garbage", "bad field",
                                    "other file", "empty hull", "old format"])
def test_a_corrupt_entry_is_never_trusted(tmp_path, damage):
    path = box_robot(tmp_path)
    expected, _ = check_json(path)
    (entry,) = entries()
    data = entry.read_bytes()
    header, _, values = data.partition(b"\n")
    stored = json.loads(header)
    if damage == "truncated":
        entry.write_bytes(data[:-5])
    elif damage == "extended":
        entry.write_bytes(data + b"\0" * 8)
    elif damage == "garbage":
        entry.write_bytes(b"\x93NUMPY\x01\x00" + data[:100])
    elif damage == "bad field":
        stored["data"]["lower"] = ["0", 0.0, 0.0]
        entry.write_bytes(json.dumps(stored).encode() + b"\n" + values)
    elif damage == "other file":
        stored["key"]["path"] = str(tmp_path / "other.stl")
        entry.write_bytes(json.dumps(stored).encode() + b"\n" + values)
    elif damage == "empty hull":
        stored["values"] = 0
        entry.write_bytes(json.dumps(stored).encode() + b"\n")
    else:
        stored["key"]["format"] -= 1
        entry.write_bytes(json.dumps(stored).encode() + b"\n" + values)
    assert check_json(path) == (expected, 1)
    assert check_json(path) == (expected, 0)  # and the entry was written again, whole


def test_an_unusable_cache_directory_falls_back_to_loading(tmp_path, monkeypatch):
    path = box_robot(tmp_path)
    expected, _ = check_json(path, "--no-cache")
    (tmp_path / "a-file").write_text("not a directory")
    monkeypatch.setenv("URDFTOOL_CACHE_DIR", str(tmp_path / "a-file" / "cache"))
    assert check_json(path) == (expected, 1)
    assert check_json(path) == (expected, 1)
    # a directory entry where the entry should be: reads and writes fail, loading does not
    monkeypatch.setenv("URDFTOOL_CACHE_DIR", str(tmp_path / "cache"))
    entry = cache._entry("mesh", cache.stamp((tmp_path / "box.stl").resolve(), meshes.READING))
    (entry / "sub").mkdir(parents=True)
    assert check_json(path) == (expected, 1)
    assert check_json(path) == (expected, 1)
    # no home directory to put it in
    monkeypatch.delenv("URDFTOOL_CACHE_DIR")
    monkeypatch.delenv("XDG_CACHE_HOME", raising=False)

    def no_home():
        raise RuntimeError("Could not determine home directory.")

    monkeypatch.setattr(Path, "home", no_home)
    assert check_json(path) == (expected, 1)
    assert check_json(path) == (expected, 1)


def test_no_cache_reads_and_writes_nothing(tmp_path):
    path = box_robot(tmp_path)
    real, _ = check_json(path)
    # a planted entry (valid, but twice the size): the cache is read when on...
    stl = (tmp_path / "box.stl").resolve()
    key = cache.stamp(stl, meshes.READING)
    header, hull = meshes._encode(meshes._load(stl, need_volume=True))
    header["lower"] = [2 * x for x in header["lower"]]
    header["upper"] = [2 * x for x in header["upper"]]
    cache.write("mesh", key, header, [2 * x for x in hull])
    planted, loads = check_json(path)
    assert loads == 0 and messages(planted) != messages(real)
    # ...and not with --no-cache, which leaves the planted entry alone
    before = entries()[0].read_bytes()
    assert check_json(path, "--no-cache") == (real, 1)
    assert entries()[0].read_bytes() == before
    # nothing written either
    other = tmp_path / "other"
    other.mkdir()
    box_robot(other)
    check_json(other / "robot.urdf", "--no-cache")
    assert len(entries()) == 1
    fresh_process()
    result = run_urdftool("inertia", "--format", "json", "--no-cache", other / "robot.urdf")
    assert result.code in (0, 1) and meshes.LOADS == 1 and len(entries()) == 1
    fresh_process()
    run_urdftool("inertia", "--format", "json", other / "robot.urdf")
    assert meshes.LOADS == 1 and len(entries()) == 2


def test_an_entry_without_volume_is_completed_when_the_volume_is_needed(tmp_path):
    box_robot(tmp_path)
    inertial = ('<inertial><mass value="2"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" '
                'izz="1"/></inertial>')
    mesh = '<geometry><mesh filename="box.stl"/></geometry>'
    # the mesh as a visual beside a collision box: its volume is not needed
    visual = tmp_path / "visual.urdf"
    visual.write_text(f'<robot name="r"><link name="a">{inertial}<visual>{mesh}</visual>'
                      '<collision><geometry><box size="0.2 0.1 0.05"/></geometry></collision>'
                      "</link></robot>")
    collision = tmp_path / "collision.urdf"
    collision.write_text(f'<robot name="r"><link name="a">{inertial}<collision>{mesh}'
                         "</collision></link></robot>")
    key = cache.stamp((tmp_path / "box.stl").resolve(), meshes.READING)
    assert check_json(visual)[1] == 1
    stored = meshes._decode(Path("box.stl"), cache.read("mesh", key))
    assert not stored.has_volume and stored.solid is None
    report, loads = check_json(collision)
    assert loads == 1
    assert check_json(collision) == (report, 0)
    stored = meshes._decode(Path("box.stl"), cache.read("mesh", key))
    assert stored.has_volume and stored.solid.volume == pytest.approx(0.2 * 0.1 * 0.05)
    assert check_json(visual)[1] == 0  # the complete entry serves the visual too


def test_errors_are_cached_and_untrusted_runs_use_the_cache(tmp_path):
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "package.xml").write_text("<package><name>pkg</name></package>")
    path = box_robot(package)
    (package / "broken.stl").write_text("solid x\n facet normal 0 0 1\n")
    path.write_text(path.read_text().replace(
        "</link>", '<visual><geometry><mesh filename="broken.stl"/></geometry></visual></link>'))
    cold, loads = check_json(path, *UNTRUSTED)
    assert loads == 2 and any("cannot be read" in m for m in messages(cold))
    assert check_json(path, *UNTRUSTED) == (cold, 0)
    assert check_json(path, "--trusted") == (cold, 0)


def _write_many(directory: str, key: dict, worker: int) -> None:
    os.environ["URDFTOOL_CACHE_DIR"] = directory
    for i in range(200):
        rows = 1 + (worker * 7 + i) % 50
        cache.write("mesh", key, {"rows": rows}, np.full((rows, 3), float(rows)))


def test_concurrent_writers_leave_whole_entries(tmp_path):
    key = {"path": "/some/mesh.stl", "size": 1, "mtime_ns": 2, "format": cache.FORMAT,
           "version": "x"}
    context = multiprocessing.get_context("fork")
    writers = [context.Process(target=_write_many, args=(str(cache.directory()), key, w))
               for w in range(4)]
    for writer in writers:
        writer.start()
    seen = 0
    while any(writer.is_alive() for writer in writers) or seen == 0:
        stored = cache.read("mesh", key)
        if stored is not None:
            header, values = stored
            assert len(values) == 3 * header["rows"]
            assert set(values) == {header["rows"]}
            seen += 1
    for writer in writers:
        writer.join()
        assert writer.exitcode == 0
    assert seen > 0
    assert [p.name for p in entries()] == [cache._entry("mesh", key).name]  # no temp files left


def test_untrusted_run_writes_no_cache_unless_a_directory_is_named(monkeypatch, tmp_path):
    # checking a stranger's files writes nothing (CI=true is untrusted): the cache under the
    # home directory is read but not written; naming $URDFTOOL_CACHE_DIR opts in
    robot = box_robot(tmp_path)
    monkeypatch.delenv("URDFTOOL_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    cold, parsed = check_json(*UNTRUSTED, robot)
    assert parsed == 1 and not (tmp_path / "xdg").exists()
    assert check_json("--trusted", robot) == (cold, 1)
    assert len(entries()) == 1  # a trusted run writes it ...
    assert check_json(*UNTRUSTED, robot) == (cold, 0)  # ... and an untrusted one reads it
    monkeypatch.setenv("URDFTOOL_CACHE_DIR", str(tmp_path / "named"))
    check_json(*UNTRUSTED, robot)
    assert len(entries()) == 1 and entries()[0].is_relative_to(tmp_path / "named")


def test_a_mesh_changed_between_runs_of_one_process_is_read_again(tmp_path, monkeypatch):
    """The language server runs many checks in one process: a mesh exported again between
    two of them is read again (the summaries a process keeps are dropped when the file's size
    or time changed), so the bound follows the new geometry."""
    import json

    import trimesh

    from tests.conftest import run_urdftool

    monkeypatch.setenv("URDFTOOL_CACHE_DIR", str(tmp_path / "cache"))
    mesh = tmp_path / "part.stl"
    robot = tmp_path / "r.urdf"
    robot.write_text(
        '<robot name="r"><link name="base"><inertial><mass value="1"/>'
        '<inertia ixx="0.05" ixy="0" ixz="0" iyy="0.05" iyz="0" izz="0.05"/></inertial>'
        '<collision><geometry><mesh filename="part.stl"/></geometry></collision></link>'
        '</robot>\n')

    def bound_findings() -> list[str]:
        out = run_urdftool("check", "--format", "json", "--jobs", "1", str(robot)).out
        return [d["rule"] for f in json.loads(out)["files"] for d in f["diagnostics"]
                if d["rule"] == "inertia.exceeds-geometry"]

    trimesh.creation.box(extents=(0.1, 0.1, 0.1)).export(mesh)
    assert bound_findings() == ["inertia.exceeds-geometry"]  # 0.05 kg m^2 in a 10 cm cube
    trimesh.creation.box(extents=(1.0, 1.0, 1.0)).export(mesh)
    assert bound_findings() == []  # the same process, the new 1 m cube: possible


def test_an_entry_read_the_old_way_is_read_again(tmp_path, monkeypatch):
    """A change in how meshes are read (``meshes.READING``: issue 29 stopped turning COLLADA
    up axes) makes every stored summary stale, whatever the file's time or content: a new
    mtime with the same content (the SHA-256 path) does not bring the old summary back."""
    path = box_robot(tmp_path)
    first, loads = check_json(path)
    assert loads == 1 and check_json(path) == (first, 0)
    monkeypatch.setattr(meshes, "READING", meshes.READING + 1)
    stat = os.stat(tmp_path / "box.stl")
    os.utime(tmp_path / "box.stl", ns=(stat.st_atime_ns, stat.st_mtime_ns + 10**9))
    assert check_json(path) == (first, 1)
    assert check_json(path) == (first, 0)  # stored again, the new way


def test_an_entry_is_hashed_from_the_bytes_read_not_read_again(tmp_path, monkeypatch):
    """A cold read stores the SHA-256 of the bytes it parsed (hashlib over the file, here), and
    never reads the file a second time to hash it (issue 33: 0.1 s of 309 COLLADA files)."""
    import hashlib

    trimesh.creation.box().export(tmp_path / "box.stl")
    trimesh.creation.icosphere().export(tmp_path / "ball.dae")
    monkeypatch.setattr(cache, "_digest", lambda path: pytest.fail(f"{path} read again"))
    monkeypatch.setattr(meshes, "PARSER", None)
    fresh_process()
    for name in ("box.stl", "ball.dae"):
        assert meshes.load_mesh(tmp_path / name, need_volume=True).ok
    stored = {json.loads(e.read_bytes().split(b"\n", 1)[0])["key"]["path"]:
              json.loads(e.read_bytes().split(b"\n", 1)[0])["sha256"] for e in entries()}
    assert stored == {str((tmp_path / n).resolve()):
                      hashlib.sha256((tmp_path / n).read_bytes()).hexdigest()
                      for n in ("box.stl", "ball.dae")}
