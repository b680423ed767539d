"""Write every JSON report urdftool gives on robots/ and the corpus into one file, to compare
two versions of the code byte for byte (a speed-up must not change a report).

    python benchmarks/snapshot_reports.py OUT.json [--commands]

`check --format json --jobs 1` over robots/ and every pybullet_data (random_urdfs included) and
example-robot-data URDF, without the mesh cache, then filling an empty one and reading it (the
three must agree); with --commands also `tree`, `limits`, `inertia` (--format json) per
file. Run from the checkout whose code is to be recorded (PYTHONPATH=that checkout)."""

from __future__ import annotations

import json
import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tests.conftest import (
    ROBOTS,
    example_robot_urdfs,
    pybullet_data_dir,
    run_urdftool,
)


def main() -> None:
    out = Path(sys.argv[1])
    out = out.resolve()
    os.chdir(ROOT)  # robots/ by relative paths: two checkouts give the same reports
    robots = sorted(str(p.relative_to(ROOT)) for p in ROBOTS.rglob("*")
                    if p.suffix in (".urdf", ".xacro"))
    corpus = sorted(str(p) for p in pybullet_data_dir().rglob("*.urdf")) + \
        [str(p) for p in example_robot_urdfs()]
    snapshot = {}
    for name, files in (("robots", robots), ("corpus", corpus)):
        result = run_urdftool("check", "--format", "json", "--jobs", "1", "--no-cache", *files)
        snapshot[f"check {name}"] = [result.code, result.out]
        with tempfile.TemporaryDirectory() as cache:
            os.environ["URDFTOOL_CACHE_DIR"] = cache
            for run in ("cold", "warm"):
                again = run_urdftool("check", "--format", "json", "--jobs", "1", *files)
                if again.out != result.out:
                    print(f"check {name}: the report with a {run} cache differs")
    if "--commands" in sys.argv:
        for path in robots + [p for p in corpus if "random_urdfs" not in p]:
            for command in ("tree", "limits", "inertia"):
                result = run_urdftool(command, "--format", "json", path)
                snapshot[f"{command} {path}"] = [result.code, result.out, result.err]
    text = json.dumps(snapshot, indent=1, sort_keys=True)
    for prefix, name in ((sys.prefix, "<python>"), (str(ROOT), "<checkout>")):
        text = text.replace(json.dumps(prefix)[1:-1], name)
    out.write_text(text)
    print(f"{out}: {len(snapshot)} reports")


if __name__ == "__main__":
    main()
