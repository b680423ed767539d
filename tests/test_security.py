"""Untrusted xacro files: code execution, secrets, files outside the package, resource limits.

Each escape class is a .xacro file whose payload would create a marker file (or leak a secret).
urdftool must report it (``xacro.unsafe-expression``) and the marker must not exist afterwards;
plain ``xacro`` on the same file is shown to run it (that half is skipped if a future xacro
closes the hole).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.conftest import WallLessWaiting, run_urdftool

XACRO_BIN = Path(sys.executable).parent / "xacro"
HEAD = '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
TAIL = '  <link name="base"/>\n</robot>\n'


def _frame_walk(marker):  # the payload: a generator's frame reaches xacro's globals
    return (f'  <link name="${{[*(g:=(g.gi_frame.f_back.f_back.f_globals[\'os\']'
            f'.system(\'touch {marker}\') for _ in [1]))]}}"/>\n')


def _lambda_generator(marker):  # no walrus: a lambda hands the generator to itself
    return (f'  <link name="${{(lambda l: l.append(y.gi_frame.f_back.f_back.f_back'
            f'.f_globals[\'os\'].system(\'touch {marker}\') for y in l) or [*l[0]])([])}}"/>\n')


def _comprehension_self_reference(marker):  # no walrus, no lambda: a list holds the generator
    return (f'  <link name="${{[x for l in [[]] for _ in [l.append(g.gi_frame.f_back.f_back'
            f'.f_back.f_globals[\'os\'].system(\'touch {marker}\') for g in l)] '
            f'for x in l[0]]}}"/>\n')


def _eval_builtins(marker):  # $(eval) sees every builtin; ')' is smuggled in through properties
    return ('  <xacro:property name="lp" value="("/>\n  <xacro:property name="rp" value=")"/>\n'
            f'  <link name="$(eval exec${{lp}}\'import os;os.system${{lp}}&quot;touch {marker}'
            '&quot;${rp}\', {}${rp})"/>\n')


def _yaml_units(marker, tmp_path):  # a YAML data file whose !degrees value is an expression
    (tmp_path / "evil.yaml").write_text(
        f"angle: !degrees \"[*(g:=(g.gi_frame.f_back.f_back.f_globals['os']"
        f".system('touch {marker}') for _ in [1]))] and 0\"\n", encoding="utf-8")
    return '  <link name="${xacro.load_yaml(\'evil.yaml\')[\'angle\']}"/>\n'


ESCAPES = {
    "frame-walk": lambda marker, tmp: _frame_walk(marker),
    "lambda-generator": lambda marker, tmp: _lambda_generator(marker),
    "comprehension-self-reference": lambda marker, tmp: _comprehension_self_reference(marker),
    "eval-builtins": lambda marker, tmp: _eval_builtins(marker),
    "yaml-unit-expression": _yaml_units,
}


def _plain_xacro(path: Path, env=None) -> subprocess.CompletedProcess:
    return subprocess.run([str(XACRO_BIN), str(path)], capture_output=True, text=True,
                          timeout=60, cwd=path.parent, env=env, check=False)


@pytest.mark.parametrize("kind", sorted(ESCAPES))
@pytest.mark.parametrize("mode", ["--trusted", "--untrusted"])
def test_escape_is_reported_and_never_runs(kind, mode, tmp_path, monkeypatch):
    marker = tmp_path / f"PWNED-{kind}"
    path = tmp_path / "evil.urdf.xacro"
    path.write_text(HEAD + ESCAPES[kind](marker, tmp_path) + TAIL, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    for command in (["check", "--format", "json", mode, path], ["expand", mode, path]):
        result = run_urdftool(*command)
        assert not marker.exists(), f"{kind}: urdftool {command[0]} ran the payload"
        assert result.code == 1, result.err
        assert "xacro.unsafe-expression" in result.out + result.err
        assert "Traceback" not in result.err
    report = json.loads(run_urdftool("check", "--format", "json", mode, path).out)
    (unsafe,) = [d for d in report["files"][0]["diagnostics"]
                 if d["rule"] == "xacro.unsafe-expression"]
    assert unsafe["severity"] == "error" and unsafe["line"] is not None
    assert Path(unsafe["path"]).name in ("evil.urdf.xacro", "evil.yaml")
    assert not marker.exists()


@pytest.mark.parametrize("kind", sorted(ESCAPES))
def test_plain_xacro_runs_the_payload(kind, tmp_path):
    """The other half: the same file is a real exploit against plain xacro."""
    marker = tmp_path / f"PWNED-{kind}"
    path = tmp_path / "evil.urdf.xacro"
    path.write_text(HEAD + ESCAPES[kind](marker, tmp_path) + TAIL, encoding="utf-8")
    _plain_xacro(path)
    assert marker.exists(), f"plain xacro (xacro<3, pinned) no longer runs the {kind} payload: " \
        "update this half (urdftool's half is test_escape_is_reported_and_never_runs)"


# -- secrets: str.format traversal, $(env), files outside the package ------------------------


def test_format_string_cannot_walk_to_globals(tmp_path, monkeypatch):
    """'{0.__globals__[os].environ[...]}'.format(f): the dunder hides in a string constant."""
    path = tmp_path / "leak.urdf.xacro"
    path.write_text(HEAD + '  <xacro:property name="rb" value="}"/>\n'
                    '  <link name="${(\'{0.__globals__[os].environ[URDFTOOL_SECRET]\' + rb)'
                    '.format(xacro.load_yaml)}"/>\n' + TAIL, encoding="utf-8")
    monkeypatch.setenv("URDFTOOL_SECRET", "hunter2")
    result = run_urdftool("expand", "--trusted", path)
    assert result.code == 1 and "hunter2" not in result.out + result.err
    assert "xacro.unsafe-expression" in result.err and "format field" in result.err
    plain = _plain_xacro(path, env={**os.environ, "URDFTOOL_SECRET": "hunter2"})
    assert "hunter2" in plain.stdout, "plain xacro (xacro<3, pinned) no longer leaks through " \
        "str.format: update this half (urdftool's half passed above)"


def test_untrusted_env_sees_only_allowed_variables(tmp_path, monkeypatch):
    path = tmp_path / "env.urdf.xacro"
    path.write_text(HEAD + '  <link name="a_$(optenv URDFTOOL_SECRET none)"/>\n'
                    '  <xacro:property name="lp" value="("/>\n'  # $(eval) cannot hold ')'
                    '  <xacro:property name="rp" value=")"/>\n'
                    '  <link name="b_$(eval optenv${lp}\'URDFTOOL_SECRET\', \'none\'${rp})"/>\n'
                    + TAIL, encoding="utf-8")
    monkeypatch.setenv("URDFTOOL_SECRET", "hunter2")
    trusted = run_urdftool("expand", "--trusted", path)  # your own files: still no variable
    assert trusted.code == 0 and "hunter2" not in trusted.out + trusted.err
    assert "hunter2" in run_urdftool("expand", "--trusted", "--allow-env", "URDFTOOL_SECRET",
                                     path).out
    untrusted = run_urdftool("expand", "--untrusted", path)
    assert untrusted.code == 0 and "hunter2" not in untrusted.out
    assert 'name="a_none"' in untrusted.out and 'name="b_none"' in untrusted.out
    allowed = run_urdftool("expand", "--untrusted", "--allow-env", "URDFTOOL_SECRET", path)
    assert 'name="a_hunter2"' in allowed.out and 'name="b_hunter2"' in allowed.out
    required = tmp_path / "env2.urdf.xacro"
    required.write_text(HEAD + '  <link name="$(env URDFTOOL_SECRET)"/>\n' + TAIL)
    result = run_urdftool("expand", "--untrusted", required)
    assert result.code == 1 and "hunter2" not in result.out + result.err
    assert "--allow-env" in result.err


def test_ci_variable_makes_untrusted_the_default(tmp_path, monkeypatch):
    path = tmp_path / "env.urdf.xacro"
    path.write_text(HEAD + '  <link name="$(optenv URDFTOOL_SECRET none)"/>\n' + TAIL)
    monkeypatch.setenv("URDFTOOL_SECRET", "hunter2")
    monkeypatch.setenv("CI", "true")
    assert "hunter2" not in run_urdftool("expand", path).out
    assert "hunter2" in run_urdftool("expand", "--trusted", "--allow-env", "URDFTOOL_SECRET",
                                     path).out
    monkeypatch.setenv("CI", "")
    assert "hunter2" in run_urdftool("expand", "--allow-env", "URDFTOOL_SECRET", path).out


def _package(tmp_path) -> Path:
    package = tmp_path / "robot_description"
    (package / "urdf").mkdir(parents=True)
    (package / "package.xml").write_text("<package><name>robot_description</name></package>")
    secret = tmp_path / "secret.yaml"
    secret.write_text("token: hunter2\n")
    (tmp_path / "outside.xacro").write_text(
        HEAD + '  <link name="outside_hunter2"/>\n</robot>\n')
    return package


@pytest.mark.parametrize("payload", [
    '  <link name="${xacro.load_yaml(\'../../secret.yaml\')[\'token\']}"/>\n',
    '  <link name="${python.list(python.map(xacro.load_yaml, [\'../../secret.yaml\']))}"/>\n',
    '  <xacro:include filename="../../outside.xacro"/>\n',
    '  <xacro:include filename="$(find robot_description)/../outside.xacro"/>\n',
])
def test_untrusted_reads_only_inside_the_package(payload, tmp_path, monkeypatch):
    package = _package(tmp_path)
    path = package / "urdf" / "robot.urdf.xacro"
    path.write_text(HEAD + payload + TAIL, encoding="utf-8")
    monkeypatch.chdir(package)
    # one trust model (issue 20): what a file may read is the same in both modes
    trusted = run_urdftool("expand", "--trusted", path)
    assert "hunter2" not in trusted.out + trusted.err
    for mode in ("--untrusted", "--trusted"):
        result = run_urdftool("check", mode, "--format", "json", path)
        assert "hunter2" not in result.out
        messages = [d["message"] for f in json.loads(result.out)["files"]
                    for d in f["diagnostics"] if d["rule"] == "xacro.error"]
        assert any("outside the repository" in m and ("secret.yaml" in m or "outside.xacro" in m)
                   for m in messages), messages


def test_untrusted_reads_inside_the_package_and_given_packages(tmp_path, monkeypatch):
    package = _package(tmp_path)
    (package / "config").mkdir()
    (package / "config" / "arm.yaml").write_text("length: 0.5\n")
    other = tmp_path / "other_pkg"
    other.mkdir()
    (other / "parts.xacro").write_text(HEAD + '  <link name="other_part"/>\n</robot>\n')
    path = package / "urdf" / "robot.urdf.xacro"
    path.write_text(HEAD + '  <link name="l_${xacro.load_yaml(\'../config/arm.yaml\').length}"/>\n'
                    '  <xacro:include filename="$(find other_pkg)/parts.xacro"/>\n' + TAIL)
    monkeypatch.chdir(package)
    result = run_urdftool("expand", "--untrusted", "-P", f"other_pkg={other}", path)
    assert result.code == 0, result.err
    assert 'name="l_0.5"' in result.out and 'name="other_part"' in result.out


# -- the runtime guard (what the static scan cannot see) --------------------------------------


@pytest.mark.parametrize("expression,reason", [
    ("python.type('X', (), dict())", "builds classes"),
    ("python.list(python.map(python.type, ['X'], [()], [python.dict()]))", "builds classes"),
    ("python['type']('X', (), dict())", "builds classes"),
    ("python.vars(xacro)", "internals"),
    ("python.sorted([1], key=python.vars)", "internals"),
    ("(x for x in [1]).close()", "attribute 'close' of a generator"),
    ("(x for x in [1]).gi_frame", "attribute 'gi_frame' of a generator"),
    ("'{0.real}'.format(1)", "format field"),
    ("str.format('{0.imag}', 2)", "format field"),
    ("xacro.load_yaml.gi_code", "attribute 'gi_code'"),
    ("python.len.__self__", "dunder"),
    ("'x'.encode()", "attribute 'encode' of a str"),
    ("(lambda: 0).__globals__", "dunder"),
    ("python.type('X', (), {})", "builds classes"),
    ("python.dict(a=1).keys().mapping", "attribute 'mapping' of a dict_keys"),
    ("(lambda: 0).scope", "attribute 'scope' of a function"),
    ("(lambda: 0).lookup", "attribute 'lookup' of a function"),
    ("[].__class__", "dunder"),
    ("__import__('os')", "names starting with __"),
    ("[y := 1]", "assignment expression"),
    ("[y for x.attr in [1]]", "assigning to an attribute"),
    ("b'x'", "bytes literals"),
])
def test_interpreter_refuses(expression, reason):
    import xacro

    from urdftool.xacro_eval import Interpreter, UnsafeExpression

    with pytest.raises(UnsafeExpression, match=reason):
        Interpreter().evaluate(expression, xacro.Table(xacro._global_symbols))


@pytest.mark.parametrize("expression", [
    "math.parent", "xacro.dotify(python).type", "xacro.dotify(python.dict(a=[1])).a.wrap",
    "python.list(dict.values(python))[-3]('X', (), dict())", "getattr", "python.getattr",
    "python.sorted([1], key=python.list(dict.values(python))[-3])",
])
def test_interpreter_has_no_such_thing(expression):
    """What plain xacro reaches through its namespaces' dict methods does not exist here."""
    import xacro

    from urdftool.xacro_eval import Interpreter

    with pytest.raises((NameError, TypeError, AttributeError)):
        Interpreter().evaluate(expression, xacro.Table(xacro._global_symbols))


