"""Issue 21: small hostile files that attacked the work *around* the reader (scans of file
content in the parent, the run's budget, the trusted interpreter's accounting), through every
reading command (``convert`` for SDF), trusted and ``CI=true``, with ``--timeout 1``: each run finishes under
2 x --timeout plus start-up (STARTUP), the runs' peak memory stays under 1 GB, a report under 1 MB for
an input under 1 MB, no traceback, exit 0, 1 or 2.

The runs go through one process (``tests/redteam_batch.py``), as ``tests/test_redteam.py``.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from tests.redteam_batch import run_plan

TIMEOUT = 1.0
STARTUP = 3.0  # seconds beyond 2 x --timeout: imports, the reader's start, pybullet
MEGABYTES = 1024
REPORT_BYTES = 1 << 20
HEAD = '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
ARM = ('  <link name="base"/>\n  <link name="tip"><inertial><mass value="1"/><inertia ixx="1" '
       'iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>\n'
       '  <joint name="j" type="revolute"><parent link="base"/><child link="tip"/>'
       '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n')
READING = ["check", "expand", "inertia", "limits", "tree", "dh", "jacobian", "sim"]
EXTRA = {"jacobian": ["--tip", "tip"], "sim": ["--duration", "0.05"], "dh": ["--tip", "tip"]}


def _cases(base: Path) -> dict[str, tuple[Path, list[str]]]:
    package = base / "budget_pkg"
    (package / "urdf").mkdir(parents=True)
    (package / "package.xml").write_text("<package><name>budget_pkg</name></package>")
    cases: dict[str, tuple[Path, list[str]]] = {}

    def add(name, text, suffix=".urdf.xacro", commands=READING, data=None):
        directory = package / name
        directory.mkdir()
        path = directory / f"robot{suffix}"
        path.write_bytes(text.encode("utf-8") if isinstance(text, str) else text)
        for file, content in (data or {}).items():
            (directory / file).write_text(content)
        cases[name] = (path, [c for c in commands if suffix != ".urdf" or c != "expand"])

    size = 300_000  # a few hundred KB: minutes for each quadratic scan
    robot = HEAD + ARM
    # scans of file content in the parent (kind detection, includes, suppressions, encoding)
    add("unterminated-comments", robot + "<!--" * (size // 4) + "</robot>\n", suffix=".urdf")
    add("comment-of-includes", robot + "<!-- " + "<include " * (size // 9) + "\n</robot>\n")
    add("long-suppression", robot.replace("<link name=\"base\"/>", "<link name=\"base\"/><!-- "
        "urdftool: ignore " + " " * size + "x") + "</robot>\n", suffix=".urdf")
    add("bom-xml-declarations", b"\xef\xbb\xbf" + b"<?xml " * (size // 6) + robot.encode()
        + b"</robot>\n", suffix=".urdf")
    add("macro-names", robot + "<!-- " + "<xacro:macro " * (size // 13) + "-->\n</robot>\n")
    # the trusted interpreter's accounting: bytes, not items; clocks on every call
    add("property-references", HEAD + '<xacro:property name="p" value="${\'x\' * 1000000}"/>\n'
        + "".join(f'<link name="l{i}${{p}}"/>\n' for i in range(18)) + ARM + "</robot>\n")
    add("count-terabyte", HEAD + '<xacro:property name="s" value="${\'x\' * 200000}"/>\n'
        '<link name="${([s] * 1000000).count(s[:-1] + \'y\')}"/>\n' + ARM + "</robot>\n")
    merges = ["m0: &m0 {" + ", ".join(f"k{i}: {i}" for i in range(50)) + "}"] + [
        f"m{i}: &m{i} {{<<: [*m{i - 1}, *m0], x{i}: 1}}" for i in range(1, 400)]
    add("yaml-merge-chain", HEAD + '<link name="${len(str(xacro.load_yaml(\'d.yaml\')))}"/>\n'
        + ARM + "</robot>\n", data={"d.yaml": "\n".join(merges) + "\n"})
    # the expanded document's size and names (xacro_expand.MAX_DOCUMENT, MAX_NAME): a 64 KB
    # text doubled by 10 levels of macros is 64 MB, a 4 MB file included 10 times 40 MB
    doubling = "".join(f'<xacro:macro name="m{i}"><xacro:m{i - 1}/><xacro:m{i - 1}/></xacro:macro>\n'
                       for i in range(1, 11))
    expanding = ["check", "expand", "tree"]
    add("document-doubling", HEAD + '<xacro:macro name="m0"><gazebo>' + "x" * 65536
        + "</gazebo></xacro:macro>\n" + doubling + ARM + "<xacro:m10/>\n</robot>\n",
        commands=expanding)
    add("include-repeated", HEAD + '<xacro:include filename="part.xacro"/>\n' * 10 + ARM
        + "</robot>\n", commands=expanding, data={"part.xacro": HEAD + "<!-- " + "y" * (4 << 20)
                                                 + " -->\n</robot>\n"})
    add("long-element-name", HEAD + ARM + '<xacro:element xacro:name="${\'g\' * 100000}"/>\n'
        "</robot>\n", commands=expanding)
    _sdf_cases(add, package)
    return package, cases


SDF = '<?xml version="1.0"?>\n<sdf version="1.7">\n'
SDF_LINK = ('<link name="{name}"><inertial><mass>1</mass><inertia><ixx>1</ixx><iyy>1</iyy>'
            "<izz>1</izz></inertia></inertial></link>")
SDF_COMMANDS = ["convert", "check", "tree"]


def _sdf_cases(add, package: Path) -> None:
    """SDFormat through ``convert`` (and check, tree): models nested deeply, includes that
    double at each level and a long chain of them, a huge attribute, many models (each a
    free body: a floating joint and a warning; the URDF stays under 1 MB, the warnings are
    capped as check's)."""
    link = SDF_LINK.format(name="base")
    add("sdf-nested-models", SDF + "".join(f'<model name="m{i}">' for i in range(3000)) + link
        + "</model>" * 3000 + "\n</sdf>\n", suffix=".sdf", commands=SDF_COMMANDS)
    add("sdf-huge-attribute", SDF + f'<model name="m">{SDF_LINK.format(name="b" * 900_000)}'
        "</model>\n</sdf>\n", suffix=".sdf", commands=SDF_COMMANDS)
    add("sdf-many-models", SDF + '<model name="top">' + link + "".join(
        f'<model name="m{i}">{SDF_LINK.format(name="l")}</model>' for i in range(2000))
        + "</model>\n</sdf>\n", suffix=".sdf", commands=SDF_COMMANDS)
    # each level includes the next twice (2^40 models unbounded), and a chain of 400 levels
    add("sdf-include-doubling", SDF + '<model name="top">' + link
        + "<include><uri>d1</uri><name>a</name></include>"
        "<include><uri>d1</uri><name>b</name></include></model>\n</sdf>\n", suffix=".sdf",
        commands=SDF_COMMANDS)
    directory = package / "sdf-include-doubling"
    for i in range(1, 41):
        (directory / f"d{i}").mkdir()
        inner = ("<include><uri>../d{0}</uri><name>a</name></include><include><uri>../d{0}"
                 "</uri><name>b</name></include>").format(i + 1) if i < 40 else ""
        (directory / f"d{i}" / "model.sdf").write_text(
            SDF + f'<model name="d{i}">{SDF_LINK.format(name="l")}{inner}</model>\n</sdf>\n')
    add("sdf-include-chain", SDF + '<model name="top">' + link
        + "<include><uri>c1</uri><name>c</name></include></model>\n</sdf>\n", suffix=".sdf",
        commands=SDF_COMMANDS)
    directory = package / "sdf-include-chain"
    for i in range(1, 401):
        (directory / f"c{i}").mkdir()
        inner = f"<include><uri>../c{i + 1}</uri><name>c</name></include>" if i < 400 else ""
        (directory / f"c{i}" / "model.sdf").write_text(
            SDF + f'<model name="c{i}">{SDF_LINK.format(name="l")}{inner}</model>\n</sdf>\n')


def _launch_package(base: Path) -> Path:
    """A package whose launch file has a long string literal, and whose configuration lists
    one slow file 20 times with different arguments."""
    package = base / "entries_pkg"
    (package / "urdf").mkdir(parents=True)
    (package / "launch").mkdir()
    (package / "package.xml").write_text("<package><name>entries_pkg</name></package>")
    (package / "launch" / "a.launch.py").write_text("X = '" + "a" * 200_000 + "'\n")
    (package / "urdf" / "robot.urdf.xacro").write_text(
        HEAD + '<xacro:arg name="k" default="0"/>\n<xacro:macro name="t" params="n">'
        '<xacro:if value="${n > 0}"><xacro:t n="${n-1}"/><xacro:t n="${n-1}"/></xacro:if>'
        '</xacro:macro><xacro:t n="40"/>\n' + ARM + "</robot>\n")
    (package / "urdftool.toml").write_text("entries = [\n" + "".join(
        f'  {{ file = "urdf/robot.urdf.xacro", args = {{ k = "{i}" }} }},\n'
        for i in range(20)) + "]\n")
    return package


@pytest.fixture(scope="module")
def plan_cases(tmp_path_factory):
    base = tmp_path_factory.mktemp("budget")
    package, cases = _cases(base)
    return base, package, cases, _launch_package(base)


def _plan(cases, entries: Path, ci: bool) -> list[dict]:
    mode = [] if ci else ["--trusted"]
    plan = []
    for name, (path, commands) in cases.items():
        for command in commands:
            args = [command, *EXTRA.get(command, ()), *mode, "--timeout", str(TIMEOUT)]
            if command == "check":
                args.append("--no-cache")
            plan.append({"name": f"{name}: {command}", "case": name, "command": command,
                         "ci": ci, "cwd": str(path.parent), "args": [*args, str(path)],
                         "input": path.stat().st_size})
    plan.append({"name": "entries-20-times: check", "case": "entries", "command": "check",
                 "ci": ci, "cwd": str(entries), "input": 1000,
                 "args": ["check", *mode, "--timeout", str(TIMEOUT), "--no-cache", "."]})
    return plan


# the whole attack corpus, both modes: CI (slow, ~65 s of CPU with its twin in
# test_redteam*.py); make test keeps the attacks of test_security*.py, test_sandbox.py
@pytest.mark.slow
@pytest.mark.parametrize("ci", [True, False], ids=["ci-untrusted", "trusted"])
def test_every_reading_command_holds(plan_cases, ci, tmp_path):
    _, _, cases, entries = plan_cases
    plan = _plan(cases, entries, ci)
    env = {**os.environ, "URDFTOOL_CACHE_DIR": str(tmp_path), "NO_COLOR": "1"}
    env.pop("CI", None)
    report = run_plan(plan, tmp_path, env, timeout=600)
    failures = []
    for run in report["runs"]:
        output = run["out"] + run["err"]
        problems = []
        if "Traceback" in output or "internal error" in output:
            problems.append("traceback")
        if run["seconds"] - run["waited"] > 2 * TIMEOUT + STARTUP:  # less others' load
            problems.append(f"took {run['seconds']:.1f} s ({run['waited']:.1f} s waiting)")
        if run["code"] not in (0, 1, 2):
            problems.append(f"exit code {run['code']}")
        if run["input"] < (1 << 20) and len(output.encode()) > REPORT_BYTES:
            problems.append(f"report of {len(output.encode())} bytes")
        if problems:
            failures.append(f"{run['name']}: {', '.join(problems)}\n  {output[-300:]!r}")
    assert not failures, "\n".join(failures)
    assert report["peak_mb"] < MEGABYTES, report["peak_mb"]
    by_name = {run["name"]: run for run in report["runs"]}
    # the file listed 20 times: the run's budget is 3 s (--timeout 1 for each of the 2 files
    # found, and once for the run), so at most three 1 s expansions are stopped at their
    # deadline (a third when the first two used no more than theirs); the others are not
    # checked, exit 1
    entries_run = by_name["entries-20-times: check"]
    assert entries_run["code"] == 1
    assert 17 <= entries_run["out"].count("not checked: the run's time budget is spent") <= 19, \
        entries_run["out"][-2000:]
    # refused in bytes: the property referenced 18 times, the terabyte count, the document's
    # size and its names
    for name in ("property-references", "count-terabyte", "document-doubling",
                 "include-repeated", "long-element-name"):
        run = by_name[f"{name}: check"]
        assert run["code"] == 1 and "xacro.limit-exceeded" in run["out"], run["out"][-500:]
    # SDF includes: one finding for the count limit, one for the depth limit (not one each)
    for name, limit in (("sdf-include-doubling", "passed urdftool's limit of 1000 files"),
                        ("sdf-include-chain", "includes nested more than 20 deep")):
        run = by_name[f"{name}: check"]
        assert run["code"] == 1 and run["out"].count(limit) == 1, run["out"][-1000:]
