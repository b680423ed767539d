"""Human-readable output, shared by every command: one location format
(``path:line:col: severity rule: message``) and file content made harmless before it reaches a
terminal or a CI log.

A robot file is untrusted: its names and lines are shown through ``clean``, which escapes control
characters (C0, DEL, C1, bidi overrides and other invisible format characters, line and paragraph
separators) as ``\\x1b``, ``\\n``, ``\\u202e``..., so that content cannot move the cursor, recolour
the terminal, start a new line or reorder text. A CI runner also executes commands written in its
log: GitHub Actions a line starting (after blanks) with ``::``, and its legacy form ``##[...]`` (as
Azure Pipelines ``##vso[...]``) anywhere in a line. ``clean`` neutralises both in a value, and
``guard`` (``GuardedStream`` for rich consoles) in whole lines of output, whatever the layout put
at the start of a line. Machine formats (JSON, SARIF) stay exact: ``json_safe`` only writes ``#``
as ``\\u0023`` where it would spell a legacy command, which any JSON reader reads back unchanged.

Bottom layer: no reader, no rich (imported by ``check`` on every run).
"""

from __future__ import annotations

import re

SEVERITY_STYLE = {"error": ("red", True), "warning": ("yellow", False), "info": ("cyan", False)}

# categories escaped: controls, format characters (bidi overrides and isolates, zero-width
# characters, soft hyphen...), line and paragraph separators, surrogates, private use
_UNSAFE = frozenset(("Cc", "Cf", "Zl", "Zp", "Cs", "Co"))
_SHORT = {"\t": "\\t", "\n": "\\n", "\r": "\\r"}
_LEGACY = re.compile(r"#(?=#(?:vso)?\[)", re.IGNORECASE)  # the first '#' of ##[ or ##vso[
# a line start (CI runners split lines at \n and \r) followed by blanks or colour codes, then ::
# (blanks and colour codes written as an unrolled loop: one fast run of blanks, then codes each
# followed by blanks; the same language, five times cheaper than an alternation per character)
_LINE_START = re.compile(r"(?:\A|(?<=[\r\n]))([^\S\r\n]*(?:\x1b\[[0-9;:]*m[^\S\r\n]*)*):(?=:)")
_OPEN_START = re.compile(r"[^\S\r\n]*(?:\x1b\[[0-9;:]*m[^\S\r\n]*)*:?")  # may become "::"
_OPEN_TAIL = re.compile(r"#(?:#(?:v(?:so?)?)?)?\Z", re.IGNORECASE)  # may still become "##["


def _escape(char: str) -> str:
    code = ord(char)
    if char in _SHORT:
        return _SHORT[char]
    if code < 0x100:
        return f"\\x{code:02x}"
    return f"\\u{code:04x}" if code < 0x10000 else f"\\U{code:08x}"


def clean(value, newlines: bool = False, tabs: bool = False) -> str:
    """``value`` as text safe to print: control and invisible format characters escaped (CR and
    LF kept with ``newlines``, for formats that escape them themselves; tabs with ``tabs``), no
    legacy CI command, and no ``::`` at its start."""
    text = str(value)
    if not text.isprintable():
        import unicodedata

        keep = ("\r\n" if newlines else "") + ("\t" if tabs else "")
        text = "".join(_escape(c) if c not in keep and unicodedata.category(c) in _UNSAFE else c
                       for c in text)
    return guard(text)


def guard(text: str) -> str:
    """Whole lines of output: no line starts (after blanks and colour codes) with ``::`` and no
    ``##[`` anywhere. Values are escaped by ``clean`` already; this holds whatever the layout
    (a table cell, a wrapped line) puts where."""
    if "#" in text:
        text = _LEGACY.sub(r"\\x23", text)
    if ":" in text:
        text = _LINE_START.sub(r"\1\\x3a", text)
    return text


def xml_guard(document: str) -> str:
    """An XML document bound for stdout (``expand``, ``convert``): the same document for any
    XML parser, with no line a CI runner executes. Outside comments and CDATA a ``:`` that
    would start a line with ``::`` is written ``&#58;`` and the first ``#`` of ``##[``
    ``&#35;``; inside them (no character references there, and no data) as ``guard`` writes
    them. A document without such a line is returned as is."""
    if guard(document) == document:
        return document
    from urdftool.textscan import markup_split

    pieces = markup_split(document)
    for index in range(0, len(pieces), 2):  # the text and markup between comments
        piece = _LEGACY.sub("&#35;", pieces[index])
        pieces[index] = _LINE_START.sub(r"\1&#58;", piece)
    for index in range(1, len(pieces), 2):
        pieces[index] = guard(pieces[index])
    return "".join(pieces)


def json_safe(text: str) -> str:
    """A JSON document with no legacy CI command in it (``#`` as ``\\u0023`` there; the same
    JSON value once read)."""
    return _LEGACY.sub(r"\\u0023", text) if "#" in text else text


