"""Resource names as robot files write them, parsed in one place (base layer, issue 33):
``package://NAME/rest``, ``model://NAME/rest``, ``file://path``, another scheme
(``http://...``) or a plain path; and ``$(find NAME)`` in a xacro file name. What the parts
resolve to is the readers' business (``urdftool.packages``, ``urdftool.sdf.reader``); every
reader, rule and command takes the parts from here."""

from __future__ import annotations

import re
from typing import NamedTuple

# ``$(find NAME)`` in a xacro file name: the package NAME (no blank, no ``)``, no ``$``)
FIND = re.compile(r"\$\(find\s+([^)\s$]+)\)")


class Uri(NamedTuple):
    """A parsed resource name. ``scheme``: ``package``, ``model``, ``file``, ``path`` (no
    scheme) or another one as written (``http``); ``name``: the package or model (``package``
    and ``model`` only); ``rest``: what follows the name (or the path of ``file``/``path``, what
    follows ``://`` for another scheme); ``empty_name``: ``package:///...`` (three slashes: an
    empty package name that ROS's resource retriever rejects; ``name`` is then the first part
    of the path, as pinocchio and PyBullet read it)."""

    scheme: str
    name: str
    rest: str
    written: str
    empty_name: bool = False

    @property
    def named(self) -> str:
        """``NAME/rest`` of a package or model URI (``rest`` alone when there is no name)."""
        return f"{self.name}/{self.rest}" if self.name else self.rest


def parse_uri(text: str) -> Uri:
    """``text`` (a mesh filename, an SDF ``<uri>``) as its parts."""
    scheme, sep, after = text.partition("://")
    if not sep or not scheme or "/" in scheme:
        return Uri("path", "", text, text)
    if scheme in ("package", "model"):
        empty = after.startswith("/")
        name, _, rest = after.lstrip("/").partition("/")
        return Uri(scheme, name, rest, text, empty)
    return Uri(scheme, "", after, text)


def find_parts(spec: str) -> tuple[str, str] | None:
    """``(NAME, rest)`` of a xacro file name that starts with ``$(find NAME)`` (``rest``
    without its leading ``/``); None otherwise."""
    found = FIND.match(spec)
    if found is None:
        return None
    return found.group(1), spec[found.end():].lstrip("/")
