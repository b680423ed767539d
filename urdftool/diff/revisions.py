"""Git revisions for ``urdftool diff`` (issue 30): a revision's files read from git objects
(``git ls-tree`` + ``git cat-file --batch``) into a temporary tree, and the files a change
touched. Nothing here touches the user's working tree or index: git runs with
``GIT_OPTIONAL_LOCKS=0`` (no opportunistic index refresh), without external diff or textconv
drivers and without the file-system monitor hook.
"""

from __future__ import annotations

import os
import subprocess
import tempfile
from pathlib import Path

from urdftool.errors import ToolError

WORKTREE = "WORKTREE"
_SAFE = ("-c", "core.fsmonitor=false", "-c", "core.hooksPath=/dev/null")


def _git(repo: Path, *args: str, input_bytes: bytes | None = None) -> bytes:
    environment = {**os.environ, "GIT_OPTIONAL_LOCKS": "0", "GIT_TERMINAL_PROMPT": "0",
                   "LC_ALL": "C"}
    try:
        done = subprocess.run(["git", *_SAFE, "-C", str(repo), *args], input=input_bytes,
                              capture_output=True, env=environment, check=False)
    except FileNotFoundError:
        raise ToolError("git is not installed (urdftool diff reads revisions with it)") from None
    if done.returncode != 0:
        message = done.stderr.decode("utf-8", "replace").strip().splitlines()
        raise ToolError(f"git {args[0]}: {message[-1] if message else 'failed'}")
    return done.stdout


def repository(start: Path) -> Path:
    """The top of the git working tree holding ``start``; ToolError outside one."""
    try:
        out = _git(start, "rev-parse", "--show-toplevel")
    except ToolError:
        raise ToolError(f"{start}: not inside a git repository (give two files or two "
                        "directories to compare snapshots: urdftool diff OLD NEW)") from None
    return Path(out.decode("utf-8", "surrogateescape").strip())


def commit(repo: Path, revision: str) -> str:
    """The commit ``revision`` names (its full hash); ToolError naming it otherwise."""
    if revision.startswith("-"):
        raise ToolError(f"{revision!r} is not a revision")
    try:
        out = _git(repo, "rev-parse", "--verify", "--quiet", "--end-of-options",
                   f"{revision}^{{commit}}")
    except ToolError:
        raise ToolError(f"{revision!r}: no such revision in {repo}") from None
    return out.decode().strip()


def changed_files(repo: Path, base: str, head: str | None) -> list[str]:
    """Paths (relative to the repository, '/'-separated) that differ between ``base`` and
    ``head`` (a commit), or between ``base`` and the working tree when ``head`` is None
    (untracked files not ignored included). Deleted files are listed too."""
    args = ["diff", "-z", "--name-only", "--no-renames", "--no-ext-diff", "--no-textconv",
            base] + ([head] if head is not None else []) + ["--"]
    names = _split(_git(repo, *args))
    if head is None:
        names += _split(_git(repo, "ls-files", "-z", "--others", "--exclude-standard"))
    return sorted(set(names))


def _split(out: bytes) -> list[str]:
    return [name.decode("utf-8", "surrogateescape") for name in out.split(b"\0") if name]


def blobs(repo: Path, revision: str) -> list[tuple[bytes, bytes, str]]:
    """(mode, blob id, path) of every file of ``revision``; no submodules, no path that
    climbs out or into ``.git``."""
    listing = _git(repo, "ls-tree", "-r", "-z", "--full-tree", revision)
    entries = []
    for record in listing.split(b"\0"):
        if not record:
            continue
        meta, _, name = record.partition(b"\t")
        mode, kind, sha = meta.split()
        if kind != b"blob":
            continue  # a submodule (commit): not part of this repository's files
        path = name.decode("utf-8", "surrogateescape")
        parts = Path(path).parts
        if not parts or any(p in ("..", ".git") for p in parts) or Path(path).is_absolute():
            continue
        entries.append((mode, sha, path))
    return entries


def worktree_blobs(repo: Path) -> dict[str, str]:
    """Path -> blob id of the working tree's files that hold HEAD's bytes (not changed since
    HEAD, staged or not)."""
    changed = set(changed_files(repo, "HEAD", None))
    return {path: sha.decode() for _, sha, path in blobs(repo, "HEAD") if path not in changed}


def materialize(repo: Path, revision: str, destination: Path,
                same: dict[str, str] | None = None) -> dict[str, str]:
    """Write the files of ``revision`` (a commit hash) under ``destination`` from git objects:
    regular files with their executable bit, symbolic links as links (the loader refuses one
    that leads out of the run's roots), no submodules. A file whose blob the working tree
    holds unchanged (``same``: ``worktree_blobs``) is linked or copied from it rather than
    read through git (a description's meshes: tens of megabytes). Returns path -> blob id."""
    entries = blobs(repo, revision)
    if not entries:
        return {}
    every = {path: sha.decode() for _, sha, path in entries}
    if same:
        rest = []
        for mode, sha, path in entries:
            if mode != b"120000" and same.get(path) == sha.decode() and \
                    _reuse(repo / path, destination / path, mode):
                continue
            rest.append((mode, sha, path))
        entries = rest
        if not entries:
            return every
    process = subprocess.Popen(["git", *_SAFE, "-C", str(repo), "cat-file", "--batch"],
                               stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                               stderr=subprocess.DEVNULL,
                               env={**os.environ, "GIT_OPTIONAL_LOCKS": "0"})
    try:
        assert process.stdin is not None and process.stdout is not None
        process.stdin.write(b"".join(sha + b"\n" for _, sha, _ in entries))
        process.stdin.close()
        stream = process.stdout
        made: set[Path] = set()
        for mode, sha, path in entries:
            header = stream.readline().split()
            if len(header) == 2 and header[1] == b"missing":
                continue  # not in this clone (a partial or shallow one): as if absent
            if len(header) != 3 or header[1] != b"blob":
                raise ToolError(f"git cat-file: cannot read {path} of {revision[:12]}")
            data = stream.read(int(header[2]))
            stream.read(1)  # the newline after the object
            target = destination / path
            if target.parent not in made:
                target.parent.mkdir(parents=True, exist_ok=True)
                made.add(target.parent)
            if mode == b"120000":
                os.symlink(data.decode("utf-8", "surrogateescape"), target)
                continue
            with open(target, "wb") as handle:
                handle.write(data)
            if mode == b"100755":
                os.chmod(target, 0o755)
    finally:
        if process.stdout is not None:
            process.stdout.close()
        process.wait()
    return every


def _reuse(source: Path, target: Path, mode: bytes) -> bool:
    """``source`` (a regular file of the working tree) hard-linked, else copied, to ``target``;
    False when neither can be done (then it is read from git)."""
    import shutil
    import stat

    try:
        if not stat.S_ISREG(os.lstat(source).st_mode):
            return False
        target.parent.mkdir(parents=True, exist_ok=True)
        try:
            os.link(source, target)
        except OSError:
            shutil.copyfile(source, target, follow_symlinks=False)
            if mode == b"100755":
                os.chmod(target, 0o755)
    except OSError:
        return False
    return True


def temporary_tree(prefix: str) -> tempfile.TemporaryDirectory:
    """A private temporary directory for one side's files (removed when the diff ends)."""
    return tempfile.TemporaryDirectory(prefix=f"urdftool-diff-{prefix}-")


def merge_base(repo: Path, one: str, other: str) -> str:
    """The best common ancestor of two commits (``BASE...HEAD``)."""
    return _git(repo, "merge-base", one, other).decode().strip()
