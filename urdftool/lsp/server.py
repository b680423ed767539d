"""``urdftool lsp``: the Language Server Protocol over stdio (pygls), a thin front end on
``urdftool.lsp.engine`` (the checks) and ``urdftool.lsp.navigation`` (hover, definitions...).

Changes are checked in one worker thread, coalesced: a change waits ``Settings.debounce`` for
the next keystroke, and changes made while a check runs are checked together after it. The
checks put off (fragments an entry reads) run after ``PENDING_DELAY`` without a change; a
change ends that wait at once and stops them between two targets, so it never waits for more
than the one target being checked. The
requests (hover, code actions...) are answered from the last check's reports and robots.
Every handler survives its own exceptions: logged to the client, answered with null.
"""

from __future__ import annotations

import asyncio
import functools
import gc
import os
import re
import tempfile
import traceback
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from lsprotocol import types as lsp
from pygls.exceptions import JsonRpcException
from pygls.lsp.server import LanguageServer
from pygls.protocol import LanguageServerProtocol
from pygls.uris import from_fs_path, to_fs_path

from urdftool import __version__
from urdftool.lsp.engine import ERROR_RULE, Engine, Result, Settings, resolved
from urdftool.source import DEFAULT_TIMEOUT

SEVERITY = {"error": lsp.DiagnosticSeverity.Error, "warning": lsp.DiagnosticSeverity.Warning,
            "info": lsp.DiagnosticSeverity.Information}
# rules whose finding is something consumers ignore (faded), or an old way of writing
UNNECESSARY = frozenset({"joint.fixed-with-axis", "schema.duplicate-element"})
DEPRECATED = frozenset({"xacro.unprefixed-tag", "xacro.unprefixed-macro-call"})
CHECK_COMMAND = "urdftool.check"
# settings that widen what is read or seen, or where the server's links point: from the
# operator only (launch arguments, initializationOptions) in an untrusted workspace
WIDENING = frozenset({"packages", "allowEnv", "ruleDocsUrl"})
# limits an untrusted workspace may only lower (issue 28.5): setting -> the operator's value
# when none was given (``source.LoadOptions``' defaults)
LIMITS = {"timeout": ("timeout", DEFAULT_TIMEOUT), "memoryLimit": ("memory_mb", 1024)}
# seconds without a change before the checks put off (fragments an entry reads) are run
PENDING_DELAY = 0.5
# checks after which the garbage is collected even while changes keep coming
COLLECT_EVERY = 8
_SITE = re.compile(r"^(.*):(\d+)$")


class _Protocol(LanguageServerProtocol):
    """pygls' protocol, answering every request: one whose parameters do not fit the
    protocol's types (a negative line or character: ``uinteger``) was dropped unanswered, the
    client waiting for ever (issue 28.8); it now gets the JSON-RPC error (Invalid Params).
    The guard of every request before any handler (a position past the end is each
    handler's: an empty answer)."""

    def structure_message(self, data):
        try:
            return super().structure_message(data)
        except JsonRpcException as exc:
            if isinstance(data, dict) and "id" in data and "method" in data:
                self._send_response(data["id"], error=exc.to_response_error())
            raise


