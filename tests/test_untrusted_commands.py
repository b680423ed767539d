"""Every command that loads a file takes ``--untrusted/--trusted`` and follows the same default
(untrusted when ``CI`` is set): ``limits``, ``tree``, ``dh``, ``jacobian``, ``sim`` and ``convert``
refuse what ``check`` and ``expand`` refuse, a xacro that reads an environment variable or a
file outside its package (an SDF include, for ``convert``)."""

from __future__ import annotations

import json

import pytest
from conftest import ROBOTS, run_urdftool

HEAD = '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
# a moving joint whose name carries the payload: limits prints joint names, tree link names
BODY = """  <link name="base"/>
  <link name="{name}"/>
  <joint name="{name}" type="revolute">
    <parent link="base"/><child link="{name}"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
</robot>
"""
COMMANDS = ["limits", "tree", "dh", "jacobian"]


def _package(tmp_path):
    package = tmp_path / "robot_description"
    (package / "urdf").mkdir(parents=True)
    (package / "package.xml").write_text("<package><name>robot_description</name></package>")
    (tmp_path / "secret.yaml").write_text("token: hunter2\n")
    return package


@pytest.fixture
def env_reader(tmp_path, monkeypatch):
    monkeypatch.setenv("URDFTOOL_SECRET", "hunter2")
    path = _package(tmp_path) / "urdf" / "env.urdf.xacro"
    path.write_text(HEAD + BODY.format(name="j_$(optenv URDFTOOL_SECRET none)"))
    return path


@pytest.fixture
def file_reader(tmp_path, monkeypatch):
    path = _package(tmp_path) / "urdf" / "file.urdf.xacro"
    path.write_text(HEAD + BODY.format(
        name="j_${xacro.load_yaml('../../secret.yaml')['token']}"))
    monkeypatch.chdir(path.parent)
    return path


@pytest.mark.parametrize("command", COMMANDS)
def test_env_read_sees_nothing_unless_allowed(command, env_reader):
    # in both modes: --trusted only means "not in the sandboxed reader", never "print my secrets"
    for mode in ("--trusted", "--untrusted"):
        hidden = run_urdftool(command, mode, env_reader)
        assert hidden.code == 0, hidden.err
        assert "hunter2" not in hidden.out + hidden.err and "j_none" in hidden.out
        allowed = run_urdftool(command, mode, "--allow-env", "URDFTOOL_SECRET", env_reader)
        assert "j_hunter2" in allowed.out  # the payload works


@pytest.mark.parametrize("command", COMMANDS)
def test_untrusted_file_outside_the_package_is_refused(command, file_reader):
    # one trust model (issue 20): refused in both modes, the same way
    for mode in ("--untrusted", "--trusted"):
        result = run_urdftool(command, mode, file_reader)
        assert result.code == 2 and "hunter2" not in result.out + result.err
        assert "outside the repository" in result.err and "secret.yaml" in result.err
        assert len(result.err.strip().splitlines()) == 1


@pytest.mark.parametrize("command", COMMANDS)
def test_ci_variable_makes_untrusted_the_default(command, env_reader, monkeypatch):
    # shown by where the xacro file is read: the sandboxed reader only when untrusted
    from urdftool import sandbox

    calls = []
    original = sandbox.load_source
    monkeypatch.setattr(sandbox, "load_source", lambda *a: calls.append(1) or original(*a))
    monkeypatch.setenv("CI", "true")
    assert run_urdftool(command, env_reader).code == 0 and calls == [1]
    assert run_urdftool(command, "--trusted", env_reader).code == 0 and calls == [1]
    monkeypatch.setenv("CI", "")
    assert run_urdftool(command, env_reader).code == 0 and calls == [1]


def test_sim_untrusted_refuses_a_file_outside_the_package(file_reader):
    for mode in ("--untrusted", "--trusted"):  # one trust model (issue 20)
        result = run_urdftool("sim", mode, "--format", "json", "--duration", "0.1",
                              file_reader)
        assert result.code == 1 and "hunter2" not in result.out + result.err
        assert "outside the repository" in result.out and "secret.yaml" in result.out


def test_convert_untrusted_reads_no_include_outside_the_package(tmp_path, monkeypatch):
    outside = tmp_path / "machine" / "secret_model"
    outside.mkdir(parents=True)
    (outside / "model.sdf").write_text('<sdf version="1.7"><model name="hunter2">'
                                       '<link name="hunter2_link"/></model></sdf>')
    path = _package(tmp_path) / "world.sdf"
    path.write_text('<sdf version="1.7"><model name="m"><link name="a"/><include>'
                    f"<uri>{outside / 'model.sdf'}</uri></include></model></sdf>")
    monkeypatch.chdir(path.parent)
    for mode in ("--untrusted", "--trusted"):  # one trust model (issue 20)
        result = run_urdftool("convert", mode, path)
        assert "hunter2" not in result.out and "outside the repository" in result.err, result


