"""The GitHub Action (action.yml) and the README's workflow, run here the way the runner runs a
composite action: the README's step `uses: ./tools/urdftool` with its `with:` inputs, each
`run:` step in `bash -eo pipefail` with `${{ inputs.* }}` / `${{ github.* }}` substituted.
`actions/setup-python` and the pip install are the runner's business: urdftool is already
installed here (the install step is checked to take the mesh extra)."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from tests.conftest import ROOT

pytestmark = pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")
DEMO = Path(__file__).parent / "data" / "packages" / "demo_description"


def _workflow_step() -> dict:
    readme = (ROOT / "README.md").read_text()
    text = readme.split("<!-- snippet: github-workflow ", 1)[1].split("```yaml\n", 1)[1]
    workflow = yaml.safe_load(text.split("```", 1)[0])
    [job] = workflow["jobs"].values()
    [step] = [s for s in job["steps"] if s.get("uses", "").startswith("./")]
    return step


def run_action(repo: Path, inputs: dict, github: dict) -> tuple[int, str]:
    """Run action.yml's steps in ``repo``; (exit code of the last step, its output)."""
    action = yaml.safe_load((ROOT / "action.yml").read_text())
    values = {name: str(spec.get("default", "")) for name, spec in action["inputs"].items()}
    values.update({k: str(v) for k, v in inputs.items()})

    def substitute(text: str) -> str:
        def value(match):
            scope, name = match.group(1), match.group(2)
            return values[name] if scope == "inputs" else github.get(name, "")

        return re.sub(r"\$\{\{\s*(inputs|github)\.([\w-]+)\s*\}\}", value, text)

    env = {**os.environ, "GITHUB_ACTION_PATH": str(ROOT),
           "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    env.pop("URDFTOOL_DEBUG", None)
    code, output = 0, ""
    for step in action["runs"]["steps"]:
        if "uses" in step:
            assert step["uses"].startswith("actions/setup-python@")
            continue
        if step["name"] == "Install urdftool":
            assert '"${GITHUB_ACTION_PATH}[mesh]"' in step["run"]
            continue
        step_env = {**env, **{k: substitute(str(v)) for k, v in step.get("env", {}).items()}}
        assert "${{" not in step["run"]  # inputs only through the environment
        done = subprocess.run(["bash", "--noprofile", "--norc", "-eo", "pipefail", "-c",
                               step["run"]], cwd=repo, env=step_env, capture_output=True,
                              text=True, timeout=300, check=False)
        code, output = done.returncode, done.stdout + done.stderr
    return code, output


def _git(cwd: Path, *args: str) -> str:
    return subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@t", *args], cwd=cwd,
                          check=True, capture_output=True, text=True).stdout


@pytest.fixture
def repo(tmp_path) -> Path:
    root = tmp_path / "team"
    shutil.copytree(DEMO, root / "src" / "demo_description")
    _git(root.parent, "init", "-q", str(root))
    _git(root, "add", "-A")
    _git(root, "commit", "-qm", "base")
    return root


def test_readme_workflow_annotates_and_writes_sarif(repo):
    step = _workflow_step()
    assert step["uses"] == "./tools/urdftool"
    wheel = repo / "src" / "demo_description" / "urdf" / "wheel.xacro"
    wheel.write_text(wheel.read_text().replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>'))
    code, output = run_action(repo, step["with"], {})
    assert code == 1, output
    line = next(n for n, t in enumerate(wheel.read_text().splitlines(), 1) if "<axis" in t)
    assert f"::error file=src/demo_description/urdf/wheel.xacro,line={line}," in output
    sarif = json.loads((repo / step["with"]["sarif"]).read_text())
    [result] = sarif["runs"][0]["results"]
    assert result["ruleId"] == "joint.zero-axis"
    assert result["locations"][0]["physicalLocation"]["region"]["startLine"] == line


def test_changed_files_on_a_pull_request(repo):
    entry = repo / "src" / "demo_description" / "urdf" / "robot.urdf.xacro"
    entry.write_text(entry.read_text().replace('<mass value="2.0"/>', '<mass value="0"/>'))
    _git(repo, "commit", "-qam", "an old defect on the base branch")
    _git(repo, "update-ref", "refs/remotes/origin/main", "HEAD")
    # untouched files only: nothing to check
    code, output = run_action(repo, {"changed-files": "true"}, {"base_ref": "main"})
    assert code == 0 and "no robot file changed" in output
    wheel = repo / "src" / "demo_description" / "urdf" / "wheel.xacro"
    wheel.write_text(wheel.read_text().replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>'))
    _git(repo, "commit", "-qam", "the pull request")
    code, output = run_action(repo, {"changed-files": "true"}, {"base_ref": "main"})
    assert code == 1
    errors = [line for line in output.splitlines() if line.startswith("::error")]
    assert len(errors) == 1 and "wheel.xacro" in errors[0], output  # not the old defect
    assert "1 finding(s) in files that were not given" in output
