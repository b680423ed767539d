"""Edits attached to findings: text replacements at positions in the file the user wrote.

A rule (or the XML repair, or the xacro loader) that knows the fix of what it found returns it
with the finding as ``Edit`` records; the rule's registration says whether the fix is *safe*
(the intent is unambiguous) or *unsafe* (it changes values a person chose). ``check`` applies
the safe ones in memory to look through the mistake; ``check --fix`` writes them.

An edit never adds or removes a line break, so the lines of the rest of the file never move
and every other finding keeps its position. Bottom layer: works on texts only (no readers).
"""

from __future__ import annotations

import re
from typing import NamedTuple

APPLICABILITIES = ("safe", "unsafe")


class Edit(NamedTuple):
    """Replace the text from (line, column) up to, not including, (end_line, end_column) of
    ``path`` by ``text``. Lines and columns are 1-based; columns count characters."""

    path: str
    line: int
    column: int
    end_line: int
    end_column: int
    text: str

    def to_json(self) -> dict:
        return self._asdict()


class Fix(NamedTuple):
    """The edits of one finding and how safe it is to apply them without looking."""

    applicability: str  # "safe" or "unsafe"
    edits: tuple[Edit, ...]

    def to_json(self) -> dict:
        return {"applicability": self.applicability, "edits": [e.to_json() for e in self.edits]}


class ByHand(str):
    """Why there is no edit (e.g. the value is computed by a xacro expression): the finding
    says it instead of carrying an edit."""


# -- positions ----------------------------------------------------------------------------------


_STARTS: dict[str, list[int]] = {}  # text -> its line starts: every text is split once
_STARTS_KEPT = 64
_LAST: list = [None, None]  # the text asked last and its starts


def line_starts(text: str) -> list[int]:
    """The offset where each line of ``text`` starts (lines end at ``\\n``), computed once per
    text and shared by the edits, the report's excerpts and positions (the list is shared:
    never change it). The last few texts are kept (a run checks one file, its includes and
    their look-through rounds at a time)."""
    if _LAST[0] is text:  # the same text again (every position of one file): no lookup,
        return _LAST[1]   # which would compare an equal text of another object in full
    starts = _STARTS.get(text)
    if starts is None:
        if len(_STARTS) >= _STARTS_KEPT:
            del _STARTS[next(iter(_STARTS))]
        starts = [0]
        find, add = text.find, starts.append
        at = find("\n")
        while at >= 0:
            add(at + 1)
            at = find("\n", at + 1)
        _STARTS[text] = starts
    _LAST[0], _LAST[1] = text, starts
    return starts


def line_at(text: str, line: int) -> str | None:
    """Line ``line`` (1-based) of ``text`` without its line end; None past the end."""
    starts = line_starts(text)
    if not 0 < line <= len(starts):
        return None
    end = starts[line] - 1 if line < len(starts) else len(text)
    return text[starts[line - 1]:end].rstrip("\r")


def offset(starts: list[int], line: int, column: int) -> int:
    return starts[line - 1] + column - 1


def edit(path: str, text: str, start: int, end: int, replacement: str,
         starts: list[int] | None = None) -> Edit:
    """The Edit replacing ``text[start:end]``."""
    from bisect import bisect_right

    starts = starts or line_starts(text)
    line, end_line = bisect_right(starts, start), bisect_right(starts, end)
    return Edit(path, line, start - starts[line - 1] + 1, end_line, end - starts[end_line - 1] + 1,
                replacement)


def apply(text: str, edits, path: str | None = None) -> tuple[str, list]:
    """``text`` with the edits (of ``path``, when given) made; returns the text and the edits
    made. Identical edits count once; an edit overlapping one made before it (in position
    order), or one that would add or remove a line break, is left out."""
    starts = line_starts(text)
    spans = []
    for e in dict.fromkeys(edits):
        if path is not None and e.path != path:
            continue
        if not (0 < e.line <= len(starts) and 0 < e.end_line <= len(starts)):
            continue
        start, end = offset(starts, e.line, e.column), offset(starts, e.end_line, e.end_column)
        if not 0 <= start <= end <= len(text) or text.count("\n", start, end) != e.text.count("\n"):
            continue
        spans.append((start, end, e))
    spans.sort(key=lambda s: (s[0], s[1]))
    parts, made, position = [], [], 0
    for start, end, e in spans:
        if start < position:
            continue
        parts.append(text[position:start])
        parts.append(e.text)
        made.append(e)
        position = end
    parts.append(text[position:])
    return "".join(parts), made


