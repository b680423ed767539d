"""What a run may read: the roots (issue 20). Base layer: imports nothing else of urdftool.

Two sources only decide it. The *repository* of each checked path (the version-control root
above it: a ``.git``, ``.hg`` or ``.svn`` entry; without one, the directory given, or for a file
its package's parent directory or its own directory) is always readable, except its
version-control metadata. The *operator* widens it: ``-P NAME=DIR``, ``--model-path``, and the
package and model path variables of the environment (``PATH_VARIABLES``). Nothing a repository
file says widens it: a configuration value, an include, a mesh, a ``package.xml`` is resolved
(``realpath``) and must land inside. ``urdftool.loader.run_roots`` computes the ``Roots`` of a
run, once; the readers only ask ``Roots.readable``.
"""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

VCS_DIRS = (".git", ".hg", ".svn")
# where packages and models are: the operator's (environment) roots
PACKAGE_VARIABLES = ("ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH")
MODEL_VARIABLES = ("GZ_SIM_RESOURCE_PATH", "IGN_GAZEBO_RESOURCE_PATH", "GAZEBO_MODEL_PATH",
                   "SDF_PATH")
PATH_VARIABLES = (*PACKAGE_VARIABLES, *MODEL_VARIABLES)


class OutsideRepository(Exception):
    """A value a repository file gives names a place outside the repository (or its
    version-control metadata). The message names the key and the value as written, never
    where it resolves, and is the same whether or not anything is there."""

    def __init__(self, key: str, value: str):
        super().__init__(f"{key}: {value!r} is outside the repository (only the operator's "
                         "-P NAME=DIR, --model-path or package path variables reach outside it)")
        self.key = key
        self.value = value


_RESOLVED: dict[str, str] = {}  # absolute path as given -> its realpath, during one run
_READABLE: dict[tuple, bool] = {}  # (roots, path as given) -> Roots.readable, during one run
_REPOSITORIES: dict[str, Path | None] = {}  # absolute directory -> repository_of, during one run
_FILES: dict[str, bool] = {}  # absolute path as given -> is_file, during one run
_TRACKED: dict[tuple[str, str], bool] = {}  # (top, relative directory) -> tracked, one run


def forget_resolved() -> None:
    """Start a run: the realpaths memoised by ``resolved`` are forgotten (``loader.run_roots``
    calls it; links may change between runs of one process, as in the editor)."""
    _RESOLVED.clear()
    _READABLE.clear()
    _REPOSITORIES.clear()
    _FILES.clear()
    _TRACKED.clear()


def resolved(path) -> str:
    """``os.path.realpath`` of ``path``, memoised for the run when ``path`` is absolute (a
    check asks for the same files and directories thousands of times; the links on the way
    do not change during a run). OSError when a link on the way cannot be read (not kept)."""
    name = os.fspath(path)
    found = _RESOLVED.get(name)
    if found is None:
        if not os.path.isabs(name):
            return os.path.realpath(name)
        found = _RESOLVED[name] = _realpath(name)
    return found


def _realpath(name: str) -> str:
    """``os.path.realpath`` of absolute ``name``: a last component that is a plain name and not
    a symbolic link is appended to its directory's (memoised) realpath, as ``realpath`` does
    component by component (the files of one folder walk its parents once)."""
    head, tail = os.path.split(name)
    if head and head != name and tail not in ("", ".", ".."):
        joined = os.path.join(resolved(head), tail)
        try:
            link = stat.S_ISLNK(os.lstat(joined).st_mode)
        except OSError as exc:  # missing or unreachable: realpath keeps the name (a loop
            link = exc.errno == errno.ELOOP  # on the way: realpath's own answer)
        except ValueError:
            link = False
        if not link:
            return joined
    return os.path.realpath(name)


def is_file(path) -> bool:
    """Whether ``path`` is a regular file (links followed), memoised for the run when absolute;
    False, not an OSError, for a name the system refuses (longer than NAME_MAX, say)."""
    name = os.fspath(path)
    found = _FILES.get(name)
    if found is None:
        found = os.path.isfile(name)  # (False for a name the system refuses, not an error)
        if os.path.isabs(name):
            _FILES[name] = found
    return found


def real(path) -> str:
    """``resolved`` of ``path`` made absolute, as a string; the absolute path as written when a
    link on the way cannot be read (what is then asked of it fails as for a missing file).
    The memoised stand-in for ``str(Path(path).resolve())``, without its RuntimeError on a
    symbolic-link loop."""
    name = os.path.abspath(os.fspath(path))
    try:
        return resolved(name)
    except (OSError, ValueError):
        return name


def realpath(path) -> Path:
    """``os.path.realpath`` (``resolved``); OSError when a link on the way cannot be read
    (``/proc/1/root``)."""
    return Path(resolved(path))


