"""Diagnostics, the report of a ``check`` run, and its formatters (text, json, sarif, github).
Plain records (no dataclasses): this module is imported by every ``urdftool check``.

Formatters return strings; the CLI prints them. Floats in machine output are never rounded.
"""


import json
from typing import NamedTuple

from urdftool import __version__
from urdftool.model import Loc

SEVERITIES = ("error", "warning", "info")


class Finding(NamedTuple):
    """What a rule found: a message at a place, with an optional fix hint.

    ``severity`` overrides the rule's default when a rule grades its own findings
    (e.g. 2x over a bound is an error, 1x-2x a warning).
    """

    message: str
    loc: Loc | None
    hint: str | None = None
    severity: str | None = None


class Diagnostic(NamedTuple):
    rule: str
    severity: str
    message: str
    path: str
    line: int | None
    column: int | None
    element: str | None
    hint: str | None
    # inside a macro body: how many instances share this finding, and the call sites of each
    # (innermost call first, as "path:line")
    instances: int = 1
    call_sites: tuple[tuple[str, ...], ...] = ()

    def to_json(self) -> dict:
        data = self._asdict()
        if not self.call_sites:
            del data["instances"], data["call_sites"]
        else:
            data["call_sites"] = [list(chain) for chain in self.call_sites]
        return data


def sites_text(call_sites) -> str:
    """What a message says of the macro instances it was found in."""
    if not call_sites:
        return ""
    if len(call_sites) == 1:
        return " (expanded from the macro call at " + ", called from ".join(call_sites[0]) + ")"
    shown = ", ".join(" from ".join(chain) for chain in call_sites[:8])
    more = f", and {len(call_sites) - 8} more" if len(call_sites) > 8 else ""
    return f" (in {len(call_sites)} instances: {shown}{more})"


def _shape(message: str) -> str:
    """A message with its numbers and quoted names masked: the same finding in two macro
    instances (other names, other values) has the same shape."""
    import re

    return re.sub(r"'[^']*'|\"[^\"]*\"|[-+]?\d[\d.eE+-]*", "#", message)


def group_instances(diagnostics: list[Diagnostic]) -> list[Diagnostic]:
    """One diagnostic per written line: the findings that macro instances share (same rule,
    place and shape of message, other call sites) become one, with the instances and their call
    sites. Diagnostics carry their own call site and no suffix yet; the message gets it here."""
    groups: dict[tuple, list[Diagnostic]] = {}
    order: list[tuple] = []
    for d in diagnostics:
        if not d.call_sites:
            key: tuple = (id(d),)
        else:
            base = (d.rule, d.severity, d.path, d.line, d.column, _shape(d.message))
            number = 0  # two findings of one instance at one place stay two
            while (base, number) in groups and any(
                    g.call_sites == d.call_sites for g in groups[(base, number)]):
                number += 1
            key = (base, number)
        if key not in groups:
            groups[key] = []
            order.append(key)
        groups[key].append(d)
    result = []
    for key in order:
        members = groups[key]
        first = members[0]
        if not first.call_sites:
            result.append(first)
            continue
        sites = tuple(dict.fromkeys(site for d in members for site in d.call_sites))
        result.append(first._replace(message=first.message + sites_text(sites),
                                     instances=len(sites), call_sites=sites))
    return result


def merge_repeats(files: list["FileReport"]) -> list["FileReport"]:
    """A finding in a file that several checks read (a fragment of several entries, an entry
    with several argument sets) is kept once, in the first report, with the instances of all."""
    first: dict[tuple, tuple[FileReport, int]] = {}
    for report in files:
        kept = []
        for d in report.diagnostics:
            base = d.message[:len(d.message) - len(sites_text(d.call_sites))]
            key = (d.rule, d.severity, d.path, d.line, d.column,
                   _shape(base) if d.call_sites else base)
            if key not in first:
                first[key] = (report, len(kept))
                kept.append(d)
                continue
            owner, index = first[key]
            if owner is report:  # two findings of one check at one place: both stay
                kept.append(d)
                continue
            seen = owner.diagnostics[index] if owner is not report else kept[index]
            sites = tuple(dict.fromkeys(seen.call_sites + d.call_sites))
            if sites != seen.call_sites:
                seen_base = seen.message[:len(seen.message) - len(sites_text(seen.call_sites))]
                owner.diagnostics[index] = seen._replace(
                    message=seen_base + sites_text(sites), instances=len(sites),
                    call_sites=sites)
        report.diagnostics = kept
    return files


class FileReport:
    __slots__ = ("args", "diagnostics", "includes", "path", "robot", "role", "texts")

    def __init__(self, path: str, robot: str | None, diagnostics: list[Diagnostic] | None = None,
                 texts: dict[str, str] | None = None):
        self.path = path
        self.robot = robot
        self.diagnostics = diagnostics if diagnostics is not None else []
        self.texts = texts if texts is not None else {}  # for source excerpts
        self.args: dict[str, str] = {}  # the xacro arguments of this check (configured entries)
        self.includes: tuple[str, ...] = ()  # every other file the check read (resolved paths)
        self.role = "entry"  # or "fragment": holds only definitions (urdftool.package)

    def to_json(self) -> dict:
        data = {"path": self.path, "robot": self.robot,
                "diagnostics": [d.to_json() for d in self.diagnostics]}
        if self.args:
            data["args"] = self.args
        return data


