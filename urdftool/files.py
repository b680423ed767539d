"""Reading a file a repository holds, bounded: only a regular file (a committed symlink to
``/dev/zero``, a FIFO or a device would never end), of at most a given size, checked on the
open descriptor before reading. Every read of a file named by an input, a package or a
configuration goes through ``read_regular``.

Every file read is also recorded (``READ``: its device and inode, taken from the descriptor
already open, so at no cost): the one "files read" set of the run, which no output may
overwrite (``urdftool.output``). Files read by other means (meshes through their libraries, a
sandboxed reader's or a worker process's reads sent back) are added with ``note``.

``write_file`` is the core of urdftool's one writer (``urdftool.output`` wraps it with the
run's whole "files read" set; the cache, in this layer, calls it directly): atomic, through no
symbolic link below the repository, over no file read."""

from __future__ import annotations

import errno
import os
from stat import S_ISDIR, S_ISLNK, S_ISREG

from urdftool.errors import ToolError

MAX_BYTES = 64 << 20  # a robot description, an include, a configuration file
READ: dict[tuple[int, int], str] = {}  # (st_dev, st_ino) of every file read -> a path of it


def note(path) -> None:
    """Record a file read other than through ``read_regular`` (nothing if it does not exist)."""
    try:
        info = os.stat(path)
    except (OSError, ValueError):
        return
    READ.setdefault((info.st_dev, info.st_ino), os.fspath(path))


def read_paths() -> list[str]:
    """A path of every file recorded as read by this process."""
    return list(READ.values())


def read_regular(path, limit: int = MAX_BYTES) -> bytes:
    """The bytes of a regular file of at most ``limit`` bytes; OSError (with the reason in
    ``strerror``) for anything else."""
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    try:
        info = os.fstat(fd)
        if S_ISDIR(info.st_mode):
            raise IsADirectoryError(errno.EISDIR, "is a directory", str(path))
        if not S_ISREG(info.st_mode):
            raise OSError(errno.EINVAL, "not a regular file (a device, FIFO or socket): not read",
                          str(path))
        if info.st_size > limit:
            raise OSError(errno.EFBIG, f"{_size(info.st_size)}, larger than the "
                                       f"{_size(limit)} urdftool reads: not read", str(path))
    except BaseException:
        os.close(fd)
        raise
    READ.setdefault((info.st_dev, info.st_ino), os.fspath(path))
    with open(fd, "rb", closefd=True) as handle:
        data = handle.read(info.st_size + 1)  # (asking for `limit` would allocate it)
        if len(data) > info.st_size:  # grew since, or a size the system does not know (/proc)
            data += handle.read(limit + 1 - len(data))
    if len(data) > limit:
        raise OSError(errno.EFBIG, f"larger than the {_size(limit)} urdftool reads", str(path))
    return data


def _size(size: int) -> str:
    return f"{size >> 20} MB" if size >= 1 << 20 else f"{size >> 10} KB"


def read_regular_text(path, limit: int = MAX_BYTES) -> str:
    return read_regular(path, limit).decode("utf-8", errors="replace")


# -- writing: the one writer's core (``urdftool.output`` adds the run's "files read" set) ------

_VCS = (".git", ".hg", ".svn")
_DIR_FLAGS = os.O_RDONLY | getattr(os, "O_DIRECTORY", 0) | getattr(os, "O_CLOEXEC", 0)
_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)


def write_file(output, data: bytes, inputs=(), may_replace=(), make_dirs: bool = False,
               hint: str = "", read=None) -> None:
    """Write ``data`` to the file ``output``: atomically, through no symbolic link, over no file
    of ``read`` ((device, inode) keys; default ``READ`` and ``inputs``) except those in
    ``may_replace``; ``make_dirs``: create missing directories (each one as the directories
    above it are opened). ToolError on refusal or failure."""
    shown = os.fspath(output)
    directory, name = os.path.split(os.path.abspath(shown))
    if not name or name in (".", ".."):
        raise ToolError(f"{shown}: not a file name")
    fd = _open_directory(shown, directory, inputs, make_dirs)
    temporary = None
    try:
        mode = _check_target(shown, fd, name, inputs, may_replace, hint, read)
        temporary = _temporary(fd, name)
        handle = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NOFOLLOW
                         | getattr(os, "O_CLOEXEC", 0), 0o600, dir_fd=fd)
        with open(handle, "wb", closefd=True) as stream:
            stream.write(data)
            os.chmod(stream.fileno(), mode)
        os.replace(temporary, name, src_dir_fd=fd, dst_dir_fd=fd)
        temporary = None
    except OSError as exc:
        raise ToolError(f"{shown}: cannot write: {exc.strerror or exc}") from None
    finally:
        if temporary is not None:
            try:
                os.unlink(temporary, dir_fd=fd)
            except OSError:
                pass
        os.close(fd)


