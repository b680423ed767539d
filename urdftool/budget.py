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
and PyYAML in this process under ``--trusted``): at the deadline ``make_exception()`` is
raised in the block, then again every ``REPEAT`` seconds until the block ends, so that a
handler that swallows one exception does not keep it running. In the main thread a timer
signal (``setitimer``) raises it; in another thread (the language server checks in a worker
thread) a timer thread hands it over with ``PyThreadState_SetAsyncExc``, which the thread
raises at its next call or loop iteration.

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


_paused = 0.0  # CPU seconds of the threads in ``paused()`` blocks, in this process


@contextlib.contextmanager
def paused():
    """A block whose CPU time the rules' clock (``rules.run``: the thread's CPU time) does not
    count (issue 28): reading a mesh for a rule (its libraries' imports and parsing, bounded by
    the mesh reader's own size and time limits), so that a cold mesh cache is not a rule out
    of time."""
    global _paused
    started = time.thread_time()
    try:
        yield
    finally:
        _paused += time.thread_time() - started


def paused_total() -> float:
    return _paused


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
def watchdog(seconds: float | None, make_exception, inside: tuple[str, ...] = (), due=None):
    """Run the block with ``make_exception()`` raised in it after ``seconds`` (then every
    REPEAT seconds until it ends), only while code whose file's path holds one of ``inside``
    runs (a library's own loops, not the caller's bookkeeping), and, with ``due``, only once
    ``due()`` says the time is really out (a clock that leaves time out: ``paused``). Only in the main thread of a process with interval timers
    (elsewhere the block runs unwatched: its own counting bounds it); a watchdog inside
    another keeps the outer one's timer."""
    import signal
    import threading

    if seconds is None:
        yield
        return
    if threading.current_thread() is not threading.main_thread():
        with _thread_watchdog(seconds, make_exception, inside, due):
            yield
        return
    try:
        busy = signal.getitimer(signal.ITIMER_REAL)[0] > 0
    except (OSError, AttributeError):  # no interval timers (a seccomp allowlist, not Unix)
        busy = True
    if busy:
        yield
        return
    armed = [True]

    def interrupt(signum, frame):
        # only inside the watched code, never in an import (a module left half-initialised
        # breaks every later run of the process): the timer fires again REPEAT seconds later
        if not armed[0] or not _interruptible(frame, inside) or (due is not None and not due()):
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


_WATCHED: set[int] = set()  # threads (idents) under a thread watchdog: an inner one keeps it


@contextlib.contextmanager
def _thread_watchdog(seconds: float, make_exception, inside: tuple[str, ...], due=None):
    """``watchdog`` in a thread other than the main one: a timer thread raises an exception
    of ``make_exception()``'s type and message in this thread (``PyThreadState_SetAsyncExc``,
    CPython), only while this thread runs ``inside`` code outside an import, then every
    REPEAT seconds until the block ends. The thread's frame is looked at before and after the
    exception is handed over: when it has moved out of the watched code in between, the
    exception is taken back before it is raised. Elsewhere (not CPython) the block runs
    unwatched."""
    import ctypes
    import sys
    import threading

    target = threading.get_ident()
    try:
        api = ctypes.pythonapi  # (PYFUNCTYPE: the calls keep the GIL)
        hand = ctypes.PYFUNCTYPE(ctypes.c_int, ctypes.c_ulong, ctypes.py_object)(
            ("PyThreadState_SetAsyncExc", api))
        take_back = ctypes.PYFUNCTYPE(ctypes.c_int, ctypes.c_ulong, ctypes.c_void_p)(
            ("PyThreadState_SetAsyncExc", api))
    except (AttributeError, OSError):
        hand = None
    if hand is None or target in _WATCHED:
        yield
        return
    sample = make_exception()
    base = type(sample)
    # the exception is raised from its type, without arguments: a subclass that carries them
    late = type(base.__name__, (base,), {"__init__": lambda self: base.__init__(self, *sample.args),
                                         "__module__": base.__module__})
    state = threading.Condition()
    armed = [True]

    def frame_ok() -> bool:
        frame = sys._current_frames().get(target)
        return frame is not None and _interruptible(frame, inside) and (due is None or due())

    def run() -> None:
        wait = max(seconds, 0.001)
        with state:
            while True:
                state.wait(wait)
                if not armed[0]:
                    return
                wait = REPEAT
                if frame_ok():
                    hand(target, late)
                    if not frame_ok():  # moved on (an import?) before it was raised
                        take_back(target, None)

    timer = threading.Thread(target=run, name="urdftool-watchdog", daemon=True)
    _WATCHED.add(target)
    timer.start()
    try:
        yield
    finally:
        armed[0] = False  # first (no call before it): the timer hands nothing more over
        try:
            with state:
                take_back(target, None)  # handed over, not raised yet: never after the block
                state.notify_all()
        finally:
            _WATCHED.discard(target)
