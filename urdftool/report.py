"""Diagnostics, the report of a ``check`` run, and its formatters (text, json, sarif, github,
statistics). Plain records (no dataclasses): this module is imported by every ``urdftool check``.

Formatters return strings; the CLI prints them. Floats in machine output are never rounded; file
content in human output goes through ``urdftool.display`` (escaped, one location format).
"""


import json
import re
from typing import NamedTuple

from urdftool import __version__
from urdftool.findings import SEVERITIES, Finding, Loc  # noqa: F401 - re-exported


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
    fix: object = None  # urdftool.edits.Fix, when the finding has one

    def to_json(self) -> dict:
        from urdftool.display import clip

        data = self._asdict()
        data["message"], data["hint"] = clip(self.message), clip(self.hint)
        data["element"] = clip(self.element)
        if not self.call_sites:
            del data["instances"], data["call_sites"]
        else:
            data["call_sites"] = [list(chain) for chain in self.call_sites]
        if self.fix is None:
            del data["fix"]
        else:
            data["fix"] = self.fix.to_json()
        return data


def sites_text(call_sites) -> str:
    """What a message says of the macro instances it was found in."""
    if not call_sites:
        return ""
    if len(call_sites) == 1:
        return " (expanded from the macro call at " + _chain(call_sites[0]) + ")"
    shown = ", ".join(_chain(chain, " from ") for chain in call_sites[:SITES_SHOWN])
    more = f", and {len(call_sites) - SITES_SHOWN} more" if len(call_sites) > SITES_SHOWN else ""
    return f" (in {len(call_sites)} instances: {shown}{more})"


SITES_SHOWN = 3  # call sites a message names (JSON's call_sites has every one)
CHAIN_SHOWN = 3  # calls of one site's chain a message names: the innermost, ..., the outermost


def _chain(chain, joint: str = ", called from ") -> str:
    """A call chain (innermost first) as a message says it: at most ``CHAIN_SHOWN`` calls, the
    outermost last."""
    if len(chain) <= CHAIN_SHOWN:
        return joint.join(chain)
    return joint.join((*chain[:CHAIN_SHOWN - 1], f"({len(chain) - CHAIN_SHOWN} more)",
                       chain[-1]))


def _shape(message: str) -> str:
    """A message with its numbers and quoted names masked: the same finding in two macro
    instances (other names, other values) has the same shape."""
    return re.sub(r"'[^']*'|\"[^\"]*\"|[-+]?\d[\d.eE+-]*", "#", message)


_QUOTED = re.compile(r"'[^']*'|\"[^\"]*\"")
_FILE_NAME = re.compile(r"/|\.[A-Za-z][A-Za-z0-9]{0,4}['\"]$")
OTHERS = "; other instances name "  # the files a grouped finding's other instances name


def _with_others(message: str, messages) -> str:
    """``message`` (without an ``OTHERS`` part) naming the files the other ``messages`` of its
    group name and it does not (instances of one macro line missing ``wrist1.dae``,
    ``wrist2.dae``...: one finding at the line, no file hidden)."""
    own = {t for t in _QUOTED.findall(message) if _FILE_NAME.search(t)}
    others = list(dict.fromkeys(t for m in messages for t in _QUOTED.findall(m)
                                if _FILE_NAME.search(t) and t not in own))
    if not others:
        return message
    return message + OTHERS + ", ".join(others[:3]) + (
        f" and {len(others) - 3} more" if len(others) > 3 else "")


