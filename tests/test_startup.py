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
    "xacro", "yaml", "urdftool.xacro_expand", "urdftool.sandbox", "urdftool.sdf",
    # importlib.resources pulls in zipfile, tempfile, shutil, bz2, lzma, random (~4 ms)
    "importlib.resources", "zipfile", "tempfile", "shutil", "bz2", "lzma", "random",
    # did-you-mean hints and the XML repair; the mesh cache's file names and writes; --jobs
    # and its worker results; pyproject.toml
    "difflib", "bisect", "hashlib", "multiprocessing", "concurrent.futures", "pickle",
    "tomllib" if sys.version_info >= (3, 11) else "tomli",
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


def _check(tmp_path, fmt: str) -> tuple[int, list[str], str]:
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