def _root(path) -> Path:
    """A root as resolved as it can be: an operator's directory that cannot be resolved (a
    link the system refuses to read) is kept as written; nothing below it can be read."""
    try:
        return realpath(path)
    except (OSError, ValueError):
        return Path(os.path.abspath(os.fspath(path)))


def has_vcs_component(path: Path, root: Path) -> bool:
    """Whether ``path`` (resolved, below ``root``) is inside version-control metadata."""
    try:
        parts = path.relative_to(root).parts
    except ValueError:
        return False
    return any(part in VCS_DIRS for part in parts)


def repository_of(path) -> Path | None:
    """The version-control root above ``path`` (as given: a link's own place, not its
    target), resolved; None outside any. A directory that is a symbolic link is never a
    repository (a committed link to another checkout decides nothing). Each directory is looked
    at once a run (the files of a tree share their parents)."""
    start = os.path.abspath(os.fspath(path))
    walked = []
    directory, found = start, None
    while True:
        if directory in _REPOSITORIES:
            found = _REPOSITORIES[directory]
            break
        walked.append(directory)
        if not os.path.islink(directory) and any(
                os.path.lexists(os.path.join(directory, name)) for name in VCS_DIRS):
            found = _root(directory)
            break
        parent = os.path.dirname(directory)
        if parent == directory:
            break
        directory = parent
    for directory in walked:
        _REPOSITORIES[directory] = found
    return found


MAX_INDEX_BYTES = 1 << 30  # a git index larger than this: nothing below the top is known


def tracked(top: Path, directory: Path) -> bool:
    """Whether the repository at ``top`` holds files below ``directory`` (resolved, below
    ``top``): a subdirectory of a work tree, not a checkout without metadata of its own
    unpacked inside it (a tarball in a home directory under git, a copy in a monorepo). Git:
    an entry of its index names a file below it (index versions 2 and 3; version 4 and an
    index that cannot be read: not known, False; no index yet, a new repository: True).
    Mercurial and Subversion: True (their metadata is not read)."""
    try:
        relative = Path(directory).relative_to(top).as_posix()
    except ValueError:
        return False
    if relative == ".":
        return True
    git = Path(top) / ".git"
    if not os.path.lexists(git):
        return True
    key = (os.fspath(top), relative)
    found = _TRACKED.get(key)
    if found is None:
        found = _TRACKED[key] = _in_git_index(_git_dir(git), relative.encode() + b"/")
    return found


def _git_dir(git: Path) -> Path:
    """The git directory of a ``.git`` entry (a worktree's or submodule's ``.git`` file says
    ``gitdir: PATH``)."""
    if os.path.isdir(git):
        return git
    try:
        with open(git, "rb") as stream:
            line = stream.read(4096).split(b"\n", 1)[0].decode("utf-8", "replace")
    except OSError:
        return git
    if line.startswith("gitdir:"):
        return (git.parent / line[len("gitdir:"):].strip()).resolve()
    return git


def _in_git_index(git_dir: Path, prefix: bytes) -> bool:
    """Whether an entry's name in ``git_dir/index`` starts with ``prefix``. The name of an
    entry follows its 16-bit flags, whose low 12 bits are the name's length (0xFFF: longer):
    a match is kept only where they agree, so a name that merely contains ``prefix`` does
    not count (version 3: an entry with the extended bit has 16 more bits of flags before its
    name)."""
    try:
        fd = os.open(git_dir / "index", os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except FileNotFoundError:  # a new repository: nothing added yet
        return True
    except OSError:
        return False
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode) or info.st_size > MAX_INDEX_BYTES:
            return False
        with open(fd, "rb", closefd=False) as stream:
            data = stream.read()
    finally:
        os.close(fd)
    if data[:4] != b"DIRC" or int.from_bytes(data[4:8], "big") not in (2, 3):
        return False
    at = data.find(prefix, 12)
    while at != -1:
        end = data.find(b"\0", at)
        wanted = min(end - at, 0xFFF)
        flags = int.from_bytes(data[at - 2:at], "big")
        extended = int.from_bytes(data[at - 4:at - 2], "big")
        if end != -1 and ((flags & 0xFFF) == wanted or (
                extended & 0x4000 and (extended & 0xFFF) == wanted)):
            return True
        at = data.find(prefix, at + 1)
    return False


def own_repository(directory) -> Path | None:
    """The repository ``directory`` belongs to: the version-control root above it
    (``repository_of``) when it is that root or a directory the repository holds
    (``tracked``); None for a directory outside any, or inside a work tree that does not
    hold it (a checkout without its own metadata: it is not that work tree's)."""
    top = repository_of(directory)
    if top is None:
        return None
    try:
        real_directory = realpath(directory)
    except (OSError, ValueError):
        return None
    return top if tracked(top, real_directory) else None