@pytest.mark.parametrize("expression", [
    "1 + 2 * 3 ** 2 / 4 - 5 // 2 % 3", "pi / 2", "math.radians(90)", "sin(0.5) + cos(0.5)",
    "python.sorted([3, 1, 2], reverse=True)", "'-'.join(['a', 'b'])", "'a_b'.split('_')[1]",
    "'%s_%d' % ('link', 3)", "'{}_{:.2f}'.format('x', 1.234)", "str.upper('x')",
    "[i * i for i in python.range(5) if i % 2]", "python.dict(a=1).get('a')",
    "1 if True else 2", "not (1 < 2 <= 3) or 4 in [4]", "python.list(python.zip('ab', [1, 2]))",
    "xacro.dotify(python.dict(a=python.dict(b=2))).a.b", "python.abs(-1.5)", "round(1.23456, 2)",
    "float('1e-3') + int('2')", "[1, 2, 3][::-1]", "max([1, 5, 2])", "len('abc')",
    "python.sum(x for x in [1, 2])", "-(3).real", "'X'.lower().startswith('x')",
    "python.isinstance(1.0, float)", "python.list(python.map(str, [1, 2]))",
    "dict.fromkeys(['a'], 0)", "sorted(python.dict(b=1, a=2).items())", "2 ** 10 << 2",
])
def test_guard_allows_and_agrees_with_xacro(expression):
    import xacro

    from urdftool.xacro_eval import Interpreter

    plain = xacro.safe_eval(expression, xacro.Table(xacro._global_symbols))
    ours = Interpreter().evaluate(expression, xacro.Table(xacro._global_symbols))
    assert ours == plain and type(ours) is type(plain)


