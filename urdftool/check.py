"""The ``check`` pipeline: source -> model -> rules -> report, one file at a time; several files
in a pool of forked worker processes (``CheckOptions.jobs``), reports in the order of the files.

Look-through: when findings carry safe fixes (``urdftool.edits``) beyond the XML repairs (made
in memory while reading), the fixed texts are read again from memory and every rule runs on the
robot as it was meant; the report is the fixed mistakes plus the findings of the fixed robot,
at their places in the files as written (fixes never move lines). A xacro expansion stopped by
an undefined name is read again past it (the expression left as written)."""

from __future__ import annotations

import copy
import gc
import os
import sys
from dataclasses import dataclass, field
from pathlib import Path

from urdftool import budget
from urdftool import rules as rules_module
from urdftool.config import Config, suppressions
from urdftool.errors import NothingToCheck, ToolError, exception_text
from urdftool.findings import Loc
from urdftool.loader import load, run_roots
from urdftool.model import build_robot
from urdftool.package import (
    Selection,
    Target,
    classify,
    gone,
    is_companion,
    other_inputs,
    plan,
    role,
    seen_files,
    settle,
    store_reads,
    unaffected,
    with_operator_args,
)
from urdftool.report import (
    Diagnostic,
    FileReport,
    Finding,
    Report,
    group_instances,
    merge_repeats,
)
from urdftool.roots import real
from urdftool.rules import load_all, selected
from urdftool.source import LoadOptions


@dataclass
class CheckOptions:
    load: LoadOptions = field(default_factory=LoadOptions)
    select: list[str] = field(default_factory=list)
    ignore: list[str] = field(default_factory=list)
    config: Config = field(default_factory=Config)
    debug: bool = False
    jobs: int | None = None  # worker processes for several files (None: default_jobs)
    changed: bool = False  # changed-files mode: the paths are files a commit changes (issue 13)
    look_through: bool = True  # check the robot with its safe fixes applied (see above)
    # the output shows the edits of unsafe fixes (--fix, --diff, JSON, SARIF, the editor); text
    # shows only their hints, so the costly ones are not derived (``rules.UNSAFE_EDITS``)
    unsafe_edits: bool = True
    selection: object = None  # package.Selection: what directories' files are checked
    config_file: Path | None = None  # --config: this configuration for every file
    robot: str | None = None  # --robot: the robot of the companion files (SRDF) given


LOOKS = 3  # rounds of look-through: a fix can uncover more (a macro call's body)
FOUND_THROUGH = " (found once the safe fixes are applied)"
FOUND_PAST = " (found by reading past the xacro errors)"


def _diagnostic(rule, severity: str, finding: Finding, default_path: str) -> Diagnostic:
    loc = finding.loc
    fix = None
    if finding.edits and rule.fix:
        from urdftool.edits import Fix

        fix = Fix(rule.fix, tuple(finding.edits))
    return Diagnostic(rule.id, finding.severity or severity, finding.message,
                      loc.path if loc is not None else default_path,
                      loc.line if loc is not None else None,
                      loc.column if loc is not None else None,
                      loc.element if loc is not None else None, finding.hint,
                      call_sites=(tuple(loc.via),) if loc is not None and loc.via else (),
                      fix=fix)


def target_options(options: CheckOptions, target: Target | None = None) -> LoadOptions:
    """``options.load`` with the xacro arguments and packages of ``target``'s configuration
    (the command line's values win)."""
    load_options = options.load
    if target is not None and (target.args or target.packages):
        load_options = copy.copy(load_options)
        load_options.xacro_args = {**target.args, **load_options.xacro_args}
        load_options.packages = {**target.packages, **load_options.packages}
    return load_options


def check_once(path: Path | str, options: CheckOptions, load_options=None):
    """(source, robot, diagnostics) of one reading of ``path``: every selected rule, no
    look-through, no suppressions (a companion file: ``companion_check.companion_once``)."""
    if is_companion(path):
        from urdftool.companion_check import companion_once

        return companion_once(sys.modules[__name__], path, options, load_options)[:3]
    source = load(path, load_options or options.load)
    robot = build_robot(source)
    diagnostics = run_rules(robot, source.path, options)
    if source.controllers:  # the controllers YAML its simulator plugin names (issue 31)
        from urdftool.companion import Controllers

        for data in source.controllers:
            diagnostics += run_rules(Controllers(data, robot), source.path, options,
                                     on="controllers")
    return source, robot, diagnostics


