"""Rules of the `xml` family: the file is not well-formed XML. These findings are made while
loading (``urdftool.xmlrepair``), where every recognised breakage is repaired in memory so that
the rest of the file stays checkable; the rules here report them."""

from __future__ import annotations

from urdftool.rules import source_rule

source_rule(
    "xml.syntax", "error", "the XML parser rejects the file here",
    doc="""The file is not well-formed XML, and the breakage is not one urdftool recognises and
    repairs. Every robot tool will refuse the file; what follows the error may be read wrongly.""",
    bad='<robot name="r"><link name="a"></robot>',
    good='<robot name="r"><link name="a"/></robot>',
)

source_rule(
    "xml.declaration", "warning", "the XML declaration names a version other than 1.0",
    doc="""Only XML 1.0 exists in practice. Strict parsers reject `<?xml version="0.0"?>`, which
    several published URDFs carry; robot tools tolerate it, so urdftool reads on.""",
    bad='<?xml version="0.0"?>\n<robot name="r"><link name="a"/></robot>',
    good='<?xml version="1.0"?>\n<robot name="r"><link name="a"/></robot>',
)