class UrdfLanguageServer(LanguageServer):
    def __init__(self, settings: Settings | None = None):
        super().__init__("urdftool", __version__, protocol_cls=_Protocol,
                         text_document_sync_kind=lsp.TextDocumentSyncKind.Incremental)
        self.launch_settings = settings or Settings()
        self.operator_settings = self.launch_settings  # + initializationOptions
        self.engine = Engine(self.launch_settings)
        self.worker = ThreadPoolExecutor(1, thread_name_prefix="urdftool-check")
        self.changed: set[str] = set()  # paths changed since their last check
        self.task: asyncio.Task | None = None
        self.running = False  # a check of changed files is under way
        self.now = False  # a change asks for its check without the debounce
        self.wake = asyncio.Event()  # set by every change
        self.checks = 0  # checks of changes run
        self.frozen = False  # the objects alive after the first check are out of the GC
        self.configuring = 0  # settings changes being applied
        self.published: dict[Path, set[str]] = {}  # unit root -> URIs given diagnostics
        self.uris: dict[str, str] = {}  # resolved path -> the URI the client opened it by
        self.shown: dict[str, list[tuple[lsp.Diagnostic, object]]] = {}  # uri -> last published
        self.versions: dict[str, int | None] = {}  # resolved path -> version the checks read
        self._docs: str | None = None  # directory of the rule pages (codeDescription)

    # -- logging ---------------------------------------------------------------------------

    def log(self, message: str, kind=lsp.MessageType.Log) -> None:
        try:
            self.window_log_message(lsp.LogMessageParams(kind, message))
        except Exception:  # noqa: BLE001, S110 - the connection is gone: nothing to tell
            pass

    def report_server_error(self, error, source):
        self.log(f"urdftool: {type(error).__name__}: {error}", lsp.MessageType.Error)

    # -- paths -----------------------------------------------------------------------------

    def path_of(self, uri: str) -> str | None:
        path = to_fs_path(uri)
        return os.path.abspath(path) if path and uri.startswith("file:") else None

    def uri_of(self, path: str) -> str:
        key = resolved(path)
        return self.uris.get(key) or from_fs_path(os.path.abspath(path)) or key

    def text_of(self, path: str) -> str | None:
        """The text the client has (an open buffer), else the text the last check read."""
        key = resolved(path)
        uri = self.uris.get(key)
        if uri is not None:
            document = self.workspace.text_documents.get(uri)
            if document is not None:
                return document.source
        read = False
        for result in self.engine.snapshot.values():
            for report, _ in result.checks:
                for name, text in report.texts.items():
                    if resolved(name) == key:
                        return text
                read = read or key in report.includes
        if read:  # a file the check read but keeps no text of (a controllers YAML: issue 31)
            from urdftool.files import read_regular

            try:
                return read_regular(key, 1 << 20).decode("utf-8", "replace")
            except OSError:
                return None
        return None

    def units(self, n: int, text: str) -> int:
        """The client's code units of ``text`` (UTF-16 unless negotiated otherwise)."""
        return self.workspace.position_codec.client_num_units(text) if n else 0

    def position(self, lines: list[str], line: int, column: int) -> lsp.Position:
        """(0-based line, 0-based character column) in the client's units."""
        if line >= len(lines):
            return lsp.Position(max(line, 0), 0)
        text = lines[line]
        column = max(0, min(column, len(text)))
        return lsp.Position(line, self.units(column, text[:column]))

    def char_column(self, lines: list[str], position: lsp.Position) -> int:
        """A client position's character column (0-based) in Python characters."""
        if position.line >= len(lines):
            return 0
        text = lines[position.line]
        units = 0
        for index, char in enumerate(text):
            if units >= position.character:
                return index
            units += self.units(1, char)
        return len(text)

    # -- diagnostics -----------------------------------------------------------------------

    def rule_href(self, rule: str) -> str | None:
        """The page of a rule: ``ruleDocsUrl`` with {rule} replaced, else a Markdown page
        made from the rule's registration (as ``urdftool rules RULE`` prints it) in a private
        temporary directory of this server, removed at exit."""
        if not rule:
            return None
        if self.engine.settings.rule_docs_url:
            return self.engine.settings.rule_docs_url.replace("{rule}", rule)
        from urdftool.rules import load_all

        found = load_all().get(rule)
        if found is None:
            return None
        if self._docs is None:
            import atexit
            import shutil

            self._docs = tempfile.mkdtemp(prefix="urdftool-rules-")
            atexit.register(shutil.rmtree, self._docs, True)
        page = Path(self._docs) / f"{rule}.md"
        if not page.exists():
            page.write_text(rule_page(found), encoding="utf-8")
        return page.as_uri()

    def to_lsp(self, d, lines: list[str]) -> lsp.Diagnostic:
        line = (d.line or 1) - 1
        text = lines[line] if line < len(lines) else ""
        if d.column:
            start = d.column - 1
            token = re.match(r"</?[\w:.-]*", text[start:])
            end = start + (token.end() if token and token.end() > 1 else len(text) - start)
        else:
            start = len(text) - len(text.lstrip())
            end = len(text)
        message = d.message + (f"\nfix: {d.hint}" if d.hint else "")
        related = []
        for chain in d.call_sites:
            site = _SITE.match(chain[0]) if chain else None
            if site is None:
                continue
            where = self.uri_of(site.group(1))
            more = ", called from ".join(chain[1:])
            related.append(lsp.DiagnosticRelatedInformation(
                lsp.Location(where, lsp.Range(lsp.Position(int(site.group(2)) - 1, 0),
                                              lsp.Position(int(site.group(2)) - 1, 0))),
                "macro instance called here" + (f", called from {more}" if more else "")))
        tags = [lsp.DiagnosticTag.Unnecessary] if d.rule in UNNECESSARY else \
            [lsp.DiagnosticTag.Deprecated] if d.rule in DEPRECATED else None
        href = self.rule_href(d.rule)
        return lsp.Diagnostic(
            range=lsp.Range(self.position(lines, line, start), self.position(lines, line, end)),
            message=message, severity=SEVERITY.get(d.severity, lsp.DiagnosticSeverity.Error),
            code=d.rule or None, source="urdftool",
            code_description=lsp.CodeDescription(href) if href else None,
            related_information=related or None, tags=tags)

    def publish(self, roots: list[Path]) -> None:
        for root in roots:
            result = self.engine.snapshot.get(root)
            if result is None:
                continue
            uris = set()
            found_in = dict(result.diagnostics)
            for report, _ in result.checks:  # open files the checks read: a fresh (maybe
                for name in (report.path, *report.includes):  # empty) set after each check
                    key = resolved(name)
                    if key in self.uris:
                        found_in.setdefault(key, [])
            for path, found in found_in.items():
                lines = (self.text_of(path) or "").splitlines()
                uri = self.uri_of(path)
                pairs = [(self.to_lsp(d, lines), d) for d in found]
                self.shown[uri] = pairs
                uris.add(uri)
                self.text_document_publish_diagnostics(lsp.PublishDiagnosticsParams(
                    uri, [p for p, _ in pairs], version=self.versions.get(path)))
            for uri in self.published.get(root, set()) - uris:
                self.shown.pop(uri, None)
                self.text_document_publish_diagnostics(lsp.PublishDiagnosticsParams(uri, []))
            self.published[root] = uris
            for note in result.notes:
                self.log(f"urdftool: {note}")

    # -- scheduling ------------------------------------------------------------------------

    def schedule(self, path: str, now: bool = False) -> None:
        self.changed.add(path)
        self.now = self.now or now
        self.wake.set()  # a wait for typing to pause ends here: the change goes first
        if self.task is None or self.task.done():
            self.task = asyncio.get_running_loop().create_task(self._run())

    async def _run(self) -> None:
        loop = asyncio.get_running_loop()
        try:
            while True:
                if self.changed:
                    if not self.now and self.engine.settings.debounce:
                        await asyncio.sleep(self.engine.settings.debounce)
                    self.now = False
                    paths = sorted(self.changed)
                    self.changed.clear()
                    texts = {p: self.buffer(p) for p in paths}
                    self.running = True
                    try:
                        roots = await loop.run_in_executor(self.worker, self._refresh, texts)
                        self.publish(roots)
                    finally:
                        self.running = False
                    self.collect()
                    continue
                if not self.engine.pending():
                    return
                # typing goes on: the checks put off wait for a pause, and a change ends the
                # wait at once (it is checked first); they stop between targets for a change
                self.wake.clear()
                try:
                    await asyncio.wait_for(self.wake.wait(), PENDING_DELAY)
                    continue
                except asyncio.TimeoutError:
                    pass
                roots = await loop.run_in_executor(
                    self.worker, self.engine.refresh_pending, lambda: bool(self.changed))
                self.publish(roots)
        except Exception as exc:  # noqa: BLE001 - said, and the next change runs again
            self.log(f"urdftool: check failed: {type(exc).__name__}: {exc}\n"
                     + traceback.format_exc(), lsp.MessageType.Error)

    def collect(self) -> None:
        """Collect the garbage of a check after its diagnostics are out, not during the next
        one: an expansion leaves ~13,000 minidom nodes in reference cycles, and Python's own
        full collection, when it fell inside a check, doubled that edit's time (the p95 of
        the UR arm). The objects alive after the first check (modules, rules) are frozen out
        of every later collection. Skipped while a change waits, up to COLLECT_EVERY checks."""
        self.checks += 1
        if self.changed and self.checks % COLLECT_EVERY:
            return
        gc.collect()
        if not self.frozen:
            gc.freeze()
            self.frozen = True

    def buffer(self, path: str) -> str | None:
        """The open buffer's text given to the checks (None: not open), its version noted."""
        key = resolved(path)
        uri = self.uris.get(key)
        document = self.workspace.text_documents.get(uri) if uri else None
        if document is None:
            self.versions.pop(key, None)
            return None
        self.versions[key] = document.version
        return document.source

    def _refresh(self, texts: dict[str, str | None]) -> list[Path]:
        for path, text in texts.items():
            self.engine.set_buffer(path, text)
        return self.engine.refresh(list(texts))

    async def run_in_worker(self, function, *args):
        return await asyncio.get_running_loop().run_in_executor(self.worker, function, *args)


