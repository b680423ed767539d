"""Red team: hostile files through every reading command, trusted and untrusted (``CI=true``).

Each case is a file written as an attacker would (expression escapes, YAML tricks,
substitutions, files outside the package, devices and symlinks, XML bombs, mesh bombs, names
that inject CI commands or terminal escapes, hostile SDF), run through the commands it
reaches, in both modes. Every run must leave no marker file, print no byte of a secret
environment variable (stdout, stderr, and any file it writes), finish under 4 s (wall time,
less the time other processes' load kept it waiting for a CPU), print no traceback, never
let file content start a line a CI runner executes; and the peak memory of
all runs (urdftool's process and its sandboxed readers) stays under 1 GB.

The runs of a mode go through one process (``tests/redteam_batch.py``, the CLI in-process),
so that the whole corpus costs seconds: one package holds most cases, so one sandboxed
reader serves them.
"""

from __future__ import annotations

import json
import os
import re
import struct
import zipfile
from pathlib import Path

import pytest

from tests.redteam_batch import run_plan

SECRET = "hunter2-redteam-7a9c"
ALL = ["check", "expand", "inertia", "limits", "tree", "dh", "jacobian", "sim"]
SDF_ALL = ["check", "convert", "inertia", "limits", "tree", "dh", "jacobian", "sim"]
EXTRA = {"jacobian": ["--tip", "tip"], "sim": ["--duration", "0.05"], "dh": ["--tip", "tip"]}
SECONDS, MEGABYTES = 4.0, 1024
HEAD = '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
ARM = ('  <link name="base"/>\n  <link name="tip"><inertial><mass value="1"/><inertia ixx="1" '
       'iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>{extra}</link>\n'
       '  <joint name="j" type="revolute"><parent link="base"/><child link="tip"/>'
       '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n')
SDF_HEAD = '<?xml version="1.0"?>\n<sdf version="1.7">'
# a line a CI runner executes (GitHub Actions, Azure Pipelines), or raw terminal controls
INJECTED = re.compile(r"(?m)^\s*(::|##\[|##vso\[)|##vso\[|[\x1b\x9b\u202e\u2066-\u2069]")


class Corpus:
    def __init__(self, base: Path):
        self.base = base
        self.package = self.new_package("redteam_pkg")
        self.cases: dict[str, tuple[Path, list[str]]] = {}

    def new_package(self, name: str) -> Path:
        package = self.base / name
        (package / "urdf").mkdir(parents=True)
        (package / "package.xml").write_text(f"<package><name>{name}</name></package>")
        return package

    def marker(self, name: str) -> Path:
        return self.base / f"MARKER-{name}"

    def file(self, name: str, relative: str, text: str | bytes, package: Path | None = None):
        path = (package or self.package) / name / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(text if isinstance(text, bytes) else text.encode("utf-8"))
        return path

    def xacro(self, name, body, commands=ALL, extra="", package=None):
        path = self.file(name, "robot.urdf.xacro", HEAD + body + ARM.format(extra=extra) +
                         "</robot>\n", package)
        self.cases[name] = (path, commands)
        return path.parent

    def urdf(self, name, extra="", commands=ALL, robot="r", package=None, text=None):
        path = self.file(name, "robot.urdf", text if text is not None else
                         f'<robot name="{robot}">\n' + ARM.format(extra=extra) + "</robot>\n",
                         package)
        self.cases[name] = (path, [c for c in commands if c != "expand"])
        return path.parent

    def sdf(self, name, model, commands=SDF_ALL, package=None, prolog=""):
        path = self.file(name, "model.sdf", f'<?xml version="1.0"?>\n{prolog}<sdf version="1.7">'
                         f"{model}</sdf>\n", package)
        self.cases[name] = (path, commands)
        return path.parent

    def link(self, name, relative, target, package=None):
        path = (package or self.package) / name / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.symlink_to(target)
        return path


def _touch(corpus, name):
    return f"touch {corpus.marker(name)}"