def group_instances(diagnostics: list[Diagnostic]) -> list[Diagnostic]:
    """One diagnostic per written line: the findings that macro instances share (same rule,
    place and shape of message, other call sites) become one, with the instances and their call
    sites. Diagnostics carry their own call site and no suffix yet; the message gets it here."""
    groups: dict[tuple, list[Diagnostic]] = {}
    sites_in: dict[tuple, set] = {}  # the call sites of a group's members (a set: thousands)
    order: list[tuple] = []
    for d in diagnostics:
        if not d.call_sites:
            key: tuple = (id(d),)
        else:
            base = (d.rule, d.severity, d.path, d.line, d.column, _shape(d.message))
            number = 0  # two findings of one instance at one place stay two
            while (base, number) in groups and d.call_sites in sites_in[(base, number)]:
                number += 1
            key = (base, number)
        if key not in groups:
            groups[key] = []
            sites_in[key] = set()
            order.append(key)
        groups[key].append(d)
        sites_in[key].add(d.call_sites)
    result = []
    for key in order:
        members = groups[key]
        first = members[0]
        if not first.call_sites:
            result.append(first)
            continue
        sites = tuple(dict.fromkeys(site for d in members for site in d.call_sites))
        fixes = [d.fix for d in members if d.fix is not None]  # each instance's edits
        fix = fixes[0]._replace(edits=tuple(dict.fromkeys(
            e for f in fixes for e in f.edits))) if fixes else None
        message = _with_others(first.message, [d.message for d in members])
        result.append(first._replace(message=message + sites_text(sites),
                                     instances=len(sites), call_sites=sites, fix=fix))
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
                   _shape(base.split(OTHERS)[0]) if d.call_sites else base)
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
            seen_base = seen.message[:len(seen.message) - len(sites_text(seen.call_sites))]
            named = _with_others(seen_base.split(OTHERS)[0], [seen_base, base])
            if sites != seen.call_sites or named != seen_base:
                owner.diagnostics[index] = seen._replace(
                    message=named + sites_text(sites), instances=len(sites),
                    call_sites=sites)
        report.diagnostics = kept
    return files


class FileReport:
    __slots__ = ("args", "companion", "diagnostics", "includes", "missing", "path", "robot",
                 "role", "texts")

    def __init__(self, path: str, robot: str | None, diagnostics: list[Diagnostic] | None = None,
                 texts: dict[str, str] | None = None):
        self.path = path
        self.robot = robot
        self.diagnostics = diagnostics if diagnostics is not None else []
        self.texts = texts if texts is not None else {}  # for source excerpts
        self.args: dict[str, str] = {}  # the xacro arguments of this check (configured entries)
        self.includes: tuple[str, ...] = ()  # every other file the check read (resolved paths)
        # files the check asked for that are not there: resolved -> [(file, line) that asked]
        self.missing: dict[str, list[tuple[str, int | None]]] = {}
        self.role = "entry"  # or "fragment": holds only definitions (urdftool.package)
        # a companion file's check (an SRDF, a controllers YAML: issue 31): the files of the robot
        # it was checked against (resolved), kept apart from ``includes`` (an SRDF does not make
        # its robot a fragment); changed-files mode re-checks the companion when one changes
        self.companion: tuple[str, ...] = ()

    def to_json(self, per_rule: int | None = None) -> dict:
        """The file's report; with ``per_rule``, at most that many findings of one rule in one
        file, the rest counted in ``omitted`` (rule -> count)."""
        kept, omitted = capped(self.diagnostics, per_rule)
        data = {"path": self.path, "robot": self.robot,
                "diagnostics": [d.to_json() for d in kept]}
        if omitted:
            data["omitted"] = omitted
        if self.args:
            data["args"] = self.args
        return data


# machine formats list at most this many findings of one rule in one file (a hostile file of
# thousands of one defect would otherwise make a report many times its size); the rest are
# counted (``omitted``), and the summary and exit code count every one
MACHINE_PER_RULE = 200


def capped(diagnostics: list[Diagnostic], per_rule: int | None) -> tuple[list, dict[str, int]]:
    """(the diagnostics listed, rule -> how many more of it are not): at most ``per_rule``
    of one rule in one written file (all without a limit)."""
    if per_rule is None:
        return diagnostics, {}
    counts: dict[tuple[str, str], int] = {}
    kept, omitted = [], {}
    for d in diagnostics:
        key = (d.rule, d.path)
        counts[key] = counts.get(key, 0) + 1
        if counts[key] > per_rule:
            omitted[d.rule] = omitted.get(d.rule, 0) + 1
        else:
            kept.append(d)
    return kept, omitted


class Report:
    __slots__ = ("files", "notes", "seen")

    def __init__(self, files: list[FileReport] | None = None, notes: list[str] | None = None):
        self.files = files if files is not None else []
        self.notes = notes if notes is not None else []  # one line each, for stderr
        # the files (resolved) whose findings this report holds in full (None: all it names);
        # a baseline compares only those (urdftool.baseline)
        self.seen: set[str] | None = None

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

    def to_json(self, per_rule: int | None = None) -> dict:
        files = [f.to_json(per_rule) for f in self.files]
        summary = self.summary()
        omitted = sum(n for f in files for n in f.get("omitted", {}).values())
        if omitted:
            summary["omitted"] = omitted
        return {"tool": "urdftool", "version": __version__, "files": files, "summary": summary}


