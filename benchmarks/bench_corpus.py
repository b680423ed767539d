"""The 1164-file corpus in one `urdftool check` against a `check_urdf` loop and against an
earlier urdftool, all measured in this one run (issue 21.5), printing ratios.

Corpus: every pybullet_data URDF (its 1000 random_urdfs objects included) and every
example-robot-data URDF. Compared, interleaved run by run so that load changes hit them alike
(median wall time of --runs runs):

  check_urdf   urdfdom's C++ check_urdf (the `pin` wheel's cmeel prefix), one process per file
  this tree    python -m urdftool check --format json FILES (default --jobs, and --jobs 1)
  baseline     the same command from a git worktree of --baseline (default 3504ce4), run with
               the same interpreter and virtualenv through PYTHONPATH

Each urdftool has its own mesh-summary cache, filled by one untimed run first (the cache's
format may differ between versions). Start-up, same interleaving: a primitive-geometry URDF
and a xacro robot (robots/open_manipulator/corrected), this tree against the baseline.

Usage: python benchmarks/bench_corpus.py [--runs N] [--baseline COMMIT]
Targets: corpus faster than the check_urdf loop (ratio < 1), at least as fast as the baseline
(ratio <= 1); start-up no slower than the baseline.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from bench_check import check_urdf_command

from tests.conftest import SMALL, example_robot_urdfs, pybullet_data_dir


def corpus() -> list[str]:
    return [str(p) for p in sorted(pybullet_data_dir().rglob("*.urdf")) + example_robot_urdfs()]


CPU: dict[str, list[float]] = {}  # label -> CPU seconds (user + system) of each run


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def loop(command: list[str], files: list[str], env: dict) -> float:
    """Wall time of ``command FILE`` for each file in turn."""
    start = time.perf_counter()
    for path in files:
        subprocess.run(command + [path], check=False, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL, env=env)
    return time.perf_counter() - start


def once(command: list[str], env: dict) -> float:
    """Wall time of one run of ``command`` (no ``timeout=``: see bench_check.interleaved)."""
    start = time.perf_counter()
    subprocess.run(command, check=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                   env=env)
    return time.perf_counter() - start


def medians(series: list[tuple[str, object]], runs: int) -> dict[str, float]:
    """Median of each timed callable, called in turn ``runs`` times (interleaved), and
    (``CPU``) the CPU time of each of its runs."""
    times: dict[str, list[float]] = {label: [] for label, _ in series}
    for _ in range(runs):
        for label, run in series:
            cpu = _children_cpu()
            times[label].append(run())
            CPU.setdefault(label, []).append(_children_cpu() - cpu)
    return {label: statistics.median(values) for label, values in times.items()}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--baseline", default="3504ce4")
    args = parser.parse_args()
    files = corpus()
    check_urdf, check_urdf_env = check_urdf_command()
    base_env = {k: v for k, v in os.environ.items() if k not in ("PYTHONDONTWRITEBYTECODE", "CI")}
    with tempfile.TemporaryDirectory() as tmp:
        tree = Path(tmp) / "baseline"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "--quiet",
                        str(tree), args.baseline], check=True)
        try:
            envs = {}
            for name, source in (("this tree", ROOT), ("baseline", tree)):
                envs[name] = {**base_env, "PYTHONPATH": str(source),
                              "URDFTOOL_CACHE_DIR": str(Path(tmp) / f"cache-{name}")}
            small = Path(tmp) / "small.urdf"
            small.write_text(SMALL)
            xacro_robot = ROOT / "robots" / "open_manipulator" / "corrected" / \
                "open_manipulator.urdf.xacro"
            command = [sys.executable, "-m", "urdftool", "check", "--format", "json"]
            for name, env in envs.items():  # bytecode written, mesh caches filled: untimed
                subprocess.run(command + files, env=env, check=False,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                subprocess.run(command + [str(xacro_robot)], env=env, check=False,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            series = [("check_urdf loop", lambda: loop(check_urdf, files, check_urdf_env))]
            for name, env in envs.items():
                for jobs in ([], ["--jobs", "1"]):
                    series.append((f"{name}{' --jobs 1' if jobs else ''}",
                                   lambda env=env, jobs=jobs: once(command + jobs + files, env)))
            median = medians(series, args.runs)
            cpu = {label: statistics.median(CPU[label]) for label, _ in series}
            startup = {}
            for robot_name, robot in (("plain URDF", small), ("xacro robot", xacro_robot)):
                found = medians([(name, lambda env=env, robot=robot: once(command + [str(robot)], env))
                                 for name, env in envs.items()], args.runs * 5)
                startup[robot_name] = (found["this tree"], found["baseline"])
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)],
                           check=False)
    loop_time = median["check_urdf loop"]
    print(f"corpus: {len(files)} files (pybullet_data incl. random_urdfs + example-robot-data),"
          f" median of {args.runs} interleaved runs")
    print(f"  check_urdf, one process per file       {loop_time:7.2f} s   "
          f"(CPU {cpu['check_urdf loop']:.2f} s)")
    for jobs in ("", " --jobs 1"):
        this, base = median[f"this tree{jobs}"], median[f"baseline{jobs}"]
        print(f"  urdftool{jobs or ' (default jobs)':<14} this tree {this:6.2f} s   "
              f"{args.baseline} {base:6.2f} s   this/check_urdf {this / loop_time:.2f}x "
              f"(target < 1)   this/{args.baseline} {this / base:.2f}x (target <= 1)   "
              f"CPU this {cpu[f'this tree{jobs}']:.2f} s, {args.baseline} "
              f"{cpu[f'baseline{jobs}']:.2f} s")
    print(f"  load average at the end: {os.getloadavg()[0]:.1f} (wall ratios mean little above"
          " ~1 on two CPUs: the CPU columns are the load-independent ones)")
    for robot_name, (this, base) in startup.items():
        print(f"  start-up, {robot_name:<12} this tree {this * 1000:6.1f} ms   {args.baseline} "
              f"{base * 1000:6.1f} ms   ratio {this / base:.2f}x (target <= 1)")


if __name__ == "__main__":
    main()