def _laughs(root: str) -> str:
    entities = '<!ENTITY a0 "hahahahahaha">' + "".join(
        f'<!ENTITY a{i} "{("&a" + str(i - 1) + ";") * 10}">' for i in range(1, 10))
    return f"<!DOCTYPE {root} [{entities}]>"


def _zip(path: Path, member: str, size: int) -> None:
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr(member, b"<COLLADA>" + b" " * size + b"</COLLADA>")


def expression_escapes(c: Corpus) -> None:
    """Expressions that reach Python objects: each would touch its marker."""
    walk = ("[*(g:=(g.gi_frame.f_back.f_back.f_globals['os'].system('{cmd}') "
            "for _ in [1]))]")
    escapes = {
        "frame-walk": "${" + walk + "}",
        "subclass-walk": "${[c for c in ().__class__.__base__.__subclasses__() "
                         "if c.__name__ == '_wrap_close'][0].__init__.__globals__['system']"
                         "('{cmd}')}",
        "string-dunder": "${python.getattr(python.getattr(1, '__cla' + 'ss__'), '__bases__')}",
        "namespace-subscript": "${python['vars'](python['type'])['__subclasses__']"
                               "(python['type'](1).mro()[-1])}",
        "class-building": "${python.type('X', (), python.dict(f=python.map))}",
        "format-globals": "${'{0.__init__.__globals__[os].system}'.format(xacro.arg)}",
        "percent-repr": "${'%r' % (python.vars(xacro),)}",
        "eval-import": "$(eval __import__('os').system('{cmd}'))",
        "eval-exec": "$(eval exec('import os; os.system(\"{cmd}\")'))",
        "fstring-walk": "${f'{(lambda: 0).__globals__}'}",
        "dotify-callable": "${xacro.dotify(python.dict(format=python.exec)).format('{cmd}')}",
        "yaml-construct": "${xacro.load_yaml('python.yaml')}",
        "yaml-degrees": "${xacro.load_yaml('degrees.yaml')['a']}",
    }
    for index, (name, expression) in enumerate(escapes.items()):
        expression = expression.replace("{cmd}", _touch(c, name))
        # check, and one other command each in turn (tests/test_xacro_interpreter.py runs
        # its attacks through every command)
        directory = c.xacro(name, f'  <link name="n{_attr(expression)}"/>\n',
                            commands=["check", ALL[1 + index % 7]])
        (directory / "python.yaml").write_text(
            f"a: !!python/object/apply:os.system ['{_touch(c, name)}']\n")
        (directory / "degrees.yaml").write_text(
            f'a: !degrees "{walk.format(cmd=_touch(c, name))}"\n')


def _attr(text: str) -> str:
    return text.replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;")


