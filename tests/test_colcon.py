"""`colcon test` (issue 23): a generated ament_python workspace whose test is urdftool's pytest
helper, built and tested with the real colcon (colcon-common-extensions from PyPI), fails on a
seeded defect and `colcon test-result` lists it at its line; the `--xunit-file` of
`urdftool-ament` is read by `colcon test-result` as the xunit of an ament_cmake linter test."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import ROOT

COLCON = Path(sys.executable).parent / "colcon"


@pytest.fixture(autouse=True)
def _colcon_is_installed():
    """The test extra installs colcon: missing, these tests fail (never skip in silence)."""
    assert COLCON.exists(), "colcon is not installed (pip install -e '.[test]')"

PACKAGE_XML = """<?xml version="1.0"?>
<package format="3">
  <name>bot_description</name>
  <version>0.0.1</version>
  <description>a robot description</description>
  <maintainer email="m@example.com">m</maintainer>
  <license>MIT</license>
  <test_depend>python3-pytest</test_depend>
  <export><build_type>ament_python</build_type></export>
</package>
"""
SETUP_PY = """from setuptools import setup
setup(name="bot_description", version="0.0.1", packages=[],
      data_files=[("share/ament_index/resource_index/packages", ["resource/bot_description"]),
                  ("share/bot_description", ["package.xml"])],
      tests_require=["pytest"])
"""


def _readme_test() -> str:
    """The README's ament_python test file, as written."""
    readme = (ROOT / "README.md").read_text()
    after = readme.split("<!-- snippet: ament-python-test ", 1)[1]
    return after.split("```python\n", 1)[1].split("```", 1)[0]


ROBOT = """<?xml version="1.0"?>
<robot name="bot">
  <link name="base"/>
  <link name="arm">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <joint name="elbow" type="revolute">
    <parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
</robot>
"""


def _workspace(root: Path, robot: str) -> Path:
    package = root / "src" / "bot_description"
    for sub in ("urdf", "test", "resource"):
        (package / sub).mkdir(parents=True)
    (package / "resource" / "bot_description").write_text("")
    (package / "package.xml").write_text(PACKAGE_XML)
    (package / "setup.py").write_text(SETUP_PY)
    (package / "test" / "test_urdftool.py").write_text(_readme_test())
    (package / "urdf" / "bot.urdf").write_text(robot)
    return root


def _colcon(workspace: Path, *args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "COLCON_HOME": str(workspace / ".colcon"),
           "PATH": f"{COLCON.parent}{os.pathsep}{os.environ['PATH']}"}
    env.pop("CI", None)  # the desk's mode: the same findings (tests/test_untrusted_commands.py)
    return subprocess.run([str(COLCON), *args], cwd=workspace, env=env, capture_output=True,
                          text=True, timeout=120, check=False)


@pytest.mark.slow  # a real colcon build and test (~11 s CPU): CI
def test_colcon_test_fails_on_a_seeded_defect_and_test_result_lists_it(tmp_path):
    seeded = ROBOT.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>')
    workspace = _workspace(tmp_path / "ws", seeded)
    assert _colcon(workspace, "build").returncode == 0
    tested = _colcon(workspace, "test")
    assert tested.returncode == 0, tested.stderr  # colcon test itself succeeds...
    result = _colcon(workspace, "test-result", "--verbose")
    assert result.returncode != 0  # ...test-result fails the job
    line = next(n for n, text in enumerate(seeded.splitlines(), 1) if "<axis" in text)
    column = seeded.splitlines()[line - 1].index("<axis") + 1
    assert "1 test, 0 errors, 1 failure" in result.stdout, result.stdout
    assert f"urdf/bot.urdf:{line}:{column}: error joint.zero-axis" in result.stdout

    # fixed: the same workspace passes
    (workspace / "src" / "bot_description" / "urdf" / "bot.urdf").write_text(ROBOT)
    assert _colcon(workspace, "test").returncode == 0
    result = _colcon(workspace, "test-result")
    assert result.returncode == 0 and "1 test, 0 errors, 0 failures" in result.stdout, \
        result.stdout


def test_test_result_reads_the_xunit_file(tmp_path):
    """What an ament_cmake package's test writes (`ament_urdftool --xunit-file`, the README's
    CMake snippet): colcon test-result counts one testcase per file, the defect a failure."""
    robot = tmp_path / "pkg" / "urdf"
    robot.mkdir(parents=True)
    (robot / "good.urdf").write_text(ROBOT)
    (robot / "bad.urdf").write_text(ROBOT.replace('lower="-1" upper="1"', 'lower="1" upper="-1"'))
    results = tmp_path / "build" / "test_results" / "pkg"
    run = subprocess.run([sys.executable, "-m", "urdftool.cli.ament", "--xunit-file",
                          str(results / "urdftool.xunit.xml"), "pkg"], cwd=tmp_path,
                         capture_output=True, text=True, env={**os.environ, "PYTHONPATH": str(ROOT)},
                         check=False)
    assert run.returncode == 1, run.stderr
    result = _colcon(tmp_path, "test-result", "--test-result-base", str(tmp_path / "build"),
                     "--verbose")
    assert result.returncode != 0
    assert "2 tests, 0 errors, 1 failure" in result.stdout, result.stdout
    assert "- pkg.urdftool pkg/urdf/bad.urdf" in result.stdout
    assert "joint.lower-above-upper" in result.stdout
