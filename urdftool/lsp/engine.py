"""The runs behind ``urdftool lsp``, without the protocol.

The open buffers, and one *unit* per package an open file belongs to: the plan of
``check DIR`` on that package (``package.plan``: every robot file, configured entries with their
arguments, launch-file arguments), a report and a robot per target, and what each check read.
An edit marks stale the checks that read the edited file; ``refresh`` re-checks those (the
entries first: a fragment an entry reads is reported through the entry, so its own check is
put off until nothing else is waiting) and the unit's findings are then ``check DIR``'s:
``check.run_report`` (the last steps of ``check_paths``) and the configured baseline, on the
same reports. Nothing here judges a robot: every finding comes from ``urdftool.check``.

The buffers are read through ``LoadOptions.overlay`` (in the sandboxed reader too when the
workspace is untrusted). Used from one thread (the server's worker); ``snapshot`` is replaced
whole after each refresh, for the requests answered meanwhile.
"""

from __future__ import annotations

import copy
import functools
import os
import sys
from pathlib import Path
from typing import ClassVar, NamedTuple

from urdftool.check import CheckOptions, check_model, run_report
from urdftool.config import Config, load_config
from urdftool.errors import ToolError
from urdftool.loader import run_roots
from urdftool.package import (
    Selection,
    Target,
    is_launch_file,
    is_srdf_file,
    package_root,
    plan,
    with_operator_args,
)
from urdftool.report import Diagnostic, FileReport
from urdftool.source import ROBOT_SUFFIXES, LoadOptions

# a directory that is no package (no package.xml, no configuration above the file) is checked
# as `check DIR` would when it holds at most this many robot files, else the file alone
MAX_LOOSE_FILES = 64
CONFIGURATIONS = ("urdftool.toml", "pyproject.toml", "package.xml")  # a unit plans again
ERROR_RULE = ""  # a check that could not run (`check` exits 2): said at the file's first line


class Settings:
    """What the operator chose: launch arguments, then ``initializationOptions``, then the
    ``urdftool`` section of the workspace settings. ``trusted`` only from the client's
    initialization options (VS Code's workspace trust): untrusted otherwise."""

    KEYS: ClassVar[dict] = {"packages": dict, "args": dict, "select": list, "ignore": list, "allowEnv": list,
            "timeout": (int, float), "memoryLimit": int, "debounce": (int, float),
            "ruleDocsUrl": str, "trusted": bool}
    CLIENT_KEYS: ClassVar[frozenset] = frozenset({"path"})  # the editor's own (executable)

    def __init__(self):
        self.packages: dict[str, str] = {}
        self.args: dict[str, str] = {}
        self.select: list[str] = []
        self.ignore: list[str] = []
        self.allow_env: tuple[str, ...] = ()
        self.timeout: float | None = None
        self.memory_mb: int | None = None
        self.debounce = 0.025  # seconds between the last change and its check
        self.rule_docs_url: str | None = None
        self.trusted = False

    def updated(self, data, trust: bool = False) -> tuple[Settings, list[str]]:
        """A copy with the keys of ``data`` (a dict from the client) applied, and what was
        refused (unknown keys, wrong types), to be said to the user."""
        new = copy.copy(self)
        problems = []
        if not isinstance(data, dict):
            return new, ([] if data is None else ["settings: expected an object"])
        for key, value in data.items():
            if key in self.CLIENT_KEYS:
                continue
            kind = self.KEYS.get(key)
            if kind is None:
                problems.append(f"unknown setting {key!r} (known: {', '.join(self.KEYS)})")
                continue
            if not isinstance(value, kind) or (kind is dict and not all(
                    isinstance(k, str) and isinstance(v, str) for k, v in value.items())) or (
                    kind is list and not all(isinstance(v, str) for v in value)):
                problems.append(f"setting {key!r}: wrong type")
                continue
            if key == "trusted":
                if trust:
                    new.trusted = value
                else:
                    problems.append("'trusted' is read from initializationOptions only")
            elif key in ("select", "ignore") and self._unknown_rules(key, value):
                problems.append(self._unknown_rules(key, value))
            elif key == "packages":
                new.packages = {**self.packages, **value}
            elif key == "args":
                new.args = {**self.args, **value}
            elif key == "allowEnv":
                new.allow_env = tuple(value)
            elif key == "memoryLimit":
                new.memory_mb = value
            elif key == "debounce":
                new.debounce = max(0.0, float(value) / 1000)
            elif key == "ruleDocsUrl":
                new.rule_docs_url = value
            else:
                setattr(new, key, value)
        return new, problems


    @staticmethod
    def _unknown_rules(key: str, ids: list[str]) -> str | None:
        from urdftool.config import check_rule_ids

        try:
            check_rule_ids(ids, f"setting {key!r}")
        except ToolError as exc:
            return str(exc)
        return None


