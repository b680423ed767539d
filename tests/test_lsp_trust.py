"""Trust and configuration of ``urdftool lsp``: a workspace is untrusted unless the client's
initializationOptions say ``{"trusted": true}``; untrusted, the server reads as
``check --untrusted`` (its findings are that command's). What may be read is the loader's
decision in both modes (the repository and the operator's directories): nothing the server
sends carries content of a file outside them, and only the operator's options (launch
arguments, initializationOptions) widen them, never settings that arrive later from the
workspace when it is untrusted."""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

import pytest
import pytest_lsp
from lsprotocol import types as lsp
from pytest_lsp import LanguageClient

from tests.conftest import ROBOTS
from tests.lsp_client import SERVER, check_json, checked, open_file, published, start, uri

MARKER = "SECRET_7f3a"
ENTRY = """<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="{include}"/>
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="j" type="fixed"><parent link="base"/><child link="base_2"/></joint>
</robot>
"""
OUTSIDE = f"""<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <link name="{MARKER}"><inertial><mass value="-1"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
</robot>
"""
# a directory outside every test package, holding the marker (one per test run)
SECRET = Path(tempfile.mkdtemp(prefix="urdftool-lsp-secret-")) / "secret_pkg"
SECRET.mkdir()
(SECRET / "package.xml").write_text("<package><name>secret_pkg</name></package>",
                                    encoding="utf-8")
(SECRET / "secret.xacro").write_text(OUTSIDE, encoding="utf-8")


def _layout(tmp_path, include: str):
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "package.xml").write_text("<package><name>pkg</name></package>",
                                         encoding="utf-8")
    robot = package / "robot.urdf.xacro"
    robot.write_text(ENTRY.format(include=include), encoding="utf-8")
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
    await start(lsp_client, trusted=True, select=["xacro", "inertia", "structure"],
                packages={"secret_pkg": str(SECRET)})
    yield
    await lsp_client.shutdown_session()


async def test_a_workspace_is_untrusted_unless_the_client_says_so(untrusted, tmp_path):
    package, robot = _layout(tmp_path, str(SECRET / "secret.xacro"))
    await open_file(untrusted, robot)
    assert published(untrusted, tmp_path) == check_json("--untrusted", str(package))
    assert any(d.code == "xacro.error" and d.range.start.line == 1
               for d in untrusted.diagnostics[uri(robot)])  # the include, refused
    assert MARKER not in _everything(untrusted)
    # a request on the include names nothing outside the roots either
    where = lsp.Position(1, 30)
    hover = await untrusted.text_document_hover_async(lsp.HoverParams(
        lsp.TextDocumentIdentifier(uri(robot)), where))
    found = await untrusted.text_document_definition_async(lsp.DefinitionParams(
        lsp.TextDocumentIdentifier(uri(robot)), where))
    assert MARKER not in json.dumps([str(hover), str(found)])
    assert found is None


async def test_workspace_settings_of_an_untrusted_workspace_do_not_widen_reading(
        untrusted, tmp_path):
    """A repository's own settings (``.vscode/settings.json``...) arrive as workspace
    settings: naming a package directory there is refused while the workspace is untrusted;
    the include stays outside."""
    package, robot = _layout(tmp_path, "$(find secret_pkg)/secret.xacro")
    await open_file(untrusted, robot)
    untrusted.workspace_did_change_configuration(lsp.DidChangeConfigurationParams(
        settings={"urdftool": {"packages": {"secret_pkg": str(SECRET)}}}))
    await checked(untrusted)
    assert MARKER not in _everything(untrusted)
    assert any("untrusted" in m.message and "packages" in m.message
               for m in untrusted.log_messages)
    assert published(untrusted, tmp_path) == check_json("--untrusted", str(package))


async def test_trusted_with_the_operators_options_reads_as_check(trusted, tmp_path):
    """Trusted, with a package given in the initialization options (the operator's -P): the
    findings are `check --trusted -P ... --select ...`'s, the package's file among them (so
    the marker does reach the client when the operator allows it: the other tests could see
    it)."""
    package, robot = _layout(tmp_path, "$(find secret_pkg)/secret.xacro")
    await open_file(trusted, robot)
    expected = check_json("--trusted", "--select", "xacro,inertia,structure",
                          "-P", f"secret_pkg={SECRET}", str(package))
    assert published(trusted, tmp_path) | published(trusted, SECRET) == expected
    assert any(MARKER in d.message for found in trusted.diagnostics.values() for d in found)
    assert {d.code.split(".")[0] for found in trusted.diagnostics.values()
            for d in found} <= {"xacro", "inertia", "structure"}


async def test_untrusted_seed_is_check_untrusted(untrusted):
    directory = ROBOTS / "dual_arm" / "published"
    await open_file(untrusted, next(directory.glob("*.xacro")))
    assert published(untrusted, directory) == check_json("--untrusted", str(directory))


async def test_workspace_settings_change_the_rules(trusted, tmp_path):
    """The ``urdftool`` section of the workspace settings (here pulled with
    workspace/configuration after a didChangeConfiguration) applies to the next checks."""
    package, robot = _layout(tmp_path, "$(find secret_pkg)/secret.xacro")
    await open_file(trusted, robot)
    assert any(d.code.startswith("inertia.") for found in trusted.diagnostics.values()
               for d in found)
    trusted.set_configuration({"select": ["structure"]}, section="urdftool")
    trusted.workspace_did_change_configuration(lsp.DidChangeConfigurationParams(settings=None))
    await checked(trusted)
    expected = check_json("--trusted", "--select", "structure", "-P", f"secret_pkg={SECRET}",
                          str(package))
    assert published(trusted, tmp_path) | published(trusted, SECRET) == expected
