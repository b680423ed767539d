"""The expression interpreter changes nothing for valid files: every xacro file we have that plain
xacro expands (the seed robots, example-robot-data's, tests/data/xacro_safe, the real description
packages in /work/shared/real-packages, entries and macro fragments) expands to the same URDF
through urdftool, trusted (interpreter in-process) and --untrusted (interpreter + sandbox).

Plain xacro resolves ``$(find PKG)`` through ``ament_index_python``, which a machine without ROS
lacks: a stand-in module (``_ament_shim``) answers from the ``package.xml`` files of the corpus,
so plain xacro itself, unchanged, is the reference."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from lxml import etree

from tests.conftest import ROBOTS, ROOT, example_robot_data_dir, run_urdftool

XACRO_BIN = Path(sys.executable).parent / "xacro"
SAFE = ROOT / "tests" / "data" / "xacro_safe"
REAL = Path("/work/shared/real-packages")
SHIM = """
import json, os
def get_package_share_directory(name):
    packages = json.loads(os.environ["URDFTOOL_TEST_PACKAGES"])
    if name not in packages:
        raise LookupError(name)
    return packages[name]
"""


def _packages() -> dict[str, str]:
    """Package name -> directory, for every package.xml of the corpus."""
    found = {}
    for root in (ROBOTS, SAFE, REAL):
        for manifest in sorted(root.rglob("package.xml")) if root.is_dir() else []:
            name = etree.parse(str(manifest)).findtext("name")
            if name:
                found.setdefault(name.strip(), str(manifest.parent))
    return found


@pytest.fixture(scope="module")
def ament_shim(tmp_path_factory) -> dict[str, str]:
    """Environment for plain xacro: PYTHONPATH with ament_index_python answering from
    _packages()."""
    directory = tmp_path_factory.mktemp("ament_shim")
    (directory / "ament_index_python").mkdir()
    (directory / "ament_index_python" / "__init__.py").write_text("")
    (directory / "ament_index_python" / "packages.py").write_text(SHIM)
    return {**os.environ, "PYTHONPATH": str(directory),
            "URDFTOOL_TEST_PACKAGES": json.dumps(_packages())}


def _corpus() -> list[tuple[Path, tuple[str, ...]]]:
    files = [(p, ()) for p in sorted(ROBOTS.rglob("*.xacro"))]
    try:
        files += [(p, ()) for p in sorted(example_robot_data_dir().rglob("*.xacro"))]
    except RuntimeError:
        pass
    arm = SAFE / "arm_description" / "urdf" / "arm.urdf.xacro"
    files += [(arm, ()), (arm, ("prefix:=r_", "use_gripper:=false", "scale:=2")),
              (SAFE / "dynamic.urdf.xacro", ()),
              (SAFE / "dynamic.urdf.xacro", ("wheels:=3", "kind:=drive"))]
    if REAL.is_dir():
        files += [(p, ()) for p in sorted(REAL.rglob("*.xacro"))]
        files.append((REAL / "realsense2_description" / "urdf" / "test_d435_camera.urdf.xacro",
                      ("use_nominal_extrinsics:=true", "add_plug:=true")))
        files.append((REAL / "flir_camera_description" / "urdf" / "demo.urdf.xacro",
                      ("model:=flir_blackfly_s",)))
    return files


def canonical(text: str) -> bytes:
    """The URDF with comments and whitespace-only text removed, in canonical XML."""
    parser = etree.XMLParser(remove_blank_text=True, remove_comments=True)
    root = etree.fromstring(text.encode("utf-8"), parser)
    for element in root.iter():
        if element.text is not None and not element.text.strip():
            element.text = None
        if element.tail is not None and not element.tail.strip():
            element.tail = None
    return etree.tostring(root, method="c14n")


def _plain_xacro(path: Path, args: tuple[str, ...], env=None) -> subprocess.CompletedProcess:
    return subprocess.run([str(XACRO_BIN), str(path), *args], capture_output=True, text=True,
                          timeout=120, cwd=ROOT, check=False, env=env)


@pytest.mark.parametrize("path,args", _corpus(),
                         ids=lambda v: v.name if isinstance(v, Path) else " ".join(v) or "-")
def test_interpreter_keeps_valid_files_identical(path, args, monkeypatch, ament_shim):
    monkeypatch.chdir(ROOT)
    plain = _plain_xacro(path, args, ament_shim)
    if plain.returncode != 0:
        pytest.skip(f"plain xacro cannot expand {path.name} either: {plain.stderr[-300:]}")
    expected = canonical(plain.stdout)
    packages = [f"-P{name}={directory}" for name, directory in _packages().items()]
    for mode in ("--trusted", "--untrusted"):
        ours = run_urdftool("expand", mode, *packages, path, *args)
        assert ours.code == 0, f"{mode}: {ours.err}"
        assert canonical(ours.out) == expected, f"{mode}: {path} expands differently"


def test_corpus_is_not_trivial():
    """The corpus really exercises the interpreter: YAML, python.*, string methods, comprehensions,
    $(eval), namespaces; and the seeds and example-robot-data files are in it."""
    names = {p.name for p, _ in _corpus()}
    assert {"arm.urdf.xacro", "dynamic.urdf.xacro", "m2wr.xacro", "test.xacro"} <= names
    if REAL.is_dir():
        assert {"test_d435_multiple_cameras.urdf.xacro", "_d455.urdf.xacro",
                "flir_blackfly_s.urdf.xacro"} <= names
    text = (SAFE / "arm_description" / "urdf" / "arm.urdf.xacro").read_text()
    for feature in ("xacro.load_yaml", "python.sorted", ".format(", "for j in joints",
                    "$(eval", ".upper()", "extra.", "' if "):
        assert feature in text or feature in (SAFE / "dynamic.urdf.xacro").read_text(), feature