def rule_page(rule) -> str:
    """A rule's page (Markdown) from its registration."""
    fix = f", {rule.fix} fix" if rule.fix else ""
    parts = [f"# {rule.id}", f"*{rule.severity}{fix}*", rule.summary]
    if rule.doc:
        parts.append(" ".join(rule.doc.split()))
    if rule.bad:
        parts.append(f"Triggers it:\n\n```xml\n{rule.bad}\n```")
    if rule.good:
        parts.append(f"Use instead:\n\n```xml\n{rule.good}\n```")
    return "\n\n".join(parts) + "\n"


def guarded(function):
    """A handler that never takes the server down: its exception is logged to the client and
    the request answered with null."""

    def said(server, exc) -> None:
        server.log(f"urdftool: {function.__name__} failed: {type(exc).__name__}: {exc}\n"
                   + traceback.format_exc(), lsp.MessageType.Error)

    if asyncio.iscoroutinefunction(function):
        @functools.wraps(function)
        async def waited(server: UrdfLanguageServer, params):
            try:
                return await function(server, params)
            except Exception as exc:  # noqa: BLE001
                said(server, exc)
                return None

        return waited

    @functools.wraps(function)
    def wrapper(server: UrdfLanguageServer, params):
        try:
            return function(server, params)
        except Exception as exc:  # noqa: BLE001
            said(server, exc)
            return None

    return wrapper


