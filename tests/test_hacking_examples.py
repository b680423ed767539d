"""HACKING.md's code runs as written (issue 33): each ```python block names the module it belongs
in on its first line (`# urdftool/rules/joint.py`); its urdftool imports must keep the layers of
`.importlinter` (read here, independently of urdftool), and the block must run there: a rule
example registers, fires on its `bad` example and not on its `good` one."""

from __future__ import annotations

import ast
import configparser
import re
import sys
import types
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
BLOCK = re.compile(r"^```python\n(.*?)^```$", re.DOTALL | re.MULTILINE)


def blocks() -> list[tuple[str, str]]:
    """(module, code) of every python block of HACKING.md."""
    found = []
    for code in BLOCK.findall((ROOT / "HACKING.md").read_text(encoding="utf-8")):
        first = code.splitlines()[0]
        assert re.fullmatch(r"# urdftool/[\w/]+\.py", first), (
            f"a HACKING.md python block starts with the module it belongs in, not {first!r}")
        path = first[2:].removesuffix(".py")
        found.append((path.replace("/", "."), code))
    return found


BLOCKS = blocks()


def test_hacking_has_its_examples():
    assert [module for module, _ in BLOCKS] == ["urdftool.rules.joint"]


def layers() -> list[list[str]]:
    """The layers contract of .importlinter, top layer first, each a list of module names."""
    config = configparser.ConfigParser()
    config.read(ROOT / ".importlinter")
    section = config["importlinter:contract:layers"]
    container = section["containers"].strip()
    return [[f"{container}.{name.strip()}" for name in line.split(":")]
            for line in section["layers"].strip().splitlines() if line.strip()]


def layer_of(module: str, table: list[list[str]]) -> int | None:
    """The index of the layer holding ``module`` (the longest name of the table it is in)."""
    best, depth = None, -1
    for index, names in enumerate(table):
        for name in names:
            if (module == name or module.startswith(name + ".")) and name.count(".") > depth:
                best, depth = index, name.count(".")
    return best


def imported(code: str) -> list[str]:
    names = []
    for node in ast.walk(ast.parse(code)):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.append(node.module)
        elif isinstance(node, ast.Import):
            names.extend(alias.name for alias in node.names)
    return [name for name in names if name == "urdftool" or name.startswith("urdftool.")]


def test_the_layer_reading_refuses_what_lint_imports_refuses():
    """The check below, on the import HACKING once showed (`Finding` from `report`, a runs
    module, in a rule): refused."""
    table = layers()
    assert layer_of("urdftool.report", table) < layer_of("urdftool.rules.joint", table)
    assert layer_of("urdftool.findings", table) > layer_of("urdftool.rules.joint", table)


@pytest.mark.parametrize("module, code", BLOCKS, ids=[m for m, _ in BLOCKS])
def test_example_keeps_the_layers(module, code):
    table = layers()
    home = layer_of(module, table)
    assert home is not None, f"{module} is in no layer of .importlinter"
    for name in imported(code):
        layer = layer_of(name, table)
        assert layer is not None, f"{name} is in no layer of .importlinter"
        assert layer >= home, f"{module} may not import {name}: a layer above it"


@pytest.mark.parametrize("module, code", BLOCKS, ids=[m for m, _ in BLOCKS])
def test_example_runs(module, code, tmp_path, monkeypatch):
    from urdftool import rules
    from urdftool.check import CheckOptions, check_file

    registry = dict(rules.load_all())
    monkeypatch.setattr(rules, "REGISTRY", {})  # the example registers anew
    namespace = types.ModuleType(module + "_hacking_example")
    namespace.__file__ = str(tmp_path / "example.py")
    monkeypatch.setitem(sys.modules, namespace.__name__, namespace)
    exec(compile(code, f"HACKING.md ({module})", "exec"), namespace.__dict__)  # noqa: S102
    added = dict(rules.REGISTRY)
    assert added, "the example registers a rule"
    monkeypatch.setattr(rules, "REGISTRY", {**registry, **added})
    for rule_id, rule in added.items():
        for example, fires in ((rule.bad, True), (rule.good, False)):
            path = tmp_path / "example.urdf"
            path.write_text(example + "\n", encoding="utf-8")
            report = check_file(path, CheckOptions(select=[rule_id]))
            found = [d for d in report.diagnostics if d.rule == rule_id]
            assert bool(found) == fires, (rule_id, example, found)
    # the findings came from the example's functions, not from rules registered before
    assert all(rules.REGISTRY[rule_id] is rule for rule_id, rule in added.items())