def run_rules(subject, default_path: str, options: CheckOptions, on: str = "robot",
              keep=None) -> list[Diagnostic]:
    """The diagnostics of every selected rule given ``on`` (``rules.SUBJECTS``: the robot, or
    a companion model) that ``keep(rule)`` keeps (all without it)."""
    rules_module.UNSAFE_EDITS = options.unsafe_edits
    select = options.select or options.config.select
    ignore = options.ignore + options.config.ignore
    enabled = [(rule, severity) for rule, severity in
               _enabled(select, ignore, options.config.severity)
               if rule.on == on and (keep is None or keep(rule))]
    source = subject.source
    ran = rules_module.run(subject, enabled, options.load.timeout, options.debug)
    diagnostics = [_diagnostic(r.rule, r.severity, r.finding, default_path) for r in ran]
    if any(rule in REFUSING_RULES for rule, _ in source.problems):
        diagnostics = _without_refused(diagnostics, source)
    return diagnostics


REFUSING_RULES = ("xacro.unsafe-expression", "xacro.limit-exceeded")


def _without_refused(diagnostics: list[Diagnostic], source) -> list[Diagnostic]:
    """A refused expression's value is a placeholder (``xacro_eval.REFUSED_TEXT``) so that
    the rest of the file is expanded and checked. Findings that depend on it would be false
    alarms: those that quote it, and those located at an element that holds it, inside one,
    or around one (a link whose origin was refused), are dropped; the refusal itself is the
    finding."""
    from urdftool.xacro_eval import REFUSED_TEXT

    marked = set()
    if source.root is not None:
        for element in source.root.iter():
            if isinstance(element.tag, str) and (
                    REFUSED_TEXT in (element.text or "")
                    or any(REFUSED_TEXT in value for value in element.attrib.values())):
                marked.add(source.xpath(element))
    if not marked:
        return diagnostics

    def depends(d: Diagnostic) -> bool:
        if REFUSED_TEXT in d.message:
            return True
        where = d.element
        return bool(where) and any(where == m or m.startswith(where + "/")
                                   or where.startswith(m + "/") for m in marked)

    return [d for d in diagnostics if d.rule.startswith("xacro.") or not depends(d)]


def overlay_options(load_options: LoadOptions, texts: dict[str, str]) -> LoadOptions:
    """``load_options`` reading ``texts`` (shown path -> text) from memory."""
    load_options = copy.copy(load_options)
    load_options.overlay = {**getattr(load_options, "overlay", {}),
                            **{str(Path(p).resolve()): t for p, t in texts.items()}}
    return load_options


def _safe(diagnostic: Diagnostic) -> bool:
    return diagnostic.fix is not None and diagnostic.fix.applicability == "safe"


