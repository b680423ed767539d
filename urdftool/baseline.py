"""Baselines (issues 13, 23): record today's findings, then fail only on new ones.

A finding is matched by its rule, its file, its element (the XPath without positions:
``/robot/link/inertial``) and its message with the numbers that are values taken out (digits in
a name stay: ``wheel_1`` is not ``wheel_2``),
so it survives lines moving and values being retouched.

Portable (issue 23): files and every path a message names are written relative to the
repository root (the nearest directory above the baseline file holding ``.git``, else the
baseline file's directory), never absolute and never relative to the working directory, so a
baseline written in one clone matches in another clone at another path, run from any directory.
A path outside the repository (an installed package) is matched by its file name only.

Matching counts: a finding recorded twice hides two. A run that saw only some files (``check
--changed``, a subdirectory, ``--fix``, a file whose expansion failed) counts as "gone" only the
recorded findings of the files whose findings it computed in full (``Report.seen``). The file is JSON, sorted, for
reviewable diffs.
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

# a number that is a value: not inside a name (``wheel_1``, ``link2``, ``arm-3``, ``j1.5``: the
# digits of a name tell one link from another, issue 28.8)
_NUMBER = r"(?<![\w.-])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?!\w|\.\d)"
# a path in a message: absolute (with or without file://), or relative with a directory in it
# an absolute path: after file://, or not inside a word, a URI (package://) or another path
_ABSOLUTE = re.compile(r"(?:file://|(?<![\w:/.~-]))(/[^\s'\"(),:;]+)")
_RELATIVE = re.compile(r"(?<![\w/.:~-])((?:\.\.?/)*[\w.~-]+(?:/[\w.~-]+)+)")


def repository_root(baseline: Path) -> Path:
    """The directory the baseline's paths are relative to: the nearest one above the baseline
    file holding ``.git`` (a clone, a worktree), else the baseline file's own directory."""
    start = Path(os.path.abspath(baseline)).parent
    for directory in (start, *start.parents):
        if (directory / ".git").exists():
            return directory
    return start


class _Paths:
    """Paths of findings and messages made relative to one repository root."""

    def __init__(self, root: Path):
        self.root = root
        # the root as the run may spell it: as given and with its symbolic links resolved
        self.prefixes = sorted({str(root), os.path.realpath(root)}, key=len, reverse=True)

    def relative(self, path: str) -> str | None:
        """``path`` (absolute, or relative to the working directory) relative to the root, or
        None when it lies outside."""
        full = os.path.abspath(path)
        for candidate in (full, os.path.realpath(full)):
            for prefix in self.prefixes:
                if candidate == prefix or candidate.startswith(prefix.rstrip(os.sep) + os.sep):
                    return Path(os.path.relpath(candidate, prefix)).as_posix()
        return None

    def file(self, path: str) -> str:
        found = self.relative(path)
        return found if found is not None else Path(path).name

    def message(self, text: str) -> str:
        """A message with every path the run spelled its own way (absolute, or relative to
        the working directory) written relative to the root; a path outside it by its name."""
        def absolute(match: re.Match) -> str:
            found = self.relative(match.group(1))
            return found if found is not None else "<outside>/" + Path(match.group(1)).name

        def relative(match: re.Match) -> str:
            token = match.group(1)
            if not os.path.exists(token):
                return token
            found = self.relative(token)
            return found if found is not None else "<outside>/" + Path(token).name

        return _RELATIVE.sub(relative, _ABSOLUTE.sub(absolute, text))


def _record(d: Diagnostic, paths: _Paths) -> dict:
    return {"rule": d.rule, "path": paths.file(d.path), "line": d.line,
            "element": re.sub(r"\[\d+\]", "", d.element) if d.element else None,
            "message": paths.message(d.message[:len(d.message) - len(sites_text(d.call_sites))])}


def _key(record: dict) -> tuple:
    message = re.sub(_NUMBER, "#", record["message"])
    return record["rule"], record["path"], record["element"], message


def write_baseline(report: Report, path: Path) -> None:
    from urdftool.output import write_output

    paths = _Paths(repository_root(path))
    records = [_record(d, paths) for d in report.diagnostics()]
    records.sort(key=lambda r: (r["path"], r["line"] or 0, r["rule"], r["message"]))
    text = json.dumps({"tool": "urdftool", "baseline": FORMAT, "findings": records}, indent=1)
    write_output(text + "\n", str(path))


# a baseline holds a record (~300 bytes) per accepted finding: tens of thousands fit; a larger
# file is refused unread (issue 21: JSON parsing is linear, the matching is per finding)
MAX_BASELINE_BYTES = 8 << 20


def read_baseline(path: Path) -> list[dict]:
    try:
        data = json.loads(read_regular(path, MAX_BASELINE_BYTES).decode("utf-8"))
        records = data["findings"]
        if data.get("baseline") != FORMAT or not isinstance(records, list):
            raise ValueError("not a urdftool baseline")
        for record in records:
            _key(record)
            if not isinstance(record["path"], str):
                raise TypeError("a finding without a path")
        return records
    except FileNotFoundError:
        raise ToolError(f"{path}: no such baseline file (write one with --write-baseline)") \
            from None
    except (OSError, ValueError, KeyError, TypeError, RecursionError) as exc:
        raise ToolError(f"{path}: cannot read the baseline: {exc}") from None


def apply_baseline(report: Report, path: Path) -> None:
    """Drop from ``report`` the findings recorded in the baseline at ``path``; say how many
    were hidden and how many recorded ones are gone (among the files the run saw)."""
    records = read_baseline(path)
    paths = _Paths(repository_root(path))
    # a finding matches only records of its own file, so every record may hide one; "gone" is
    # said only of the files whose findings the run computed in full (``Report.seen``: not the
    # entries a --fix or --changed run never looked at, nor an expansion that failed)
    left = Counter(_key(r) for r in records)
    hidden = 0
    for file in report.files:
        kept = []
        for d in file.diagnostics:
            key = _key(_record(d, paths))
            if left[key] > 0:
                left[key] -= 1
                hidden += 1
            else:
                kept.append(d)
        file.diagnostics = kept
    seen = getattr(report, "seen", None)
    visible = None if seen is None else {paths.file(p) for p in seen}
    gone = sum(count for key, count in left.items() if visible is None or key[1] in visible)
    new = len(report.diagnostics())
    report.notes.append(f"baseline {path}: {new} new finding(s), {hidden} recorded one(s) "
                        f"still present, {gone} recorded one(s) gone"
                        + (" (write the baseline again to drop them)" if gone else ""))
