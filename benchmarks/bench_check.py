"""Time `urdftool check` against urdfdom's `check_urdf` on the same files and print ratios.

Figures (wall time, median of several runs, all measured in this one run):
  floor      python -c "import lxml.etree, click, xacro"  (a Python CLI of this kind cannot beat it)
  small      one primitive-geometry robot: urdftool check vs check_urdf
  large      a robot with 30+ links: urdftool check vs check_urdf
  corpus     every pybullet_data (without random_urdfs) and example-robot-data URDF:
             ONE urdftool invocation vs one check_urdf process per file; urdftool with the
             families check_urdf's checks fall in (xml, schema, structure), without the
             mesh-based families, and with every rule (meshes parsed: --no-cache; and with
             the mesh-summary cache warm), each with the default --jobs and with --jobs 1

check_urdf is the C++ binary that the `pin` wheel ships (cmeel.prefix/bin/check_urdf, run with
LD_LIBRARY_PATH=cmeel.prefix/lib), not the pip wrapper script.

Usage: python benchmarks/bench_check.py [--runs N]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tests.conftest import SMALL, example_robot_urdfs, pybullet_urdfs


def check_urdf_command() -> tuple[list[str], dict]:
    import cmeel  # noqa: F401 - the pin wheel's prefix

    for entry in sys.path:
        prefix = Path(entry) / "cmeel.prefix"
        if (prefix / "bin" / "check_urdf").is_file():
            env = {**os.environ, "LD_LIBRARY_PATH": str(prefix / "lib")}
            return [str(prefix / "bin" / "check_urdf")], env
    raise SystemExit("check_urdf not found (pip install pin)")


def wall(command: list[str], runs: int, env: dict | None = None) -> float:
    """Median wall time of `command` in seconds."""
    return interleaved([command], runs, env)[0]


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=7)
    args = parser.parse_args()
    urdftool = [sys.executable, "-m", "urdftool", "check", "--format", "json"]
    check_urdf, env = check_urdf_command()
    # start-up figures are only meaningful with bytecode: PYTHONDONTWRITEBYTECODE recompiles
    # every module at each start (about twice the start-up); warm the bytecode once
    ours_env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}

    with tempfile.TemporaryDirectory() as tmp:
        small = Path(tmp) / "small.urdf"
        small.write_text(SMALL)
        corpus = [str(p) for p in pybullet_urdfs() + example_robot_urdfs()]
        large = max(example_robot_urdfs(), key=lambda p: p.read_text().count("<link"))
        n_links = large.read_text().count("<link")
        ours_env["URDFTOOL_CACHE_DIR"] = str(Path(tmp) / "cache")
        subprocess.run(urdftool + [str(small)], env=ours_env, stdout=subprocess.DEVNULL,
                       check=False)

        floor_cmd = [sys.executable, "-c", "import lxml.etree, click, xacro"]
        floor, ours_small = interleaved([floor_cmd, urdftool + [str(small)]], args.runs * 3,
                                        ours_env)
        ours_small_text = wall(urdftool[:-2] + [str(small)], args.runs, ours_env)
        theirs_small = wall(check_urdf + [str(small)], args.runs, env)
        ours_large = wall(urdftool + [str(large)], args.runs, ours_env)
        theirs_large = wall(check_urdf + [str(large)], args.runs, env)

        start = time.perf_counter()
        for path in corpus:
            subprocess.run(check_urdf + [path], check=False, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL, env=env)
        theirs_corpus = time.perf_counter() - start
        runs = max(1, args.runs // 3)
        same_scope = wall(urdftool + ["--select", "xml,schema,structure"] + corpus, runs, ours_env)
        same_scope_1 = wall(urdftool + ["--jobs", "1", "--select", "xml,schema,structure"]
                            + corpus, runs, ours_env)
        no_meshes = wall(urdftool + ["--ignore", "inertia,mesh,geometry"] + corpus, runs,
                         ours_env)
        cold = wall(urdftool + ["--no-cache"] + corpus, 1, ours_env)
        cold_1 = wall(urdftool + ["--no-cache", "--jobs", "1"] + corpus, 1, ours_env)
        filling = wall(urdftool + corpus, 1, ours_env)  # the first run with a cache fills it
        warm = wall(urdftool + corpus, runs, ours_env)
        warm_1 = wall(urdftool + ["--jobs", "1"] + corpus, runs, ours_env)

    ms = 1000.0
    print(f"floor (import lxml.etree, click, xacro): {floor * ms:7.1f} ms")
    print(f"small robot   urdftool {ours_small * ms:7.1f} ms   check_urdf {theirs_small * ms:6.1f} ms"
          f"   urdftool/floor = {ours_small / floor:.2f}x (target <= 1.5x)")
    print(f"small robot   urdftool, default text output {ours_small_text * ms:7.1f} ms   "
          f"urdftool/floor = {ours_small_text / floor:.2f}x")
    print(f"large robot   ({large.name}, {n_links} links) urdftool {ours_large * ms:7.1f} ms   "
          f"check_urdf {theirs_large * ms:6.1f} ms   ratio {ours_large / theirs_large:.1f}x")
    print(f"corpus        {len(corpus)} files, check_urdf one process per file: "
          f"{theirs_corpus:6.2f} s")
    rows = [("xml, schema, structure (check_urdf's scope)", same_scope, same_scope_1),
            ("every rule but inertia, mesh, geometry", no_meshes, None),
            ("every rule, meshes parsed (--no-cache)", cold, cold_1),
            ("every rule, first run filling the mesh cache", filling, None),
            ("every rule, mesh cache warm", warm, warm_1)]
    for label, default_jobs, one_job in rows:
        single = f"   --jobs 1 {one_job:6.2f} s" if one_job is not None else ""
        print(f"  urdftool, one invocation, {label}: {default_jobs:6.2f} s "
              f"(ratio {default_jobs / theirs_corpus:.2f}x, target < 1){single}")


def interleaved(commands: list[list[str]], runs: int, env: dict | None) -> list[float]:
    """Median wall time of each command, run in turn (so load changes hit them alike). No
    ``timeout=``: with one, subprocess polls the child with growing sleeps, which rounds
    every time up to its steps (a 51 ms run measured 64 ms, a 3 ms one 4-7 ms)."""
    times: list[list[float]] = [[] for _ in commands]
    for _ in range(runs):
        for command, series in zip(commands, times):
            start = time.perf_counter()
            subprocess.run(command, check=False, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL, env=env)
            series.append(time.perf_counter() - start)
    return [statistics.median(series) for series in times]


if __name__ == "__main__":
    main()
