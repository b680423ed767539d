"""Issue 28.5 and the language-server part of 28.8, and issue 29's editor rough edges,
through the editor's own entry point (``urdftool lsp`` over stdio):

- an untrusted workspace's settings (``.vscode/settings.json`` arrives as
  ``workspace/didChangeConfiguration``) may only lower the operator's limits: a ``timeout``
  of a day does not let a spinning expansion run, ``ruleDocsUrl`` does not point the
  diagnostics' links at a ``command:`` URI;
- every request is answered, whatever its position (a negative line or character was
  dropped, the client waiting for ever);
- a quick fix whose edit goes through a committed symbolic link is not offered
  (``check --fix``'s one writer refuses it);
- hovers show numbers as the CLI does (``display.number``), references span the name, a
  ``package.xml`` added while the server runs is found by the next check.
"""

from __future__ import annotations

import asyncio
import json
import os
import select
import subprocess
import sys
import time

import pytest
import pytest_lsp
from lsprotocol import types as lsp
from pytest_lsp import LanguageClient

from tests.conftest import ROOT
from tests.lsp_client import SERVER, checked, open_file, start, uri

pytestmark = pytest.mark.asyncio(loop_scope="module")

SPIN = """<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <link name="base"/>
  <link name="l${len([a for a in range(999999) for b in range(999999) if a == -1])}"/>
</robot>
"""
ROBOT = """<robot name="r">
  <link name="base"/>
  <link name="tip"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="tip"/>
    <axis xyz="0 0 1"/><limit lower="-0.1" upper="0.30000000000000004" effort="1" velocity="1"/>
  </joint>
  <gazebo reference="tip"><mu1>1</mu1></gazebo>
</robot>
"""


@pytest_lsp.fixture(config=SERVER, scope="module", loop_scope="module")
async def client(lsp_client: LanguageClient):
    await start(lsp_client, trusted=None)  # untrusted: the workspace's settings are its own
    yield
    await lsp_client.shutdown_session()


def _package(tmp_path, name="pkg"):
    package = tmp_path / name
    package.mkdir()
    (package / "package.xml").write_text(f"<package><name>{name}</name></package>",
                                         encoding="utf-8")
    return package


async def test_an_untrusted_workspace_may_only_lower_its_limits(client, tmp_path):
    package = _package(tmp_path)
    robot = package / "spin.urdf.xacro"
    robot.write_text(SPIN, encoding="utf-8")
    client.workspace_did_change_configuration(lsp.DidChangeConfigurationParams(settings={
        "urdftool": {"timeout": 86400, "memoryLimit": 1 << 20,
                     "ruleDocsUrl": "command:workbench.action.terminal.new?{rule}"}}))
    started = time.monotonic()
    # the operator's limit (3 s) stops the expansion; a day's would never answer here
    await asyncio.wait_for(open_file(client, robot), 90)
    assert time.monotonic() - started < 60
    found = client.diagnostics[uri(robot)]
    assert any(d.code == "xacro.limit-exceeded" for d in found), [d.message for d in found]
    links = [d.code_description.href for d in found if d.code_description is not None]
    assert links and not any(link.startswith("command:") for link in links), links
    said = " ".join(m.message for m in client.log_messages)
    assert "ruleDocsUrl" in said and "may only lower" in said


def _raw_session(requests: list[dict], document, text: str, wait: float = 60) -> dict:
    """The server's answers (id -> message) to ``requests``, sent as raw JSON-RPC after
    opening ``document`` (the client library refuses to send a negative position)."""
    env = {**SERVER.server_env, "PYTHONPATH": str(ROOT)}
    server = subprocess.Popen([sys.executable, "-m", "urdftool", "lsp"], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, env=env)

    def send(message):
        body = json.dumps({"jsonrpc": "2.0", **message}).encode()
        server.stdin.write(b"Content-Length: %d\r\n\r\n" % len(body) + body)
        server.stdin.flush()

    send({"id": 0, "method": "initialize", "params": {
        "capabilities": {}, "rootUri": document.parent.as_uri()}})
    send({"method": "initialized", "params": {}})
    send({"method": "textDocument/didOpen", "params": {"textDocument": {
        "uri": uri(document), "languageId": "xml", "version": 1, "text": text}}})
    for request in requests:
        send(request)
    answers, buffer, end = {}, b"", time.monotonic() + wait
    wanted = {r["id"] for r in requests}
    try:
        while not wanted <= set(answers) and time.monotonic() < end:
            if select.select([server.stdout], [], [], 0.2)[0]:
                buffer += os.read(server.stdout.fileno(), 1 << 16)
            while b"\r\n\r\n" in buffer:
                head, rest = buffer.split(b"\r\n\r\n", 1)
                length = int(head.split(b"\r\n")[0].split(b":")[1])
                if len(rest) < length:
                    break
                message = json.loads(rest[:length])
                buffer = rest[length:]
                if "id" in message and "method" not in message:
                    answers[message["id"]] = message
    finally:
        server.kill()
        server.wait()
    return answers


