"""urdftool.xacro_eval attacked: the escape classes of issue 12 through every command that reads
xacro, in both modes; denial-of-service expressions under ``--timeout 1``; YAML bombs.

Each escape payload would, if run, create a marker file or print a secret environment variable.
urdftool must report ``xacro.unsafe-expression`` at the payload's line (exit 1, or 2 with one
line for the commands that need a robot), write nothing, leak nothing, and stay within 4 s and
1 GB. ``test_plain_xacro_is_exploitable`` shows that the new payloads are real exploits against
plain xacro (skipped if a future xacro closes them).
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.conftest import WallLessWaiting, run_urdftool
from tests.test_security import ESCAPES, HEAD

XACRO_BIN = Path(sys.executable).parent / "xacro"
SECRET = "hunter2-interp"
# a moving joint after the payload, so that every command has a robot to work on
TAIL = ('  <link name="base"/>\n  <link name="tip"/>\n'
        '  <joint name="j" type="revolute"><parent link="base"/><child link="tip"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n'
        "</robot>\n")
COMMANDS = {  # command -> extra arguments
    "check": ["--format", "json"], "expand": [], "inertia": [], "limits": [], "tree": [],
    "dh": [], "jacobian": [], "sim": ["--duration", "0.05"],
}


def _touch(marker) -> str:
    return f"touch {marker}"


def _subclass_walk(marker, tmp):
    """3-arg-free class walk: object from mro(), its subclasses through vars(type), a
    function's __globals__ through object.__getattribute__, all dunders as string constants."""
    return ('  <link name="${[python.vars(o)[\'__getattribute__\'](python.vars(c)[\'__init__\'], '
            f'\'__glob\' + \'als__\')[\'system\'](\'{_touch(marker)}\') '
            'for o in [python.type(1).mro()[-1]] '
            'for c in python.vars(python.type)[\'__subclasses__\'](o) '
            'if \'_wrap_close\' in python.repr(c)]}"/>\n')


def _namespace_subscript(marker, tmp):
    """The same walk, every builtin taken by subscript on the python namespace."""
    return _subclass_walk(marker, tmp).replace("python.vars", "python['vars']") \
        .replace("python.type", "python['type']").replace("python.repr", "python['repr']")


def _class_building(marker, tmp):
    """type(name, bases, dict): a class whose method reaches globals."""
    return ('  <link name="${python.type(\'X\', (python.type(1).mro()[-1],), '
            'python.dict(run=python.map)).mro()}"/>\n')


def _dotified_format(marker, tmp):
    """The walk, with vars() carried under a dotify'd dict's 'format' key."""
    return _subclass_walk(marker, tmp).replace(
        "python.vars", "xacro.dotify(python.dict(format=python.vars)).format")


def _format_env(marker, tmp):
    """str.format walking __globals__ to os.environ: the dunder hides in a string constant."""
    return ('  <xacro:property name="rb" value="}"/>\n'
            '  <link name="${(\'{0.__globals__[os].environ[URDFTOOL_SECRET]\' + rb)'
            '.format(xacro.load_yaml)}"/>\n')


def _fstring_frame(marker, tmp):
    """The generator-frame walk inside an f-string, in a YAML unit (xacro's lexer ends ${...} at
    the first brace; a YAML value has no such limit)."""
    (tmp / "f.yaml").write_text(
        "angle: !degrees \"len(f'{[*(g:=(g.gi_frame.f_back.f_back.f_globals[\\\"os\\\"]"
        f".system(\\\"{_touch(marker)}\\\") for _ in [1]))]}}') and 0\"\n", encoding="utf-8")
    return '  <link name="${xacro.load_yaml(\'f.yaml\')[\'angle\']}"/>\n'


def _yaml_format(marker, tmp):
    """YAML data carrying a 'format' key, called as the string method."""
    (tmp / "fmt.yaml").write_text("format: '{0.__globals__}'\n", encoding="utf-8")
    return ('  <link name="${xacro.load_yaml(\'fmt.yaml\').format.format(xacro.load_yaml)'
            '[\'os\'].system(\'x\')}"/>\n')


ATTACKS = {
    **ESCAPES,  # frame-walk (walrus), lambda-generator, comprehension-self-reference,
    # eval-builtins ($(eval)), yaml-unit-expression (!degrees)
    "subclass-walk": _subclass_walk,
    "namespace-subscript": _namespace_subscript,
    "class-building": _class_building,
    "dotified-format": _dotified_format,
    "format-env": _format_env,
    "fstring-frame": _fstring_frame,
    "yaml-format": _yaml_format,
}