# -- positions after edits, back in the text as written ------------------------------------------


def map_column(made: list, line: int, column: int) -> int:
    """A column of ``line`` in a text after ``made`` (edits of one file, one round), in the text
    before them. Only edits within one line shift columns (none moves a line)."""
    shifts = sorted((e.column, e.end_column, len(e.text)) for e in made
                    if e.line == e.end_line == line and "\n" not in e.text)
    moved = 0  # how far the text after the edits seen so far has moved
    for start, end, length in shifts:
        new_start = start + moved
        if column < new_start:
            break
        if column < new_start + length:
            return start
        moved += length - (end - start)
    return column - moved


def map_back(history: list[dict], path: str, line: int | None, column: int | None):
    """``column`` of ``path``:``line`` after the rounds of ``history`` (oldest first; each a dict
    path -> edits made), in the text as written."""
    if not line or not column:
        return column
    for made in reversed(history):
        column = map_column(made.get(path, ()), line, column)
    return column


def map_diagnostic(diagnostic, history: list[dict]):
    """A diagnostic (and its fix's edits) of a text after ``history``, in the text as
    written."""
    if not history:
        return diagnostic
    column = map_back(history, diagnostic.path, diagnostic.line, diagnostic.column)
    fix = diagnostic.fix
    if fix is not None:
        fix = fix._replace(edits=tuple(e._replace(
            column=map_back(history, e.path, e.line, e.column),
            end_column=map_back(history, e.path, e.end_line, e.end_column)) for e in fix.edits))
    return diagnostic._replace(column=column, fix=fix)


# -- finding things in a start tag -------------------------------------------------------------

_NAME = r"[^\W\d][-\w.:]*"


def tag_at(text: str, starts: list[int], line: int | None, column: int | None,
           names: tuple[str, ...] = ()) -> tuple[int, int] | None:
    """(offset of '<', offset after '>') of the start tag written at ``line``/``column``, named
    one of ``names`` (with or without a prefix; any name when empty). When the tag at
    ``column`` is not one of them (a column found by a prefix search: ``<inertia`` also starts
    ``<inertial>``), or no column is known, the first such tag on the line."""
    if not line or line > len(starts):
        return None

    def named(start: int) -> bool:
        name = tag_name(text, start)
        return name is not None and (not names or name in names or name.split(":")[-1] in names)

    start = offset(starts, line, column) if column else -1
    if not (start >= 0 and text.startswith("<", start) and named(start)):
        end_of_line = starts[line] if line < len(starts) else len(text)
        start = text.find("<", starts[line - 1], end_of_line)
        while start >= 0 and not named(start):
            start = text.find("<", start + 1, end_of_line)
        if start < 0:
            return None
    end = tag_end(text, start)
    return None if end is None else (start, end)


def tag_name(text: str, start: int) -> str | None:
    match = re.compile(_NAME).match(text, start + 1)
    return match.group() if match else None


def tag_end(text: str, start: int) -> int | None:
    """The offset after the '>' closing the start tag at ``start`` (quotes respected)."""
    quote = None
    for index in range(start + 1, len(text)):
        char = text[index]
        if quote:
            if char == quote:
                quote = None
        elif char in "\"'":
            quote = char
        elif char == ">":
            return index + 1
        elif char == "<":
            return None
    return None


def attribute(text: str, tag: tuple[int, int], name: str):
    """(name start, name end, value start, value end) of attribute ``name`` in the start tag
    spanning ``tag``; None when it has no such attribute."""
    pattern = re.compile(r"(?<=[\s\"'])(" + re.escape(name) + r")\s*=\s*(?:\"([^\"]*)\"|'([^']*)')")
    match = pattern.search(text, tag[0], tag[1])
    if match is None:
        return None
    group = 2 if match.group(2) is not None else 3
    return match.start(1), match.end(1), match.start(group), match.end(group)


_AFTER_NAME = frozenset(" \t\r\n\f\v/>")  # what may follow a tag's name (\\s, '/', '>')


