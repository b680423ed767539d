"""Output of ``urdftool diff`` (issue 30): the JSON document (DESIGN.md's contract), the text
lines (one per change, located as ``check`` locates findings: ``display.diagnostic_line``) and
the markdown summary of a pull request (``$GITHUB_STEP_SUMMARY``): per robot, largest effects
first, many small changes of one kind folded into one line, findings introduced and fixed.
"""

from __future__ import annotations

import math
from pathlib import Path

from urdftool.diff.compare import Change
from urdftool.diff.run import RobotDiff, Side, located, relative, relative_text
from urdftool.display import clean, diagnostic_line

SMALL = 0.01  # a relative change below this (1 %), or below 1 mm, is folded in markdown
SMALL_METRES = 0.001
SHOWN = 25  # changes listed per robot in markdown before the rest are counted


def change_json(change: Change, base: Side, head: Side) -> dict:
    path, line, sites = located(change.loc, head.tree)
    base_path, base_line, base_sites = located(change.base_loc, base.tree)
    data = {"element": change.element, "name": change.name, "aspect": change.aspect,
            "before": change.before, "after": change.after,
            "path": path, "line": line, "base_path": base_path, "base_line": base_line,
            "summary": change.summary}
    data.update(change.extra)
    if sites:
        data["call_sites"] = sites
    if base_sites:
        data["base_call_sites"] = base_sites
    return data


def _finding_json(d, tree: Path) -> dict:
    return {"rule": d.rule, "severity": d.severity, "message": relative_text(d.message, tree),
            "path": relative(d.path, tree), "line": d.line}


def to_json(robots: list[RobotDiff], base: Side, head: Side) -> dict:
    from urdftool import __version__

    out = []
    for robot in robots:
        data = {"entry": robot.entry, "args": robot.args, "status": robot.status,
                "changes": [change_json(c, base, head) for c in robot.changes]}
        if robot.reason:
            data["reason"] = robot.reason
        data["findings"] = {"introduced": [_finding_json(d, head.tree) for d in robot.introduced],
                            "fixed": [_finding_json(d, base.tree) for d in robot.fixed]}
        out.append(data)
    return {"tool": "urdftool", "version": __version__, "base": base.label, "head": head.label,
            "robots": out,
            "summary": {"robots": len(robots),
                        "changed": sum(r.status != "unchanged" for r in robots),
                        "changes": sum(len(r.changes) for r in robots)}}


def _args_text(args: dict) -> str:
    return " ".join(f"{k}:={v}" for k, v in args.items())


def robot_title(robot: RobotDiff) -> str:
    return clean(robot.entry + (f" ({_args_text(robot.args)})" if robot.args else ""))


def text_lines(robots: list[RobotDiff], base: Side, head: Side, colour: bool = False) -> list[str]:
    """Human output: per robot a title line with its status, then one located line per change
    (at HEAD, and where it was at BASE)."""
    lines = []
    for robot in robots:
        if robot.status == "unchanged" and not robot.introduced and not robot.fixed:
            lines.append(f"{robot_title(robot)}: unchanged")
            continue
        count = len(robot.changes)
        head_text = f"{robot_title(robot)}: {robot.status}"
        if count:
            head_text += f", {count} change{'s' if count != 1 else ''}"
        lines.append(head_text)
        if robot.reason:
            lines.append("    " + clean(robot.reason))
        for change in robot.changes:
            path, line, _ = located(change.loc, head.tree)
            base_path, base_line, _ = located(change.base_loc, base.tree)
            where_path, where_line = (path, line) if path else (base_path, base_line)
            message = f"{change.element} {change.name or ''} {change.aspect}: {change.summary}"
            if path and base_path and (base_path, base_line) != (path, line):
                message += f" (at BASE: {base_path}:{base_line})"
            elif not path and base_path:
                message += " (at BASE)"
            lines.append("    " + diagnostic_line(where_path or robot.entry, where_line, None,
                                                  "change", None, message, colour))
        for label, found, tree in (("introduced", robot.introduced, head.tree),
                                   ("fixed", robot.fixed, base.tree)):
            for d in found:
                lines.append(f"    finding {label}: " + diagnostic_line(
                    relative(d.path, tree), d.line, d.column, d.severity, d.rule,
                    relative_text(d.message, tree), colour))
    return lines


# -- markdown ---------------------------------------------------------------------------------


def _md(text) -> str:
    """File content in markdown: escaped so that no name becomes markup or a link."""
    text = clean("" if text is None else str(text))
    for ch in "\\`*_{}[]<>()#+!|~":
        text = text.replace(ch, "\\" + ch)
    return text


def _small(change: Change) -> bool:
    if change.aspect == "origin":
        effect = change.extra.get("effect", {})
        return effect.get("max_displacement", 1) < SMALL_METRES and \
            effect.get("max_rotation", 1) < SMALL * 0.1
    if change.aspect == "com":
        return change.size < SMALL_METRES
    rel = change.extra.get("relative_change")
    return rel is not None and not math.isinf(rel) and rel < SMALL


