"""Timing of the inertia and mesh checks.

    .venv/bin/python benchmarks/bench_inertia.py [--runs N]

1. start-up: `urdftool check` on a robot made of primitives, against
   `python -c "import lxml.etree, click, xacro"` (the budget is 1.5x), median of N runs;
2. the whole example-robot-data corpus checked in one process (every rule, then only the
   inertia and mesh families), wall and CPU time, and how many mesh files were read (each
   once: the cache is per process).
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

PRIMITIVE_ROBOT = """<robot name="r">
  <link name="base"><inertial><mass value="5"/><inertia ixx="0.04" ixy="0" ixz="0" iyy="0.1"
    iyz="0" izz="0.14"/></inertial><visual><geometry><box size="0.5 0.3 0.07"/></geometry>
    </visual><collision><geometry><box size="0.5 0.3 0.07"/></geometry></collision></link>
  <joint name="j" type="continuous"><parent link="base"/><child link="wheel"/>
    <origin xyz="0 0.17 0" rpy="1.5708 0 0"/><axis xyz="0 0 1"/></joint>
  <link name="wheel"><inertial><mass value="0.2"/><inertia ixx="0.00053" ixy="0" ixz="0"
    iyy="0.00053" iyz="0" izz="0.001"/></inertial><visual><geometry><cylinder radius="0.1"
    length="0.04"/></geometry></visual><collision><geometry><cylinder radius="0.1"
    length="0.04"/></geometry></collision></link>
</robot>
"""


def _median_run(command: list[str], runs: int, env: dict) -> float:
    subprocess.run(command, capture_output=True, check=False, env=env)  # warm: write bytecode
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        subprocess.run(command, capture_output=True, check=False, env=env)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def startup(runs: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "robot.urdf"
        path.write_text(PRIMITIVE_ROBOT)
        # as installed: with bytecode (an editable checkout run with PYTHONDONTWRITEBYTECODE
        # compiles every module on every start), kept out of the source tree
        env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
        env["PYTHONPYCACHEPREFIX"] = str(Path(tmp) / "pycache")
        base = _median_run([sys.executable, "-c", "import lxml.etree, click, xacro"], runs, env)
        check = _median_run([sys.executable, "-m", "urdftool", "check", str(path)], runs, env)
        probe = ("import sys\nfrom urdftool.cli import main\ntry:\n    main(['check', sys.argv[1]])"
                 "\nexcept SystemExit:\n    pass\nprint(sorted(m for m in ('numpy', 'trimesh', "
                 "'scipy') if m in sys.modules))")
        loaded = subprocess.run([sys.executable, "-c", probe, str(path)], capture_output=True,
                                text=True, check=False).stdout.strip().splitlines()[-1]
    print(f"import lxml.etree, click, xacro : {base * 1000:7.1f} ms")
    print(f"urdftool check primitive robot  : {check * 1000:7.1f} ms ({check / base:.2f}x), "
          f"heavy modules imported: {loaded}")


def corpus() -> None:
    from tests.conftest import example_robot_data_dir, example_robot_urdfs
    from urdftool.check import CheckOptions, check_file
    from urdftool.physics import meshes
    from urdftool.source import LoadOptions

    load = LoadOptions(packages={"example-robot-data": str(example_robot_data_dir())})
    files = example_robot_urdfs()
    for label, select in (("inertia+mesh only", ["inertia", "mesh"]), ("every rule", [])):
        meshes.clear_cache()
        wall, cpu = time.perf_counter(), time.process_time()
        for path in files:
            check_file(path, CheckOptions(load=load, select=select))
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        print(f"example-robot-data, {len(files)} files, {label:17}: {wall:6.1f} s wall, "
              f"{cpu:6.1f} s CPU, {meshes.LOADS} mesh files read, {len(meshes._CACHE)} cached")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=15)
    args = parser.parse_args()
    startup(args.runs)
    corpus()


if __name__ == "__main__":
    main()
