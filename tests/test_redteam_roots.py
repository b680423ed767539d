"""Red team round 4 (issue 28): the roots of a run come from the operator only. Each attack is
made the way a pull request makes it, in real git repositories, and run through a shipped entry
point: the Action's `urdftool check` step (``tests.test_action.run_action``, action.yml's own
script in bash), the hook (the real ``pre-commit`` running .pre-commit-hooks.yaml,
``tests.test_precommit``) or the editor (``tests.test_lsp_trust``)."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.test_action import PACKAGES, _git, run_action
from tests.test_precommit import _commit, _env, _repo, _shipped_config, shipped  # noqa: F401

pytestmark = pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")

SECRET = "hunter2_7f3a"
ROBOT = ('<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
         '  <link name="base"/>\n'
         '  <joint name="j" type="{kind}"><parent link="base"/><child link="tip"/></joint>\n'
         '  <link name="tip"/>\n</robot>\n')


def _other_checkout(tmp_path: Path) -> Path:
    """Another checkout on the runner (a .git of its own) holding a secret."""
    other = tmp_path / "other"
    other.mkdir()
    _git(tmp_path, "init", "-q", str(other))
    (other / "secret.yaml").write_text(f"kind: {SECRET}\n")
    return other


def _team(tmp_path: Path) -> Path:
    repo = tmp_path / "team"
    urdf = repo / "robot_description" / "urdf"
    urdf.mkdir(parents=True)
    (repo / "robot_description" / "package.xml").write_text(
        "<package><name>robot_description</name></package>\n")
    (urdf / "r.urdf.xacro").write_text(ROBOT.format(kind="fixed"))
    _git(tmp_path, "init", "-q", str(repo))
    _git(repo, "add", "-A")
    _git(repo, "commit", "-qm", "base")
    _git(repo, "update-ref", "refs/remotes/origin/main", "HEAD")
    return repo


def _pull_request(repo: Path, link: str, target: Path, kind: str) -> None:
    """The pull request: a link ``link`` to ``target`` (another checkout), and an entry whose
    joint type is ``kind`` (a joint type prints its value in the finding), committed."""
    (repo / link).symlink_to(target)
    (repo / "robot_description" / "urdf" / "r.urdf.xacro").write_text(ROBOT.format(kind=kind))
    _git(repo, "add", "-A")
    _git(repo, "commit", "-qm", "the pull request")


def test_action_a_changed_link_to_another_checkout_is_no_root(tmp_path):
    """Issue 28.1: the Action's changed-files mode passes the committed link after
    ``--changed --``; it was a root (the other checkout has a .git), the secret was read and
    annotated. A changed path is data: the link's target is outside the roots."""
    other = _other_checkout(tmp_path)
    repo = _team(tmp_path)
    _pull_request(repo, "robot_description/urdf/other", other,
                  "${xacro.load_yaml('other/secret.yaml')['kind']}")
    run = run_action(repo, {"changed-files": "true"}, {"base_ref": "main"})
    [call] = [c for c in run.calls if c[:1] == ["check"]]
    assert "robot_description/urdf/other" in call  # the link was among the changed names
    assert SECRET not in run.output, run.output
    assert run.code == 1, run.output
    assert "xacro.error" in run.output and "other/secret.yaml" in run.output, run.output


def test_action_paths_that_are_links_into_another_checkout_are_no_root(tmp_path):
    """The workflow's ``paths`` (the operator's) name a directory that the pull request
    replaced by a link to another checkout: a typed path that is a link decides nothing (it
    was a root: the entry read the other checkout's secret through it)."""
    other = _other_checkout(tmp_path)
    repo = _team(tmp_path)
    _pull_request(repo, "vendor", other, "${xacro.load_yaml('../../vendor/secret.yaml')['kind']}")
    run = run_action(repo, {"paths": "vendor robot_description"}, {"base_ref": "main"})
    assert SECRET not in run.output, run.output
    assert run.code == 1 and "xacro.error" in run.output, run.output


def _relative_includes(root: Path) -> Path:
    """demo_description with its entry including wheel.xacro by a relative name."""
    package = root / "demo_description"
    shutil.copytree(PACKAGES / "demo_description", package)
    entry = package / "urdf" / "robot.urdf.xacro"
    entry.write_text(entry.read_text().replace(
        'filename="$(find demo_description)/urdf/wheel.xacro"', 'filename="wheel.xacro"'))
    return entry


def _include_line(entry: Path) -> int:
    return next(n for n, t in enumerate(entry.read_text().splitlines(), 1)
                if 'filename="wheel.xacro"' in t)


