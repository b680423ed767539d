"""Package resolution: ``package://NAME/...`` and ``$(find NAME)``.

Packages come from, in order: ``-P NAME=DIR`` options, the nearest ``package.xml`` above the
file (and its sibling packages), ``ROS_PACKAGE_PATH`` and ``AMENT_PREFIX_PATH``; a
``package://NAME/...`` URI none of them knows is then looked for as a directory NAME above the
referring file or beside one of its ancestors.
"""

from __future__ import annotations

import os
import re
import stat
from pathlib import Path

from urdftool.files import read_regular_text

_NAME_RE = re.compile(r"<name>\s*([^<\s]+)\s*</name>")


def is_file(path: Path) -> bool:
    """``path.is_file()`` that is False, not an OSError, for a name the system refuses (longer
    than NAME_MAX, say): inputs name files, and a name is not a reason to crash."""
    try:
        return path.is_file()
    except OSError:
        return False


_REALPATHS: dict[str, str] = {}
_DISCOVERED: dict[tuple, dict[str, Path]] = {}  # PackageResolver._discover, per process
_DIRECTORIES: dict[tuple[str, str], Path | None] = {}  # PackageResolver.by_directory
_URIS: dict[tuple, Path | None] = {}  # PackageResolver.resolve_uri, per process
_UNKNOWN = object()


def resolved(path: Path | str) -> str:
    """``str(Path(path).resolve())``, memoised by the name as given: the file system does not
    change during a run, and resolving walks every component (an lstat each)."""
    key = os.fspath(path)
    if not os.path.isabs(key):  # a relative name means another file after a chdir
        key = os.path.join(os.getcwd(), key)
    found = _REALPATHS.get(key)
    if found is None:
        found = _REALPATHS[key] = _resolve(key)
    return found


def _resolve(key: str) -> str:
    """``str(Path(key).resolve())``: a plain last component that is not a symbolic link is
    appended to its directory's (memoised) resolution, as ``realpath`` does component by
    component; anything else is left to ``Path.resolve``."""
    text = str(Path(key))
    head, name = os.path.split(text)
    if head and head != text and name not in ("", ".", ".."):
        try:
            link = stat.S_ISLNK(os.lstat(text).st_mode)
        except OSError:  # missing (or unreadable): realpath keeps the name as it is
            link = False
        if not link:
            return os.path.join(resolved(head), name)
    return str(Path(key).resolve())


def _package_name(package_xml: Path) -> str | None:
    try:
        match = _NAME_RE.search(read_regular_text(package_xml, 1 << 20))
    except OSError:
        return None
    return match.group(1) if match else None


