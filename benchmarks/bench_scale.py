"""Growth of urdftool with the robot's size (issue 15), against baselines measured in the same
run. CPU time (user + system) of each child process, the median of --runs: a loaded machine
stretches wall time, much less CPU time.

  baselines   python start (`python -c pass`), an lxml parse of the same file,
              check_urdf (urdfdom's C++ binary from the `pin` wheel) when it is there
  growth      check, tree, tree --format json, limits, limits --format json, inertia --format
              json, dh and jacobian --format json (to the last link: the whole chain, or the
              tree's deepest path), convert (the same robot written in SDFormat 1.7) over 10,
              100, 1k, 10k, 50k links, a serial chain and a branching tree
              (benchmarks/generated.py), with the fitted log-log slope from 1k up and the
              10k -> 50k ratio; text tables against their JSON
  peak memory of check per link (max RSS over the links)

Usage: python benchmarks/bench_scale.py [--runs N] [--sizes 10,100,1000,10000,50000]
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from generated import robot_text, sdf_text

COMMANDS = {"check": ["check", "--format", "json"], "tree": ["tree"],
            "tree json": ["tree", "--format", "json"], "limits": ["limits"],
            "limits json": ["limits", "--format", "json"],
            "inertia json": ["inertia", "--format", "json"],
            "dh json": ["dh", "--format", "json", "--tip", "{tip}"],
            "jacobian json": ["jacobian", "--format", "json", "--tip", "{tip}"],
            "convert": ["convert", "--trusted", "-o", "{out}"]}  # of the SDF file


# Started by a small launcher: a child forked from this process inherits its peak RSS (Linux
# keeps the high-water mark across exec), which the generated files make large.
LAUNCH = """import os, subprocess, sys
child = subprocess.Popen(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
_, status, usage = os.wait4(child.pid, 0)
print(os.waitstatus_to_exitcode(status), usage.ru_utime + usage.ru_stime, usage.ru_maxrss)
"""


def cpu(command: list[str], runs: int, env: dict | None = None) -> tuple[float, int]:
    """(median CPU seconds, largest max RSS in KB) of ``command``."""
    times, rss = [], 0
    for _ in range(runs):
        out = subprocess.run([sys.executable, "-c", LAUNCH, *command], env=env, check=True,
                             capture_output=True, text=True).stdout.split()
        code, taken, peak = int(out[0]), float(out[1]), int(out[2])
        if code not in (0, 1):  # 1: findings; anything else did not finish
            print(f"  (exit {code}: {' '.join(command[-6:])})", file=sys.stderr)
        times.append(taken)
        rss = max(rss, peak)
    return statistics.median(times), rss


def check_urdf() -> tuple[list[str], dict] | None:
    for entry in sys.path:
        prefix = Path(entry) / "cmeel.prefix"
        if (prefix / "bin" / "check_urdf").is_file():
            return [str(prefix / "bin" / "check_urdf")], {
                **os.environ, "LD_LIBRARY_PATH": str(prefix / "lib")}
    return None


def slope(points: list[tuple[int, float]]) -> float:
    xs = [math.log(n) for n, _ in points]
    ys = [math.log(max(t, 1e-6)) for _, t in points]
    mx, my = statistics.fmean(xs), statistics.fmean(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--sizes", default="10,100,1000,10000,50000")
    args = parser.parse_args()
    sizes = [int(s) for s in args.sizes.split(",")]
    python = sys.executable
    urdftool = [python, "-m", "urdftool"]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    start, _ = cpu([python, "-c", "pass"], args.runs * 3, env)
    print(f"python start: {start * 1000:.0f} ms CPU")
    theirs = check_urdf()
    if theirs is None:
        print("check_urdf: not found (pip install pin); its column is left out")
    with tempfile.TemporaryDirectory() as tmp:
        for shape in ("chain", "tree"):
            print(f"\n{shape}: CPU seconds (x = ratio to the lxml parse of the same file)")
            header = f"{'links':>7} {'lxml':>7} {'check_urdf':>10} " + " ".join(
                f"{name:>13}" for name in COMMANDS) + f" {'check KB/link':>13} {'convert KB/link':>15}"
            print(header)
            series: dict[str, list[tuple[int, float]]] = {name: [] for name in COMMANDS}
            for n in sizes:
                path = Path(tmp) / f"{shape}{n}.urdf"
                path.write_text(robot_text(n, shape))
                sdf = Path(tmp) / f"{shape}{n}.sdf"
                sdf.write_text(sdf_text(n, shape))
                parse, _ = cpu([python, "-c", "import sys, lxml.etree as e; e.parse(sys.argv[1])",
                                str(path)], args.runs, env)
                reference = "-"
                if theirs is not None:
                    reference = f"{cpu(theirs[0] + [str(path)], args.runs, theirs[1])[0]:.3f}"
                cells, per_link = [], {}
                for name, command in COMMANDS.items():
                    argv = [a.format(tip=f"l{n - 1}", out=Path(tmp) / "out.urdf")
                            for a in command]
                    given = sdf if name == "convert" else path
                    taken, rss = cpu(urdftool + argv + [str(given)], args.runs, env)
                    series[name].append((n, taken))
                    cells.append(f"{taken:7.3f} {taken / parse:4.1f}x")
                    if name in ("check", "convert"):
                        per_link[name] = rss * 1024 / n
                print(f"{n:>7} {parse:7.3f} {reference:>10} " + " ".join(cells)
                      + f" {per_link['check'] / 1024:13.1f} {per_link['convert'] / 1024:15.1f}")
            print("slope (log-log, from 1k links):", ", ".join(
                f"{name} {slope([p for p in pts if p[0] >= 1000]):.2f}"
                for name, pts in series.items() if len([p for p in pts if p[0] >= 1000]) > 1))
            if 10000 in sizes and 50000 in sizes:
                print("10k -> 50k:", ", ".join(
                    f"{name} {dict(pts)[50000] / dict(pts)[10000]:.1f}x"
                    for name, pts in series.items()))
            big = max(sizes)
            print(f"text / JSON at {big} links:", ", ".join(
                f"{name} {dict(series[name])[big] / dict(series[name + ' json'])[big]:.2f}x"
                for name in ("tree", "limits")))


if __name__ == "__main__":
    main()
