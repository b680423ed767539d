"""Issue 20 item 6: the layers (DESIGN.md "Layers", HACKING.md) hold, and no import cycle
anywhere in urdftool/, between modules or between packages (issue 33). ``lint-imports`` reads the contracts in ``.importlinter``; the cycles are
computed here over grimp's graph (what import-linter itself builds), function-level imports
included."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path
from typing import ClassVar

ROOT = Path(__file__).resolve().parent.parent


def test_lint_imports_keeps_every_contract():
    command = shutil.which("lint-imports", path=str(Path(sys.executable).parent))
    assert command is not None, "import-linter is in the test extra"
    done = subprocess.run([command, "--config", str(ROOT / ".importlinter"), "--no-cache"],
                          cwd=ROOT, capture_output=True, text=True, timeout=120, check=False,
                          env={"PATH": str(Path(sys.executable).parent), "PYTHONPATH": str(ROOT)})
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
    assert "0 broken" in done.stdout


def _cycles(graph) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for start in sorted(graph.modules):
        if start in index:
            continue
        work = [(start, iter(sorted(graph.find_modules_directly_imported_by(start))))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            for child in children:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph.find_modules_directly_imported_by(
                        child)))))
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    if len(component) > 1:
                        found.append(sorted(component))
    return found


def test_the_cycle_finder_finds_a_cycle():
    class Graph:
        modules = frozenset("abcd")
        edges: ClassVar = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}

        def find_modules_directly_imported_by(self, module):
            return self.edges.get(module, set())

    assert _cycles(Graph()) == [["a", "b", "c"]]


def _graph():
    import grimp

    sys.path.insert(0, str(ROOT))
    try:
        return grimp.build_graph("urdftool", exclude_type_checking_imports=True,
                                 cache_dir=None)  # no cache written into the tree
    finally:
        sys.path.remove(str(ROOT))


class _Packages:
    """The graph of urdftool's top-level modules and packages (``urdftool.physics.links`` is
    ``urdftool.physics``): an import between two of them is an edge between the two."""

    def __init__(self, graph):
        def top(module: str) -> str:
            return ".".join(module.split(".")[:2])

        self.modules = frozenset(top(m) for m in graph.modules)
        self.edges: dict[str, set[str]] = {m: set() for m in self.modules}
        for module in graph.modules:
            for imported in graph.find_modules_directly_imported_by(module):
                if top(imported) != top(module):
                    self.edges[top(module)].add(top(imported))

    def find_modules_directly_imported_by(self, module):
        return self.edges[module]


def test_no_import_cycle_in_urdftool():
    assert _cycles(_graph()) == []


def test_no_import_cycle_between_urdftool_packages():
    """Issue 33: `limits` <-> `rules`, `physics` <-> `rules`, `cli` <-> `fuzz` were cycles of
    packages without being cycles of modules."""
    packages = _Packages(_graph())
    assert {"urdftool.rules", "urdftool.physics", "urdftool.cli"} <= packages.modules
    assert "urdftool.physics" in packages.edges["urdftool.rules"]  # the graph has edges
    assert _cycles(packages) == []


def test_every_module_is_in_a_layer():
    """A module in no layer of .importlinter escapes the layers contract (issue 33: `budget` and
    `textscan` were in none). A package is in a layer when each of its modules is."""
    import configparser

    config = configparser.ConfigParser()
    config.read(ROOT / ".importlinter")
    section = config["importlinter:contract:layers"]
    names = {"urdftool." + name.strip() for line in section["layers"].splitlines()
             for name in line.split(":") if name.strip()}
    graph = _graph()
    outside = sorted(module for module in graph.modules if module != "urdftool"
                     and not any(module == name or module.startswith(name + ".")
                                 for name in names)
                     and not graph.find_children(module))  # a package: its modules count
    assert outside == []
