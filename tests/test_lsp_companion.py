"""The language server on companion files (issue 31): an SRDF's and a controllers YAML's
findings published at their own lines, as ``check --format json`` gives them; an edit of the
URDF buffer re-checks the SRDF that describes it; the SRDF's quick fix renames."""

from __future__ import annotations

import subprocess

import pytest
import pytest_lsp
from lsprotocol import types as lsp
from pytest_lsp import LanguageClient

from tests.lsp_client import SERVER, change, check_json, checked, open_file, published, start, uri
from tests.test_ros2_control import CONTROLLERS
from tests.test_ros2_control import ROBOT as CONTROLLED
from tests.test_srdf import NEVER
from urdftool.rules.srdf import EXAMPLE_ROBOT

pytestmark = pytest.mark.asyncio(loop_scope="module")


@pytest_lsp.fixture(config=SERVER, scope="module", loop_scope="module")
async def client(lsp_client: LanguageClient):
    await start(lsp_client)
    yield
    await lsp_client.shutdown_session()


def _moveit(tmp_path):
    repo = tmp_path / "repo"
    (repo / "arm_description" / "urdf").mkdir(parents=True)
    (repo / "arm_description" / "package.xml").write_text(
        "<package><name>arm_description</name></package>")
    narrow = EXAMPLE_ROBOT.replace('lower="-2.8" upper="2.8"', 'lower="-2.2" upper="2.2"')
    (repo / "arm_description" / "urdf" / "arm.urdf").write_text(narrow, encoding="utf-8")
    config = repo / "arm_moveit_config"
    (config / "config").mkdir(parents=True)
    (config / "package.xml").write_text("<package><name>arm_moveit_config</name></package>")
    (config / ".setup_assistant").write_text(
        "moveit_setup_assistant_config:\n  URDF:\n    package: arm_description\n"
        "    relative_path: urdf/arm.urdf\n")
    srdf = config / "config" / "arm.srdf"
    srdf.write_text(NEVER.replace('tip_link="tool0"', 'tip_link="tol0"'), encoding="utf-8")
    subprocess.run(["git", "init", "-q", str(repo)], check=True)
    return repo, srdf, repo / "arm_description" / "urdf" / "arm.urdf"


def _ros(tmp_path, controllers: str):
    repo = tmp_path / "ros"
    for name, sub in (("arm_description", "urdf"), ("arm_bringup", "config")):
        (repo / name / sub).mkdir(parents=True)
        (repo / name / "package.xml").write_text(f"<package><name>{name}</name></package>")
    robot = repo / "arm_description" / "urdf" / "arm.urdf.xacro"
    robot.write_text(CONTROLLED, encoding="utf-8")
    yaml = repo / "arm_bringup" / "config" / "controllers.yaml"
    yaml.write_text(controllers, encoding="utf-8")
    subprocess.run(["git", "init", "-q", str(repo)], check=True)
    return repo, robot, yaml


async def test_srdf_diagnostics_follow_check_and_its_robots_edits(client, tmp_path):
    repo, srdf, urdf = _moveit(tmp_path)
    await open_file(client, srdf)
    got = {d for d in published(client, repo) if d[0].startswith("srdf.")}
    assert got == {d for d in check_json("--trusted", str(repo)) if d[0].startswith("srdf.")}
    assert {(d[0], d[2]) for d in got} == {("srdf.unknown-link", 2)}
    # the robot's limits widened in its unsaved buffer: the SRDF's Never pair now collides
    await open_file(client, urdf)
    await change(client, urdf, EXAMPLE_ROBOT)
    await checked(client, uri(srdf))
    got = {(d[0], d[2]) for d in published(client, repo) if d[0].startswith("srdf.")}
    assert got == {("srdf.unknown-link", 2), ("srdf.never-pair-collides", 3)}
    # the quick fix of the unknown link renames it as check --fix would
    actions = await client.text_document_code_action_async(lsp.CodeActionParams(
        lsp.TextDocumentIdentifier(uri(srdf)), lsp.Range(lsp.Position(1, 0), lsp.Position(1, 80)),
        lsp.CodeActionContext(diagnostics=client.diagnostics[uri(srdf)])))
    edits = [e for a in actions or () if isinstance(a, lsp.CodeAction) and a.edit
             for e in (a.edit.changes or {}).get(uri(srdf), ())]
    assert any(e.new_text == "tool0" for e in edits), actions


async def test_controllers_yaml_diagnostics_at_its_lines(client, tmp_path):
    repo, robot, _ = _ros(tmp_path, CONTROLLERS.replace("      - joint2\n", "      - jiont2\n"))
    await open_file(client, robot)
    got = {d for d in published(client, repo) if d[0].startswith("ros2_control.")}
    assert got == {d for d in check_json("--trusted", str(repo))
                   if d[0].startswith("ros2_control.")}
    assert [(d[1].rsplit("/", 1)[-1], d[2]) for d in got] == [("controllers.yaml", 13)]


async def _definition(client, path, line: int, column: int):
    return await client.text_document_definition_async(lsp.DefinitionParams(
        lsp.TextDocumentIdentifier(uri(path)), lsp.Position(line - 1, column - 1)))


async def test_go_to_definition_from_srdf_and_yaml_names(client, tmp_path):
    _, srdf, urdf = _moveit(tmp_path)
    await open_file(client, srdf)
    text = srdf.read_text(encoding="utf-8").split("\n")
    column = text[2].index('"forearm"') + 2  # inside link2="forearm" (line 3)
    found = await _definition(client, srdf, 3, column)
    lines = urdf.read_text(encoding="utf-8").split("\n")
    expected = next(i for i, line in enumerate(lines) if '<link name="forearm"' in line)
    assert [(f.uri, f.range.start.line) for f in found or ()] == [(uri(urdf), expected)]
    # a joint name in a controllers YAML -> the robot's joint
    _, robot, yaml = _ros(tmp_path, CONTROLLERS)
    await open_file(client, robot)
    await open_file(client, yaml)
    yaml_lines = CONTROLLERS.split("\n")
    row = next(i for i, line in enumerate(yaml_lines) if line.strip() == "- joint2") + 1
    found = await _definition(client, yaml, row, yaml_lines[row - 1].index("joint2") + 2)
    robot_lines = CONTROLLED.split("\n")
    expected = next(i for i, line in enumerate(robot_lines) if '<joint name="joint2"' in line)
    assert [(f.uri, f.range.start.line) for f in found or ()] == [(uri(robot), expected)]
