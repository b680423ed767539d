"""The trusted watchdog outside the main thread (issue 21): the language server checks in a
worker thread, where no timer signal reaches; ``budget.watchdog`` hands the exception over
from a timer thread instead, only while the thread runs the watched code, never after the
block."""

from __future__ import annotations

import threading
import time

import xacro

from urdftool import budget

# a loop that counts nothing, compiled as xacro's own code (what the watchdog is for: xacro's
# and PyYAML's loops that the interpreter's clock never sees)
LOOP = "def spin(end):\n    while time.monotonic() < end:\n        pass\n"


def _compiled(filename: str):
    namespace: dict = {}
    exec(compile(LOOP, filename, "exec"), {"time": time}, namespace)  # noqa: S102 - our text
    return namespace["spin"]


XACRO_SPIN = _compiled(xacro.__file__)


def _in_worker(work) -> dict:
    result: dict = {}

    def run():
        started = time.monotonic()
        try:
            work()
            result["outcome"] = "ended"
        except TimeoutError as exc:
            result["outcome"] = f"interrupted: {exc}"
        result["seconds"] = time.monotonic() - started

    worker = threading.Thread(target=run)
    worker.start()
    worker.join(60)
    assert not worker.is_alive()
    return result


def late() -> TimeoutError:
    return TimeoutError("late")


def test_a_worker_thread_is_interrupted_in_the_watched_code():
    def work():
        with budget.watchdog(0.3, late, ("/xacro/",)):
            XACRO_SPIN(time.monotonic() + 20)

    result = _in_worker(work)
    assert result["outcome"] == "interrupted: late"
    assert 0.3 <= result["seconds"] < 1.5, result


def test_only_the_watched_code_and_never_after_the_block():
    def work():
        with budget.watchdog(0.1, late, ("/xacro/",)):
            end = time.monotonic() + 0.5
            while time.monotonic() < end:  # this file's code: not watched, runs to its end
                pass
        XACRO_SPIN(time.monotonic() + 0.4)  # watched code, after the block: left alone

    result = _in_worker(work)
    assert result["outcome"] == "ended"
    assert result["seconds"] >= 0.9


def test_a_trusted_expansion_in_a_worker_thread_stops_at_its_timeout(tmp_path, monkeypatch):
    """A check from a worker thread (as the language server's) whose expansion is stuck in
    xacro's own code (a loop no counting of urdftool's sees) ends at --timeout with the
    limit finding, not 20 s later."""
    from urdftool.check import CheckOptions, check_file
    from urdftool.source import LoadOptions

    stuck = _compiled(xacro.__file__)
    original = xacro.eval_text

    def eval_text(text, symbols):
        if "stuck" in text:
            stuck(time.monotonic() + 20)
        return original(text, symbols)

    monkeypatch.setattr(xacro, "eval_text", eval_text)
    path = tmp_path / "robot.urdf.xacro"
    path.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                    '  <link name="base"/>\n  <link name="${\'stuck\'}"/>\n</robot>\n')
    found = {}

    def work():
        report = check_file(path, CheckOptions(load=LoadOptions(timeout=1.0)))
        found["rules"] = [(d.rule, d.message) for d in report.diagnostics]

    result = _in_worker(work)
    assert result["outcome"] == "ended"
    assert result["seconds"] < 1.0 + 1.5, result
    stopped = "xacro: xacro expansion took longer than the time limit; expansion stopped"
    assert ("xacro.limit-exceeded", stopped) in found["rules"], found


def test_the_watched_code_is_where_the_libraries_are_installed():
    """The watchdog may interrupt xacro's, PyYAML's and minidom's code as installed, and the
    interpreter: matched by their directories, never by a folder name a checkout's path holds
    (a clone under `.../xacro/` is not xacro's code: urdftool's patching of xacro there must
    never be interrupted)."""
    import types
    import xml.dom

    import yaml

    from urdftool import xacro_eval, xacro_expand

    watched = xacro_expand.watched_code()
    for module in (xacro, yaml, xml.dom):
        inside = types.SimpleNamespace(f_code=types.SimpleNamespace(
            co_filename=module.__file__), f_back=None)
        assert budget._interruptible(inside, watched), module.__name__
    own = types.SimpleNamespace(f_code=types.SimpleNamespace(co_filename=xacro_eval.__file__),
                                f_back=None)
    assert budget._interruptible(own, watched)
    for elsewhere in ("/home/u/xacro/urdftool/xacro_expand.py", "/srv/yaml/urdftool/check.py",
                      xacro_expand.__file__):
        frame = types.SimpleNamespace(f_code=types.SimpleNamespace(co_filename=elsewhere),
                                      f_back=None)
        assert not budget._interruptible(frame, watched), elsewhere
