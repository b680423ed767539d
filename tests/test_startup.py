"""Start-up of ``urdftool check`` (issue 2): on a primitive-geometry robot it runs in a pre-commit
hook, so it must not pay for what only other inputs or commands need. Guarded by the modules a
run imports rather than by wall time, which a loaded CI machine makes meaningless."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys

from tests.conftest import SMALL

# Each costs start-up time and none is needed to check a plain URDF with primitive shapes.
UNNEEDED = (
    # heavy optional dependencies: meshes, kinematics, simulation, symbolic maths, pretty output
    "numpy", "scipy", "trimesh", "pinocchio", "pybullet", "sympy", "rich",
    # xacro and SDF inputs
    "xacro", "yaml", "urdftool.xacro_expand", "urdftool.xacro_eval", "urdftool.sandbox",
    "urdftool.sdf", "string",
    # meshes: only for a robot that has one (the loader sets its large-mesh hook then)
    "urdftool.physics.meshes",
    # importlib.resources pulls in zipfile, tempfile, shutil, bz2, lzma, random (~4 ms)
    "importlib.resources", "zipfile", "tempfile", "shutil", "bz2", "lzma", "random",
    # did-you-mean hints and the XML repair; the mesh cache's file names and writes; --jobs
    # and its worker results; pyproject.toml
    "difflib", "bisect", "hashlib", "multiprocessing", "concurrent.futures", "pickle",
    "tomllib" if sys.version_info >= (3, 11) else "tomli",
    # the language server (urdftool lsp) and its protocol libraries
    "urdftool.lsp", "urdftool.cli.lsp", "pygls", "lsprotocol", "cattrs", "asyncio",
)

RUN = """
import json, sys
from urdftool.cli import main
try:
    main(["check", "--format", sys.argv[3], sys.argv[1]])
except SystemExit as exc:
    with open(sys.argv[2], "w") as out:
        json.dump([exc.code, sorted(sys.modules)], out)
"""


def _check(tmp_path, fmt: str, robot=None) -> tuple[int, list[str], str]:
    if robot is None:
        robot = tmp_path / "small.urdf"
        robot.write_text(SMALL, encoding="utf-8")
    result = tmp_path / "modules.json"
    done = subprocess.run([sys.executable, "-c", RUN, str(robot), str(result), fmt],
                          capture_output=True, text=True, check=True, cwd=tmp_path)
    code, modules = json.loads(result.read_text(encoding="utf-8"))
    return code, modules, done.stdout


def test_check_on_a_primitive_robot_imports_nothing_it_does_not_need(tmp_path):
    code, modules, out = _check(tmp_path, "json")
    assert code == 0 and json.loads(out)["summary"] == {
        "files": 1, "errors": 0, "warnings": 0, "infos": 0}, out
    assert "urdftool.rules.inertia" in modules  # the rules did run
    assert sorted(set(UNNEEDED) & set(modules)) == []


def test_text_output_of_a_clean_robot_needs_no_rich(tmp_path):
    """The default format: a clean run prints its summary line without importing rich."""
    code, modules, out = _check(tmp_path, "text")
    assert code == 0 and out == "1 file(s): 0 error(s), 0 warning(s), 0 info\n"
    assert sorted(set(UNNEEDED) & set(modules)) == []


def test_the_unneeded_modules_exist():
    """The guard above could fail: what it forbids is installed (the heavy optional ones come
    with the test dependencies)."""
    missing = [m for m in UNNEEDED if importlib.util.find_spec(m) is None]
    assert missing == []


# -- warm mesh cache (issue 15) ---------------------------------------------------------------
MESH_ROBOT = """<robot name="boxes">
  <link name="base">
    <inertial><mass value="1.2"/><inertia ixx="0.005" iyy="0.0125" izz="0.0145" ixy="0" ixz="0"
      iyz="0"/></inertial>
    <visual><geometry><mesh filename="box.stl"/></geometry></visual>
    <collision><geometry><mesh filename="box.stl" scale="1 1 2"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><origin xyz="0 0 0.5"/><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0"
      ixz="0" iyz="0"/></inertial>
    <visual><origin rpy="0.3 0 0"/><geometry><mesh filename="box.stl"/></geometry></visual>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""


def _box_stl(path, size=(0.3, 0.2, 0.1)) -> None:
    """A closed binary STL box (12 outward triangles)."""
    import itertools
    import struct

    corners = [tuple(s / 2 * c for s, c in zip(size, signs))
               for signs in itertools.product((-1, 1), repeat=3)]
    faces = [(0, 2, 3), (0, 3, 1), (4, 5, 7), (4, 7, 6), (0, 1, 5), (0, 5, 4),
             (2, 6, 7), (2, 7, 3), (0, 4, 6), (0, 6, 2), (1, 3, 7), (1, 7, 5)]
    records = b"".join(struct.pack("<12fH", 0, 0, 0, *(x for i in face for x in corners[i]), 0)
                       for face in faces)
    path.write_bytes(b"\0" * 80 + struct.pack("<I", len(faces)) + records)


def test_a_robot_whose_meshes_are_cached_is_checked_without_numpy(tmp_path):
    """The mesh summaries of the persistent cache are read with the standard library, and the
    report is the one the cold run (numpy, scipy, trimesh) gave."""
    robot = tmp_path / "boxes.urdf"
    robot.write_text(MESH_ROBOT, encoding="utf-8")
    _box_stl(tmp_path / "box.stl")
    cold_code, cold_modules, cold = _check(tmp_path, "json", robot)
    # the meshes were read (a binary STL with numpy and scipy's qhull: no trimesh since b6bee4b)
    assert {"numpy", "scipy"} <= set(cold_modules)
    rules = {d["rule"] for d in json.loads(cold)["files"][0]["diagnostics"]}
    assert "inertia.exceeds-geometry" in rules  # the meshes' numbers reach the report
    code, modules, warm = _check(tmp_path, "json", robot)
    assert (code, warm) == (cold_code, cold)
    assert sorted({"numpy", "scipy", "trimesh"} & set(modules)) == []


def test_a_cold_visual_mesh_needs_no_trimesh(tmp_path):
    """A binary STL needed only for its hull (a visual beside a collision box) is read with
    numpy and scipy's qhull: trimesh (its topology, for volumes) is not imported."""
    robot = tmp_path / "visual.urdf"
    robot.write_text('<robot name="v"><link name="a"><visual><geometry><mesh filename="box.stl"/>'
                     '</geometry></visual><collision><geometry><box size="0.3 0.2 0.1"/>'
                     "</geometry></collision></link></robot>", encoding="utf-8")
    _box_stl(tmp_path / "box.stl")
    _, modules, _ = _check(tmp_path, "json", robot)
    assert "scipy" in modules and "trimesh" not in modules