class PackageResolver:
    """Finds package directories by name for one input file."""

    def __init__(self, explicit: dict[str, str] | None = None, start: Path | None = None,
                 environ: dict[str, str] | None = None):
        self.explicit = {k: Path(v).resolve() for k, v in (explicit or {}).items()}
        self.start = start
        self.environ = os.environ if environ is None else environ
        self._found: dict[str, Path] | None = None
        self._context: tuple | None = None  # what resolve_uri depends on besides its arguments
        self.confined_roots: list[Path] | None = None  # --untrusted: set by sandbox.confine

    def allows(self, path: Path, also: tuple[Path, ...] = ()) -> bool:
        """Whether the input may read ``path``: anywhere, unless confined (``--untrusted``) to
        the package roots and the directories ``also`` the user named."""
        if self.confined_roots is None:
            return True
        from urdftool.sandbox import inside

        return inside(path, [*self.confined_roots, *(Path(p).resolve() for p in also)])

    def _discovery_key(self) -> tuple:
        """What ``_discover`` depends on: the start directory and the environment."""
        directory = None
        if self.start is not None:
            directory = Path(resolved(self.start))
            directory = directory if directory.is_dir() else directory.parent
        return (directory, self.environ.get("ROS_PACKAGE_PATH", ""),
                self.environ.get("AMENT_PREFIX_PATH", ""))

    def _discover(self) -> dict[str, Path]:
        # the same for every file of a directory: memoised per process (the file system does
        # not change during a run)
        key = self._discovery_key()
        found = _DISCOVERED.get(key)
        if found is None:
            found = _DISCOVERED[key] = self._walk(key[0])
        return dict(found)

    def _walk(self, directory: Path | None) -> dict[str, Path]:
        found: dict[str, Path] = {}
        if directory is not None:
            for parent in (directory, *directory.parents):
                if (parent / "package.xml").is_file():
                    own = _package_name(parent / "package.xml")
                    if own:
                        found.setdefault(own, parent)
                    try:
                        siblings = sorted(parent.parent.iterdir())
                    except OSError:
                        siblings = []
                    for sibling in siblings[:500]:
                        name = _package_name(sibling / "package.xml") if sibling.is_dir() else None
                        if name:
                            found.setdefault(name, sibling)
                    break
        for entry in self.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
            if entry and Path(entry).is_dir():
                base = Path(entry)
                if (base / "package.xml").is_file():
                    name = _package_name(base / "package.xml")
                    if name:
                        found.setdefault(name, base)
                for xml in sorted(base.glob("*/package.xml")) + sorted(base.glob("*/*/package.xml")):
                    name = _package_name(xml)
                    if name:
                        found.setdefault(name, xml.parent)
        for prefix in self.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep):
            if prefix:
                index = Path(prefix) / "share" / "ament_index" / "resource_index" / "packages"
                if index.is_dir():
                    for marker in index.iterdir():
                        found.setdefault(marker.name, Path(prefix) / "share" / marker.name)
        return found

    def find(self, name: str) -> Path | None:
        """The directory of package ``name``, or None."""
        if name in self.explicit:
            return self.explicit[name]
        if self._found is None:
            self._found = self._discover()
        return self._found.get(name)

    def by_directory(self, name: str, start: Path) -> Path | None:
        """Package ``name`` as a directory NAME above ``start`` or beside one of its ancestors
        (how pinocchio's package_dirs and ROS_PACKAGE_PATH trees are laid out, e.g.
        example-robot-data, whose package.xml names it differently); ``urdftool`` is
        urdftool's own example meshes (used in the rule docs)."""
        if not name:
            return None
        if name == "urdftool":
            return Path(__file__).resolve().parent
        key = (name, os.fspath(start))
        if key not in _DIRECTORIES:  # memoised per process, like _discover
            directory = start.resolve()
            _DIRECTORIES[key] = next(
                (ancestor if ancestor.name == name else ancestor / name
                 for ancestor in (directory, *directory.parents)
                 if ancestor.name == name or (ancestor / name).is_dir()), None)
        return _DIRECTORIES[key]

    def roots(self) -> list[Path]:
        """Every package directory known (the places an input may legitimately read from)."""
        if self._found is None:
            self._found = self._discover()
        return list(self.explicit.values()) + list(self._found.values())

    def resolve_uri(self, uri: str, base_dir: Path) -> Path | None:
        """Resolve a mesh or resource URI to a local path; None when it cannot be resolved.
        Relative paths and unknown packages are looked for from ``base_dir``, the directory of
        the file that names them. Memoised per process, for every resolver with the same
        packages and start directory (a robot, and the robots of a directory, name the same few
        directories hundreds of times); a confined resolver wraps this method, so its refusals
        apply to what comes from here."""
        if self._context is None:
            self._context = (tuple(sorted((k, os.fspath(v)) for k, v in self.explicit.items())),
                             self._discovery_key())
        key = (self._context, uri, os.fspath(base_dir))
        found = _URIS.get(key, _UNKNOWN)
        if found is _UNKNOWN:
            found = _URIS[key] = self._resolve_uri(uri, base_dir)
        return found

    def _resolve_uri(self, uri: str, base_dir: Path) -> Path | None:
        if uri.startswith("package://"):
            # package:///NAME/... (three slashes) is seen in the wild and read by ROS tools
            name, _, rest = uri[len("package://"):].lstrip("/").partition("/")
            package = self.find(name) or self.by_directory(name, base_dir)
            return package / rest if package is not None else None
        if uri.startswith("file://"):
            return Path(uri[len("file://"):])
        if "://" in uri:
            return None
        path = Path(uri)
        return path if path.is_absolute() else base_dir / path
