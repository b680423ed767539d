"""Time the pre-commit hook (`urdftool check --changed FILE`, what .pre-commit-hooks.yaml runs) on
a real package with several entries, warm (issue 23.8: <= 0.3 s), against baselines measured in
this same run:

  floor      python -c "import lxml.etree, click, xacro"  (a Python CLI of this kind cannot beat it)
  package    `urdftool check PACKAGE`, warm: what a hook that checks everything would cost

and the hook itself (the mesh-summary and files-read caches warm from a first run):

  fragment   a macro file three entries include, edited before every run (a comment appended):
             those entries are expanded and checked again
  same       the same staged file again, unchanged since the last run (pre-commit run twice,
             `git commit` after a failed one)
  unrelated  a YAML file no entry reads (the hook's `files:` passes it): nothing to check

The package is copied into a temporary git repository (default: realsense2_description of
/work/shared/real-packages, 9 entries, 9 fragments). Python runs as installed (bytecode
written: the PYTHONDONTWRITEBYTECODE of a development shell is unset).

Usage: python benchmarks/bench_hook.py [--runs N] [--package DIR]
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = Path("/work/shared/real-packages/realsense2_description")
FRAGMENT = "urdf/_d435.urdf.xacro"


def timed(command: list[str], cwd: Path, env: dict, before=None) -> tuple[float, float]:
    """(wall seconds, CPU seconds: user + system) of one run of ``command``."""
    if before is not None:
        before()
    start = time.perf_counter()
    process = subprocess.Popen(command, cwd=cwd, env=env, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    _, _, usage = os.wait4(process.pid, 0)
    process.returncode = 0  # reaped here
    return time.perf_counter() - start, usage.ru_utime + usage.ru_stime


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--package", type=Path, default=PACKAGE)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        repo = Path(scratch) / "repo"
        package = repo / args.package.name
        shutil.copytree(args.package, package)
        (package / "config").mkdir(exist_ok=True)
        (package / "config" / "unrelated.yaml").write_text("a: 1\n")
        subprocess.run(["git", "init", "-q"], cwd=repo, check=True)
        env = {k: v for k, v in os.environ.items()
               if k not in ("PYTHONDONTWRITEBYTECODE", "URDFTOOL_DEBUG", "CI")}
        env["URDFTOOL_CACHE_DIR"] = str(Path(scratch) / "cache")
        env["PYTHONPATH"] = str(ROOT)
        urdftool = [sys.executable, "-m", "urdftool"]
        fragment = package / FRAGMENT
        relative = f"{args.package.name}/{FRAGMENT}"

        def edit() -> None:
            with fragment.open("a") as stream:
                stream.write("<!-- edited -->\n")

        cases = {
            "floor": ([sys.executable, "-c", "import lxml.etree, click, xacro"], None),
            "package": ([*urdftool, "check", args.package.name], None),
            "fragment": ([*urdftool, "check", "--changed", relative], edit),
            "same": ([*urdftool, "check", "--changed", relative], None),
            "unrelated": ([*urdftool, "check", "--changed",
                           f"{args.package.name}/config/unrelated.yaml"], None),
        }
        for command, _ in cases.values():  # bytecode, mesh summaries, what each entry reads
            timed(command, repo, env)
        times: dict[str, list[tuple[float, float]]] = {name: [] for name in cases}
        for _ in range(args.runs):  # interleaved: a load change hits every case alike
            for name, (command, before) in cases.items():
                times[name].append(timed(command, repo, env, before))
        wall = {name: statistics.median(w for w, _ in values) for name, values in times.items()}
        cpu = {name: statistics.median(c for _, c in values) for name, values in times.items()}
    print(f"{args.package.name}: median of {args.runs} runs (wall seconds; CPU seconds, which "
          f"a loaded machine inflates less)")
    for name in cases:
        extra = "" if name in ("floor", "package") else (
            f"   wall {wall[name] / wall['package']:.2f}x package, "
            f"{wall[name] / wall['floor']:.2f}x floor")
        print(f"  {name:<10} wall {wall[name]:6.3f}  cpu {cpu[name]:6.3f}{extra}")


if __name__ == "__main__":
    main()
