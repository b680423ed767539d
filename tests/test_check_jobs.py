"""`check --jobs N`: several files in forked worker processes give the report of one process,
in the same order; a file that cannot be checked is reported as without workers."""

from __future__ import annotations

import itertools
import json
import os
import shutil

import pytest

from tests.conftest import ROBOTS, pybullet_urdfs, run_urdftool
from urdftool import check
from urdftool.errors import ToolError

GOOD = """<robot name="good">
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
</robot>
"""


@pytest.fixture
def many(tmp_path):
    """The seed robots (URDF and xacro, published and corrected) and a dozen pybullet ones."""
    root = tmp_path / "many"
    shutil.copytree(ROBOTS, root / "robots")
    for index, path in enumerate(pybullet_urdfs()[:40:3]):
        shutil.copy(path, root / f"pybullet_{index:02d}_{path.name}")
    return root


# the workers' reports are merged before any format prints them: json in make test, the others
# in CI (slow; ~3 s)
@pytest.mark.parametrize("fmt", ["json", pytest.param("text", marks=pytest.mark.slow),
                                 pytest.param("sarif", marks=pytest.mark.slow)])
def test_jobs_give_the_report_of_one_process(many, fmt):
    one = run_urdftool("check", "--format", fmt, "--jobs", "1", many)
    two = run_urdftool("check", "--format", fmt, "--jobs", "2", many)
    assert one.code == two.code == 1  # the published seeds have errors
    # stderr: only the line that counts the files per role (a directory was given)
    assert one.out == two.out and one.err == two.err
    assert [line.split(":")[0] for line in one.err.splitlines()] == ["roles"]
    if fmt == "json":
        files = [f["path"] for f in json.loads(one.out)["files"]]
        assert len(files) > 20 and files == sorted(files)


def test_untrusted_xacro_expansion_in_workers(many):
    one = run_urdftool("check", "--untrusted", "--format", "json", "--jobs", "1", many / "robots")
    two = run_urdftool("check", "--untrusted", "--format", "json", "--jobs", "2", many / "robots")
    assert one.code == two.code == 1
    assert one.out == two.out
    report = json.loads(two.out)
    xacro_files = [f for f in report["files"]
                   if f["path"].endswith(".xacro") and "/corrected/" in f["path"]]
    assert len(xacro_files) == 4 and all(f["robot"] for f in xacro_files)  # expanded


def test_exit_codes_with_workers(tmp_path, write):
    for index in range(3):
        write(GOOD.replace("good", f"good{index}"), f"ok/r{index}.urdf")
    assert run_urdftool("check", "--jobs", "2", tmp_path / "ok").code == 0
    write(GOOD.replace('value="1"', 'value="-1"'), "ok/zz_bad_mass.urdf")
    assert run_urdftool("check", "--jobs", "2", tmp_path / "ok").code == 1
    assert run_urdftool("check", "--jobs", "0", tmp_path / "ok").code == 2


@pytest.mark.parametrize("jobs", ["1", "2", "3"])
def test_a_file_that_cannot_be_read_among_good_ones(tmp_path, write, jobs):
    for index in range(4):
        write(GOOD, f"dir/r{index}.urdf")
    (tmp_path / "dir" / "r2_binary.urdf").write_bytes(b"\x00\x01\x02\x89PNG\x00\x00binary")
    (tmp_path / "dir" / "r3_binary.urdf").write_bytes(b"\x00\x01\x02\x89PNG\x00\x00binary")
    result = run_urdftool("check", "--format", "json", "--jobs", jobs, tmp_path / "dir")
    assert result.code == 2 and "Traceback" not in result.err
    # one line, about the first file (in order) that could not be read
    assert result.err.strip().splitlines() == [
        f"urdftool: {tmp_path / 'dir' / 'r2_binary.urdf'}: binary file, not an XML robot description"]


def test_a_crashing_worker_is_reported_for_its_file_only(tmp_path, write, monkeypatch):
    paths = [write(GOOD, f"r{index}.urdf") for index in range(5)]
    real = check.check_file

    def crash_on_r2(path, options=None, target=None):
        if str(path).endswith("r2.urdf"):
            os._exit(3)  # a parser crashing the process (the pool cannot go on)
        return real(path, options, target)

    monkeypatch.setattr(check, "check_file", crash_on_r2)
    options = check.CheckOptions(jobs=2)
    with pytest.raises(ToolError, match=r"r2\.urdf: the check of this file crashed"):
        check.check_paths([str(tmp_path)], options)
    # the other files are checked in spite of the crash
    reports = check._check_in_workers([p for p in paths if p.name != "r2.urdf"], options, 2)
    assert [r.robot for r in reports] == ["good"] * 4
    monkeypatch.setattr(check, "check_file", real)
    assert [r.path for r in check.check_paths([str(tmp_path)], options).files] == \
        [str(p) for p in paths]


def test_an_unexpected_error_in_a_worker_is_reported_as_in_process(tmp_path, write, monkeypatch):
    for index in range(3):
        write(GOOD, f"r{index}.urdf")

    class Unpicklable(Exception):
        def __reduce__(self):
            raise TypeError("no")

    def fail(path, options=None, target=None):
        raise Unpicklable("boom")

    monkeypatch.setattr(check, "check_file", fail)
    for jobs in ("1", "2"):
        result = run_urdftool("check", "--jobs", jobs, tmp_path)
        assert result.code == 2
        assert "internal error" in result.err and "boom" in result.err
        assert "Unpicklable" in result.err