# -- limits: never a hang ---------------------------------------------------------------------


PATHOLOGICAL = {
    "recursive-macro": '  <xacro:macro name="loop"><xacro:loop/></xacro:macro>\n  <xacro:loop/>\n',
    "exponential": '  <xacro:macro name="twice" params="n"><xacro:if value="${n > 0}">'
                   '<xacro:twice n="${n-1}"/><xacro:twice n="${n-1}"/></xacro:if>'
                   '<link name="l${n}"/></xacro:macro>\n  <xacro:twice n="40"/>\n',
    "huge-number": '  <link name="${10**10**10}"/>\n',
    "huge-string": '  <link name="${\'x\' * 10**10}"/>\n',
    "long-loop": '  <link name="${python.sum([1 for i in python.range(10**7) '
                 'for j in python.range(10**7)])}"/>\n',
    "recursive-property": '  <xacro:property name="a" value="${b}"/>\n'
                          '  <xacro:property name="b" value="${a}"/>\n  <link name="${a}"/>\n',
}


@pytest.mark.parametrize("kind", sorted(PATHOLOGICAL))
@pytest.mark.parametrize("mode", ["--trusted", "--untrusted"])
def test_pathological_input_stops_within_the_limit(kind, mode, tmp_path):
    path = tmp_path / f"{kind}.urdf.xacro"
    path.write_text(HEAD + PATHOLOGICAL[kind] + TAIL, encoding="utf-8")
    with WallLessWaiting() as clock:
        result = run_urdftool("check", "--format", "json", mode, "--timeout", "1", path)
    elapsed = clock.seconds
    assert elapsed < 1 + 6, f"{kind} took {elapsed:.1f} s"  # 1 s limit, 1 s grace, slack
    assert result.code == 1, result.err
    rules = {d["rule"] for f in json.loads(result.out)["files"] for d in f["diagnostics"]}
    expected = "xacro.error" if kind == "recursive-property" else "xacro.limit-exceeded"
    assert expected in rules, rules