def test_optenv_default_taken_for_a_hidden_variable_is_a_finding(env_reader, monkeypatch):
    """Issue 14: a default taken because urdftool hides a set variable (in every mode) is
    said, with how to allow it; an unset variable's default (what xacro takes too) and an
    allowed one are not findings."""

    def hidden(*args):
        result = run_urdftool("check", "--format", "json", *args, env_reader)
        return [d for f in json.loads(result.out)["files"] for d in f["diagnostics"]
                if d["rule"] == "xacro.env-not-allowed"]

    (finding,) = hidden("--untrusted")
    assert finding["severity"] == "warning" and "URDFTOOL_SECRET" in finding["message"]
    assert finding["hint"] == "--allow-env URDFTOOL_SECRET" and "hunter2" not in str(finding)
    assert finding["line"] == 4 and finding["path"].endswith("env.urdf.xacro")
    assert hidden("--untrusted", "--allow-env", "URDFTOOL_SECRET") == []
    assert [f["line"] for f in hidden("--trusted")] == [4]
    assert hidden("--trusted", "--allow-env", "URDFTOOL_SECRET") == []
    monkeypatch.delenv("URDFTOOL_SECRET")
    assert hidden("--untrusted") == []


def _messages(path, rule_family="xacro"):
    result = run_urdftool("check", "--untrusted", "--format", "json", path)
    return [d["message"] for f in json.loads(result.out)["files"] for d in f["diagnostics"]
            if d["rule"].startswith(rule_family)]


def test_an_include_glob_outside_the_roots_names_no_file_it_found(tmp_path):
    outside = tmp_path / "machine"
    outside.mkdir()
    (outside / "id_rsa_hunter2.xacro").write_text('<robot xmlns:xacro="http://www.ros.org/wiki/'
                                                  'xacro"><link name="stolen"/></robot>')
    answers = []
    package = _package(tmp_path)
    for pattern in ("id_rsa_*.xacro", "nothing_*.xacro"):
        path = package / "urdf" / f"glob_{pattern[:4]}.urdf.xacro"
        path.write_text(HEAD + f'  <xacro:include filename="../../machine/{pattern}"/>\n'
                        + BODY.format(name="j"))
        messages = _messages(path)
        assert not any("hunter2" in m or "stolen" in m for m in messages), messages
        answers.append([m.replace(pattern, "PATTERN") for m in messages])
    assert answers[0] == answers[1]


def test_model_uri_outside_the_roots_answers_the_same_whether_it_exists(tmp_path):
    (tmp_path / "exists").mkdir()
    (tmp_path / "exists" / "model.sdf").write_text(
        '<sdf version="1.7"><model name="x"><link name="l"/></model></sdf>')
    answers = []
    package = _package(tmp_path)
    for name in ("exists", "missing"):
        path = package / f"{name}.sdf"
        path.write_text('<sdf version="1.7"><model name="m"><link name="a"/><include>'
                        f"<uri>model://../../{name}</uri></include></model></sdf>")
        answers.append([m.replace(name, "X") for m in _messages(path, "sdf")])
    assert answers[0] == answers[1] and answers[0], answers


@pytest.mark.parametrize("entry", sorted(ROBOTS.glob("*/corrected/*.xacro")),
                         ids=lambda p: p.parent.parent.name)
def test_untrusted_expand_prints_what_trusted_prints(entry, monkeypatch):
    # the sandboxed reader's document comes back whole: the comments beside the root too
    monkeypatch.chdir(entry.parent)
    trusted = run_urdftool("expand", "--trusted", entry.name)
    assert trusted.code == 0, trusted.err
    assert run_urdftool("expand", "--untrusted", entry.name).out == trusted.out


def test_reader_reused_across_working_directories(tmp_path, monkeypatch):
    # a library caller (or a test run) that changes directory between runs: a relative path
    # is the caller's, never the directory an earlier reader was started in
    for name in ("first", "second"):
        (tmp_path / name).mkdir()
        (tmp_path / name / "robot.urdf.xacro").write_text(
            f'<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="{name}">'
            '<xacro:property name="s" value="0.1"/><link name="a${s}"/></robot>')
    monkeypatch.chdir(tmp_path)  # one reader for both packages, started here
    assert run_urdftool("check", "--untrusted", "first", "second").code == 0
    for name in ("first", "second"):
        monkeypatch.chdir(tmp_path / name)
        result = run_urdftool("expand", "--untrusted", "robot.urdf.xacro")
        assert result.code == 0 and f'name="{name}"' in result.out, result.err
