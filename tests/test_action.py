"""The GitHub Action (action.yml) and the README's workflow, run here the way the runner runs a
composite action: the README's step `uses: ./tools/urdftool` with its `with:` inputs, each
`run:` step of action.yml itself (never a copy) in `bash -eo pipefail` with `${{ inputs.* }}`,
`${{ github.* }}`, `${{ runner.* }}` and `${{ steps.*.outputs.* }}` substituted and the
variables the runner sets (`CI`, `GITHUB_ACTIONS`, `RUNNER_TEMP`, `GITHUB_OUTPUT`...).
`actions/setup-python`, `actions/cache` and the pip install are the runner's business: urdftool
is already installed here (the install step is checked to take the mesh extra, the cache step
to keep the directory urdftool writes its cache in)."""

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
PACKAGES = Path(__file__).parent / "data" / "packages"
BROKEN = '<?xml version="1.0"?>\n<robot name="r"><link name="base"></robot>\n'
SLOW = "--timeout 120"  # a mesh parsed in the sandboxed reader on a loaded test machine


def _workflow_step() -> dict:
    readme = (ROOT / "README.md").read_text()
    text = readme.split("<!-- snippet: github-workflow ", 1)[1].split("```yaml\n", 1)[1]
    workflow = yaml.safe_load(text.split("```", 1)[0])
    [job] = workflow["jobs"].values()
    [step] = [s for s in job["steps"] if s.get("uses", "").startswith("./")]
    return step


class Run:
    def __init__(self, code: int, output: str, calls: list[list[str]], cache_step: dict | None,
                 runner_temp: Path, summary: str = "", artifact: dict | None = None):
        self.code, self.output, self.calls = code, output, calls
        self.cache_step, self.runner_temp = cache_step, runner_temp
        self.summary, self.artifact = summary, artifact  # $GITHUB_STEP_SUMMARY, upload-artifact

    def annotations(self) -> list[str]:
        """The annotations on a file."""
        return [line for line in self.output.splitlines()
                if line.startswith("::") and " file=" in line]


def run_action(repo: Path, inputs: dict, github: dict) -> Run:
    """Run action.yml's steps in ``repo`` as the runner does; every `urdftool` call is logged
    (a shim in front of the real command on PATH)."""
    action = yaml.safe_load((ROOT / "action.yml").read_text())
    values = {name: str(spec.get("default", "")) for name, spec in action["inputs"].items()}
    values.update({k: str(v) for k, v in inputs.items()})
    work = repo.parent / f"runner-{len(list(repo.parent.glob('runner-*')))}"
    temp, shims = work / "temp", work / "bin"
    temp.mkdir(parents=True)
    shims.mkdir()
    calls = work / "calls.json"
    shim = shims / "urdftool"
    shim.write_text(f"#!{sys.executable}\nimport json, sys\n"
                    f"with open({str(calls)!r}, 'a') as log:\n"
                    "    log.write(json.dumps(sys.argv[1:]) + '\\n')\n"
                    "from urdftool.cli import main\nmain()\n")
    shim.chmod(0o755)
    outputs: dict[str, dict[str, str]] = {}

    def substitute(text: str) -> str:
        def value(match):
            scope, name = match.group(1), match.group(2)
            if scope == "inputs":
                return values[name]
            if scope == "runner":
                return {"temp": str(temp), "os": "Linux"}[name]
            if scope.startswith("steps."):
                return outputs.get(scope.split(".")[1], {}).get(name, "")
            return github.get(name, "")

        return re.sub(r"\$\{\{\s*(inputs|github|runner|steps\.[\w-]+\.outputs)\.([\w-]+)\s*\}\}",
                      value, text)

    def condition(text: str | None) -> bool:  # the `if:` forms action.yml uses, joined by &&
        if text is None:
            return True
        for part in text.split("&&"):
            scope, name, op, wanted = re.fullmatch(
                r"\s*(inputs|github)\.([\w-]+) (==|!=) '(\w*)'\s*", part).groups()
            actual = values[name] if scope == "inputs" else github.get(name, "")
            if (actual == wanted) != (op == "=="):
                return False
        return True

    summary_file = work / "step-summary.md"
    artifact = None
    env = {**os.environ, "GITHUB_ACTION_PATH": str(ROOT), "CI": "true", "GITHUB_ACTIONS": "true",
           "GITHUB_STEP_SUMMARY": str(summary_file),
           "RUNNER_TEMP": str(temp), "RUNNER_OS": "Linux", "GITHUB_WORKSPACE": str(repo),
           "XDG_CACHE_HOME": str(work / "xdg"),
           "PATH": f"{shims}{os.pathsep}{Path(sys.executable).parent}{os.pathsep}"
                   f"{os.environ['PATH']}",
           "PYTHONPATH": str(ROOT)}
    for name in ("URDFTOOL_DEBUG", "URDFTOOL_CACHE_DIR"):
        env.pop(name, None)
    code, output, cache_step = 0, "", None
    for step in action["runs"]["steps"]:
        if "uses" in step:
            if step["uses"].startswith("actions/cache@"):
                if condition(step["if"]):
                    cache_step = {k: substitute(str(v)) for k, v in step["with"].items()}
                continue
            if step["uses"].startswith("actions/upload-artifact@"):
                if condition(step["if"]):
                    artifact = {k: substitute(str(v)) for k, v in step["with"].items()}
                continue
            assert step["uses"].startswith("actions/setup-python@")
            continue
        if step["name"] == "Install urdftool":
            assert '"${GITHUB_ACTION_PATH}[$extras]"' in step["run"] and "extras=mesh" in step["run"]
            continue
        if not condition(step.get("if")):
            continue
        assert "${{" not in step["run"]  # inputs only through the environment
        github_output = work / f"output-{step.get('id', 'step')}"
        step_env = {**env, "GITHUB_OUTPUT": str(github_output),
                    **{k: substitute(str(v)) for k, v in step.get("env", {}).items()}}
        done = subprocess.run(["bash", "--noprofile", "--norc", "-eo", "pipefail", "-c",
                               step["run"]], cwd=repo, env=step_env, capture_output=True,
                              text=True, timeout=300, check=False)
        code, output = done.returncode, done.stdout + done.stderr
        if "id" in step and github_output.exists():
            outputs[step["id"]] = dict(line.split("=", 1) for line in
                                       github_output.read_text().splitlines())
        if code:
            break
    logged = [json.loads(line) for line in calls.read_text().splitlines()] \
        if calls.exists() else []
    return Run(code, output, logged, cache_step, temp,
               summary_file.read_text() if summary_file.exists() else "", artifact)


