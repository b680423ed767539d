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
from urdftool.roots import has_vcs_component, is_file
from urdftool.uris import parse_uri

_NAME_RE = re.compile(r"<name>\s*([^<\s]+)\s*</name>")




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


def _package_name(package_xml: Path, root: Path | str | None = None) -> str | None:
    """The ``<name>`` of a ``package.xml``. With ``root`` (the repository or the operator's
    directory being crawled), a ``package.xml`` that is a link resolving outside it (or into
    version-control metadata) is not read: a committed link names no file of the machine."""
    if root is not None and os.path.islink(package_xml):
        top = Path(os.path.realpath(root))
        target = Path(os.path.realpath(package_xml))
        if not target.is_relative_to(top) or has_vcs_component(target, top):
            return None
    try:
        match = _NAME_RE.search(read_regular_text(package_xml, 1 << 20))
    except OSError:
        return None
    return match.group(1) if match else None


# a directory holding one of these is not crawled (catkin, colcon, ament; rospack's own)
IGNORE_MARKERS = ("CATKIN_IGNORE", "COLCON_IGNORE", "AMENT_IGNORE", "rospack_nosubdirs")
MAX_CRAWL_DIRECTORIES = 20000  # a crawl's bound: a description repository has far fewer
_CRAWLS: dict[str, dict[str, Path]] = {}  # crawl(root), per process


def crawl(root: Path | str) -> dict[str, Path]:
    """The packages below ``root`` as rospack and colcon find them: each directory is descended
    until it holds a ``package.xml`` (a package: its ``<name>``, not descended further);
    directories whose name starts with a dot, and those holding ``CATKIN_IGNORE``,
    ``COLCON_IGNORE``, ``AMENT_IGNORE`` or ``rospack_nosubdirs`` are not. The first of a name
    (in sorted order, breadth first) is kept. Memoised per process."""
    key = os.fspath(root)
    found = _CRAWLS.get(key)
    if found is not None:
        return found
    found = {}
    pending = [Path(root)]
    visited = 0
    while pending and visited < MAX_CRAWL_DIRECTORIES:
        directory = pending.pop(0)
        visited += 1
        try:
            with os.scandir(directory) as entries:
                names = {e.name: e for e in entries}
        except OSError:
            continue
        if "package.xml" in names:
            name = _package_name(directory / "package.xml", root)
            if name:
                found.setdefault(name, directory)
            continue
        if any(marker in names for marker in IGNORE_MARKERS):
            continue
        for name in sorted(names):
            entry = names[name]
            if name.startswith("."):
                continue
            try:
                if entry.is_dir(follow_symlinks=False):
                    pending.append(directory / name)
            except OSError:
                continue
    _CRAWLS[key] = found
    return found


def ament_packages(prefix: Path | str) -> dict[str, Path]:
    """The packages of one ``AMENT_PREFIX_PATH`` entry: those the ament index lists
    (``share/ament_index/resource_index/packages/NAME``) at ``share/NAME``, and any
    ``share/NAME/package.xml``."""
    key = "ament:" + os.fspath(prefix)
    found = _CRAWLS.get(key)
    if found is not None:
        return found
    found = {}
    share = Path(prefix) / "share"
    index = share / "ament_index" / "resource_index" / "packages"
    try:
        markers = sorted(os.listdir(index))
    except OSError:
        markers = []
    for name in markers:
        if not name.startswith("."):
            found.setdefault(name, share / name)
    try:
        shared = sorted(os.listdir(share))
    except OSError:
        shared = []
    for name in shared:
        if name not in found and is_file(share / name / "package.xml"):
            found.setdefault(_package_name(share / name / "package.xml", prefix) or name,
                             share / name)
    _CRAWLS[key] = found
    return found


def _start_directory(start: str) -> Path:
    """The resolved directory of a resolver's start (absolute; a file: its folder), memoised
    per process like the rest of this module's answers (every file of a run has a resolver)."""
    found = _STARTS.get(start)
    if found is None:
        directory = Path(resolved(start))
        found = _STARTS[start] = directory if directory.is_dir() else directory.parent
    return found


_STARTS: dict[str, Path] = {}


