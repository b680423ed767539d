"""`urdftool check --fix`: apply the edits findings carry (``urdftool.edits``) to the files the
user wrote, repeatedly until nothing more applies (a fix can uncover more: a macro call's body).

Safe fixes by default, unsafe ones too with ``unsafe=True``. Every byte outside the edits stays
as it was (comments, indentation, attribute order, line endings, a BOM), and no edit moves a
line. Files are changed in memory here; the CLI writes them (``-o``, ``--in-place``) or shows
the diff.
"""

from __future__ import annotations

import codecs
from pathlib import Path

from urdftool.check import CheckOptions, check_file, check_once, overlay_options
from urdftool.edits import apply
from urdftool.report import FileReport

MAX_ROUNDS = 10


class FixResult:
    __slots__ = ("fixed", "originals", "remaining", "texts")

    def __init__(self, originals: dict[str, str], texts: dict[str, str], fixed: int,
                 remaining: FileReport):
        self.originals = originals  # every file read -> its text as written
        self.texts = texts  # -> its text fixed
        self.fixed = fixed  # findings whose fix was applied
        self.remaining = remaining  # the check of the fixed files

    def changed(self) -> list[str]:
        return [p for p, t in self.texts.items() if t != self.originals.get(p)]


def fix_file(path: str | Path, options: CheckOptions, unsafe: bool = False) -> FixResult:
    """Fix ``path`` (and the files it includes) in memory."""
    import copy

    from urdftool import budget

    reading = copy.copy(options.load)
    reading.lenient = True  # past undefined xacro names: the rest still gets its fixes
    own = budget.remaining() is None  # every round and the last check share one budget
    if own:
        budget.start(options.load.timeout, 1)
    try:
        return _fix_rounds(path, options, unsafe, reading)
    finally:
        if own:
            budget.stop()


def _fix_rounds(path, options: CheckOptions, unsafe: bool, reading) -> FixResult:
    import copy

    from urdftool import budget

    originals: dict[str, str] = {}
    texts: dict[str, str] = {}
    fixed: set = set()
    for _ in range(MAX_ROUNDS):
        if budget.spent():
            break
        source, _, diagnostics = check_once(path, options, overlay_options(reading, texts))
        for name, text in source.texts.items():
            originals.setdefault(name, text)
            texts.setdefault(name, text)
        chosen = [d for d in diagnostics if d.fix is not None
                  and (unsafe or d.fix.applicability == "safe")]
        edits = [e for d in chosen for e in d.fix.edits]
        made: set = set()
        changed = False
        for name in sorted({e.path for e in edits}):
            if name not in texts:  # named only by an unprocessed include
                if name not in source.unread:
                    continue  # no file the reading read: never written
                texts[name] = originals[name] = source.unread[name]
            new, made_here = apply(texts[name], edits, name)
            made.update(made_here)
            if new != texts[name]:
                texts[name], changed = new, True
        fixed.update((d.rule, d.path, d.line, d.message) for d in chosen
                     if any(e in made for e in d.fix.edits))
        if not changed:
            break
    final = copy.copy(options)
    final.load = overlay_options(options.load, texts)
    remaining = check_file(path, final)  # looking through what could not be fixed
    return FixResult(originals, texts, len(fixed), remaining)


_BOMS = ((codecs.BOM_UTF32_LE, "utf-32"), (codecs.BOM_UTF32_BE, "utf-32"),
         (codecs.BOM_UTF8, "utf-8-sig"), (codecs.BOM_UTF16_LE, "utf-16"),
         (codecs.BOM_UTF16_BE, "utf-16"))


def encoded(path: str | Path, original: str, fixed: str) -> tuple[str, str]:
    """(text, encoding) to write ``fixed`` as the file ``path`` was written: the lines the fixes
    changed replace those of the file's own text (reading may have rewritten an encoding
    declaration), in its encoding."""
    try:
        data = Path(path).read_bytes()
    except OSError:
        return fixed, "utf-8"
    from urdftool.textscan import declared_encoding

    encoding = next((e for bom, e in _BOMS if data.startswith(bom)), None) \
        or declared_encoding(data) or "utf-8"
    try:
        raw = data.decode(encoding)
    except UnicodeDecodeError:
        return fixed, "utf-8"
    if not encoding.startswith("utf"):  # (ISO-8859-1...): what it cannot hold as references
        fixed = fixed.encode(encoding, "xmlcharrefreplace").decode(encoding)
    if encoding == "utf-8":
        if fixed.isascii():
            return fixed, encoding
        from urdftool.textscan import declared_utf8

        fixed = declared_utf8(fixed)  # read as UTF-8 whatever the declaration says: say so
        return fixed, encoding
    lines, before, after = raw.split("\n"), original.split("\n"), fixed.split("\n")
    if not len(lines) == len(before) == len(after):
        return fixed, encoding
    return "\n".join(a if a != b else line for line, b, a in zip(lines, before, after)), encoding


def unified_diff(result: FixResult) -> str:
    """The unified diff of the fixes, safe to print: lines are split at LF only (as ``patch``
    and ``git`` split them), and each line's content goes through ``display.clean`` (tabs and a
    CRLF ending kept): a control or format character (ESC, a lone CR, a bidi override) is
    shown escaped, a legacy ``##[`` CI command defused. A valid XML file has no such character
    in it, so its diff applies as printed; the others' is a view (``--fix`` writes the file)."""
    import difflib
    import re

    from urdftool.display import clean

    def lines(text: str) -> list[str]:
        return re.findall(r"[^\n]*\n|[^\n]+", text)

    def shown(line: str) -> str:
        body, end = (line[:-2], "\r\n") if line.endswith("\r\n") else \
            (line[:-1], "\n") if line.endswith("\n") else (line, "\n")
        return clean(body, tabs=True) + end

    parts = []
    for name in result.changed():
        label = clean(name.lstrip("/"))
        parts.extend(map(shown, difflib.unified_diff(
            lines(result.originals[name]), lines(result.texts[name]), f"a/{label}",
            f"b/{label}")))
    return "".join(parts)
