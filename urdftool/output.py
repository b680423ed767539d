"""The one writer: every file urdftool writes (``-o``, ``--output-file``, ``--extra-output``,
``--fix`` output and ``--in-place``, ``--write-baseline``, expand's and convert's ``-o``,
``sim --render`` pictures, the persistent cache) goes through ``files.write_file``; commands
call it through this module, which adds the run's "files read" set.

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

A refusal is a ``ToolError`` (one line, exit 2) raised before anything is written. The core is
in ``urdftool.files`` (the base layer: the cache writes through it too).
"""

from __future__ import annotations

import os
import sys

from urdftool import files
from urdftool.errors import ToolError


def files_read(extra=()) -> dict[tuple[int, int], str]:
    """The run's one "files read" set, as (device, inode) -> a path: what the loader read
    (``loader.files_read``), what ``urdftool.files`` recorded (configuration, baseline,
    launch files, worker processes' and the sandboxed reader's reads) and ``extra`` (inputs a
    command names)."""
    loader = sys.modules.get("urdftool.loader")  # (nothing loaded: nothing read through it)
    for path in [*(loader.files_read() if loader is not None else ()), *extra]:
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
    write_file(output, text.encode(encoding), inputs, may_replace=(output,) if in_place else (),
               hint=" (use --in-place)" if offer_in_place else "")


def write_file(output, data: bytes, inputs=(), may_replace=(), make_dirs: bool = False,
               hint: str = "") -> None:
    """``files.write_file`` over the run's "files read" set."""
    files.write_file(output, data, inputs, may_replace, make_dirs, hint, files_read(inputs))


def check_target(output, inputs=(), make_dirs: bool = False, may_replace=(),
                 hint: str = "") -> None:
    """Refuse now (ToolError) what ``write_file`` would refuse for ``output`` given what has
    been read so far: a command whose files are written later (``sim --render`` in worker
    processes) fails before its work, not after. Creates nothing."""
    shown = os.fspath(output)
    directory, name = os.path.split(os.path.abspath(shown))
    try:
        fd = files._open_directory(shown, directory, inputs, False)
    except ToolError as exc:
        if make_dirs and "does not exist" in str(exc):
            return  # created when written (each new directory opened without following)
        raise
    try:
        files._check_target(shown, fd, name, inputs, may_replace, hint, files_read(inputs))
    finally:
        os.close(fd)