@pytest.mark.parametrize("mode", ["--trusted", "--untrusted"])
def test_huge_include_is_refused_without_reading_it(mode, tmp_path, monkeypatch):
    big = tmp_path / "big.xacro"
    with open(big, "wb") as stream:  # 1 GB, sparse: no disk used
        stream.truncate(1 << 30)
    path = tmp_path / "robot.urdf.xacro"
    path.write_text(HEAD + '  <xacro:include filename="big.xacro"/>\n' + TAIL)
    monkeypatch.chdir(tmp_path)
    with WallLessWaiting() as clock:  # wall time less the machine's other load
        result = run_urdftool("check", "--format", "json", mode, path)
    assert clock.seconds < 10
    diagnostics = [d for f in json.loads(result.out)["files"] for d in f["diagnostics"]]
    assert any(d["rule"] == "xacro.limit-exceeded" and "big.xacro" in d["message"]
               for d in diagnostics), diagnostics


def test_sandbox_memory_limit(tmp_path):
    """Code in the sandboxed reader that allocates past ``memory_mb`` gets a MemoryError, not
    the machine. (No xacro expression can do it any more: the interpreter's size budget stops
    them first.)"""
    from urdftool.sandbox import run_test_payload

    # what the child itself spent (CPU seconds): a loaded machine slows the wall clock of the
    # start, not this. (Not its ru_maxrss: Linux keeps the forked parent's across exec.)
    payload = """
import resource
def used():
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime
start = used()
fits = len(bytearray(64 << 20))  # under the limit: allowed (the limit, not a failure, refuses)
try:
    bytearray(4 << 30)
    refused = False
except MemoryError:
    refused = True
end = used()
result = [fits, refused, end - start]
"""
    answer = run_test_payload(payload, [tmp_path], memory_mb=256)
    fits, refused, cpu_seconds = answer["ok"]
    assert fits == 64 << 20 and refused and cpu_seconds < 2