@pytest.mark.asyncio(loop_scope="module")
async def test_every_request_is_answered_whatever_its_position(tmp_path):
    document = _package(tmp_path) / "robot.urdf"
    document.write_text(ROBOT, encoding="utf-8")
    doc = {"uri": uri(document)}
    positions = [(-1, 0), (0, -5), (100000, 3), (1, 10 ** 9)]
    requests = []
    for index, (line, character) in enumerate(positions):
        at = {"line": line, "character": character}
        base = 10 * (index + 1)
        requests += [
            {"id": base, "method": "textDocument/hover",
             "params": {"textDocument": doc, "position": at}},
            {"id": base + 1, "method": "textDocument/definition",
             "params": {"textDocument": doc, "position": at}},
            {"id": base + 2, "method": "textDocument/references",
             "params": {"textDocument": doc, "position": at,
                        "context": {"includeDeclaration": True}}},
            {"id": base + 3, "method": "textDocument/completion",
             "params": {"textDocument": doc, "position": at}},
            {"id": base + 4, "method": "textDocument/codeAction",
             "params": {"textDocument": doc, "range": {"start": at, "end": at},
                        "context": {"diagnostics": []}}}]
    answers = await asyncio.to_thread(_raw_session, requests, document, ROBOT)
    missing = [r["method"] + json.dumps(r["params"].get("position") or r["params"]["range"])
               for r in requests if r["id"] not in answers]
    assert not missing, missing
    for request in requests:  # an empty answer or a proper error, never a crash
        answer = answers[request["id"]]
        assert "result" in answer or answer["error"]["code"] == -32602, answer


async def test_no_quick_fix_writes_through_a_committed_link(client, tmp_path):
    package = _package(tmp_path)
    (package / "shared").mkdir()
    (package / "shared" / "part.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <gazebo reference="whel"><mu1>1</mu1></gazebo>\n</robot>\n', encoding="utf-8")
    (package / "parts").symlink_to(package / "shared", target_is_directory=True)
    robot = package / "robot.urdf.xacro"
    robot.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                     '  <link name="base"/><link name="wheel"/>\n'
                     '  <joint name="w" type="fixed"><parent link="base"/>'
                     '<child link="wheel"/></joint>\n'
                     '  <xacro:include filename="parts/part.xacro"/>\n'
                     '  <gazebo reference="whel"><mu1>1</mu1></gazebo>\n</robot>\n',
                     encoding="utf-8")
    await open_file(client, robot)
    typos = {key: [d for d in found if d.code == "gazebo.unknown-reference"]
             for key, found in client.diagnostics.items()}
    offered = {}
    for key, found in typos.items():
        for diagnostic in found:
            actions = await client.text_document_code_action_async(lsp.CodeActionParams(
                lsp.TextDocumentIdentifier(key), diagnostic.range,
                lsp.CodeActionContext([diagnostic], only=[lsp.CodeActionKind.QuickFix])))
            for action in actions or ():
                for target in (action.edit.changes or {}) if action.edit else {}:
                    if action.title.startswith("Fix "):
                        offered.setdefault(target, []).append(action.title)
    # the entry's own typo is fixed; the one behind the committed link is not offered
    assert uri(robot) in offered, (offered, list(typos))
    assert not any("/parts/" in target or "/shared/" in target for target in offered), offered


async def test_hover_numbers_and_reference_ranges_are_the_clis(client, tmp_path):
    document = _package(tmp_path) / "robot.urdf"
    document.write_text(ROBOT, encoding="utf-8")
    await open_file(client, document)
    lines = ROBOT.split("\n")
    joint_line = next(i for i, line in enumerate(lines) if "<joint" in line)
    hover = await client.text_document_hover_async(lsp.HoverParams(
        lsp.TextDocumentIdentifier(uri(document)),
        lsp.Position(joint_line, lines[joint_line].index('"j"') + 1)))
    text = hover.contents.value if hover is not None else ""
    assert "upper 0.3," in text and "0.30000000000000004" not in text, text
    # references of link 'tip': each range covers the name where it is written
    tip_line = next(i for i, line in enumerate(lines) if '<link name="tip"' in line)
    found = await client.text_document_references_async(lsp.ReferenceParams(
        text_document=lsp.TextDocumentIdentifier(uri(document)),
        position=lsp.Position(tip_line, lines[tip_line].index("tip") + 1),
        context=lsp.ReferenceContext(include_declaration=True)))
    assert found and len(found) >= 3
    for location in found:
        r = location.range
        assert r.start.line == r.end.line
        assert lines[r.start.line][r.start.character:r.end.character] == "tip", r


async def test_a_package_added_while_the_server_runs_is_found(client, tmp_path):
    await asyncio.to_thread(subprocess.run, ["git", "init", "-q", str(tmp_path)], check=True)
    package = _package(tmp_path, "arm")
    robot = package / "robot.urdf.xacro"
    robot.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                     '  <xacro:include filename="$(find late_parts)/part.xacro"/>\n'
                     '  <link name="base"/>\n</robot>\n', encoding="utf-8")
    await open_file(client, robot)
    assert any("late_parts" in d.message for d in client.diagnostics[uri(robot)])
    late = tmp_path / "late_parts"
    late.mkdir()
    (late / "part.xacro").write_text('<robot xmlns:xacro="http://www.ros.org/wiki/xacro">'
                                     '<link name="part"/></robot>\n', encoding="utf-8")
    (late / "package.xml").write_text("<package><name>late_parts</name></package>",
                                      encoding="utf-8")
    client.workspace_did_change_watched_files(lsp.DidChangeWatchedFilesParams([lsp.FileEvent(
        uri(late / "package.xml"), lsp.FileChangeType.Created)]))
    await checked(client)
    assert not any("late_parts" in d.message for d in client.diagnostics[uri(robot)]), \
        [d.message for d in client.diagnostics[uri(robot)]]