def _write(tmp_path: Path, kind: str) -> tuple[Path, Path]:
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "package.xml").write_text("<package><name>pkg</name></package>")
    marker = tmp_path / f"PWNED-{kind}"
    path = package / "robot.urdf.xacro"
    path.write_text(HEAD + ATTACKS[kind](marker, package) + TAIL, encoding="utf-8")
    return path, marker


def _peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


@pytest.mark.parametrize("kind", sorted(ATTACKS))
def test_attack_is_refused_by_every_command(kind, tmp_path, monkeypatch):
    path, marker = _write(tmp_path, kind)
    monkeypatch.chdir(path.parent)
    monkeypatch.setenv("URDFTOOL_SECRET", SECRET)
    for command, extra in COMMANDS.items():
        for mode in ("--trusted", "--untrusted"):
            before = _peak_rss_mb()
            with WallLessWaiting() as clock:  # wall time less the machine's other load
                result = run_urdftool(command, mode, *extra, path)
            elapsed = clock.seconds
            what = f"{kind}: urdftool {command} {mode}"
            assert not marker.exists(), f"{what} ran the payload"
            assert SECRET not in result.out + result.err, f"{what} leaked the secret"
            assert "Traceback" not in result.err, what
            assert elapsed < 4, f"{what} took {elapsed:.1f} s"
            assert _peak_rss_mb() - before < 1024, what
            assert "unsafe expression" in result.out + result.err, \
                f"{what}: {result.out[-500:]} {result.err[-500:]}"
            assert result.code == 1, f"{what}: {result.err}"  # a located finding, every command
    report = json.loads(run_urdftool("check", "--format", "json", path).out)
    unsafe = [d for d in report["files"][0]["diagnostics"]
              if d["rule"] == "xacro.unsafe-expression"]
    assert unsafe and all(d["line"] for d in unsafe), report


@pytest.mark.parametrize("kind", ["subclass-walk", "namespace-subscript", "dotified-format",
                                  "fstring-frame"])
def test_plain_xacro_is_exploitable(kind, tmp_path):
    """The other half: these payloads do run under plain xacro."""
    path, marker = _write(tmp_path, kind)
    subprocess.run([str(XACRO_BIN), str(path)], capture_output=True, timeout=60,
                   cwd=path.parent, check=False)
    assert marker.exists(), f"plain xacro (xacro<3, pinned) no longer runs the {kind} payload: " \
        "update this half"


# -- denial of service: each stops within 4 s and 1 GB under --timeout 1 ----------------------

def _doubled(levels: int) -> str:
    """[[x, x] for x in [[y, y] for y in ...]]: a list of 2**levels leaves, shared."""
    text = "[[0] * 10**4]"
    for level in range(levels):
        text = f"[[v{level}, v{level}] for v{level} in {text}]"
    return text


BRACES = '  <xacro:property name="lb" value="{"/><xacro:property name="rb" value="}"/>\n'
DOS = {
    "tokenize-backtracking": "xacro.tokenize('a' * 40, 'b]|(a+)+c|[b')",
    "tokenize-long": "python.len(xacro.tokenize('a,' * 10**6))",
    "sum-of-lists": "python.len(python.sum([[0] * 1000 for i in python.range(10**5)], []))",
    "prod-of-range": "math.prod(python.range(1, 10**7))",
    "nested-repr": "python.len(python.str([[[[[[0] * 10] * 10] * 10] * 10] * 10] * 100))",
    "format-width": "(lb + ':1000000000' + rb).format(1)",
    "fstring-width": "$(eval f'{1:{10**9}}')",
    "percent-width": "'%1000000000d' % 1",
    "to-bytes": "(10**100000).to_bytes(10**6, 'big')",
    "join-huge": "'x'.join(['y' * 10**5] * 10**5)",
    "translate": "('x' * 10**6).translate(python.dict([(120, 'y' * 10**4)]))",
    "replace": "('x' * 10**6).replace('x', 'y' * 10**4)",
    "power": "10**10**8",
    "shift": "1 << 10**10",
    "str-of-int": "python.len(python.str(2 ** 60000))",
    "factorial": "math.factorial(10**7)",
    "range-loop": "python.sum(1 for i in python.range(10**6) for j in python.range(10**6))",
    # one sort is ~0.7 s on a fast machine: a hundred of them only stop at the deadline
    "sort-key-loop": "python.sum(python.len(python.sorted(python.range(10**6), key=str))"
                     " for j in python.range(100))",
    "compare-shared": " == ".join([_doubled(12)] * 2),  # 4096 x 10 000 items, shared
}


