"""Per-finding waivers for the no-false-alarm corpus (tests/test_corpus.py, the data in it and in
tests/test_inertia_corpus.py).

A waiver names ONE finding of a corpus file: its rule, the line it points at, and a fragment of
its message that tells it from the other findings of that rule on that line (the link, joint,
material or attribute it names), under the reason the finding is a genuine defect. Findings
that share a reason share one entry, the reason written once:

    (rule, reason, {file: [(line, fragment), ...], ...})

with ``**in_each((file, file, ...), [(line, fragment), ...])`` for copies of one file whose
findings stand on the same lines.

``(line, fragment, n)`` names n identical findings on one line (legitimate only when the file
really repeats the defect there; the corpus has none today). A finding without a line is named
with line ``None``: it matches only findings without a line (none in the corpus today).

``problems`` fails a file on: a finding no waiver names (a new false alarm, or a new genuine
defect: add it under its reason), a finding two waivers name (a fragment too loose), and a
waiver that names no finding (stale: the defect is gone or the rule lost the case) or not as
many as it says. The lists were written once from the findings and reviewed against their
reasons; they are never regenerated from urdftool's output at test time.
"""

from __future__ import annotations

from typing import NamedTuple

Instance = tuple[int | None, str] | tuple[int | None, str, int]
Entry = tuple[str, str, dict[str, list[Instance]]]  # (rule, reason, {file: instances})


class Waiver(NamedTuple):
    rule: str
    line: int | None
    fragment: str
    count: int  # how many identical findings it names (1 but for a repeated defect)
    reason: str


def in_each(names: tuple[str, ...], instances: list[Instance]) -> dict[str, list[Instance]]:
    """The same waivers for each of several files (copies with the defect on the same lines)."""
    return {name: list(instances) for name in names}


def by_file(entries: list[Entry]) -> dict[str, list[Waiver]]:
    waivers: dict[str, list[Waiver]] = {}
    for rule, reason, files in entries:
        for name, instances in files.items():
            for line, fragment, *count in instances:
                waivers.setdefault(name, []).append(
                    Waiver(rule, line, fragment, count[0] if count else 1, reason))
    return waivers


def problems(findings, waivers: list[Waiver]) -> list[str]:
    """What is wrong between a file's findings (errors and warnings: objects with rule, line,
    severity and message) and its waivers; empty when each finding is named by exactly one
    waiver and each waiver names as many findings as it says."""
    matched = [0] * len(waivers)
    out = []
    for finding in findings:
        names = [index for index, waiver in enumerate(waivers)
                 if waiver.rule == finding.rule and waiver.line == finding.line
                 and waiver.fragment in finding.message]
        where = f"line {finding.line}: {finding.severity} {finding.rule} {finding.message}"
        if not names:
            out.append(f"{where}\n    no waiver names this finding")
        elif len(names) > 1:
            out.append(f"{where}\n    named by {len(names)} waivers: "
                       + ", ".join(repr(waivers[index].fragment) for index in names))
        for index in names:
            matched[index] += 1
    for waiver, count in zip(waivers, matched):
        if count != waiver.count:
            out.append(f"waiver {waiver.rule} (line {waiver.line}, {waiver.fragment!r}) names "
                       f"{waiver.count} finding(s) but matches {count}"
                       + (" (stale)" if not count else ""))
    return out
