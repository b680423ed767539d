"""The serial chain taken from the model: fixed joints folded, mimic joints expressed through
their leader (chains of mimics composed), and clear errors for whatever is not a serial chain."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import run_urdftool
from tests.test_kinematics_pinocchio import MIMIC, PRISMATIC_FIXED, _robot
from urdftool.cli import load_robot
from urdftool.errors import ToolError
from urdftool.kinematics.chain import extract_chain


def _chain(write, text, base=None, tip=None):
    return extract_chain(load_robot(str(write(text))), base, tip)


def test_fixed_joints_are_folded(write):
    chain = _chain(write, PRISMATIC_FIXED)
    assert [j.name for j in chain.joints] == ["j1", "slide", "j3"]
    assert chain.joints[1].folded == ("fix",)
    assert chain.tool_folded == ("tool_joint",)
    assert chain.links == ("base", "l1", "l1b", "l2", "l3", "tool")
    assert np.linalg.norm(chain.joints[1].axis) == pytest.approx(1.0)  # 0 0.6 0.8 is unit
    assert chain.variable_names == ["j1", "slide", "j3"]


def test_non_unit_axis_is_normalised(write):
    chain = _chain(write, _robot("r", [("j", "revolute", "a", "b", "0 0 0", "0 0 0", "0 0 2",
                                        (-1, 1))]))
    assert chain.joints[0].axis.tolist() == [0.0, 0.0, 1.0]


def test_default_axis_is_x(write):
    chain = _chain(write, _robot("r", [("j", "continuous", "a", "b")]))
    assert chain.joints[0].axis.tolist() == [1.0, 0.0, 0.0]
    variable = chain.variables[0]
    assert not variable.bounded and variable.middle == 0.0
    assert variable.sample_range() == (-math.pi, math.pi)


def test_mimic_through_leader(write):
    chain = _chain(write, MIMIC, tip="l4")
    assert chain.variable_names == ["j1", "other", "j4"]  # first appearance along the chain
    assert [v.in_chain for v in chain.variables] == [True, False, True]
    j2, j3 = chain.joints[1], chain.joints[2]
    assert (j2.leader, j2.multiplier, j2.offset, j2.variable) == ("other", 0.5, 0.1, 1)
    assert (j3.leader, j3.multiplier, j3.offset, j3.variable) == ("j1", -2.0, 0.0, 0)
    assert chain.joint_values([0.3, 0.4, 0.1]).tolist() == pytest.approx([0.3, 0.3, -0.6, 0.1])


def test_chained_mimics_compose(write):
    text = _robot("m", [
        ("c", "revolute", "base", "x", "0 0 0", "0 0 0", "0 0 1", (-1, 1)),
        {"name": "b", "kind": "revolute", "parent": "base", "child": "y", "axis": "0 0 1",
         "limit": (-9, 9), "mimic": '<mimic joint="c" multiplier="3" offset="0.2"/>'},
        {"name": "a", "kind": "revolute", "parent": "base", "child": "z", "axis": "0 0 1",
         "limit": (-9, 9), "mimic": '<mimic joint="b" multiplier="2" offset="0.1"/>'},
    ])
    chain = _chain(write, text, tip="z")
    (joint,) = chain.joints
    # a = 2 * b + 0.1 = 2 * (3 c + 0.2) + 0.1 = 6 c + 0.5
    assert joint.leader == "c" and joint.multiplier == 6.0 and joint.offset == pytest.approx(0.5)
    assert chain.variables[0].name == "c" and chain.variables[0].upper == 1.0


def _mimic_robot(leader_type="revolute", target="b"):
    return _robot("m", [
        ("b", leader_type, "base", "x", "0 0 0", "0 0 0", "0 0 1", (-1, 1)),
        {"name": "a", "kind": "revolute", "parent": "x", "child": "y", "axis": "0 0 1",
         "limit": (-1, 1), "mimic": f'<mimic joint="{target}"/>'},
    ])


CYCLE = _robot("m", [
    {"name": "a", "kind": "revolute", "parent": "base", "child": "x", "axis": "0 0 1",
     "limit": (-1, 1), "mimic": '<mimic joint="b"/>'},
    {"name": "b", "kind": "revolute", "parent": "x", "child": "y", "axis": "0 0 1",
     "limit": (-1, 1), "mimic": '<mimic joint="a"/>'},
])
TWO_PARENTS = _robot("t", [("j1", "revolute", "a", "c", "0 0 0", "0 0 0", "0 0 1", (-1, 1)),
                           ("j2", "revolute", "b", "c", "0 0 0", "0 0 0", "0 0 1", (-1, 1))])
LOOP = _robot("l", [("j1", "revolute", "a", "b", "0 0 0", "0 0 0", "0 0 1", (-1, 1)),
                    ("j2", "revolute", "b", "a", "0 0 0", "0 0 0", "0 0 1", (-1, 1))])
TWO_ROOTS = _robot("r", [("j1", "revolute", "a", "b", "0 0 0", "0 0 0", "0 0 1", (-1, 1)),
                         ("j2", "revolute", "c", "d", "0 0 0", "0 0 0", "0 0 1", (-1, 1))])
ZERO_AXIS = _robot("z", [("j1", "revolute", "a", "b", "0 0 0", "0 0 0", "0 0 0", (-1, 1))])


@pytest.mark.parametrize(("text", "tip", "message"), [
    (_mimic_robot(target="nope"), "y", "joint 'a' mimics 'nope', which does not exist"),
    (_mimic_robot(leader_type="fixed"), "y", "mimics 'b' of type fixed"),
    (CYCLE, "y", "mimic cycle: a -> b -> a"),
    (TWO_PARENTS, "c", "link 'c' is the child of several joints (j1, j2): not a tree"),
    (LOOP, None, "no root link"),
    (LOOP, "b", "form a loop"),
    (TWO_ROOTS, None, "several root links (a, c): choose one with --base"),
    (ZERO_AXIS, None, "joint 'j1' has a zero axis"),
])
def test_not_a_serial_chain(write, text, tip, message):
    with pytest.raises(ToolError) as info:
        _chain(write, text, tip=tip)
    assert message in str(info.value)
    # and through the CLI: exit 2, one line, no traceback
    args = ["--tip", tip] if tip else []
    for command in ("dh", "jacobian"):
        result = run_urdftool(command, str(write(text)), *args)
        assert result.code == 2 and message in result.err
        assert len(result.err.strip().splitlines()) == 1 and "Traceback" not in result.err


def test_two_roots_with_a_tip_take_the_tip_s_root(write):
    chain = _chain(write, TWO_ROOTS, tip="d")
    assert chain.base == "c" and chain.base_is_root