class Report:
    __slots__ = ("files", "notes")

    def __init__(self, files: list[FileReport] | None = None, notes: list[str] | None = None):
        self.files = files if files is not None else []
        self.notes = notes if notes is not None else []  # one line each, for stderr

    def count(self, severity: str) -> int:
        return sum(d.severity == severity for f in self.files for d in f.diagnostics)

    def diagnostics(self) -> list[Diagnostic]:
        return [d for f in self.files for d in f.diagnostics]

    def exit_code(self, strict: bool = False) -> int:
        failing = ("error", "warning") if strict else ("error",)
        return 1 if any(d.severity in failing for d in self.diagnostics()) else 0

    def summary(self) -> dict:
        return {"files": len(self.files), "errors": self.count("error"),
                "warnings": self.count("warning"), "infos": self.count("info")}

    def to_json(self) -> dict:
        return {"tool": "urdftool", "version": __version__,
                "files": [f.to_json() for f in self.files], "summary": self.summary()}


def format_json(report: Report) -> str:
    return json.dumps(report.to_json(), indent=2)


def format_github(report: Report) -> str:
    """GitHub Actions workflow commands (::error file=...,line=...::message)."""
    level = {"error": "error", "warning": "warning", "info": "notice"}

    def escape(value: str, prop: bool = False) -> str:
        value = value.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")
        return value.replace(":", "%3A").replace(",", "%2C") if prop else value

    lines = []
    for d in report.diagnostics():
        props = [f"file={escape(d.path, True)}"]
        if d.line:
            props.append(f"line={d.line}")
        if d.column:
            props.append(f"col={d.column}")
        props.append(f"title={escape(d.rule, True)}")
        text = d.message + (f" (fix: {d.hint})" if d.hint else "")
        lines.append(f"::{level[d.severity]} {','.join(props)}::{escape(text)}")
    return "\n".join(lines)


def format_sarif(report: Report, rule_docs: dict[str, str] | None = None) -> str:
    """SARIF 2.1.0, one run, rules listed in the driver."""
    level = {"error": "error", "warning": "warning", "info": "note"}
    rule_ids = sorted({d.rule for d in report.diagnostics()})
    rules = [{"id": r, "shortDescription": {"text": (rule_docs or {}).get(r, r)}} for r in rule_ids]
    results = []
    for d in report.diagnostics():
        region = {}
        if d.line:
            region["startLine"] = d.line
        if d.column:
            region["startColumn"] = d.column
        location = {"physicalLocation": {"artifactLocation": {"uri": d.path}}}
        if region:
            location["physicalLocation"]["region"] = region
        message = d.message + (f" Fix: {d.hint}" if d.hint else "")
        results.append({"ruleId": d.rule, "ruleIndex": rule_ids.index(d.rule),
                        "level": level[d.severity], "message": {"text": message},
                        "locations": [location]})
    sarif = {
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [{"tool": {"driver": {"name": "urdftool", "version": __version__,
                                      "informationUri": "https://pypi.org/project/urdftool/",
                                      "rules": rules}},
                  "results": results}],
    }
    return json.dumps(sarif, indent=2)


def render_text(report: Report, make_console) -> None:
    """Human output on a rich console (``make_console()``): file:line:col, severity, rule,
    message, the source line with a caret, the hint; then a summary line. A report without
    findings is the summary line alone, written without rich: importing rich would be half the
    start-up of a clean run (a pre-commit hook's usual case)."""
    s = report.summary()
    colour = "red" if s["errors"] else ("yellow" if s["warnings"] else "green")
    summary = (f"{s['files']} file(s): {s['errors']} error(s), {s['warnings']} warning(s), "
               f"{s['infos']} info")
    if not any(file.diagnostics for file in report.files):
        import os

        import click

        colour_on = None if not os.environ.get("NO_COLOR") else False  # None: when a terminal
        click.echo(click.style(summary, fg=colour), color=colour_on)
        return
    from rich.markup import escape
    from rich.text import Text

    console = make_console()
    style = {"error": "bold red", "warning": "yellow", "info": "cyan"}
    for file in report.files:
        for d in file.diagnostics:
            where = d.path + (f":{d.line}" if d.line else "") + (f":{d.column}" if d.column else "")
            console.print(f"[bold]{escape(where)}[/]: [{style[d.severity]}]{d.severity}[/] "
                          f"[dim]{d.rule}[/] {escape(d.message)}", highlight=False)
            text = file.texts.get(d.path)
            if text is not None and d.line:
                lines = text.splitlines()
                if 0 < d.line <= len(lines):
                    source_line = lines[d.line - 1].expandtabs(4)
                    console.print(Text(f"  {d.line:>5} | {source_line}", style="dim"))
                    if d.column:
                        console.print(Text(" " * (10 + d.column - 1) + "^", style=style[d.severity]))
            if d.hint:
                console.print(f"        [green]fix:[/] {escape(d.hint)}", highlight=False)
    console.print(f"[{colour}]{summary}[/]", highlight=False)
