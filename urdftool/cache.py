"""The persistent cache: what urdftool derives from files that rarely change (mesh summaries),
kept between runs in ``$URDFTOOL_CACHE_DIR``, else ``$XDG_CACHE_HOME/urdftool``, else
``~/.cache/urdftool``.

An entry is data, never code (no pickle): one file holding a JSON header line, then raw
little-endian float64 values. It is keyed on the source file's resolved path, size and
``mtime_ns``, the cache format and urdftool's version, all stored in the entry and compared on
read (the file name is a hash of the path and kind only, so a changed file replaces its entry).
Hashing the content on every read would be safer against a same-size rewrite within one mtime
tick, but reading the 400 MB of meshes of the test corpus costs ~0.3 s, more than a warm run's
whole cache lookup; the content's SHA-256 is stored with the entry and compared only when the
modification time differs (a fresh checkout of the same files: the GitHub Action restores the
cache of an earlier run with ``actions/cache``), so a new clone still reads no mesh again. The versions of trimesh and pycollada are not in the key (asking for them costs
~80 ms a run): after upgrading them, delete the directory to read every mesh again.

Writes go through urdftool's one writer (``urdftool.output``: a temporary file in the same
directory, then a rename, through no symbolic link): concurrent writers (a process pool over
files) and readers only ever see whole entries, the last writer wins. Any failure to read or write (read-only home, a corrupt or truncated entry, a full disk)
makes the caller compute the value again: the cache can only save time. ``ENABLED`` is turned
off by ``--no-cache`` (nothing read, nothing written); ``WRITABLE`` by an untrusted run
without ``$URDFTOOL_CACHE_DIR`` (read, never written: no entry of any kind, no directory).
"""

from __future__ import annotations

import json
import os
import sys
from array import array
from pathlib import Path

from urdftool import __version__

FORMAT = 1  # bump when an entry's layout or the way its data is derived changes (urdftool's
# version does not change between commits)
ENABLED = True
# An untrusted run (``--untrusted``, or under CI) reads the cache but writes nothing, unless
# ``$URDFTOOL_CACHE_DIR`` names a directory for it: checking a stranger's files writes no file
# the user did not ask for (``urdftool.cli.load_options`` sets it).
WRITABLE = True
_MAX_HEADER = 1 << 16


def directory() -> Path:
    explicit = os.environ.get("URDFTOOL_CACHE_DIR")
    if explicit:
        return Path(explicit)
    xdg = os.environ.get("XDG_CACHE_HOME")
    base = Path(xdg) if xdg else Path.home() / ".cache"
    return base / "urdftool"


def stamp(path: Path, reading: int = 0) -> dict | None:
    """The key of an entry derived from the file at ``path`` (a resolved path), or None when
    the cache is off or the file cannot be stat'ed. Take it before reading the file: a file
    changed meanwhile is then stored under its old stamp, never the reverse. ``reading``: the
    version of how the caller derives its entry (``meshes.READING``): an entry derived the old
    way is never read again, whatever the file's content."""
    if not ENABLED:
        return None
    try:
        st = os.stat(path)
    except OSError:
        return None
    key = {"path": str(path), "size": st.st_size, "mtime_ns": st.st_mtime_ns,
           "format": FORMAT, "version": __version__}
    if reading:
        key["reading"] = reading
    return key


def _entry(kind: str, key: dict) -> Path:
    import hashlib  # here, not at the top: `check` on a primitive robot never needs it (start-up)

    digest = hashlib.sha256(f"{kind}\0{key['path']}".encode("utf-8", "surrogatepass"))
    return directory() / kind / digest.hexdigest()[:40]


def read(kind: str, key: dict):
    """(header dict, ``array("d")`` of the values) stored for ``key``, or None (absent, stale,
    corrupt). Read with the standard library: a warm run imports no numpy."""
    try:
        with open(_entry(kind, key), "rb") as handle:
            data = handle.read()
        end = data.index(b"\n", 0, _MAX_HEADER)
        entry = json.loads(data[:end])
        if not isinstance(entry, dict):
            return None
        if entry.get("key") != key:
            if not _same_content(entry, key):
                return None
            entry["key"] = key  # the new modification time: found without hashing next time
            store(_entry(kind, key), json.dumps(entry).encode("utf-8") + data[end:])
        header = entry.get("data")
        count = entry.get("values")
        if not isinstance(header, dict) or type(count) is not int \
                or len(data) - end - 1 != 8 * count:
            return None
        values = array("d")
        values.frombytes(data[end + 1:])
        if sys.byteorder == "big":  # stored little-endian
            values.byteswap()
        return header, values
    except (OSError, ValueError, RecursionError, RuntimeError):  # RuntimeError: no home directory
        return None


def _digest(path: str) -> str | None:
    """The SHA-256 of a file (at most 64 MB, as urdftool reads), None if it cannot be read."""
    import hashlib

    from urdftool.files import read_regular

    try:
        return hashlib.sha256(read_regular(path)).hexdigest()
    except OSError:
        return None


def _same_content(entry: dict, key: dict) -> bool:
    """An entry stored for the same file, same size, format and version, whose modification
    time differs (a fresh checkout: a CI job restoring the cache of an earlier run) but whose
    content is the same (its SHA-256, computed only in this case)."""
    stored = entry.get("key")
    if not isinstance(stored, dict) or not isinstance(entry.get("sha256"), str):
        return False
    if any(stored.get(name) != key.get(name)
           for name in ("path", "size", "format", "version", "reading")):
        return False
    return _digest(key["path"]) == entry["sha256"]


def write(kind: str, key: dict, header: dict, values, content: bytes | None = None) -> None:
    """Store ``header`` (JSON-able) and ``values`` (floats: a flat sequence, or a numpy array of
    any shape) for ``key``; any failure is silently ignored. ``content``: the file's bytes the
    entry was derived from, when the caller has them (hashed instead of reading the file)."""
    if not WRITABLE:
        return
    try:
        if hasattr(values, "dtype"):  # numpy: its bytes as little-endian float64
            import numpy as np

            flat = np.ascontiguousarray(values, dtype="<f8").ravel()
            count, data = int(flat.size), flat.tobytes()
        else:
            floats = array("d", values)
            if sys.byteorder == "big":
                floats.byteswap()
            count, data = len(floats), floats.tobytes()
        if content is not None:
            import hashlib

            digest = hashlib.sha256(content).hexdigest()
        else:
            digest = _digest(key["path"])
        text = json.dumps({"key": key, "sha256": digest, "data": header,
                           "values": count})
        store(_entry(kind, key), text.encode("utf-8") + b"\n" + data)
    except (ValueError, TypeError, RuntimeError):  # RuntimeError: no home directory
        pass


def store(target: Path, data: bytes) -> None:
    """Write one entry (any kind: mesh summaries, ``package``'s reads) through urdftool's one
    writer (``urdftool.output``: atomic, through no link, over no file the run read), unless
    the cache is off or not writable (an untrusted run without ``$URDFTOOL_CACHE_DIR``); a
    failure is ignored (the cache only saves time)."""
    if not (ENABLED and WRITABLE):
        return
    from urdftool.errors import ToolError
    from urdftool.files import write_file

    try:
        write_file(target, data, make_dirs=True)
    except (ToolError, OSError):
        pass