def forget() -> None:
    """Drop what was found about packages (discovery, crawls, directory and URI lookups):
    a run starts (``loader.run_roots``), and a ``package.xml`` added or removed since (the
    language server runs for hours) is seen (issue 29)."""
    for memo in (_REALPATHS, _DISCOVERED, _DIRECTORIES, _URIS, _CRAWLS, _STARTS):
        memo.clear()


class PackageResolver:
    """Finds package directories by name for one input file.

    Where a package is looked for, in order (``tried`` names them for a finding): the
    operator's ``-P NAME=DIR``; the package the file is in and every package of its repository
    (crawled as rospack does); ``ROS_PACKAGE_PATH`` (crawled); ``AMENT_PREFIX_PATH`` (the ament
    index and ``share/NAME``). ``roots`` (``urdftool.roots.Roots``, set by the loader) bound
    what may be read: a package or file outside them is not taken. ``model_paths`` (the
    operator's ``--model-path`` and model path variables) resolve ``model://`` URIs."""

    def __init__(self, explicit: dict[str, str] | None = None, start: Path | None = None,
                 environ: dict[str, str] | None = None, roots=None,
                 model_paths: tuple = ()):
        self.explicit = {k: Path(v).resolve() for k, v in (explicit or {}).items()}
        self.start = start
        self.environ = os.environ if environ is None else environ
        self.roots = roots  # urdftool.roots.Roots, or None: not bounded (library use)
        self.model_paths = tuple(Path(p) for p in model_paths)
        self._found: dict[str, Path] | None = None
        self._context: tuple | None = None  # what resolve_uri depends on besides its arguments

    @property
    def confined_roots(self) -> list[Path] | None:
        """The roots as a list (None when not bounded)."""
        return None if self.roots is None else self.roots.all()

    def allows(self, path: Path, also: tuple[Path, ...] = ()) -> bool:
        """Whether the input may read ``path``: inside the run's roots (``also``: kept for
        callers that name the operator's model paths, which the roots already hold)."""
        if self.roots is None:
            return True
        return self.roots.readable(path)

    def _discovery_key(self) -> tuple:
        """What ``_discover`` depends on: the start directory, the roots and the environment."""
        directory = None
        if self.start is not None:
            directory = _start_directory(os.path.abspath(self.start))
        return (directory, self.roots, self.environ.get("ROS_PACKAGE_PATH", ""),
                self.environ.get("AMENT_PREFIX_PATH", ""))

    def _discover(self) -> dict[str, Path]:
        # the same for every file of a directory: memoised per process (the file system does
        # not change during a run)
        key = self._discovery_key()
        found = _DISCOVERED.get(key)
        if found is None:
            found = _DISCOVERED[key] = self._walk(key[0])
        return dict(found)

    def _repository_of(self, directory: Path) -> Path | None:
        if self.roots is None:
            return None
        return next((root for root in self.roots.repositories
                     if directory.is_relative_to(root)), None)

    def _walk(self, directory: Path | None) -> dict[str, Path]:
        found: dict[str, Path] = {}
        if directory is not None:
            repository = self._repository_of(directory)
            for parent in (directory, *directory.parents):
                if repository is not None and not parent.is_relative_to(repository):
                    break
                if is_file(parent / "package.xml"):
                    own = _package_name(parent / "package.xml", repository)
                    if own:
                        found.setdefault(own, parent)
                    if repository is None:  # not bounded: its siblings (library use)
                        try:
                            siblings = sorted(parent.parent.iterdir())
                        except OSError:
                            siblings = []
                        for sibling in siblings[:500]:
                            name = (_package_name(sibling / "package.xml")
                                    if is_file(sibling / "package.xml") else None)
                            if name:
                                found.setdefault(name, sibling)
                    break
            if repository is not None:
                for name, package in crawl(repository).items():
                    found.setdefault(name, package)
        for entry in self.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
            if entry:
                for name, package in crawl(entry).items():
                    found.setdefault(name, package)
        for prefix in self.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep):
            if prefix:
                for name, package in ament_packages(prefix).items():
                    found.setdefault(name, package)
        if self.roots is not None:  # a package.xml inside the repository that links out
            found = {name: package for name, package in found.items()
                     if self.roots.readable(package)}
        return found

    def find(self, name: str) -> Path | None:
        """The directory of package ``name``, or None."""
        if name in self.explicit:
            return self.explicit[name]
        if self._found is None:
            self._found = self._discover()
        return self._found.get(name)

    def known(self) -> list[str]:
        """The names of the packages ``find`` knows, and ``urdftool`` (``by_directory``'s
        example meshes): for a did-you-mean."""
        if self._found is None:
            self._found = self._discover()
        return sorted({*self.explicit, *self._found, "urdftool"})

    def tried(self) -> str:
        """Where ``find`` looked, and what would widen it (for a finding's hint)."""
        places = ["-P NAME=DIR" + (f" ({', '.join(sorted(self.explicit))})"
                                   if self.explicit else " (none given)")]
        repository = (self._repository_of(Path(resolved(self.start)).parent)
                      if self.start is not None else None)
        places.append("the packages of the repository" if repository is not None
                      else "the file's package and its siblings")
        for variable in ("ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH"):
            places.append(variable + ("" if self.environ.get(variable) else " (not set)"))
        return ", ".join(places)

    def by_directory(self, name: str, start: Path) -> Path | None:
        """Package ``name`` as a directory NAME above ``start`` or beside one of its ancestors
        (how pinocchio's package_dirs and ROS_PACKAGE_PATH trees are laid out, e.g.
        example-robot-data, whose package.xml names it differently), looked for inside the
        run's roots only; ``urdftool`` is urdftool's own example meshes (used in the rule
        docs)."""
        if not name or name in (".", ".."):
            return None
        if name == "urdftool":
            return Path(__file__).resolve().parent
        key = (name, os.fspath(start), self.roots)
        if key not in _DIRECTORIES:  # memoised per process, like _discover
            directory, found = start.resolve(), None
            for ancestor in (directory, *directory.parents):
                if not self.allows(ancestor):  # only inside the roots: what is beside a
                    break  # directory of the machine is never asked (an existence oracle)
                candidate = ancestor if ancestor.name == name else ancestor / name
                if candidate == ancestor or (self.allows(candidate) and candidate.is_dir()):
                    found = candidate
                    break
            _DIRECTORIES[key] = found
        return _DIRECTORIES[key]

    def roots_known(self) -> list[Path]:
        """Every package directory known."""
        if self._found is None:
            self._found = self._discover()
        return list(self.explicit.values()) + list(self._found.values())

    def resolve_uri(self, uri: str, base_dir: Path) -> Path | None:
        """Resolve a mesh or resource URI to a local path; None when it cannot be resolved.
        Relative paths and unknown packages are looked for from ``base_dir``, the directory of
        the file that names them. A path outside the roots resolves to a path under
        ``REFUSED`` (which does not exist) made of the path as written, never where links
        lead: the mesh rules report it missing, the same whether or not a file is there.
        Memoised per process, for every resolver with the same packages, roots and start
        directory (a robot, and the robots of a directory, name the same few directories
        hundreds of times)."""
        if self._context is None:
            self._context = (tuple(sorted((k, os.fspath(v)) for k, v in self.explicit.items())),
                             self._discovery_key(), self.model_paths)
        key = (self._context, uri, os.fspath(base_dir))
        found = _URIS.get(key, _UNKNOWN)
        if found is _UNKNOWN:
            found = self._resolve_uri(uri, base_dir)
            if found is not None and not self.allows(found):
                written = os.path.normpath(os.path.abspath(os.fspath(found)))
                found = REFUSED / written.lstrip(os.sep)
            _URIS[key] = found
        return found

    def _resolve_uri(self, uri: str, base_dir: Path) -> Path | None:
        parsed = parse_uri(uri)
        if parsed.scheme == "package":
            # package:///NAME/... (three slashes) is seen in the wild and read by ROS tools
            package = self.find(parsed.name) or self.by_directory(parsed.name, base_dir)
            return package / parsed.rest if package is not None else None
        if parsed.scheme == "model":  # a mesh of an included SDF model: the model paths
            candidates = [directory / parsed.named for directory in self.model_paths]
            for candidate in candidates:
                if self.allows(candidate) and is_file(candidate):
                    return candidate
            return None
        if parsed.scheme == "file":
            return Path(parsed.rest)
        if parsed.scheme != "path":
            return None
        path = Path(uri)
        return path if path.is_absolute() else base_dir / path


# where a refused path points (it does not exist): see PackageResolver.resolve_uri
REFUSED = Path("/urdftool-untrusted-outside-the-package-roots")
