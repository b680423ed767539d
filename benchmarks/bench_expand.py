"""`urdftool expand` against plain xacro on the same file (issue 15), measured in the same run.

CPU time (user + system, the median of --runs) of each child process:

  python      `python -c pass` (the floor of any Python CLI)
  floor       `python -c "import xacro, click, lxml.etree"`: what urdftool must import to
              expand (its CLI is click, its model lxml), before reading anything
  xacro       plain xacro on the same file: the `xacro` package's own `main()` (its CLI), with
              `$(find PKG)` answered from the package directories (no ROS index here)
  trusted     `urdftool expand --trusted --timeout 3600 FILE`
  untrusted   `urdftool expand --untrusted --timeout 3600 FILE` (the default under CI: the
              xacro pass runs in the sandboxed reader, a fresh `python -I`)
  (--timeout: the default time limit of one expansion, LoadOptions.timeout, stops the big
  generated files; the last column says whether the default stops it)

Inputs: the xacro entries of robots/ (corrected), of /work/shared/real-packages (or --packages)
and a generated xacro robot with macros (properties, nested macro calls, expressions per
link) of 1k, 5k and 10k links, so xacro's own growth shows. Ratios are to plain xacro.

Usage: python benchmarks/bench_expand.py [--runs N] [--sizes 1000,5000,10000] [--profile N]
  --profile N   cProfile of the trusted expansion (in process) of the generated N-link file:
                where urdftool's time beyond xacro goes (top functions by cumulative time)
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from bench_scale import cpu

PACKAGES = Path("/work/shared/real-packages")
ARGS = {"demo.urdf.xacro": ["model:=flir_blackfly_s"]}  # entries that need a xacro arg

# plain xacro: its main() with $(find) answered from the packages given as argv[1] (NAME=DIR,...)
PLAIN_XACRO = """\
import sys
from xacro import main, substitution_args
dirs = dict(item.split("=", 1) for item in sys.argv.pop(1).split(",") if item)
substitution_args._eval_find = lambda package: dirs[package]
main()
"""


def xacro_robot(n_links: int) -> str:
    """A generated robot of ``n_links`` links in xacro: properties, a segment macro calling an
    inertial macro, expressions in every link and joint, one call per link (as generators and
    CAD exports write them)."""
    head = """<?xml version="1.0"?>
<robot name="gen_xacro" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="length" value="0.1"/>
  <xacro:property name="radius" value="0.02"/>
  <xacro:property name="mass" value="0.5"/>
  <xacro:macro name="box_inertial" params="m x y z">
    <inertial>
      <origin xyz="0 0 ${z/2}"/>
      <mass value="${m}"/>
      <inertia ixx="${m*(y*y+z*z)/12}" ixy="0" ixz="0" iyy="${m*(x*x+z*z)/12}" iyz="0"
               izz="${m*(x*x+y*y)/12}"/>
    </inertial>
  </xacro:macro>
  <xacro:macro name="segment" params="i parent">
    <link name="l${i}">
      <xacro:box_inertial m="${mass}" x="${2*radius}" y="${2*radius}" z="${length}"/>
      <visual>
        <origin xyz="0 0 ${length/2}"/>
        <geometry><box size="${2*radius} ${2*radius} ${length}"/></geometry>
      </visual>
      <collision>
        <origin xyz="0 0 ${length/2}"/>
        <geometry><box size="${2*radius} ${2*radius} ${length}"/></geometry>
      </collision>
    </link>
    <joint name="j${i}" type="revolute">
      <parent link="${parent}"/>
      <child link="l${i}"/>
      <origin xyz="0 0 ${length}" rpy="0 0 ${pi/6 if i % 2 else 0}"/>
      <axis xyz="${'0 1 0' if i % 2 else '1 0 0'}"/>
      <limit lower="${-pi/2}" upper="${pi/2}" effort="10" velocity="2"/>
    </joint>
  </xacro:macro>
  <link name="l0"/>