_KIND = {"inertia": "inertias", "mass": "masses", "com": "centres of mass", "origin": "origins",
         "limit.lower": "lower limits", "limit.upper": "upper limits",
         "limit.effort": "effort limits", "limit.velocity": "velocity limits",
         "dynamics": "dynamics"}


def markdown(robots: list[RobotDiff], base: Side, head: Side,
             pictures: dict[str, tuple[str, str]] | None = None) -> str:
    """The pull-request summary: a table of robots, then per changed robot its changes
    (largest first, small ones folded: "31 inertias changed by < 1 %"), the findings the
    change introduced and fixed, and links to its pictures (``--render``)."""
    pictures = pictures or {}
    out = [f"## urdftool diff: {_md(base.label)} → {_md(head.label)}", ""]
    if not robots:
        out.append("No robot reads a file this change touched.")
        return "\n".join(out) + "\n"
    out += ["| robot | status | changes | findings introduced | findings fixed |",
            "|---|---|---|---|---|"]
    for robot in robots:
        out.append(f"| {_md(robot_title(robot))} | {robot.status} | {len(robot.changes)} | "
                   f"{len(robot.introduced)} | {len(robot.fixed)} |")
    for robot, same in _grouped(robots, base, head):
        if robot.status == "unchanged" and not robot.introduced and not robot.fixed:
            continue
        title = robot_title(robot)
        if same:  # variants the change changed alike: one section
            varying = sorted({k for r in (robot, *same) for k, v in r.args.items()
                              if any(o.args.get(k) != v for o in (robot, *same))})
            common = {k: v for k, v in robot.args.items() if k not in varying}
            title = clean(robot.entry + (f" ({_args_text(common)})" if common else "")) + \
                ", alike for " + "; ".join(
                    " ".join(f"{k}:={r.args.get(k, '')}" for k in varying) for r in (robot, *same))
        out += ["", f"### {_md(title)}: {robot.status}", ""]
        if robot.reason:
            out += [_md(robot.reason), ""]
        if robot.entry in pictures or robot_title(robot) in pictures:
            before, after = pictures.get(robot_title(robot)) or pictures[robot.entry]
            out += ["| before | after |", "|---|---|",
                    f"| ![before]({before}) | ![after]({after}) |", ""]
        large = sorted((c for c in robot.changes if not _small(c)), key=lambda c: -c.size)
        small = [c for c in robot.changes if _small(c)]
        for change in large[:SHOWN]:
            path, line, _ = located(change.loc, head.tree)
            base_path, base_line, _ = located(change.base_loc, base.tree)
            where = f"`{_code(path)}:{line}`" if path else \
                (f"`{_code(base_path)}:{base_line}` (BASE)" if base_path else "")
            out.append(f"- **{_md(change.element)} {_md(change.name)}** {_md(change.aspect)}: "
                       f"{_md(change.summary)}" + (f" — {where}" if where else ""))
        if len(large) > SHOWN:
            out.append(f"- … and {len(large) - SHOWN} more changes (see `urdftool diff`)")
        folded: dict[str, list[Change]] = {}
        for change in small:
            folded.setdefault(change.aspect, []).append(change)
        for aspect, changes in sorted(folded.items(), key=lambda item: -len(item[1])):
            kind = _KIND.get(aspect, aspect)
            bound = "by < 1 mm" if aspect in ("origin", "com") else "by < 1 %"
            out.append(f"- {len(changes)} {kind if len(changes) > 1 else kind.rstrip('s')} "
                       f"changed {bound}")
        for label, found, tree in (("introduced", robot.introduced, head.tree),
                                   ("fixed", robot.fixed, base.tree)):
            if found:
                out += ["", f"Findings {label} by this change:", ""]
                for d in found[:SHOWN]:
                    where = relative(d.path, tree) + (f":{d.line}" if d.line else "")
                    out.append(f"- {d.severity} `{_code(d.rule)}` `{_code(where)}`: "
                               f"{_md(relative_text(d.message, tree))}")
                if len(found) > SHOWN:
                    out.append(f"- … and {len(found) - SHOWN} more")
    return "\n".join(out) + "\n"


def _signature(robot: RobotDiff, base: Side, head: Side) -> tuple:
    """What a robot's section shows, without its arguments: variants with the same one are
    shown once."""
    changes = tuple((c.element, c.name, c.aspect, repr(c.before), repr(c.after),
                     located(c.loc, head.tree)[:2], located(c.base_loc, base.tree)[:2])
                    for c in robot.changes)
    findings = tuple((d.rule, relative(d.path, t), d.line, relative_text(d.message, t))
                     for found, t in ((robot.introduced, head.tree), (robot.fixed, base.tree))
                     for d in found)
    return robot.entry, robot.status, robot.reason, changes, findings


def _grouped(robots: list[RobotDiff], base: Side, head: Side) -> list[tuple]:
    """(robot, the later robots with the same section) in order of first appearance."""
    groups: dict[tuple, list[RobotDiff]] = {}
    for robot in robots:
        groups.setdefault(_signature(robot, base, head), []).append(robot)
    return [(group[0], group[1:]) for group in groups.values()]


def _code(text) -> str:
    return clean("" if text is None else str(text)).replace("`", "'")
