"""urdftool.uris: the one parser of package://, model://, file:// and $(find) (issue 33)."""

from __future__ import annotations

import pytest

from urdftool.uris import Uri, find_parts, parse_uri


@pytest.mark.parametrize("text, expected", [
    ("package://arm/meshes/a.stl", Uri("package", "arm", "meshes/a.stl",
                                       "package://arm/meshes/a.stl")),
    ("package:///arm/meshes/a.stl", Uri("package", "arm", "meshes/a.stl",
                                        "package:///arm/meshes/a.stl", True)),
    ("package://arm", Uri("package", "arm", "", "package://arm")),
    ("model://box/meshes/b.dae", Uri("model", "box", "meshes/b.dae", "model://box/meshes/b.dae")),
    ("file:///abs/c.stl", Uri("file", "", "/abs/c.stl", "file:///abs/c.stl")),
    ("https://x.org/d.stl", Uri("https", "", "x.org/d.stl", "https://x.org/d.stl")),
    ("../meshes/e.stl", Uri("path", "", "../meshes/e.stl", "../meshes/e.stl")),
    ("/abs/f.stl", Uri("path", "", "/abs/f.stl", "/abs/f.stl")),
    ("dir/a://b.stl", Uri("path", "", "dir/a://b.stl", "dir/a://b.stl")),  # no scheme
])
def test_parse_uri(text, expected):
    assert parse_uri(text) == expected


def test_named_joins_name_and_rest():
    assert parse_uri("package:///arm/meshes/a.stl").named == "arm/meshes/a.stl"
    assert parse_uri("model://box").named == "box/"


@pytest.mark.parametrize("spec, expected", [
    ("$(find arm)/urdf/a.xacro", ("arm", "urdf/a.xacro")),
    ("$(find  arm)urdf", ("arm", "urdf")),
    ("$(find $(arg p))/a.xacro", None),
    ("urdf/$(find arm)/a.xacro", None),
    ("a.xacro", None),
])
def test_find_parts(spec, expected):
    assert find_parts(spec) == expected
