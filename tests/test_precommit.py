"""urdftool as a pre-commit hook, with the real `pre-commit` package: the hook this repository
ships (.pre-commit-hooks.yaml, installed once in its own environment) and the README's local
hook, as written, in temporary git repositories: single files, and a package with fragments
committed the way a team commits (issue 13)."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import ROOT

pytestmark = pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")

GOOD = '<?xml version="1.0"?>\n<robot name="r"><link name="base"/></robot>\n'
BAD = '<?xml version="1.0"?>\n<robot name="r"><link name="base"></robot>\n'
DEMO = Path(__file__).parent / "data" / "packages" / "demo_description"


def _git(cwd: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(["git", *args], cwd=cwd, check=True, capture_output=True, text=True)


def _env(home: Path, path_first: Path | None = None) -> dict:
    env = {**os.environ, "PRE_COMMIT_HOME": str(home), "GIT_AUTHOR_NAME": "t",
           "GIT_AUTHOR_EMAIL": "t@t", "GIT_COMMITTER_NAME": "t", "GIT_COMMITTER_EMAIL": "t@t",
           "URDFTOOL_CACHE_DIR": str(home / "urdftool-cache")}
    env.pop("URDFTOOL_DEBUG", None)
    if path_first is not None:
        env["PATH"] = f"{path_first}{os.pathsep}{env['PATH']}"
    return env


# The shipped hook's tests install its environment (pre-commit's own venv: pip install of this
# tree with the mesh extra, ~30 s of CPU): CI runs them (slow); make test keeps the README's
# local hook (test_readme_local_hook_works_as_written) and the manifest's checks.
SHIPPED = pytest.mark.slow


@pytest.fixture(scope="module")
def shipped(tmp_path_factory) -> tuple[str, str, Path]:
    """(repo, rev, PRE_COMMIT_HOME): this working tree's tracked files committed to a scratch
    repository (what a clone at a commit holds), its hook environment installed once."""
    base = tmp_path_factory.mktemp("hook")
    source = base / "urdftool"
    files = _git(ROOT, "ls-files", "-z", "--cached", "--others", "--exclude-standard").stdout
    for name in filter(None, files.split("\0")):
        if (ROOT / name).is_file():
            (source / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / name, source / name)
    _git(source, "init", "-q")
    _git(source, "add", ".")
    _git(source, "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "snapshot")
    rev = _git(source, "rev-parse", "HEAD").stdout.strip()
    return str(source), rev, base / "pre-commit-home"


def _repo(path: Path, config: str) -> Path:
    path.mkdir()
    _git(path, "init", "-q")
    (path / ".pre-commit-config.yaml").write_text(config)
    return path


def _shipped_config(shipped) -> str:
    repo, rev, _ = shipped
    return f"repos:\n  - repo: {repo}\n    rev: {rev}\n    hooks:\n      - id: urdftool\n"


def _commit(repo: Path, env: dict, message: str) -> subprocess.CompletedProcess:
    _git(repo, "add", "-A")  # the hook's output: on stderr, which git gives the hook
    return subprocess.run(["git", "commit", "-qm", message], cwd=repo, env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          timeout=900, check=False)


@SHIPPED
def test_shipped_hook_blocks_a_broken_robot(shipped, tmp_path):
    repo = _repo(tmp_path / "robot_description", _shipped_config(shipped))
    (repo / "good.urdf").write_text(GOOD)
    (repo / "bad.urdf").write_text(BAD)
    _git(repo, "add", ".")
    env = _env(shipped[2])

    def run(*files: str) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "-m", "pre_commit", "run", "--files", *files],
                              check=False, cwd=repo, env=env, capture_output=True, text=True,
                              timeout=900)

    good = run("good.urdf")
    assert good.returncode == 0, good.stdout + good.stderr
    assert "Passed" in good.stdout
    bad = run("bad.urdf")
    assert bad.returncode == 1, bad.stdout + bad.stderr
    assert "Failed" in bad.stdout and "bad.urdf:" in bad.stdout


@SHIPPED
def test_shipped_hook_gates_a_package_with_fragments(shipped, tmp_path):
    repo = _repo(tmp_path / "team", _shipped_config(shipped))
    package = repo / "demo_description"
    shutil.copytree(DEMO, package)
    env = _env(shipped[2])
    subprocess.run([sys.executable, "-m", "pre_commit", "install"], cwd=repo, env=env,
                   check=True, capture_output=True)
    first = _commit(repo, env, "a clean package")
    assert first.returncode == 0, first.stdout + first.stderr  # fragments are not robots

    # a broken fragment is blocked, the finding at the fragment's line
    wheel = package / "urdf" / "wheel.xacro"
    wheel.write_text(wheel.read_text().replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>'))
    blocked = _commit(repo, env, "zero axis")
    line = next(n for n, text in enumerate(wheel.read_text().splitlines(), 1) if "<axis" in text)
    assert blocked.returncode != 0
    assert f"demo_description/urdf/wheel.xacro:{line}:" in blocked.stdout
    assert "joint.zero-axis" in blocked.stdout and "in 4 instances" in blocked.stdout
    _git(repo, "reset", "-q", "--hard")  # the scratch repository, back to its last commit

    # a change that is wrong only where the entry uses it: the includer is checked again
    camera = package / "urdf" / "camera.xacro"
    camera.write_text(camera.read_text().replace('<parent link="base_link"/>',
                                                 '<parent link="base_lnk"/>'))
    blocked = _commit(repo, env, "mount on a link that does not exist")
    line = next(n for n, text in enumerate(camera.read_text().splitlines(), 1)
                if "base_lnk" in text)
    assert blocked.returncode != 0
    assert "structure.missing-link" in blocked.stdout, blocked.stdout
    assert re.search(rf"demo_description/urdf/camera\.xacro:({line - 1}|{line}):",
                     blocked.stdout), blocked.stdout
    _git(repo, "reset", "-q", "--hard")  # the scratch repository, back to its last commit

    # meshes are checked in the hook's environment: an unreadable mesh blocks the commit
    (package / "meshes").mkdir()
    shutil.copy(ROOT / "urdftool" / "physics" / "examples" / "corrupt.stl",
                package / "meshes" / "cover.stl")
    camera.write_text(camera.read_text().replace(
        '<visual><geometry><box size="0.04 0.04 0.04"/></geometry></visual>',
        '<visual><geometry><mesh filename="package://demo_description/meshes/cover.stl"/>'
        '</geometry></visual>'))
    blocked = _commit(repo, env, "a mesh")
    assert blocked.returncode != 0 and "mesh.unreadable" in blocked.stdout, blocked.stdout


def test_hook_installs_the_mesh_extra():
    import tomllib
    import yaml

    hooks = {h["id"]: h for h in yaml.safe_load((ROOT / ".pre-commit-hooks.yaml").read_text())}
    hook = hooks["urdftool"]
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
        "optional-dependencies"]
    for each in hooks.values():
        assert each["additional_dependencies"] == extras["mesh"]
    assert hook["entry"] == "urdftool check --changed --" and hook["require_serial"] is True


def test_every_hook_passes_file_names_after_a_separator():
    # pre-commit appends the file names to `entry`: after `--`, none can be an option
    import yaml

    hooks = yaml.safe_load((ROOT / ".pre-commit-hooks.yaml").read_text())
    readme = yaml.safe_load(_readme_snippet("pre-commit-local"))["repos"][0]["hooks"]
    for hook in hooks + readme:
        assert hook["entry"].split()[-1] == "--", hook


def test_the_readmes_local_hook_is_triggered_by_what_triggers_the_shipped_one():
    """The README's local hook and the shipped one check the same files: the local one had
    drifted and left SRDFs out (a commit changing only an SRDF was never checked)."""
    import re

    import yaml

    shipped = next(h for h in yaml.safe_load((ROOT / ".pre-commit-hooks.yaml").read_text())
                   if h["id"] == "urdftool")
    local = yaml.safe_load(_readme_snippet("pre-commit-local"))["repos"][0]["hooks"][0]
    assert local["files"] == shipped["files"]
    assert re.search(local["files"], "moveit_config/config/robot.srdf")


HOSTILE = ["--write-baseline=x.urdf", "-o.urdf", "--output-file=y.urdf", "--exit-zero.urdf",
           "--ignore=xml.urdf", "-x.urdf", "a:=b.urdf"]


@SHIPPED
def test_shipped_hook_checks_files_named_like_options(shipped, tmp_path):
    """A commit of broken robot files whose names are options that would set the verdict
    (write a baseline and exit 0, ignore the xml rules, send the report to a file): the real
    pre-commit runs the shipped hook's own entry on them, each is checked as a file and the
    commit is blocked; nothing is written."""
    repo = _repo(tmp_path / "team", _shipped_config(shipped))
    for name in HOSTILE:
        (repo / name).write_text(BAD)
    _git(repo, "add", "--", *HOSTILE)
    before = sorted(p.name for p in repo.iterdir())
    env = _env(shipped[2])
    subprocess.run([sys.executable, "-m", "pre_commit", "install"], cwd=repo, env=env,
                   check=True, capture_output=True)
    blocked = _commit(repo, env, "hostile names")
    assert blocked.returncode != 0, blocked.stdout
    for name in HOSTILE:
        assert f"{name}:2:" in blocked.stdout, (name, blocked.stdout)
    assert "no such option" not in blocked.stdout and "baseline:" not in blocked.stdout
    assert sorted(p.name for p in repo.iterdir()) == before  # no x.urdf, no y.urdf


def _readme_snippet(name: str) -> str:
    readme = (ROOT / "README.md").read_text()
    after = readme.split(f"<!-- snippet: {name} ", 1)[1]
    return after.split("```yaml\n", 1)[1].split("```", 1)[0]


def test_readme_local_hook_works_as_written(tmp_path):
    repo = _repo(tmp_path / "team", _readme_snippet("pre-commit-local"))
    shutil.copytree(DEMO, repo / "demo_description")
    env = _env(tmp_path / "home", Path(sys.executable).parent)  # urdftool installed here
    subprocess.run([sys.executable, "-m", "pre_commit", "install"], cwd=repo, env=env,
                   check=True, capture_output=True)
    assert _commit(repo, env, "clean").returncode == 0
    unused = repo / "demo_description" / "urdf" / "unused.xacro"
    unused.write_text(unused.read_text().replace("<mu1>0.1</mu1>", "<mu1>0.1</mu>"))
    blocked = _commit(repo, env, "broken")
    assert blocked.returncode != 0 and "unused.xacro:6:" in blocked.stdout, blocked.stdout


ARM = Path(__file__).parent / "data" / "packages" / "arm_description"


@SHIPPED
def test_shipped_hook_sees_every_input_of_an_entry(shipped, tmp_path):
    """Issue 23: a commit that changes only the YAML file the xacro loads is checked through
    the entry that loads it; a commit of a file no entry reads passes silently."""
    repo = _repo(tmp_path / "team", _shipped_config(shipped))
    package = repo / "arm_description"
    shutil.copytree(ARM, package)
    env = _env(shipped[2])
    subprocess.run([sys.executable, "-m", "pre_commit", "install"], cwd=repo, env=env,
                   check=True, capture_output=True)
    first = _commit(repo, env, "a clean package")
    assert first.returncode == 0, first.stdout

    limits = package / "config" / "joint_limits.yaml"
    limits.write_text(limits.read_text().replace("lower: -1.5", "lower: 2.5"))
    blocked = _commit(repo, env, "limits retouched")
    line = next(n for n, text in enumerate((package / "urdf" / "arm.urdf.xacro").read_text()
                                           .splitlines(), 1) if "<limit" in text)
    assert blocked.returncode != 0, blocked.stdout
    assert f"arm_description/urdf/arm.urdf.xacro:{line}:" in blocked.stdout
    assert "joint.lower-above-upper" in blocked.stdout and "lower 2.5 > upper 1.5" in blocked.stdout
    assert "reads arm_description/config/joint_limits.yaml" in blocked.stdout, blocked.stdout
    _git(repo, "reset", "-q", "--hard")

    # a YAML file no entry reads: the hook runs (not skipped), passes, prints nothing
    (package / "config" / "controllers.yaml").write_text("controller_manager: {}\n")
    passed = _commit(repo, env, "controllers")
    assert passed.returncode == 0, passed.stdout
    assert re.search(r"urdftool check\.+Passed", passed.stdout), passed.stdout
    assert "error" not in passed.stdout and "file(s)" not in passed.stdout


@SHIPPED
def test_shipped_fix_hook_fixes_the_staged_files(shipped, tmp_path):
    """The second hook id, urdftool-fix: a typo'd attribute in a staged macro file is fixed in
    place through the entry that includes it; pre-commit fails the commit (a file changed) and
    the working tree is the last commit's again."""
    repo, rev, home = shipped
    config = f"repos:\n  - repo: {repo}\n    rev: {rev}\n    hooks:\n      - id: urdftool-fix\n"
    team = _repo(tmp_path / "team", config)
    package = team / "demo_description"
    shutil.copytree(DEMO, package)
    env = _env(home)
    subprocess.run([sys.executable, "-m", "pre_commit", "install"], cwd=team, env=env,
                   check=True, capture_output=True)
    assert _commit(team, env, "clean").returncode == 0
    wheel = package / "urdf" / "wheel.xacro"
    entry = package / "urdf" / "robot.urdf.xacro"
    written = wheel.read_text()
    wheel.write_text(written.replace(' rpy="-1.5707963267948966 0 0"',
                                     ' ryp="-1.5707963267948966 0 0"'))
    entry_before = entry.read_text()
    first = _commit(team, env, "typo")
    assert first.returncode != 0 and "files were modified by this hook" in first.stdout, \
        first.stdout
    assert wheel.read_text() == written  # fixed back, byte for byte
    assert entry.read_text() == entry_before  # only the staged file is written
    # the working tree is the last commit's again (the typo is still staged: the user adds)
    assert _git(team, "diff", "HEAD", "--", "demo_description").stdout == ""