def workspace_folders(params: lsp.InitializeParams) -> list[Path]:
    """The client's workspace folders (``workspaceFolders``, else ``rootUri``/``rootPath``),
    resolved: the roots of the checks of their files (the workspace folder, not the work tree
    around it: a checkout without metadata of its own, a folder of a monorepo)."""
    uris = [f.uri for f in params.workspace_folders or ()] or \
        ([params.root_uri] if params.root_uri else [])
    paths = [to_fs_path(u) for u in uris if u.startswith("file:")]
    if not paths and params.root_path:
        paths = [params.root_path]
    return [Path(os.path.realpath(p)) for p in paths if p]


def _untrusted_settings(ls: UrdfLanguageServer, data: dict) -> dict:
    """What an untrusted workspace's settings may change (issue 28.5): nothing that widens
    what is read or where links point (``WIDENING``: the operator's alone), and the limits
    (``LIMITS``) only downwards from the operator's (a larger value is the operator's)."""
    widening = sorted(set(data) & WIDENING)
    if widening:
        ls.log(f"urdftool: settings {', '.join(widening)} ignored: the workspace is "
               "untrusted (give them as initializationOptions or on the command line)",
               lsp.MessageType.Warning)
    data = {k: v for k, v in data.items() if k not in WIDENING}
    for key, (attribute, default) in LIMITS.items():
        value = data.get(key)
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            continue  # (a wrong type is refused by Settings.updated)
        ceiling = getattr(ls.operator_settings, attribute)
        ceiling = default if ceiling is None else ceiling
        if not 0 < value <= ceiling:
            ls.log(f"urdftool: setting {key} {value!r} ignored: an untrusted workspace may only "
                   f"lower it (the operator's is {ceiling!r})", lsp.MessageType.Warning)
            data[key] = ceiling
    return data


