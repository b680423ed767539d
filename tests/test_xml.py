"""The `xml` family: every recognised breakage is reported at the line and column where the user
must act, repaired in memory (same line count, strictly well-formed afterwards), and the fixed
file gives no finding."""

from __future__ import annotations

import pytest
from lxml import etree

from urdftool import xmlrepair
from urdftool.check import CheckOptions, check_file
from urdftool.xmlrepair import repair, secure_parser

ROBOT = '<robot name="r">\n{}\n</robot>\n'  # the body starts on line 2


def document(body: str) -> str:
    return body if body.startswith(("<robot", "<?xml")) else ROBOT.format(body)


def strict_ok(text: str) -> bool:
    try:
        etree.fromstring(text.encode(), secure_parser())
        return True
    except etree.XMLSyntaxError:
        return False


def findings(text: str):
    fixed, problems = repair(text, "t.urdf")
    return fixed, [(rule, f.loc.line, f.loc.column) for rule, f in problems], problems


# (case id, broken body, fixed body, expected rule, line, column) — bodies sit in ROBOT
CASES = [
    ("lost-end-bracket", '<gazebo reference="a">\n  <material>Gazebo/Orange/material>\n</gazebo>',
     '<gazebo reference="a">\n  <material>Gazebo/Orange</material>\n</gazebo>',
     "xml.unclosed-tag", 3, 3),
    ("lost-end-tag-text-only", ('<transmission name="t">\n <joint name="j">\n'
     '  <hardwareInterface>hardware_interface/EffortJointInterface\n </joint>\n</transmission>'),
     ('<transmission name="t">\n <joint name="j">\n'
     '  <hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface>\n'
     ' </joint>\n</transmission>'), "xml.unclosed-tag", 4, 3),
    ("lost-end-without-gt", ('<transmission name="t">\n <joint name="j">\n'
     '  <hardwareInterface>hw/EffortJointInterface/hardwareInterface\n </joint>\n</transmission>'),
     ('<transmission name="t">\n <joint name="j">\n'
     '  <hardwareInterface>hw/EffortJointInterface</hardwareInterface>\n </joint>\n'
     '</transmission>'), "xml.unclosed-tag", 4, 3),
    ("empty-element-not-self-closed", ('<joint name="j" type="fixed">\n  <origin xyz="0 0 1">\n'
     '  <parent link="a"/><child link="b"/>\n</joint>'),
     ('<joint name="j" type="fixed">\n  <origin xyz="0 0 1"/>\n'
     '  <parent link="a"/><child link="b"/>\n</joint>'), "xml.unclosed-tag", 3, 3),
    ("link-never-closed", ('<link name="a">\n  <visual><geometry><box size="1 1 1"/></geometry>'
     '</visual>\n<joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>'),
     ('<link name="a">\n  <visual><geometry><box size="1 1 1"/></geometry></visual>\n</link>'
     '<joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>'),
     "xml.unclosed-tag", 2, 1),
    ("end-tag-typo", '<joint name="j" type="fixed">\n  <parent link="a"/><child link="b"/>\n</ioint>',
     '<joint name="j" type="fixed">\n  <parent link="a"/><child link="b"/>\n</joint>',
     "xml.mismatched-tag", 4, 1),
    ("end-tag-closes-nothing", '<link name="a"/>\n</visual>\n<link name="b"/>',
     '<link name="a"/>\n\n<link name="b"/>', "xml.mismatched-tag", 3, 1),
    ("start-tag-missing", ('<link name="a">\n  <visual>\n    <box size="1 1 1"/>\n  </geometry>\n'
     '  </visual>\n</link>'),
     ('<link name="a">\n  <visual>\n    <geometry><box size="1 1 1"/>\n  </geometry>\n'
     '  </visual>\n</link>'), "xml.mismatched-tag", 4, 5),
    ("tag-lost-lt", '<link name="a"/>\n  link name="b">\n    <visual/>\n  </link>',
     '<link name="a"/>\n  <link name="b">\n    <visual/>\n  </link>',
     "xml.missing-open-bracket", 3, 3),
    ("end-tag-lost-lt", '<link name="a">\n  <visual/>\n  /link>',
     '<link name="a">\n  <visual/>\n  </link>', "xml.missing-open-bracket", 4, 3),
    ("start-tag-lost-gt", ('<joint name="j" type="fixed"\n  <parent link="a"/><child link="b"/>\n'
     '</joint>'), '<joint name="j" type="fixed">\n  <parent link="a"/><child link="b"/>\n</joint>',
     "xml.missing-close-bracket", 2, 1),
    ("end-tag-lost-gt", '<link name="a">\n</link\n<link name="b"/>',
     '<link name="a">\n</link>\n<link name="b"/>', "xml.missing-close-bracket", 3, 1),
    ("limit-lost-lt-and-l", ('<joint name="j" type="revolute">\n  <parent link="a"/><child link="b"/>'
     '\n  imit effort="1" velocity="1" lower="0" upper="1"/>\n</joint>'),
     ('<joint name="j" type="revolute">\n  <parent link="a"/><child link="b"/>'
     '\n  <limit effort="1" velocity="1" lower="0" upper="1"/>\n</joint>'), "xml.stray-text", 4, 3),
    ("limit-name-garbled", ('<joint name="j" type="revolute">\n  <parent link="a"/>'
     '<child link="b"/>\n  ! velocity="1" effort="1" lower="0" upper="1" />\n</joint>'),
     ('<joint name="j" type="revolute">\n  <parent link="a"/><child link="b"/>\n'
     '  <limit velocity="1" effort="1" lower="0" upper="1" />\n</joint>'), "xml.stray-text", 4, 3),
    ("text-after-root", '<robot name="r">\n<link name="a"/>\n</robot>\n```\n',
     '<robot name="r">\n<link name="a"/>\n</robot>\n\n', "xml.content-after-root", 4, 1),
    ("early-root-end", '<link name="a"/>\n</robot>\n<link name="b"/>',
     '<link name="a"/>\n\n<link name="b"/>', "xml.content-after-root", 3, 1),
    ("bare-ampersand", '<link name="a&b"/>', '<link name="a&amp;b"/>', "xml.bad-entity", 2, 14),
    ("nbsp", '<link name="a"><visual><origin xyz="0&nbsp0&nbsp0"/></visual></link>',
     '<link name="a"><visual><origin xyz="0 0 0"/></visual></link>', "xml.bad-entity", 2, 38),
    ("undefined-entity", '<link name="a">&copy;</link>', '<link name="a">(c)</link>',
     "xml.bad-entity", 2, 16),
    ("lt-in-text", '<link name="a"> 1 < 2 </link>', '<link name="a"> 1 &lt; 2 </link>',
     "xml.bad-entity", 2, 19),
    ("unquoted-value", '<link name=a/>', '<link name="a"/>', "xml.bad-attribute", 2, 12),
    ("duplicate-attribute", '<link name="a" name="b"/>', '<link name="a"/>',
     "xml.bad-attribute", 2, 16),
    ("attribute-without-value", '<joint name="j" revolute/>', '<joint name="j"/>',
     "xml.bad-attribute", 2, 17),
    ("no-space-between-attributes", '<joint name="j"type="fixed"/>',
     '<joint name="j" type="fixed"/>', "xml.bad-attribute", 2, 16),
    ("missing-equals", '<link name "a"/>', '<link name="a"/>', "xml.bad-attribute", 2, 7),
    ("unterminated-quote", '<link name="a>\n  <visual/>\n</link>',
     '<link name="a">\n  <visual/>\n</link>', "xml.bad-attribute", 2, 12),
    ("space-after-lt", '< link name="a"/>', '<link name="a"/>', "xml.bad-tag", 2, 1),
    ("comma-in-tag", '<link name="a", type="b"/>', '<link name="a" type="b"/>', "xml.bad-tag", 2, 15),
    ("double-hyphen-comment", '<!-- ---- links ---- -->\n<link name="a"/>',
     '<!-- ==== links ==== -->\n<link name="a"/>', "xml.bad-comment", 2, 6),
    ("unterminated-comment", '<!-- links ->\n<link name="a"/>', '<!-- links -->\n<link name="a"/>',
     "xml.bad-comment", 2, 1),
    ("comment-lost-gt", '<!-- links --\n<link name="a"/>\n<!-- joints -->',
     '<!-- links -->\n<link name="a"/>\n<!-- joints -->', "xml.bad-comment", 2, 1),
    ("comment-one-dash-opener", '<!- links -->\n<link name="a"/>', '<!-- links -->\n<link name="a"/>',
     "xml.bad-comment", 2, 1),
    ("damaged-declaration", '<?xml vers"on="1.0"?>\n<robot name="r"><link name="a"/></robot>\n',
     '<?xml version="1.0"?>\n<robot name="r"><link name="a"/></robot>\n', "xml.declaration", 1, 1),
    ("control-character", '<link name="a">\x0c</link>', '<link name="a"> </link>',
     "xml.bad-character", 2, 16),
    ("undeclared-xacro", '<xacro:property name="w" value="1"/>', '<link name="a"/>',
     "xml.undefined-prefix", 2, 1),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_breakage_is_found_where_to_act_and_repaired(case):
    _, broken, _good, rule, line, column = case
    text = document(broken)
    fixed, found, _ = findings(text)
    assert (rule, line, column) in found, found
    assert fixed.count("\n") == text.count("\n"), "a repair moved a line"
    assert strict_ok(fixed), fixed
    assert not any(r == "xml.syntax" for r, _, _ in found), found


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_fixed_version_gives_nothing(case):
    good = document(case[2])
    fixed, found, _ = findings(good)
    assert found == [] and fixed == good


@pytest.mark.parametrize("case", [c for c in CASES if c[3] != "xml.undefined-prefix"],
                         ids=[c[0] for c in CASES if c[3] != "xml.undefined-prefix"])
def test_repair_is_what_the_user_meant(case):
    """The repaired tree is the corrected file's tree (same elements, attributes, nesting)."""
    fixed, _, _ = findings(document(case[1]))

    def shape(text):
        root = etree.fromstring(text.encode(), secure_parser())
        return [(root.getroottree().getpath(e), sorted(e.attrib.items()))
                for e in root.iter() if isinstance(e.tag, str)]

    if case[0] in ("undefined-entity", "lt-in-text", "bare-ampersand", "control-character"):
        return  # text content differs by design (the literal characters are kept)
    assert shape(fixed) == shape(document(case[2]))


def test_declaration_version_zero_is_a_warning_and_the_rest_is_checked(write):
    path = write('<?xml version="0.0"?>\n<robot name="r">\n  <link name="a"/>\n  <link name="b"/>\n'
                 '  <joint name="j" type="revolute">\n    <parent link="a"/><child link="b"/>\n'
                 '    <limit lower="1" upper="-1" effort="1" velocity="1"/>\n  </joint>\n</robot>\n')
    report = check_file(path)
    by_rule = {(d.rule, d.severity, d.line) for d in report.diagnostics}
    assert ("xml.declaration", "warning", 1) in by_rule
    assert not [d for d in report.diagnostics if d.rule.startswith("xml.") and d.severity == "error"]
    assert ("joint.lower-above-upper", "error", 7) in by_rule  # the rest was checked


def test_declaration_after_blank_lines_is_a_warning_and_moved_to_the_start():
    text = '\n\n<?xml version="1.0"?>\n<robot name="r"><link name="a"/></robot>\n'
    fixed, found, problems = findings(text)
    assert found == [("xml.declaration", 3, 1)]
    assert problems[0][1].severity is None  # the rule's severity: warning
    assert fixed.startswith('<?xml version="1.0"?>') and fixed.count("\n") == text.count("\n")
    assert strict_ok(fixed)


@pytest.mark.parametrize("text", ["", "   \n\n", "<!-- only a comment -->\n", "just text\n"])
def test_no_root(text):
    _, found, _ = findings(text)
    assert [r for r, _, _ in found] == ["xml.no-root"]


def test_leftover_parser_error_is_reported_with_its_position():
    text = '<robot name="r">\n  <link name="a"/>\n  <![CDATA[ never closed\n</robot>\n'
    _, found, problems = findings(text)
    assert [r for r, _, _ in found] == ["xml.syntax"]
    assert "CData" in problems[0][1].message and found[0][1] == 5


def test_every_breakage_reported_in_one_pass():
    text = ROBOT.format(
        '<gazebo reference="a">\n  <material>Gazebo/Orange/material>\n</gazebo>\n'  # 3
        '<link name="a">\n  <visual><origin xyz="0 0 0" rpy="0 0 0" rpy="1 1 1"/>\n'  # 6
        '    <geometry><box size=1/></geometry>\n  </visual>\n</link>\n'  # 7
        '<joint name="j" type="revolute">\n  <parent link="a"/><child link="b"/>\n'
        '  imit effort="1" velocity="1" lower="1" upper="0"/>\n</ioint>\n'  # 12, 13
        '  link name="b">\n  <collision/>\n</link>\n'  # 14
        '<transmission name="t"><joint name="j">\n'
        '  <hardwareInterface>EffortJointInterface/hardwareInterface>\n'  # 18
        '</joint></transmission>\n<material name="m"><color rgba="1 0 0 1"/></material')  # 20
    fixed, found, _ = findings(text)
    expected = {("xml.unclosed-tag", 3, 3), ("xml.bad-attribute", 6, 43),
                ("xml.bad-attribute", 7, 25), ("xml.stray-text", 12, 3),
                ("xml.mismatched-tag", 13, 1), ("xml.missing-open-bracket", 14, 3),
                ("xml.unclosed-tag", 18, 3), ("xml.missing-close-bracket", 20, 43)}
    assert set(found) == expected, sorted(set(found) ^ expected)
    assert not [f for f in found if f[0] == "xml.syntax"]
    assert strict_ok(fixed) and fixed.count("\n") == text.count("\n")
    root = etree.fromstring(fixed.encode(), secure_parser())
    assert [e.tag for e in root] == ["gazebo", "link", "joint", "link", "transmission", "material"]
    assert root.find("joint/limit").get("upper") == "0"


def test_columns_are_the_original_ones_after_several_repairs_on_a_line():
    text = ROBOT.format('<box size=1 a=2 b=3/>')
    _, found, _ = findings(text)
    assert [(r, c) for r, _, c in found] == [("xml.bad-attribute", 11), ("xml.bad-attribute", 15),
                                              ("xml.bad-attribute", 19)]


def test_leftover_column_maps_back_across_earlier_repairs():
    # the unquoted value is repaired (two quotes inserted before the CDATA on the same line)
    text = '<robot name="r">\n<link name=a/><![CDATA[ x\n</robot>\n'
    _, found, problems = findings(text)
    assert ("xml.bad-attribute", 2, 12) in found
    syntax = [p for r, p in problems if r == "xml.syntax"]
    assert syntax and syntax[0].loc.line == 4  # lxml complains at the end


def test_well_formed_text_that_is_a_broken_tag_is_still_found():
    """`imit effort=...` is well-formed XML (text inside <joint>): the fast path must not miss it."""
    text = ROBOT.format('<link name="a"/><link name="b"/>\n<joint name="j" type="revolute">\n'
                        '  <parent link="a"/><child link="b"/>\n'
                        '  imit effort="1" velocity="1" lower="0" upper="1"/>\n</joint>')
    assert strict_ok(text)
    fixed, found, _ = findings(text)
    assert found == [("xml.stray-text", 5, 3)]
    assert etree.fromstring(fixed.encode(), secure_parser()).find("joint/limit") is not None


def test_multiline_tags_and_comments_are_not_stray_text():
    text = ROBOT.format('<joint name="j"\n       type="fixed">\n  <parent link="a"/>\n'
                        '  <child link="b"/>\n</joint>\n<!--\n  link name="c">\n-->\n'
                        '<link\n  name="a" />')
    assert strict_ok(text)
    assert findings(text)[1] == []


def test_unclosed_elements_at_end_of_file():
    text = '<robot name="r">\n  <link name="a">\n    <visual/>\n'
    fixed, found, problems = findings(text)
    assert ("xml.unclosed-tag", 1, 1) in found and ("xml.unclosed-tag", 2, 3) in found
    hints = {f.loc.line: f.hint for _, f in problems}
    assert hints[1] == "write </robot> at the end of the file"
    assert strict_ok(fixed)


def test_element_xpath_is_given():
    text = ROBOT.format('<gazebo reference="a">\n  <material>Gazebo/Orange/material>\n</gazebo>')
    _, _, problems = findings(text)
    assert problems[0][1].loc.element == "/robot/gazebo/material"


def test_findings_reach_the_check_report(write):
    path = write(ROBOT.format('<link name="a">\n  <visual/>\n  /link>'))
    report = check_file(path, CheckOptions(select=["xml"]))
    assert [(d.rule, d.line, d.column, d.severity) for d in report.diagnostics] == [
        ("xml.missing-open-bracket", 4, 3, "error")]


def test_columns_on_line_one_survive_the_declaration_rewrite():
    text = '<?xml vers"on="1.0" ?> <robot name="r"><link name=b/></robot>\n'
    fixed, found, _ = findings(text)
    assert ("xml.declaration", 1, 1) in found
    assert ("xml.bad-attribute", 1, text.index("name=b") + len("name=") + 1) in found
    assert strict_ok(fixed)


def test_truncated_file_is_closed_in_the_right_order():
    text = '<robot name="r">\n  <link name="a">\n    <visual name="v'
    fixed, found, _ = findings(text)
    assert {r for r, _, _ in found} == {"xml.bad-attribute", "xml.missing-close-bracket",
                                        "xml.unclosed-tag"}
    assert fixed.endswith('<visual name="v"></visual></link></robot>')
    assert strict_ok(fixed)


def test_other_processing_instructions_are_not_declarations():
    text = '<?xml-stylesheet href="robot.xsl"?>\n<robot name="r"><link name="a"/></robot>\n'
    assert findings(text)[1] == []


@pytest.mark.parametrize("text", [ROBOT.format('<link name="a"/>'),
                                  ROBOT.format('<link name="a">\n  <visual/>\n  /link>'),
                                  '<robot name="r"><![CDATA[ x </robot>', ""])
def test_repair_and_parse_returns_the_tree_of_the_repaired_text(text):
    fixed, problems, root = xmlrepair.repair_and_parse(text, "t.urdf")
    assert (fixed, problems) == repair(text, "t.urdf")
    if strict_ok(fixed):
        assert etree.tostring(root) == etree.tostring(etree.fromstring(fixed.encode()))
    else:
        assert root is None