def _look_through(path, options: CheckOptions, load_options: LoadOptions, source, robot,
                  diagnostics):
    """(texts as written, robot, diagnostics) after looking through the safe fixes, and past
    an undefined xacro name (a missing include's properties): reported where it is used, the
    rest expanded with the expression left as written (``LoadOptions.lenient``)."""
    from urdftool.edits import apply, map_diagnostic

    originals = dict(source.texts)
    written = source  # the files as written, for what their consumers read
    stopped = source.kind == "xacro" and source.root is None and any(
        rule == "xacro.error" and "is not defined" in f.message for rule, f in source.problems)
    if not stopped and not any(_safe(d) and not d.rule.startswith("xml.") for d in diagnostics):
        return originals, robot, diagnostics  # the XML repairs are made while reading
    seen = {(d.rule, d.path, d.line, d.message) for d in diagnostics}
    # what reading past the undefined names hides: the error itself is reported
    kept = [d for d in diagnostics if d.rule.startswith("xacro.") and not _safe(d)] \
        if stopped else []
    texts = dict(source.texts)
    history: list[dict] = []  # per round: path -> the edits made (in that round's text)
    fixed: list[Diagnostic] = []
    current = diagnostics
    if stopped:
        load_options = copy.copy(load_options)
        load_options.lenient = True
    for round_ in range(LOOKS):
        if budget.spent():  # the run's time is out: what was found so far is the report
            break
        safe = [d for d in current if _safe(d)]
        edits = [e for d in safe for e in d.fix.edits]
        made: dict[str, list] = {}
        for name in {e.path for e in edits}:
            if name not in texts:  # a file xacro did not read (an unprocessed include)
                if name not in source.unread:
                    continue
                texts[name] = originals[name] = source.unread[name]
            new, made_here = apply(texts[name], edits, name)
            if new != texts[name]:
                texts[name], made[name] = new, made_here
        if not made and not (stopped and round_ == 0):
            break
        fixed.extend(map_diagnostic(d, history) for d in safe if d.path in made)
        history.append(made)
        try:
            source, robot, current = check_once(path, options,
                                                overlay_options(load_options, texts))
        except ToolError:
            return originals, robot, diagnostics
        for name, text in source.texts.items():
            originals.setdefault(name, text)
    note = FOUND_PAST if stopped else FOUND_THROUGH
    keys = {(d.rule, d.path, d.line, d.message) for d in fixed}
    unread = _unread_spans(written, fixed)
    result = list(fixed)
    for d in [*kept, *current]:
        d = map_diagnostic(d, history) if d not in kept else d
        key = (d.rule, d.path, d.line, d.message)
        if key in keys or (stopped and "unexpanded xacro expression" in d.message):
            continue
        keys.add(key)
        if key not in seen:
            d = d._replace(message=d.message + note)
            tag = _inside(d, unread)
            if tag is not None and d.severity == "error":
                d = d._replace(severity="warning", message=d.message + UNREAD_NOTE.format(tag))
        result.append(d)
    return originals, robot, result


# fixed findings that say their element, as written, is read by no consumer: what the fix
# makes read was never read before it
UNREAD_AS_WRITTEN = ("schema.unknown-element", "schema.misplaced-element",
                     "schema.unknown-attribute")
UNREAD_NOTE = ("; as written, <{}> is read by no consumer, so this is a warning (an error "
               "once the fix is applied: correct both together)")


def _unread_spans(source, fixed: list[Diagnostic]) -> list[tuple[str, int, int, str]]:
    """(path, first line, last line, tag) of the elements as written that safe fixes make read
    (a renamed unknown element, a moved misplaced one, an element with a renamed attribute)."""
    from lxml import etree

    spans = []
    root = source.root
    for d in fixed:
        if d.rule not in UNREAD_AS_WRITTEN or not d.element or d.line is None or root is None:
            continue
        try:
            found = root.getroottree().xpath(d.element)
        except etree.XPathError:  # a path this document cannot answer: no span
            continue
        for element in found if isinstance(found, list) else ():
            if not isinstance(getattr(element, "tag", None), str):
                continue
            lines = [loc.line for loc in map(source.loc, element.iter())
                     if loc.line is not None and loc.path == d.path]
            spans.append((d.path, min([d.line, *lines]), max([d.line, *lines]), element.tag))
    return spans


def _inside(d: Diagnostic, spans) -> str | None:
    """The tag of the span ``d`` lies in, if any."""
    for path, first, last, tag in spans:
        if d.path == path and d.line is not None and first <= d.line <= last:
            return tag
    return None


def check_file(path: Path | str, options: CheckOptions | None = None,
               target: Target | None = None) -> FileReport:
    """All findings for one file (``target``: with the xacro arguments and packages of its
    configuration), looking through its safe fixes. Raises ToolError when the file cannot be
    read at all."""
    return check_model(path, options, target)[0]


def check_model(path: Path | str, options: CheckOptions | None = None,
                target: Target | None = None):
    """(``check_file``'s report, the robot the rules ran on): the language server answers
    hovers from the model of its last check."""
    options = options or CheckOptions()
    if budget.spent():
        return not_checked(path, target), None
    if is_companion(path):
        from urdftool.companion_check import check_companion

        return check_companion(sys.modules[__name__], path, options, target)
    load_options = target_options(options, target)
    source, robot, diagnostics = check_once(path, options, load_options)
    texts = source.texts
    if options.look_through:
        texts, robot, diagnostics = _look_through(path, options, load_options, source, robot,
                                                  diagnostics)
    report = finish(source, robot, diagnostics, texts)
    report.args = target.args if target is not None else {}
    return report, robot


