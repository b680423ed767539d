"""`urdftool check --fix -o OUT FILE`: write FILE with its XML-level breakages repaired.

Only what ``urdftool.xmlrepair`` recognises is changed (unclosed and mismatched tags, tags that
lost a bracket, bad attributes and entities...); every line stays where it was, so the output
can be diffed against the input line by line. Never written over the input.
"""

from __future__ import annotations

import re
from pathlib import Path

from urdftool.output import write_output
from urdftool.source import read_text
from urdftool.xmlrepair import repair

_ENCODING_DECL_RE = re.compile(r"(<\?xml[^>]*?encoding\s*=\s*)([\"'])[^\"']*\2")


def fixed_text(path: str | Path) -> str:
    """The repaired text of ``path`` (raises ToolError when it cannot be read)."""
    text = read_text(Path(path))
    fixed, _ = repair(text, str(path))
    # written as UTF-8 whatever it was read as: make the declaration say so
    return _ENCODING_DECL_RE.sub(r"\1\2UTF-8\2", fixed, count=1)


def write_fixed(path: str | Path, output: str) -> None:
    """Write the repaired text of ``path`` to ``output`` (refuses to overwrite ``path``)."""
    write_output(fixed_text(path), output, inputs=[str(path)])
