"""Nothing skipped in silence (issue 14): without trimesh the mesh checks that did not run are
named, and what trimesh or pycollada log while reading a mesh never reaches stderr (a load
error carries the first line of it)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

from tests.conftest import run_urdftool

OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
ROBOT = """<robot name="r">
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><geometry><mesh filename="part.obj" scale="0.1 0.1 0.1"/></geometry></collision>
  </link>
</robot>
"""
BLOCKER = """import sys
class _NoTrimesh:
    def find_spec(self, name, path=None, target=None):
        if name == "trimesh" or name.startswith("trimesh."):
            raise ModuleNotFoundError(f"No module named {name!r}")
        return None
sys.meta_path.insert(0, _NoTrimesh())
"""


def test_without_trimesh_check_names_the_skipped_mesh_checks(tmp_path):
    (tmp_path / "part.obj").write_text(OBJ)
    (tmp_path / "robot.urdf").write_text(ROBOT)
    (tmp_path / "site").mkdir()
    (tmp_path / "site" / "sitecustomize.py").write_text(BLOCKER)
    env = dict(os.environ, PYTHONPATH=str(tmp_path / "site"))
    result = subprocess.run([sys.executable, "-m", "urdftool", "check", "--format", "json",
                             str(tmp_path / "robot.urdf")], capture_output=True, text=True,
                            env=env, timeout=60, check=False)
    assert result.stderr == ""
    (diagnostic,) = json.loads(result.stdout)["files"][0]["diagnostics"]
    assert (diagnostic["rule"], diagnostic["severity"]) == ("mesh.not-checked", "warning")
    assert "trimesh is not installed" in diagnostic["message"]
    for skipped in ("mesh.unreadable", "mesh.scale", "mesh.not-watertight",
                    "inertia.exceeds-geometry", "on 'base'"):
        assert skipped in diagnostic["message"]
    assert diagnostic["hint"] == "pip install 'urdftool[mesh]'"
    assert diagnostic["line"] == 4
    # with trimesh the same run reads the mesh: no such finding
    result = run_urdftool("check", "--format", "json", tmp_path / "robot.urdf")
    rules = [d["rule"] for d in json.loads(result.out)["files"][0]["diagnostics"]]
    assert "mesh.not-checked" not in rules


def test_library_logging_becomes_the_cause_not_stderr(tmp_path, monkeypatch):
    import logging

    import trimesh

    def failing_load(*args, **kwargs):
        try:
            raise KeyError("faces")
        except KeyError:  # what trimesh's loaders do: a warning with its traceback
            logging.getLogger("trimesh").warning("unable to get faces", exc_info=True)
            logging.getLogger("collada").error("broken <triangles>\nsecond line")
        return trimesh.Scene()

    monkeypatch.setattr(trimesh, "load", failing_load)
    (tmp_path / "part.obj").write_text(OBJ)
    (tmp_path / "robot.urdf").write_text(ROBOT)
    result = run_urdftool("check", "--no-cache", "--format", "json", tmp_path / "robot.urdf")
    assert result.err == ""
    (diagnostic,) = json.loads(result.out)["files"][0]["diagnostics"]
    assert diagnostic["rule"] == "mesh.unreadable"
    assert diagnostic["message"].endswith("cannot be read: no triangles in it "
                                          "(unable to get faces)")
    assert logging.getLogger("trimesh").propagate  # the loggers are given back as they were
