"""The `mimic` rules, on small robots and on the OpenManipulator seed: its gripper's joint8
follows id_7 with multiplier -0.01 and offset -0.0110133334, which drives it to
[0.004, 0.0204] while its limits are [-0.033, 0]; joint9 follows joint8 (a chain)."""

from __future__ import annotations

from pathlib import Path

import pytest

from urdftool.check import CheckOptions, check_file

ROOT = Path(__file__).resolve().parent.parent
OPEN_MANIPULATOR = ROOT / "robots" / "open_manipulator"
# the published xacro includes four files the seed did not contain; the corrected package has
# them, so the published robot is checked with its includes resolved there
PACKAGE = f"open_manipulator_support_description={OPEN_MANIPULATOR / 'corrected'}"


def diagnostics(path, select="mimic", packages=None):
    from urdftool.source import LoadOptions

    options = CheckOptions(LoadOptions(packages or {}), select=[select])
    return check_file(path, options).diagnostics


def robot(*joints: tuple[str, str, str, str]) -> str:
    """Joints (name, type, limit attributes, extra XML) from l0 to their own link, one per line
    starting at line 3."""
    links = "".join(f'<link name="l{i}"/>' for i in range(len(joints) + 1))
    lines = ['<robot name="r">', f"  {links}"]
    for i, (name, joint_type, limit, extra) in enumerate(joints):
        limit_xml = f'<limit {limit} effort="1" velocity="1"/>' if limit else ""
        lines.append(f'  <joint name="{name}" type="{joint_type}"><parent link="l0"/>'
                     f'<child link="l{i + 1}"/>{limit_xml}{extra}</joint>')
    return "\n".join(lines) + "\n</robot>\n"


LEADER = ("lead", "revolute", 'lower="0" upper="1"', "")


def test_follower_inside_its_limits_is_quiet(write):
    text = robot(LEADER, ("f", "revolute", 'lower="-2" upper="0"',
                          '<mimic joint="lead" multiplier="-2" offset="0"/>'))
    assert diagnostics(write(text)) == []


def test_unknown_leader_a_link_and_a_typo(write):
    text = robot(LEADER, ("a", "revolute", 'lower="0" upper="1"', '<mimic joint="l1"/>'),
                 ("b", "revolute", 'lower="0" upper="1"', '<mimic joint="laed"/>'),
                 ("c", "revolute", 'lower="0" upper="1"', "<mimic/>"))
    found = diagnostics(write(text))
    assert [(d.rule, d.line) for d in found] == [("mimic.unknown-joint", 4),
                                                 ("mimic.unknown-joint", 5),
                                                 ("mimic.unknown-joint", 6)]
    assert "a link, not a joint" in found[0].message and "'lead'" in found[0].hint
    assert "did you mean 'lead'" in found[1].hint
    assert "without a joint attribute" in found[2].message


def test_self_and_cycle_reports_the_whole_cycle_once(write):
    text = robot(("s", "revolute", 'lower="0" upper="1"', '<mimic joint="s"/>'),
                 ("a", "revolute", 'lower="0" upper="1"', '<mimic joint="b"/>'),
                 ("b", "revolute", 'lower="0" upper="1"', '<mimic joint="c"/>'),
                 ("c", "revolute", 'lower="0" upper="1"', '<mimic joint="a"/>'),
                 ("d", "revolute", 'lower="0" upper="1"', '<mimic joint="a"/>'))
    found = diagnostics(write(text))
    assert [d.rule for d in found] == ["mimic.self", "mimic.cycle"]
    assert "'a' -> 'b' -> 'c' -> 'a'" in found[1].message


def test_chained_mimic_hint_composes_multiplier_and_offset(write):
    # A = 2*B + 0.5, B = -3*C + 1  =>  A = -6*C + 2.5
    text = robot(("C", "revolute", 'lower="0" upper="1"', ""),
                 ("B", "revolute", 'lower="-5" upper="5"', ('<mimic joint="C" multiplier="-3" '
                                                            'offset="1"/>')),
                 ("A", "revolute", 'lower="-20" upper="20"', ('<mimic joint="B" multiplier="2" '
                                                             'offset="0.5"/>')))
    found = diagnostics(write(text))
    assert [(d.rule, d.severity) for d in found] == [("mimic.chained", "warning")]
    assert "'A' -> 'B' -> 'C'" in found[0].message
    assert found[0].hint == '<mimic joint="C" multiplier="-6" offset="2.5"/>'