def not_checked(path: Path | str, target: Target | None = None) -> FileReport:
    """The report of a file the run had no time left for (issue 21): one
    ``xacro.limit-exceeded`` finding, an error (the gate must not pass what it did not read)."""
    message = f"not checked: {budget.describe()}"
    if target is not None and target.args:
        message += " (with " + " ".join(f"{k}:={v}" for k, v in target.args.items()) + ")"
    report = FileReport(str(path), None, [Diagnostic(
        "xacro.limit-exceeded", "error", message, str(path), None, None, None,
        "raise --timeout, or check fewer files in one run")], {})
    report.args = target.args if target is not None else {}
    return report


def refused_reports(refused: list[tuple[str, str]], options: CheckOptions,
                    given: set[str] | None = None) -> list[FileReport]:
    """One report per file the plan refused unread for its size (``Selection.refused``: a
    launch file over ``launch.MAX_BYTES``, issue 21), each with one ``xacro.limit-exceeded``
    warning at the file: the xacro arguments it passes are not known, the package's xacro
    files are checked without them (an error there says what is missing). In changed-files
    mode only those among the given files."""
    rule = load_all().get("xacro.limit-exceeded")
    select = options.select or options.config.select
    ignore = options.ignore + options.config.ignore
    if rule is None or not selected(rule.id, select, ignore):
        return []
    configured = options.config.severity.get(rule.id)  # else a warning: the robots were checked
    reports = []
    for path, why in refused:
        if given is not None and str(Path(path).resolve()) not in given:
            continue
        finding = Finding(f"{why}; the xacro arguments passed there are not known",
                          Loc(path, None, None), severity=None if configured else "warning",
                          hint="split the launch files, or list the entries and their arguments "
                               "in urdftool.toml")
        report = FileReport(path, None, [_diagnostic(rule, configured, finding, path)], {})
        report.role = "refused"
        reports.append(report)
    return reports


def finish(source, robot, diagnostics: list[Diagnostic], texts: dict[str, str]) -> FileReport:
    """The FileReport: suppressed findings dropped, macro instances grouped, the rest in file
    and line order."""
    quiet = {p: suppressions(t, p) for p, t in texts.items()}
    diagnostics = [d for d in diagnostics
                   if not (d.line and (quiet.get(d.path, {}).get(d.line, set())
                                       & {d.rule, d.rule.split(".")[0]}))]
    diagnostics = group_instances(diagnostics)
    diagnostics.sort(key=lambda d: (d.path != source.path, d.path, d.line or 0, d.column or 0,
                                    d.rule))
    report = FileReport(source.path, robot.name, diagnostics, texts)
    report.args = {}
    read, missing = other_inputs(source, robot)
    report.includes = tuple(sorted({real(p) for p in texts if p != source.path} | read))
    report.missing = missing
    report.role = role(source, robot)
    return report


_ENABLED: dict[tuple, list] = {}


def _enabled(select: list[str], ignore: list[str], severities: dict[str, str]) -> list:
    """(rule, severity) of every rule selected, in registry order (the same for every file of
    a run: found once)."""
    registry = load_all()
    key = (tuple(select), tuple(ignore), tuple(severities.items()), len(registry))
    found = _ENABLED.get(key)
    if found is None:
        found = _ENABLED[key] = [(rule, severities.get(rule.id, rule.severity))
                                 for rule in registry.values()
                                 if selected(rule.id, select, ignore)]
    return found