def repository_for(path) -> Path:
    """The repository of a checked path: its own repository (``own_repository``); without
    one, a directory as given, a file's package (the nearest directory holding a
    ``package.xml`` that the enclosing work tree does not hold: never that work tree nor one
    of its directories) or the file's own directory. The same whether or not the place is
    inside a work tree that does not hold it (installed packages' data under a virtual
    environment in a checkout, a tarball unpacked in a home directory under git).
    (Sibling packages outside it come from the operator: ROS_PACKAGE_PATH.)"""
    absolute = Path(os.path.abspath(os.fspath(path)))
    # a link decides nothing: its own place's directory, never where it leads
    link = os.path.islink(absolute)
    directory = absolute if os.path.isdir(absolute) and not link else absolute.parent
    found = own_repository(directory)
    if found is not None:
        return found
    if directory == absolute:
        return _root(absolute)
    enclosing = repository_of(directory)
    for parent in (directory, *directory.parents):
        if enclosing is not None and (not _root(parent).is_relative_to(enclosing)
                                      or tracked(enclosing, _root(parent))):
            break
        if os.path.isfile(parent / "package.xml"):
            return _root(parent)
    return _root(directory)


def clamp(value: str, base: Path, key: str, repository: Path) -> Path:
    """``value`` (a path a repository file gives, relative to ``base``) resolved; it must be
    inside ``repository`` and not in its version-control metadata, else OutsideRepository.
    Nothing is asked of the file system beyond resolving links: the answer does not depend on
    whether the target exists."""
    root = _root(repository)
    try:
        target = realpath(Path(base) / value)
    except (OSError, ValueError):  # a link that cannot be read: not known to be inside
        raise OutsideRepository(key, value) from None
    if not target.is_relative_to(root) or has_vcs_component(target, root):
        raise OutsideRepository(key, value)
    return target


class Roots:
    """The places a run may read (all resolved)."""

    __slots__ = ("_hash", "_prefixes", "operator", "repositories")

    def __init__(self, repositories=(), operator=()):
        self.repositories = tuple(dict.fromkeys(_root(p) for p in repositories))
        self.operator = tuple(dict.fromkeys(_root(p) for p in operator))
        self._hash = hash((self.repositories, self.operator))
        # each root as text, and as the start of the paths below it
        self._prefixes = tuple((text, text if text.endswith(os.sep) else text + os.sep)
                               for text in map(str, self.all()))

    def __repr__(self) -> str:
        return f"Roots({list(map(str, self.repositories))}, {list(map(str, self.operator))})"

    def __eq__(self, other) -> bool:
        return isinstance(other, Roots) and (self.repositories, self.operator) == (
            other.repositories, other.operator)

    def __hash__(self) -> int:
        return self._hash

    def __reduce__(self):  # the hash of str differs between interpreters: made there again
        return Roots, (self.repositories, self.operator)

    def all(self) -> list[Path]:
        return [*self.repositories, *self.operator]

    def readable(self, path) -> bool:
        """Whether ``path`` (resolved here) may be read (memoised for the run, like
        ``resolved``, when ``path`` is absolute)."""
        name = os.fspath(path)
        key = (self, name)
        found = _READABLE.get(key)
        if found is None:
            try:
                found = self._readable_text(resolved(name))
            except (OSError, ValueError):
                return False
            if os.path.isabs(name):
                _READABLE[key] = found
        return found

    def _readable_text(self, target: str) -> bool:
        """``target`` (a realpath) is a root or below one, not in its version-control
        metadata (``has_vcs_component``, on text: pathlib's ``is_relative_to`` and parts were
        a tenth of a corpus run's mesh lookups)."""
        return any((target == root or target.startswith(prefix)) and not any(
            part in VCS_DIRS for part in target[len(prefix):].split(os.sep))
            for root, prefix in self._prefixes)

    def landlock(self) -> list[Path]:
        """What the sandboxed reader's Landlock gets: the operator's roots, and each repository
        without its top-level version-control metadata (Landlock only allows: a repository is
        given as its entries; the in-process check refuses deeper metadata too)."""
        paths: list[Path] = []
        for root in self.repositories:
            try:
                entries = sorted(os.listdir(root))
            except OSError:
                continue
            if not any(name in VCS_DIRS for name in entries):
                paths.append(root)
                continue
            paths.extend(root / name for name in entries if name not in VCS_DIRS)
        paths.extend(self.operator)
        return list(dict.fromkeys(paths))

    def to_json(self) -> dict:
        return {"repositories": [str(p) for p in self.repositories],
                "operator": [str(p) for p in self.operator]}

    @classmethod
    def from_json(cls, data) -> Roots:
        return cls([str(p) for p in data["repositories"]], [str(p) for p in data["operator"]])