def test_zero_multiplier_fixed_and_mixed_kinds(write):
    text = robot(LEADER,
                 ("z", "revolute", 'lower="0" upper="1"', ('<mimic joint="lead" multiplier="0" '
                                                          'offset="0.5"/>')),
                 ("fixed_lead", "fixed", "", ""),
                 ("g", "revolute", 'lower="0" upper="1"', '<mimic joint="fixed_lead"/>'),
                 ("h", "fixed", "", '<mimic joint="lead"/>'),
                 ("p", "prismatic", 'lower="0" upper="0.01"', ('<mimic joint="lead" '
                                                              'multiplier="0.01"/>')))
    found = [(d.rule, d.severity, d.line) for d in diagnostics(write(text))]
    assert found == [("mimic.zero-multiplier", "warning", 4),
                     ("mimic.fixed-joint", "warning", 6),
                     ("mimic.fixed-joint", "info", 7),
                     ("mimic.mixed-kinds", "info", 8)]


def test_out_of_range_reports_both_intervals_and_the_minimal_offset_fix(write):
    text = robot(("lead", "revolute", 'lower="-3.14159265" upper="-1.5"', ""),
                 ("f", "prismatic", 'lower="-0.033" upper="0"',
                  '<mimic joint="lead" multiplier="-0.01" offset="-0.0110133334"/>'))
    found = diagnostics(write(text))
    assert sorted((d.rule, d.severity) for d in found) == [("mimic.mixed-kinds", "info"),
                                                           ("mimic.out-of-range", "error")]
    violation = next(d for d in found if d.rule == "mimic.out-of-range")
    # independent arithmetic: the image of [-pi, -1.5] under -0.01*q - 0.0110133334
    lo, hi = -0.01 * -1.5 - 0.0110133334, -0.01 * -3.14159265 - 0.0110133334
    assert f"[{lo:.6g}, {hi:.6g}]" in violation.message
    assert "[-0.033, 0]" in violation.message and "entirely outside" in violation.message
    assert 'offset="-0.0314159265"' in violation.hint  # shifts the image up against 0


def test_image_touching_the_limits_is_inside(write):
    text = robot(LEADER, ("f", "revolute", 'lower="0.5" upper="1.5"',
                          '<mimic joint="lead" multiplier="1" offset="0.5"/>'))
    assert diagnostics(write(text)) == []


def test_continuous_follower_has_no_limits_to_violate(write):
    text = robot(LEADER, ("f", "continuous", 'lower="0" upper="0"',
                          '<mimic joint="lead" multiplier="100"/>'))
    assert diagnostics(write(text)) == []


@pytest.mark.parametrize("mimic", ['<mimic joint="lead" multiplier="abc" offset=""/>',
                                   '<mimic joint="" multiplier="1"/>',
                                   '<mimic joint="lead" multiplier="inf"/>'])
def test_bad_mimic_values_never_crash(write, mimic):
    text = robot(LEADER, ("f", "revolute", 'lower="x" upper="1"', mimic))
    report = check_file(write(text), CheckOptions())
    assert not [d for d in report.diagnostics if "internal error" in d.message]


def _published():
    path = OPEN_MANIPULATOR / "published" / "open_manipulator.urdf.xacro"
    return path


def test_open_manipulator_published_gripper_mimics():
    path = _published()
    found = diagnostics(path, packages={PACKAGE.split("=")[0]: PACKAGE.split("=")[1]})
    by_rule = {(d.rule, d.line): d for d in found}
    text = path.read_text().splitlines()
    joint8 = next(i for i, line in enumerate(text, 1) if 'mimic joint="id_7"' in line)
    joint9 = next(i for i, line in enumerate(text, 1) if 'mimic joint="joint8"' in line)
    violation = by_rule[("mimic.out-of-range", joint8)]
    assert "[0.00398667, 0.0204026]" in violation.message and "[-0.033, 0]" in violation.message
    # the README's fix: offset -0.01*pi puts the image at [-0.0164, 0]
    assert 'offset="-0.03141592654"' in violation.hint
    assert ("mimic.chained", joint9) in by_rule
    assert by_rule[("mimic.chained", joint9)].hint == \
        '<mimic joint="id_7" multiplier="-0.01" offset="-0.0110133334"/>'
    assert ("mimic.out-of-range", joint9) in by_rule  # [-0.033, 0] vs its limits [0, 0.033]


def test_open_manipulator_corrected_has_no_mimic_problem():
    path = OPEN_MANIPULATOR / "corrected" / "open_manipulator.urdf.xacro"
    found = diagnostics(path)
    assert [d.rule for d in found if d.severity != "info"] == []