def dumps_indented(value) -> str:
    """``json.dumps(value, indent=2)``, the same text, about 2.5x faster on a report (the
    standard encoder indents in pure Python, through nested generators): for values made of
    dicts with string keys, lists, tuples, strings, ints, floats, booleans and None; anything
    else is left to ``json.dumps``."""
    parts: list[str] = []
    add = parts.append
    string = json.encoder.encode_basestring_ascii

    def encode(o, indent: str) -> None:
        kind = type(o)
        if kind is str:
            add(string(o))
        elif kind is dict:
            if not o:
                add("{}")
                return
            inner = "\n" + indent + "  "
            separator = "{" + inner
            for key, item in o.items():
                if type(key) is not str:
                    raise TypeError(key)
                add(separator + string(key) + ": ")
                separator = "," + inner
                encode(item, indent + "  ")
            add("\n" + indent + "}")
        elif kind is list or kind is tuple:
            if not o:
                add("[]")
                return
            inner = "\n" + indent + "  "
            separator = "[" + inner
            for item in o:
                add(separator)
                separator = "," + inner
                encode(item, indent + "  ")
            add("\n" + indent + "]")
        elif o is None:
            add("null")
        elif o is True:
            add("true")
        elif o is False:
            add("false")
        elif kind is int:
            add(int.__repr__(o))
        elif kind is float:
            add(json.dumps(o))
        else:
            raise TypeError(kind)

    try:
        encode(value, "")
    except (TypeError, RecursionError):
        return json.dumps(value, indent=2)
    return "".join(parts)


def format_json(report: Report, per_rule: int | None = MACHINE_PER_RULE) -> str:
    """The report as JSON: every finding (at most ``per_rule`` of one rule in one file, the
    rest counted in the file's ``omitted`` and the summary's), messages and hints clipped."""
    from urdftool.display import json_safe

    return json_safe(dumps_indented(report.to_json(per_rule)))


def format_github(report: Report, annotate: set[str] | None = None,
                  per_rule: int = 20, summary: bool = False) -> str:
    """GitHub Actions workflow commands (``::error file=...,line=...::message``), escaped as
    GitHub documents: ``%``, CR and LF in the message; also ``:`` and ``,`` in properties.
    Other control characters are shown as ``\\x1b``... (``display.clean``). ``annotate``: the
    files (resolved paths) to annotate (a pull request's); a finding elsewhere is a plain log
    line, and one notice counts them. At most ``per_rule`` findings of one rule in one file
    (GitHub shows a few annotations per step): the rest are counted in one notice. With
    ``summary``, the last line is the summary line (a plain log line)."""
    import os

    from urdftool.display import clean, clip, diagnostic_line, guard

    level = {"error": "error", "warning": "warning", "info": "notice"}

    def escape(value: str, prop: bool = False) -> str:
        value = clean(value, newlines=True)
        value = value.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")
        return value.replace(":", "%3A").replace(",", "%2C") if prop else value

    lines, elsewhere, omitted = [], 0, 0
    for file in report.files:
        listed, more = capped(file.diagnostics, per_rule)
        omitted += sum(more.values())
        for d in listed:
            if annotate is not None and os.path.realpath(d.path) not in annotate:
                elsewhere += 1
                lines.append(guard(diagnostic_line(d.path, d.line, d.column, d.severity,
                                                   d.rule, clip(d.message))))
                continue
            props = [f"file={escape(d.path, True)}"]
            if d.line:
                props.append(f"line={d.line}")
            if d.column:
                props.append(f"col={d.column}")
            props.append(f"title={escape(d.rule, True)}")
            text = clip(d.message) + (f" (fix: {clip(d.hint)})" if d.hint else "")
            lines.append(f"::{level[d.severity]} {','.join(props)}::{escape(text)}")
    if elsewhere:
        lines.append(f"::notice::{elsewhere} finding(s) in files this change does not touch "
                     "(listed in the log, not annotated)")
    if omitted:
        lines.append(f"::notice title=urdftool::{omitted} more finding(s) not annotated (at "
                     f"most {per_rule} per rule and file; --format json lists them)")
    if summary:  # a plain log line, as the text format ends: what the run found in all
        lines.append("urdftool: " + summary_line(report))
    return "\n".join(lines)


