"""Writing results: to stdout or to ``-o``, never over an input file, atomically."""

from __future__ import annotations

import os
import sys
from pathlib import Path

from urdftool.errors import ToolError


def write_output(text: str, output: str | None, inputs: list[str] = (), in_place: bool = False,
                 offer_in_place: bool = True, encoding: str = "utf-8") -> None:
    """Print ``text`` or write it to ``output`` (temp file + rename) in ``encoding``. Refuses to
    overwrite one of ``inputs`` unless ``in_place`` (the refusal suggests ``--in-place`` when
    the command has it: ``offer_in_place``)."""
    if output is None or output == "-":
        sys.stdout.write(text)
        return
    import tempfile  # here: a report on stdout (the usual case) needs none of it

    target = Path(output)
    if not in_place and any(target.resolve() == Path(i).resolve() for i in inputs):
        raise ToolError(f"{output}: refusing to overwrite an input file"
                        + (" (use --in-place)" if offer_in_place else ""))
    directory = target.resolve().parent
    if not directory.is_dir():
        raise ToolError(f"{output}: directory {directory} does not exist")
    handle, temporary = tempfile.mkstemp(dir=directory, prefix=f".{target.name}.", suffix=".tmp")
    try:
        with os.fdopen(handle, "w", encoding=encoding, newline="") as stream:
            stream.write(text)
            # mkstemp makes the file 0600: keep the mode of the file replaced, else the umask's
            try:
                mode = target.stat().st_mode & 0o7777
            except OSError:
                umask = os.umask(0)
                os.umask(umask)
                mode = 0o666 & ~umask
            os.chmod(stream.fileno(), mode)
        os.replace(temporary, target)
    except OSError as exc:
        Path(temporary).unlink(missing_ok=True)
        raise ToolError(f"{output}: cannot write: {exc.strerror or exc}") from None