class Unit:
    """One package (or loose directory, or lone file) and the last check of each target."""

    __slots__ = ("config", "error", "planned", "refused", "reports", "robots", "root", "stale",
                 "targets")

    def __init__(self, root: Path):
        self.root = root
        self.planned = False
        self.config = Config()
        self.error: str | None = None  # the configuration could not be read
        self.targets: list[Target] = []
        self.reports: list[FileReport | None] = []
        self.robots: list = []
        self.stale: set[int] = set()
        self.refused: list[tuple[str, str]] = []  # what planning refused unread (Selection)


class Result(NamedTuple):
    """What a refresh found: per file (resolved path) its findings, as ``check DIR`` shows
    them; the reports and robots of every target (navigation, fixes)."""

    diagnostics: dict[str, list[Diagnostic]]
    checks: tuple[tuple[FileReport, object], ...]  # (report, robot or None) per target
    notes: tuple[str, ...]


@functools.lru_cache(maxsize=8192)
def _planned_kind(name: str) -> bool:
    """A file ``check DIR`` plans a check of: a robot file, an SRDF, a launch file."""
    return name.endswith(ROBOT_SUFFIXES) or is_srdf_file(name) or is_launch_file(name)


def _resolved(path: str) -> str:
    return str(Path(path).resolve())


def resolved(path) -> str:
    """A file's resolved path (memoised: asked for every file of every check on each edit;
    a symlink changed during a session is seen after a restart)."""
    return _resolved(os.fspath(path))