def _check_target(shown: str, fd: int, name: str, inputs, may_replace, hint: str,
                  read=None) -> int:
    """The mode to give the new file; ToolError if ``name`` in ``fd`` may not be replaced."""
    try:
        info = os.lstat(name, dir_fd=fd)
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask
    if S_ISLNK(info.st_mode):
        raise ToolError(f"{shown}: refusing to write through a symbolic link")
    if S_ISDIR(info.st_mode):
        raise ToolError(f"{shown}: is a directory")
    if read is None:
        for path in inputs:
            note(path)
        read = READ
    if (info.st_dev, info.st_ino) in read:
        allowed = set()
        for path in may_replace:
            try:
                other = os.stat(path)
                allowed.add((other.st_dev, other.st_ino))
            except OSError:
                pass
        if (info.st_dev, info.st_ino) not in allowed:
            raise ToolError(f"{shown}: refusing to overwrite an input file (this run read it)"
                            + hint)
    return info.st_mode & 0o7777


def _temporary(fd: int, name: str) -> str:
    import secrets  # here: a report on stdout (the usual case) needs none of it

    return f".{name[:64]}.{secrets.token_hex(6)}.tmp"


def _open_directory(shown: str, directory: str, inputs, make_dirs: bool) -> int:
    """A descriptor of ``directory`` (absolute, not resolved) opened without following a link
    below the repository it is in; ToolError for a link, a missing directory (unless
    ``make_dirs``) or a file in the way."""
    base = _base(directory, inputs)
    if base is None:  # outside every repository: the operator's directories
        if make_dirs:
            try:
                os.makedirs(directory, exist_ok=True)
            except OSError as exc:
                raise ToolError(f"{shown}: cannot create {directory}: "
                                f"{exc.strerror or exc}") from None
        try:
            return os.open(directory, _DIR_FLAGS)
        except FileNotFoundError:
            raise ToolError(f"{shown}: directory {directory} does not exist") from None
        except OSError as exc:
            raise ToolError(f"{shown}: cannot open {directory}: {exc.strerror or exc}") from None
    fd = os.open(base, _DIR_FLAGS)
    done = base
    try:
        for part in os.path.relpath(directory, base).split(os.sep):
            if part in ("", "."):
                continue
            done = os.path.join(done, part)
            try:
                following = os.open(part, _DIR_FLAGS | _NOFOLLOW, dir_fd=fd)
            except FileNotFoundError:
                if not make_dirs:
                    raise ToolError(f"{shown}: directory {done} does not exist") from None
                os.mkdir(part, 0o777, dir_fd=fd)
                following = os.open(part, _DIR_FLAGS | _NOFOLLOW, dir_fd=fd)
            except OSError as exc:
                if exc.errno in (errno.ELOOP, errno.ENOTDIR, errno.EMLINK):
                    try:
                        link = S_ISLNK(os.lstat(part, dir_fd=fd).st_mode)
                    except OSError:
                        link = False
                    raise ToolError(f"{shown}: refusing to write through a symbolic link "
                                    f"({done})" if link else
                                    f"{shown}: {done} is not a directory") from None
                raise
            os.close(fd)
            fd = following
    except OSError as exc:
        os.close(fd)
        raise ToolError(f"{shown}: cannot open {done}: {exc.strerror or exc}") from None
    except BaseException:
        os.close(fd)
        raise
    return fd


def _base(directory: str, inputs) -> str | None:
    """The repository ``directory`` is in, as a lexical prefix of it: the version-control root
    above the working directory or above an input (else the working directory itself); None
    when ``directory`` is in none of them."""
    candidates = [_repository(os.getcwd())]
    for path in inputs:
        candidates.append(_repository(os.path.dirname(os.path.realpath(path))))
    best = None
    for root in candidates:
        inside = directory == root or directory.startswith(root.rstrip(os.sep) + os.sep)
        if inside and (best is None or len(root) < len(best)):
            best = root
    return best


_REPOSITORIES: dict[str, str] = {}


def _repository(start: str) -> str:
    """The nearest directory at or above ``start`` (a resolved path) holding a VCS directory;
    ``start`` itself when there is none."""
    found = _REPOSITORIES.get(start)
    if found is None:
        found = _REPOSITORIES[start] = _find_repository(start)
    return found


def _find_repository(start: str) -> str:
    current = start
    while True:
        if any(os.path.lexists(os.path.join(current, vcs)) for vcs in _VCS):
            return current
        parent = os.path.dirname(current)
        if parent == current:
            return start
        current = parent


def read_head(path, size: int) -> bytes:
    """The first ``size`` bytes of a regular file (b"" for anything else: a device, a FIFO, a
    directory), read without blocking."""
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    try:
        if not S_ISREG(os.fstat(fd).st_mode):
            return b""
        return os.read(fd, size)
    finally:
        os.close(fd)
