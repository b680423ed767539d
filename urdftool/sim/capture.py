"""Keep what C libraries print out of our stdout: PyBullet prints a build banner on import and
its warnings and errors (``b3Warning[...]``) with ``printf`` while loading.

``captured_fds()`` points file descriptors 1 and 2 at a temporary file at the OS level (so C code
writes there too), flushes the C stdio buffers before putting them back (C stdout is block
buffered when it is not a terminal, so without the flush the banner would come out at exit), and
hands back what was printed, so that PyBullet's own error messages can be passed on.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import re
import sys
import tempfile


class Captured:
    """What was printed while capturing (filled in when the ``with`` block ends)."""

    text: str = ""


def _flush_c_stdio() -> None:
    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):  # pragma: no cover - no libc (not on Linux/macOS)
        pass


@contextlib.contextmanager
def captured_fds():
    """Redirect fds 1 and 2 (C and Python alike) into a temporary file for the block."""
    captured = Captured()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    _flush_c_stdio()
    saved = [os.dup(1), os.dup(2)]
    with tempfile.TemporaryFile(mode="w+b") as sink:
        os.dup2(sink.fileno(), 1)
        os.dup2(sink.fileno(), 2)
        try:
            yield captured
        finally:
            for stream in (sys.stdout, sys.stderr):
                with contextlib.suppress(Exception):
                    stream.flush()
            _flush_c_stdio()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)
            sink.seek(0)
            captured.text = sink.read().decode("utf-8", errors="replace")


_B3_RE = re.compile(r"b3(?:Warning|Error|Printf)\[[^][\n]*\]:\s*\n?")


def bullet_messages(text: str) -> list[str]:
    """PyBullet's printed messages as clean lines: the ``b3Error[file,line]:`` prefixes removed,
    the banner and empty lines dropped."""
    lines = []
    for part in _B3_RE.split(text):
        for line in part.splitlines():
            line = line.strip()
            if line and not line.startswith(("pybullet build time", "argv[0]=")):
                lines.append(line)
    return lines
