"""Find every malformed tag in a file, repair what is recognised in memory, and say so.

``repair(text, path)`` returns the repaired text and the problems found (rule id + Finding), so
that the rest of the file stays checkable. What cannot be repaired is reported with the parser's
own message and left to lxml's recovery.
"""

from __future__ import annotations

import re

from lxml import etree

from urdftool.model import Loc
from urdftool.report import Finding

_DECL_RE = re.compile(r"^\s*<\?xml\s+version\s*=\s*([\"'])([^\"']*)\1")


def secure_parser(recover: bool = False) -> etree.XMLParser:
    """The only XML parser urdftool uses: no entities, no network, no DTD, no huge trees."""
    return etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False,
                           huge_tree=False, remove_blank_text=False, recover=recover)


def _fix_declaration(text: str, path: str, problems: list) -> str:
    match = _DECL_RE.match(text)
    if match and match.group(2) != "1.0":
        line = text.count("\n", 0, match.start(2)) + 1
        problems.append(("xml.declaration", Finding(
            f"XML declaration says version \"{match.group(2)}\"; only 1.0 is valid",
            Loc(path, line, None), hint='write <?xml version="1.0"?>')))
        text = text[:match.start(2)] + "1.0" + text[match.end(2):]
    return text


def repair(text: str, path: str) -> tuple[str, list[tuple[str, Finding]]]:
    """Repair recognised breakages; report each one, plus whatever the parser still rejects."""
    problems: list[tuple[str, Finding]] = []
    text = _fix_declaration(text, path, problems)
    try:
        etree.fromstring(text.encode("utf-8"), secure_parser())
    except etree.XMLSyntaxError as exc:
        line, column = exc.position if exc.position else (None, None)
        problems.append(("xml.syntax", Finding(exc.msg, Loc(path, line, column))))
    return text, problems