def end_tag(text: str, tag: tuple[int, int], name: str) -> tuple[int, int] | None:
    """The span of the name in the end tag matching the start tag ``tag`` (None when it is
    self-closing or not found). Comments and CDATA are skipped (``str.find``: an unterminated
    comment repeated is looked at once, issue 21)."""
    if text[tag[1] - 2] == "/":
        return None
    depth = 1
    position = tag[1]
    size = len(name)
    unclosed: set[str] = set()  # a closer not found once is not found later either
    while True:
        start = text.find("<", position)
        if start < 0:
            return None
        position = start + 1
        for opener, closer in (("<!--", "-->"), ("<![CDATA[", "]]>")):
            if closer not in unclosed and text.startswith(opener, start):
                end = text.find(closer, start + len(opener))
                if end < 0:
                    unclosed.add(closer)
                    continue
                position = end + len(closer)
                break
        else:
            closing = text.startswith("/", start + 1)
            at = start + 1 + closing
            if not text.startswith(name, at) or at + size >= len(text) \
                    or text[at + size] not in _AFTER_NAME:
                continue
            if closing:
                depth -= 1
                if depth == 0:
                    return start + 2, at + size
            else:
                end = tag_end(text, start)
                if end is not None and text[end - 2] != "/":
                    depth += 1


def _written(texts: dict[str, str], loc, names: tuple[str, ...], attr: str):
    """(text, line starts, start tag span, attribute span or None when not written) of
    attribute ``attr`` of the element written at ``loc`` (its tag one of ``names``, any when
    empty); None when the text or the tag is not found."""
    text = texts.get(loc.path) if loc is not None and loc.line else None
    if text is None:
        return None
    starts = line_starts(text)
    tag = tag_at(text, starts, loc.line, loc.column, names)
    return None if tag is None else (text, starts, tag, attribute(text, tag, attr))


def attribute_loc(texts: dict[str, str], loc, names: tuple[str, ...], attr: str):
    """``loc`` (a model ``Loc`` of an element whose tag is one of ``names``, any when empty)
    moved to where attribute ``attr`` is written in its start tag, on whichever line of the
    tag that is; ``loc`` itself when the tag or the attribute is not found."""
    found = _written(texts, loc, names, attr)
    if found is None or found[3] is None:
        return loc
    _, starts, _, span = found
    from bisect import bisect_right

    line = bisect_right(starts, span[0])
    return loc._replace(line=line, column=span[0] - starts[line - 1] + 1)


# -- values: written where the text was written ------------------------------------------------

_CALL = r"<xacro:([^\s/>]+)"


def value_edit(texts: dict[str, str], loc, names: tuple[str, ...], attr: str,
               new_value: str) -> Edit | ByHand | None:
    """The edit setting attribute ``attr`` of the element written at ``loc`` (a model ``Loc``;
    its start tag is named one of ``names``) to ``new_value``, in the file where the value was
    written: the element's own text when the value is a literal (inside a macro body: the
    body, once for every instance), the macro call site when the value is a macro parameter
    given there as a literal. A value computed by an expression gets ``ByHand`` (why), a tag
    that cannot be found None."""
    found = _written(texts, loc, names, attr)
    if found is None:
        return None
    text, starts, tag, span = found
    if span is None:  # not written: add it before the end of the start tag
        close = tag[1] - (2 if text[tag[1] - 2] == "/" else 1)
        while close > tag[0] and text[close - 1] in " \t":
            close -= 1
        return edit(loc.path, text, close, close, f' {attr}="{new_value}"', starts)
    value = text[span[2]:span[3]]
    if "${" not in value and "$(" not in value:
        return edit(loc.path, text, span[2], span[3], new_value, starts)
    parameter = re.fullmatch(r"\$\{\s*([^\W\d]\w*)\s*\}", value.strip())
    if parameter and loc.via:
        call_path, _, call_line = loc.via[0].rpartition(":")
        call_text = texts.get(call_path)
        if call_text is not None and call_line.isdigit():
            call_starts = line_starts(call_text)
            call = tag_at(call_text, call_starts, int(call_line), None)
            if call is not None and tag_name(call_text, call[0]).startswith("xacro:"):
                given = attribute(call_text, call, parameter.group(1))
                if given is not None:
                    argument = call_text[given[2]:given[3]]
                    if "${" not in argument and "$(" not in argument:
                        return edit(call_path, call_text, given[2], given[3], new_value,
                                    call_starts)
                    value = argument
    return ByHand(f"fix by hand: {attr}= is computed from `{value.strip()}`"
                  f" (to become {new_value})")


