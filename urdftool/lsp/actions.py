"""Code actions of ``urdftool lsp``: each finding's fix as a quick fix (the finding's own
``Fix`` edits, as ``check --fix`` applies them: safe ones preferred, unsafe ones labelled), an
"ignore this rule here" comment (``<!-- urdftool: ignore RULE -->``, what ``config.suppressions``
reads), and "fix all safe" (``fix.fix_file``, the code of ``check --fix``, on the entry that
reads the document; the document's changes only)."""

from __future__ import annotations

import copy
import os
import re

from lsprotocol import types as lsp

from urdftool.lsp.engine import resolved

# (linear: the ids and the spaces around them in one lazy group that cannot cross a '<' or
# '>'; adjacent \s+ ... \s* quantifiers took cubic time on a long comment: issue 21)
_IGNORE = re.compile(r"<!--\s*urdftool:\s*ignore(\s[^<>]*?)-->")


def text_edits(server, lines: list[str], edits) -> list[lsp.TextEdit]:
    return [lsp.TextEdit(lsp.Range(server.position(lines, e.line - 1, e.column - 1),
                                   server.position(lines, e.end_line - 1, e.end_column - 1)),
                         e.text) for e in edits]


def line_edits(server, old: str, new: str) -> list[lsp.TextEdit]:
    """The lines that differ, each replaced whole (a fix never adds or removes a line)."""
    before, after = old.split("\n"), new.split("\n")
    if len(before) != len(after):
        end = server.position(before, len(before) - 1, len(before[-1]))
        return [lsp.TextEdit(lsp.Range(lsp.Position(0, 0), end), new)]
    return [lsp.TextEdit(lsp.Range(server.position(before, i, 0),
                                   server.position(before, i, len(a))), b)
            for i, (a, b) in enumerate(zip(before, after)) if a != b]


def checked_text(server, path: str) -> str | None:
    """The text of ``path`` that the last check read."""
    key = resolved(path)
    for result in server.engine.snapshot.values():
        for report, _ in result.checks:
            for name, text in report.texts.items():
                if resolved(name) == key:
                    return text
    return None


def current(server, path: str) -> bool:
    """Whether the client's text of ``path`` is still the one the last check read."""
    checked = checked_text(server, path)
    return checked is not None and server.text_of(path) == checked


def writable(server, path: str) -> bool:
    """Whether the server may offer an edit of ``path`` (issue 28.8): what ``check --fix``'s
    one writer (``urdftool.output``) would write, in the workspace: the file lies in a
    workspace folder, as named and once resolved (not a link out of it), no symbolic link is
    on the way to it below that folder (nor below its repository), nor is it one."""
    from urdftool.errors import ToolError
    from urdftool.output import check_target

    absolute = os.path.abspath(path)
    engine = server.engine
    key = resolved(path)
    # the workspace folders; without any (a client that names none), the package whose
    # check read the file
    folders = [str(f) for f in engine.folders] or [
        str(unit.root) for unit in list(engine.units.values())
        if any(r is not None and key in engine._reads(r) for r in unit.reports)]
    if folders:
        inside = [f for f in folders if _under(absolute, f)]
        if not inside or not _under(os.path.realpath(absolute), inside[0]):
            return False
        # the workspace folder is the repository of an editor's edits: no link below it
        # (as the one writer walks below a repository), whether or not it is under git
        where = inside[0]
        for part in os.path.relpath(absolute, where).split(os.sep):
            where = os.path.join(where, part)
            try:
                if os.path.islink(where):
                    return False
            except OSError:
                return False
    try:
        check_target(absolute, inputs=(absolute,), may_replace=(absolute,))
    except (ToolError, OSError):
        return False
    return True


def _under(path: str, folder: str) -> bool:
    return path == folder or path.startswith(folder.rstrip(os.sep) + os.sep)


def fix_action(server, diagnostic: lsp.Diagnostic, d) -> lsp.CodeAction | None:
    fix = d.fix
    if fix is None or not fix.edits:
        return None
    changes: dict[str, list[lsp.TextEdit]] = {}
    for path in dict.fromkeys(e.path for e in fix.edits):
        if not current(server, path):
            return None  # the text changed since: its check is on the way
        if not writable(server, path):
            return None  # check --fix would refuse to write it
        lines = server.text_of(path).split("\n")
        changes[server.uri_of(path)] = text_edits(
            server, lines, [e for e in fix.edits if e.path == path])
    safe = fix.applicability == "safe"
    what = " ".join((d.hint or "apply the fix").split())
    what = what if len(what) <= 100 else what[:99] + "…"
    title = f"Fix {d.rule}: {what}" + ("" if safe else " (unsafe: changes a value you chose)")
    return lsp.CodeAction(title, kind=lsp.CodeActionKind.QuickFix, diagnostics=[diagnostic],
                          is_preferred=safe, edit=lsp.WorkspaceEdit(changes=changes))