@pytest.mark.parametrize("expression", [
    "'%100000000d' % 1", "'%*d' % (100000000, 1)", "'{:>100000000}'.format(1)",
    "'{:{}}'.format(1, 100000000)", "'x'.center(10**9)", "('x' * 10**7).replace('x', 'xx')",
    "math.factorial(10**6)", "'x' * 10**8", "[0] * 10**8", "python.range(10**9)",
    "1 << 10**9", "10**10**6",
])
def test_size_guards(expression):
    """Without the sandbox, expressions that would build gigabytes are stopped up front."""
    import xacro

    from urdftool.xacro_eval import Interpreter, LimitExceeded

    started = time.process_time()  # CPU: the machine's other load does not count
    with pytest.raises(LimitExceeded):
        Interpreter().evaluate(expression, xacro.Table(xacro._global_symbols))
    assert time.process_time() - started < 1


TETRAHEDRON = "solid t\n" + "".join(
    f"facet normal 0 0 0\nouter loop\n{a}\n{b}\n{c}\nendloop\nendfacet\n"
    for a, b, c in [("vertex 0 0 0", "vertex 0 1 0", "vertex 1 0 0"),
                    ("vertex 0 0 0", "vertex 1 0 0", "vertex 0 0 1"),
                    ("vertex 0 0 0", "vertex 0 0 1", "vertex 0 1 0"),
                    ("vertex 1 0 0", "vertex 0 1 0", "vertex 0 0 1")]) + "endsolid t\n"


