"""The `structure` family: names, the root, joints' links, loops, orphans — each reported at the
line that is wrong, and quiet on a well-formed tree."""

from __future__ import annotations

import itertools

from urdftool.check import CheckOptions, check_file


def fired(path, rule_id):
    return [d for d in check_file(path, CheckOptions(select=[rule_id])).diagnostics
            if d.rule == rule_id]


def structure(path):
    return check_file(path, CheckOptions(select=["structure"])).diagnostics


def joint(name, parent, child, kind="fixed"):
    return (f'  <joint name="{name}" type="{kind}">\n    <parent link="{parent}"/>\n'
            f'    <child link="{child}"/>\n  </joint>')


def robot(*lines, attrs='name="r"'):
    """Line 1 is the XML declaration, line 2 <robot>, the given lines follow from line 3."""
    return '<?xml version="1.0"?>\n' + f"<robot {attrs}>\n" + "\n".join(lines) + "\n</robot>\n"


TREE = robot('  <link name="base"/>', '  <link name="arm"/>', '  <link name="hand"/>',
             joint("shoulder", "base", "arm", "continuous"), joint("wrist", "arm", "hand"))


def test_a_tree_is_quiet(write):
    assert structure(write(TREE)) == []


def test_robot_name(write):
    [d] = fired(write(robot('  <link name="a"/>', attrs='version="1.0"')), "structure.no-name")
    assert (d.severity, d.line) == ("error", 2)
    [d] = fired(write(robot('  <link name="a"/>', attrs='name=""'), "empty.urdf"),
                "structure.no-name")
    assert d.severity == "warning"


def test_no_links(write):
    [d] = fired(write(robot('  <material name="m"><color rgba="1 1 1 1"/></material>')),
                "structure.no-links")
    assert d.line == 2


def test_duplicate_link_names_the_first_definition(write):
    path = write(robot('  <link name="base"/>', '  <link name="arm"/>', '  <link name="arm"/>',
                       joint("j", "base", "arm")))
    [d] = fired(path, "structure.duplicate-link")
    assert d.line == 5 and "line 4" in d.message


def test_duplicate_joint(write):
    path = write(robot('  <link name="a"/>', '  <link name="b"/>', '  <link name="c"/>',
                       joint("j", "a", "b"), joint("j", "a", "c")))
    [d] = fired(path, "structure.duplicate-joint")
    assert d.line == 10 and "line 6" in d.message


def test_missing_link_points_at_the_parent_element_with_did_you_mean(write):
    path = write(robot('  <link name="base_link"/>', '  <link name="arm"/>',
                       joint("j", "base_lnk", "arm")))
    [d] = fired(path, "structure.missing-link")
    assert d.line == 6 and "did you mean 'base_link'" in d.message
    # one finding per cause: the link cut off by the typo is counted there, not an orphan too
    assert fired(path, "structure.orphan-link") == []
    assert "the 1 link(s) below it ('arm') are cut off" in d.message


def test_one_typo_above_a_chain_is_one_finding(write):
    """issue 22.3: one typo'd <parent link> above six links gave 1 missing-link + 6 orphans."""
    chain = ["base", "torso", "a1", "a2", "a3", "a4", "hand"]
    joints = [joint("mount", "bas", "torso")] + [
        joint(f"j{i}", parent, child)
        for i, (parent, child) in enumerate(itertools.pairwise(chain[1:]))]
    path = write(robot(*(f'  <link name="{n}"/>' for n in chain), *joints))
    found = [(d.rule, d.line) for d in structure(path)]
    assert found == [("structure.missing-link", 11)]
    [d] = structure(path)
    assert "the 6 link(s) below it ('a1', 'a2', 'a3' and 3 more)" in d.message
    # a link cut off for another reason is still an orphan
    lone = write(robot(*(f'  <link name="{n}"/>' for n in chain), *joints,
                       '  <link name="spare"/>'), "lone.urdf")
    assert [d.rule for d in structure(lone)] == ["structure.missing-link", "structure.orphan-link"]


def test_self_joint(write):
    path = write(robot('  <link name="base"/>', '  <link name="arm"/>', joint("j0", "base", "arm"),
                       joint("j", "arm", "arm")))
    [d] = fired(path, "structure.self-joint")
    assert d.line == 11


def test_two_parents(write):
    path = write(robot('  <link name="base"/>', '  <link name="a"/>', '  <link name="b"/>',
                       joint("j1", "base", "a"), joint("j2", "base", "b"), joint("j3", "a", "b")))
    [d] = fired(path, "structure.two-parents")
    assert d.line == 16 and "'j2'" in d.message and "'j3'" in d.message


def test_loop_is_named_link_by_link(write):
    path = write(robot('  <link name="base"/>', '  <link name="a"/>', '  <link name="b"/>',
                       '  <link name="c"/>', joint("j0", "base", "a"), joint("j1", "a", "b"),
                       joint("j2", "b", "c"), joint("j3", "c", "a")))
    [d] = fired(path, "structure.loop")
    assert "a -> b -> c -> a" in d.message and "'j1', 'j2', 'j3'" in d.message
    assert d.line == 19  # the joint that closes the loop
    assert fired(path, "structure.orphan-link") == []  # the loop says it already


def test_loop_without_root(write):
    path = write(robot('  <link name="a"/>', '  <link name="b"/>', joint("j1", "a", "b"),
                       joint("j2", "b", "a")))
    [d] = fired(path, "structure.loop")
    assert "a -> b -> a" in d.message


def test_multiple_roots_lists_the_trees(write):
    path = write(robot('  <link name="base"/>', '  <link name="arm"/>', '  <link name="cart"/>',
                       '  <link name="wheel"/>', joint("j1", "base", "arm"),
                       joint("j2", "cart", "wheel", "continuous")))
    [d] = fired(path, "structure.multiple-roots")
    assert "'base' (2 links)" in d.message and "'cart' (2 links)" in d.message
    assert d.line == 5


def test_links_and_no_joints_are_multiple_roots(write):
    path = write(robot('  <link name="a"/>', '  <link name="b"/>'))
    [d] = fired(path, "structure.multiple-roots")
    assert "'a', 'b'" in d.message
    assert fired(path, "structure.orphan-link") == []


def test_single_link_robot_is_fine(write):
    assert structure(write(robot('  <link name="only"/>'))) == []


def test_orphan_link(write):
    path = write(robot('  <link name="base"/>', '  <link name="arm"/>', '  <link name="camera"/>',
                       joint("j", "base", "arm")))
    [d] = fired(path, "structure.orphan-link")
    assert d.line == 5 and "'camera'" in d.message
    assert fired(path, "structure.multiple-roots") == []


def test_a_duplicated_link_is_one_root(write):
    path = write(robot('  <link name="base"/>', '  <link name="base"/>', '  <link name="arm"/>',
                       joint("j", "base", "arm")))
    assert [d.rule for d in structure(path)] == ["structure.duplicate-link"]


def test_sdf_inputs_are_left_to_the_sdf_family(write):
    path = write('<?xml version="1.0"?>\n<sdf version="1.7">\n  <model name="m">\n'
                 '    <link name="a"/>\n    <link name="a"/>\n    <link name="b"/>\n'
                 '    <joint name="j" type="fixed"><parent>a</parent><child>b</child></joint>\n'
                 '  </model>\n</sdf>\n', "model.sdf")
    report = check_file(path, CheckOptions(select=["structure", "sdf"]))
    assert "sdf.duplicate-name" in {d.rule for d in report.diagnostics}
    assert not [d for d in report.diagnostics if d.rule.startswith("structure.")]
