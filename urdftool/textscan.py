"""Linear scans of file text (issue 21): what a regular expression over a whole file did with a
lazy ``.*?`` or ``[^>]*`` (one pass from every start: an unterminated ``<!--`` repeated, a
BOM and ``<?xml `` repeated, took minutes on a few hundred KB), done with ``str.find`` loops
that look at every character a bounded number of times.

Every regular expression left in urdftool is run against adversarial inputs by
``tests/test_regex_linear.py``. This module imports nothing else of urdftool.
"""

from __future__ import annotations

import re

_OPENERS = (("<!--", "-->"), ("<![CDATA[", "]]>"))


def without_comments(text: str, keep_unclosed: bool = True) -> str:
    """``text`` without its ``<!-- ... -->`` comments (an unterminated one is left, as
    ``re.sub(r"(?s)<!--.*?-->", "", text)`` left it; with ``keep_unclosed=False`` it runs to the
    end, as an XML parser reads it)."""
    if "<!--" not in text:
        return text
    pieces = []
    position = 0
    while True:
        start = text.find("<!--", position)
        if start < 0:
            pieces.append(text[position:])
            break
        pieces.append(text[position:start])
        end = text.find("-->", start + 4)
        if end < 0:
            if keep_unclosed:
                pieces.append(text[start:])
            break
        position = end + 3
    return "".join(pieces)


def markup_split(document: str) -> list[str]:
    """``document`` as [text, comment-or-CDATA, text, ...] (what ``re.split`` with the
    capturing pattern ``(<!--.*?-->|<![CDATA[.*?]]>)`` gave): even indices are text and
    markup, odd ones whole comments and CDATA sections; an unterminated one stays text."""
    pieces = []
    position = done = 0
    unclosed: set[str] = set()  # a closer not found once is not found later either
    while True:
        start = document.find("<!", position)
        if start < 0:
            break
        position = start + 2
        for opener, closer in _OPENERS:
            if closer in unclosed or not document.startswith(opener, start):
                continue
            end = document.find(closer, start + len(opener))
            if end < 0:
                unclosed.add(closer)
                break
            end += len(closer)
            pieces += [document[done:start], document[start:end]]
            position = done = end
            break
    pieces.append(document[done:])
    return pieces


_DECLARED = re.compile(r"(<\?xml[^<>]*?encoding\s*=\s*)([\"'])[^\"'<>]*\2")


_DECLARED_BYTES = re.compile(rb"<\?xml[^<>]*?encoding\s*=\s*[\"']([A-Za-z][\w.:-]{0,40})[\"']")


def declared_encoding(data: bytes) -> str | None:
    """The Python codec of the encoding ``data``'s XML declaration names (ASCII-compatible
    bytes, before any BOM handling), or None: no declaration, a Unicode encoding (UTF-8's is
    the default; UTF-16/32 have a BOM), or a name Python does not know."""
    import codecs

    head = data[:1024]
    match = _DECLARED_BYTES.match(head, len(head) - len(head.lstrip()))
    if match is None:
        return None
    try:
        name = codecs.lookup(match.group(1).decode("ascii")).name
    except LookupError:
        return None
    return None if name.startswith(("utf-8", "utf-16", "utf-32", "utf_")) else name


def declared_utf8(text: str) -> str:
    """``text`` with the encoding its first XML declaration names made UTF-8 (the text is
    decoded already). Only the first ``<?xml`` is looked at, up to its ``>``."""
    start = text.find("<?xml")
    if start < 0:
        return text
    end = text.find(">", start)
    end = len(text) if end < 0 else end + 1
    match = _DECLARED.match(text, start, end)
    if match is None:
        return text
    return f"{text[:start]}{match.group(1)}{match.group(2)}UTF-8{match.group(2)}" \
           f"{text[match.end():]}"


def tag_closes(text: str, position: int) -> bool:
    """Whether a ``>`` comes at or after ``position`` before any ``<`` (the rest of a start
    tag): looks no further than the next ``<``."""
    bound = text.find("<", position)
    return text.find(">", position, len(text) if bound < 0 else bound) >= 0
