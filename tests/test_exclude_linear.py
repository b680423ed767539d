"""Issue 28.3: a repository's exclusion patterns (``.gitignore`` lines, ``exclude`` and
``extend-exclude`` in ``urdftool.toml``) are untrusted text, matched in linear time: one short
line of stars and brackets sent pathspec's backtracking regular expression into hours on a long
file name, before any budget applied. The verdicts stay git's: ``git check-ignore`` on a
repository with many patterns decides the same files."""

from __future__ import annotations

import os
import resource
import subprocess
import sys
from pathlib import Path

import pytest

from urdftool.package import Selection, git_top

ROBOT = '<robot name="r"><link name="base"/></robot>\n'
# 30 bytes: Python's re takes ~2 s for a 28-letter name, hours for 60 (each * backtracks)
HOSTILE = "*a*a*a*a*a*a*a*a*a*a*a*a*c[x]"
LONG_NAME = "a" * 80 + ".urdf"
CPU_KILL = 20
STARTUP = 4.0  # CPU beyond 2 x --timeout: imports, the sandboxed reader's start


def _git(directory: Path, *args: str, stdin: str | None = None) -> str:
    return subprocess.run(["git", "-C", str(directory), *args], input=stdin, text=True,
                          capture_output=True, check=False).stdout


def _repository(tmp_path: Path) -> Path:
    repo = tmp_path / "repo"
    (repo / "urdf").mkdir(parents=True)
    _git(repo, "init", "-q")
    (repo / "urdf" / LONG_NAME).write_text(ROBOT, encoding="utf-8")
    (repo / "urdf" / "robot.urdf").write_text(ROBOT, encoding="utf-8")
    return repo


def _check_cpu(repo: Path, *args: str) -> tuple[float, subprocess.CompletedProcess]:
    """``urdftool check`` as the Action runs it (CI=true) in ``repo``: its CPU seconds (and its
    children's), killed at CPU_KILL."""
    env = {**os.environ, "CI": "true", "NO_COLOR": "1"}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run(
        ["prlimit", f"--cpu={CPU_KILL}", sys.executable, "-m", "urdftool", "check",
         "--timeout", "1", "--no-cache", *args], cwd=repo, env=env, capture_output=True,
        text=True, timeout=CPU_KILL * 10, check=False)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    return cpu, done


@pytest.mark.parametrize("where", ["gitignore", "extend-exclude", "exclude-option"])
def test_a_hostile_pattern_is_matched_in_linear_time(tmp_path, where):
    repo = _repository(tmp_path)
    args = ["."]
    if where == "gitignore":
        (repo / ".gitignore").write_text(f"{HOSTILE}\n", encoding="utf-8")
    elif where == "extend-exclude":
        (repo / "urdftool.toml").write_text(f'extend-exclude = ["{HOSTILE}"]\n',
                                            encoding="utf-8")
    else:
        args = ["--extend-exclude", HOSTILE, "."]
    cpu, done = _check_cpu(repo, *args)
    assert done.returncode in (0, 1), (done.returncode, done.stderr[-800:])
    assert cpu < 2 * 1 + STARTUP, cpu
    # the pattern does not match either file (no 'c' in them): both are checked
    assert "Traceback" not in done.stderr
    assert "2 file(s)" in done.stdout + done.stderr, done.stdout[-500:] + done.stderr[-500:]


PATTERNS = """\
# comments and blank lines

*.pyc
build/
/install
**/log
doc/*.urdf
!doc/keep.urdf
a?c.urdf
[bc]x.urdf
[!q]y.urdf
foo/**/bar.urdf
\\#hash.urdf
\\!bang.urdf
trailing.urdf   
sub/
!sub/inner.urdf
deep/*/
*.tmp.urdf
x[a-c]z.urdf
**/generated/**
nested/*.urdf
!nested/ok.urdf
"""
NESTED = "*.urdf\n!good.urdf\n/only_here.urdf\n"
FILES = [
    "a.pyc", "robot.urdf", "build/r.urdf", "install/r.urdf", "src/install/r.urdf", "log/r.urdf",
    "x/log/r.urdf", "doc/d.urdf", "doc/keep.urdf", "doc/more/d.urdf", "abc.urdf", "abbc.urdf",
    "bx.urdf", "cx.urdf", "dx.urdf", "qy.urdf", "zy.urdf", "foo/bar.urdf", "foo/a/b/bar.urdf",
    "#hash.urdf", "!bang.urdf", "trailing.urdf", "sub/inner.urdf", "sub/other.urdf",
    "deep/one/r.urdf", "deep/r.urdf", "m.tmp.urdf", "xbz.urdf", "xdz.urdf",
    "p/generated/q/r.urdf", "nested/n.urdf", "nested/ok.urdf", "nested/deeper/n.urdf",
    "pkg/bad.urdf", "pkg/good.urdf", "pkg/only_here.urdf", "pkg/inner/only_here.urdf",
    "pkg/inner/x.urdf",
]


def test_the_verdicts_are_gits(tmp_path):
    repo = tmp_path / "repo"
    repo.mkdir()
    _git(repo, "init", "-q")
    (repo / ".gitignore").write_text(PATTERNS, encoding="utf-8")
    (repo / "pkg").mkdir()
    (repo / "pkg" / ".gitignore").write_text(NESTED, encoding="utf-8")
    (repo / ".git" / "info").mkdir(exist_ok=True)
    (repo / ".git" / "info" / "exclude").write_text("*.secret.urdf\n", encoding="utf-8")
    files = [*FILES, "s.secret.urdf", "pkg/t.secret.urdf"]
    for name in files:
        (repo / name).parent.mkdir(parents=True, exist_ok=True)
        (repo / name).write_text(ROBOT, encoding="utf-8")
    ignored = set(_git(repo, "check-ignore", "--stdin", stdin="\n".join(files) + "\n")
                  .splitlines())
    assert 10 < len(ignored) < len(files) - 10  # the patterns decide both ways
    selection = Selection(base=repo)
    top = git_top(repo)

    def ours(name: str) -> bool:  # a folder git ignores hides what is below it, as walking
        path = repo / name
        parents = list(reversed(path.relative_to(repo).parents))[1:]
        return any(selection.ignored_by_git(repo / p, True, top) for p in parents) or \
            selection.ignored_by_git(path, False, top)

    differ = [name for name in files if ours(name) != (name in ignored)]
    assert not differ, [(name, name in ignored) for name in differ]