def available_cpus() -> int:
    """The CPUs this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


# what a file costs a worker, roughly (warm mesh cache, one 2-core machine: the corpus's 164
# robots, 3.3 MB, take ~1.3 s in one process), and the work a worker must have to pay for its
# fork, its share of the results' pickling and the per-process memos it builds again
SECONDS_PER_FILE = 0.002
SECONDS_PER_BYTE = 3e-7
WORK_PER_WORKER = 1.0


def _cost(path: str, per_file: float = SECONDS_PER_FILE,
          per_byte: float = SECONDS_PER_BYTE) -> float:
    """The estimated seconds of checking ``path``: ``per_file`` plus ``per_byte`` a byte."""
    try:
        size = os.stat(path).st_size
    except OSError:
        size = 0
    return per_file + size * per_byte


def default_jobs(paths: list, per_file: float = SECONDS_PER_FILE,
                 per_byte: float = SECONDS_PER_BYTE) -> int:
    """The most worker processes worth having when --jobs is not given: one per
    ``WORK_PER_WORKER`` seconds of work estimated from the files' count and sizes (``per_file``
    seconds a file plus ``per_byte`` a byte), at most the CPUs available. A handful of small
    files is checked in this process (issue 15: a pool of 2 was 1.2x slower than one process
    on the corpus); ``check`` then measures (see ``_check_measured``). ``urdftool sim`` sizes
    its pool the same way with its own costs."""
    work = sum(_cost(path, per_file, per_byte) for path in paths)
    return max(1, min(available_cpus(), len(paths), int(work / WORK_PER_WORKER)))


RUNS_PER_WORKER = 8


def _runs(paths: list[str], jobs: int) -> list[tuple[int, int, float]]:
    """``paths`` cut into runs of neighbouring files (a directory's robots share meshes: one
    worker reads them) of about equal estimated cost, ``RUNS_PER_WORKER`` for each of ``jobs``
    workers: (start, end, cost). Equal counts of files were not equal work (a corpus's 1000 small
    objects beside its 20 humanoids left one worker busy for seconds after the other ended)."""
    costs = [_cost(path) for path in paths]
    share = sum(costs) / (jobs * RUNS_PER_WORKER)
    runs, start, cost = [], 0, 0.0
    for index, value in enumerate(costs):
        cost += value
        if cost >= share:
            runs.append((start, index + 1, cost))
            start, cost = index + 1, 0.0
    if start < len(paths):
        runs.append((start, len(paths), cost))
    return runs


def check_paths(paths: list[str], options: CheckOptions | None = None,
                progress=None) -> Report:
    """Check every robot file under ``paths``. Raises ToolError when there is nothing to check,
    and the error of the first file (in order) that cannot be checked at all. ``progress(done,
    total)`` is called as files are done (the CLI's progress display)."""
    import time

    started = time.monotonic()
    options = copy.copy(options or CheckOptions())
    # what the run may read, once, from the operator's options and the paths given (changed
    # files are data: the working directory's repository): before any configuration is read
    options.load = copy.copy(options.load)
    # (--robot: the robot of the companion files given, typed by the operator)
    options.load.roots = run_roots([*paths, *([options.robot] if options.robot else [])],
                                   options.load, named=options.changed)
    selection = options.selection if options.selection is not None else Selection()
    files, given = plan(paths, options.changed, selection, options.config_file)
    files = with_operator_args(files, options.load.xacro_args)
    if not files and given is not None:  # changed files of no package with robot files
        report = Report([], [])
        report.seen = set()
        return report
    if not files:
        raise NothingToCheck("no robot files (*.urdf, *.xacro, *.sdf) found in " + ", ".join(paths))
    _single_threaded_blas()
    # a run allocates many short-lived objects (XML proxies, model records): the young
    # generation collected 30x less often, and so the whole heap rarely walked (~4% of a run)
    thresholds = gc.get_threshold()
    gc.set_threshold(max(thresholds[0], 20000), *thresholds[1:])
    try:
        # one budget for the run: --timeout for each distinct file found (a file listed many
        # times in the configuration's entries shares its own)
        budget.start(options.load.timeout, len({real(f.path) for f in files}), started)
        if given is not None:  # what the checks read last time and is gone: deleted too
            given |= gone(files, options.load)
        todo, reports, waiting = unaffected(files, given, options.load)  # changed files:
        checked = _check_targets(files, todo, options, progress)  # what reads them
        for i, report in zip(todo, checked):
            reports[i] = report
            if given is not None:
                store_reads(files[i], options.load, report)
        later = settle(files, reports, waiting, options.load) if waiting else []
        for i, report in zip(later, _check_targets(files, later, options, progress)):
            reports[i] = report
            store_reads(files[i], options.load, report)
        return run_report(files, reports, given, selection, options)
    finally:
        gc.set_threshold(*thresholds)
        budget.stop()


def run_report(files: list[Target], reports: list[FileReport], given=None,
               selection: Selection | None = None, options: CheckOptions | None = None) -> Report:
    """The findings of a run from the report of each planned target, as ``check DIR`` shows
    them: each file's role (``package.classify``: a fragment's findings come through its
    entries), repeats merged, one finding per missing package, what the plan refused unread
    (``selection.refused``: ``refused_reports``), and the files seen (for baselines).
    ``check_paths`` and the language server both end here, so that they cannot drift.
    ``reports`` may be changed (copy them to keep them)."""
    shown, notes = classify(files, reports, given, selection)
    refused = refused_reports(selection.refused, options or CheckOptions(), given) \
        if selection is not None else []
    report = Report(_one_per_missing_package(merge_repeats(shown)) + refused, notes)
    report.seen = seen_files(files, shown, reports, given) | {
        str(Path(r.path).resolve()) for r in refused}
    return report


def _one_per_missing_package(files: list[FileReport]) -> list[FileReport]:
    """One finding per cause (issue 22.3): a package no check of the run finds stops every
    expansion that needs it; it is said once, at its first place, with how many other places
    (files) met it, not once per file."""
    import re

    pattern = re.compile(r"xacro: \$\(find (\S+)\): package '\1' not found(?:$|; skipped)")
    first: dict[str, tuple[FileReport, int]] = {}
    others: dict[str, list[str]] = {}
    for report in files:
        kept = []
        for d in report.diagnostics:
            match = pattern.match(d.message) if d.rule == "xacro.error" else None
            if match is None:
                kept.append(d)
                continue
            name = match.group(1)
            if name in first:
                others[name].append(f"{d.path}:{d.line}" if d.line else d.path)
                continue
            first[name] = (report, len(kept))
            others[name] = []
            kept.append(d)
        report.diagnostics = kept
    for name, places in others.items():
        if places:
            report, index = first[name]
            d = report.diagnostics[index]
            shown = ", ".join(places[:3]) + (f" and {len(places) - 3} more" if len(places) > 3
                                             else "")
            head = f"xacro: $(find {name}): package '{name}' not found"
            report.diagnostics[index] = d._replace(  # (then what an include does without it)
                message=f"{head}; {len(places)} other expansion(s) need it too: {shown}"
                        f"{d.message[len(head):]}")
    return files


def _check_targets(files: list, todo: list[int], options: CheckOptions, progress) -> list:
    """The reports of ``files[i]`` for ``i`` in ``todo``, in that order: in this process, or
    in worker processes when that pays."""
    if not todo:
        return []
    targets = [files[i] for i in todo]
    jobs = min(options.jobs or default_jobs([t.path for t in targets]), len(targets))
    if jobs <= 1 or options.debug or not hasattr(os, "fork"):  # --debug: tracebacks here
        checked = []
        for target in targets:
            checked.append(check_file(target.path, options, target))
            if progress is not None:
                progress(len(checked), len(targets))
    elif options.jobs is None:  # measured before forking: the estimate cannot see meshes
        checked = _check_measured(targets, options, jobs, progress)
    else:
        checked = _check_in_workers(targets, options, jobs, progress)
    return checked


PROBE = 0.25  # seconds of checking in this process before deciding on workers
# ... unless after this long the rest, extrapolated, is already twice what the workers need
PROBE_SURE = 0.05


def _check_measured(targets: list, options: CheckOptions, jobs: int, progress) -> list:
    """The default --jobs: files checked here for ``PROBE`` seconds, then the rest in up to
    ``jobs`` workers if their time, extrapolated, gives each ``WORK_PER_WORKER`` seconds (a
    cold mesh cache: seconds of mesh parsing a file), else here too (a warm corpus: a pool
    was slower than this process, which already holds the run's memos; forked workers
    inherit them). The workers start after ``PROBE_SURE`` seconds when the rest is already
    twice that (a large corpus: the probe is time on one CPU while the others wait)."""
    import time

    start = time.perf_counter()
    checked: list = []
    total = len(targets)
    for target in targets:
        checked.append(check_file(target.path, options, target))
        if progress is not None:
            progress(len(checked), total)
        elapsed = time.perf_counter() - start
        left = total - len(checked)
        if elapsed > min(PROBE, PROBE_SURE) and left > 1:
            rest = elapsed / len(checked) * left
            workers = min(jobs, left, int(rest / WORK_PER_WORKER))
            if workers > 1 and (elapsed > PROBE or rest >= 2 * jobs * WORK_PER_WORKER):
                done = len(checked)
                shifted = None if progress is None else \
                    (lambda finished, _, done=done: progress(done + finished, total))
                return checked + _check_in_workers(targets[done:], options, workers, shifted)
    return checked


def _single_threaded_blas() -> None:
    """One BLAS thread, unless the user chose (read when numpy is first imported, so only then):
    the mesh arrays are small, and OpenBLAS's thread pool spent ~8% of a check run's CPU for no
    gain in time (and oversubscribed the CPUs with --jobs workers). Results are the same: each
    product here is computed by one thread either way."""
    if "numpy" not in sys.modules and not any(
            name in os.environ for name in ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS",
                                            "OMP_NUM_THREADS")):
        os.environ["OPENBLAS_NUM_THREADS"] = "1"