def test_action_a_deleted_relative_include_fails_the_pull_request(tmp_path):
    """Issue 28.7: a pull request deleting a file its entry includes by a relative name passed
    the changed-files gate (the finding was kept only when its message named the absolute
    path). The entry's reads graph says where it asked for the deleted file."""
    repo = tmp_path / "team"
    entry = _relative_includes(repo)
    _git(tmp_path, "init", "-q", str(repo))
    _git(repo, "add", "-A")
    _git(repo, "commit", "-qm", "base")
    _git(repo, "update-ref", "refs/remotes/origin/main", "HEAD")
    _git(repo, "rm", "-q", "demo_description/urdf/wheel.xacro")
    _git(repo, "commit", "-qm", "the pull request deletes a fragment")
    run = run_action(repo, {"changed-files": "true"}, {"base_ref": "main"})
    assert run.code == 1, run.output
    listed = [line for line in run.output.splitlines() if "xacro.error" in line]
    assert len(listed) == 1, run.output
    assert f"demo_description/urdf/robot.urdf.xacro:{_include_line(entry)}:" in listed[0]


@pytest.mark.slow  # the shipped hook installs its environment (~28 s of CPU): CI
def test_hook_a_deleted_relative_include_blocks_the_commit(shipped, tmp_path):  # noqa: F811
    """The hook is never given a deleted file (pre-commit passes what a commit adds or
    changes): a commit that deletes the relative include and retouches another fragment of
    the same entry passed. The entry's last reads (the reads cache) name the deleted file."""
    repo = _repo(tmp_path / "team", _shipped_config(shipped))
    entry = _relative_includes(repo)
    env = _env(shipped[2])
    subprocess.run([sys.executable, "-m", "pre_commit", "install"], cwd=repo, env=env,
                   check=True, capture_output=True)
    first = _commit(repo, env, "a clean package")
    assert first.returncode == 0, first.stdout
    (repo / "demo_description" / "urdf" / "wheel.xacro").unlink()
    materials = repo / "demo_description" / "urdf" / "materials.xacro"
    materials.write_text(materials.read_text() + "\n")
    blocked = _commit(repo, env, "wheel.xacro goes")
    assert blocked.returncode != 0, blocked.stdout
    assert re.search(rf"demo_description/urdf/robot\.urdf\.xacro:{_include_line(entry)}:\d+: "
                     r"error xacro\.error", blocked.stdout), blocked.stdout


WHEELS = ('<?xml version="1.0"?>\n<robot name="r">\n  <link name="base"/>\n'
          '  <joint name="wheel_1_joint" type="continuous"><parent link="base"/>'
          '<child link="wheel_1"/><axis xyz="{a1}"/></joint>\n  <link name="wheel_1"/>\n'
          '  <joint name="wheel_2_joint" type="continuous"><parent link="base"/>'
          '<child link="wheel_2"/><axis xyz="{a2}"/></joint>\n  <link name="wheel_2"/>\n'
          '</robot>\n')


def test_action_a_baseline_finding_hides_no_defect_on_another_link(tmp_path):
    """Issue 28.8: the baseline's matching removed every digit (``wheel_1`` was ``wheel_2``):
    a pull request that fixes the recorded zero axis of wheel_1 and breaks wheel_2 passed the
    Action's ``--baseline``."""
    repo = tmp_path / "team"
    repo.mkdir()
    robot = repo / "r.urdf"
    robot.write_text(WHEELS.format(a1="0 0 0", a2="0 1 0"))
    _git(tmp_path, "init", "-q", str(repo))
    from tests.conftest import run_urdftool

    written = run_urdftool("check", "--write-baseline", str(repo / "base.json"), str(robot))
    assert written.code == 0 and "finding(s) recorded" in written.err, written
    _git(repo, "add", "-A")
    _git(repo, "commit", "-qm", "base, with its baseline")
    args = {"paths": "r.urdf", "args": "--baseline base.json"}
    assert run_action(repo, args, {}).code == 0  # the recorded finding is hidden
    robot.write_text(WHEELS.format(a1="0 1 0", a2="0 0 0"))
    _git(repo, "commit", "-qam", "the pull request")
    run = run_action(repo, args, {})
    assert run.code == 1, run.output
    [annotation] = run.annotations()
    assert "wheel_2_joint" in annotation and "joint.zero-axis" in annotation, run.output