def denial_of_service(c: Corpus) -> None:
    """Time and memory: each is stopped by a size check or the deadline."""
    one = ["check", "tree"]
    SLOW = ("exponential-macro",)  # the default deadline: 3 s
    exprs = {
        "exponential-macro": '<xacro:macro name="t" params="n"><xacro:if value="${n > 0}">'
                             '<xacro:t n="${n-1}"/><xacro:t n="${n-1}"/></xacro:if><a/>'
                             '</xacro:macro><xacro:t n="40"/>',
        "recursive-macro": '<xacro:macro name="m"><xacro:m/></xacro:macro><xacro:m/>',
        "recursive-property": '<xacro:property name="a" value="${b}"/>'
                              '<xacro:property name="b" value="${a}"/><link name="${a}"/>',
        "doubling-properties": "".join(
            f'<xacro:property name="p{i}" value="${{[p{i - 1}, p{i - 1}]}}"/>' if i else
            '<xacro:property name="p0" value="x"/>' for i in range(64))
        + '<link name="${len(str(p63))}"/>',
        "nested-loops": '<link name="${python.sum([1 for i in python.range(10**7) '
                        'for j in python.range(10**7)])}"/>',
        "huge-power": '<link name="${10**10**10}"/>',
        "huge-repeat": '<link name="${\'x\' * 10**10}"/>',
        "format-width": '<link name="${\'{:>999999999}\'.format(1)}"/>',
        "deep-unary": '<link name="${' + "-" * 100_000 + '1}"/>',
        "long-sum": '<link name="${' + "+".join(["1"] * 100_000) + '}"/>',
        "deep-parentheses": '<link name="${' + "(" * 3000 + "1" + ")" * 3000 + '}"/>',
        "int-to-str": '<link name="${str(7**40000)}"/>',
        "math-comb": '<link name="${math.comb(10**7, 5*10**6) % 7}"/>',
        "sorted-keys": '<link name="${python.sorted(python.range(10**6), '
                       'key=lambda x: -x)}"/>',
        "tokenize-regex": '<link name="${xacro.tokenize(\'a\' * 5000, \'(a*)*b\')}"/>',
        "nested-repr": '<link name="${str([[[[[[[[[[[[[[[[[[[[[[[[1]]]]]]]]]]]]]]]]]]]]]]] '
                       '* 100000)}"/>',
    }
    for name, body in exprs.items():
        c.xacro(name, "  " + body + "\n", commands=["check"] if name in SLOW else one)
    c.xacro("macro-flood", '<xacro:macro name="t" params="n"><xacro:if value="${n > 0}">'
            '<xacro:t n="${n-1}"/><xacro:t n="${n-1}"/></xacro:if></xacro:macro>'
            '<xacro:t n="40"/>', commands=["limits", "jacobian"])


def yaml_tricks(c: Corpus) -> None:
    aliases = "a: &a [x,x,x,x,x,x,x,x,x,x]\n" + "".join(
        f"{b}: &{b} [{', '.join(['*' + a] * 10)}]\n" for a, b in zip("abcdefgh", "bcdefghi"))
    files = {
        "yaml-alias-bomb": aliases,
        "yaml-deep": "[" * 50_000 + "]" * 50_000,
        "yaml-huge": "a: " + "x" * (3 << 20) + "\n",
        "yaml-many-keys": "".join(f"k{i}: {{a: [1, 2]}}\n" for i in range(90_000)),
        "yaml-merge-keys": "base: &b {x: 1}\n" + "".join(
            f"m{i}: {{<<: *b, y: {i}}}\n" for i in range(2000)),
    }
    for name, text in files.items():
        directory = c.xacro(name, '  <link name="${len(str(xacro.load_yaml(\'d.yaml\')))}"/>\n',
                            commands=["check", "inertia"])
        (directory / "d.yaml").write_text(text)


