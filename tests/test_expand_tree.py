"""`urdftool expand` (same URDF as plain xacro, errors located, never writes over its input)
and `urdftool tree`."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from lxml import etree

from tests.conftest import pybullet_data_dir, run_urdftool

XACRO = """<?xml version="1.0"?>
<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="l" value="0.5"/>
  <xacro:macro name="seg" params="i parent">
    <link name="link${i}"><visual><geometry><box size="0.1 0.1 ${l}"/></geometry></visual></link>
    <joint name="j${i}" type="revolute"><parent link="${parent}"/><child link="link${i}"/>
      <origin xyz="0 0 ${l*i}"/><axis xyz="0 1 0"/>
      <limit lower="${-pi/2}" upper="${pi/2}" effort="10" velocity="1"/></joint>
  </xacro:macro>
  <link name="base"/>
  <xacro:seg i="1" parent="base"/>
  <xacro:seg i="2" parent="link1"/>
</robot>
"""


def _canonical(text: str) -> bytes:
    parser = etree.XMLParser(remove_blank_text=True, remove_comments=True)
    return etree.tostring(etree.fromstring(text.encode(), parser), method="c14n")


def test_expand_equals_plain_xacro(write, tmp_path):
    path = write(XACRO, "arm.urdf.xacro")
    ours = run_urdftool("expand", path)
    assert ours.code == 0, ours.err
    theirs = subprocess.run([str(Path(sys.executable).parent / "xacro"), str(path)], capture_output=True,
                            text=True, check=True).stdout
    assert _canonical(ours.out) == _canonical(theirs)
    out = tmp_path / "out.urdf"
    assert run_urdftool("expand", path, "-o", out).code == 0
    assert _canonical(out.read_text()) == _canonical(theirs)


def test_expand_refuses_to_overwrite_input(write):
    path = write(XACRO, "arm.urdf.xacro")
    result = run_urdftool("expand", path, "-o", path)
    assert result.code == 2 and "refusing to overwrite" in result.err
    assert path.read_text() == XACRO


def test_expand_error_points_into_xacro(write):
    path = write(XACRO.replace("${l*i}", "${l*k}"), "arm.urdf.xacro")
    result = run_urdftool("expand", path)
    assert result.code == 1 and result.out == ""
    assert f"{path}:7:" in result.err and "k" in result.err


def test_tree_of_r2d2():
    result = run_urdftool("tree", "--format", "json", pybullet_data_dir() / "r2d2.urdf")
    data = json.loads(result.out)
    (root,) = data["roots"]
    assert root["link"] == "base_link"

    def count(node):
        return 1 + sum(count(c) for c in node["children"])

    links = etree.parse(str(pybullet_data_dir() / "r2d2.urdf")).getroot().findall("link")
    assert count(root) == len(links) == 16  # every link hangs under base_link
    text = run_urdftool("tree", pybullet_data_dir() / "r2d2.urdf")
    assert text.code == 0 and "right_tip" in text.out and "gripper_extension" in text.out