def test_action_an_unknown_package_is_not_looked_for_outside_the_repository(tmp_path):
    """Issue 28.8: ``package://NAME/...`` with an unknown NAME looked for a directory NAME
    beside every ancestor of the file, outside the repository too: the annotation told
    whether the runner has that directory (and named its absolute path)."""
    repo = tmp_path / "team"
    repo.mkdir()
    (repo / "r.urdf").write_text(
        '<?xml version="1.0"?>\n<robot name="r"><link name="base"><visual><geometry>'
        '<mesh filename="package://runner_secrets/key.stl"/></geometry></visual></link>'
        '</robot>\n')
    _git(tmp_path, "init", "-q", str(repo))
    _git(repo, "add", "-A")
    _git(repo, "commit", "-qm", "the pull request")
    answers = []
    for exists in (True, False):
        secrets = tmp_path / "runner_secrets"
        if exists:
            secrets.mkdir()
            (secrets / "key.stl").write_text("solid s\nendsolid s\n")
        else:
            shutil.rmtree(secrets)
        run = run_action(repo, {"paths": "r.urdf"}, {})
        assert str(tmp_path) not in run.output, run.output
        answers.append([line for line in run.output.splitlines() if line.startswith("::")])
    assert answers[0] == answers[1] and answers[0], answers


SIMMED = ('<?xml version="1.0"?>\n<robot name="r"><link name="base"><inertial><mass value="1"/>'
          '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'
          '<collision><geometry><mesh filename="{mesh}"/></geometry></collision></link>'
          '</robot>\n')


def _sim(repo: Path, *args: str) -> subprocess.CompletedProcess:
    """``urdftool sim`` as a CI job runs it (CI=true: untrusted)."""
    import os

    from tests.conftest import ROOT

    env = {**os.environ, "CI": "true", "PYTHONPATH": str(ROOT)}
    env.pop("URDFTOOL_DEBUG", None)
    return subprocess.run([sys.executable, "-m", "urdftool", "sim", "--timeout", "20", *args],
                          cwd=repo, env=env, capture_output=True, text=True, timeout=120,
                          check=False)


def test_sim_gives_pybullet_no_fifo(tmp_path):
    """Issue 28.6: ``sim`` handed PyBullet the mesh names as written: a FIFO in the checkout
    blocked it forever (``--timeout`` ignored). PyBullet gets only regular files urdftool
    found; the FIFO is named, not opened."""
    import os

    repo = tmp_path / "team"
    repo.mkdir()
    os.mkfifo(repo / "wheel.stl")
    (repo / "r.urdf").write_text(SIMMED.format(mesh="wheel.stl"))
    done = _sim(repo, "r.urdf")
    output = done.stdout + done.stderr
    assert "wheel.stl (not a regular file" in output, output
    assert "Traceback" not in output


def test_sim_gives_pybullet_no_mesh_outside_the_roots(tmp_path):
    """A mesh outside the repository was opened by the unconfined simulator: its verdict told
    whether a file of the runner exists, and its shape. The same answer either way now."""
    repo = tmp_path / "team"
    repo.mkdir()
    outside = tmp_path / "outside"
    outside.mkdir()
    (repo / "r.urdf").write_text(SIMMED.format(mesh=str(outside / "m.stl")))
    _git(tmp_path, "init", "-q", str(repo))
    answers = []
    for exists in (True, False):
        if exists:
            shutil.copy(Path(__file__).resolve().parent.parent / "urdftool" / "physics" /
                        "examples" / "open_box.stl", outside / "m.stl")
        else:
            (outside / "m.stl").unlink()
        done = _sim(repo, "--format", "json", "r.urdf")
        checks = [(c["check"], c["status"], c["message"])
                  for m in json.loads(done.stdout)["models"] for c in m["checks"]]
        answers.append(checks)
    assert answers[0] == answers[1], answers


@pytest.mark.parametrize("args", [(".",), ("robot.urdf.xacro",), ("--changed", "--",
                                                                   "robot.urdf.xacro")])
def test_check_in_a_checkout_without_metadata_reads_nothing_of_the_enclosing_work_tree(
        tmp_path, monkeypatch, args):
    """Issue 28.2 for ``check``: a tarball unpacked in a home directory under git took the home
    directory as its repository (its files readable: here a secret the entry loads). A
    directory the enclosing work tree does not hold is rooted at what the operator gave."""
    from tests.conftest import run_urdftool

    home = tmp_path / "home"
    home.mkdir()
    (home / "secret.yaml").write_text(f"kind: {SECRET}\n")
    _git(tmp_path, "init", "-q", str(home))
    _git(home, "add", "secret.yaml")
    robot = home / "Downloads" / "robot"
    robot.mkdir(parents=True)
    (robot / "robot.urdf.xacro").write_text(ROBOT.format(
        kind="${xacro.load_yaml('../../secret.yaml')['kind']}"))
    monkeypatch.chdir(robot)
    for mode in ("--untrusted", "--trusted"):
        result = run_urdftool("check", mode, *args)
        assert SECRET not in result.out + result.err, result
        assert result.code == 1 and "xacro.error" in result.out, result


