"""Outputs never damage inputs: ``-o`` (expand, convert, check --fix) refuses to write over any
file the command read (also through a symlink or an include) unless ``--in-place`` says so, and
every write is atomic (temp file + rename) and keeps the replaced file's permissions."""

from __future__ import annotations

import os
import shutil
import stat

import pytest

from tests.conftest import ROBOTS, run_urdftool

BROKEN = ROBOTS / "m2wr" / "published" / "m2wr.xacro"
XACRO = """<?xml version="1.0"?>
<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="parts.xacro"/>
  <xacro:part name="base"/>
</robot>
"""
PARTS = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="part" params="name"><link name="${name}"/></xacro:macro>
</robot>
"""
SDF = """<?xml version="1.0"?>
<sdf version="1.7"><model name="m"><link name="base"/></model></sdf>
"""


@pytest.fixture
def xacro_files(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "robot.urdf.xacro").write_text(XACRO)
    (tmp_path / "parts.xacro").write_text(PARTS)
    return tmp_path / "robot.urdf.xacro", tmp_path / "parts.xacro"


def _no_temp_files(directory):
    return not [p for p in directory.iterdir() if p.name.endswith(".tmp")]


def test_expand_refuses_to_overwrite_an_included_file(xacro_files):
    top, parts = xacro_files
    for target in (top, parts, "./parts.xacro"):
        result = run_urdftool("expand", top, "-o", target)
        assert result.code == 2 and "refusing to overwrite" in result.err
    assert top.read_text() == XACRO and parts.read_text() == PARTS


def test_expand_refuses_a_symlink_to_its_input(xacro_files):
    top, parts = xacro_files
    link = top.parent / "out.urdf"
    link.symlink_to(parts)
    result = run_urdftool("expand", top, "-o", link)
    assert result.code == 2 and "refusing to write through a symbolic link" in result.err
    assert parts.read_text() == PARTS and link.is_symlink()


def test_expand_writes_atomically_with_normal_permissions(xacro_files):
    top, _ = xacro_files
    out = top.parent / "robot.urdf"
    assert run_urdftool("expand", top, "-o", out).code == 0
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(out.stat().st_mode) == 0o666 & ~umask  # not mkstemp's 0600
    assert 'link name="base"' in out.read_text()
    assert _no_temp_files(top.parent)


def test_fix_refuses_its_input_without_in_place(tmp_path):
    path = tmp_path / "m2wr.xacro"
    shutil.copy(BROKEN, path)
    original = path.read_text()
    result = run_urdftool("check", "--fix", "-o", path, path)
    assert result.code == 2 and "--in-place" in result.err
    assert path.read_text() == original
    assert run_urdftool("check", "--in-place", path).code == 2  # --in-place needs --fix


def test_fix_in_place_rewrites_atomically_and_keeps_the_mode(tmp_path):
    path = tmp_path / "m2wr.xacro"
    shutil.copy(BROKEN, path)
    path.chmod(0o640)
    original = path.read_text()
    run_urdftool("check", "--fix", "--in-place", path)
    fixed = path.read_text()
    assert fixed != original and "<material>Gazebo/Orange</material>" in fixed
    assert len(fixed.splitlines()) == len(original.splitlines())  # lines stay where they were
    assert stat.S_IMODE(path.stat().st_mode) == 0o640
    assert _no_temp_files(tmp_path)


def test_failed_write_leaves_the_target_untouched(tmp_path, monkeypatch):
    from urdftool.errors import ToolError
    from urdftool.output import write_output

    target = tmp_path / "out.urdf"
    target.write_text("previous")

    def fail(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", fail)
    with pytest.raises(ToolError, match="cannot write"):
        write_output("new text", str(target))
    assert target.read_text() == "previous"
    assert _no_temp_files(tmp_path)


def test_convert_refuses_to_overwrite_its_input(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    model = tmp_path / "model.sdf"
    model.write_text(SDF)
    result = run_urdftool("convert", model, "-o", model)
    assert result.code == 2 and "refusing to overwrite" in result.err
    assert model.read_text() == SDF
    assert run_urdftool("convert", model, "-o", tmp_path / "model.urdf").code == 0
    assert "<robot" in (tmp_path / "model.urdf").read_text()


INJECTED = "\n::error::pwned\n  ::stop-commands::x\n##[group]y ##vso[task.setvariable]z\n"


def _runner_commands(text: str) -> list[str]:
    return [line for line in text.splitlines()
            if line.lstrip().startswith("::") or "##[" in line or "##vso[" in line]


@pytest.mark.parametrize("kind", ["expand", "convert"])
def test_documents_on_stdout_start_no_runner_command(tmp_path, kind):
    # text and comments carried into the output document (a link's comment, a plugin's text)
    # hold lines a CI runner executes: on stdout they are written as the same XML without
    # them; a file written with -o stays exact
    from lxml import etree

    if kind == "expand":
        path = tmp_path / "r.urdf.xacro"
        path.write_text('<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">'
                        f'<!--{INJECTED}--><link name="a"/><gazebo>{INJECTED}</gazebo></robot>')
    else:
        path = tmp_path / "m.sdf"
        path.write_text("<sdf version='1.7'><model name='m'><link name='a'/>"
                        f"<plugin name='p' filename='libp.so'><k>{INJECTED}</k></plugin>"
                        "</model></sdf>")
    shown = run_urdftool(kind, "--trusted", str(path))
    assert shown.code == 0, shown.err
    assert _runner_commands(shown.out) == []
    written = tmp_path / "out.urdf"
    assert run_urdftool(kind, "--trusted", str(path), "-o", str(written)).code == 0
    exact = written.read_text()
    assert _runner_commands(exact)  # the file is the document as it is

    def texts(document: str) -> list[str]:
        root = etree.fromstring(document.encode())
        return [t for t in root.itertext() if "pwned" in t or "group" in t]

    assert texts(shown.out) == texts(exact) and texts(exact)
