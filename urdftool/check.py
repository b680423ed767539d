"""The ``check`` pipeline: source -> model -> rules -> report, one file at a time."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from urdftool.config import Config, suppressions
from urdftool.errors import ToolError
from urdftool.model import build_robot
from urdftool.report import Diagnostic, FileReport, Finding, Report
from urdftool.rules import load_all, selected
from urdftool.source import LoadOptions, discover, load


@dataclass
class CheckOptions:
    load: LoadOptions = field(default_factory=LoadOptions)
    select: list[str] = field(default_factory=list)
    ignore: list[str] = field(default_factory=list)
    config: Config = field(default_factory=Config)
    debug: bool = False


def _diagnostic(rule_id: str, severity: str, finding: Finding, default_path: str) -> Diagnostic:
    loc = finding.loc
    message = finding.message
    if loc is not None and loc.via:
        message += " (expanded from the macro call at " + ", called from ".join(loc.via) + ")"
    return Diagnostic(rule_id, finding.severity or severity, message,
                      loc.path if loc is not None else default_path,
                      loc.line if loc is not None else None,
                      loc.column if loc is not None else None,
                      loc.element if loc is not None else None, finding.hint)


def check_file(path: Path | str, options: CheckOptions | None = None) -> FileReport:
    """All findings for one file. Raises ToolError when the file cannot be read at all."""
    options = options or CheckOptions()
    source = load(path, options.load)
    robot = build_robot(source)
    registry = load_all()
    select = options.select or options.config.select
    ignore = options.ignore + options.config.ignore
    diagnostics: list[Diagnostic] = []
    for rule in registry.values():
        if not selected(rule.id, select, ignore):
            continue
        severity = options.config.severity.get(rule.id, rule.severity)
        try:
            findings = list(rule.check(robot))
        except Exception as exc:  # a rule must never take the whole run down
            if options.debug:
                raise
            findings = [Finding(f"internal error in rule {rule.id}: {type(exc).__name__}: {exc}",
                                None, severity="warning")]
        diagnostics.extend(_diagnostic(rule.id, severity, f, source.path) for f in findings)
    quiet = {p: suppressions(t) for p, t in source.texts.items()}
    diagnostics = [d for d in diagnostics
                   if not (d.line and (quiet.get(d.path, {}).get(d.line, set())
                                       & {d.rule, d.rule.split(".")[0]}))]
    diagnostics.sort(key=lambda d: (d.path != source.path, d.path, d.line or 0, d.column or 0,
                                    d.rule))
    return FileReport(source.path, robot.name, diagnostics, source.texts)


def check_paths(paths: list[str], options: CheckOptions | None = None) -> Report:
    """Check every robot file under ``paths``. Raises ToolError when there is nothing to check."""
    files = discover(paths)
    if not files:
        raise ToolError("no robot files (*.urdf, *.xacro, *.sdf) found in " + ", ".join(paths))
    return Report([check_file(f, options) for f in files])
