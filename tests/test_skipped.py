"""Nothing skipped in silence (issue 14): without trimesh the mesh checks that did not run are
named, and what trimesh or pycollada log while reading a mesh never reaches stderr (a load
error carries the first line of it)."""

from __future__ import annotations

import json
import os
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import run_urdftool

ROOT = Path(__file__).resolve().parents[1]
# how this checkout is installed, written out independently of urdftool.errors.install_line
INSTALL = f"{shlex.quote(sys.executable)} -m pip install -e {shlex.quote(f'{ROOT}[mesh]')}"

OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
ROBOT = """<robot name="r">
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><geometry><mesh filename="part.obj" scale="0.1 0.1 0.1"/></geometry></collision>
  </link>
</robot>
"""
BLOCKER = """import sys
class _Missing:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in {blocked!r}:
            raise ModuleNotFoundError(f"No module named {{name!r}}", name=name)
        return None
sys.meta_path.insert(0, _Missing())
"""


def without(tmp_path: Path, *modules: str, args=(), code: str | None = None):
    """urdftool (this checkout) run as a fresh process in which ``modules`` are not installed."""
    site = tmp_path / ("site-" + "-".join(modules))
    site.mkdir(exist_ok=True)
    (site / "sitecustomize.py").write_text(BLOCKER.format(blocked=modules))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join((str(site), str(ROOT))))
    command = ["-c", code] if code else ["-m", "urdftool", *map(str, args)]
    return subprocess.run([sys.executable, *command], capture_output=True, text=True, env=env,
                          timeout=120, check=False, cwd=tmp_path)


def test_without_trimesh_check_names_the_skipped_mesh_checks(tmp_path):
    (tmp_path / "part.obj").write_text(OBJ)
    (tmp_path / "robot.urdf").write_text(ROBOT)
    result = without(tmp_path, "trimesh",
                     args=("check", "--format", "json", tmp_path / "robot.urdf"))
    assert result.stderr == ""
    (diagnostic,) = json.loads(result.stdout)["files"][0]["diagnostics"]
    assert (diagnostic["rule"], diagnostic["severity"]) == ("mesh.not-checked", "warning")
    assert "trimesh is not installed" in diagnostic["message"]
    for skipped in ("mesh.unreadable", "mesh.scale", "mesh.not-watertight",
                    "inertia.exceeds-geometry", "on 'base'"):
        assert skipped in diagnostic["message"]
    assert diagnostic["hint"] == f"install urdftool's mesh extra: {INSTALL}"
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


# -- issue 22.6: a mesh that needs a missing optional library is not checked, never unreadable ----


def _pybullet_mesh(name: str) -> Path:
    import pybullet_data
    return Path(pybullet_data.getDataPath()) / name


def _obj_geometry(path: Path) -> tuple[list[float], list[float], int]:
    """Bounds and triangle count of an OBJ read here line by line (polygons as fans)."""
    points, triangles = [], 0
    for line in path.read_text().splitlines():
        parts = line.split()
        if parts[:1] == ["v"]:
            points.append([float(x) for x in parts[1:4]])
        elif parts[:1] == ["f"]:
            triangles += len(parts) - 3
    return [min(p[i] for p in points) for i in range(3)], \
        [max(p[i] for p in points) for i in range(3)], triangles


READ = """import json, sys
from pathlib import Path
from urdftool.physics import meshes
info = meshes._load(Path(sys.argv[1]), True)
print(json.dumps([info.error, info.lower, info.upper, info.faces, info.watertight]))
"""


def test_textured_obj_is_read_without_pillow(tmp_path):
    """pybullet's duck.obj names its material library and texture: trimesh needs Pillow to join
    its textured parts; the geometry is read without it, the same triangles."""
    duck = _pybullet_mesh("duck.obj")
    result = without(tmp_path, "PIL", code=READ.replace("sys.argv[1]", repr(str(duck))))
    assert result.returncode == 0, result.stderr
    error, lower, upper, faces, _ = json.loads(result.stdout)
    assert error is None
    want_lower, want_upper, want_faces = _obj_geometry(duck)
    assert faces == want_faces
    assert lower == pytest.approx(want_lower, abs=1e-6)
    assert upper == pytest.approx(want_upper, abs=1e-6)