def _git(cwd: Path, *args: str) -> str:
    return subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@t", *args], cwd=cwd,
                          check=True, capture_output=True, text=True).stdout


@pytest.fixture
def repo(tmp_path) -> Path:
    root = tmp_path / "team"
    for name in ("demo_description", "arm_description"):
        shutil.copytree(PACKAGES / name, root / "src" / name)
    _git(root.parent, "init", "-q", str(root))
    _git(root, "add", "-A")
    _git(root, "commit", "-qm", "base")
    return root


def test_readme_workflow_annotates_and_writes_sarif_in_one_pass(repo):
    step = _workflow_step()
    assert step["uses"] == "./tools/urdftool"
    wheel = repo / "src" / "demo_description" / "urdf" / "wheel.xacro"
    wheel.write_text(wheel.read_text().replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>'))
    run = run_action(repo, step["with"], {})
    assert run.code == 1, run.output
    line = next(n for n, t in enumerate(wheel.read_text().splitlines(), 1) if "<axis" in t)
    assert f"::error file=src/demo_description/urdf/wheel.xacro,line={line}," in run.output
    sarif = json.loads((repo / step["with"]["sarif"]).read_text())
    # (the arm's mesh may be reported not checked in time on a loaded machine)
    [result] = [r for r in sarif["runs"][0]["results"] if r["ruleId"] == "joint.zero-axis"]
    assert result["locations"][0]["physicalLocation"]["region"]["startLine"] == line
    # one urdftool run wrote both, the file names after `--`
    [call] = [c for c in run.calls if c[:1] == ["check"]]
    assert call[call.index("--format") + 1] == "github"
    assert call[call.index("--extra-output") + 1] == "sarif:" + step["with"]["sarif"]
    assert call[call.index("--") + 1:] == ["src"]
    # the job summary, from the same run: the verdict, the rule, the finding's location
    assert run.summary.startswith("### urdftool check failed: 1 error(s)"), run.summary
    assert "| error | `joint.zero-axis` | 1 |" in run.summary
    assert f"src/demo\\_description/urdf/wheel.xacro\\:{line}\\:" in run.summary
    # --format github ends with the summary line, a plain log line
    assert any(re.fullmatch(r"urdftool: \d+ file\(s\): 1 error\(s\), \d+ warning\(s\), \d+ info", x)
               for x in run.output.splitlines()), run.output


def test_the_mesh_cache_is_the_one_actions_cache_keeps(repo):
    run = run_action(repo, {"paths": "src", "args": SLOW}, {"run_id": "42"})
    assert run.code == 0, run.output
    from urdftool import __version__

    assert run.cache_step == {
        "path": str(run.runner_temp / "urdftool-cache"),
        "key": f"urdftool-Linux-{__version__}-42",
        "restore-keys": f"urdftool-Linux-{__version__}-"}
    # the untrusted run (CI=true) wrote its cache there, because the Action named it
    stored = list((run.runner_temp / "urdftool-cache" / "mesh").iterdir())
    assert len(stored) == 1  # upper.stl of arm_description
    header = json.loads(stored[0].read_bytes().split(b"\n", 1)[0])
    assert header["key"]["path"].endswith("arm_description/meshes/upper.stl")
    off = run_action(repo, {"paths": "src", "cache": "false", "args": SLOW}, {"run_id": "43"})
    assert off.code == 0 and off.cache_step is None
    assert not (off.runner_temp / "urdftool-cache").exists()  # untrusted: no cache written
    assert not (off.runner_temp.parent / "xdg").exists()


def _pull_request(repo: Path) -> None:
    _git(repo, "update-ref", "refs/remotes/origin/main", "HEAD")


def test_changed_files_on_a_pull_request(repo):
    entry = repo / "src" / "demo_description" / "urdf" / "robot.urdf.xacro"
    entry.write_text(entry.read_text().replace('<mass value="2.0"/>', '<mass value="0"/>'))
    _git(repo, "commit", "-qam", "an old defect on the base branch")
    _pull_request(repo)
    # untouched files only: nothing to check
    run = run_action(repo, {"changed-files": "true", "sarif": "out.sarif"}, {"base_ref": "main"})
    assert run.code == 0 and "no file changed" in run.output
    sarif = json.loads((repo / "out.sarif").read_text())  # for the upload step: no results
    assert sarif["version"] == "2.1.0" and sarif["runs"][0]["results"] == []
    (repo / "out.sarif").unlink()
    wheel = repo / "src" / "demo_description" / "urdf" / "wheel.xacro"
    wheel.write_text(wheel.read_text().replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>'))
    _git(repo, "commit", "-qam", "the pull request")
    run = run_action(repo, {"changed-files": "true"}, {"base_ref": "main"})
    assert run.code == 1
    errors = [line for line in run.output.splitlines() if line.startswith("::error")]
    assert len(errors) == 1 and "wheel.xacro" in errors[0], run.output  # not the old defect
    assert "1 finding(s) in files that were not given" in run.output


def test_a_pull_request_that_deletes_an_included_file_fails_at_the_include(repo):
    """The Action passes deleted files (``--diff-filter=ACMRD``) and ``check --changed``
    re-checks the entries that included them: deleting wheel.xacro fails the pull request at
    the include line (it passed: no file was given, or exit 2 for a missing one)."""
    _pull_request(repo)
    _git(repo, "rm", "-q", "src/demo_description/urdf/wheel.xacro")
    _git(repo, "commit", "-qm", "the pull request deletes a fragment")
    run = run_action(repo, {"changed-files": "true"}, {"base_ref": "main"})
    listed = [line for line in run.output.splitlines() if "error xacro.error" in line]
    assert run.code == 1, run.output
    # in the log (the includer is not a file of the pull request: a notice, not annotated)
    assert len(listed) == 1 and "robot.urdf.xacro:" in listed[0] and "wheel.xacro" in listed[0]


def test_changed_files_annotate_only_the_pull_requests_files(repo):
    _pull_request(repo)
    limits = repo / "src" / "arm_description" / "config" / "joint_limits.yaml"
    limits.write_text(limits.read_text().replace("lower: -1.5", "lower: 2.5"))  # swapped
    _git(repo, "commit", "-qam", "a limit swapped in the YAML only")
    run = run_action(repo, {"changed-files": "true", "sarif": "out.sarif", "args": SLOW},
                     {"base_ref": "main"})
    assert run.code == 1, run.output  # the verdict: the defect is found...
    assert "joint.lower-above-upper" in run.output
    assert run.annotations() == [], run.output  # ...but the xacro is not in the pull request
    sarif = json.loads((repo / "out.sarif").read_text())
    assert [r["ruleId"] for r in sarif["runs"][0]["results"]] == ["joint.lower-above-upper"]
    # a pull request that also touches the xacro: annotated there
    arm = repo / "src" / "arm_description" / "urdf" / "arm.urdf.xacro"
    arm.write_text(arm.read_text() + "\n")
    _git(repo, "commit", "-qam", "and the xacro")
    run = run_action(repo, {"changed-files": "true", "args": SLOW}, {"base_ref": "main"})
    assert run.code == 1
    [annotation] = run.annotations()
    assert annotation.startswith("::error file=src/arm_description/urdf/arm.urdf.xacro,line=")


HOSTILE = ["--write-baseline=x.urdf", "-o.urdf", "--output-file=y.urdf", "--exit-zero.urdf",
           "--ignore=xml.urdf", "-x.urdf", "a:=b.urdf", "--changed", "--"]


@pytest.mark.parametrize("mode", ["changed-files", "paths"])
def test_file_names_never_become_options(repo, mode):
    """A pull request that adds broken robot files named like options: each is checked as a
    file (an annotation at its line 2), the run fails, nothing is written."""
    _pull_request(repo)
    for name in HOSTILE:
        (repo / name).write_text(BROKEN)
    _git(repo, "add", "-A", "--", *HOSTILE)
    _git(repo, "commit", "-qm", "hostile names")
    before = sorted(p.name for p in repo.iterdir())
    inputs = {"changed-files": "true"} if mode == "changed-files" else \
        {"paths": " ".join(HOSTILE)}
    run = run_action(repo, {**inputs, "sarif": "out.sarif"}, {"base_ref": "main"})
    assert run.code == 1, run.output
    annotated = {re.match(r"::error file=([^,]*),line=2,", a).group(1)
                 for a in run.annotations()}
    # named explicitly, every file is checked; among changed files, `--` and `--changed` are
    # no robot files (no entry reads them): skipped, and not parsed either
    checked = [n for n in HOSTILE if mode == "paths" or n.endswith(".urdf")]
    assert annotated == {n.replace(":", "%3A").replace(",", "%2C") for n in checked}, \
        run.output
    assert "no such option" not in run.output and "Usage" not in run.output
    assert sorted(p.name for p in repo.iterdir()) == sorted(before + ["out.sarif"])
    results = json.loads((repo / "out.sarif").read_text())["runs"][0]["results"]
    assert len(results) == len(checked)


@pytest.mark.slow  # diff of both revisions with pictures (~6 s of CPU, 14 s of wall): CI
def test_diff_summary_on_a_pull_request(repo):
    """`diff-summary`: the pull request's effect on each robot in the job summary (markdown,
    from the merge base), pictures as an artifact, and the check's verdict as before."""
    _pull_request(repo)
    limits = repo / "src" / "arm_description" / "config" / "joint_limits.yaml"
    limits.write_text(limits.read_text().replace("upper: 1.5", "upper: 1.25"))
    _git(repo, "commit", "-qam", "a tighter limit")
    run = run_action(repo, {"changed-files": "true", "diff-summary": "true",
                            "diff-pictures": "true", "args": SLOW}, {"base_ref": "main"})
    assert run.code == 0, run.output
    assert [c[0] for c in run.calls] == ["diff", "check"]
    assert run.calls[0][-1] == "origin/main...HEAD"
    assert "## urdftool diff: origin/main → HEAD" in run.summary
    assert "**joint shoulder** limit.upper: joint 'shoulder' limit upper 1.5 -\\> 1.25" in run.summary
    assert "![before](" in run.summary and "the artifact `urdftool-diff`" in run.summary
    assert run.artifact == {"name": "urdftool-diff", "path": str(run.runner_temp / "urdftool-diff"),
                            "if-no-files-found": "ignore"}
    assert len(list((run.runner_temp / "urdftool-diff").glob("*.png"))) == 2
    # not a pull request: no diff, no artifact
    push = run_action(repo, {"diff-summary": "true", "args": SLOW}, {})
    assert [c[0] for c in push.calls] == ["check"] and push.artifact is None
    assert "urdftool diff" not in push.summary  # (the check's own summary is there)
