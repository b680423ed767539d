"""Cold against warm mesh reading (issue 33): every mesh file under DIR summarised as `check`
summarises the meshes a link derives its inertia from (hull, extents, volume, mass properties),
first with an empty persistent cache (cold: every file parsed), then again in the same process
with the in-memory summaries dropped (warm: every summary from the persistent cache). Both in
CPU time of this process (``time.process_time``), measured in the same run.

Usage: python benchmarks/bench_meshes.py DIR [DIR...] [--suffix .dae] [--profile N]

DIR: real packages' mesh folders, e.g. the COLLADA files of Universal_Robots_ROS2_Description,
universal_robot, franka_description, abb, abb_experimental, kinova-ros, moveit_resources,
ros2_kortex and franka_ros2 checked out side by side (their git mirrors, ``fetch``). Files over
``meshes.IN_PROCESS_BYTES`` are left out (`check` parses them in the sandboxed reader, whose CPU
is not this process's). ``--profile N``: cProfile of the cold pass, top N functions.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def files_under(directories: list[Path], suffix: str) -> list[Path]:
    from urdftool.physics import meshes

    found = sorted(p for d in directories for p in d.rglob("*")
                   if p.is_file() and p.suffix.lower() == suffix)
    return [p for p in found if p.stat().st_size <= meshes.IN_PROCESS_BYTES]


def read_all(paths: list[Path]) -> tuple[float, int]:
    """(CPU seconds, files parsed) of summarising every file with its volume."""
    from urdftool.physics import meshes

    meshes.clear_cache()  # nothing in memory: what a new process starts with
    start = time.process_time()
    for path in paths:
        meshes.load_mesh(path, need_volume=True)
    return time.process_time() - start, meshes.LOADS


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("dirs", nargs="+", type=Path)
    parser.add_argument("--suffix", default=".dae")
    parser.add_argument("--profile", type=int, default=0)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bench-meshes-") as cache_dir:
        os.environ["URDFTOOL_CACHE_DIR"] = cache_dir  # an empty persistent cache
        paths = files_under(args.dirs, args.suffix.lower())
        size = sum(p.stat().st_size for p in paths)
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
            pstats.Stats(profiler).sort_stats("cumulative").print_stats(args.profile)
        warm, reparsed = read_all(paths)
    print(f"{len(paths)} {args.suffix} files, {size / 1e6:.1f} MB")
    print(f"cold: {cold:.2f} s CPU ({parsed} parsed)")
    print(f"warm: {warm:.2f} s CPU ({reparsed} parsed)")
    print(f"cold/warm: {cold / warm:.2f}x")


if __name__ == "__main__":
    main()
