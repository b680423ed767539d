"""Baselines (issue 13): record today's findings, then fail only on new ones.

A finding is matched by its rule, its file (relative to the baseline file's directory), its
element (the XPath without positions: ``/robot/link/inertial``) and its message with the numbers
taken out (link and joint names stay), so it survives lines moving and values being retouched.
Matching counts: a finding recorded twice hides two. The file is JSON, sorted, for reviewable
diffs.
"""

from __future__ import annotations

import json
import os
import re
from collections import Counter
from pathlib import Path

from urdftool.errors import ToolError
from urdftool.files import read_regular
from urdftool.report import Diagnostic, Report, sites_text

FORMAT = 1


_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def _record(d: Diagnostic, base: Path) -> dict:
    try:
        path = Path(os.path.relpath(Path(d.path).resolve(), base)).as_posix()
    except ValueError:  # another drive
        path = Path(d.path).resolve().as_posix()
    return {"rule": d.rule, "path": path, "line": d.line,
            "element": re.sub(r"\[\d+\]", "", d.element) if d.element else None,
            "message": d.message[:len(d.message) - len(sites_text(d.call_sites))]}


def _key(record: dict) -> tuple:
    message = re.sub(_NUMBER, "#", record["message"])
    return record["rule"], record["path"], record["element"], message


def write_baseline(report: Report, path: Path) -> None:
    from urdftool.output import write_output

    base = path.resolve().parent
    records = [_record(d, base) for d in report.diagnostics()]
    records.sort(key=lambda r: (r["path"], r["line"] or 0, r["rule"], r["message"]))
    text = json.dumps({"tool": "urdftool", "baseline": FORMAT, "findings": records}, indent=1)
    write_output(text + "\n", str(path))


def read_baseline(path: Path) -> Counter:
    try:
        data = json.loads(read_regular(path).decode("utf-8"))
        records = data["findings"]
        if data.get("baseline") != FORMAT or not isinstance(records, list):
            raise ValueError("not a urdftool baseline")
        return Counter(_key(r) for r in records)
    except FileNotFoundError:
        raise ToolError(f"{path}: no such baseline file (write one with --write-baseline)") \
            from None
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise ToolError(f"{path}: cannot read the baseline: {exc}") from None


def apply_baseline(report: Report, path: Path) -> None:
    """Drop from ``report`` the findings recorded in the baseline at ``path``; say how many
    were hidden and how many recorded ones are gone."""
    recorded = read_baseline(path)
    left = Counter(recorded)
    base = path.resolve().parent
    hidden = 0
    for file in report.files:
        kept = []
        for d in file.diagnostics:
            key = _key(_record(d, base))
            if left[key] > 0:
                left[key] -= 1
                hidden += 1
            else:
                kept.append(d)
        file.diagnostics = kept
    gone = sum(left.values())
    new = len(report.diagnostics())
    report.notes.append(f"baseline {path}: {new} new finding(s), {hidden} recorded one(s) "
                        f"still present, {gone} recorded one(s) gone"
                        + (" (write the baseline again to drop them)" if gone else ""))