_SARIF_LEVEL = {"error": "error", "warning": "warning", "info": "note"}


def _sarif_rule(rule_id: str, rule) -> dict:
    """A SARIF reportingDescriptor from a rule's registration (``rules.Rule``: summary, doc,
    bad and good examples); only the id when the rule is unknown."""
    if rule is None:
        return {"id": rule_id, "shortDescription": {"text": rule_id}}
    doc = " ".join(rule.doc.split()) or rule.summary
    text, markdown = [doc], [doc]
    for title, example in (("Triggers it", rule.bad), ("Use instead", rule.good)):
        if example:
            text.append(f"{title}:\n{example}")
            markdown.append(f"{title}:\n\n```xml\n{example}\n```")
    return {"id": rule_id, "name": rule_id.split(".", 1)[1],
            "shortDescription": {"text": rule.summary},
            "fullDescription": {"text": doc},
            "help": {"text": "\n\n".join(text), "markdown": "\n\n".join(markdown)},
            "defaultConfiguration": {"level": _SARIF_LEVEL[rule.severity]},
            "properties": {"tags": [rule.family]}}


def format_sarif(report: Report | None, rules: dict | None = None,
                 tool_error: str | None = None, per_rule: int | None = MACHINE_PER_RULE) -> str:
    """SARIF 2.1.0, one run: the rules of its results (description and help from the rule
    docs, ``rules`` mapping id to ``rules.Rule``), the results, and an invocation that says
    whether the run succeeded; ``tool_error`` (a file that could not be read...) is a
    ``toolExecutionNotification`` of a failed invocation. At most ``per_rule`` results of one
    rule in one file (the rest counted in a notification)."""
    from urdftool.display import clip, json_safe

    diagnostics, omitted = [], 0
    for file in (report.files if report is not None else ()):
        listed, more = capped(file.diagnostics, per_rule)
        diagnostics.extend(listed)
        omitted += sum(more.values())
    rule_ids = sorted({d.rule for d in diagnostics})
    index = {rule_id: i for i, rule_id in enumerate(rule_ids)}
    results = []
    for d in diagnostics:
        region = {}
        if d.line:
            region["startLine"] = d.line
        if d.column:
            region["startColumn"] = d.column
        location = {"physicalLocation": {"artifactLocation": {"uri": d.path}}}
        if region:
            location["physicalLocation"]["region"] = region
        message = clip(d.message) + (f" Fix: {clip(d.hint)}" if d.hint else "")
        result = {"ruleId": d.rule, "ruleIndex": index[d.rule],
                  "level": _SARIF_LEVEL[d.severity], "message": {"text": message},
                  "locations": [location]}
        if d.fix is not None:
            result["fixes"] = [_sarif_fix(d.fix)]
        results.append(result)
    invocation = {"executionSuccessful": tool_error is None}
    if tool_error is not None:
        invocation["toolExecutionNotifications"] = [
            {"level": "error", "message": {"text": tool_error}}]
    elif omitted:
        invocation["toolExecutionNotifications"] = [{"level": "note", "message": {"text": (
            f"{omitted} more finding(s) not listed (at most {per_rule} per rule and file; "
            "the summary of --format json counts them)")}}]
    sarif = {
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [{"tool": {"driver": {
                      "name": "urdftool", "version": __version__,  # no informationUri: the
                      # project has no public page (it is on no package index)
                      "rules": [_sarif_rule(r, (rules or {}).get(r)) for r in rule_ids]}},
                  "invocations": [invocation],
                  "results": results}],
    }
    return json_safe(dumps_indented(sarif))


def _sarif_fix(fix) -> dict:
    """A finding's fix as a SARIF ``fix`` (one ``artifactChange`` per file)."""
    changes: dict[str, list] = {}
    for e in fix.edits:
        changes.setdefault(e.path, []).append({
            "deletedRegion": {"startLine": e.line, "startColumn": e.column,
                              "endLine": e.end_line, "endColumn": e.end_column},
            "insertedContent": {"text": e.text}})
    return {"description": {"text": f"{fix.applicability} fix"},
            "artifactChanges": [{"artifactLocation": {"uri": path}, "replacements": replacements}
                                for path, replacements in changes.items()]}


