"""Where something was written (``Loc``) and what a rule or reader found there (``Finding``).
Base layer: imports nothing else of urdftool; every layer above uses these records.
``urdftool.model`` and ``urdftool.report`` re-export them."""

from typing import NamedTuple

SEVERITIES = ("error", "warning", "info")

class Loc(NamedTuple):
    """Where something was written: the user's file and 1-based line/column.

    ``via`` lists the macro call sites ("file:line") that produced the element, innermost first.
    """

    path: str
    line: int | None = None
    column: int | None = None
    element: str | None = None
    via: tuple[str, ...] = ()


class Finding(NamedTuple):
    """What a rule found: a message at a place, with an optional fix hint.

    ``severity`` overrides the rule's default when a rule grades its own findings
    (e.g. 2x over a bound is an error, 1x-2x a warning). ``edits`` fix it
    (``urdftool.edits.Edit``, in the files the user wrote; the rule's registration says how
    safe they are).
    """

    message: str
    loc: Loc | None
    hint: str | None = None
    severity: str | None = None
    edits: tuple = ()


def enclosing(index: dict, element: str | None):
    """The value ``index`` (element path -> value) holds for ``element`` or for the nearest
    element path that contains it (``/robot/joint[3]`` for ``/robot/joint[3]/limit``), or None:
    one lookup per level of ``element``, never a walk over the index (issue 28)."""
    while element:
        found = index.get(element)
        if found is not None:
            return found
        if "/" not in element:
            return None
        element = element.rsplit("/", 1)[0]
    return None