def test_check_a_package_in_the_work_tree_does_not_root_a_checkout_without_metadata(
        tmp_path, monkeypatch):
    """A file of an untracked checkout is rooted at its own package: the package.xml found
    above it must not be one the enclosing work tree holds (here its top: the whole home
    directory was readable)."""
    from tests.conftest import run_urdftool

    home = tmp_path / "home"
    home.mkdir()
    (home / "secret.yaml").write_text(f"kind: {SECRET}\n")
    (home / "package.xml").write_text("<package><name>home</name></package>\n")
    _git(tmp_path, "init", "-q", str(home))
    _git(home, "add", "secret.yaml", "package.xml")
    robot = home / "Downloads" / "robot"
    robot.mkdir(parents=True)
    (robot / "robot.urdf.xacro").write_text(ROBOT.format(
        kind="${xacro.load_yaml('../../secret.yaml')['kind']}"))
    monkeypatch.chdir(home)
    for mode in ("--untrusted", "--trusted"):
        result = run_urdftool("check", mode, "Downloads/robot/robot.urdf.xacro")
        assert SECRET not in result.out + result.err, result
        assert result.code == 1 and "xacro.error" in result.out, result


def test_check_an_installed_package_in_the_work_tree_reads_its_own_meshes(tmp_path, monkeypatch):
    """The data of a package installed in a virtual environment inside the checkout (CI's
    ``.venv``, untracked): a robot of it is rooted at its package (package.xml), as outside
    any work tree, so its meshes beside its robots/ folder are read (it was rooted at the
    robot's own folder: every mesh was outside the roots)."""
    import trimesh

    from tests.conftest import run_urdftool

    repo = tmp_path / "team"
    repo.mkdir()
    (repo / "README").write_text("tracked\n")
    _git(tmp_path, "init", "-q", str(repo))
    _git(repo, "add", "README")
    package = repo / ".venv" / "lib" / "site-packages" / "share" / "pkg"
    (package / "robots").mkdir(parents=True)
    (package / "meshes").mkdir()
    (package / "package.xml").write_text("<package><name>pkg</name></package>\n")
    trimesh.creation.box(extents=(0.1, 0.1, 0.1)).export(package / "meshes" / "box.stl")
    robot = package / "robots" / "r.urdf"
    robot.write_text('<robot name="r"><link name="a"><visual><geometry><mesh filename='
                     '"package://pkg/meshes/box.stl"/></geometry></visual></link></robot>')
    monkeypatch.chdir(repo)

    def mesh_findings():
        result = run_urdftool("check", "--format", "json", "--select", "mesh", str(robot))
        return [d["message"] for f in json.loads(result.out)["files"] for d in f["diagnostics"]]

    assert mesh_findings() == []
    (package / "meshes" / "box.stl").unlink()  # (the same check finds a missing mesh)
    assert len(mesh_findings()) == 1


def test_action_a_changed_link_brings_no_configuration(tmp_path):
    """The configuration of a changed-files run is looked for above the first changed name:
    a committed link to another checkout (named first) brought that checkout's
    ``urdftool.toml`` (``ignore`` every family: the pull request's broken robot passed). A
    link decides nothing: the configuration is the repository's own."""
    other = _other_checkout(tmp_path)
    (other / "urdftool.toml").write_text(
        'ignore = ["xml", "schema", "structure", "joint", "geometry", "inertia"]\n')
    repo = _team(tmp_path)
    _pull_request(repo, "a_link", other, "sideways")
    run = run_action(repo, {"changed-files": "true"}, {"base_ref": "main"})
    [call] = [c for c in run.calls if c[:1] == ["check"]]
    assert call[call.index("--") + 1] == "a_link", call  # the link is the first name
    assert run.code == 1 and "schema.bad-value" in run.output, run.output


def test_action_a_changed_link_plans_nothing_of_another_checkout(tmp_path):
    """A changed link's package was looked for where the link leads: the other checkout's
    robots were planned (and refused: the whole run failed with exit 2, no finding). The
    link is data where it is written: its own package is checked."""
    other = _other_checkout(tmp_path)
    (other / "package.xml").write_text("<package><name>other</name></package>\n")
    (other / "x.urdf").write_text(f'<?xml version="1.0"?>\n<robot name="{SECRET}">'
                                  f'<link name="{SECRET}"/></robot>\n')
    repo = _team(tmp_path)
    _pull_request(repo, "robot_description/urdf/other", other, "sideways")
    run = run_action(repo, {"changed-files": "true"}, {"base_ref": "main"})
    assert SECRET not in run.output, run.output
    assert run.code == 1 and "schema.bad-value" in run.output, run.output