def ignore_action(server, uri: str, diagnostic: lsp.Diagnostic, d) -> lsp.CodeAction | None:
    """``<!-- urdftool: ignore RULE -->`` on its own line above the finding's (a comment
    there already: the rule added to it). A finding in a macro body is ignored in every
    instance."""
    if not d.rule or not d.line:
        return None
    path = server.path_of(uri)
    text = server.text_of(path) if path else None
    if text is None:
        return None
    lines = text.split("\n")
    index = d.line - 1
    if index >= len(lines):
        return None
    above = _IGNORE.search(lines[index - 1]) if index > 0 else None
    if above is not None:
        raw = above.group(1)
        ids = raw.split()
        if d.rule in ids:
            return None
        start = server.position(lines, index - 1,
                                above.start(1) + len(raw) - len(raw.lstrip()))
        end = server.position(lines, index - 1, above.end(1) - (len(raw) - len(raw.rstrip())))
        edit = lsp.TextEdit(lsp.Range(start, end), " ".join([*ids, d.rule]))
    else:
        indent = re.match(r"[ \t]*", lines[index]).group(0)
        edit = lsp.TextEdit(lsp.Range(lsp.Position(index, 0), lsp.Position(index, 0)),
                            f"{indent}<!-- urdftool: ignore {d.rule} -->\n")
    return lsp.CodeAction(f"Ignore {d.rule} here (urdftool: ignore comment)", kind=lsp.CodeActionKind.QuickFix,
                          diagnostics=[diagnostic],
                          edit=lsp.WorkspaceEdit(changes={uri: [edit]}))


def fix_all_edits(server, path: str) -> list[lsp.TextEdit] | None:
    """The document's changes from ``check --fix`` (safe fixes) of the check that reads it
    (the entry for a fragment). Runs in the worker thread."""
    from urdftool.check import target_options
    from urdftool.fix import fix_file

    engine = server.engine
    key = resolved(path)
    unit = engine.unit_of(path)
    if unit is None:
        return None
    candidates = [(t, r) for t, r in zip(unit.targets, unit.reports)
                  if r is not None and key in engine._reads(r)]
    candidates.sort(key=lambda tr: (not (tr[0].configured or tr[1].role == "entry"),
                                    resolved(tr[0].path) != key))
    if not candidates:
        return None
    target = candidates[0][0]
    options = engine.check_options(unit)
    options = copy.copy(options)
    options.load = target_options(options, target)
    result = fix_file(target.path, options)
    for name, fixed in result.texts.items():
        if resolved(name) == key:
            original = result.originals.get(name)
            if original is None or original == fixed:
                return []
            return line_edits(server, original, fixed)
    return []


def register(server, guarded) -> None:
    kinds = [lsp.CodeActionKind.QuickFix, lsp.CodeActionKind.SourceFixAll]

    @server.feature(lsp.TEXT_DOCUMENT_CODE_ACTION,
                    lsp.CodeActionOptions(code_action_kinds=kinds))
    @guarded
    async def code_action(ls, params: lsp.CodeActionParams):
        uri = params.text_document.uri
        wanted = params.context.only
        first, last = params.range.start.line, params.range.end.line
        result: list[lsp.CodeAction] = []

        def asked(kind: str) -> bool:
            return not wanted or any(kind == w or kind.startswith(w + ".") for w in wanted)

        shown = ls.shown.get(uri, [])
        if asked(lsp.CodeActionKind.QuickFix):
            fixes, ignores = [], []
            for diagnostic, d in shown:
                line = diagnostic.range.start.line
                if not first <= line <= max(last, first):
                    continue
                action = fix_action(ls, diagnostic, d)
                if action is not None:
                    fixes.append(action)
                action = ignore_action(ls, uri, diagnostic, d)
                if action is not None:
                    ignores.append(action)
            fixes.sort(key=lambda a: not a.is_preferred)
            result += fixes + ignores
        path = ls.path_of(uri)
        if path and asked(FIX_ALL) and writable(ls, path) and any(
                d.fix is not None and d.fix.applicability == "safe" for _, d in shown) \
                and current(ls, path):
            edits = await ls.run_in_worker(fix_all_edits, ls, path)
            if edits:
                result.append(lsp.CodeAction(
                    "urdftool: apply every safe fix (as check --fix)", kind=FIX_ALL,
                    edit=lsp.WorkspaceEdit(changes={uri: edits})))
        return result


FIX_ALL = "source.fixAll.urdftool"
