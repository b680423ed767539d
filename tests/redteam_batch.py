"""Runs a red-team plan in one process (``python redteam_batch.py PLAN RESULTS``): each run is
``urdftool ARGS`` in-process (as ``conftest.run_urdftool``), with ``CI=true`` or ``--trusted``,
its output captured, its wall time measured, and the part of it spent waiting for a CPU
that other processes held (``waited``: the tests bound the wall time less that). The
process's peak memory (its own and its sandboxed readers') bounds every run's. A run that
hangs leaves its name in RESULTS.started.
"""

from __future__ import annotations

import io
import json
import os
import resource
import sys
import time


def run(args: list[str], ci: bool) -> tuple[int, str, str]:
    from urdftool.cli import main

    if ci:
        os.environ["CI"] = "true"
    else:
        os.environ.pop("CI", None)
    out, err = io.StringIO(), io.StringIO()
    saved = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = out, err
    try:
        main(args)
        code = 0
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    finally:
        sys.stdout, sys.stderr = saved
    return code, out.getvalue(), err.getvalue()


def _tasks(pid: int) -> list[str]:
    """The threads of ``pid`` and of all its descendants, as /proc/PID/task/TID paths."""
    found, todo = [], [pid]
    while todo:
        current = todo.pop()
        try:
            threads = os.listdir(f"/proc/{current}/task")
        except OSError:  # ended meanwhile
            continue
        for tid in threads:
            found.append(f"/proc/{current}/task/{tid}")
            try:
                with open(f"/proc/{current}/task/{tid}/children", encoding="ascii") as stream:
                    todo.extend(int(child) for child in stream.read().split())
            except OSError:
                pass
    return found


def waited() -> dict[str, float]:
    """Per thread of this process and its live descendants (the sandboxed reader, sim
    workers): seconds spent ready to run while the CPUs ran another process (the run queue,
    /proc/.../schedstat). On a machine shared with other work this is the part of a run's
    wall time that the load, not urdftool, took; a run blocked on a read (a FIFO) is asleep,
    not waiting, and keeps its time."""
    times = {}
    for task in _tasks(os.getpid()):
        try:
            with open(f"{task}/schedstat", encoding="ascii") as stream:
                times[task] = int(stream.read().split()[1]) / 1e9
        except (OSError, IndexError, ValueError):
            pass
    return times


def main() -> None:
    plan_path, results_path = sys.argv[1], sys.argv[2]
    # a run that reads without bound fails here (MemoryError: a finding of the test) rather
    # than taking the machine's memory; the peak measured below is what the test bounds
    resource.setrlimit(resource.RLIMIT_AS, (6 << 30, resource.RLIM_INFINITY))
    with open(plan_path, encoding="utf-8") as stream:
        plan = json.load(stream)
    results = []
    for entry in plan:
        with open(results_path + ".started", "w", encoding="utf-8") as stream:
            stream.write(entry["name"])
        os.chdir(entry["cwd"])
        before = waited()
        started = time.monotonic()
        code, out, err = run(entry["args"], entry["ci"])
        seconds = time.monotonic() - started
        after = waited()
        # the longest wait of one thread: threads waiting side by side (check's worker
        # processes) are not added up, and a process that ended during the run counts nothing
        queued = max((value - before.get(task, 0.0) for task, value in after.items()),
                     default=0.0)
        results.append({**entry, "code": code, "out": out, "err": err, "seconds": seconds,
                        "waited": min(max(queued, 0.0), seconds)})
    sandbox = sys.modules.get("urdftool.sandbox")
    if sandbox is not None:
        sandbox._close_children()  # waited for: its peak is in RUSAGE_CHILDREN
    # this process's own peak (VmHWM: ru_maxrss would count the pytest worker this process
    # was forked from, which Linux keeps across exec), and its children's (the sandboxed
    # readers and sim workers, forked from this small process)
    with open("/proc/self/status", encoding="ascii") as status:
        own = next(int(line.split()[1]) for line in status if line.startswith("VmHWM:"))
    peak = max(own, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
    with open(results_path, "w", encoding="utf-8") as stream:
        json.dump({"runs": results, "peak_mb": peak / 1024}, stream)


def run_plan(plan: list[dict], directory, env: dict, timeout: float) -> dict:
    """The tests' side: ``plan`` run by this script in a fresh process (PLAN and RESULTS in
    ``directory``), its report ({"runs": [...], "peak_mb": ..., "batch_output": ...});
    AssertionError naming the run that hung or the batch's own error."""
    import subprocess
    from pathlib import Path

    plan_path, results = Path(directory) / "plan.json", Path(directory) / "results.json"
    plan_path.write_text(json.dumps(plan))
    root = Path(__file__).resolve().parent.parent
    try:
        done = subprocess.run([sys.executable, __file__, str(plan_path), str(results)], env=env,
                              cwd=root, capture_output=True, text=True, timeout=timeout,
                              check=False)
    except subprocess.TimeoutExpired:
        started = Path(f"{results}.started")
        raise AssertionError(f"hung on {started.read_text() if started.exists() else '?'}") \
            from None
    assert done.returncode == 0, done.stderr[-3000:]
    report = json.loads(results.read_text())
    report["batch_output"] = done.stdout + done.stderr  # what the batch process itself printed
    return report


if __name__ == "__main__":
    main()