def format_statistics(report: Report, as_json: bool = False, rules: dict | None = None) -> str:
    """Findings counted per rule and severity (``--statistics``, like ruff's), most frequent
    first: text columns, or a JSON list of ``{"rule", "severity", "count", "summary"}``."""
    counts: dict[tuple[str, str], int] = {}
    for d in report.diagnostics():
        counts[d.rule, d.severity] = counts.get((d.rule, d.severity), 0) + 1
    rows = sorted(counts.items(), key=lambda item: (-item[1], item[0][0],
                                                     SEVERITIES.index(item[0][1])))

    def summary(rule_id):
        rule = (rules or {}).get(rule_id)
        return rule.summary if rule is not None else ""

    if as_json:
        return json.dumps([{"rule": r, "severity": s, "count": n, "summary": summary(r)}
                           for (r, s), n in rows], indent=2)
    if not rows:
        return ""
    width = max(len(str(n)) for n in counts.values())
    rule_width = max(len(r) for r, _ in counts)
    return "\n".join(f"{n:>{width}}  {s:<7}  {r:<{rule_width}}  {summary(r)}".rstrip()
                     for (r, s), n in rows)


def summary_line(report: Report, show_info: bool = True, colour: bool = False) -> str:
    """``N file(s): E error(s), W warning(s), I info``; red, yellow or green with ``colour``."""
    s = report.summary()
    line = (f"{s['files']} file(s): {s['errors']} error(s), {s['warnings']} warning(s), "
            f"{s['infos']} info")
    if s["infos"] and not show_info:
        line += " (listed with --show-info)"
    if not colour:
        return line
    import click

    return click.style(line, fg="red" if s["errors"] else "yellow" if s["warnings"] else "green")


LISTED_PER_RULE = 20  # text: findings listed per rule and file (the rest counted)


def render_text(report: Report, show_info: bool = False, colour: bool = False,
                summary: bool = True, per_rule: int = LISTED_PER_RULE) -> str:
    """Human output: each error and warning (and info with ``show_info``) as
    ``path:line:col: severity rule: message`` (``display.diagnostic_line``), an excerpt of the
    source line around the column with a caret, the hint; then the summary line. At most
    ``per_rule`` findings of one rule in one file are listed, the rest counted in the summary
    line (JSON and SARIF carry them all). Messages and hints are clipped (``display.clip``) and
    file content is escaped (``display.clean``). A report without listed findings is the
    summary line alone, made without importing ``display`` (a clean run is a pre-commit hook's
    usual case)."""
    shown = SEVERITIES if show_info else ("error", "warning")
    lines = []
    listed = []
    unlisted = 0
    for file in report.files:
        counts: dict[tuple[str, str], int] = {}
        for d in file.diagnostics:
            if d.severity not in shown:
                continue
            key = (d.rule, d.path)
            counts[key] = counts.get(key, 0) + 1
            if counts[key] > per_rule:
                unlisted += 1
            else:
                listed.append((file, d))
    if listed:
        import click

        from urdftool.display import SEVERITY_STYLE, clean, clip, diagnostic_line, excerpt
        from urdftool.edits import line_starts

        def style(text, **how):
            return click.style(text, **how) if colour else text

        for file, d in listed:
            lines.append(diagnostic_line(d.path, d.line, d.column, d.severity, d.rule,
                                         clip(d.message), colour))
            text = file.texts.get(d.path)
            if text is not None and d.line:
                starts = line_starts(text)
                if 0 < d.line <= len(starts):
                    end = starts[d.line] - 1 if d.line < len(starts) else len(text)
                    quoted, caret = excerpt(text, starts[d.line - 1], end, d.column)
                    lines.append(style(f"  {d.line:>5} | {quoted}", dim=True))
                    if caret is not None:
                        fg, bold = SEVERITY_STYLE[d.severity]
                        lines.append(" " * 10 + style(" " * caret + "^", fg=fg, bold=bold))
            if d.hint:
                lines.append(f"        {style('fix:', fg='green')} {clean(clip(d.hint))}")
    if summary:
        line = summary_line(report, show_info, colour)
        if unlisted:
            line += (f"; {unlisted} more not listed (at most {per_rule} per rule and file;"
                     " --format json lists every one)")
        lines.append(line)
    text = "".join(line + "\n" for line in lines)
    if listed:  # whatever the layout: no line a CI runner would execute
        from urdftool.display import guard

        text = guard(text)
    return text


MARKDOWN_LISTED = 50  # markdown: findings listed (the summary table counts them all)