# -- the worker pool --------------------------------------------------------------------------


def _worker_chunk(paths: list, options: CheckOptions) -> tuple[list[tuple[bool, object]], list]:
    """The results of ``paths``, and the files this worker read (for the parent's "files read"
    set: ``urdftool.files``)."""
    from urdftool import files

    return [_worker(path, options) for path in paths], files.read_paths()


def _note_reads(paths: list) -> None:
    from urdftool import files

    for path in paths:
        files.note(path)


def _worker(path, options: CheckOptions) -> tuple[bool, object]:
    """(True, FileReport) or (False, the exception), so that one file's error comes back as
    that file's result and the pool goes on with the others."""
    try:
        return True, check_file(path.path, options, path)
    except Exception as exc:  # noqa: BLE001 - re-raised in the parent, in file order
        import pickle  # here: only workers need it (start-up of a one-file check)

        try:
            pickle.dumps(exc)
        except Exception:  # noqa: BLE001 - an exception that cannot travel: its text does
            exc = RuntimeError(exception_text(exc))
        return False, exc


def _check_in_workers(files: list, options: CheckOptions, jobs: int,
                      progress=None) -> list[FileReport]:
    """``check_file`` of every file in ``jobs`` forked processes, in runs of neighbouring files
    (a directory's robots share meshes: one worker reads them). A worker that dies (a crash in
    a parser, the OOM killer) breaks the pool: the files it left unchecked are then checked one
    process each, so that only the file that kills its process is reported (ToolError)."""
    import multiprocessing

    context = multiprocessing.get_context("fork")
    files = [f if isinstance(f, Target) else Target(str(f)) for f in files]
    gc.freeze()  # what the workers inherit is never collected there (nor its pages copied)
    try:
        results = _pooled(files, options, jobs, context, progress)
    finally:
        gc.unfreeze()
    for index, path in enumerate(files):
        if results[index] is None:
            results[index] = _check_alone(path, options, context)
    reports = []
    for ok, value in results:  # type: ignore[misc]
        if not ok:
            raise value  # type: ignore[misc]
        reports.append(value)
    return reports