def test_untrusted_meshes_only_inside_the_package(tmp_path):
    package = tmp_path / "pkg"
    (package / "meshes").mkdir(parents=True)
    (package / "package.xml").write_text("<package><name>pkg</name></package>")
    (package / "meshes" / "inside.stl").write_text(TETRAHEDRON)
    (tmp_path / "outside.stl").write_text(TETRAHEDRON)
    path = package / "robot.urdf"
    path.write_text('<robot name="r"><link name="a"><visual><geometry>'
                    '<mesh filename="meshes/inside.stl"/></geometry></visual><collision><geometry>'
                    '<mesh filename="../outside.stl"/></geometry></collision></link></robot>')

    def not_found(mode):
        report = json.loads(run_urdftool("check", "--format", "json", mode, "--select",
                                         "mesh.not-found", path).out)
        return [d["message"] for f in report["files"] for d in f["diagnostics"]]

    for mode in ("--untrusted", "--trusted"):  # one trust model (issue 20)
        (message,) = not_found(mode)
        assert "../outside.stl" in message and "outside-the-package-roots" in message


def test_untrusted_input_symlink_to_a_machine_file_is_not_read(tmp_path, monkeypatch):
    """A PR can commit a symlink: robot.urdf -> a secret of the CI machine. Reporting its
    'syntax errors' would print the secret into the CI log."""
    secret = tmp_path / "home" / "id_rsa"
    secret.parent.mkdir()
    secret.write_text("-----BEGIN hunter2 KEY-----\n")
    repo = tmp_path / "repo" / "robot_description"
    repo.mkdir(parents=True)
    (repo / "package.xml").write_text("<package><name>robot_description</name></package>")
    (repo / "robot.urdf").symlink_to(secret)
    monkeypatch.chdir(repo)
    for mode in ("--untrusted", "--trusted"):  # one trust model (issue 20)
        result = run_urdftool("check", mode, repo)
        assert result.code == 2 and "outside the repository" in result.err
        assert "hunter2" not in result.out + result.err and "home" not in result.err


@pytest.mark.parametrize("mode", ["--trusted", "--untrusted"])
def test_device_and_pipe_includes_are_refused(mode, tmp_path, monkeypatch):
    os.mkfifo(tmp_path / "pipe.xacro")
    (tmp_path / "zero.xacro").symlink_to("/dev/zero")
    path = tmp_path / "robot.urdf.xacro"
    path.write_text(HEAD + '  <xacro:include filename="pipe.xacro"/>\n'
                    '  <xacro:include filename="zero.xacro"/>\n'
                    '  <link name="${xacro.load_yaml(\'zero.xacro\')}"/>\n' + TAIL)
    monkeypatch.chdir(tmp_path)
    with WallLessWaiting() as clock:  # wall time less the machine's other load
        result = run_urdftool("check", "--format", "json", mode, path)
    assert clock.seconds < 10
    messages = [d["message"] for f in json.loads(result.out)["files"] for d in f["diagnostics"]
                if d["rule"].startswith("xacro.")]
    assert sum("pipe.xacro" in m or "zero" in m for m in messages) >= 2, messages


def test_untrusted_sdf_includes_only_inside_the_package(tmp_path, monkeypatch):
    """An SDF <include> may name any directory: under --untrusted only the package roots and
    the model paths the user gave are read."""
    outside = tmp_path / "machine" / "secret_model"
    outside.mkdir(parents=True)
    (outside / "model.config").write_text('<model><sdf version="1.7">model.sdf</sdf></model>')
    (outside / "model.sdf").write_text('<sdf version="1.7"><model name="hunter2">'
                                       '<link name="hunter2_link"/></model></sdf>')
    package = tmp_path / "robot_description"
    package.mkdir()
    (package / "package.xml").write_text("<package><name>robot_description</name></package>")
    path = package / "world.sdf"
    path.write_text('<sdf version="1.7"><model name="m"><link name="a"/><include>'
                    f"<uri>{outside}</uri></include></model></sdf>")
    monkeypatch.chdir(package)

    def include_findings(*mode):
        result = run_urdftool("check", "--format", "json", *mode, path)
        return result.out, [d["message"] for f in json.loads(result.out)["files"]
                            for d in f["diagnostics"] if d["rule"] == "sdf.include"]

    for mode in ("--untrusted", "--trusted"):  # one trust model (issue 20)
        out, (message,) = include_findings(mode)
        assert "outside the repository" in message and "hunter2" not in out
        out, messages = include_findings(mode, "--model-path", str(outside.parent))
        assert messages == []  # a folder the operator names is allowed
