"""The run's time budget (issue 21): ``--timeout`` seconds for every file the scan found, one
wall-clock deadline for the whole run, shared by every step that reads repository content.

``check`` starts it (``start``) once it knows how many distinct files it found (what the
configuration lists does not count: the same file listed 20 times with different arguments
shares one file's time). Every reader request and every expansion asks ``clamp(timeout)``
for its own limit (at most what is left of the run); the parent's steps between them call
``check()`` (``Spent`` once the run is out of time). The deadline is a ``time.monotonic()``
value, so forked workers share it. Without ``start`` (one-file commands) there is no run
budget: each reading has its own ``--timeout``.

``watchdog(seconds, make_exception)`` stops work that does not count its own steps (xacro
and PyYAML in this process under ``--trusted``): a timer signal raises ``make_exception()``
in the main thread at the deadline, then again every ``REPEAT`` seconds until the block
ends, so that a handler that swallows one exception does not keep it running.

This module imports nothing else of urdftool: readers, the interpreter and ``check`` all use
it.
"""

from __future__ import annotations

import contextlib
import time

_deadline: float | None = None  # time.monotonic() after which the run is out of time
_seconds: float | None = None  # the budget it was started with (for messages)
_files = 0
REPEAT = 0.05  # seconds between a watchdog's repeated interrupts
MINIMUM = 0.05  # a reading never gets less than this (it would be refused anyway: said so)


class Spent(Exception):
    """The run's time budget is spent: what is left is reported, not read."""


def start(timeout: float | None, files: int, started: float | None = None) -> None:
    """A run of ``files`` files (at least one), ``timeout`` seconds each and ``timeout`` more
    for the run's own start (the sandboxed reader's start, configuration, planning: seconds on
    a loaded machine), from ``started`` (``time.monotonic()``; now if None). ``timeout``
    None: no budget."""
    global _deadline, _seconds, _files
    if timeout is None:
        stop()
        return
    _files = max(1, files)
    _seconds = timeout * (_files + 1)
    _deadline = (started if started is not None else time.monotonic()) + _seconds


def stop() -> None:
    global _deadline, _seconds, _files
    _deadline = _seconds = None
    _files = 0


def remaining() -> float | None:
    """Seconds left in the run (None: no run budget)."""
    return None if _deadline is None else _deadline - time.monotonic()


def spent() -> bool:
    return _deadline is not None and time.monotonic() > _deadline


def check() -> None:
    """Raise Spent when the run is out of time."""
    if _deadline is not None and time.monotonic() > _deadline:
        raise Spent(describe())


def clamp(timeout: float | None) -> float | None:
    """The limit of one reading: ``timeout``, at most what is left of the run (never less
    than MINIMUM: a reading that starts is bounded, not refused)."""
    left = remaining()
    if left is None:
        return timeout
    left = max(left, MINIMUM)
    return left if timeout is None else min(timeout, left)


def describe() -> str:
    if _seconds is None:
        return "the time limit is spent"
    return (f"the run's time budget is spent ({_seconds:g} s: --timeout for each of the "
            f"{_files} file(s) found, and once for the run)")


def _interruptible(frame, inside: tuple[str, ...]) -> bool:
    """Whether the code running (``frame``) may be interrupted: its file's path holds one of
    ``inside`` (any code when empty), and no import is under way."""
    name = frame.f_code.co_filename.replace("\\", "/") if frame is not None else ""
    if inside and not any(part in name for part in inside):
        return False
    while frame is not None:
        if frame.f_code.co_filename.startswith("<frozen importlib"):
            return False
        frame = frame.f_back
    return True


@contextlib.contextmanager
def watchdog(seconds: float | None, make_exception, inside: tuple[str, ...] = ()):
    """Run the block with ``make_exception()`` raised in it after ``seconds`` (then every
    REPEAT seconds until it ends), only while code whose file's path holds one of ``inside``
    runs (a library's own loops, not the caller's bookkeeping). Only in the main thread of a process with interval timers
    (elsewhere the block runs unwatched: its own counting bounds it); a watchdog inside
    another keeps the outer one's timer."""
    import signal
    import threading

    try:
        busy = signal.getitimer(signal.ITIMER_REAL)[0] > 0
    except (OSError, AttributeError):  # no interval timers (a seccomp allowlist, not Unix)
        busy = True
    if seconds is None or busy or threading.current_thread() is not threading.main_thread():
        yield
        return
    armed = [True]

    def interrupt(signum, frame):
        # only inside the watched code, never in an import (a module left half-initialised
        # breaks every later run of the process): the timer fires again REPEAT seconds later
        if not armed[0] or not _interruptible(frame, inside):
            return
        raise make_exception()

    try:
        previous = signal.signal(signal.SIGALRM, interrupt)
    except (OSError, ValueError):  # a sandbox that allows no signal handling: unwatched
        yield
        return
    try:
        try:
            signal.setitimer(signal.ITIMER_REAL, max(seconds, 0.001), REPEAT)
        except OSError:  # no interval timers here (a seccomp allowlist): unwatched
            armed[0] = False
        yield
    finally:
        armed[0] = False
        with contextlib.suppress(OSError):
            signal.setitimer(signal.ITIMER_REAL, 0)
        if previous is not None:
            signal.signal(signal.SIGALRM, previous)
