"""urdftool as a pre-commit hook: the real `pre-commit` package installs this repository's hook
(.pre-commit-hooks.yaml) in a temporary git repository and runs it on a good and a bad file."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import ROOT

GOOD = '<?xml version="1.0"?>\n<robot name="r"><link name="base"/></robot>\n'
BAD = '<?xml version="1.0"?>\n<robot name="r"><link name="base"></robot>\n'


def _git(cwd: Path, *args: str) -> None:
    subprocess.run(["git", *args], cwd=cwd, check=True, capture_output=True)


@pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")
def test_pre_commit_hook_blocks_a_broken_robot(tmp_path):
    repo = tmp_path / "robot_description"
    repo.mkdir()
    _git(repo, "init", "-q")
    (repo / "good.urdf").write_text(GOOD)
    (repo / "bad.urdf").write_text(BAD)
    _git(repo, "add", ".")
    env = {**os.environ, "PRE_COMMIT_HOME": str(tmp_path / "cache"),
           "GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@t", "GIT_COMMITTER_NAME": "t",
           "GIT_COMMITTER_EMAIL": "t@t"}
    env.pop("URDFTOOL_DEBUG", None)

    def try_repo(*files: str) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "-m", "pre_commit", "try-repo", str(ROOT), "urdftool",
                               "--files", *files], check=False, cwd=repo, env=env,
                              capture_output=True,
                              text=True, timeout=600)

    good = try_repo("good.urdf")
    assert good.returncode == 0, good.stdout + good.stderr
    assert "Passed" in good.stdout
    bad = try_repo("bad.urdf")
    assert bad.returncode == 1, bad.stdout + bad.stderr
    assert "Failed" in bad.stdout and "bad.urdf:" in bad.stdout
