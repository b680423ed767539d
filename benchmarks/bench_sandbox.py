"""What the untrusted sandbox costs, and that `check` on a plain URDF did not get slower.

Figures (wall time, median of several runs, all measured in this one run, interleaved so that
load changes hit them alike):
  floor        python -c pass, and python -c "import lxml.etree" + a parse of the file
  start-up     `urdftool check` of a plain primitive URDF (tests.conftest.SMALL): this tree vs
               the baseline commit (default 3504ce4, before the sandbox; extracted with
               `git archive`, run with the same interpreter), trusted and under CI=true (a
               plain URDF is read in-process in both modes: no reader is started)
  xacro        `urdftool check` of a small xacro robot, --trusted vs CI=true (the reader)
  reader       in one process: a fresh sandboxed reader's start (python -I, imports,
               confinement) and one `load` request of the small xacro file, against the
               in-process load of the same file

Usage: python benchmarks/bench_sandbox.py [--runs N] [--baseline COMMIT]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from io import BytesIO
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from benchmarks.bench_check import interleaved
from tests.conftest import SMALL

XACRO = ('<?xml version="1.0"?>\n<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
         '  <xacro:property name="l" value="0.5"/>\n'
         '  <xacro:macro name="arm" params="n"><link name="l${n}"><inertial>'
         '<mass value="${n + 1}"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>'
         '</inertial><visual><geometry><box size="${l} 0.1 0.1"/></geometry></visual>'
         '</link></xacro:macro>\n'
         + "".join(f'  <xacro:arm n="{i}"/>\n' for i in range(6))
         + "".join(f'  <joint name="j{i}" type="revolute"><parent link="l{i}"/>'
                   f'<child link="l{i + 1}"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" '
                   'effort="1" velocity="1"/></joint>\n' for i in range(5))
         + "</robot>\n")


def baseline_tree(commit: str, into: Path) -> Path:
    """The urdftool package of ``commit``, extracted (no worktree, nothing checked out)."""
    archive = subprocess.run(["git", "archive", commit, "urdftool"], cwd=ROOT, check=True,
                             capture_output=True).stdout
    with tarfile.open(fileobj=BytesIO(archive)) as tar:
        tar.extractall(into, filter="data")
    return into


def in_process(runs: int, path: Path) -> dict[str, float]:
    """Median seconds of a reader's start, a request to it, and the same load in-process."""
    from urdftool import sandbox
    from urdftool.loader import load
    from urdftool.roots import Roots
    from urdftool.source import LoadOptions

    starts, requests, local = [], [], []
    for _ in range(runs):
        started = time.perf_counter()
        child = sandbox.Child([path.parent], 1024)
        starts.append(time.perf_counter() - started)
        request = {"op": "load", "path": str(path), "packages": {}, "xacro_args": {},
                   "sdf_model": None, "sdf_model_paths": [], "allow_env": [], "timeout": 3.0,
                   "roots": Roots([path.parent]).to_json()}
        child.ask(request, 5.0, "bench")  # the first request imports what loading needs
        started = time.perf_counter()
        child.ask(request, 5.0, "bench")
        requests.append(time.perf_counter() - started)
        child.close()
        started = time.perf_counter()
        load(path, LoadOptions())
        local.append(time.perf_counter() - started)
    return {"start": statistics.median(starts), "request": statistics.median(requests),
            "in-process": statistics.median(local)}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=9)
    parser.add_argument("--baseline", default="3504ce4")
    args = parser.parse_args()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONDONTWRITEBYTECODE", "CI")}
    ci_env = {**env, "CI": "true"}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        plain, xacro = tmp / "small.urdf", tmp / "small.urdf.xacro"
        plain.write_text(SMALL)
        xacro.write_text(XACRO)
        old = baseline_tree(args.baseline, tmp / "baseline")
        boot = "import sys; sys.path.insert(0, sys.argv.pop(1)); from urdftool.cli import main; main()"
        run_old = [sys.executable, "-c", boot, str(old)]
        run_new = [sys.executable, "-m", "urdftool"]
        check = ["check", "--format", "json", "--no-cache"]
        floor = [[sys.executable, "-c", "pass"],
                 [sys.executable, "-c", "import sys, lxml.etree; lxml.etree.parse(sys.argv[1])",
                  str(plain)]]
        startup = [[*run_old, *check, str(plain)], [*run_new, *check, str(plain)]]
        for command in startup:  # bytecode written once, before timing
            subprocess.run(command, check=False, capture_output=True, env=env)
        trusted = interleaved([*floor, *startup], args.runs, env)
        untrusted = interleaved(startup, args.runs, ci_env)
        xacro_times = interleaved([[*run_new, *check, "--trusted", str(xacro)],
                                   [*run_new, *check, "--untrusted", str(xacro)]],
                                  args.runs, env)
        reader = in_process(args.runs, xacro)
    python, parse, old_plain, new_plain = trusted
    ms = 1000

    def line(label, seconds, reference=None):
        ratio = f"  {seconds / reference:5.2f}x" if reference else ""
        print(f"  {label:52s} {seconds * ms:7.1f} ms{ratio}")

    print(f"floor ({args.runs} runs, medians)")
    line("python -c pass", python)
    line("python: import lxml, parse the URDF", parse, python)
    print(f"check on a plain URDF: baseline {args.baseline} vs this tree")
    line(f"{args.baseline} --trusted (no CI)", old_plain, python)
    line("this tree --trusted (no CI)", new_plain, python)
    line(f"{args.baseline} CI=true", untrusted[0], python)
    line("this tree CI=true", untrusted[1], python)
    print(f"  ratio this/baseline: {new_plain / old_plain:.2f} (no CI), "
          f"{untrusted[1] / untrusted[0]:.2f} (CI=true)")
    print("check on a small xacro robot")
    line("--trusted (expanded in-process)", xacro_times[0], python)
    line("--untrusted (a sandboxed reader started)", xacro_times[1], python)
    print(f"  the sandbox adds {(xacro_times[1] - xacro_times[0]) * ms:.1f} ms to a one-file run")
    print("the sandboxed reader, in one process")
    line("start (python -I, imports, confinement)", reader["start"], python)
    line("one load request (small xacro)", reader["request"], python)
    line("the same load in-process", reader["in-process"], python)


if __name__ == "__main__":
    main()
