"""Run `urdftool sim` over the whole corpus: a verdict for every pybullet_data URDF (the thousand
random_urdfs objects left out) and every example-robot-data URDF, with timings.

Prints one line per model (verdict, failed checks, links, wall time, load time, real-time
factor), then the totals for -j 1 and -j N (the speed-up), the models over 1 s wall, and the
verdict list as markdown (--markdown FILE) for the issue note.

"Robots" are the files with at least one moving joint; the rest (cubes, planes, trays...) get a
verdict too but are listed apart.

Usage: python benchmarks/bench_sim.py [--jobs N] [--duration S] [--only SUBSTRING]
                                      [--markdown FILE] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tests.conftest import (
    example_robot_data_dir,
    example_robot_urdfs,
    pybullet_data_dir,
    pybullet_urdfs,
)
from urdftool.sim import SimOptions
from urdftool.sim.runner import simulate

_MOVING = re.compile(r"<joint\b[^>]*\btype\s*=\s*[\"'](revolute|continuous|prismatic|planar|"
                     r"floating)[\"']")


def corpus() -> list[tuple[str, Path]]:
    files = [("pybullet_data", p) for p in pybullet_urdfs()]
    files += [("example-robot-data", p) for p in example_robot_urdfs()]
    return files


def short(origin: str, path: Path) -> str:
    base = pybullet_data_dir() if origin == "pybullet_data" else example_robot_data_dir() / "robots"
    return f"{origin}/{path.relative_to(base)}"


def is_robot(path: Path) -> bool:
    return bool(_MOVING.search(path.read_text(encoding="utf-8", errors="replace")))


def run(files: list[Path], jobs: int, duration: float, **extra) -> tuple[list, float]:
    options = SimOptions(duration=duration, jobs=jobs, **extra)
    started = time.perf_counter()
    results = simulate([str(f) for f in files], options)
    return results, time.perf_counter() - started


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--duration", type=float, default=1.0)
    parser.add_argument("--only", default="")
    parser.add_argument("--markdown")
    parser.add_argument("--json")
    args = parser.parse_args()

    entries = [(o, p) for o, p in corpus() if args.only in str(p)]
    files = [p for _, p in entries]
    serial, serial_wall = run(files, 1, args.duration)
    parallel, parallel_wall = run(files, args.jobs, args.duration) if args.jobs > 1 else (None, None)

    # a failing model that is not anchored: would it pass mounted (an arm, a hand, a pendulum
    # whose URDF has no 'world' link)?
    retry = [p for p, r in zip(files, serial) if r.verdict == "fail" and r.anchored is False]
    mounted = dict(zip(retry, run(retry, args.jobs, args.duration, fixed_base=True)[0])) \
        if retry else {}

    rows = []
    for (origin, path), result in zip(entries, serial):
        timing = result.timing
        rows.append({
            "model": short(origin, path), "robot": is_robot(path), "verdict": result.verdict,
            "failed": [c.check for c in result.failures()],
            "messages": {c.check: c.message for c in result.failures()},
            "links": result.links, "wall_s": timing.get("total"), "load_s": timing.get("load"),
            "simulate_s": timing.get("simulate"), "rtf": result.real_time_factor,
            "anchored": result.anchor_reason if result.anchored else None,
            "cpu_s": timing.get("cpu"),
            "fixed_base": mounted[path].verdict if path in mounted else None,
            "fixed_base_failed": [c.check for c in mounted[path].failures()]
            if path in mounted else None,
        })
    print(f"{'model':58} {'verdict':7} {'links':>5} {'wall':>6} {'cpu':>6} {'load':>6} {'rtf':>6}"
          "  failed")
    for row in rows:
        def num(value, fmt):
            return format(value, fmt) if value is not None else "-"
        mounted_text = ""
        if row["fixed_base"] is not None:
            mounted_text = f"  [--fixed-base: {row['fixed_base']}" + (
                f" {', '.join(c[4:] for c in row['fixed_base_failed'])}]"
                if row["fixed_base_failed"] else "]")
        print(f"{row['model'][:58]:58} {row['verdict']:7} {num(row['links'], 'd'):>5} "
              f"{num(row['wall_s'], '.2f'):>6} {num(row['cpu_s'], '.2f'):>6} "
              f"{num(row['load_s'], '.2f'):>6} {num(row['rtf'], '.0f'):>6}  "
              f"{', '.join(c[4:] for c in row['failed'])}{mounted_text}")
    robots = [r for r in rows if r["robot"]]
    print()
    print(f"{len(rows)} models ({len(robots)} robots): "
          f"{sum(r['verdict'] == 'pass' for r in rows)} pass, "
          f"{sum(r['verdict'] == 'fail' for r in rows)} fail")
    print(f"robots: {sum(r['verdict'] == 'pass' for r in robots)} pass, "
          f"{sum(r['verdict'] == 'fail' for r in robots)} fail")
    small = [r for r in rows if r["links"] and r["links"] <= 30 and r["wall_s"]]
    slow = [r for r in small if r["wall_s"] > 1.0]
    print(f"models up to 30 links: {len(small)}, over 1 s wall: {len(slow)} "
          + ", ".join(f"{r['model']} ({r['wall_s']:.2f} s, load {r['load_s']:.2f} s)"
                      for r in slow))
    total_load = sum(r["load_s"] or 0 for r in rows)
    total_sim = sum(r["simulate_s"] or 0 for r in rows)
    total_model = sum(r["wall_s"] or 0 for r in rows)
    total_cpu = sum(r["cpu_s"] or 0 for r in rows)
    print(f"sum over models: wall {total_model:.2f} s (CPU {total_cpu:.2f} s), of which PyBullet "
          f"load {total_load:.2f} s, stepping {total_sim:.2f} s")
    print(f"-j 1 total: {serial_wall:.2f} s")
    if parallel is not None:
        print(f"-j {args.jobs} total: {parallel_wall:.2f} s (speed-up {serial_wall / parallel_wall:.2f}x)")
        changed = [short(o, p) for (o, p), a, b in zip(entries, serial, parallel)
                   if a.verdict != b.verdict]
        if changed:
            print("verdicts differing between -j 1 and -j N: " + ", ".join(changed))
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1), encoding="utf-8")
    if args.markdown:
        lines = ["| model | verdict | failed checks | --fixed-base | links | wall s | load s |",
                 "|---|---|---|---|---|---|---|"]
        for row in rows:
            failed = "; ".join(f"{c[4:]}: {row['messages'][c]}" for c in row["failed"])
            lines.append(f"| {row['model']}{'' if row['robot'] else ' (object)'} | "
                         f"{row['verdict']} | {failed.replace('|', '/')} | "
                         f"{row['fixed_base'] or ''} | {row['links']} | "
                         f"{row['wall_s']:.2f} | {(row['load_s'] or 0):.2f} |")
        Path(args.markdown).write_text("\n".join(lines) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
