"""Helpers of the language-server tests: a pytest-lsp client driving ``urdftool lsp`` over
stdio, and the findings of ``urdftool check --format json`` to compare with."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from lsprotocol import types as lsp
from pytest_lsp import ClientServerConfig, client_capabilities

from tests.conftest import ROOT

# the servers' own mesh cache (they outlive one test's), never the user's
SERVER = ClientServerConfig([sys.executable, "-m", "urdftool", "lsp"], server_env={
    "PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin",
    "URDFTOOL_CACHE_DIR": tempfile.mkdtemp(prefix="urdftool-lsp-cache-")})


def _env() -> dict[str, str]:
    """The environment of a CLI run from a test: the test's own cache (conftest)."""
    env = {"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"}
    if os.environ.get("URDFTOOL_CACHE_DIR"):
        env["URDFTOOL_CACHE_DIR"] = os.environ["URDFTOOL_CACHE_DIR"]
    return env
SEVERITY = {lsp.DiagnosticSeverity.Error: "error", lsp.DiagnosticSeverity.Warning: "warning",
            lsp.DiagnosticSeverity.Information: "info"}


async def start(client, trusted: bool | None = True, **options) -> None:
    init = dict(options)
    if trusted is not None:
        init["trusted"] = trusted
    await client.initialize_session(lsp.InitializeParams(
        capabilities=client_capabilities("visual-studio-code"), initialization_options=init))


def uri(path) -> str:
    return Path(path).resolve().as_uri()


async def open_file(client, path, text: str | None = None) -> str:
    text = Path(path).read_text(encoding="utf-8") if text is None else text
    client.text_document_did_open(lsp.DidOpenTextDocumentParams(
        lsp.TextDocumentItem(uri(path), "xml", 1, text)))
    await checked(client)
    return uri(path)


async def checked(client, *uris: str) -> None:
    """Wait until every check the server has waiting is done (and published)."""
    await client.workspace_execute_command_async(lsp.ExecuteCommandParams(
        "urdftool.check", list(uris)))


async def change(client, path, text: str, version: int = 2) -> None:
    client.text_document_did_change(lsp.DidChangeTextDocumentParams(
        lsp.VersionedTextDocumentIdentifier(version=version, uri=uri(path)),
        [lsp.TextDocumentContentChangeWholeDocument(text=text)]))
    await checked(client)


def published(client, under) -> set[tuple]:
    """(rule, resolved path, line, column) of every diagnostic published for files under
    ``under`` (columns back from UTF-16: the files here are ASCII where findings are)."""
    base = str(Path(under).resolve())
    found = set()
    for key, diagnostics in client.diagnostics.items():
        path = str(Path(key.removeprefix("file://")).resolve())
        if not (path == base or path.startswith(base + "/")):
            continue
        for d in diagnostics:
            found.add((d.code, path, d.range.start.line + 1, d.range.start.character + 1,
                       SEVERITY[d.severity]))
    return found


def check_report(*args: str, cwd=None, parse: bool = True) -> dict | None:
    """``urdftool check --format json``'s report (a separate process: the CLI as a user runs
    it)."""
    done = subprocess.run([sys.executable, "-m", "urdftool", "check", "--format", "json", *args],
                          capture_output=True, text=True, cwd=cwd or ROOT,
                          env=_env(), check=False)
    assert done.returncode in (0, 1), done.stderr
    return json.loads(done.stdout) if parse else None


def check_json(*args: str, cwd=None) -> set[tuple]:
    """The tuples of ``published`` from ``urdftool check --format json``. A diagnostic without
    a column is at the first non-blank of its line in the editor; without a line, at the first
    line."""
    found = set()
    for file in check_report(*args, cwd=cwd)["files"]:
        for d in file["diagnostics"]:
            path = Path(cwd or ROOT, d["path"]).resolve()
            line = d["line"] or 1
            column = d["column"]
            if column is None:
                text = path.read_text(encoding="utf-8").split("\n")[line - 1]
                column = len(text) - len(text.lstrip()) + 1
            found.add((d["rule"], str(path), line, column, d["severity"]))
    return found


def check_fix(path, out) -> str:
    """What ``urdftool check --fix -o OUT PATH`` writes."""
    subprocess.run([sys.executable, "-m", "urdftool", "check", "--trusted", "--fix", "-o",
                    str(out), str(path)], cwd=ROOT, capture_output=True, check=False,
                   env=_env())
    return Path(out).read_text(encoding="utf-8")


def apply_edits(text: str, edits: list[lsp.TextEdit]) -> str:
    """``text`` with LSP text edits made (from the last, so earlier offsets hold)."""
    lines = text.split("\n")
    starts = [0]
    for line in lines:
        starts.append(starts[-1] + len(line) + 1)

    def offset(position: lsp.Position) -> int:
        return starts[position.line] + position.character

    for e in sorted(edits, key=lambda e: offset(e.range.start), reverse=True):
        text = text[:offset(e.range.start)] + e.new_text + text[offset(e.range.end):]
    return text