def test_textured_collada_is_read_without_pillow(tmp_path):
    """duck.dae binds an image texture; its triangles are read without Pillow, and they are the
    ones trimesh itself reads from the file with Pillow installed."""
    import trimesh

    duck = _pybullet_mesh("duck.dae")
    result = without(tmp_path, "PIL", code=READ.replace("sys.argv[1]", repr(str(duck))))
    assert result.returncode == 0, result.stderr
    error, lower, upper, faces, _ = json.loads(result.stdout)
    assert error is None
    reference = trimesh.load(duck, force="mesh")
    assert faces == len(reference.faces)
    scale = 0.01  # the file's <unit meter="0.01">, which urdftool applies and trimesh does not
    assert lower == pytest.approx((reference.bounds[0] * scale).tolist(), rel=1e-6)
    assert upper == pytest.approx((reference.bounds[1] * scale).tolist(), rel=1e-6)


@pytest.mark.parametrize("module,distribution", [("collada", "pycollada"), ("scipy", "scipy")])
def test_missing_mesh_library_is_not_checked_never_unreadable(tmp_path, module, distribution,
                                                             monkeypatch):
    (tmp_path / "part.obj").write_text(OBJ)
    (tmp_path / "robot.urdf").write_text(ROBOT)
    monkeypatch.setenv("URDFTOOL_CACHE_DIR", str(tmp_path / "cache"))
    result = without(tmp_path, module, args=("check", "--format", "json",
                                             tmp_path / "robot.urdf"))
    assert result.returncode == 0 and "Traceback" not in result.stderr, result.stderr
    (diagnostic,) = json.loads(result.stdout)["files"][0]["diagnostics"]
    assert (diagnostic["rule"], diagnostic["severity"]) == ("mesh.not-checked", "warning")
    assert diagnostic["message"].startswith(f"{distribution} is not installed: 1 mesh file(s)")
    assert diagnostic["hint"] == f"install urdftool's mesh extra: {INSTALL}"
    # the answer is not stored: with the library the same file is read and its link checked
    # against it (the tetrahedron allows far less than the declared 0.01 kg·m²)
    result = run_urdftool("check", "--format", "json", tmp_path / "robot.urdf")
    rules = [d["rule"] for d in json.loads(result.out)["files"][0]["diagnostics"]]
    assert "mesh.not-checked" not in rules and "inertia.geometry-mismatch" in rules


@pytest.mark.parametrize("direct,line", [
    (None, ("PIP './urdftool[mesh]' (from the folder holding your clone of urdftool: it is on "
            "no package index)")),  # no record: never an index name
    ({"url": "file:///src/urdf%20tool", "dir_info": {"editable": True}},
     "PIP -e '/src/urdf tool[mesh]'"),
    ({"url": "file:///src/urdftool", "dir_info": {}}, "PIP '/src/urdftool[mesh]'"),
    ({"url": "https://github.com/o/urdftool", "vcs_info": {"vcs": "git", "commit_id": "abc"}},
     "PIP 'urdftool[mesh] @ git+https://github.com/o/urdftool@abc'"),
    ({"url": "file:///w/urdftool-0.1.0-py3-none-any.whl", "archive_info": {}},
     "PIP 'urdftool[mesh] @ file:///w/urdftool-0.1.0-py3-none-any.whl'"),
])
def test_install_line_follows_how_urdftool_was_installed(direct, line):
    """PEP 610's direct_url.json examples: the extra is installed from where urdftool came."""
    from urdftool.errors import pip_line

    assert pip_line("PIP", "mesh", None, direct) == line
    assert pip_line("PIP", "mesh", Path("/co"), direct) == "PIP -e '/co[mesh]'"