def tail_edit(texts: dict[str, str], loc, names: tuple[str, ...], attr: str, old: str,
              new: str) -> Edit | None:
    """The edit replacing ``old`` by ``new`` at the end of attribute ``attr`` of the element
    written at ``loc``, when the value as written ends with ``old`` literally (a file name after
    ``$(find pkg)/`` or ``package://pkg/``); None otherwise (computed there, or not found)."""
    found = _written(texts, loc, names, attr)
    if found is None or found[3] is None:
        return None
    text, starts, _, span = found
    value = text[span[2]:span[3]]
    kept = value[:len(value) - len(old)]
    if not value.endswith(old) or "}" in value[len(kept):] or kept.count("${") > kept.count("}"):
        return None
    return edit(loc.path, text, span[3] - len(old), span[3], new, starts)


def head_edit(texts: dict[str, str], loc, names: tuple[str, ...], attr: str, old: str,
              new: str) -> Edit | None:
    """The edit replacing ``old`` by ``new`` at the start of attribute ``attr`` of the element
    written at ``loc``, when the value as written starts with ``old`` literally (the package of
    a ``package://NAME/...`` URI); None otherwise."""
    found = _written(texts, loc, names, attr)
    if found is None or found[3] is None:
        return None
    text, starts, _, span = found
    if not text[span[2]:span[3]].startswith(old) or "$" in old:
        return None
    return edit(loc.path, text, span[2], span[2] + len(old), new, starts)


def text_edit(texts: dict[str, str], loc, names: tuple[str, ...], new: str) -> Edit | None:
    """The edit making ``new`` the text of the element written at ``loc`` (``<tag>text</tag>``,
    blanks around it kept); None when its text is computed (``${...}``) or not found."""
    text = texts.get(loc.path) if loc is not None else None
    if text is None:
        return None
    starts = line_starts(text)
    tag = tag_at(text, starts, loc.line, loc.column, names)
    if tag is None or text[tag[1] - 2] == "/":
        return None
    end = text.find("<", tag[1])
    content = text[tag[1]:end] if end >= 0 else ""
    value = content.strip()
    if not value or "${" in value or "$(" in value:
        return None
    start = tag[1] + content.index(value)
    return edit(loc.path, text, start, start + len(value), new, starts)


def rename_element(texts: dict[str, str], loc, old: str, new: str) -> tuple[Edit, ...]:
    """Edits renaming the element written at ``loc`` from ``old`` to ``new`` (start and end
    tag); () when it cannot be found."""
    text = texts.get(loc.path) if loc is not None else None
    if text is None:
        return ()
    starts = line_starts(text)
    tag = tag_at(text, starts, loc.line, loc.column, (old,))
    if tag is None or tag_name(text, tag[0]) != old:
        return ()
    edits = [edit(loc.path, text, tag[0] + 1, tag[0] + 1 + len(old), new, starts)]
    closing = end_tag(text, tag, old)
    if closing is not None:
        edits.append(edit(loc.path, text, closing[0], closing[1], new, starts))
    return tuple(edits)


def rename_attribute(texts: dict[str, str], loc, names: tuple[str, ...], old: str,
                     new: str) -> tuple[Edit, ...]:
    text = texts.get(loc.path) if loc is not None else None
    if text is None:
        return ()
    starts = line_starts(text)
    tag = tag_at(text, starts, loc.line, loc.column, names)
    span = attribute(text, tag, old) if tag is not None else None
    if span is None:
        return ()
    return (edit(loc.path, text, span[0], span[1], new, starts),)


def declare_namespace(texts: dict[str, str], path: str, prefix: str, uri: str) -> tuple[Edit, ...]:
    """An edit declaring ``xmlns:prefix`` on the root element of ``path`` when it does not."""
    text = texts.get(path)
    if text is None or f"xmlns:{prefix}" in text:
        return ()
    root = re.search(r"<(?![?!])" + _NAME, text)
    if root is None:
        return ()
    return (edit(path, text, root.end(), root.end(), f' xmlns:{prefix}="{uri}"'),)


def number(value: float) -> str:
    """A float as written in a fixed file: the shortest text that reads back the same."""
    text = repr(float(value))
    text = text.removesuffix(".0")
    return "0" if text == "-0" else text
