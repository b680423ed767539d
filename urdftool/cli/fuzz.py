"""``python -m urdftool.cli.fuzz`` (``make fuzz``): the command line of a fuzz campaign
(``urdftool.fuzz``). A developer's tool, not a ``urdftool`` command."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from urdftool import fuzz


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m urdftool.cli.fuzz",
                                     description=fuzz.__doc__.split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=1000, help="how many mutated cases")
    parser.add_argument("--minutes", type=float, default=None,
                        help="stop after this long even if --cases are not all run")
    parser.add_argument("--seed", type=int, default=0, help="random seed (reproducible runs)")
    parser.add_argument("--out", type=Path, default=None, help="where crash reproducers go")
    parser.add_argument("--time-bound", type=float, default=fuzz.TIME_BOUND,
                        help="seconds one command may take on one case")
    options = parser.parse_args(argv)
    started = time.monotonic()

    def progress(summary: fuzz.Summary) -> None:
        print(f"  {summary.cases} cases, {len(summary.crashes)} crashes, "
              f"{time.monotonic() - started:.0f} s", file=sys.stderr, flush=True)

    summary, out_dir = fuzz.campaign(options.cases, options.seed, options.out, options.time_bound,
                                progress, options.minutes)
    elapsed = time.monotonic() - started
    print(f"fuzz: {summary.cases} cases ({summary.runs} command runs) in {elapsed:.0f} s")
    print(f"crashes: {len(summary.crashes)}")
    for crash in summary.crashes[:50]:
        print(f"  case {crash['case']}: {crash['command']} on {Path(crash['seed']).name} "
              f"[{', '.join(crash['mutations'])}]: {crash['problem'][:200]}\n"
              f"    reproducer: {crash['reproducer']}")
    if summary.crashes:
        print(f"reproducers in {out_dir}")
    print(f"slowest: {summary.slowest[0]:.2f} s ({summary.slowest[1]})")
    return 1 if summary.crashes else 0


if __name__ == "__main__":
    sys.exit(main())