class GuardedStream:
    """A text stream that writes through ``guard`` a line at a time. ``flush`` writes a partial
    line too, except what could still become a command with the next write (blanks and one
    ``:`` at a line start, a trailing ``#``)."""

    def __init__(self, stream):
        self._stream = stream
        self._partial = ""
        self._midline = False  # the last text written did not end a line

    def write(self, text: str) -> int:
        joined = self._partial + text
        end = max(joined.rfind("\n"), joined.rfind("\r")) + 1
        self._partial = joined[end:]
        if end:
            self._emit(joined[:end])
        return len(text)

    def _emit(self, text: str) -> None:
        if text:
            # mid-line: the text does not start a line ('x' stands for what was written before)
            self._stream.write(guard("x" + text)[1:] if self._midline else guard(text))
            self._midline = not text.endswith(("\n", "\r"))

    def flush(self) -> None:
        partial = self._partial
        if partial and (self._midline or not _OPEN_START.fullmatch(partial)):
            tail = _OPEN_TAIL.search(partial)
            cut = tail.start() if tail else len(partial)
            self._emit(partial[:cut])
            self._partial = partial[cut:]
        self._stream.flush()

    def __getattr__(self, name):  # isatty, fileno, encoding...: the stream's
        return getattr(self._stream, name)


CLIP = 600  # characters of a message, hint or element path from a file that a report shows
EXCERPT = 160  # characters of a quoted source line shown around the column


def clip(text: str | None, limit: int = CLIP) -> str | None:
    """``text`` cut to about ``limit`` characters: its start and end kept, the middle said as
    ``[… N characters …]`` (a message that quotes a megabyte-long name stays one line)."""
    if text is None or len(text) <= limit:
        return text
    tail = limit // 4
    head = limit - tail
    return f"{text[:head]}[… {len(text) - head - tail} characters …]{text[-tail:]}"


def excerpt(text: str, start: int, end: int, column: int | None,
            width: int = EXCERPT) -> tuple[str, int | None]:
    """(shown, caret) of the line ``text[start:end]`` (its line end excluded): about ``width``
    characters around ``column`` (1-based; the start of the line without one), an ellipsis
    where the line goes on, tabs expanded, escaped (``clean``); ``caret`` is the column's
    0-based position in ``shown`` (None without a column). Only the window is read."""
    length = end - start
    at = min(max((column or 1) - 1, 0), length)
    if length > width:
        first = min(max(0, at - width // 2), length - width)
    else:
        first = 0
    last = min(length, first + width)
    before = "…" if first > 0 else ""
    after = "…" if last < length else ""
    window = text[start + first:start + last].rstrip("\r")
    shown = before + clean(window.expandtabs(4)) + after
    caret = None
    if column:
        caret = len(before) + len(clean(window[:at - first].expandtabs(4)))
    return shown, caret


# characters GitHub-flavoured markdown gives a meaning inside a line (emphasis, code, links,
# images, table cells, HTML, entities, strikethrough, autolinks `http:`, mentions): escaped so
# that text from a file is shown as written (the text never starts a line: no heading or list)
_MARKDOWN = {c: "\\" + c for c in "\\`*_[]<>|!&~:@"}
_MARKDOWN_TABLE = str.maketrans(_MARKDOWN)


def markdown_text(value) -> str:
    """``value`` (text from a file: a name, a message) as inert markdown: every character
    markdown or HTML could read escaped with a backslash (no tag, link, image, table cell or
    mention can come of it), control characters escaped (``clean``), one line."""
    return clean(value).translate(_MARKDOWN_TABLE).replace("\n", " ").replace("\r", " ")


def location(path, line: int | None = None, column: int | None = None) -> str:
    """``path:line:col``, ``path:line`` or ``path``: the same in every command."""
    where = clean(path)
    if line:
        where += f":{line}"
        if column:
            where += f":{column}"
    return where


def diagnostic_line(path, line: int | None, column: int | None, severity: str, rule: str | None,
                    message: str, colour: bool = False) -> str:
    """``path:line:col: severity rule: message`` (``path: severity: message`` without a line or
    a rule): how every command states a finding."""
    where = location(path, line, column)
    label = f"{severity} {rule}" if rule else severity
    message = clean(message)
    if not colour:
        return f"{where}: {label}: {message}"
    import click

    fg, bold = SEVERITY_STYLE.get(severity, (None, False))
    styled = click.style(severity, fg=fg, bold=bold) + (
        " " + click.style(rule, dim=True) if rule else "")
    return f"{click.style(where, bold=True)}: {styled}: {message}"


def number(value, digits: int = 6, missing: str = "-") -> str:
    """A number as the human tables show it (``limits`` 6 significant digits, ``inertia``
    4; JSON keeps every digit): the one display format of the CLI and the editor's hovers."""
    if value is None:
        return missing
    return f"{value:.{digits}g}" if isinstance(value, float) else str(value)
