"""Trust and configuration of ``urdftool lsp``: a workspace is untrusted unless the client's
initializationOptions say ``{"trusted": true}``; untrusted, the server reads as
``check --untrusted`` (its findings are that command's) and nothing it sends carries content of a
file outside the run's roots (in either mode: one trust model, issue 20). Options given as
initializationOptions are honoured."""

from __future__ import annotations

import json

import pytest
import pytest_lsp
from lsprotocol import types as lsp
from pytest_lsp import LanguageClient

from tests.conftest import ROBOTS
from tests.lsp_client import SERVER, check_json, checked, open_file, published, start, uri

MARKER = "SECRET_7f3a"
ENTRY = """<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="{outside}"/>
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="j" type="fixed"><parent link="base"/><child link="{marker}"/></joint>
</robot>
"""
OUTSIDE = f"""<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <link name="{MARKER}"><inertial><mass value="-1"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
</robot>
"""


def _layout(tmp_path):
    outside = tmp_path / "outside" / "secret.xacro"
    outside.parent.mkdir()
    outside.write_text(OUTSIDE, encoding="utf-8")
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "package.xml").write_text("<package><name>pkg</name></package>",
                                         encoding="utf-8")
    robot = package / "robot.urdf.xacro"
    robot.write_text(ENTRY.format(outside=outside, marker="base_2"), encoding="utf-8")
    return package, robot


def _everything(client) -> str:
    """Every diagnostic and log message the client got, as text."""
    parts = [m.message for m in client.log_messages + client.messages]
    for found in client.diagnostics.values():
        for d in found:
            parts.append(json.dumps([d.message, d.code, str(d.related_information)]))
    return "\n".join(parts)


pytestmark = pytest.mark.asyncio(loop_scope="module")


@pytest_lsp.fixture(config=SERVER, scope="module", loop_scope="module")
async def untrusted(lsp_client: LanguageClient):
    await start(lsp_client, trusted=None)
    yield
    await lsp_client.shutdown_session()


@pytest_lsp.fixture(config=SERVER, scope="module", loop_scope="module")
async def trusted(lsp_client: LanguageClient):
    await start(lsp_client, trusted=True, select=["xacro", "inertia", "structure"])
    yield
    await lsp_client.shutdown_session()


async def test_a_workspace_is_untrusted_unless_the_client_says_so(untrusted, tmp_path):
    package, robot = _layout(tmp_path)
    await open_file(untrusted, robot)
    assert published(untrusted, package) == check_json("--untrusted", str(package))
    text = _everything(untrusted)
    assert "outside the repository" in text
    assert MARKER not in text
    # a request on the include names nothing outside the roots either
    line = robot.read_text(encoding="utf-8").split("\n").index(
        next(x for x in robot.read_text(encoding="utf-8").split("\n") if "include" in x))
    where = lsp.Position(line, 30)
    hover = await untrusted.text_document_hover_async(lsp.HoverParams(
        lsp.TextDocumentIdentifier(uri(robot)), where))
    found = await untrusted.text_document_definition_async(lsp.DefinitionParams(
        lsp.TextDocumentIdentifier(uri(robot)), where))
    assert MARKER not in json.dumps([str(hover), str(found)])
    assert found is None


async def test_trusted_reads_as_check_trusted_with_the_options_given(trusted, tmp_path):
    package, robot = _layout(tmp_path)
    await open_file(trusted, robot)
    expected = check_json("--trusted", "--select", "xacro,inertia,structure", str(package))
    assert published(trusted, tmp_path) == expected
    # trusted reads in this process, inside the same roots: the file outside is not read
    text = _everything(trusted)
    assert "outside the repository" in text and MARKER not in text
    assert {d.code.split(".")[0] for found in trusted.diagnostics.values()
            for d in found} <= {"xacro", "inertia", "structure"}


async def test_untrusted_seed_is_check_untrusted(untrusted):
    directory = ROBOTS / "dual_arm" / "published"
    await open_file(untrusted, next(directory.glob("*.xacro")))
    assert published(untrusted, directory) == check_json("--untrusted", str(directory))


async def test_workspace_settings_change_the_rules(trusted, tmp_path):
    """The ``urdftool`` section of the workspace settings (here pulled with
    workspace/configuration after a didChangeConfiguration) applies to the next checks."""
    package, robot = _layout(tmp_path)
    await open_file(trusted, robot)
    assert any(d.code.startswith("xacro.") for found in trusted.diagnostics.values()
               for d in found)  # the refused include: not a structure finding
    trusted.set_configuration({"select": ["structure"]}, section="urdftool")
    trusted.workspace_did_change_configuration(lsp.DidChangeConfigurationParams(settings=None))
    await checked(trusted)
    expected = check_json("--trusted", "--select", "structure", str(package))
    assert published(trusted, tmp_path) == expected
    trusted.set_configuration({"select": ["xacro", "inertia", "structure"]}, section="urdftool")
    trusted.workspace_did_change_configuration(lsp.DidChangeConfigurationParams(settings=None))
    await checked(trusted)
