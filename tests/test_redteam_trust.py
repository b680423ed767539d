"""Red team of issue 20 (one trust model) after it landed: attacks a pull request can commit,
run through ``urdftool check`` in both modes (``--untrusted`` is what ``CI=true`` implies,
``--trusted`` the hook's desk mode). Each case holds when nothing outside the repository (or in
its ``.git``) is read, the answer is the same whether the outside target exists (no existence
oracle), and the refusal names the file as written. Fast: in-process runs on tiny files."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest
from conftest import run_urdftool

SECRET = "hunter2"
MODES = ("--untrusted", "--trusted")
XACRO = ('<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
         '  <link name="{body}"/>\n</robot>\n')


def _checkout(tmp_path: Path) -> tuple[Path, Path]:
    """(a git checkout with a description package, a directory outside it with secrets)."""
    repo = tmp_path / "checkout"
    (repo / "robot_description" / "urdf").mkdir(parents=True)
    (repo / "robot_description" / "package.xml").write_text(
        "<package><name>robot_description</name></package>")
    subprocess.run(["git", "init", "-q", str(repo)], check=True)
    with open(repo / ".git" / "config", "a") as config:
        config.write(f"[http]\n\textraheader = {SECRET}\n")
    outside = tmp_path / "outside"
    (outside / "evil").mkdir(parents=True)
    (outside / "evil" / "package.xml").write_text("<package><name>evil</name></package>")
    (outside / "evil" / "secret.yaml").write_text(f"token: {SECRET}\n")
    (outside / "conf.toml").write_text(f"{SECRET}_key = 1\n")
    return repo, outside


def _check(repo: Path, mode: str, *args: str):
    cwd = os.getcwd()
    os.chdir(repo)
    try:
        return run_urdftool("check", mode, *args)
    finally:
        os.chdir(cwd)


# a committed configuration file that is a link: to a TOML file outside (whose keys the
# "unknown key" error would print), to the job token's .git/config, to a device
@pytest.mark.parametrize("name", ["urdftool.toml", "pyproject.toml"])
@pytest.mark.parametrize("target", ["{outside}/conf.toml", "{repo}/.git/config", "/dev/zero",
                                    "/proc/self/environ"])
@pytest.mark.parametrize("mode", MODES)
def test_a_configuration_linked_outside_is_not_read(name, target, mode, tmp_path):
    repo, outside = _checkout(tmp_path)
    (repo / "robot_description" / "urdf" / "r.urdf").write_text(
        '<?xml version="1.0"?>\n<robot name="r"><link name="base"/></robot>\n')
    answers = set()
    for exists in (True, False):  # a dangling link answers the same: no existence oracle
        link = repo / name
        if link.is_symlink():
            link.unlink()
        where = target.format(outside=outside, repo=repo)
        link.symlink_to(where if exists else where + ".missing")
        result = _check(repo, mode, "robot_description")
        assert result.code == 2, result
        (line,) = result.err.strip().splitlines()
        assert SECRET not in result.out + result.err
        assert f"{name}: a link to outside the repository" in line
        assert str(outside) not in line and ".git" not in line
        answers.add(line)
    assert len(answers) == 1


@pytest.mark.parametrize("target", ["{outside}/evil/package.xml", "{outside}/missing.xml",
                                    "{repo}/.git/config"])
@pytest.mark.parametrize("mode", MODES)
def test_a_package_xml_linked_outside_names_no_package(target, mode, tmp_path):
    """A committed ``package.xml`` that links out: its name is not read (the crawl of the
    repository and the file's own package alike), so ``$(find evil)`` is not found and the
    answer is the same whether the outside file exists."""
    repo, outside = _checkout(tmp_path)
    package = repo / "pk2"
    (package / "urdf").mkdir(parents=True)
    (package / "package.xml").symlink_to(target.format(outside=outside, repo=repo))
    (package / "urdf" / "a.urdf.xacro").write_text(XACRO.format(body="$(find evil)"))
    result = _check(repo, mode, "--format", "json", "pk2/urdf/a.urdf.xacro")
    assert result.code == 1, result
    assert "package 'evil' not found" in result.out
    assert str(repo / "pk2") not in result.out  # $(find evil) never became the package


@pytest.mark.parametrize("ref", ["../../../outside/m.stl", "../link/m.stl",
                                 "file://{outside}/m.stl",
                                 "package://robot_description/../../outside/m.stl",
                                 "package://robot_description/../.git/config"])
@pytest.mark.parametrize("mode", MODES)
def test_a_mesh_outside_is_reported_as_written_and_never_probed(ref, mode, tmp_path):
    """A mesh outside the repository (through ``..``, a committed directory link, a file URI,
    a package URI, into ``.git``): the same finding whether the file is there or not, naming
    the reference as written (the link not resolved)."""
    repo, outside = _checkout(tmp_path)
    (repo / "robot_description" / "link").symlink_to(outside)
    urdf = repo / "robot_description" / "urdf" / "m.urdf"
    answers = []
    for name in ("m.stl", "missing.stl"):
        (outside / "m.stl").write_text("solid s\nendsolid s\n") if name == "m.stl" else \
            (outside / "m.stl").unlink()
        urdf.write_text('<?xml version="1.0"?>\n<robot name="r"><link name="base"><visual>'
                        f'<geometry><mesh filename="{ref.format(outside=outside)}"/>'
                        '</geometry></visual></link></robot>\n')
        result = _check(repo, mode, "robot_description/urdf/m.urdf")
        assert SECRET not in result.out + result.err
        answers.append(result.out)
    assert answers[0] == answers[1]
    assert "mesh.not-found" in answers[0]
    if ref.startswith("../link"):
        assert "robot_description/link/m.stl" in answers[0]  # as written, not its target


@pytest.mark.parametrize("ref", ["../../../outside/evil/secret.yaml", "../../.git/config",
                                 "../../gitlink/config", "$(find robot_description)/../.git/config",
                                 "/proc/self/environ", "file://{outside}/evil/secret.yaml"])
@pytest.mark.parametrize("mode", MODES)
def test_load_yaml_outside_or_in_git_is_refused(ref, mode, tmp_path):
    repo, outside = _checkout(tmp_path)
    (repo / "gitlink").symlink_to(".git")
    (repo / "robot_description" / "urdf" / "a.urdf.xacro").write_text(XACRO.format(
        body="${xacro.load_yaml('" + ref.format(outside=outside) + "')}"))
    result = _check(repo, mode, "robot_description/urdf/a.urdf.xacro")
    assert result.code == 1, result
    assert "xacro.error" in result.out
    assert SECRET not in result.out + result.err
    assert "repositoryformatversion" not in result.out


@pytest.mark.parametrize("value", ["~", "/", "../outside/evil", "link", "link/evil", ".git",
                                   "gitlink"])
@pytest.mark.parametrize("mode", MODES)
def test_configuration_packages_never_widen(value, mode, tmp_path):
    repo, outside = _checkout(tmp_path)
    (repo / "link").symlink_to(outside)
    (repo / "gitlink").symlink_to(".git")
    (repo / "urdftool.toml").write_text(f'[packages]\nevil = "{value}"\n')
    (repo / "robot_description" / "urdf" / "a.urdf.xacro").write_text(XACRO.format(
        body="${xacro.load_yaml('$(find evil)/secret.yaml')['token']}"))
    result = _check(repo, mode, "robot_description/urdf/a.urdf.xacro")
    assert result.code in (1, 2), result
    assert SECRET not in result.out + result.err
    assert "Traceback" not in result.err


@pytest.mark.parametrize("command", ["check", "expand", "tree", "convert", "inertia", "limits",
                                     "dh", "jacobian", "sim", "check-dir", "check-changed"])
@pytest.mark.parametrize("mode", MODES)
def test_a_committed_link_out_answers_the_same_whether_its_target_exists(command, mode,
                                                                        tmp_path):
    """A robot file that is a link out of the repository: one line, exit 2, naming the file as
    given, the same bytes whether the target exists (was: "no such file" when it did not, an
    existence oracle on the runner's files)."""
    repo, outside = _checkout(tmp_path)
    link = repo / "robot_description" / "urdf" / "flink.urdf"
    (outside / "s.urdf").write_text(f'<?xml version="1.0"?>\n<robot name="{SECRET}">'
                                    f'<link name="{SECRET}"></robot>\n')
    name = "robot_description/urdf/flink.urdf"
    args = {"check-dir": ("check", mode, "robot_description"),
            "check-changed": ("check", mode, "--changed", "--", name)}.get(
        command, (command, mode, name))
    answers = []
    cwd = os.getcwd()
    os.chdir(repo)
    try:
        for target in ("s.urdf", "missing.urdf"):
            if link.is_symlink():
                link.unlink()
            link.symlink_to(outside / target)
            result = run_urdftool(*args)
            assert result.code == 2, result
            assert SECRET not in result.out + result.err
            answers.append(result.err)
    finally:
        os.chdir(cwd)
    assert answers[0] == answers[1]
    assert answers[0].strip() == (f"urdftool: {name}: outside the repository and the "
                                  "operator's directories (a link out of it, or version-control "
                                  "metadata); not read")


@pytest.mark.parametrize("target", ["{outside}/inc.xacro", "{repo}/.git/inc.xacro"])
def test_a_directory_walk_reads_no_xacro_that_links_out(target, tmp_path, monkeypatch):
    """``sim DIR`` finds robots with ``source.discover``, which reads each xacro's includes to
    tell fragments from robots: a committed ``.xacro`` link out is not read (its includes
    would drop a robot of the repository from the walk; its target's content is the
    machine's), the link itself is kept for the loader to refuse."""
    from urdftool.source import discover

    repo, outside = _checkout(tmp_path)
    urdf = repo / "robot_description" / "urdf"
    (urdf / "r.urdf.xacro").write_text(XACRO.format(body="b"))
    where = Path(target.format(outside=outside, repo=repo))
    where.write_text(XACRO.format(body="x").replace(
        "<link", '<xacro:include filename="r.urdf.xacro"/><link'))
    (urdf / "l.urdf.xacro").symlink_to(where)
    monkeypatch.chdir(repo)
    assert discover(["robot_description"]) == [Path("robot_description/urdf/l.urdf.xacro"),
                                                Path("robot_description/urdf/r.urdf.xacro")]
