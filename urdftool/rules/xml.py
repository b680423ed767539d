"""Rules of the `xml` family: the file is not well-formed XML. These findings are made while
loading (``urdftool.xmlrepair``), where every recognised breakage is repaired in memory so that
the rest of the file stays checkable; the rules here report them. ``urdftool check --fix -o OUT``
writes the repaired text (same line numbers as the original)."""

from __future__ import annotations

from urdftool.rules import source_rule

source_rule(
    "xml.syntax", "error", "the XML parser rejects the file here",
    doc="""The file is not well-formed XML, and the breakage is not one urdftool recognises and
    repairs (the other `xml.*` rules cover those). The message is the XML parser's own. Every
    robot tool will refuse the file, and what follows the error may be read wrongly, so other
    findings after this line are less reliable.""",
    bad='<robot name="r"><link name="a"/><![CDATA[ never closed </robot>',
    good='<robot name="r"><link name="a"/><![CDATA[ closed ]]></robot>',
)

source_rule(
    "xml.declaration", "warning", "the XML declaration is not `<?xml version=\"1.0\"?>` at the very start",
    doc="""Only XML 1.0 exists in practice, and the declaration must be the first thing in the
    file (not even a blank line before it). Strict parsers (lxml, Python's expat, so xacro)
    reject `<?xml version="0.0"?>` or a declaration after blank lines; the C++ robot tools
    (urdfdom, PyBullet) tolerate both, which is why 26 of PyBullet's own URDFs carry
    `version="0.0"`. urdftool reads on and warns.""",
    bad='<?xml version="0.0"?>\n<robot name="r"><link name="a"/></robot>',
    good='<?xml version="1.0"?>\n<robot name="r"><link name="a"/></robot>',
    fix="safe",
)

source_rule(
    "xml.no-root", "error", "the file has no XML element at all",
    doc="""An empty file, or one holding only comments or text, describes no robot. Usually a
    file that was truncated or written by a failed generator.""",
    bad='<!-- the robot goes here -->',
    good='<!-- the robot goes here -->\n<robot name="r"><link name="a"/></robot>',
)

source_rule(
    "xml.unclosed-tag", "error", "an element is never closed",
    doc="""An element's end tag is missing, so everything after it would be read as its
    content. The most common cause is an end tag that lost its `</`, as in
    `<material>Gazebo/Orange/material>`: the text `Gazebo/Orange/material>` becomes the
    material's content and the parser then complains about a later, innocent line. urdftool
    reports the element where it was opened and says where its end tag belongs: after its text,
    as `/>` for an element URDF defines as empty (`<origin ...>` that should be `<origin .../>`),
    before the first child it cannot hold (`<joint>` inside an unclosed `<link>`), or before the
    parent's end tag.""",
    bad=('<robot name="r"><link name="a"/>\n'
         '  <gazebo reference="a">\n    <material>Gazebo/Orange/material>\n  </gazebo>\n</robot>'),
    good=('<robot name="r"><link name="a"/>\n'
          '  <gazebo reference="a">\n    <material>Gazebo/Orange</material>\n  </gazebo>\n'
          '</robot>'),
    fix="safe",
)

source_rule(
    "xml.mismatched-tag", "error", "an end tag does not match the element it closes",
    doc="""An end tag names an element that is not open: a typo (`</ioint>` for `</joint>`),
    an end tag whose start tag is missing (`<box/></geometry>` without `<geometry>`), or a
    leftover end tag. urdftool renames the typo, puts back the missing start tag where the
    children it would hold begin, or drops the leftover, and reads on.""",
    bad='<robot name="r">\n  <link name="a"/>\n  <joint name="j" type="fixed">\n'
        '    <parent link="a"/><child link="b"/>\n  </ioint>\n  <link name="b"/>\n</robot>',
    good='<robot name="r">\n  <link name="a"/>\n  <joint name="j" type="fixed">\n'
         '    <parent link="a"/><child link="b"/>\n  </joint>\n  <link name="b"/>\n</robot>',
    fix="safe",
)

source_rule(
    "xml.missing-open-bracket", "error", "a tag lost its `<` and is read as text",
    doc="""A line such as `link name="link1">` is a tag that lost its `<`. XML reads it as
    text, so the element silently disappears (here a whole link, whose children then land in
    the wrong parent, and whose `</link>` closes nothing). urdftool recognises a line that reads
    as a tag of a known element without its `<` (or an end tag without `</`), restores the
    bracket and checks the element.""",
    bad=('<robot name="r">\n  <link name="a"/>\n  link name="b">\n    <visual><geometry>'
         '<box size="1 1 1"/></geometry></visual>\n  </link>\n</robot>'),
    good=('<robot name="r">\n  <link name="a"/>\n  <link name="b">\n    <visual><geometry>'
          '<box size="1 1 1"/></geometry></visual>\n  </link>\n</robot>'),
    fix="safe",
)

source_rule(
    "xml.missing-close-bracket", "error", "a tag lost its `>`",
    doc="""A start or end tag is not closed by `>` before the next tag begins (`<origin
    xyz="0 0 0"` followed by `<axis .../>`). The parser then reads the next tag as part of this
    one. urdftool ends the tag (with `/>` for elements URDF defines as empty).""",
    bad=('<robot name="r">\n  <link name="a"/><link name="b"/>\n'
         '  <joint name="j" type="fixed">\n    <origin xyz="0 0 1"\n'
         '    <parent link="a"/><child link="b"/>\n  </joint>\n</robot>'),
    good=('<robot name="r">\n  <link name="a"/><link name="b"/>\n'
          '  <joint name="j" type="fixed">\n    <origin xyz="0 0 1"/>\n'
          '    <parent link="a"/><child link="b"/>\n  </joint>\n</robot>'),
    fix="safe",
)

