"""Reading a file a repository holds, bounded: only a regular file (a committed symlink to
``/dev/zero``, a FIFO or a device would never end), of at most a given size, checked on the
open descriptor before reading. Every read of a file named by an input, a package or a
configuration goes through ``read_regular``.

Every file read is also recorded (``READ``: its device and inode, taken from the descriptor
already open, so at no cost): the one "files read" set of the run, which no output may
overwrite (``urdftool.output``). Files read by other means (meshes through their libraries, a
sandboxed reader's or a worker process's reads sent back) are added with ``note``."""

from __future__ import annotations

import errno
import os
from stat import S_ISDIR, S_ISREG

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
            raise OSError(errno.EFBIG, f"{info.st_size >> 20} MB, larger than the "
                                       f"{limit >> 20} MB urdftool reads: not read", str(path))
    except BaseException:
        os.close(fd)
        raise
    READ.setdefault((info.st_dev, info.st_ino), os.fspath(path))
    with open(fd, "rb", closefd=True) as handle:
        data = handle.read(info.st_size + 1)  # (asking for `limit` would allocate it)
        if len(data) > info.st_size:  # grew since, or a size the system does not know (/proc)
            data += handle.read(limit + 1 - len(data))
    if len(data) > limit:
        raise OSError(errno.EFBIG, f"larger than the {limit >> 20} MB urdftool reads", str(path))
    return data


def read_regular_text(path, limit: int = MAX_BYTES) -> str:
    return read_regular(path, limit).decode("utf-8", errors="replace")
