"""The engine behind ``urdftool lsp`` without the protocol: an edit re-runs only the checks
that read the edited file; YAML read by xacro is parsed once per text and every expansion
still gets its own data."""

from __future__ import annotations

from urdftool.lsp.engine import Engine, Settings

MACROS = """<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="arm" params="prefix length">
    <link name="${prefix}link"/>
  </xacro:macro>
</robot>
"""
ENTRY = """<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="macros.xacro"/>
  <xacro:property name="data" value="${xacro.load_yaml('data.yaml')}"/>
  <link name="base"/>
  <xacro:arm prefix="a_" length="${data['length']}"/>
  <joint name="j" type="fixed"><parent link="base"/><child link="a_link"/></joint>
  <link name="n${len(data['items'])}"/>
  <xacro:if value="${data['items'].append(1) or True}"><link name="m${len(data['items'])}"/></xacro:if>
</robot>
"""
OTHER = '<robot name="o"><link name="x"/></robot>\n'


def _engine() -> Engine:
    settings, problems = Settings().updated({"trusted": True}, trust=True)
    assert problems == []
    return Engine(settings)


def test_an_edit_rechecks_only_the_checks_that_read_the_file(tmp_path):
    (tmp_path / "package.xml").write_text("<package/>", encoding="utf-8")
    (tmp_path / "macros.xacro").write_text(MACROS, encoding="utf-8")
    (tmp_path / "data.yaml").write_text("length: 2\nitems: [1, 2]\n", encoding="utf-8")
    (tmp_path / "robot.urdf.xacro").write_text(ENTRY, encoding="utf-8")
    (tmp_path / "other.urdf").write_text(OTHER, encoding="utf-8")
    engine = _engine()
    checked = []
    original = engine._check_one

    def spy(unit, index, options):
        checked.append(unit.targets[index].path.rsplit("/", 1)[-1])
        original(unit, index, options)

    engine._check_one = spy
    engine.refresh([str(tmp_path / "macros.xacro")])
    assert sorted(checked) == ["macros.xacro", "other.urdf", "robot.urdf.xacro"]
    checked.clear()
    engine.set_buffer(str(tmp_path / "macros.xacro"),
                      MACROS.replace("${prefix}link", "${prefix}lnk"))
    engine.refresh([str(tmp_path / "macros.xacro")])
    # the entry that reads it; the fragment's own check is put off (its findings come
    # through the entry), the URDF that does not read it is not checked again
    assert checked == ["robot.urdf.xacro"]
    result = next(iter(engine.snapshot.values()))
    found = {(d.rule, d.message) for ds in result.diagnostics.values() for d in ds}
    assert any(rule == "structure.missing-link" and "a_link" in message
               for rule, message in found), found
    assert engine.refresh_pending() and checked == ["robot.urdf.xacro", "macros.xacro"]


def test_yaml_data_changed_by_an_expression_is_not_shared_between_expansions(tmp_path):
    """The parsed YAML is kept between expansions (the server expands on every edit); an
    expression that changes the data it got changes only its own expansion's copy."""
    (tmp_path / "macros.xacro").write_text(MACROS, encoding="utf-8")
    (tmp_path / "data.yaml").write_text("length: 2\nitems: [1, 2]\n", encoding="utf-8")
    (tmp_path / "robot.urdf.xacro").write_text(ENTRY, encoding="utf-8")
    import xacro
    from lxml import etree

    from urdftool.model import build_robot
    from urdftool.source import LoadOptions, load

    names = []
    for _ in range(3):
        robot = build_robot(load(tmp_path / "robot.urdf.xacro", LoadOptions()))
        names.append(sorted(link.name for link in robot.links))
    document = xacro.process_file(str(tmp_path / "robot.urdf.xacro"), mappings={})
    plain = sorted(e.get("name") for e in etree.fromstring(document.toxml().encode()).iter("link"))
    assert names == [plain] * 3 and "n2" in plain
