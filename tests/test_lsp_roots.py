"""Issue 28.2 through the editor: the root of an editor workspace is the workspace folder, not
the work tree around it. A checkout without its own metadata unpacked in a home directory under
git, and a folder of a monorepo opened alone, each include a file of the enclosing work tree;
the untrusted server reads none of it (it did: the enclosing work tree was the repository)."""

from __future__ import annotations

import json
import shutil
import subprocess
import tempfile
from pathlib import Path

import pytest
import pytest_lsp
from lsprotocol import types as lsp
from pytest_lsp import LanguageClient, client_capabilities

from tests.lsp_client import SERVER, open_file

pytestmark = [pytest.mark.asyncio(loop_scope="module"),
              pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")]
MARKER = "SECRET_28_2"
ENTRY = """<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="{include}"/>
  <link name="base"/>
</robot>
"""
# one home directory under git for the module: what the enclosing work tree holds (tracked)
HOME = Path(tempfile.mkdtemp(prefix="urdftool-lsp-roots-")).resolve() / "home"
(HOME / "secret_pkg").mkdir(parents=True)
(HOME / "secret_pkg" / "secret.xacro").write_text(
    f'<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="{MARKER}">'
    '<inertial><mass value="-1"/></inertial></link></robot>\n')
# a folder of the work tree, tracked: opened alone as a workspace (a monorepo's package)
(HOME / "pkg_a").mkdir()
(HOME / "pkg_a" / "package.xml").write_text("<package><name>pkg_a</name></package>\n")
(HOME / "pkg_a" / "robot.urdf.xacro").write_text(
    ENTRY.format(include="../secret_pkg/secret.xacro"))
subprocess.run(["git", "init", "-q", str(HOME)], check=True)
subprocess.run(["git", "add", "-A"], cwd=HOME, check=True)
# a tarball's checkout, untracked, without metadata of its own
TARBALL = HOME / "Downloads" / "robot"
TARBALL.mkdir(parents=True)
(TARBALL / "robot.urdf.xacro").write_text(
    ENTRY.format(include="../../secret_pkg/secret.xacro"))


def _everything(client) -> str:
    parts = [m.message for m in client.log_messages + client.messages]
    for found in client.diagnostics.values():
        parts.extend(json.dumps([d.message, d.code]) for d in found)
    return "\n".join(parts)


@pytest_lsp.fixture(config=SERVER, scope="module", loop_scope="module")
async def editor(lsp_client: LanguageClient):
    folders = [lsp.WorkspaceFolder(TARBALL.as_uri(), "robot"),
               lsp.WorkspaceFolder((HOME / "pkg_a").as_uri(), "pkg_a")]
    await lsp_client.initialize_session(lsp.InitializeParams(
        capabilities=client_capabilities("visual-studio-code"), workspace_folders=folders,
        initialization_options={}))
    yield
    await lsp_client.shutdown_session()


@pytest.mark.parametrize("robot", [TARBALL / "robot.urdf.xacro",
                                   HOME / "pkg_a" / "robot.urdf.xacro"],
                         ids=["tarball-in-home", "monorepo-folder"])
async def test_the_workspace_folder_is_the_root(editor, robot):
    found = await open_file(editor, robot)
    assert MARKER not in _everything(editor)
    diagnostics = editor.diagnostics[found]
    assert any(d.code == "xacro.error" and d.range.start.line == 1 for d in diagnostics), \
        diagnostics  # the include, refused
