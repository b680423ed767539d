"""Time changed-files mode (`urdftool check --changed FILE`, what the pre-commit hook runs) on a
description package with several entries, against checking the whole package, in one run.

The package (made in a temporary directory): ENTRIES robot variants `urdf/robot_K.urdf.xacro`,
each including through `$(find ...)` the shared fragments (materials, a wheel macro used four
times, a six-link arm macro) and its own sensor fragment; 16 links per robot.

Figures (wall time of one `urdftool` process, median of several runs, interleaved):
  floor        python -c "import urdftool.cli"  (start-up that no hook run can avoid)
  package      urdftool check PKG                     (the baseline: every entry)
  one-entry    urdftool check --changed urdf/sensor_0.xacro   (read by one entry)
  shared       urdftool check --changed urdf/wheel.xacro      (read by every entry)
  entry        urdftool check --changed urdf/robot_0.urdf.xacro
each cold (URDFTOOL cache emptied before every run) and warm (the cache of the previous run).

Usage: python benchmarks/bench_gate.py [--runs N] [--entries N]
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

HEADER = '<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro"'


def box_inertia(m, x, y, z):
    return (m * (y * y + z * z) / 12, m * (x * x + z * z) / 12, m * (x * x + y * y) / 12)


def link(name: str, mass: float, size: tuple[float, float, float]) -> str:
    ixx, iyy, izz = box_inertia(mass, *size)
    box = f'<box size="{size[0]} {size[1]} {size[2]}"/>'
    return (f'<link name="{name}"><inertial><mass value="{mass}"/>'
            f'<inertia ixx="{ixx:.6g}" ixy="0" ixz="0" iyy="{iyy:.6g}" iyz="0" izz="{izz:.6g}"/>'
            f'</inertial><visual><geometry>{box}</geometry><material name="grey"/></visual>'
            f'<collision><geometry>{box}</geometry></collision></link>\n')


def make_package(directory: Path, entries: int) -> None:
    urdf = directory / "urdf"
    urdf.mkdir(parents=True)
    (directory / "package.xml").write_text(
        '<?xml version="1.0"?><package format="3"><name>bench_description</name>'
        '<version>0.0.0</version><description>b</description>'
        '<maintainer email="a@b.c">a</maintainer><license>MIT</license></package>\n')
    (urdf / "materials.xacro").write_text(
        HEADER + '>\n<material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>\n</robot>\n')
    (urdf / "wheel.xacro").write_text(
        HEADER + '>\n<xacro:macro name="wheel" params="prefix x y">\n'
        + link("${prefix}_wheel", 0.5, (0.1, 0.04, 0.1))
        + '<joint name="${prefix}_wheel_joint" type="continuous"><parent link="base_link"/>'
          '<child link="${prefix}_wheel"/><origin xyz="${x} ${y} 0"/><axis xyz="0 1 0"/>'
          '</joint>\n</xacro:macro>\n</robot>\n')
    arm = [HEADER + '>\n<xacro:macro name="arm" params="parent">\n']
    previous = "${parent}"
    for k in range(6):
        arm.append(link(f"arm_{k}", 0.4, (0.05, 0.05, 0.2)))
        arm.append(f'<joint name="arm_joint_{k}" type="revolute"><parent link="{previous}"/>'
                   f'<child link="arm_{k}"/><origin xyz="0 0 0.2"/><axis xyz="0 1 0"/>'
                   '<limit lower="-1.5" upper="1.5" effort="10" velocity="2"/></joint>\n')
        previous = f"arm_{k}"
    arm.append("</xacro:macro>\n</robot>\n")
    (urdf / "arm.xacro").write_text("".join(arm))
    for k in range(entries):
        (urdf / f"sensor_{k}.xacro").write_text(
            HEADER + '>\n<xacro:macro name="sensor">\n' + link(f"sensor_{k}", 0.1,
                                                               (0.04, 0.04, 0.04))
            + f'<joint name="sensor_{k}_joint" type="fixed"><parent link="base_link"/>'
              f'<child link="sensor_{k}"/><origin xyz="0.2 0 0.1"/></joint>\n'
              '</xacro:macro>\n</robot>\n')
        includes = "".join(f'<xacro:include filename="$(find bench_description)/urdf/{name}"/>\n'
                           for name in ("materials.xacro", "wheel.xacro", "arm.xacro",
                                        f"sensor_{k}.xacro"))
        wheels = "".join(f'<xacro:wheel prefix="w{i}" x="{x}" y="{y}"/>\n'
                         for i, (x, y) in enumerate(((0.2, 0.2), (0.2, -0.2), (-0.2, 0.2),
                                                     (-0.2, -0.2))))
        (urdf / f"robot_{k}.urdf.xacro").write_text(
            HEADER + f' name="robot_{k}">\n' + includes + link("base_link", 5.0, (0.5, 0.4, 0.1))
            + wheels + '<xacro:arm parent="base_link"/>\n<xacro:sensor/>\n</robot>\n')


def timed(command: list[str], cwd: Path, env: dict, cold: Path | None) -> float:
    if cold is not None:
        shutil.rmtree(cold, ignore_errors=True)
    start = time.perf_counter()
    done = subprocess.run(command, cwd=cwd, env=env, check=False, stdout=subprocess.DEVNULL,
                          stderr=subprocess.PIPE, text=True)
    elapsed = time.perf_counter() - start
    if done.returncode not in (0, 1):
        raise SystemExit(f"{' '.join(command)}: exit {done.returncode}: {done.stderr}")
    return elapsed


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--entries", type=int, default=8)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        package = Path(tmp) / "bench_description"
        make_package(package, args.entries)
        cache = Path(tmp) / "cache"
        env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
        env["URDFTOOL_CACHE_DIR"] = str(cache)
        urdftool = [sys.executable, "-m", "urdftool", "check"]
        commands = {
            "floor": [sys.executable, "-c", "import urdftool.cli"],
            "package": urdftool + ["."],
            "one-entry": urdftool + ["--changed", "urdf/sensor_0.xacro"],
            "shared": urdftool + ["--changed", "urdf/wheel.xacro"],
            "entry": urdftool + ["--changed", "urdf/robot_0.urdf.xacro"],
        }
        subprocess.run(urdftool + ["."], cwd=package, env=env, check=False,
                       capture_output=True)  # bytecode
        for state in ("cold", "warm"):
            times: dict[str, list[float]] = {name: [] for name in commands}
            for _ in range(args.runs):
                for name, command in commands.items():
                    if state == "warm":  # the cache as the previous run of the same command left it
                        timed(command, package, env, None)
                    times[name].append(timed(command, package, env,
                                             cache if state == "cold" else None))
            median = {name: statistics.median(series) for name, series in times.items()}
            base = median["package"]
            print(f"{state} cache, {args.entries} entries, median of {args.runs}:")
            for name, value in median.items():
                print(f"  {name:10s} {value * 1000:7.1f} ms   {value / base:5.2f}x package")


if __name__ == "__main__":
    main()