class Engine:
    def __init__(self, settings: Settings | None = None):
        self.settings = settings or Settings()
        self.buffers: dict[str, str] = {}  # resolved path -> unsaved text
        self.units: dict[Path, Unit] = {}
        self.snapshot: dict[Path, Result] = {}  # unit root -> its last result
        # the client's workspace folders (resolved): each one is the root of the checks of
        # the files in it, nothing above it (issue 28.2; ``urdftool.loader.run_roots``)
        self.folders: list[Path] = []

    # -- options -------------------------------------------------------------------------

    def load_options(self) -> LoadOptions:
        s = self.settings
        options = LoadOptions(dict(s.packages), dict(s.args), untrusted=not s.trusted,
                              allow_env=tuple(s.allow_env))
        if s.timeout is not None:
            options.timeout = s.timeout
        if s.memory_mb is not None:
            options.memory_mb = s.memory_mb
        options.overlay = dict(self.buffers)
        if options.untrusted or "urdftool.cache" in sys.modules:
            from urdftool import cache

            # untrusted: the mesh cache is read but written only where it is named for it
            cache.WRITABLE = not options.untrusted or bool(os.environ.get("URDFTOOL_CACHE_DIR"))
        return options

    def check_options(self, unit: Unit) -> CheckOptions:
        """The options of the unit's checks (and of its fixes): what they may read from the
        operator's settings and the unit's repository, once (``urdftool.loader``), before any
        configuration is merged in."""
        options = CheckOptions(self.load_options(), list(self.settings.select),
                               list(self.settings.ignore), unit.config)
        options.load.roots = run_roots([unit.root], options.load,
                                       workspace=self.workspace_of(unit.root))
        return options

    def workspace_of(self, path: Path) -> Path | None:
        """The innermost workspace folder holding ``path``; None for a file outside them (its
        root is then as ``check PATH`` gives it)."""
        inside = [f for f in self.folders if Path(resolved(path)).is_relative_to(f)]
        return max(inside, key=lambda f: len(f.parts)) if inside else None

    def set_settings(self, settings: Settings) -> None:
        self.settings = settings
        for unit in self.units.values():  # everything again, with the new options
            unit.planned = False

    # -- buffers -------------------------------------------------------------------------

    def set_buffer(self, path: str, text: str | None) -> None:
        """An open buffer's text (None: closed, the disk's text again)."""
        key = resolved(path)
        if text is None:
            self.buffers.pop(key, None)
        elif self.buffers.get(key) == text:
            return
        else:
            self.buffers[key] = text
        self.touched(key)

    def touched(self, key: str) -> None:
        """The file ``key`` (resolved) changed: the checks that read it are stale; a robot file
        no check knows yet, or a configuration, makes its unit plan again."""
        name = Path(key).name
        for unit in self.units.values():
            root = str(unit.root)
            inside = key == root or key.startswith(root + os.sep)
            if not inside and not any(key in self._reads(r) for r in unit.reports
                                      if r is not None):
                continue
            if inside and (name in CONFIGURATIONS or (
                    _planned_kind(name) and key not in self._paths(unit))):
                unit.planned = False
                continue
            for index, report in enumerate(unit.reports):
                if report is None or key in self._reads(report) or \
                        resolved(unit.targets[index].path) == key:
                    unit.stale.add(index)

    @staticmethod
    def _reads(report: FileReport) -> set[str]:
        # (an SRDF's check reads its robot's files too: editing the URDF re-checks it)
        return {resolved(report.path), *report.includes, *report.companion}

    @staticmethod
    def _paths(unit: Unit) -> set[str]:
        return {resolved(t.path) for t in unit.targets}

    # -- units ---------------------------------------------------------------------------

    def unit_of(self, path: str) -> Unit | None:
        """The unit whose checks read ``path``, or the unit of its package (made now) for a
        robot file or a configuration; None for another file no check reads (a YAML file, a
        mesh... opened in the editor: checked when an entry that reads it is)."""
        key = resolved(path)
        for unit in self.units.values():
            if any(r is not None and key in self._reads(r) for r in unit.reports):
                return unit
        if not _planned_kind(key) and Path(key).name not in CONFIGURATIONS:
            return None
        root = self._root(Path(key))
        unit = self.units.get(root)
        if unit is None:
            unit = self.units[root] = Unit(root)
        elif unit.planned and key not in self._paths(unit) and _planned_kind(key):
            unit.planned = False  # a new file of the package
        return unit

    @staticmethod
    def _root(file: Path) -> Path:
        root = package_root(file)
        if (root / "package.xml").is_file() or (root / "urdftool.toml").is_file() or \
                (root / "pyproject.toml").is_file():
            return root
        count = 0
        for _, _, names in os.walk(root):
            count += sum(_planned_kind(name) for name in names)
            if count > MAX_LOOSE_FILES:
                return file  # a loose file among many: alone
        return root

    def _plan(self, unit: Unit) -> None:
        unit.error = None
        unit.planned = True
        try:
            unit.config = load_config(unit.root)
            selection = Selection()
            unit.targets = with_operator_args(plan([str(unit.root)], selection=selection)[0],
                                              dict(self.settings.args))
            unit.refused = selection.refused  # launch files over their size limit (issue 21)
        except ToolError as exc:
            unit.config, unit.targets, unit.error = Config(), [], str(exc)
            unit.refused = []
        unit.reports = [None] * len(unit.targets)
        unit.robots = [None] * len(unit.targets)
        unit.stale = set(range(len(unit.targets)))

    # -- checking ------------------------------------------------------------------------

    def refresh(self, paths: list[str], everything: bool = False) -> list[Path]:
        """Check again what is stale in the units of ``paths`` (with ``everything``, the
        fragments put off too); the roots of the units whose result changed."""
        changed = []
        for unit in dict.fromkeys(self.unit_of(p) for p in paths):
            if unit is None:
                continue
            if not unit.planned:
                self._plan(unit)
            if not unit.stale and unit.root in self.snapshot:
                continue
            self._check(unit, everything)
            self.snapshot[unit.root] = self._result(unit)
            changed.append(unit.root)
        return changed

    def pending(self) -> list[Path]:
        """Units with checks put off (fragments that entries read)."""
        return [u.root for u in self.units.values() if u.stale and u.planned]

    def refresh_pending(self, stop=None) -> list[Path]:
        """Run the checks put off; ``stop()`` true (a change came) ends the run between two
        targets, what is left stays pending."""
        changed = []
        for unit in list(self.units.values()):
            if stop is not None and stop():
                break
            if unit.stale and unit.planned:
                self._check(unit, True, stop)
                self.snapshot[unit.root] = self._result(unit)
                changed.append(unit.root)
        return changed

    def _check(self, unit: Unit, everything: bool, stop=None) -> None:
        options = self.check_options(unit)

        def read_by_entry() -> set[str]:
            found: set[str] = set()
            for target, report in zip(unit.targets, unit.reports):
                if report is not None and (target.configured or report.role == "entry"):
                    found.update(report.includes)
            return found

        readers = read_by_entry()
        later = []
        for index in sorted(unit.stale):
            if everything and stop is not None and stop():
                return  # the rest stays stale (nothing was put off: everything)
            target, report = unit.targets[index], unit.reports[index]
            if not everything and report is not None and not target.configured and \
                    report.role != "entry" and resolved(target.path) in readers:
                later.append(index)
                continue
            self._check_one(unit, index, options)
        readers = read_by_entry()
        for index in later:  # no longer read by an entry: its own findings are shown
            if resolved(unit.targets[index].path) not in readers:
                self._check_one(unit, index, options)
        # stale now: what was put off and is still read by an entry (_check_one unmarks)

    def _check_one(self, unit: Unit, index: int, options: CheckOptions) -> None:
        target = unit.targets[index]
        try:
            report, robot = check_model(target.path, options, target)
        except ToolError as exc:
            report, robot = _error_report(target.path, str(exc)), None
        except Exception as exc:  # noqa: BLE001 - one file's failure is said, the rest goes on
            report, robot = _error_report(
                target.path, f"internal error: {type(exc).__name__}: {exc}"), None
        unit.reports[index] = report
        unit.robots[index] = robot
        unit.stale.discard(index)

    def _result(self, unit: Unit) -> Result:
        """The unit's findings as ``check DIR`` reports them."""
        if unit.error is not None:
            return Result({}, (), (unit.error,))
        reports = []
        for report in unit.reports:
            if report is None:
                continue
            copied = FileReport(report.path, report.robot, list(report.diagnostics),
                                report.texts)
            copied.includes, copied.role, copied.args = report.includes, report.role, \
                report.args
            reports.append(copied)
        targets = [t for t, r in zip(unit.targets, unit.reports) if r is not None]
        refused = Selection()  # what the plan refused unread (its roles line is check's)
        refused.refused = unit.refused
        report = run_report(targets, reports, None, refused,  # check DIR's own last steps
                            self.check_options(unit))
        if unit.config.baseline is not None:  # as the CLI applies the configured one
            from urdftool.baseline import apply_baseline

            try:
                apply_baseline(report, unit.config.baseline)
            except ToolError as exc:
                report.notes.append(str(exc))
        by_path: dict[str, list[Diagnostic]] = {}
        for d in report.diagnostics():
            by_path.setdefault(resolved(d.path), []).append(d)
        return Result(by_path, tuple((r, robot) for r, robot in zip(unit.reports, unit.robots)
                                     if r is not None), tuple(report.notes))


def _error_report(path: str, message: str) -> FileReport:
    report = FileReport(path, None, [Diagnostic(ERROR_RULE, "error", message, path, None, None,
                                                None, None)])
    report.role = "entry"
    return report
