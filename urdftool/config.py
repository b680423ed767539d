"""Configuration: ``[tool.urdftool]`` in the nearest ``pyproject.toml`` and inline suppressions.

Keys: ``select`` and ``ignore`` (lists of rule ids or families), ``strict`` (bool),
``severity`` (a table rule-id -> error|warning|info).
"""

from __future__ import annotations

import re
from pathlib import Path

from urdftool.errors import ToolError

# compiled on first use (re caches it): most files have no suppression comment
_SUPPRESS = r"<!--\s*urdftool:\s*ignore\s+([^>]*?)\s*-->"


class Config:
    __slots__ = ("ignore", "path", "select", "severity", "strict")

    def __init__(self, select: list[str] | None = None, ignore: list[str] | None = None,
                 strict: bool = False, severity: dict[str, str] | None = None,
                 path: Path | None = None):
        self.select = select if select is not None else []
        self.ignore = ignore if ignore is not None else []
        self.strict = strict
        self.severity = severity if severity is not None else {}
        self.path = path


def find_pyproject(start: Path) -> Path | None:
    directory = start.resolve()
    directory = directory if directory.is_dir() else directory.parent
    for parent in (directory, *directory.parents):
        candidate = parent / "pyproject.toml"
        if candidate.is_file():
            return candidate
    return None


def load_config(start: Path) -> Config:
    """The [tool.urdftool] table of the nearest pyproject.toml (empty Config if none)."""
    pyproject = find_pyproject(start)
    if pyproject is None:
        return Config()
    try:
        import tomllib
    except ImportError:  # Python 3.10
        import tomli as tomllib  # type: ignore[no-redef]
    try:
        data = tomllib.loads(pyproject.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise ToolError(f"{pyproject}: cannot read configuration: {exc}") from None
    table = data.get("tool", {}).get("urdftool", {})
    if not isinstance(table, dict):
        raise ToolError(f"{pyproject}: [tool.urdftool] must be a table")

    def strings(key: str) -> list[str]:
        value = table.get(key, [])
        if isinstance(value, str):
            value = [value]
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise ToolError(f"{pyproject}: tool.urdftool.{key} must be a list of rule ids")
        return value

    severity = table.get("severity", {})
    if not isinstance(severity, dict) or not all(
            v in ("error", "warning", "info") for v in severity.values()):
        raise ToolError(f"{pyproject}: tool.urdftool.severity maps rule ids to error|warning|info")
    return Config(strings("select"), strings("ignore"), bool(table.get("strict", False)),
                  dict(severity), pyproject)


def suppressions(text: str) -> dict[int, set[str]]:
    """Line -> rule ids or families suppressed there. A comment suppresses its own line and the
    line below it ("on or above the line")."""
    result: dict[int, set[str]] = {}
    if "urdftool:" not in text:
        return result
    for number, line in enumerate(text.splitlines(), start=1):
        for match in re.finditer(_SUPPRESS, line):
            ids = {part for part in re.split(r"[\s,]+", match.group(1)) if part}
            for target in (number, number + 1):
                result.setdefault(target, set()).update(ids)
    return result