@pytest.mark.parametrize("kind", sorted(DOS))
def test_denial_of_service_is_bounded(kind, tmp_path):
    path = tmp_path / "dos.urdf.xacro"
    text = DOS[kind] if DOS[kind].startswith("$") else f"${{{DOS[kind]}}}"
    path.write_text(HEAD + BRACES + f'  <link name="{text}"/>\n' + TAIL, encoding="utf-8")
    before = _peak_rss_mb()
    with WallLessWaiting() as clock:  # a --timeout is wall time: less the machine's load
        result = run_urdftool("check", "--format", "json", "--trusted", "--timeout", "1", path)
    elapsed = clock.seconds
    assert elapsed < 4, f"{kind} took {elapsed:.1f} s"
    assert _peak_rss_mb() - before < 1024, f"{kind}: {_peak_rss_mb() - before:.0f} MB"
    assert result.code == 1, result.err
    rules = {d["rule"] for f in json.loads(result.out)["files"] for d in f["diagnostics"]}
    assert rules & {"xacro.limit-exceeded", "xacro.unsafe-expression"}, rules


def test_yaml_alias_bomb_is_refused(tmp_path, monkeypatch):
    lines = ["a0: &a0 [x, x, x, x, x, x, x, x, x, x]"]
    lines += [f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 10) + "]" for i in range(1, 9)]
    (tmp_path / "bomb.yaml").write_text("\n".join(lines) + "\n", encoding="utf-8")
    path = tmp_path / "robot.urdf.xacro"
    path.write_text(HEAD + '  <link name="${python.len(python.str(xacro.load_yaml('
                    '\'bomb.yaml\')))}"/>\n' + TAIL, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    with WallLessWaiting() as clock:  # a --timeout is wall time: less the machine's load
        result = run_urdftool("check", "--format", "json", "--trusted", "--timeout", "1", path)
    assert clock.seconds < 4
    rules = {d["rule"] for f in json.loads(result.out)["files"] for d in f["diagnostics"]}
    assert "xacro.limit-exceeded" in rules, rules


def test_yaml_units_go_through_the_interpreter(tmp_path, monkeypatch):
    """!degrees/!radians values are expressions over xacro's global symbols, as in xacro; a
    property of the file is not visible, Python internals are refused."""
    (tmp_path / "units.yaml").write_text(
        "a: !degrees 90\nb: !radians pi / 4\nc: !millimeters 2 * 5\n"
        "d: !degrees python.len([1, 2]) * 45\n", encoding="utf-8")
    path = tmp_path / "robot.urdf.xacro"
    path.write_text(HEAD + '  <xacro:property name="u" value="${xacro.load_yaml(\'units.yaml\')}"/>'
                    '\n  <link name="l_${u.a}_${u.b}_${u.c}_${u.d}"/>\n' + TAIL, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    ours = run_urdftool("expand", "--trusted", path)
    plain = subprocess.run([str(XACRO_BIN), str(path)], capture_output=True, text=True,
                           timeout=60, cwd=tmp_path, check=False)
    assert ours.code == 0, ours.err
    name = f"l_{math_pi() / 2}_{math_pi() / 4}_{0.01}_{math_pi() / 2}"
    assert f'name="{name}"' in ours.out
    if plain.returncode == 0:
        assert f'name="{name}"' in plain.stdout


def math_pi() -> float:
    import math

    return math.pi


def test_secret_is_not_reachable_through_env_in_expressions(tmp_path, monkeypatch):
    """No expression function reads the environment: only $(env)/$(optenv), which
    --untrusted restricts to --allow-env."""
    monkeypatch.setenv("URDFTOOL_SECRET", SECRET)
    path = tmp_path / "robot.urdf.xacro"
    path.write_text(HEAD + '  <link name="${xacro.arg(\'URDFTOOL_SECRET\')}"/>\n'
                    '  <link name="$(eval optenv(\'URDFTOOL_SECRET\', \'none\'))"/>\n' + TAIL,
                    encoding="utf-8")
    result = run_urdftool("expand", "--untrusted", path)
    assert SECRET not in result.out + result.err
    assert os.environ["URDFTOOL_SECRET"] == SECRET


@pytest.mark.parametrize("text,sep", [
    ("a, b;c d", ",; "), ("a,,b", ","), (",a,b,", ","), ("a-b_c", "-_"), ("a1b22c", "0-9"),
    ("a b\tc", "\\s"), ("x^y", "\\^"), ("abc", "^b"), ("a]b", "]"), ("a\\b", "\\\\"),
])
def test_tokenize_splits_as_xacros_regex_does(text, sep):
    """xacro.tokenize builds re.split('[sep]'); urdftool reads the class itself: same parts."""
    import re

    import xacro

    from urdftool.xacro_eval import Interpreter

    for skip in (True, False):
        expected = [p for p in re.split(f"[{sep}]", text) if p or not skip]
        ours = Interpreter().evaluate(f"xacro.tokenize({text!r}, {sep!r}, {skip})",
                                      xacro.Table(xacro._global_symbols))
        assert ours == expected, (text, sep, skip)


def test_tokenize_never_backtracks():
    """A separator that closes xacro's character class (re.split('[b]|(a+)+c|[b]'):
    catastrophic backtracking in plain xacro) is refused, at once."""
    import xacro

    from urdftool.xacro_eval import Interpreter, UnsafeExpression

    started = time.process_time()  # CPU: the machine's other load does not count
    with pytest.raises(UnsafeExpression, match="character class"):
        Interpreter().evaluate("xacro.tokenize('a' * 40, 'b]|(a+)+c|[b')",
                               xacro.Table(xacro._global_symbols))
    assert time.process_time() - started < 1


PARITY_DOCUMENT = HEAD + """\
  <xacro:macro name="v" params="tokens valid name">
    <xacro:property name="_unknown_" value="${python.set(tokens) - python.set(valid)}"/>
    <xacro:if value="${_unknown_}">${xacro.error('Unknown '+name+': '+', '.join(_unknown_))}</xacro:if>
    <link name="${name}_${'_'.join(python.sorted(python.set(tokens) &amp; python.set(valid)))}"/>
  </xacro:macro>
  <xacro:v tokens="${['a','b']}" valid="${['a','b','c']}" name="x"/>
  <xacro:v tokens="${['a','z']}" valid="${['a','b','c']}" name="y"/>
  <xacro:property name="d" value="${python.dict(k=1, j='v', m=[1, 2])}"/>
  <xacro:property name="fs" value="${python.frozenset('abc')}"/>
  <link name="sets_${'a' in fs}_${fs &gt;= python.set('a')}_${python.set([1]) &lt; python.set([1, 2])}_${python.len(fs ^ python.set('aq'))}_${python.bool(python.set())}_${python.sorted(fs | python.set('z'))[-1]}_${fs.isdisjoint('xy')}"/>
  <link name="dicts_${python.sorted(d.keys() - python.set('k'))}_${python.list(d.values())[0]}_${'k' in d.keys()}_${python.len(python.dict(d, n=2))}_${python.sorted(d)[0]}_${python.sorted(d.items())[0]}"/>
  <link name="comp_${[v * 2 for v in python.range(3) if v]}_${python.sorted(python.set(v % 2 for v in python.range(5)))}_${python.dict((k, k.upper()) for k in 'ab')['b']}_${python.sum(v for v in python.range(4))}_${[a + b for a in 'ab' if a for b in 'cd']}"/>
  <link name="slice_${'abcdef'[1:5:2]}_${[1, 2, 3][::-1]}_${python.list(python.range(10))[python.slice(2, 8, 3)]}_${python.range(10)[-3:]}"/>
  <link name="str_${'a_b'.split('_')}_${'x'.center(5, '*')}_${'AbC'.swapcase()}_${'%05.2f' % 3.14159}_${' x '.strip().title()}_${'a,b'.partition(',')}"/>
  <link name="builtins_${python.divmod(7, 2)}_${python.type(1) == python.int}_${python.isinstance(fs, python.frozenset)}_${python.complex(1, 2).imag}_${python.list(python.zip('ab', python.reversed([1, 2])))}_${python.max([3, 1, 2], key=lambda v: -v)}"/>
  <link name="lambda_${python.list(python.map(lambda a, b=10: a + b, [1, 2]))}_${(lambda *r, k=2: (r, k))(1, k=3)}"/>
""" + TAIL


def test_documents_expand_as_plain_xacro(tmp_path, monkeypatch):
    """Sets (operators, membership, truth value), dicts and their views, comprehensions,
    slices, string methods, ``python.*`` builtins and lambdas: the same document from plain
    xacro and from urdftool (issue 29's token check: ``'set' object is not subscriptable``)."""
    from lxml import etree

    path = tmp_path / "parity.urdf.xacro"
    path.write_text(PARITY_DOCUMENT, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    plain = subprocess.run([str(XACRO_BIN), str(path)], capture_output=True, text=True,
                           timeout=60, cwd=tmp_path, check=True)
    assert "Unknown y: z" in plain.stderr  # the file's own check fires in plain xacro

    def names(text):
        root = etree.fromstring(text.encode())
        return [element.get("name") for element in root.iter("link")]

    expected = names(plain.stdout)
    assert len(expected) == 11 and "x_a_b" in expected, expected
    for mode in ("--trusted", "--untrusted"):
        ours = run_urdftool("expand", mode, path)
        assert ours.code == 0, ours.err
        assert names(ours.out) == expected