"""
    calls = "".join(f'  <xacro:segment i="{i}" parent="l{i - 1}"/>\n' for i in range(1, n_links))
    return head + calls + "</robot>\n"


def package_dirs() -> dict[str, Path]:
    """Every directory with a package.xml under robots/ and the real packages, by name."""
    found = {}
    for base in (ROOT / "robots", PACKAGES):
        for manifest in sorted(base.rglob("package.xml")) if base.is_dir() else []:
            found.setdefault(manifest.parent.name, manifest.parent)
    return found


def entries() -> list[tuple[str, Path, list[str]]]:
    """(label, file, xacro args) of the real inputs: robots/*/corrected and the real packages'
    top-level xacro files (those that are not `_fragments`)."""
    chosen = []
    for path in sorted((ROOT / "robots").glob("*/corrected/*.xacro")):
        chosen.append((f"robots/{path.parent.parent.name}/{path.name}", path, []))
    for path in sorted(PACKAGES.glob("*/urdf/*.xacro")) if PACKAGES.is_dir() else []:
        if not path.name.startswith("_"):
            chosen.append((f"{path.parent.parent.name}/{path.name}", path,
                           ARGS.get(path.name, [])))
    return chosen


def profile(n_links: int) -> None:
    import cProfile
    import pstats

    from click.testing import CliRunner

    from urdftool.cli import main

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"gen{n_links}.urdf.xacro"
        path.write_text(xacro_robot(n_links))
        profiler = cProfile.Profile()
        profiler.enable()
        result = CliRunner().invoke(main, ["expand", "--trusted", str(path)])
        profiler.disable()
        assert result.exit_code == 0, result.output
        stats = pstats.Stats(profiler)
        stats.sort_stats("cumulative").print_stats(35)
        stats.sort_stats("tottime").print_stats(25)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--sizes", default="1000,5000,10000")
    parser.add_argument("--profile", type=int, default=0)
    args = parser.parse_args()
    if args.profile:
        profile(args.profile)
        return
    python = sys.executable
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONDONTWRITEBYTECODE", "CI")}
    dirs = ",".join(f"{name}={directory}" for name, directory in package_dirs().items())
    packages = [arg for name, directory in package_dirs().items()
                for arg in ("-P", f"{name}={directory}")]
    start, _ = cpu([python, "-c", "pass"], args.runs * 2, env)
    floor, _ = cpu([python, "-c", "import xacro, click, lxml.etree"], args.runs * 2, env)
    print(f"python start: {start * 1000:.0f} ms CPU; import xacro, click, lxml.etree: "
          f"{floor * 1000:.0f} ms; CPU seconds, ratios to plain xacro on the same file")
    print(f"{'input':<52} {'xacro':>7} {'floor':>6} {'trusted':>14} {'untrusted':>14} "
          "default limit")
    with tempfile.TemporaryDirectory() as tmp:
        inputs = entries()
        for n in (int(s) for s in args.sizes.split(",") if s):
            path = Path(tmp) / f"gen{n}.urdf.xacro"
            path.write_text(xacro_robot(n))
            inputs.append((f"generated, {n} links", path, []))
        for label, path, xacro_args in inputs:
            plain = [python, "-c", PLAIN_XACRO, dirs, str(path), *xacro_args]
            check = subprocess.run(plain, capture_output=True, env=env, check=False)
            if check.returncode != 0:
                print(f"{label:<52} plain xacro fails: {check.stderr.decode()[-200:].strip()}")
                continue
            theirs, _ = cpu(plain, args.runs, env)
            cells = []
            for mode in ("--trusted", "--untrusted"):
                ours = [python, "-m", "urdftool", "expand", mode, "--timeout", "3600", *packages,
                        str(path), *xacro_args]
                done = subprocess.run(ours, capture_output=True, env=env, check=False)
                if done.returncode != 0 or done.stdout != check.stdout:
                    cells.append(f"{'exit ' + str(done.returncode):>14}" if done.returncode
                                 else f"{'not xacro text':>14}")
                    continue
                taken, _ = cpu(ours, args.runs, env)
                cells.append(f"{taken:7.3f} {taken / theirs:5.2f}x")
            limited = subprocess.run([python, "-m", "urdftool", "expand", "--trusted", *packages,
                                      str(path), *xacro_args], capture_output=True, env=env,
                                     check=False)
            stopped = "stops" if b"limit-exceeded" in limited.stderr else "-"
            print(f"{label:<52} {theirs:7.3f} {floor / theirs:5.2f}x " + " ".join(cells)
                  + f" {stopped:>9}")


if __name__ == "__main__":
    main()
