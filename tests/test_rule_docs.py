"""Every rule documents itself with a failing and a passing example: the failing one must
trigger the rule and the passing one must not (so the docs cannot drift from the code)."""

from __future__ import annotations

import pytest

from urdftool.check import CheckOptions, check_file
from urdftool.rules import FAMILIES, load_all
from urdftool.source import LoadOptions

RULES = sorted(load_all().values(), key=lambda r: r.id)


def _write(tmp_path, text: str):
    suffix = ".sdf" if "<sdf" in text else (".urdf.xacro" if "xmlns:xacro" in text else ".urdf")
    path = tmp_path / f"example{suffix}"
    path.write_text(text + "\n", encoding="utf-8")
    return path


UNTRUSTED_ONLY = {"xacro.env-not-allowed"}  # rules about what --untrusted hides


def _fired(tmp_path, text: str, rule_id: str) -> list:
    load = LoadOptions(untrusted=rule_id in UNTRUSTED_ONLY)
    report = check_file(_write(tmp_path, text), CheckOptions(load=load, select=[rule_id]))
    return [d for d in report.diagnostics if d.rule == rule_id]


@pytest.mark.parametrize("rule", RULES, ids=lambda r: r.id)
def test_rule_is_documented(rule):
    assert rule.family in FAMILIES
    assert rule.summary and rule.doc, f"{rule.id} needs a summary and a doc"
    assert rule.bad and rule.good, f"{rule.id} needs a failing and a passing example"


@pytest.mark.parametrize("rule", RULES, ids=lambda r: r.id)
def test_bad_example_triggers_rule(rule, tmp_path):
    assert _fired(tmp_path, rule.bad, rule.id), f"the 'bad' example of {rule.id} does not trigger it"


@pytest.mark.parametrize("rule", RULES, ids=lambda r: r.id)
def test_good_example_does_not_trigger_rule(rule, tmp_path):
    fired = _fired(tmp_path, rule.good, rule.id)
    assert not fired, f"the 'good' example of {rule.id} triggers it: {fired}"