def make_server(settings: Settings | None = None) -> UrdfLanguageServer:
    from urdftool.lsp import actions, navigation

    server = UrdfLanguageServer(settings)

    @server.feature(lsp.INITIALIZE)
    @guarded
    def initialize(ls: UrdfLanguageServer, params: lsp.InitializeParams):
        settings, problems = ls.launch_settings.updated(params.initialization_options,
                                                        trust=True)
        ls.operator_settings = settings  # the ceiling of what the workspace may set
        ls.engine.set_settings(settings)
        ls.engine.folders = workspace_folders(params)
        for problem in problems:
            ls.log(f"urdftool: initializationOptions: {problem}", lsp.MessageType.Warning)

    @server.feature(lsp.WORKSPACE_DID_CHANGE_CONFIGURATION)
    @guarded
    async def did_change_configuration(ls: UrdfLanguageServer, params):
        ls.configuring += 1
        try:
            await _configure(ls, params.settings)
        finally:
            ls.configuring -= 1

    async def _configure(ls: UrdfLanguageServer, data):
        if isinstance(data, dict) and isinstance(data.get("urdftool"), dict):
            data = data["urdftool"]
        elif ls.client_capabilities.workspace is not None and \
                ls.client_capabilities.workspace.configuration:
            # the pull model (settings null, or another tool's): ask for our section
            answer = await ls.workspace_configuration_async(lsp.ConfigurationParams(
                [lsp.ConfigurationItem(section="urdftool")]))
            data = answer[0] if answer else None
        if not isinstance(data, dict) or not data:
            return
        if not ls.engine.settings.trusted:  # a workspace's own settings (in the repository)
            data = _untrusted_settings(ls, data)
        settings, problems = ls.engine.settings.updated(data)
        for problem in problems:
            ls.log(f"urdftool: settings: {problem}", lsp.MessageType.Warning)
        await ls.run_in_worker(ls.engine.set_settings, settings)
        for key in list(ls.uris):
            ls.schedule(key, now=True)

    @server.feature(lsp.TEXT_DOCUMENT_DID_OPEN)
    @guarded
    def did_open(ls: UrdfLanguageServer, params: lsp.DidOpenTextDocumentParams):
        path = ls.path_of(params.text_document.uri)
        if path is not None:
            ls.uris[resolved(path)] = params.text_document.uri
            ls.schedule(path, now=True)

    @server.feature(lsp.TEXT_DOCUMENT_DID_CHANGE)
    @guarded
    def did_change(ls: UrdfLanguageServer, params: lsp.DidChangeTextDocumentParams):
        path = ls.path_of(params.text_document.uri)
        if path is not None:
            ls.schedule(path)

    @server.feature(lsp.TEXT_DOCUMENT_DID_SAVE)
    @guarded
    def did_save(ls: UrdfLanguageServer, params: lsp.DidSaveTextDocumentParams):
        path = ls.path_of(params.text_document.uri)
        if path is not None:
            ls.engine.touched(resolved(path))  # saved unchanged: checked again all the same
            ls.schedule(path, now=True)

    @server.feature(lsp.WORKSPACE_DID_CHANGE_WATCHED_FILES)
    @guarded
    def did_change_watched_files(ls: UrdfLanguageServer, params):
        """Files changed on disk (the client's watchers): a ``package.xml`` added or removed
        changes what every unit resolves (issue 29: the lookups were kept for the life of
        the server), so every unit plans and checks again; another file is a change of the
        checks that read it."""
        paths = [ls.path_of(change.uri) for change in params.changes]
        paths = [p for p in paths if p is not None]
        if any(os.path.basename(p) == "package.xml" for p in paths):
            for unit in ls.engine.units.values():
                unit.planned = False
            for key in list(ls.uris):
                ls.schedule(key, now=True)
            return
        for path in paths:
            ls.engine.touched(resolved(path))
            ls.schedule(path, now=True)

    @server.feature(lsp.TEXT_DOCUMENT_DID_CLOSE)
    @guarded
    def did_close(ls: UrdfLanguageServer, params: lsp.DidCloseTextDocumentParams):
        path = ls.path_of(params.text_document.uri)
        if path is not None:
            ls.schedule(path, now=True)  # read from the disk again
            ls.uris.pop(resolved(path), None)

    @server.feature(lsp.SHUTDOWN)
    def shutdown(ls: UrdfLanguageServer, params):
        ls.worker.shutdown(wait=False, cancel_futures=True)
        # the requests still running are cancelled here, over a copy: pygls 2.1 cancels them
        # while iterating the dict their callbacks remove them from (a RuntimeError and a
        # traceback on stderr when a request is pending at shutdown)
        protocol = ls.protocol
        pending = getattr(protocol, "_request_futures", {})
        for msg_id, future in list(pending.items()):
            if msg_id != protocol.msg_id and not future.done():
                future.cancel()

    @server.command(CHECK_COMMAND)
    async def check_now(ls: UrdfLanguageServer, *uris):
        """Check the documents named (URIs) now and answer when every check waiting is done:
        the number of findings published (editors' "check now"; the tests wait on it)."""
        try:
            for uri in uris:
                path = ls.path_of(uri) if isinstance(uri, str) else None
                if path is not None:
                    ls.schedule(path, now=True)
            while ls.changed or ls.running or ls.configuring:  # (not the checks put off: they change no
                await asyncio.sleep(0.005)  # finding shown, the entries' reports hold them)
            return sum(len(found) for found in ls.shown.values())
        except Exception as exc:  # noqa: BLE001
            ls.log(f"urdftool: {CHECK_COMMAND} failed: {type(exc).__name__}: {exc}",
                   lsp.MessageType.Error)
            return None

    actions.register(server, guarded)
    navigation.register(server, guarded)
    return server


def serve(settings: Settings | None = None) -> None:
    make_server(settings).start_io()


__all__ = ["ERROR_RULE", "Result", "UrdfLanguageServer", "make_server", "serve"]
