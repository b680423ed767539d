"""The expression validator changes nothing for valid files: every xacro file we have that plain
xacro expands (the seed robots, example-robot-data's, tests/data/xacro_safe) expands to the same
URDF through urdftool, trusted (validator in-process) and --untrusted (validator + sandbox)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from lxml import etree

from tests.conftest import ROBOTS, ROOT, example_robot_data_dir, run_urdftool

XACRO_BIN = Path(sys.executable).parent / "xacro"
SAFE = ROOT / "tests" / "data" / "xacro_safe"


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


def _plain_xacro(path: Path, args: tuple[str, ...]) -> subprocess.CompletedProcess:
    return subprocess.run([str(XACRO_BIN), str(path), *args], capture_output=True, text=True,
                          timeout=120, cwd=ROOT, check=False)


@pytest.mark.parametrize("path,args", _corpus(),
                         ids=lambda v: v.name if isinstance(v, Path) else " ".join(v) or "-")
def test_validator_keeps_valid_files_identical(path, args, monkeypatch):
    monkeypatch.chdir(ROOT)
    plain = _plain_xacro(path, args)
    if plain.returncode != 0:
        pytest.skip(f"plain xacro cannot expand {path.name} either")
    expected = canonical(plain.stdout)
    for mode in ("--trusted", "--untrusted"):
        ours = run_urdftool("expand", mode, path, *args)
        assert ours.code == 0, f"{mode}: {ours.err}"
        assert canonical(ours.out) == expected, f"{mode}: {path} expands differently"


def test_corpus_is_not_trivial():
    """The corpus really exercises the validator: YAML, python.*, string methods, comprehensions,
    $(eval), namespaces; and the seeds and example-robot-data files are in it."""
    names = {p.name for p, _ in _corpus()}
    assert {"arm.urdf.xacro", "dynamic.urdf.xacro", "m2wr.xacro", "test.xacro"} <= names
    text = (SAFE / "arm_description" / "urdf" / "arm.urdf.xacro").read_text()
    for feature in ("xacro.load_yaml", "python.sorted", ".format(", "for j in joints",
                    "$(eval", ".upper()", "extra.", "' if "):
        assert feature in text or feature in (SAFE / "dynamic.urdf.xacro").read_text(), feature
