"""Reading a file a repository holds, bounded: only a regular file (a committed symlink to
``/dev/zero``, a FIFO or a device would never end), of at most a given size, checked on the
open descriptor before reading. Every read of a file named by an input, a package or a
configuration goes through ``read_regular``."""

from __future__ import annotations

import errno
import os
from stat import S_ISDIR, S_ISREG

MAX_BYTES = 64 << 20  # a robot description, an include, a configuration file


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
    with open(fd, "rb", closefd=True) as handle:
        data = handle.read(info.st_size + 1)  # (asking for `limit` would allocate it)
        if len(data) > info.st_size:  # grew since, or a size the system does not know (/proc)
            data += handle.read(limit + 1 - len(data))
    if len(data) > limit:
        raise OSError(errno.EFBIG, f"larger than the {limit >> 20} MB urdftool reads", str(path))
    return data


def read_regular_text(path, limit: int = MAX_BYTES) -> str:
    return read_regular(path, limit).decode("utf-8", errors="replace")
