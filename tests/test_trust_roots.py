"""Issue 20: one trust model. What a run may read is decided once (``urdftool.loader``) from the
operator (-P, --model-path, the package and model path variables) and the repository (its
version-control root); nothing a repository file says widens it. Attacked here with real
files in real git repositories, through every output format, ``--changed``, and both modes
(the answer is the same in both: one verdict)."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest
from conftest import run_urdftool

from urdftool.roots import OutsideRepository, Roots, clamp, has_vcs_component, repository_of

SECRET = "hunter2"
HEAD = '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
TAIL = '  <link name="base"/>\n</robot>\n'
MODES = ("--untrusted", "--trusted")
FORMATS = ("text", "json", "github", "sarif")


def _git_repo(tmp_path: Path) -> tuple[Path, Path]:
    """(a git checkout holding a description package, a directory of the machine outside it
    holding secrets)."""
    repo = tmp_path / "checkout"
    package = repo / "robot_description"
    (package / "urdf").mkdir(parents=True)
    (package / "package.xml").write_text("<package><name>robot_description</name></package>")
    subprocess.run(["git", "init", "-q", str(repo)], check=True)
    (repo / ".git" / "config").write_text(
        f"[http]\n\textraheader = AUTHORIZATION: basic {SECRET}\n", encoding="utf-8")
    outside = tmp_path / "outside"
    (outside / "evil").mkdir(parents=True)
    (outside / "evil" / "package.xml").write_text("<package><name>evil</name></package>")
    (outside / "evil" / "secret.yaml").write_text(f"token: {SECRET}\n")
    (outside / "secret.xacro").write_text(HEAD + f'  <link name="{SECRET}"/>\n</robot>\n')
    return repo, outside


def _run(*args, cwd: Path, monkeypatch):
    monkeypatch.chdir(cwd)
    return run_urdftool(*args)


def _all_output(result) -> str:
    return result.out + result.err


@pytest.mark.parametrize("value", ["../outside/evil", "/", "../outside/missing", "../../"])
def test_configuration_packages_outside_the_repository_are_refused(value, tmp_path,
                                                                   monkeypatch):
    """The critical hole: ``packages`` in the repository's urdftool.toml was a -P. A value
    outside the repository is a one-line error naming the key and the value as written,
    whatever is there; nothing is read, in any mode or format."""
    repo, outside = _git_repo(tmp_path)
    (repo / "urdftool.toml").write_text(f'[packages]\nevil = "{value}"\n')
    robot = repo / "robot_description" / "urdf" / "robot.urdf.xacro"
    robot.write_text(HEAD + "  <link name=\"${xacro.load_yaml('$(find evil)/secret.yaml')"
                     "['token']}\"/>\n" + TAIL)
    answers = set()
    for mode in MODES:
        for fmt in FORMATS:
            result = _run("check", mode, "--format", fmt, "robot_description", cwd=repo,
                          monkeypatch=monkeypatch)
            assert result.code == 2, result
            assert SECRET not in _all_output(result)
            (line,) = result.err.strip().splitlines()
            assert "packages.evil" in line and "outside the repository" in line
            assert str(outside) not in line and "Traceback" not in line
            answers.add(line.replace(value, "VALUE"))
    assert len(answers) == 1  # the same in every mode and format


def test_a_configuration_value_outside_answers_the_same_whether_it_exists(tmp_path,
                                                                         monkeypatch):
    """No existence oracle: ``entries``, ``packages`` and ``baseline`` naming a file outside
    the repository say the same bytes whether or not the file is there."""
    repo, _ = _git_repo(tmp_path)
    robot = repo / "robot_description" / "urdf" / "robot.urdf"
    robot.write_text('<robot name="r"><link name="a"/></robot>')
    for key, template in (("entries", 'entries = ["{}"]\n'),
                          ("packages.evil", '[packages]\nevil = "{}"\n'),
                          ("baseline", 'baseline = "{}"\n')):
        answers = []
        for target in ("../outside/secret.xacro", "../outside/no-such-file.xacro"):
            (repo / "urdftool.toml").write_text(template.format(target))
            result = _run("check", "robot_description", cwd=repo, monkeypatch=monkeypatch)
            assert result.code == 2 and key in result.err, (key, result)
            answers.append(result.err.replace("no-such-file", "secret"))
        assert answers[0] == answers[1], key


def test_a_link_in_the_repository_to_outside_is_refused_as_written(tmp_path, monkeypatch):
    """A directory committed as a symlink to the machine: a configuration naming it, a mesh
    under it and an include through it are refused, and the report names the path as
    written, never where the link leads."""
    repo, outside = _git_repo(tmp_path)
    package = repo / "robot_description"
    (package / "meshes").symlink_to(outside / "evil")
    (outside / "evil" / "part.stl").write_text("solid s\nendsolid s\n")
    robot = package / "urdf" / "robot.urdf.xacro"
    robot.write_text(HEAD + '  <xacro:include filename="../meshes/secret.yaml"/>\n'
                     '  <link name="a"><visual><geometry><mesh filename="../meshes/part.stl"/>'
                     '</geometry></visual></link>\n' + TAIL)
    for mode in MODES:
        result = _run("check", mode, "--format", "json", "robot_description", cwd=repo,
                      monkeypatch=monkeypatch)
        assert SECRET not in result.out
        messages = [d["message"] for f in json.loads(result.out)["files"]
                    for d in f["diagnostics"]]
        assert any("../meshes/secret.yaml" in m and "outside the repository" in m
                   for m in messages), messages
        (mesh,) = [m for m in messages if "part.stl" in m]
        assert "robot_description/meshes/part.stl" in mesh and str(outside) not in mesh
    (repo / "urdftool.toml").write_text('[packages]\nevil = "robot_description/meshes"\n')
    result = _run("check", "robot_description", cwd=repo, monkeypatch=monkeypatch)
    assert result.code == 2 and "packages.evil" in result.err and str(outside) not in result.err


@pytest.mark.parametrize("payload", [
    "  <link name=\"${xacro.load_yaml('../../.git/config')}\"/>\n",
    '  <xacro:include filename="../../.git/config"/>\n',
    '  <xacro:include filename="../../.git/*"/>\n',
    '  <xacro:include filename="$(find robot_description)/../.git/config"/>\n',
])
def test_version_control_metadata_is_never_read(payload, tmp_path, monkeypatch):
    """``.git/config`` is where a CI checkout keeps its token: inside the repository, never
    readable (in-process and in the sandboxed reader, in both modes)."""
    repo, _ = _git_repo(tmp_path)
    robot = repo / "robot_description" / "urdf" / "robot.urdf.xacro"
    robot.write_text(HEAD + payload + TAIL)
    for mode in MODES:
        for fmt in ("json", "github"):
            result = _run("check", mode, "--format", fmt, "robot_description", cwd=repo,
                          monkeypatch=monkeypatch)
            assert SECRET not in _all_output(result) and "AUTHORIZATION" not in result.out
        expanded = _run("expand", mode, str(robot), cwd=repo, monkeypatch=monkeypatch)
        assert SECRET not in _all_output(expanded)
    (repo / "urdftool.toml").write_text('[packages]\ngit = ".git"\n')
    result = _run("check", "robot_description", cwd=repo, monkeypatch=monkeypatch)
    assert result.code == 2 and "packages.git" in result.err


def test_an_include_glob_outside_answers_the_same_whether_files_match(tmp_path, monkeypatch):
    repo, outside = _git_repo(tmp_path)
    robot = repo / "robot_description" / "urdf" / "robot.urdf.xacro"
    answers = []
    for pattern in ("secret*.xacro", "nothing*.xacro"):
        robot.write_text(HEAD + f'  <xacro:include filename="{outside}/{pattern}"/>\n' + TAIL)
        for mode in MODES:
            result = _run("check", mode, "--format", "json", "robot_description", cwd=repo,
                          monkeypatch=monkeypatch)
            assert SECRET not in result.out
            answers.append(result.out.replace(pattern, "PATTERN"))
    assert len(set(answers)) == 1


def test_changed_mode_holds_the_same_roots(tmp_path, monkeypatch):
    """``--changed`` (the hook, the Action) reads through the same roots."""
    repo, _ = _git_repo(tmp_path)
    (repo / "urdftool.toml").write_text('[packages]\nevil = "../outside/evil"\n')
    robot = repo / "robot_description" / "urdf" / "robot.urdf.xacro"
    robot.write_text(HEAD + "  <link name=\"${xacro.load_yaml('$(find evil)/secret.yaml')"
                     "['token']}\"/>\n" + TAIL)
    for mode in MODES:
        result = _run("check", mode, "--changed", "robot_description/urdf/robot.urdf.xacro",
                      cwd=repo, monkeypatch=monkeypatch)
        assert result.code == 2 and "packages.evil" in result.err
        assert SECRET not in _all_output(result)


def test_the_operator_widens_the_roots(tmp_path, monkeypatch):
    """What the repository may not do, the operator may: -P and ROS_PACKAGE_PATH."""
    repo, outside = _git_repo(tmp_path)
    robot = repo / "robot_description" / "urdf" / "robot.urdf.xacro"
    robot.write_text(HEAD + "  <link name=\"l_${xacro.load_yaml('$(find evil)/secret.yaml')"
                     "['token']}\"/>\n" + TAIL)
    for mode in MODES:
        given = _run("expand", mode, "-P", f"evil={outside / 'evil'}", str(robot), cwd=repo,
                     monkeypatch=monkeypatch)
        assert f"l_{SECRET}" in given.out, given
        monkeypatch.setenv("ROS_PACKAGE_PATH", str(outside))
        crawled = _run("expand", mode, str(robot), cwd=repo, monkeypatch=monkeypatch)
        assert f"l_{SECRET}" in crawled.out, crawled
        monkeypatch.delenv("ROS_PACKAGE_PATH")


def test_roots_unit(tmp_path):
    repo, outside = _git_repo(tmp_path)
    assert repository_of(repo / "robot_description" / "urdf") == repo.resolve()
    roots = Roots([repo], [outside / "evil"])
    assert roots.readable(repo / "robot_description" / "package.xml")
    assert not roots.readable(repo / ".git" / "config")
    assert not roots.readable(outside / "secret.xacro")
    assert roots.readable(outside / "evil" / "secret.yaml")
    assert repo / ".git" not in roots.landlock() and repo / "robot_description" in roots.landlock()
    with pytest.raises(OutsideRepository) as refused:
        clamp("../outside", repo, "packages.x", repo)
    assert str(outside) not in str(refused.value) and "'../outside'" in str(refused.value)
    assert os.fspath(clamp("robot_description", repo, "k", repo)) == str(
        (repo / "robot_description").resolve())


def _package_xml(directory: Path, name: str) -> Path:
    directory.mkdir(parents=True, exist_ok=True)
    (directory / "package.xml").write_text(f"<package format='3'>\n  <name>{name}</name>\n"
                                           "</package>\n")
    return directory


def test_ros_package_path_is_crawled_as_rospack_does(tmp_path):
    """Descend until a package.xml (any depth), not into a package, not into dot directories
    or directories marked CATKIN_IGNORE / COLCON_IGNORE / AMENT_IGNORE."""
    from urdftool.packages import PackageResolver, crawl

    workspace = tmp_path / "ws" / "src"
    deep = _package_xml(workspace / "a" / "b" / "c" / "deep_pkg", "deep_pkg")
    outer = _package_xml(workspace / "outer", "outer_pkg")
    _package_xml(outer / "nested", "nested_pkg")  # inside a package: rospack never looks
    _package_xml(workspace / ".hidden" / "hidden_pkg", "hidden_pkg")
    for marker in ("CATKIN_IGNORE", "COLCON_IGNORE", "AMENT_IGNORE"):
        ignored = workspace / marker.lower()
        _package_xml(ignored / "pkg", f"ignored_{marker.lower()}")
        (ignored / marker).write_text("")
    renamed = _package_xml(workspace / "dir_name", "name_in_xml")
    assert crawl(workspace) == {"deep_pkg": deep, "outer_pkg": outer, "name_in_xml": renamed}
    resolver = PackageResolver(environ={"ROS_PACKAGE_PATH": f"/nonexistent:{workspace}"})
    assert resolver.find("deep_pkg") == deep and resolver.find("nested_pkg") is None


def test_ament_prefix_path_through_the_index_and_share(tmp_path):
    from urdftool.packages import PackageResolver

    prefix = tmp_path / "install"
    index = prefix / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    (index / "indexed_pkg").write_text("")
    (prefix / "share" / "indexed_pkg").mkdir()
    _package_xml(prefix / "share" / "shared_dir", "shared_pkg")
    resolver = PackageResolver(environ={"AMENT_PREFIX_PATH": str(prefix)})
    assert resolver.find("indexed_pkg") == prefix / "share" / "indexed_pkg"
    assert resolver.find("shared_pkg") == prefix / "share" / "shared_dir"


def test_sibling_packages_anywhere_in_the_repository(tmp_path, monkeypatch):
    """$(find P) for a package elsewhere in the same repository, in both modes, without -P."""
    repo, _ = _git_repo(tmp_path)
    other = _package_xml(repo / "deps" / "vendor" / "parts_pkg", "parts_description")
    (other / "parts.xacro").write_text(HEAD + '  <link name="part_from_sibling"/>\n</robot>\n')
    robot = repo / "robot_description" / "urdf" / "robot.urdf.xacro"
    robot.write_text(HEAD + '  <xacro:include filename="$(find parts_description)/parts.xacro"/>'
                     "\n" + TAIL)
    for mode in MODES:
        result = _run("expand", mode, str(robot), cwd=repo, monkeypatch=monkeypatch)
        assert "part_from_sibling" in result.out, result


def test_an_unknown_package_says_where_it_looked(tmp_path, monkeypatch):
    repo, _ = _git_repo(tmp_path)
    robot = repo / "robot_description" / "urdf" / "robot.urdf.xacro"
    robot.write_text(HEAD + '  <xacro:include filename="$(find nowhere_pkg)/x.xacro"/>\n' + TAIL)
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)
    messages = set()
    for mode in MODES:
        result = _run("check", mode, "--format", "json", "robot_description", cwd=repo,
                      monkeypatch=monkeypatch)
        messages |= {d["message"] + " " + (d["hint"] or "") for f in json.loads(result.out)[
            "files"] for d in f["diagnostics"] if "nowhere_pkg" in d["message"]}
    (message,) = messages  # the same in both modes
    assert "the packages of the repository" in message and "ROS_PACKAGE_PATH (not set)" in message
    assert "-P nowhere_pkg=DIR" in message


def test_model_meshes_of_an_included_model_through_the_model_paths(tmp_path, monkeypatch):
    """The meshes of an SDF model:// include, found through --model-path and
    GZ_SIM_RESOURCE_PATH in both modes (they were false mesh.not-found errors under CI)."""
    repo, _ = _git_repo(tmp_path)
    models = tmp_path / "models"
    model = models / "crate"
    (model / "meshes").mkdir(parents=True)
    (model / "meshes" / "box.stl").write_bytes(
        (Path(__file__).resolve().parent.parent / "urdftool" / "physics" / "examples"
         / "open_box.stl").read_bytes())
    (model / "model.config").write_text('<model><sdf version="1.7">model.sdf</sdf></model>')
    (model / "model.sdf").write_text(
        '<sdf version="1.7"><model name="crate"><link name="body"><visual name="v"><geometry>'
        "<mesh><uri>model://crate/meshes/box.stl</uri></mesh></geometry></visual></link>"
        "</model></sdf>")
    world = repo / "robot_description" / "world.sdf"
    world.write_text('<sdf version="1.7"><model name="m"><link name="a"/><include>'
                     "<uri>model://crate</uri></include></model></sdf>")
    for how in ("flag", "variable"):
        args = ["--model-path", str(models)] if how == "flag" else []
        if how == "variable":
            monkeypatch.setenv("GZ_SIM_RESOURCE_PATH", str(models))
        found = []
        for mode in MODES:
            result = _run("check", mode, "--no-cache", "--format", "json", *args, str(world),
                          cwd=repo, monkeypatch=monkeypatch)
            found.append(sorted((d["rule"], d["line"]) for f in json.loads(result.out)["files"]
                                for d in f["diagnostics"]))
            assert not [r for r, _ in found[-1] if r.startswith(("mesh.not-found", "sdf.include",
                                                                  "sdf.mesh-uri"))], found
        assert found[0] == found[1]


def test_realpaths_are_memoised_for_one_run_only(tmp_path):
    """``roots.resolved`` keeps a realpath for the run (the corpus asks for the same paths
    thousands of times); the next run (``loader.run_roots``) asks the file system again, so a
    link pointed outside the repository between two runs of one process (the editor) is
    refused in the second."""
    from urdftool import loader, roots

    repo = tmp_path / "repo"
    (repo / ".git").mkdir(parents=True)
    (repo / "meshes").mkdir()
    (repo / "meshes" / "a.stl").write_text("solid a\nendsolid a\n")
    outside = tmp_path / "outside.stl"
    outside.write_text("solid b\nendsolid b\n")
    link = repo / "link.stl"
    link.symlink_to(repo / "meshes" / "a.stl")
    run = loader.run_roots([repo])
    assert run.readable(link)
    assert roots.resolved(link) == os.path.realpath(repo / "meshes" / "a.stl")
    link.unlink()
    link.symlink_to(outside)
    assert roots.resolved(link) == os.path.realpath(repo / "meshes" / "a.stl")  # same run
    run = loader.run_roots([repo])  # a new run
    assert roots.resolved(link) == os.path.realpath(outside)
    assert not run.readable(link)
    relative = os.path.relpath(link)  # relative to the working directory: never kept
    assert roots.resolved(relative) == os.path.realpath(outside)
    assert relative not in roots._RESOLVED


def test_memoised_realpath_is_realpath(tmp_path):
    """``roots.resolved`` (each directory resolved once a run, a plain last name appended)
    answers what ``os.path.realpath`` answers, through links, links to links, ``..`` after
    missing folders, loops and an unreadable link, fresh or with the memo of earlier names."""
    from hypothesis import given, settings
    from hypothesis import strategies as st

    from urdftool.roots import forget_resolved, resolved

    root = tmp_path / "tree"
    (root / "a" / "b").mkdir(parents=True)
    (root / "a" / "b" / "f").write_text("")
    for name, target in (("l", root / "a" / "b"), ("loop1", root / "loop2"),
                         ("loop2", root / "loop1"), ("self", "self"), ("p", "/proc/1/root")):
        os.symlink(target, root / name)
    os.symlink("../a", root / "a" / "b" / "up")
    os.symlink("f", root / "a" / "b" / "lf")
    parts = ["a", "b", "l", "loop1", "loop2", "up", "f", "lf", "..", ".", "x", "", "p", "self"]

    def answer(function, name):
        try:
            return function(name)
        except OSError as exc:
            return type(exc)

    @settings(max_examples=500, deadline=None)
    @given(st.lists(st.sampled_from(parts), max_size=7), st.booleans())
    def same(names, fresh):
        name = str(root) + "/" + "/".join(names)
        if fresh:
            forget_resolved()
        assert answer(resolved, name) == answer(os.path.realpath, name), name

    same()
    forget_resolved()


def test_readable_on_text_is_pathlibs_answer():
    """``Roots.readable`` compares realpaths as text: the same answer as pathlib's
    ``is_relative_to`` and ``has_vcs_component`` for roots that are prefixes of each other
    as text (``/r`` and ``/ra``), the file-system root, roots inside metadata, and targets in
    and out of ``.git``/``.hg``/``.svn`` (or names that merely contain them)."""
    import random

    rng = random.Random(3)
    parts = ["tmp", "r", "ra", "a", ".git", "ab", ".hg", "a.git", ".svnx", ".svn"]
    choices = ["/", "/tmp/r", "/tmp/r/a", "/tmp/ra", "/tmp/r/.git"]
    for _ in range(5000):
        chosen = rng.sample(choices, rng.randint(1, 3))
        roots = Roots([], chosen)
        target = Path("/" + "/".join(rng.choice(parts) for _ in range(rng.randint(0, 5))))
        real = Path(os.path.realpath(target))
        expected = any(real.is_relative_to(root) and not has_vcs_component(real, root)
                       for root in roots.all())
        assert roots.readable(target) == expected, (chosen, target)
