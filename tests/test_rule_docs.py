"""Every rule documents itself with a failing and a passing example: the failing one must
trigger the rule and the passing one must not (so the docs cannot drift from the code)."""

from __future__ import annotations

import pytest

from urdftool.check import CheckOptions, check_file
from urdftool.rules import FAMILIES, load_all
from urdftool.source import LoadOptions

RULES = sorted(load_all().values(), key=lambda r: r.id)


def _write(tmp_path, text: str, rule=None):
    """The example as a file; a companion file's (an SRDF, a controllers YAML: ``rule.on``)
    beside its robot (its family module's ``EXAMPLE_ROBOT``), named ``robot.urdf``."""
    text = text.replace("{dir}", str(tmp_path))  # an example naming a file beside it
    if rule is not None and rule.on in ("srdf", "controllers", "launch"):
        path = tmp_path / {"srdf": "example.srdf", "controllers": "controllers.yaml",
                           "launch": "example.launch.py"}[rule.on]
        path.write_text(text + "\n", encoding="utf-8")
        return path
    suffix = ".sdf" if "<sdf" in text else (".urdf.xacro" if "xmlns:xacro" in text else ".urdf")
    path = tmp_path / f"example{suffix}"
    path.write_text(text + "\n", encoding="utf-8")
    return path


UNTRUSTED_ONLY = {"xacro.env-not-allowed"}  # rules about the sandboxed reader's hiding
# companion rules about a companion checked without its robot: their bad example is
ALONE = {"srdf.no-robot"}


def _options(tmp_path, rule, bad: bool = False, **kwargs) -> CheckOptions:
    """The options that check ``rule``'s examples: a companion file's with its robot."""
    options = CheckOptions(**kwargs)
    if rule is not None and rule.on in ("srdf", "controllers") and not (bad and rule.id in ALONE):
        import importlib

        robot = tmp_path / "robot.urdf"
        module = importlib.import_module(f"urdftool.rules.{rule.family}")
        robot.write_text(module.EXAMPLE_ROBOT + "\n", encoding="utf-8")
        options.robot = str(robot)
    return options


def _fired(tmp_path, text: str, rule_id: str) -> list:
    rule = load_all()[rule_id]
    load = LoadOptions(untrusted=rule_id in UNTRUSTED_ONLY)
    report = check_file(_write(tmp_path, text, rule),
                        _options(tmp_path, rule, text == rule.bad, load=load, select=[rule_id]))
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


FIXABLE = [r for r in RULES if r.fix]


def _rules(path, options=None) -> set[tuple[str, str]]:
    options = options or CheckOptions()
    options.look_through = False
    report = check_file(path, options)
    return {(d.rule, d.severity) for d in report.diagnostics}


@pytest.mark.parametrize("rule", FIXABLE, ids=lambda r: r.id)
def test_bad_example_fixed_behaves_like_good(rule, tmp_path):
    """The documented 'bad' example, fixed (unsafe fixes too), loses the finding and gains
    none that neither the 'bad' nor the 'good' example has."""
    from urdftool.fix import fix_file

    bad = _write(tmp_path, rule.bad, rule)
    result = fix_file(bad, _options(tmp_path, rule), unsafe=True)
    assert result.fixed >= 1 and result.changed() == [str(bad)], f"{rule.id}: nothing fixed"
    fixed = tmp_path / "fixed" / bad.name
    fixed.parent.mkdir()
    fixed.write_text(result.texts[str(bad)], encoding="utf-8")
    assert fixed.read_text().count("\n") == bad.read_text().count("\n")  # no line moves
    after = _rules(fixed, _options(tmp_path, rule))
    assert rule.id not in {r for r, _ in after}, f"{rule.id} still fires after its fix"
    good = tmp_path / "good" / bad.name
    good.parent.mkdir()
    good.write_text(rule.good + "\n", encoding="utf-8")
    new = after - _rules(bad, _options(tmp_path, rule)) - _rules(good, _options(tmp_path, rule))
    assert not new, f"fixing {rule.id} brings {new}"
    # idempotent: the fixed file has nothing more to fix for this rule
    again = fix_file(fixed, _options(tmp_path, rule), unsafe=True)
    assert again.texts[str(fixed)] == result.texts[str(bad)] or rule.id not in {
        d.rule for d in check_file(fixed, _options(tmp_path, rule)).diagnostics}
