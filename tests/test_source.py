"""Source loading: kind detection, xacro expansion with every element's place in the user's
files (through includes and macros), package resolution."""

from __future__ import annotations

from pathlib import Path

from urdftool.check import check_file
from urdftool.loader import load
from urdftool.model import build_robot
from urdftool.packages import PackageResolver
from urdftool.source import LoadOptions, detect_kind

MACROS = """<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="wheel" params="name r">
    <link name="${name}">
      <visual><geometry><cylinder radius="${r}" length="0.1"/></geometry></visual>
    </link>
  </xacro:macro>
</robot>
"""

TOP = """<?xml version="1.0"?>
<robot name="car" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="scale" default="1"/>
  <xacro:include filename="$(find wheels)/urdf/wheel.xacro"/>
  <xacro:property name="radius" value="${0.2 * $(arg scale)}"/>
  <link name="base"/>
  <xacro:wheel name="left" r="${radius}"/>
  <xacro:wheel name="right" r="${radius}"/>
  <joint name="j" type="fixed"><parent link="base"/><child link="left"/></joint>
</robot>
"""


def _package(tmp_path: Path) -> Path:
    package = tmp_path / "wheels"
    (package / "urdf").mkdir(parents=True)
    (package / "package.xml").write_text('<package format="2"><name>wheels</name></package>')
    (package / "urdf" / "wheel.xacro").write_text(MACROS)
    return package


def test_detect_kind():
    assert detect_kind(Path("a.urdf"), "<robot name='x'/>") == "urdf"
    uses = '<robot xmlns:xacro="http://ros.org/wiki/xacro"><xacro:property name="a" value="1"/>'
    assert detect_kind(Path("a.urdf"), uses + "</robot>") == "xacro"
    assert detect_kind(Path("a.xml"), '<robot><link name="${n}"/></robot>') == "xacro"
    # a .urdf is read as URDF consumers read it: leftover substitutions are reported, not run
    assert detect_kind(Path("a.urdf"), '<robot><link name="${n}"/></robot>') == "urdf"
    # generated URDFs often keep an unused xmlns:xacro: no need to run xacro on them
    assert detect_kind(Path("a.urdf"), '<robot xmlns:xacro="http://ros.org/wiki/xacro"/>') == "urdf"
    assert detect_kind(Path("a.xml"), '<?xml version="1.0"?><sdf version="1.7"/>') == "sdf"
    assert detect_kind(Path("a.xacro"), "<robot name='x'/>") == "xacro"


def test_macro_elements_point_at_macro_body_with_call_site(tmp_path):
    package = _package(tmp_path)
    top = tmp_path / "car.urdf.xacro"
    top.write_text(TOP)
    source = load(top, LoadOptions(packages={"wheels": str(package)}, xacro_args={"scale": "2"}))
    robot = build_robot(source)
    assert not source.problems
    left, right = robot.link("left"), robot.link("right")
    body = str(package / "urdf" / "wheel.xacro")
    assert Path(left.loc.path).resolve() == Path(body).resolve()
    assert left.loc.line == 3 and left.loc.column == 5
    assert left.loc.via == (f"{top}:7",) and right.loc.via == (f"{top}:8",)
    cylinder = left.visuals[0].geometry
    assert cylinder.radius == 0.4  # the xacro argument reached the expression
    assert cylinder.loc.line == 4 and cylinder.loc.column == 25
    assert robot.joint("j").loc == robot.joint("j").loc.__class__(str(top), 9, 3,
                                                                  robot.joint("j").loc.element)


def test_find_resolves_by_walking_up_to_package_xml(tmp_path):
    package = _package(tmp_path)
    (package / "urdf" / "car.urdf.xacro").write_text(TOP)
    source = load(package / "urdf" / "car.urdf.xacro")
    assert not source.problems and build_robot(source).link("right") is not None


def test_xacro_error_is_located_in_the_xacro_file(tmp_path):
    top = tmp_path / "bad.urdf.xacro"
    top.write_text(TOP.replace("${radius}\"/>\n  <joint", "${radius * nope}\"/>\n  <joint")
                   .replace("$(find wheels)/urdf/wheel.xacro", str(_package(tmp_path) /
                                                                  "urdf" / "wheel.xacro")))
    report = check_file(top)
    errors = [d for d in report.diagnostics if d.rule == "xacro.error"]
    assert len(errors) == 1
    assert errors[0].path == str(top) and errors[0].line == 8
    assert "nope" in errors[0].message


def test_package_resolver_sources(tmp_path):
    package = _package(tmp_path)
    explicit = PackageResolver({"wheels": str(tmp_path)})
    assert explicit.find("wheels") == tmp_path.resolve()
    from_env = PackageResolver(environ={"ROS_PACKAGE_PATH": str(tmp_path)})
    assert from_env.find("wheels") == package
    prefix = tmp_path / "install"
    (prefix / "share" / "ament_index" / "resource_index" / "packages").mkdir(parents=True)
    (prefix / "share" / "ament_index" / "resource_index" / "packages" / "arm").touch()
    ament = PackageResolver(environ={"AMENT_PREFIX_PATH": str(prefix)})
    assert ament.find("arm") == prefix / "share" / "arm"
    assert ament.resolve_uri("package://arm/meshes/a.stl", tmp_path) == \
        prefix / "share" / "arm" / "meshes" / "a.stl"
    assert ament.resolve_uri("package://missing/a.stl", tmp_path) is None
    assert ament.resolve_uri("package:///arm/a.stl", tmp_path) == prefix / "share" / "arm" / "a.stl"
    assert ament.resolve_uri("meshes/a.stl", tmp_path) == tmp_path / "meshes" / "a.stl"


def test_xpath_is_lxml_getpath():
    from lxml import etree

    from urdftool.source import Source

    root = etree.fromstring(
        b'<robot xmlns:x="urn:x"><link name="a"/><!-- c --><x:link/><link><visual/><visual/>'
        b'<?pi x?></link><x:y><link/><link/></x:y><gazebo><plugin/><x:plugin/><plugin/></gazebo>'
        b'<joint/></robot>')
    source = Source("t.urdf", "urdf", root=root)
    elements = list(root.iter())
    for element in reversed(elements):  # leaves first: parents' paths are made on the way
        assert source.xpath(element) == element.getroottree().getpath(element)


def test_xpath_is_linear_on_a_wide_file():
    """getpath counts preceding siblings: for every element of a 40k-wide file that is
    ~8e8 steps (seconds); one pass per parent is instant."""
    import time

    from lxml import etree

    from urdftool.source import Source

    root = etree.fromstring("<robot>" + "<link/>" * 40_000 + "</robot>")
    source = Source("t.urdf", "urdf", root=root)
    start = time.process_time()  # CPU: the machine's other load does not count
    paths = [source.xpath(link) for link in root]
    assert time.process_time() - start < 3.0
    assert paths[0] == "/robot/link[1]" and paths[-1] == "/robot/link[40000]"