def substitutions_and_paths(c: Corpus) -> None:
    """Reading the environment and files outside the package."""
    env = {
        "env": '<link name="a$(env URDFTOOL_TEST_SECRET)"/>',
        "optenv": '<link name="a$(optenv URDFTOOL_TEST_SECRET none)"/>',
        "arg-default-env": '<xacro:arg name="a" default="$(optenv URDFTOOL_TEST_SECRET q)"/>'
                           '<link name="a$(arg a)"/>',
        "eval-optenv": '<link name="$(eval optenv(\'URDFTOOL_TEST_SECRET\', \'d\'))"/>',
    }
    for name, body in env.items():  # trusted reads variables as xacro does (your own files)
        c.xacro(name, "  " + body + "\n", commands=["check", "expand", "limits", "sim"])
    outside = {
        "include-proc-environ": '<xacro:include filename="/proc/self/environ"/>',
        "include-parent-environ": '<xacro:include filename="/proc/${1}/environ"/>',
        "yaml-proc-environ": '<link name="${xacro.load_yaml(\'/proc/self/environ\')}"/>',
        "include-etc-glob": '<xacro:include filename="/etc/*"/>',
        "include-find-escape": '<xacro:include filename="$(find redteam_pkg)/../../../../../'
                               '../../etc/passwd"/>',
        "include-devzero-link": '<xacro:include filename="zero.xacro"/>',
        "include-environ-link": '<xacro:include filename="environ.xacro"/>',
        "include-fifo": '<xacro:include filename="fifo.xacro"/>',
        "unprefixed-include-devzero": '<include filename="zero.xacro"/>',
    }
    for name, body in outside.items():
        directory = c.xacro(name, "  " + body + "\n", commands=["check", "expand", "tree"])
        (directory / "zero.xacro").symlink_to("/dev/zero")
        (directory / "environ.xacro").symlink_to("/proc/self/environ")
        os.mkfifo(directory / "fifo.xacro")
    # the robot file itself
    for name, target in (("input-devzero", "/dev/zero"), ("input-environ", "/proc/self/environ"),
                         ("input-passwd", "/etc/passwd")):
        path = c.link(name, "robot.urdf", target)
        c.cases[name] = (path, ["check", "tree", "sim"])
    huge = c.package / "input-huge" / "robot.urdf"
    huge.parent.mkdir()
    with open(huge, "wb") as stream:
        stream.truncate(200 << 20)  # sparse
    c.cases["input-huge"] = (huge, ["check", "limits"])
    # configuration files of a package of its own
    for name, config, target in (("config-devzero", "urdftool.toml", "/dev/zero"),
                                 ("config-environ", "pyproject.toml", "/proc/self/environ")):
        package = c.new_package(name)
        (package / config).symlink_to(target)
        c.urdf(name, package=package, commands=["check"])
    package = c.new_package("package-xml-devzero")
    (package / "package.xml").unlink()
    (package / "package.xml").symlink_to("/dev/zero")
    c.urdf("package-xml-devzero", package=package, commands=["check", "tree"])


def xml_tricks(c: Corpus) -> None:
    xxe = '<!DOCTYPE robot [<!ENTITY x SYSTEM "file:///proc/self/environ">]>'
    robot = '<robot name="r&x;">' + ARM.format(extra="") + "</robot>"
    c.urdf("urdf-xxe", text=f'<?xml version="1.0"?>\n{xxe}\n{robot}',
           commands=["check", "tree", "sim"])
    c.urdf("urdf-laughs", text='<?xml version="1.0"?>\n' + _laughs("robot")
           + robot.replace("&x;", "&a9;"), commands=["check", "limits"])
    c.urdf("urdf-external-dtd", text='<?xml version="1.0"?>\n<!DOCTYPE robot SYSTEM '
           '"http://127.0.0.1:9/robot.dtd">\n' + robot.replace("&x;", ""), commands=["check"])
    c.urdf("urdf-xinclude", text='<robot name="r" xmlns:xi="http://www.w3.org/2001/XInclude">'
           '<xi:include href="/proc/self/environ" parse="text"/>' + ARM.format(extra="")
           + "</robot>", commands=["check", "tree"])
    c.urdf("urdf-deep", extra="<a>" * 50_000 + "</a>" * 50_000, commands=["check", "inertia"])
    c.urdf("urdf-unclosed", extra="<a " * 20_000, commands=["check", "tree"])
    c.urdf("urdf-attribute-flood", extra="<a " + " ".join(f'a{i}="1"' for i in range(100_000))
           + "/>", commands=["check", "limits"])
    directory = c.xacro("xacro-xxe-include", '  <xacro:include filename="inc.xacro"/>\n',
                        commands=["check", "expand"])
    (directory / "inc.xacro").write_text(f'<?xml version="1.0"?>{xxe}<robot xmlns:xacro='
                                         '"http://www.ros.org/wiki/xacro"><link name="&x;"/>'
                                         "</robot>")
    path = c.file("xacro-laughs", "robot.urdf.xacro", '<?xml version="1.0"?>\n' + _laughs("robot")
                  + HEAD.split("\n", 1)[1] + '  <link name="&a9;"/>\n' + ARM.format(extra="")
                  + "</robot>\n")
    c.cases["xacro-laughs"] = (path, ["check", "expand", "dh"])
    c.xacro("xacro-deep", "<a>" * 50_000 + "</a>" * 50_000, commands=["check", "expand"])


