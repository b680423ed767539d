"""Red team round 4 (issue 28): the roots of a run come from the operator only. Each attack is
made the way a pull request makes it, in real git repositories, and run through a shipped entry
point: the Action's `urdftool check` step (``tests.test_action.run_action``, action.yml's own
script in bash), the hook (the real ``pre-commit`` running .pre-commit-hooks.yaml,
``tests.test_precommit``) or the editor (``tests.test_lsp_trust``)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from tests.test_action import _git, run_action

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


def _link_and_load(repo: Path, other: Path) -> None:
    """The pull request: a link to the other checkout beside the entry, and an entry that loads
    the secret through it (a joint type that prints its value in the finding)."""
    urdf = repo / "robot_description" / "urdf"
    (urdf / "other").symlink_to(other)
    (urdf / "r.urdf.xacro").write_text(ROBOT.format(
        kind="${xacro.load_yaml('other/secret.yaml')['kind']}"))


def test_action_a_changed_link_to_another_checkout_is_no_root(tmp_path):
    """Issue 28.1: the Action's changed-files mode passes the committed link after
    ``--changed --``; it was a root (the other checkout has a .git), the secret was read and
    annotated. A changed path is data: the link's target is outside the roots."""
    other = _other_checkout(tmp_path)
    repo = _team(tmp_path)
    _link_and_load(repo, other)
    _git(repo, "add", "-A")
    _git(repo, "commit", "-qm", "the pull request")
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
    (repo / "vendor").symlink_to(other)
    (repo / "robot_description" / "urdf" / "r.urdf.xacro").write_text(ROBOT.format(
        kind="${xacro.load_yaml('../../vendor/secret.yaml')['kind']}"))
    _git(repo, "add", "-A")
    _git(repo, "commit", "-qm", "the pull request")
    run = run_action(repo, {"paths": "vendor robot_description"}, {"base_ref": "main"})
    assert SECRET not in run.output, run.output
    assert run.code == 1 and "xacro.error" in run.output, run.output