source_rule(
    "xml.stray-text", "error", "text that is a broken tag, or text outside the root element",
    doc="""Text where a tag belongs: a line inside an element that reads like a tag whose name
    was damaged along with its `<` (`imit effort="10" velocity="1"/>` inside a `<joint>` is a
    `<limit>` that lost `<l`: XML accepts it as text and the joint silently has no limit), or
    text before the root element (a pasted Markdown fence, a title). urdftool names the element
    it most likely was, from the elements allowed there and the attributes the text carries.""",
    bad=('<robot name="r">\n  <link name="a"/><link name="b"/>\n'
         '  <joint name="j" type="revolute">\n    <parent link="a"/><child link="b"/>\n'
         '    imit effort="10" velocity="1" lower="-1" upper="1"/>\n  </joint>\n</robot>'),
    good=('<robot name="r">\n  <link name="a"/><link name="b"/>\n'
          '  <joint name="j" type="revolute">\n    <parent link="a"/><child link="b"/>\n'
          '    <limit effort="10" velocity="1" lower="-1" upper="1"/>\n  </joint>\n</robot>'),
    fix="safe",
)

source_rule(
    "xml.content-after-root", "error", "something follows the root element's end tag",
    doc="""An XML file holds one root element. Text or elements after `</robot>` are rejected
    by strict parsers and ignored by others. Often an early `</robot>` (from a pasted block)
    cuts the robot short: the links and joints after it are lost. When what follows are
    elements the root can hold, urdftool reads them as part of the robot.""",
    bad=('<robot name="r">\n  <link name="a"/>\n</robot>\n  <link name="b"/>\n</robot>'),
    good=('<robot name="r">\n  <link name="a"/>\n  <link name="b"/>\n</robot>'),
    fix="unsafe",
)

source_rule(
    "xml.bad-entity", "error", "a bare `&` or `<`, or an entity XML does not define",
    doc="""In XML text and attribute values `&` starts an entity and `<` starts a tag. A
    literal `&` must be written `&amp;` and `<` as `&lt;`; HTML entities such as `&nbsp;` do
    not exist in XML (write `&#160;` or the character). Text copied from web pages often
    carries them.""",
    bad='<robot name="r"><link name="a"><visual><origin xyz="0&nbsp0&nbsp0"/>'
        '<geometry><box size="1 1 1"/></geometry></visual></link></robot>',
    good='<robot name="r"><link name="a"><visual><origin xyz="0 0 0"/>'
         '<geometry><box size="1 1 1"/></geometry></visual></link></robot>',
    fix="safe",
)

source_rule(
    "xml.bad-attribute", "error", "an attribute without quotes, without a value, or repeated",
    doc="""Attribute values must be quoted (`size="1 1 1"`), every attribute needs `=` and a
    value, attributes are separated by spaces, and a name appears once per tag. Strict parsers
    stop at the first such error; urdftool quotes the value, drops the repeated or empty one
    (keeping the first), and reads on.""",
    bad='<robot name="r"><link name="a"><visual><geometry><box size=1/></geometry>'
        '</visual></link></robot>',
    good='<robot name="r"><link name="a"><visual><geometry><box size="1 1 1"/></geometry>'
         '</visual></link></robot>',
    fix="safe",
)

source_rule(
    "xml.bad-tag", "error", "a tag with something inside it that does not belong there",
    doc="""Characters inside a tag that are neither attributes nor its end: a space after `<`,
    a stray `/` or `,`, attributes on an end tag, `</` without a name. urdftool removes them.""",
    bad='<robot name="r"><link name="a", type="x"/></robot>',
    good='<robot name="r"><link name="a" type="x"/></robot>',
    fix="unsafe",
)

source_rule(
    "xml.bad-comment", "error", "a comment with `--` inside, or never closed",
    doc="""XML forbids `--` inside a comment (so `<!-- ---- -->` separators break strict
    parsers) and a comment runs until `-->`: an unterminated one swallows the file.""",
    bad='<robot name="r">\n  <!-- ---- links ---- -->\n  <link name="a"/>\n</robot>',
    good='<robot name="r">\n  <!-- ==== links ==== -->\n  <link name="a"/>\n</robot>',
    fix="safe",
)

source_rule(
    "xml.bad-character", "error", "a character XML forbids (control characters, NUL)",
    doc="""XML 1.0 allows no control characters except tab, newline and carriage return. They
    come from copying out of PDFs and word processors (form feeds) or from binary garbage.
    NUL bytes at the very end of a file are a warning only: C-based tools stop reading there.
    urdftool reads them as spaces.""",
    bad='<robot name="r">\x0c<link name="a"/></robot>',
    good='<robot name="r"> <link name="a"/></robot>',
    fix="safe",
)

source_rule(
    "xml.undefined-prefix", "warning", "a namespace prefix is used but never declared",
    doc="""`<xacro:property>` needs `xmlns:xacro="http://www.ros.org/wiki/xacro"` on the root
    element. xacro itself reads the file without namespace processing and accepts it, but
    namespace-aware tools (editors, schema validators, lxml) reject the file. urdftool reads on
    as if the prefix were declared.""",
    bad='<robot name="r">\n  <xacro:property name="w" value="1"/>\n  <link name="a"/>\n</robot>',
    good=('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
          '  <xacro:property name="w" value="1"/>\n  <link name="a"/>\n</robot>'),
    fix="unsafe",
)
