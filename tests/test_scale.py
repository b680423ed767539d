"""Big inputs (issue 15): a 50k-link chain through every command (no recursion over the tree,
nothing quadratic), and big tables drawn without rich's per-cell measurement looking exactly
as rich draws them. Correctness only: the timings are in benchmarks/bench_scale.py.

The 50k chains run in CI (`slow`, `make test-slow`, issue 33); `make test` runs the same tests on
3k-link chains, three times Python's recursion limit: a recursive walk fails there too."""

from __future__ import annotations

import json
import re
import sys

import pytest

from tests.conftest import example_robot_urdfs, run_urdftool

SIZES = [pytest.param(3_000, id="3k"), pytest.param(50_000, id="50k", marks=pytest.mark.slow)]


@pytest.fixture(scope="module", params=SIZES)
def N(request):
    assert request.param >= 3 * sys.getrecursionlimit()
    return request.param


def _rope(N: int) -> str:
    parts = ['<robot name="rope">']
    for i in range(N):
        parts.append(f'<link name="l{i}"><inertial><mass value="0.5"/><inertia ixx="1e-3" '
                     'iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial></link>')
        if i:
            parts.append(f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/>'
                         f'<child link="l{i}"/><origin xyz="0 0 0.01"/><axis xyz="0 1 0"/>'
                         '<limit lower="-0.1" upper="0.1" effort="1" velocity="1"/></joint>')
    parts.append("</robot>")
    return "\n".join(parts)


@pytest.fixture(scope="module")
def chain(tmp_path_factory, N):
    """A serial chain of N links (l0 ... l{N-1}), each with a mass (the inertia rules walk
    subtrees), nothing else: the parse stays quick."""
    path = tmp_path_factory.mktemp("scale") / "rope.urdf"
    path.write_text(_rope(N), encoding="utf-8")
    return path


def test_tree_of_a_long_chain(chain, N):
    result = run_urdftool("tree", "--format", "json", chain)
    assert result.code == 0, result.err
    # 2N levels of nesting: more than Python's json module parses (its recursion limit)
    assert re.findall(r'"link": "([^"]*)"', result.out) == [f"l{i}" for i in range(N)]
    assert result.out.count("[") == result.out.count("]") == N + 1  # roots and each children
    # each node's "joint" follows its "children": innermost first
    assert re.findall(r'"joint": "([^"]*)"', result.out) == [f"j{i}" for i in range(N - 1, 0, -1)]
    text = run_urdftool("tree", chain)
    assert text.code == 0, text.err
    lines = text.out.splitlines()
    assert len(lines) == N + 1 and lines[-1].endswith(f"l{N - 1} via j{N - 1} (revolute)")
    assert max(map(len, lines)) < 300  # the indentation stops growing


def test_check_limits_and_inertia_of_a_long_chain(chain, N):
    check = run_urdftool("check", "--format", "json", chain)
    assert check.code in (0, 1), check.err
    assert json.loads(check.out)["summary"]["files"] == 1
    limits = run_urdftool("limits", chain)
    assert limits.code == 0, limits.err
    assert limits.out.count(" revolute ") == N - 1
    inertia = run_urdftool("inertia", "--format", "json", chain)
    assert inertia.code == 0, inertia.err
    assert [link["link"] for link in json.loads(inertia.out)["links"]] == [f"l{i}" for i in range(N)]


@pytest.mark.parametrize("N", SIZES)
def test_convert_of_a_long_sdf_chain(tmp_path, N):
    """Each link posed 1 cm above its parent link (SDFormat 1.7 relative_to): the URDF has every
    joint once, its origin the 1 cm step (up to the rounding of poses composed in the model
    frame), in chain order."""
    parts = ['<?xml version="1.0"?>\n<sdf version="1.7"><model name="rope">',
             '<link name="l0"><inertial><mass>0.5</mass></inertial></link>']
    for i in range(1, N):
        parts.append(f'<link name="l{i}"><pose relative_to="l{i - 1}">0 0 0.01 0 0 0</pose>'
                     f'<inertial><mass>0.5</mass></inertial></link><joint name="j{i}" '
                     f'type="revolute"><parent>l{i - 1}</parent><child>l{i}</child><axis>'
                     '<xyz>0 1 0</xyz><limit><lower>-0.1</lower><upper>0.1</upper></limit>'
                     '</axis></joint>')
    parts.append("</model></sdf>\n")
    path = tmp_path / "rope.sdf"
    path.write_text("\n".join(parts), encoding="utf-8")
    result = run_urdftool("convert", "--trusted", path)
    assert result.code == 0, result.err[:500]
    # its findings are clipped as check's (one info listed the 49,999 joints: 600 KB a line)
    assert max(map(len, result.err.splitlines()), default=0) < 2000
    joints = re.findall(r'<joint name="(j\d+)" type="revolute">\s*<origin xyz="([^"]*)"[^>]*/>\s*'
                        r'<parent link="(l\d+)"/>\s*<child link="(l\d+)"/>', result.out)
    assert [(name, parent, child) for name, _, parent, child in joints] == [
        (f"j{i}", f"l{i - 1}", f"l{i}") for i in range(1, N)]
    for _, xyz, _, _ in joints:
        x, y, z = map(float, xyz.split())
        assert x == y == 0 and z == pytest.approx(0.01, abs=1e-9)
    assert result.out.count('<mass value="0.5"/>') == N


