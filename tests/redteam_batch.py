"""Runs a red-team plan in one process (``python redteam_batch.py PLAN RESULTS``): each run is
``urdftool ARGS`` in-process (as ``conftest.run_urdftool``), with ``CI=true`` or ``--trusted``,
its output captured, its wall time measured. The process's peak memory (its own and its
sandboxed readers') bounds every run's. A run that hangs leaves its name in RESULTS.started.
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
        started = time.monotonic()
        code, out, err = run(entry["args"], entry["ci"])
        results.append({**entry, "code": code, "out": out, "err": err,
                        "seconds": time.monotonic() - started})
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


if __name__ == "__main__":
    main()
