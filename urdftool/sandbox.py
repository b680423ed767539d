"""Isolation for untrusted input: run one function (the xacro pass) in a child process.

The child is forked, so it starts at once with everything already imported; before it runs the
function it

- replaces its environment with the variables it is given (``--allow-env``),
- limits its address space (RLIMIT_AS: what it already maps plus ``memory_mb``), its CPU time,
  the size of any file it writes (0: it writes none), and on non-root users the processes it
  may start (0: no ``fork``/``exec``),
- closes every inherited file descriptor except the result pipe, with stdin/stdout/stderr on
  ``/dev/null``.

The parent reads the result as JSON (never pickle: a child that was subverted cannot run code
in the parent through it) and kills the child when the wall-time limit passes. Without
``os.fork`` (Windows) the function runs in-process: the expression validator and the deadline
still hold, the resource limits do not.
"""

from __future__ import annotations

import json
import os
import select
import signal
import sys
import time
from pathlib import Path

from urdftool.xacro_eval import LimitExceeded

GRACE_SECONDS = 1.0  # the child stops itself at the deadline; it is killed this much later
MAX_RESULT_BYTES = 1 << 30


REFUSED = Path("/urdftool-untrusted-outside-the-package-roots")


def package_roots(resolver, path: Path) -> list[Path]:
    """Where an untrusted input may read: the packages known to its resolver (``-P``, its own
    package and siblings, ``ROS_PACKAGE_PATH``, ``AMENT_PREFIX_PATH``) and its own package, or
    its directory when no ``package.xml`` is above it."""
    roots = list(resolver.roots()) if resolver is not None else []
    directory = Path(path).absolute().parent  # where the file is, not where a link points
    own = next((d for d in (directory, *directory.parents) if (d / "package.xml").is_file()),
               directory)
    roots.append(own)
    resolved = []
    for root in roots:
        try:
            resolved.append(Path(root).resolve())
        except OSError:
            continue
    return resolved


def inside(path, roots: list[Path]) -> bool:
    try:
        resolved = Path(path).resolve()
    except (OSError, RuntimeError):
        return False
    return any(resolved.is_relative_to(root) for root in roots)


def check_input(path: Path, resolver) -> None:
    """An untrusted input file itself: a regular file (not a device, FIFO or directory), and
    inside the package roots (a symlink committed to a repository must not make urdftool read,
    and quote, a file of the CI machine). Raises ToolError."""
    from urdftool.errors import ToolError

    if not Path(path).is_file():
        raise ToolError(f"{path}: not a regular file (--untrusted reads only regular files)")
    if not inside(path, package_roots(resolver, path)):
        raise ToolError(f"{path}: links to {Path(path).resolve()}, outside the package roots; "
                        "--untrusted does not follow it")


def confine(resolver, path: Path):
    """A resolver for an untrusted input: a mesh or resource URI that resolves outside the
    package roots resolves instead to a path under ``REFUSED`` (which does not exist), so the
    mesh rules report it as missing, with the refusal in the path they name."""
    resolver.confined_roots = package_roots(resolver, path)
    original = resolver.resolve_uri

    def resolve_uri(uri: str, base_dir: Path):
        found = original(uri, base_dir)
        if found is None or resolver.allows(found):
            return found
        resolved = Path(found).resolve()
        return REFUSED / resolved.relative_to(resolved.anchor)

    resolver.resolve_uri = resolve_uri
    return resolver


class SandboxFailure(Exception):
    """The child died or sent something that is not a result."""


def available() -> bool:
    return hasattr(os, "fork")