def test_dh_and_jacobian_at_the_end_of_a_long_chain(chain, N):
    """The tip's path to the root is walked in full (iteratively); the table is the last 99
    joints above the leaf."""
    dh = run_urdftool("dh", "--format", "json", "--base", f"l{N - 100}", chain)
    assert dh.code == 0, dh.err
    rows = json.loads(dh.out)["rows"]
    assert [r["joint"] for r in rows] == [f"j{i}" for i in range(N - 99, N)]
    jac = run_urdftool("jacobian", "--format", "json", "--base", f"l{N - 100}", chain)
    assert jac.code == 0, jac.err
    matrix = json.loads(jac.out)["J"]
    assert len(matrix) == 6 and all(len(row) == 99 for row in matrix)


@pytest.mark.parametrize("command", ["limits", "inertia"])
def test_big_tables_look_as_rich_draws_them(monkeypatch, command):
    """The same output through rich (every table small) and through the fast drawing (every
    table big) on real robots: multi-line verdicts, markup, right-justified numbers."""
    from urdftool.cli import table

    robots = [p for p in example_robot_urdfs() if p.name in ("panda.urdf", "talos_reduced.urdf",
                                                              "romeo.urdf", "solo12.urdf")]
    assert len(robots) >= 3
    for robot in robots:
        monkeypatch.setattr(table, "BIG", 10**9)
        by_rich = run_urdftool(command, robot)
        monkeypatch.setattr(table, "BIG", 0)
        drawn = run_urdftool(command, robot)
        assert drawn.code == by_rich.code and drawn.out == by_rich.out, robot
        assert "┃" in drawn.out


def test_expand_of_many_sibling_macro_calls_is_plain_xacros(tmp_path):
    """xacro replaces each call by its body through minidom's insertBefore/removeChild, which
    urdftool makes look a child up near the last one (issue 15); the document is plain
    xacro's: comments before calls dropped, blocks inserted, conditions, nested calls."""
    import subprocess
    import sys
    from pathlib import Path

    calls = "".join(
        f'  <!-- segment {i} -->\n  <xacro:seg i="{i}" parent="l{i - 1}"><origin xyz="0 0 {i}"/>'
        f'</xacro:seg>\n  <xacro:if value="{i % 3 == 0}"><link name="extra{i}"/></xacro:if>\n'
        for i in range(1, 400))
    path = tmp_path / "many.urdf.xacro"
    path.write_text(f"""<?xml version="1.0"?>
<robot name="many" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="mass" params="m"><inertial><mass value="${{m}}"/></inertial></xacro:macro>
  <xacro:macro name="seg" params="i parent *origin">
    <!-- kept: inside the body -->
    <link name="l${{i}}"><xacro:mass m="${{i / 10}}"/></link>
    <joint name="j${{i}}" type="fixed"><parent link="${{parent}}"/><child link="l${{i}}"/>
      <xacro:insert_block name="origin"/></joint>
  </xacro:macro>
  <link name="l0"/>
{calls}</robot>
""")
    ours = run_urdftool("expand", "--trusted", path)
    assert ours.code == 0, ours.err
    theirs = subprocess.run([str(Path(sys.executable).parent / "xacro"), str(path)],
                            capture_output=True, text=True, check=True).stdout
    assert ours.out == theirs
    assert ours.out.count("<joint ") == 399 and ours.out.count('name="extra') == 133


@pytest.mark.parametrize("command", ["tree", "limits", "inertia", "check"])
def test_commands_grow_linearly_with_the_chain(command, tmp_path):
    """What the 50k chains (CI) show, measured on small chains in make test: four times the
    links costs about four times the CPU (less than eight: a quadratic walk costs sixteen).
    CPU time of this process, after a first run that pays the imports."""
    import gc
    import time

    warm = tmp_path / "warm.urdf"
    warm.write_text(_rope(100), encoding="utf-8")
    assert run_urdftool(command, warm).code in (0, 1)
    costs = {}
    # what the earlier tests of this pytest worker left on the heap is frozen: the collector's
    # full passes over it are the worker's cost, not the command's (11x for 4x links in the
    # full suite, 3x alone)
    gc.collect()
    gc.freeze()
    try:
        for n in (1_500, 6_000):
            path = tmp_path / f"rope{n}.urdf"
            path.write_text(_rope(n), encoding="utf-8")
            started = time.process_time()
            result = run_urdftool(command, "--format", "json", path)
            costs[n] = time.process_time() - started
            assert result.code in (0, 1), result.err
    finally:
        gc.unfreeze()
    assert costs[6_000] < 8 * costs[1_500], costs
    assert costs[6_000] > 2 * costs[1_500], costs  # the sizes do show in the cost
