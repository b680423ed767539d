"""Rules of the suite itself (issue 33), checked over the tests' source: nothing the test extra
installs is imported with `pytest.importorskip` (a missing oracle fails, it never skips in
silence), and the `slow` marker is registered, so that `make test` (-m "not slow") and `make
test-slow` (-m slow) split the suite and a misspelt marker is an error."""

from __future__ import annotations

import ast
from pathlib import Path

TESTS = Path(__file__).resolve().parent


def test_no_importorskip():
    found = []
    for path in sorted(TESTS.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Attribute) and node.attr == "importorskip":
                found.append(f"{path.name}:{node.lineno}")
    assert found == [], "import it: the test extra installs it (a missing one must fail): " \
                        + ", ".join(found)


def test_the_slow_marker_is_registered(pytestconfig):
    markers = pytestconfig.getini("markers")
    assert any(line.startswith("slow:") for line in markers), markers
    assert pytestconfig.getoption("strict_markers")
