"""Cold against warm mesh reading (issue 33), measured in the same run, in CPU time.

1. `urdftool check` of a robot whose links are the mesh files under DIR (one link per file; a
   file under a `collision` folder is the link's collision, whose volume the inertia checks
   need, any other its visual; each hung on the first link by a revolute joint), first with an empty persistent cache (cold: every mesh parsed),
   then again (warm: every summary from the cache). CPU of the child processes (user + system,
   the sandboxed reader of large meshes included): what a CI runner without the Action's cache
   pays against a developer's second run.
2. The summaries alone, in this process: every file summarised with its volume (hull,
   extents, closed or not, mass properties), cold then warm.

3. With ``--packages``: `urdftool check` of the checkouts themselves (each DIR a repository
   with its URDF/xacro files, then all of them in one run), cold then warm: what the packages'
   own descriptions cost, the meshes they use read once. (1) is the worst case of a package:
   every mesh on a link of its own and nothing else to check.

Usage: python benchmarks/bench_meshes.py DIR [DIR...] [--suffix .dae] [--profile N] [--packages]

DIR: real packages' meshes, e.g. the COLLADA files of Universal_Robots_ROS2_Description,
universal_robot, franka_description, abb, abb_experimental, kinova-ros, moveit_resources,
ros2_kortex and franka_ros2 checked out side by side from their git mirrors. ``--profile N``:
cProfile of the cold pass of (2), top N functions by internal time.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def files_under(directories: list[Path], suffix: str) -> list[Path]:
    return sorted(p.resolve() for d in directories for p in d.rglob("*")
                  if p.is_file() and p.suffix.lower() == suffix)


def robot_of(paths: list[Path], base: Path) -> str:
    """A URDF with one link per mesh file (package://meshes/... under ``base``)."""
    parts = ['<robot name="meshes">']
    for i, path in enumerate(paths):
        role = "collision" if "collision" in path.relative_to(base).parts else "visual"
        parts.append(
            f'<link name="l{i}"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" '
            f'iyy="0.01" iyz="0" izz="0.01"/></inertial><{role}><geometry><mesh '
            f'filename="package://meshes/{path.relative_to(base)}"/></geometry></{role}></link>')
        if i:  # each its own moving body (fixed joints would lump them all into one)
            parts.append(f'<joint name="j{i}" type="revolute"><parent link="l0"/>'
                         f'<child link="l{i}"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" '
                         'effort="1" velocity="1"/></joint>')
    return "\n".join(parts + ["</robot>"])


def child_cpu(command: list[str], env: dict) -> tuple[float, int]:
    """(CPU seconds of ``command`` and its children, exit code)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    code = subprocess.run(command, check=False, env=env, stdout=subprocess.DEVNULL,
                          stderr=subprocess.DEVNULL).returncode
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), code


def read_all(paths: list[Path]) -> tuple[float, int]:
    """(CPU seconds, files parsed) of summarising every file with its volume, in process."""
    from urdftool.physics import meshes

    meshes.clear_cache()  # nothing in memory: what a new process starts with
    start = time.process_time()
    for path in paths:
        meshes.load_mesh(path, need_volume=True)
    return time.process_time() - start, meshes.LOADS


def check_packages(directories: list[Path]) -> None:
    """(3): each checkout's own descriptions, then all of them, cold then warm."""
    print(f"{'cold s':>8} {'warm s':>8} {'ratio':>7} {'meshes':>7}  checkout")
    for group in [[d] for d in directories] + ([directories] if len(directories) > 1 else []):
        with tempfile.TemporaryDirectory(prefix="bench-meshes-") as work:
            cache = Path(work) / "cache"
            env = dict(os.environ, URDFTOOL_CACHE_DIR=str(cache))
            command = [sys.executable, "-m", "urdftool", "check", "--format", "json",
                       "--timeout", "600", *map(str, group)]
            cold, _ = child_cpu(command, env)
            warm, _ = child_cpu(command, env)
            read = len(list((cache / "mesh").glob("*"))) if (cache / "mesh").is_dir() else 0
            name = group[0].name if len(group) == 1 else f"all {len(group)}"
            print(f"{cold:8.2f} {warm:8.2f} {cold / warm:6.2f}x {read:7d}  {name}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("dirs", nargs="+", type=Path)
    parser.add_argument("--suffix", default=".dae")
    parser.add_argument("--profile", type=int, default=0)
    parser.add_argument("--packages", action="store_true",
                        help="also check each DIR's own descriptions, cold then warm")
    args = parser.parse_args()
    if args.packages:
        check_packages(args.dirs)
    base = Path(os.path.commonpath([d.resolve() for d in args.dirs]))
    paths = files_under(args.dirs, args.suffix.lower())
    size = sum(p.stat().st_size for p in paths)
    print(f"{len(paths)} {args.suffix} files, {size / 1e6:.1f} MB under {base}")
    with tempfile.TemporaryDirectory(prefix="bench-meshes-") as work:
        robot = Path(work) / "robot.urdf"
        robot.write_text(robot_of(paths, base))
        env = dict(os.environ, URDFTOOL_CACHE_DIR=str(Path(work) / "cache"))
        command = [sys.executable, "-m", "urdftool", "check", str(robot), "--format", "json",
                   "-P", f"meshes={base}", "--timeout", "600"]
        cold, code = child_cpu(command, env)
        warm, _ = child_cpu(command, env)
        print(f"check, cold cache: {cold:.2f} s CPU (exit {code})")
        print(f"check, warm cache: {warm:.2f} s CPU")
        print(f"check cold/warm: {cold / warm:.2f}x")

        os.environ["URDFTOOL_CACHE_DIR"] = str(Path(work) / "cache-summaries")
        import numpy  # noqa: F401 - imported before timing: both passes share the import
        import trimesh  # noqa: F401

        if args.profile:
            import cProfile
            import pstats

            profiler = cProfile.Profile()
            profiler.enable()
        cold, parsed = read_all(paths)
        if args.profile:
            profiler.disable()
            pstats.Stats(profiler).sort_stats("tottime").print_stats(args.profile)
        warm, reparsed = read_all(paths)
    print(f"summaries alone, cold: {cold:.2f} s CPU ({parsed} parsed), warm: {warm:.2f} s "
          f"({reparsed} parsed)")


if __name__ == "__main__":
    main()
