"""The minidom copies behind the expansion: ``_copy_node`` makes what minidom's own
``cloneNode(deep=True)`` makes, and a file parsed once is copied for every later expansion
(``_PARSED``) with the same findings as the first time."""

from __future__ import annotations

import xml.dom.minidom

from urdftool import xacro_expand
from urdftool.loader import load
from urdftool.source import LoadOptions

DOCUMENT = """<?xml version="1.0"?>
<!-- before -->
<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro" xmlns:g="urn:g">
  <xacro:macro name="m" params="p"><link name="${p}" g:kind="x"/><![CDATA[a < b]]></xacro:macro>
  text &amp; more<?pi data?>
  <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>
</robot>
<!-- after -->
"""


def _shape(node) -> tuple:
    """Everything a copy must keep, recursively (independent of how it was made)."""
    attrs = None
    if node.attributes is not None:
        attrs = sorted((a.name, a.value, a.namespaceURI, a.localName, a.prefix,
                        a.childNodes[0].data) for a in node.attributes.values())
    return (node.nodeType, node.nodeName, node.nodeValue, node.namespaceURI,
            node.localName, attrs, tuple(_shape(c) for c in node.childNodes))


def test_copy_makes_what_clone_node_makes():
    document = xml.dom.minidom.parseString(DOCUMENT)
    root = document.documentElement
    ours = xacro_expand._copy_node(root, document)
    theirs = root.cloneNode(deep=True)
    assert _shape(ours) == _shape(theirs) and ours.toxml() == theirs.toxml()
    # links: parents, siblings, owners, attribute owners, lookups by namespace
    for node in [ours, *ours.getElementsByTagName("*")]:
        for index, child in enumerate(node.childNodes):
            assert child.parentNode is node and child.ownerDocument is document
            assert child.previousSibling is (node.childNodes[index - 1] if index else None)
        for attr in node.attributes.values():
            assert attr.ownerElement is node
    link = ours.getElementsByTagName("link")[0]
    assert link.getAttributeNS("urn:g", "kind") == "x" and link.getAttribute("name") == "${p}"
    # a copy is its own: changing it leaves the original as it was
    link.setAttribute("name", "changed")
    link.parentNode.removeChild(link)
    assert root.getElementsByTagName("link")[0].getAttribute("name") == "${p}"
    copied = xacro_expand._copy_document(document)
    assert copied.toxml() == document.toxml() and copied.documentElement is not root


def test_a_file_parsed_once_gives_the_same_expansion_and_findings(tmp_path, monkeypatch):
    monkeypatch.setattr(xacro_expand, "_PARSED", {})
    monkeypatch.setattr(xacro_expand, "_SEEN", set())
    (tmp_path / "parts.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:macro name="part" params="n"><link name="${n}"/></xacro:macro>\n'
        '  <link name="${().__class__}"/>\n'
        '</robot>\n', encoding="utf-8")
    entry = tmp_path / "robot.urdf.xacro"
    entry.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:include filename="parts.xacro"/>\n'
        '  <xacro:part n="a"/><xacro:part n="b"/>\n'
        '  <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>\n'
        '</robot>\n', encoding="utf-8")
    from lxml import etree

    runs = []
    for _ in range(3):
        source = load(entry, LoadOptions())
        runs.append((etree.tostring(source.root),
                     sorted((rule, f.message, f.loc.path, f.loc.line)
                            for rule, f in source.problems)))
    assert len(xacro_expand._PARSED) == 2  # the entry and the include, kept once read again
    assert runs[0] == runs[1] == runs[2]
    assert b'<link name="a"' in runs[0][0] and b'<link name="b"' in runs[0][0]
    assert any(rule == "xacro.unsafe-expression" and line == 3
               for rule, _, _, line in runs[0][1]), runs[0][1]
