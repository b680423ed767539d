"""Every Python version urdftool claims (pyproject.toml's classifiers, the README) installs it and
runs it (issue 33: on 3.10 `check` in a directory with a pyproject.toml exited 2, "No module
named 'tomli'"). For each claimed version other than the suite's own: a fresh venv, `pip install`
of this tree (its main dependencies: lxml, numpy, rapidfuzz, landlock, pyseccomp, tomli before
3.11...), then `urdftool check` in a directory whose pyproject.toml configures it (read with
tomllib, or tomli) on a URDF, and `--untrusted` on a xacro file (the sandboxed reader: Landlock
and seccomp on that interpreter), then `urdftool doctor`. CI only (`slow`): a venv costs a
minute. The interpreter of a version is pyenv's newest X.Y.* or `pythonX.Y` on PATH; a claimed
version with no interpreter fails (a claim not proved is not skipped)."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parent.parent
PYENV = Path(os.environ.get("PYENV_ROOT", "/root/.pyenv")) / "versions"


def claimed() -> list[str]:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    versions = [c.rsplit(" :: ", 1)[1] for c in project["classifiers"]
                if re.fullmatch(r"Programming Language :: Python :: 3\.\d+", c)]
    assert project["requires-python"] == f">={versions[0]}", "the oldest classifier is the floor"
    return versions


def interpreter(version: str) -> str | None:
    """pyenv's newest X.Y.*, else pythonX.Y on PATH (not a pyenv shim: it may point nowhere)."""
    patches = sorted(PYENV.glob(f"{version}.*/bin/python"),
                     key=lambda p: [int(n) for n in re.findall(r"\d+", p.parent.parent.name)])
    if patches:
        return str(patches[-1])
    found = shutil.which(f"python{version}")
    return found if found and "shims" not in Path(found).parts else None


def test_the_claims_agree():
    versions = claimed()
    assert versions[0] == "3.10" and "3.13" in versions
    assert f"`python3` ({versions[0]} to {versions[-1]})" in (ROOT / "README.md").read_text()
    here = f"{sys.version_info.major}.{sys.version_info.minor}"
    assert here in versions, f"the suite runs on {here}, which is not claimed"


def _source(tmp_path: Path) -> Path:
    """What `pip install` of a clone reads (a copy: building in the tree would write there)."""
    source = tmp_path / "urdftool-src"
    source.mkdir()
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        shutil.copy2(ROOT / name, source / name)
    shutil.copytree(ROOT / "urdftool", source / "urdftool",
                    ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    return source


PYPROJECT = """[project]
name = "my-robot"

[tool.urdftool]
ignore = ["inertia"]
"""
URDF = """<robot name="r"><link name="a"/><link name="b"/>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
    <limit lower="1" upper="-1" effort="1" velocity="1"/></joint></robot>
"""
XACRO = """<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="low" value="${radians(90)}"/>
  <link name="a"/><link name="b"/>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
    <limit lower="${low}" upper="-1" effort="1" velocity="1"/></joint></robot>
"""


@pytest.mark.slow
@pytest.mark.parametrize("version", [v for v in claimed()
                                     if v != f"{sys.version_info.major}.{sys.version_info.minor}"])
def test_installs_and_checks_on(version, tmp_path):
    python = interpreter(version)
    assert python is not None, f"Python {version} is claimed: no python{version} on PATH nor " \
                               f"in {PYENV} to prove it"
    venv = tmp_path / "venv"
    subprocess.run([python, "-m", "venv", str(venv)], check=True, timeout=300)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "CI")}
    done = subprocess.run([str(venv / "bin" / "python"), "-m", "pip", "install", "--quiet",
                           str(_source(tmp_path))], capture_output=True, text=True, timeout=1200,
                          env=env, check=False)
    assert done.returncode == 0, done.stderr[-3000:]
    urdftool = str(venv / "bin" / "urdftool")
    project = tmp_path / "my-robot"
    project.mkdir()
    (project / "pyproject.toml").write_text(PYPROJECT)
    (project / "robot.urdf").write_text(URDF)
    (project / "robot.urdf.xacro").write_text(XACRO)
    env["URDFTOOL_CACHE_DIR"] = str(tmp_path / "cache")
    for args in (["check", "--format", "json", "robot.urdf"],
                 ["check", "--untrusted", "--format", "json", "robot.urdf.xacro"]):
        run = subprocess.run([urdftool, *args], cwd=project, capture_output=True, text=True,
                             timeout=300, env=env, check=False)
        assert run.returncode == 1, (args, run.stdout[-2000:], run.stderr[-2000:])
        rules = set(re.findall(r'"rule": "([^"]+)"', run.stdout))
        # the defect is found; the configuration (read with tomllib or tomli) ignored inertia
        assert "joint.lower-above-upper" in rules, (args, rules)
        assert not any(rule.startswith("inertia.") for rule in rules), (args, rules)
    doctor = subprocess.run([urdftool, "doctor"], capture_output=True, text=True, timeout=300,
                            env=env, check=False)
    assert doctor.returncode == 0, doctor.stderr[-2000:]
    assert f"Python {version}." in doctor.stdout
    assert re.search(r"landlock +abi \d+", doctor.stdout), doctor.stdout
    assert re.search(r"seccomp +allowlist", doctor.stdout), doctor.stdout