def _pooled(files: list, options: CheckOptions, jobs: int, context, progress) -> list:
    """The results of ``files`` from ``jobs`` forked workers; None for the files of a run
    whose worker died."""
    from concurrent.futures import ProcessPoolExecutor, as_completed
    from concurrent.futures.process import BrokenProcessPool

    results: list[tuple[bool, object] | None] = [None] * len(files)
    done = 0
    with ProcessPoolExecutor(jobs, mp_context=context) as pool:
        # the costliest runs first: a worker that is free takes the next, and the last runs
        # to be handed out are short, so the workers finish together
        futures = {pool.submit(_worker_chunk, files[start:end], options): (start, end)
                   for start, end, _ in sorted(_runs([f.path for f in files], jobs),
                                               key=lambda run: -run[2])}
        for future in as_completed(futures):
            start, end = futures[future]
            try:
                results[start:end], reads = future.result()
                _note_reads(reads)
            except BrokenProcessPool:
                pass
            done += end - start
            if progress is not None:
                progress(done, len(files))
    return results


def _check_alone(path, options: CheckOptions, context) -> tuple[bool, object]:
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool

    with ProcessPoolExecutor(1, mp_context=context) as pool:
        try:
            [result], reads = pool.submit(_worker_chunk, [path], options).result()
            _note_reads(reads)
            return result
        except BrokenProcessPool:
            return False, ToolError(f"{path.path}: the check of this file crashed its worker "
                                    "process (run with --jobs 1 --debug to see why)")