def format_markdown(report: Report, show_info: bool = False,
                    listed: int = MARKDOWN_LISTED) -> str:
    """A pull request's job summary (``$GITHUB_STEP_SUMMARY``): the counts, a table of the
    rules found (errors first), then the first ``listed`` errors and warnings (infos with
    ``show_info``) as ``path:line:col``, severity, rule and message. Text from files is inert
    markdown (``display.markdown_text``)."""
    from collections import Counter

    from urdftool.display import clip, location, markdown_text

    s = report.summary()
    order = {"error": 0, "warning": 1, "info": 2}
    verdict = "failed" if s["errors"] else "passed"
    lines = [(f"### urdftool check {verdict}: {s['errors']} error(s), {s['warnings']} "
              f"warning(s), {s['infos']} info in {s['files']} file(s)"), ""]
    counts = Counter((d.severity, d.rule) for d in report.diagnostics())
    if counts:
        lines += ["| severity | rule | findings |", "| --- | --- | ---: |"]
        for (severity, rule), count in sorted(counts.items(),
                                              key=lambda i: (order[i[0][0]], -i[1], i[0][1])):
            lines.append(f"| {severity} | `{rule}` | {count} |")  # ids: [a-z0-9.-]
        lines.append("")
    shown = sorted((d for d in report.diagnostics() if show_info or d.severity != "info"),
                   key=lambda d: order[d.severity])
    for d in shown[:listed]:
        where = markdown_text(location(d.path, d.line, d.column))
        lines.append(f"- **{d.severity}** {where} `{d.rule}`: "
                     f"{markdown_text(clip(d.message))}")
    if len(shown) > listed:
        lines.append(f"- ... and {len(shown) - listed} more (the job's log lists them)")
    return "\n".join(lines).rstrip() + "\n"


def format_junit(report: Report, testname: str = "urdftool", strict: bool = False,
                 elapsed: float = 0.0, per_rule: int | None = MACHINE_PER_RULE) -> str:
    """JUnit/xunit XML (``colcon test-result``, CI test views; issue 23): one testsuite, one
    testcase per checked file (``ament_xmllint``'s layout: ``name`` the file, ``classname``
    the test name). A file with findings that fail the run (errors; warnings too with
    ``strict``) is a failure whose text lists them as ``path:line:col: severity rule:
    message``; the other findings are the testcase's ``system-out``. File content is escaped
    (``display.clean``): no control character reaches the XML. As JSON: at most ``per_rule``
    findings of one rule in one file (the rest counted), messages clipped."""
    from xml.sax.saxutils import escape, quoteattr

    from urdftool.display import clean, clip, diagnostic_line

    failing = ("error", "warning") if strict else ("error",)
    cases, failures = [], 0
    for file in report.files:
        listed, omitted = capped(file.diagnostics, per_rule)
        lines = [(d.severity in failing,  # (it cleans the path and the message)
                  diagnostic_line(d.path, d.line, d.column, d.severity, d.rule, clip(d.message)))
                 for d in listed]
        bad = [line for fails, line in lines if fails]
        rest = [line for fails, line in lines if not fails]
        rest += [f"{count} more {rule} finding(s) not listed (at most {per_rule} per rule and "
                 "file; --format json counts them too)" for rule, count in omitted.items()]
        case = f'  <testcase name={quoteattr(clean(file.path))} classname={quoteattr(testname)}'
        if not bad and not rest:
            cases.append(case + "/>")
            continue
        case += ">\n"
        if bad:
            failures += 1
            first = bad[0] + (f" (and {len(bad) - 1} more)" if len(bad) > 1 else "")
            case += (f"    <failure message={quoteattr(first)} type=\"urdftool\">"
                     + escape("\n".join(bad)) + "</failure>\n")
        if rest:
            case += f"    <system-out>{escape(chr(10).join(rest))}</system-out>\n"
        cases.append(case + "  </testcase>")
    checked = escape("".join(f"\n* {clean(f.path)}" for f in report.files))
    notes = escape("".join(f"\n{clean(n)}" for n in report.notes))
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            f"<testsuite name={quoteattr(testname)} tests=\"{len(report.files)}\" errors=\"0\" "
            f"failures=\"{failures}\" time=\"{elapsed:.3f}\">\n"
            + "".join(c + "\n" for c in cases)
            + f"  <system-out>Checked files:{checked}{notes}</system-out>\n</testsuite>")
