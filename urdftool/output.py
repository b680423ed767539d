"""The one writer: every file urdftool writes (``-o``, ``--output-file``, ``--fix`` output and
``--in-place``, ``--write-baseline``, expand's and convert's ``-o``, ``sim --render`` pictures,
the persistent cache) goes through ``write_file``.

- Never through a symbolic link: not the final component, and not any directory between the
  repository and the file (each opened with ``O_NOFOLLOW`` from the one above it, the file then
  created and renamed relative to that directory's descriptor, so a link swapped in meanwhile
  is not followed either). The repository is the version-control root above the working
  directory and above each input named on the command line (else the working directory);
  directories above it are the operator's and may be links.
- Never over a file the run read (``files_read``: the input, includes, YAML, launch files,
  configuration, baseline, meshes), compared by device and inode so that a link or a second
  name of it is caught too; ``--in-place`` names the files it may replace.
- Atomic: a temporary file in the same directory, renamed over the target; the replaced file's
  permissions are kept (else the umask's).

A refusal is a ``ToolError`` (one line, exit 2) raised before anything is written.
"""

from __future__ import annotations

import errno
import os
import sys
from stat import S_ISDIR, S_ISLNK

from urdftool.errors import ToolError

_VCS = (".git", ".hg", ".svn")
_DIR_FLAGS = os.O_RDONLY | getattr(os, "O_DIRECTORY", 0) | getattr(os, "O_CLOEXEC", 0)
_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)


def files_read(extra=()) -> dict[tuple[int, int], str]:
    """The run's one "files read" set, as (device, inode) -> a path: what the reading layer
    recorded (``urdftool.files``) and ``extra`` (inputs a command names)."""
    from urdftool import files

    for path in extra:
        files.note(path)
    return files.READ


def write_output(text: str, output: str | None, inputs=(), in_place: bool = False,
                 offer_in_place: bool = True, encoding: str = "utf-8") -> None:
    """Print ``text``, or write it to ``output`` in ``encoding`` (``write_file``). ``inputs``:
    files the command named besides what it read; ``in_place``: ``output`` itself may be one
    of them (``--fix --in-place``); ``offer_in_place``: a refusal suggests ``--in-place``."""
    if output is None or output == "-":
        sys.stdout.write(text)
        return
    write_file(output, text.encode(encoding), inputs,
               may_replace=(output,) if in_place else (),
               hint=" (use --in-place)" if offer_in_place else "")


def write_file(output, data: bytes, inputs=(), may_replace=(), make_dirs: bool = False,
               hint: str = "") -> None:
    """Write ``data`` to the file ``output``: atomically, through no symbolic link, over no file
    the run read except those in ``may_replace``; ``make_dirs``: create missing directories
    (each one as the directories above it are opened). ToolError on refusal or failure."""
    shown = os.fspath(output)
    directory, name = os.path.split(os.path.abspath(shown))
    if not name or name in (".", ".."):
        raise ToolError(f"{shown}: not a file name")
    fd = _open_directory(shown, directory, inputs, make_dirs)
    temporary = None
    try:
        mode = _check_target(shown, fd, name, inputs, may_replace, hint)
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


def check_target(output, inputs=(), make_dirs: bool = False, may_replace=(),
                 hint: str = "") -> None:
    """Refuse now (ToolError) what ``write_file`` would refuse for ``output`` given what has
    been read so far: a command whose files are written later (``sim --render`` in worker
    processes) fails before its work, not after. Creates nothing."""
    shown = os.fspath(output)
    directory, name = os.path.split(os.path.abspath(shown))
    try:
        fd = _open_directory(shown, directory, inputs, False)
    except ToolError as exc:
        if make_dirs and "does not exist" in str(exc):
            return  # created when written (each new directory opened without following)
        raise
    try:
        _check_target(shown, fd, name, inputs, may_replace, hint)
    finally:
        os.close(fd)


def check_directory(output, inputs=()) -> None:
    """``check_target`` for a directory that files are written into (``--render DIR/``)."""
    shown = os.fspath(output)
    try:
        os.close(_open_directory(shown, os.path.abspath(shown), inputs, False))
    except ToolError as exc:
        if "does not exist" not in str(exc):
            raise


def _check_target(shown: str, fd: int, name: str, inputs, may_replace, hint: str) -> int:
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
    read = files_read(inputs)
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