def test_default_jobs_follow_the_amount_of_work(monkeypatch, tmp_path, write):
    """A handful of small files: one process (a pool costs more than it saves). Otherwise the
    files are checked here first, and the rest go to workers only when the time measured so
    far says they are worth it."""
    assert check.available_cpus() == len(os.sched_getaffinity(0))
    for index in range(3):
        write(GOOD, f"r{index}.urdf")
    seen = []
    monkeypatch.setattr(check, "available_cpus", lambda: 2)
    monkeypatch.setattr(check, "_check_in_workers",
                        lambda files, options, jobs, progress=None: seen.append(
                            (jobs, len(files))) or
                        [check.check_file(f.path, options, f) for f in files])
    report = check.check_paths([str(tmp_path)])
    assert seen == [] and len(report.files) == 3
    assert check.default_jobs([str(p) for p in tmp_path.glob("*.urdf")]) == 1
    # 4 MB each (a comment): an estimate worth two workers, but checked in no time
    padding = "<!--" + "x" * 4_000_000 + "-->"
    for index in range(3):
        write(GOOD.replace("<robot", padding + "<robot", 1), f"big{index}.urdf")
    assert check.default_jobs([str(p) for p in tmp_path.glob("big*.urdf")]) == 2
    monkeypatch.setattr(check, "PROBE", 0.0)
    check.check_paths([str(tmp_path)])
    assert seen == []  # measured: not worth a worker
    monkeypatch.setattr(check, "WORK_PER_WORKER", 1e-9)  # as if every file took long
    report = check.check_paths([str(tmp_path)])
    assert seen == [(2, 5)] and [f.path for f in report.files] == sorted(
        str(p) for p in tmp_path.glob("*.urdf"))  # the first file here, the rest in 2 workers
    check.check_paths([str(tmp_path / "big0.urdf")])  # one file: in-process
    check.check_paths([str(tmp_path)], check.CheckOptions(jobs=1))
    check.check_paths([str(tmp_path)], check.CheckOptions(jobs=2))
    assert seen == [(2, 5), (2, 6)]


def test_runs_cover_the_files_in_order_with_about_equal_cost(tmp_path):
    """The worker runs: contiguous, covering every file once, and of about equal estimated
    cost (a thousand small files and a few large ones are not cut by count)."""
    paths = []
    for index in range(300):
        path = tmp_path / f"small_{index:03d}.urdf"
        path.write_text(GOOD)
        paths.append(str(path))
    for index in range(6):
        path = tmp_path / f"zlarge_{index}.urdf"
        path.write_text(GOOD + "<!--" + "x" * 400_000 + "-->\n")
        paths.append(str(path))
    runs = check._runs(paths, 2)
    assert runs[0][0] == 0 and runs[-1][1] == len(paths)
    assert all(a[1] == b[0] for a, b in itertools.pairwise(runs))
    costs = [check._cost(p) for p in paths]
    assert all(abs(cost - sum(costs[start:end])) < 1e-9 for start, end, cost in runs)
    share = sum(costs) / (2 * check.RUNS_PER_WORKER)
    largest = max(costs)
    # each run but the last reaches the share and overshoots it by less than one file
    assert all(share <= cost < share + largest for _, _, cost in runs[:-1])
    # the large files are not all in one run (a count-based cut put them together)
    assert len({start for start, end, _ in runs for i in range(start, end) if i >= 300}) >= 3


def test_a_large_run_starts_its_workers_without_the_whole_probe(tmp_path, monkeypatch):
    """The default --jobs forks its workers once the rest is surely worth them (after
    PROBE_SURE seconds, not the whole PROBE): checking here before the fork is time on one
    CPU. Files made slow (each check_file sleeps) show the decision, not the machine."""
    import time

    for index in range(40):
        (tmp_path / f"r{index:02d}.urdf").write_text(GOOD)
    real = check.check_file
    monkeypatch.setattr(check, "check_file",
                        lambda *a, **k: (time.sleep(0.03), real(*a, **k))[1])
    forked = []
    monkeypatch.setattr(check, "_check_in_workers",
                        lambda files, options, jobs, progress=None: forked.append(
                            (len(files), jobs)) or [real(f.path, options, f) for f in files])
    monkeypatch.setattr(check, "available_cpus", lambda: 2)
    monkeypatch.setattr(check, "default_jobs", lambda paths, *a: 2)
    monkeypatch.setattr(check, "PROBE", 10.0)  # the whole probe would check every file here
    monkeypatch.setattr(check, "WORK_PER_WORKER", 0.1)
    report = check.check_paths([str(tmp_path)])
    assert len(report.files) == 40
    # 40 x 30 ms = 1.2 s of work, twice 2 x 0.1 s after 2-3 files: forked early, to 2 workers
    assert len(forked) == 1 and forked[0][1] == 2 and forked[0][0] >= 35
    forked.clear()
    monkeypatch.setattr(check, "WORK_PER_WORKER", 1.0)  # the rest not surely worth it: probe
    check.check_paths([str(tmp_path)])
    assert forked == []
