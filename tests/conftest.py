"""Shared test helpers: run the CLI in-process, and locate the robot corpora."""

from __future__ import annotations

import io
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
ROBOTS = ROOT / "robots"
# CI (.ci/run, CI=true): what a test needs must be there; read here, before the autouse fixture
# below removes CI from each test's environment
IN_CI = os.environ.get("CI") == "true"
# shared/ (real packages, realworld-dev, SDF cases): beside the repository (CI lays a copy
# there), else the developers' /work/shared
SHARED = next((p for p in (ROOT.parent / "shared", ROOT.parent.parent / "shared",
                           Path("/work/shared")) if p.is_dir()), ROOT.parent / "shared")


@dataclass
class Result:
    code: int
    out: str
    err: str


def run_urdftool(*args: str) -> Result:
    """Run `urdftool ARGS` in-process; returns exit code, stdout and stderr."""
    from urdftool.cli import main

    out, err = io.StringIO(), io.StringIO()
    saved = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = out, err
    try:
        main([str(a) for a in args])
        code = 0
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    finally:
        sys.stdout, sys.stderr = saved
    return Result(code, out.getvalue(), err.getvalue())


class WallLessWaiting:
    """``with WallLessWaiting() as clock: ...`` then ``clock.seconds``: the block's wall time less
    the longest time one thread of this process or of its live descendants (the sandboxed
    reader, worker processes) waited for a CPU other processes held (``redteam_batch.waited``).
    A bound on a deadline or a timer (wall-time behaviour) measured so that it holds on a loaded
    machine (HACKING "Tests"); for plain computation bound ``time.process_time()`` instead."""

    def __enter__(self):
        from tests.redteam_batch import waited

        self._before, self._started = waited(), time.monotonic()
        return self

    def __exit__(self, *exc):
        from tests.redteam_batch import waited

        wall = time.monotonic() - self._started
        after = waited()
        queued = max((value - self._before.get(task, 0.0) for task, value in after.items()),
                     default=0.0)
        self.wall, self.waited = wall, min(max(queued, 0.0), wall)
        self.seconds = wall - self.waited
        return False


def pybullet_data_dir() -> Path:
    import pybullet_data

    return Path(pybullet_data.getDataPath())


def example_robot_data_dir() -> Path:
    """The installed example-robot-data share folder (its robots/ holds the URDFs)."""
    import pinocchio  # noqa: F401  - makes cmeel.prefix importable

    for entry in sys.path:
        candidate = Path(entry) / "cmeel.prefix" / "share" / "example-robot-data"
        if candidate.is_dir():
            return candidate
    raise RuntimeError("example-robot-data is not installed")


# a typical primitive-geometry robot: start-up tests and benchmarks/bench_check.py
SMALL = """<?xml version="1.0"?>
<robot name="small">
  <link name="base">
    <inertial><mass value="2"/><inertia ixx="0.03" iyy="0.03" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><box size="0.3 0.3 0.3"/></geometry></visual>
    <collision><geometry><box size="0.3 0.3 0.3"/></geometry></collision>
  </link>
  <link name="wheel">
    <inertial><mass value="0.5"/><inertia ixx="0.0007" iyy="0.0007" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><cylinder radius="0.06" length="0.04"/></geometry></visual>
    <collision><geometry><cylinder radius="0.06" length="0.04"/></geometry></collision>
  </link>
  <joint name="axle" type="continuous"><parent link="base"/><child link="wheel"/>
    <origin xyz="0 0.2 0" rpy="1.5707963267948966 0 0"/><axis xyz="0 0 1"/>
    <limit effort="5" velocity="10"/></joint>
</robot>
"""


def pybullet_urdfs() -> list[Path]:
    """pybullet_data's robot URDFs (the thousand random_urdfs objects left out)."""
    base = pybullet_data_dir()
    return sorted(p for p in base.rglob("*.urdf") if "random_urdfs" not in p.parts)


def example_robot_urdfs() -> list[Path]:
    return sorted((example_robot_data_dir() / "robots").rglob("*.urdf"))


@pytest.fixture
def write(tmp_path):
    """write(text, name='robot.urdf') -> Path of a new file with that text."""

    def make(text: str, name: str = "robot.urdf") -> Path:
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
        return path

    return make


@pytest.fixture(autouse=True)
def _same_mode_under_ci(monkeypatch):
    """The CI variable makes --untrusted the default (issue 8); the suite runs the same on a CI
    runner as on a laptop, and tests that care say --trusted/--untrusted or set CI."""
    monkeypatch.delenv("CI", raising=False)


# -- mesh cache (issue 2) -------------------------------------------------------------------
@pytest.fixture(autouse=True)
def _own_mesh_cache(monkeypatch, tmp_path_factory):
    """Every test starts from its own empty persistent cache (tests stay independent), and
    with the cache on (``--no-cache`` in one test does not leak into the next)."""
    monkeypatch.setenv("URDFTOOL_CACHE_DIR", str(tmp_path_factory.mktemp("urdftool-cache")))
    monkeypatch.setattr("urdftool.cache.ENABLED", True)
    monkeypatch.setattr("urdftool.cache.WRITABLE", True)
# -- end mesh cache -------------------------------------------------------------------------


# -- CPU durations (issue 33) ---------------------------------------------------------------
# `pytest --cpu-durations=N`: the N tests that used the most CPU (this process and the children
# it waited for; setup, call and teardown). On a shared machine wall time (--durations) measures
# the load as much as the test; this is what a test costs an idle two-core machine.
def pytest_addoption(parser):
    parser.addoption("--cpu-durations", type=int, default=None, metavar="N",
                     help="list the N tests that used the most CPU time (with children)")
    parser.addoption("--cpu-durations-file", default=None, metavar="FILE",
                     help="with --cpu-durations: write every test's CPU seconds to FILE (JSON)")


def _cpu_seconds() -> float:
    import resource

    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    if item.config.getoption("cpu_durations") is not None:
        item._cpu_start = _cpu_seconds()
    yield


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    start = getattr(item, "_cpu_start", None)
    if start is not None and call.when == "teardown":
        outcome.get_result().user_properties.append(("cpu_seconds", _cpu_seconds() - start))


_CPU: dict[str, float] = {}


def pytest_runtest_logreport(report):
    for key, value in getattr(report, "user_properties", ()):
        if key == "cpu_seconds":
            _CPU[report.nodeid] = value


def pytest_terminal_summary(terminalreporter, config):
    count = config.getoption("cpu_durations")
    if count is None or not _CPU:
        return
    terminalreporter.write_sep("=", f"slowest {count} by CPU time (with children)")
    for nodeid, seconds in sorted(_CPU.items(), key=lambda kv: -kv[1])[:count]:
        terminalreporter.write_line(f"{seconds:8.2f}s cpu  {nodeid}")
    terminalreporter.write_line(f"{sum(_CPU.values()):8.2f}s cpu  total of {len(_CPU)} tests")
    if config.getoption("cpu_durations_file"):
        import json

        Path(config.getoption("cpu_durations_file")).write_text(json.dumps(_CPU, indent=1))
# -- end CPU durations ----------------------------------------------------------------------
