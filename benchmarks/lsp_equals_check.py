"""The language server's engine against ``urdftool check --format json DIR`` on every package
(unit) of ../shared/realworld-dev: the same (rule, file, line, column) set, or the difference.

    python benchmarks/lsp_equals_check.py [SRC_DIR]
"""
import json
import subprocess
import sys
import time
from pathlib import Path

from urdftool.lsp.engine import Engine, Settings, resolved
from urdftool.package import robot_files

ROOT = Path(__file__).resolve().parent.parent
SHARED = next((p for p in (ROOT.parent / "shared", ROOT.parent.parent / "shared") if p.is_dir()),
              ROOT.parent / "shared")
src = Path(sys.argv[1]) if len(sys.argv) > 1 else SHARED / "realworld-dev" / "src"
dirs = set()
for repo in sorted(src.iterdir()):
    for f in robot_files(repo):
        dirs.add(Engine._root(f.resolve()))
dirs = sorted(dirs)
print(len(dirs), "units", flush=True)
same = differ = 0
for d in dirs:
    s, _ = Settings().updated({"trusted": True}, trust=True)
    e = Engine(s)
    first = robot_files(d)[0] if d.is_dir() else d
    t = time.perf_counter()
    roots = e.refresh([str(first)])
    el = time.perf_counter() - t
    res = e.snapshot[roots[0]]
    mine = {(x.rule, k, x.line, x.column) for k, ds in res.diagnostics.items() for x in ds}
    out = subprocess.run([sys.executable, "-m", "urdftool", "check", "--trusted", "--format", "json", str(d)], capture_output=True, text=True, check=False)
    if out.returncode not in (0, 1):
        print("CHECK FAILED", d, out.stderr[-300:], flush=True); continue
    theirs = {(x["rule"], resolved(x["path"]), x["line"], x["column"]) for f in json.loads(out.stdout)["files"] for x in f["diagnostics"]}
    ok = mine == theirs
    same += ok; differ += not ok
    print("OK " if ok else "DIFF", d, len(mine), len(theirs), f"{el:.1f}s", "" if ok else sorted(mine ^ theirs)[:3], flush=True)
print("same", same, "differ", differ)
