"""The per-process memos of a check run (link analyses shared across robots, resolved paths,
did-you-mean suggestions): a file's findings do not depend on what was checked before it."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from urdftool import packages
from urdftool.check import CheckOptions, check_file, check_paths
from urdftool.loader import load
from urdftool.model import build_robot
from urdftool.physics import links

# a link whose declared moments exceed what its box can hold, and a misspelt element
LINK = """  <link name="arm">
    <inertial><origin xyz="{x} 0 0.1"/><mass value="1"/>
      <inertia ixx="5" iyy="5" izz="5" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual>
    <colision><geometry><box size="0.1 0.1 0.1"/></geometry></colision>
  </link>
"""


def robot(x: str = "0", padding: int = 0) -> str:
    return ('<robot name="r">\n' + "  <!-- padding -->\n" * padding
            + '  <link name="base"/>\n' + LINK.format(x=x)
            + '  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>'
              '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n</robot>\n')


def fresh(path: Path):
    links._clear_memos()
    links._last = None
    return check_file(path).diagnostics


def test_identical_links_in_two_files_keep_their_own_locations(write):
    first = write(robot(padding=0), "a/robot.urdf")
    second = write(robot(padding=7), "b/robot.urdf")
    alone = [fresh(first), fresh(second)]
    together = [r.diagnostics for r in check_paths([str(first), str(second)],
                                                   CheckOptions(jobs=1)).files]
    assert together == alone
    lines = {d.rule: d.line for d in together[1]}
    assert lines["inertia.exceeds-geometry"] == {d.rule: d.line for d in together[0]}[
        "inertia.exceeds-geometry"] + 7
    assert all(d.path == str(second) for d in together[1])


def test_negative_zero_is_not_taken_for_zero(write):
    plus, minus = write(robot(x="0"), "plus.urdf"), write(robot(x="-0"), "minus.urdf")
    links._clear_memos()
    for path in (plus, minus):
        robot_ = build_robot(load(path))
        links._last = None
        (arm,) = [a for a in links.analyse(robot_).values() if a.link.name == "arm"]
        assert math.copysign(1.0, arm.com[0]) == (1.0 if path == plus else -1.0)


def test_resolved_is_path_resolve(tmp_path):
    (tmp_path / "real" / "sub").mkdir(parents=True)
    (tmp_path / "real" / "sub" / "x.stl").write_text("")
    (tmp_path / "link").symlink_to(tmp_path / "real")
    (tmp_path / "linked_sub").symlink_to(tmp_path / "link" / "sub")
    (tmp_path / "real" / "file_link.stl").symlink_to(tmp_path / "real" / "sub" / "x.stl")
    (tmp_path / "loop").symlink_to("loop")
    for name in ("link/sub/x.stl", "linked_sub/x.stl", "linked_sub/../sub/x.stl",
                 "real/file_link.stl", "real/../real/x.stl", "missing/y/z", ".", "link/",
                 "link/./sub", "real/sub/x.stl/below", "linked_sub/.."):
        path = tmp_path / name
        packages._REALPATHS.clear()
        assert packages.resolved(str(path)) == str(path.resolve()), name
        assert packages.resolved(path) == str(path.resolve()), name
    for name in ("loop", "loop/x"):
        packages._REALPATHS.clear()
        with pytest.raises(RuntimeError):
            (tmp_path / name).resolve()
        with pytest.raises(RuntimeError):
            packages.resolved(tmp_path / name)


def test_shared_uri_resolution_keeps_each_resolvers_packages(tmp_path):
    one, two = tmp_path / "one", tmp_path / "two"
    (one / "meshes").mkdir(parents=True)
    (two / "meshes").mkdir(parents=True)
    robot_file = tmp_path / "robot.urdf"
    uri = "package://pkg/meshes/a.stl"
    first = packages.PackageResolver({"pkg": str(one)}, robot_file)
    second = packages.PackageResolver({"pkg": str(two)}, robot_file)
    plain = packages.PackageResolver({}, robot_file)
    assert first.resolve_uri(uri, tmp_path) == one / "meshes" / "a.stl"
    assert second.resolve_uri(uri, tmp_path) == two / "meshes" / "a.stl"
    assert plain.resolve_uri(uri, tmp_path) is None
    assert plain.resolve_uri("meshes/a.stl", one) == one / "meshes" / "a.stl"