def mesh_bombs(c: Corpus) -> None:
    def mesh(name, filename, commands=("check", "inertia", "sim")):
        c.urdf(name, extra=f'<collision><geometry><mesh filename="{filename}"/></geometry>'
               "</collision>", commands=list(commands))
        return c.package / name

    _zip(mesh("zae-bomb", "bomb.zae") / "bomb.zae", "m.dae", 300 << 20)
    _zip(mesh("zae-under-limit", "big.zae") / "big.zae", "m.dae", 60 << 20)
    c.link("stl-devzero", "m.stl", "/dev/zero")
    mesh("stl-devzero", "m.stl")
    c.link("obj-environ", "m.obj", "/proc/self/environ")
    mesh("obj-environ", "m.obj")
    directory = mesh("stl-lying-count", "m.stl")
    (directory / "m.stl").write_bytes(b"\0" * 80 + struct.pack("<I", 2**32 - 1) + b"\0" * 500)
    directory = mesh("stl-degenerate", "m.stl")
    record = b"\0" * 12 + struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + b"\0\0"
    (directory / "m.stl").write_bytes(b"\0" * 80 + struct.pack("<I", 400_000)
                                      + record * 400_000)
    directory = mesh("obj-flood", "m.obj")  # 34 MB: parsed in the reader in both modes
    (directory / "m.obj").write_bytes(b"v 0 0 0\nv 1 0 0\nv 0 1 0\n" + b"f 1 2 3\n" * 4_300_000)
    directory = mesh("dae-xxe", "m.dae")
    (directory / "m.dae").write_text(
        '<?xml version="1.0"?><!DOCTYPE COLLADA [<!ENTITY x SYSTEM "file:///proc/self/environ">'
        ']><COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">'
        "<asset><contributor><author>&x;</author></contributor></asset></COLLADA>")
    directory = mesh("dae-laughs", "m.dae")
    (directory / "m.dae").write_text('<?xml version="1.0"?>' + _laughs("COLLADA")
                                     + "<COLLADA><asset><title>&a9;</title></asset></COLLADA>")


def injections(c: Corpus) -> None:
    names = "n&#10;::error title=x::pwned&#10;##vso[task.setvariable]x&#x1b;[31m&#x202e;&#x2066;"
    body = ARM.format(extra="").replace('"tip"', f'"tip{names}"').replace('"j"', f'"j{names}"')
    c.urdf("inject-names", text=f'<robot name="r{names}">{body}</robot>', commands=ALL)
    c.xacro("inject-expression", '  <link name="${\'\\n::error::x\\n\\x1b[2J\'}"/>\n'
            '  <link name="${\'%c\' % 10}::warning::y"/>\n', commands=["check", "tree"])
    c.sdf("inject-sdf", f'<model name="m{names}"><link name="a{names}"/><link name="b"/>'
          f'<joint name="j{names}" type="revolute"><parent>a{names}</parent><child>b</child>'
          "<axis><xyz>0 0 1</xyz></axis></joint></model>")
    c.sdf("inject-sdf-controls", '<model name="m&#x1b;[2J&#x9b;"><link name="a&#7;"/></model>',
          commands=["check", "convert"])
    evil = c.package / "inject-path" / "a\n::error::pwned\x1b[31m.urdf"
    evil.parent.mkdir()
    evil.write_text('<robot name="r">' + ARM.format(extra="") + "<bad</robot>")
    c.cases["inject-path"] = (evil, ["check", "tree"])