def _vm_bytes() -> int:
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("VmSize:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return 0


def _confine(memory_mb: int | None, env: dict[str, str], cpu_seconds: float | None) -> None:
    """Applied in the child, before it runs anything from the input."""
    import resource

    os.environ.clear()
    os.environ.update(env)
    null = os.open(os.devnull, os.O_RDWR)
    for fd in (0, 1, 2):
        os.dup2(null, fd)
    os.close(null)

    def limit(which, value):
        try:
            _, hard = resource.getrlimit(which)
            if hard != resource.RLIM_INFINITY:
                value = min(value, hard)
            resource.setrlimit(which, (value, hard))
        except (ValueError, OSError):
            pass

    if memory_mb:
        used = _vm_bytes()
        limit(resource.RLIMIT_AS, used + (memory_mb << 20))
    if cpu_seconds:
        limit(resource.RLIMIT_CPU, int(cpu_seconds) + 2)
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write fails (EFBIG) rather than kills
    limit(resource.RLIMIT_FSIZE, 0)
    limit(resource.RLIMIT_CORE, 0)
    if hasattr(resource, "RLIMIT_NPROC") and os.geteuid() != 0:
        limit(resource.RLIMIT_NPROC, 0)


def run_isolated(function, args: tuple, *, timeout: float | None, memory_mb: int | None,
                 env: dict[str, str]):
    """``function(*args)`` in a confined child; its return value must be JSON-serialisable.

    Raises LimitExceeded when the child runs past ``timeout`` (plus a grace second) or runs out
    of memory, SandboxFailure when it dies otherwise. An exception raised by ``function`` is
    re-raised as SandboxFailure with its message."""
    if not available():
        return function(*args)
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except Exception:  # noqa: BLE001, S110 - a closed or odd stream: nothing to flush
            pass
    read_fd, write_fd = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: never returns
        code = 70
        try:
            os.close(read_fd)
            _close_inherited(keep={write_fd})
            _confine(memory_mb, env, timeout)
            try:
                payload = {"ok": function(*args)}
            except MemoryError:
                payload = {"limit": "out of memory (the memory limit is "
                                    f"{memory_mb} MB)"}
            except LimitExceeded as exc:
                payload = {"limit": str(exc)}
            except BaseException as exc:  # noqa: BLE001 - reported to the parent
                payload = {"error": f"{type(exc).__name__}: {exc}"}
            data = json.dumps(payload).encode("utf-8")
            view = memoryview(data)
            while view:
                written = os.write(write_fd, view)
                view = view[written:]
            code = 0
        except MemoryError:
            code = 71
        except BaseException:  # noqa: BLE001 - the parent sees the exit code
            code = 70
        finally:
            os._exit(code)
    os.close(write_fd)
    chunks: list[bytes] = []
    size = 0
    deadline = time.monotonic() + timeout + GRACE_SECONDS if timeout else None
    try:
        while True:
            remaining = None if deadline is None else deadline - time.monotonic()
            if remaining is not None and remaining <= 0:
                _kill(pid)
                raise LimitExceeded(f"xacro expansion took longer than {timeout:g} s "
                                    "(the child process was stopped)")
            ready, _, _ = select.select([read_fd], [], [], remaining)
            if not ready:
                continue
            chunk = os.read(read_fd, 1 << 20)
            if not chunk:
                break
            size += len(chunk)
            if size > MAX_RESULT_BYTES:
                _kill(pid)
                raise LimitExceeded("the expanded document is larger than "
                                    f"{MAX_RESULT_BYTES >> 20} MB")
            chunks.append(chunk)
    finally:
        os.close(read_fd)
    _, status = os.waitpid(pid, 0)
    if not chunks:
        if os.WIFSIGNALED(status) and os.WTERMSIG(status) in (signal.SIGKILL, signal.SIGXCPU,
                                                                 signal.SIGSEGV):
            raise LimitExceeded("xacro expansion ran out of memory or CPU time "
                                f"(signal {os.WTERMSIG(status)})")
        if os.WIFEXITED(status) and os.WEXITSTATUS(status) == 71:
            raise LimitExceeded(f"xacro expansion ran out of memory (limit {memory_mb} MB)")
        raise SandboxFailure(f"the sandboxed xacro process died (status {status})")
    try:
        payload = json.loads(b"".join(chunks))
    except ValueError:
        raise SandboxFailure("the sandboxed xacro process sent an unreadable result") from None
    if not isinstance(payload, dict):
        raise SandboxFailure("the sandboxed xacro process sent an unreadable result")
    if "limit" in payload:
        raise LimitExceeded(str(payload["limit"]))
    if "error" in payload:
        raise SandboxFailure(str(payload["error"]))
    return payload.get("ok")


def _close_inherited(keep: set[int]) -> None:
    try:
        fds = [int(name) for name in os.listdir("/proc/self/fd")]
    except (OSError, ValueError):
        fds = list(range(3, 1024))
    for fd in fds:
        if fd > 2 and fd not in keep:
            try:
                os.close(fd)
            except OSError:
                pass


def _kill(pid: int) -> None:
    try:
        os.kill(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    try:
        os.waitpid(pid, 0)
    except ChildProcessError:
        pass
