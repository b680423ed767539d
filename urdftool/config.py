"""Configuration: ``[tool.urdftool]`` in a ``pyproject.toml``, or the same keys at the top level
of a ``urdftool.toml`` (the nearest of either, walking up from the input; a ``pyproject.toml``
without the table is passed over), and inline ``<!-- urdftool: ignore RULE -->`` comments.

Keys: ``select`` and ``ignore`` (lists of rule ids or families), ``strict`` (bool),
``severity`` (a table rule-id -> error|warning|info), ``entries`` (a list of
``{ file = "urdf/robot.urdf.xacro", args = { NAME = "VALUE" } }``: the package's entry points,
the same file possibly with several argument sets), ``packages`` (a table NAME -> DIR for
``package://NAME`` and ``$(find NAME)``), ``baseline`` (a baseline file), ``exclude`` and
``extend-exclude`` (glob patterns of files and folders not to check, as ruff's: ``exclude``
replaces the defaults, ``urdftool.package.DEFAULT_EXCLUDE``), ``respect-gitignore`` (bool,
default true). Paths are relative to
the configuration file's directory, and must resolve (links followed) inside its repository
(``urdftool.roots``): a configuration is a repository file, and only the operator widens what a
run reads (issue 20). Anything else (an unknown key, a wrong type, an unknown rule id, a path
outside the repository) is a ToolError (exit 2) naming the key, with a did-you-mean.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import NamedTuple

from urdftool.errors import ToolError
from urdftool.files import read_regular
from urdftool.roots import OutsideRepository, clamp, repository_for

_SEVERITIES = ("error", "warning", "info")


class Entry(NamedTuple):
    """An entry point of a package: a file and the xacro arguments to expand it with."""

    path: Path  # absolute
    args: dict[str, str]


class Companion(NamedTuple):
    """A companion file (an SRDF, a controllers YAML) and the robot it describes (issue 31):
    ``srdf = [{ file = "config/robot.srdf", robot = "urdf/robot.urdf.xacro", args = {...} }]``."""

    path: Path  # absolute
    robot: Path  # absolute
    args: dict[str, str]  # the robot's xacro arguments


class Config:
    __slots__ = ("baseline", "companions", "entries", "exclude", "extend_exclude", "ignore",
                 "packages", "path", "respect_gitignore", "select", "severity", "strict")

    def __init__(self, select: list[str] | None = None, ignore: list[str] | None = None,
                 strict: bool = False, severity: dict[str, str] | None = None,
                 path: Path | None = None, entries: list[Entry] | None = None,
                 packages: dict[str, str] | None = None, baseline: Path | None = None):
        self.select = select if select is not None else []
        self.ignore = ignore if ignore is not None else []
        self.strict = strict
        self.severity = severity if severity is not None else {}
        self.path = path  # the configuration file, None without one
        self.entries = entries if entries is not None else []
        self.packages = packages if packages is not None else {}  # NAME -> absolute DIR
        self.baseline = baseline
        self.exclude: list[str] | None = None  # None: the defaults
        self.extend_exclude: list[str] = []
        self.respect_gitignore = True
        self.companions: list[Companion] = []  # ``srdf``


KEYS = ("select", "ignore", "strict", "severity", "entries", "packages", "baseline", "srdf",
        "exclude", "extend-exclude", "respect-gitignore")


def find_config(start: Path, memo: dict | None = None) -> tuple[Path, dict] | None:
    """The nearest configuration above ``start``: (its file, its table). ``memo`` (directory ->
    what it holds) spares reading the same directories again during one run."""
    memo = memo if memo is not None else {}
    # looked for where ``start`` is written, not where a link leads: a link (a changed name,
    # a directory the pull request replaced by a link to another checkout) decides nothing
    name = os.path.abspath(start)
    directory = name if os.path.isdir(name) and not os.path.islink(name) else \
        os.path.dirname(name)
    while True:
        found = memo.get(directory)
        if found is None:
            found = memo[directory] = _config_in(Path(directory))
        if found:
            return found
        parent = os.path.dirname(directory)
        if parent == directory:
            return None
        directory = parent


def _config_in(directory: Path) -> tuple[Path, dict] | bool:
    for name in ("urdftool.toml", "pyproject.toml"):
        candidate = directory / name
        if not os.path.lexists(candidate):
            continue
        try:  # a committed link to outside (or to .git/config) is refused unread, the same
            # answer whether or not its target exists
            clamp(name, directory, name, repository_for(directory))
        except OutsideRepository:
            raise ToolError(f"{candidate}: a link to outside the repository (or into its "
                            "version-control metadata): not read "
                            "(a configuration is a repository file)") from None
        if not candidate.is_file():
            continue
        data = _read_toml(candidate)
        if name == "urdftool.toml":
            return candidate, data
        tool = data.get("tool", {})
        if isinstance(tool, dict) and "urdftool" in tool:
            table = tool["urdftool"]
            if not isinstance(table, dict):
                raise ToolError(f"{candidate}: [tool.urdftool] must be a table")
            return candidate, table
    return False


# a configuration file larger than this is refused unread (issue 21: a pyproject.toml with
# another tool's 16 MB table took seconds to parse before anything was checked)
MAX_CONFIG_BYTES = 256 << 10


def _read_toml(path: Path) -> dict:
    try:
        import tomllib
    except ImportError:  # Python 3.10
        import tomli as tomllib  # type: ignore[no-redef]
    try:
        return tomllib.loads(read_regular(path, MAX_CONFIG_BYTES).decode("utf-8"))
    except RecursionError:  # tomllib recurses into nested arrays and tables
        raise ToolError(f"{path}: cannot read configuration: nested too deeply") from None
    except (OSError, ValueError, UnicodeDecodeError) as exc:
        raise ToolError(f"{path}: cannot read configuration: {exc}") from None


def load_config(start: Path) -> Config:
    """The configuration that applies to ``start`` (an empty Config if none)."""
    found = find_config(start)
    if found is None:
        return Config()
    path, table = found
    return parse_config(table, path)


def load_config_file(path: Path) -> Config:
    """``--config FILE``: that configuration (a ``urdftool.toml``, or a ``pyproject.toml``'s
    ``[tool.urdftool]``); ToolError when it is not one."""
    if not path.is_file():
        raise ToolError(f"{path}: no such configuration file")
    data = _read_toml(path)
    if path.name == "pyproject.toml" or "tool" in data:
        tool = data.get("tool", {})
        table = tool.get("urdftool") if isinstance(tool, dict) else None
        if not isinstance(table, dict):
            raise ToolError(f"{path}: no [tool.urdftool] table")
        return parse_config(table, path)
    return parse_config(data, path)


def parse_config(table: dict, path: Path) -> Config:
    """Validate one configuration table; ToolError on anything unknown or mistyped."""
    where = f"{path}: " + ("" if path.name == "urdftool.toml" else "tool.urdftool.")
    base = path.parent
    for key in table:
        if key not in KEYS:
            raise ToolError(f"{where}{key}: unknown key{did_you_mean(key, KEYS)}")

    def strings(key: str) -> list[str]:
        value = table.get(key, [])
        if isinstance(value, str):
            value = [value]
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise ToolError(f"{where}{key} must be a list of rule ids or families")
        check_rule_ids(value, f"{where}{key}")
        return value

    strict = table.get("strict", False)
    if not isinstance(strict, bool):
        raise ToolError(f"{where}strict must be true or false, not {strict!r}")
    severity = table.get("severity", {})
    if not isinstance(severity, dict):
        raise ToolError(f"{where}severity must be a table: rule id = \"error|warning|info\"")
    check_rule_ids(list(severity), f"{where}severity", families=False)
    for rule_id, value in severity.items():
        if value not in _SEVERITIES:
            raise ToolError(f"{where}severity.{rule_id}: {value!r} is not error, warning or "
                            f"info{did_you_mean(str(value), _SEVERITIES)}")
    packages = table.get("packages", {})
    if not isinstance(packages, dict) or not all(isinstance(v, str) for v in packages.values()):
        raise ToolError(f"{where}packages must be a table: NAME = \"DIR\"")
    baseline = table.get("baseline")
    if baseline is not None and not isinstance(baseline, str):
        raise ToolError(f"{where}baseline must be a file name (a string)")
    repository = repository_for(base)
    try:
        directories = {name: str(clamp(directory, base, f"packages.{name}", repository))
                       for name, directory in packages.items()}
        entries = _entries(table.get("entries", []), where, base, repository)
        baseline_path = (clamp(baseline, base, "baseline", repository)
                         if baseline is not None else None)
        companions = _companions(table.get("srdf", []), where, base, repository)
    except OutsideRepository as exc:
        raise ToolError(f"{where}{exc}") from None
    config = Config(strings("select"), strings("ignore"), strict, dict(severity), path, entries,
                    directories, baseline_path)
    config.companions = companions
    for key in ("exclude", "extend-exclude"):
        value = table.get(key)
        if value is None:
            continue
        if not isinstance(value, list) or not all(isinstance(v, str) and v for v in value):
            raise ToolError(f'{where}{key} must be a list of glob patterns: {key} = ["vendor", '
                            '"urdf/generated/*.urdf"]')
        setattr(config, key.replace("-", "_"), list(value))
    respect = table.get("respect-gitignore", True)
    if not isinstance(respect, bool):
        raise ToolError(f"{where}respect-gitignore must be true or false, not {respect!r}")
    config.respect_gitignore = respect
    return config


def _entries(value, where: str, base: Path, repository: Path) -> list[Entry]:
    shape = 'entries = [{ file = "urdf/robot.urdf.xacro", args = { NAME = "VALUE" } }, ...]'
    if not isinstance(value, list):
        raise ToolError(f"{where}entries must be a list: {shape}")
    entries = []
    for number, item in enumerate(value, start=1):
        if isinstance(item, str):
            item = {"file": item}
        if not isinstance(item, dict) or not isinstance(item.get("file"), str):
            raise ToolError(f"{where}entries[{number}] needs a file: {shape}")
        for key in item:
            if key not in ("file", "args"):
                raise ToolError(f"{where}entries[{number}].{key}: unknown key"
                                f"{did_you_mean(key, ('file', 'args'))}")
        args = item.get("args", {})
        if not isinstance(args, dict):
            raise ToolError(f"{where}entries[{number}].args must be a table: NAME = \"VALUE\"")
        file = clamp(item["file"], base, f"entries[{number}].file", repository)
        if not file.is_file():
            raise ToolError(f"{where}entries[{number}]: {item['file']}: no such file")
        # xacro arguments are strings; TOML booleans and numbers are written as xacro reads them
        entries.append(Entry(file, {str(k): _arg_text(v) for k, v in args.items()}))
    return entries


def _companions(value, where: str, base: Path, repository: Path) -> list[Companion]:
    shape = ('srdf = [{ file = "config/robot.srdf", robot = "urdf/robot.urdf.xacro", '
             'args = { NAME = "VALUE" } }, ...]')
    if not isinstance(value, list):
        raise ToolError(f"{where}srdf must be a list: {shape}")
    found = []
    for number, item in enumerate(value, start=1):
        if not isinstance(item, dict) or not isinstance(item.get("file"), str) \
                or not isinstance(item.get("robot"), str):
            raise ToolError(f"{where}srdf[{number}] needs a file and a robot: {shape}")
        for key in item:
            if key not in ("file", "robot", "args"):
                raise ToolError(f"{where}srdf[{number}].{key}: unknown key"
                                f"{did_you_mean(key, ('file', 'robot', 'args'))}")
        args = item.get("args", {})
        if not isinstance(args, dict):
            raise ToolError(f"{where}srdf[{number}].args must be a table: NAME = \"VALUE\"")
        file = clamp(item["file"], base, f"srdf[{number}].file", repository)
        robot = clamp(item["robot"], base, f"srdf[{number}].robot", repository)
        for key, path in (("file", file), ("robot", robot)):
            if not path.is_file():
                raise ToolError(f"{where}srdf[{number}]: {item[key]}: no such file")
        found.append(Companion(file, robot, {str(k): _arg_text(v) for k, v in args.items()}))
    return found


def _arg_text(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


def did_you_mean(name: str, candidates) -> str:
    import difflib  # error path only

    close = difflib.get_close_matches(name, list(candidates), n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


def check_rule_ids(ids, where: str, families: bool = True) -> None:
    """ToolError for the first id that names no rule (nor, with ``families``, a family)."""
    from urdftool.rules import FAMILIES, load_all

    registry = load_all()
    for rule_id in ids:
        if rule_id in registry or (families and rule_id in FAMILIES):
            continue
        known = list(registry) + (list(FAMILIES) if families else [])
        raise ToolError(f"{where}: unknown rule {rule_id!r}{did_you_mean(rule_id, known)}")


def _ignored(line: str):
    """The rule ids of each ``<!-- urdftool: ignore RULE[, RULE...] -->`` comment of a line
    (a set per comment), found with ``str.find`` (a regular expression with adjacent
    quantifiers took minutes on a long comment: issue 21)."""
    start = line.find("<!--")
    while start >= 0:
        end = line.find("-->", start + 4)
        if end < 0:
            return
        body = line[start + 4:end].lstrip()
        if body.startswith("urdftool:") and ">" not in body:
            rest = body[len("urdftool:"):].lstrip()
            if rest.startswith("ignore") and rest[6:7].isspace():
                yield set(rest[6:].replace(",", " ").split())
        start = line.find("<!--", end + 3)


def suppressions(text: str, path: str | None = None) -> dict[int, set[str]]:
    """Line -> rule ids or families suppressed there. A comment suppresses its own line and the
    line below it ("on or above the line"). A comment naming no known rule or family is a
    ToolError (when ``path`` is given, located there)."""
    result: dict[int, set[str]] = {}
    if "urdftool:" not in text:
        return result
    for number, line in enumerate(text.splitlines(), start=1):
        for ids in _ignored(line):
            if path is not None:
                check_rule_ids(sorted(ids), f"{path}:{number}: urdftool: ignore")
            for target in (number, number + 1):
                result.setdefault(target, set()).update(ids)
    return result