def sdf_tricks(c: Corpus) -> None:
    c.sdf("sdf-xxe", '<model name="m&x;"><link name="a"/></model>',
          prolog='<!DOCTYPE sdf [<!ENTITY x SYSTEM "file:///proc/self/environ">]>')
    c.sdf("sdf-laughs", '<model name="&a9;"><link name="a"/></model>', prolog=_laughs("sdf"),
          commands=["check", "convert"])
    c.sdf("sdf-model-uri-escape", '<model name="m"><link name="a"/><include>'
          "<uri>model://../../../../../../../proc/self</uri></include></model>",
          commands=["check", "convert", "tree"])
    c.sdf("sdf-include-devzero", '<model name="m"><link name="a"/><include><uri>/dev/zero</uri>'
          "</include></model>", commands=["check", "convert"])
    directory = c.sdf("sdf-include-links", '<model name="m"><link name="a"/><include>'
                      "<uri>sub</uri></include></model>", commands=["check", "convert"])
    (directory / "sub").mkdir()
    (directory / "sub" / "model.config").symlink_to("/dev/zero")
    (directory / "sub" / "model.sdf").symlink_to("/proc/self/environ")
    directory = c.sdf("sdf-recursive-include", '<model name="m"><link name="a"/><include>'
                      "<uri>sub</uri></include></model>", commands=["check", "convert"])
    (directory / "sub").mkdir()
    (directory / "sub" / "model.sdf").write_text(
        '<sdf version="1.7"><model name="x"><link name="l"/><include><uri>../sub</uri>'
        "<name>y</name></include></model></sdf>")
    c.sdf("sdf-mesh-environ", '<model name="m"><link name="a"><collision name="c"><geometry>'
          "<mesh><uri>file:///proc/self/environ</uri></mesh></geometry></collision></link>"
          "</model>", commands=["check", "convert", "sim"])
    c.sdf("sdf-frame-chain", '<model name="m">' + "".join(
        f'<frame name="f{i}" attached_to="f{i + 1}"/>' for i in range(3000))
        + '<frame name="f3000" attached_to="f0"/><link name="a"/></model>',
        commands=["check", "convert", "tree"])
    c.sdf("sdf-deep", '<model name="m">' + "<a>" * 30_000 + "</a>" * 30_000 + "</model>",
          commands=["check", "convert"])


BUILDERS = (expression_escapes, denial_of_service, yaml_tricks, substitutions_and_paths,
            xml_tricks, mesh_bombs, injections, sdf_tricks)
# stopped by the deadline only: one shows the default --timeout holds the 4 s, the others are
# given 0.5 s (the mechanism is the same; the corpus stays fast)
DEADLINE_BOUND = {"macro-flood", "doubling-properties", "yaml-many-keys", "nested-loops"}


@pytest.fixture(scope="module")
def corpus(tmp_path_factory) -> Corpus:
    corpus = Corpus(tmp_path_factory.mktemp("redteam"))
    for build in BUILDERS:
        build(corpus)
    return corpus


def test_the_corpus_covers_every_command_and_class(corpus):
    commands = {command for _, listed in corpus.cases.values() for command in listed}
    assert commands == {"check", "expand", "inertia", "limits", "tree", "dh", "jacobian", "sim",
                        "convert"}
    assert len(corpus.cases) >= 70, len(corpus.cases)


def _plan(corpus: Corpus, ci: bool) -> list[dict]:
    plan = []
    for name, (path, commands) in corpus.cases.items():
        for command in commands:
            args = [command, *EXTRA.get(command, ()), *([] if ci else ["--trusted"])]
            if command == "check":
                args += ["--no-cache"]
            if name in DEADLINE_BOUND:
                args += ["--timeout", "0.5"]
            plan.append({"name": f"{name}: {command} {'CI' if ci else '--trusted'}",
                         "case": name, "command": command, "ci": ci, "cwd": str(path.parent),
                         "args": [*args, str(path)]})
    return plan


# the whole attack corpus, both modes: CI (slow, ~65 s of CPU with its twin in
# test_redteam*.py); make test keeps the attacks of test_security*.py, test_sandbox.py
@pytest.mark.slow
@pytest.mark.parametrize("ci", [True, False], ids=["ci-untrusted", "trusted"])
def test_the_corpus_holds(corpus, ci, tmp_path):
    env = {**os.environ, "URDFTOOL_TEST_SECRET": SECRET, "URDFTOOL_CACHE_DIR": str(tmp_path),
           "NO_COLOR": "1"}
    env.pop("CI", None)
    before = {p for p in corpus.base.rglob("*") if not p.is_symlink()}
    report = run_plan(_plan(corpus, ci), tmp_path, env, timeout=300)
    failures = []
    for run in report["runs"]:
        output = run["out"] + run["err"]
        problems = []
        if corpus.marker(run["case"].split(":")[0]).exists():
            problems.append("ran the payload")
        if SECRET in output:
            problems.append("leaked the secret")
        if "Traceback" in output or "internal error" in output:
            problems.append("traceback")
        # the wall time less what other processes' load took (tests/redteam_batch.py)
        if run["seconds"] - run["waited"] > SECONDS:
            problems.append(f"took {run['seconds']:.1f} s ({run['waited']:.1f} s waiting "
                            "for a CPU)")
        if run["code"] not in (0, 1, 2):
            problems.append(f"exit code {run['code']}")
        if run["command"] not in ("expand", "convert") and INJECTED.search(output):
            problems.append(f"injection: {INJECTED.search(output).group(0)!r}")
        if problems:
            failures.append(f"{run['name']}: {', '.join(problems)}\n  {output[-400:]!r}")
    markers = [p.name for p in corpus.base.glob("MARKER-*")]
    written = [p for p in corpus.base.rglob("*") if p not in before and not p.is_symlink()
               and p.is_file()]
    leaked_files = [p for p in written if SECRET in p.read_text(errors="replace")]
    assert not failures, "\n".join(failures)
    assert not markers and not leaked_files, (markers, leaked_files)
    assert SECRET not in report["batch_output"] or not ci
    assert report["peak_mb"] < MEGABYTES, report["peak_mb"]


# -- a refused expression is one located finding; the rest of the file is still checked ------

REFUSED_ROBOT = HEAD + """  <xacro:property name="evil" value="${().__class__}"/>
  <link name="base"/>
  <link name="tip"><inertial><mass value="${evil}"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="tip"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="${'x' * 10**9}"/></joint>
  <link name="c"><inertial><mass value="-1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="k" type="fixed"><parent link="base"/><child link="c"/></joint>
CONDITION</robot>
"""


@pytest.mark.parametrize("mode", ["--trusted", "--untrusted"])
def test_a_refused_expression_leaves_the_rest_checked(mode, tmp_path):
    from tests.conftest import run_urdftool

    path = tmp_path / "robot.urdf.xacro"
    path.write_text(REFUSED_ROBOT.replace("CONDITION", ""))
    result = run_urdftool("check", mode, "--format", "json", path)
    found = {(d["rule"], d["line"]) for f in json.loads(result.out)["files"]
             for d in f["diagnostics"]}
    assert result.code == 1
    assert ("xacro.unsafe-expression", 3) in found and ("xacro.limit-exceeded", 7) in found
    assert ("inertia.mass-not-positive", 8) in found  # after both: still checked
    # the placeholder values raise no false alarm (mass, velocity "not a number")
    assert not any(rule.startswith("schema.") for rule, _ in found), found
    for command in ("limits", "tree", "inertia"):  # the finding, located, and exit 1
        other = run_urdftool(command, mode, path)
        assert other.code == 1 and "robot.urdf.xacro:3" in other.err, other.err
    # a condition on a refused value: which branch is unknown, the expansion stops there
    path.write_text(REFUSED_ROBOT.replace(
        "CONDITION", '  <xacro:if value="${evil}"><link name="d"/></xacro:if>\n'))
    result = run_urdftool("check", mode, "--format", "json", path)
    messages = [(d["line"], d["message"]) for f in json.loads(result.out)["files"]
                for d in f["diagnostics"] if d["rule"] == "xacro.unsafe-expression"]
    assert result.code == 1 and any(line == 10 and "expansion stops here" in message
                                    for line, message in messages), messages
