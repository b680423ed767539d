"""The run of ``urdftool diff`` (issue 30): which robots a change touched, each read at both
sides as ``check`` reads it, and what changed (``diff.compare``).

Each side is a directory: the repository's working tree, a temporary tree written from a
revision's git objects (``diff.revisions``), or a snapshot given by the user. A side is planned
and checked exactly as ``check`` would (``package.plan`` with the side's configuration, launch
arguments and the operator's ``NAME:=VALUE``; ``check.check_model`` per target, so both sides
read under the run's trust mode and budget); the robots compared are the entries whose inputs
the change touched (``package.classify`` in changed-files mode: the "reads" graph of
``check --changed``), matched across sides by their file and arguments.
"""

from __future__ import annotations

import copy
import hashlib
import os
import re
import time
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import NamedTuple

from urdftool import budget
from urdftool.check import CheckOptions, check_model
from urdftool.config import load_config
from urdftool.diff.compare import Change, compare
from urdftool.errors import ToolError
from urdftool.findings import Loc
from urdftool.loader import run_roots
from urdftool.package import Selection, classify, plan, triggers, with_operator_args
from urdftool.roots import real

# files no robot reads: a change to them alone plans nothing (a README, CI configuration)
_NOT_INPUTS = (".md", ".rst", ".txt", ".cmake", ".c", ".cc", ".cpp", ".h", ".hpp", ".in",
               ".cfg", ".toml.orig", ".gitignore", ".gitattributes")


class Entry(NamedTuple):
    """One robot at one side: the entry (path relative to the side's tree) and its arguments,
    check's report of it and the robot its rules ran on (None when it could not be read)."""

    path: str
    args: dict
    report: object
    robot: object
    diagnostics: list


class RobotDiff(NamedTuple):
    entry: str
    args: dict
    status: str  # changed, unchanged, added, removed, error
    changes: list[Change]
    reason: str | None
    introduced: list  # diagnostics at HEAD not at BASE (check at both sides)
    fixed: list  # diagnostics at BASE not at HEAD
    base: Entry | None
    head: Entry | None


class Side(NamedTuple):
    """A side of the diff: its label (a revision, ``WORKTREE`` or a path) and its directory."""

    label: str
    tree: Path
    entry_file: str | None = None  # a snapshot file: its findings are named as the other's
    blobs: dict = {}  # noqa: RUF012 - path in the tree -> git blob id, where known (never mutated)
    args: dict = {}  # noqa: RUF012 - operator arguments as this side reads them (``side_args``)


def side_args(args: dict[str, str], repo: Path, tree: Path) -> dict[str, str]:
    """The operator's ``NAME:=VALUE`` for one side: a value naming a file of the repository
    (relative to the working directory or absolute) names that file in the side's tree, so
    that BASE reads BASE's parameter file (``visual_params:=config/ur5e/visual.yaml``)."""
    mapped = {}
    root = os.path.realpath(repo)
    for name, value in args.items():
        full = os.path.realpath(os.path.abspath(value)) if value else ""
        if full.startswith(root + os.sep):
            rel = os.path.relpath(full, root)
            if os.path.lexists(tree / rel):
                mapped[name] = str(tree / rel)
                continue
        mapped[name] = value
    return mapped


def relative(path: str | None, tree: Path) -> str | None:
    """``path`` relative to ``tree`` ('/'-separated) when inside it, else as given."""
    if path is None:
        return None
    full = os.path.abspath(path)
    for root in {os.path.abspath(tree), os.path.realpath(tree)}:
        if full == root or full.startswith(root.rstrip(os.sep) + os.sep):
            return Path(os.path.relpath(full, root)).as_posix()
    return path


def relative_text(text: str, tree: Path) -> str:
    """A message or call site with the side's tree written away (paths relative to it)."""
    for root in sorted({os.path.abspath(tree), os.path.realpath(tree)}, key=len, reverse=True):
        text = text.replace(root.rstrip(os.sep) + os.sep, "")
    return text


def relevant(name: str) -> bool:
    """Whether a changed file may be an input of a robot (not documentation, CI, sources)."""
    parts = name.split("/")
    if any(part.startswith(".") for part in parts[:-1]):
        return False
    base = parts[-1]
    return not (base.lower().endswith(_NOT_INPUTS) or base.upper().startswith("LICENSE"))


def side_entries(side: Side, options: CheckOptions, changed: list[str] | None,
                 limits: list[str]) -> tuple[dict[tuple, Entry], set[tuple]]:
    """(every entry of the side's plan by key, the keys of those the change touched). With
    ``changed`` (paths relative to the tree), the plan of ``check --changed`` over them;
    without, every entry under the tree (a snapshot)."""
    started = time.monotonic()
    options = copy.copy(options)
    options.load = copy.copy(options.load)
    tree = side.tree
    if side.args:
        options.load.xacro_args = dict(side.args)
    options.load.roots = run_roots([str(tree)], options.load)
    options.config = load_config(tree)
    selection = Selection()
    if changed is None:
        paths = [str(tree / limit) for limit in limits] if limits else [str(tree)]
        targets, given = plan(paths, False, selection)
    else:
        names = [name for name in changed if relevant(name)]
        if not names:
            return {}, set()
        targets, given = plan([str(tree / name) for name in names], True, selection)
    targets = with_operator_args(targets, options.load.xacro_args)
    if not targets:
        return {}, set()
    budget.start(options.load.timeout, len({real(t.path) for t in targets}), started)
    try:
        reports, robots = [], []
        for target in targets:
            try:
                report, robot = check_model(target.path, options, target)
            except ToolError as exc:
                from urdftool.check import not_checked

                report, robot = not_checked(target.path, target), None
                report.diagnostics[0] = report.diagnostics[0]._replace(message=str(exc))
            reports.append(report)
            robots.append(robot)
    finally:
        budget.stop()
    every = [list(r.diagnostics) for r in reports]
    # every file's role as `check DIR` gives it (whatever the change touched: an entry that
    # stopped reading a changed file is still looked up at the other side)
    shown, _ = classify(targets, reports, None, selection)
    entry_ids = {id(r) for r in shown if r.role == "entry"}
    entries: dict[tuple, Entry] = {}
    touched: set[tuple] = set()
    for target, report, robot, diagnostics in zip(targets, reports, robots, every):
        if id(report) not in entry_ids:
            continue
        path = relative(target.path, tree)
        if limits and changed is not None and not any(
                path == limit.rstrip("/") or path.startswith(limit.rstrip("/") + "/")
                for limit in limits):
            continue
        key = (path, tuple(sorted(report.args.items())))
        entry = entries.setdefault(key, Entry(path, dict(report.args), report, robot,
                                              diagnostics))
        # an entry of a touched package that does not expand may never reach the changed
        # files: compared all the same (status error, with the reason), never left out
        if changed is None or _reads(target, report, given) or _failure(entry) is not None:
            touched.add(key)
    return entries, touched


def _reads(target, report, given: set[str]) -> bool:
    """Whether a check read a changed file: the "reads" graph of ``check --changed`` (its
    file, its includes, YAML and meshes; a launch file of its package)."""
    return bool({real(target.path), *report.includes} & given) or bool(
        triggers(target, report, given))


class Meshes:
    """A mesh geometry's content at one side: its git blob id (known from the revision, or
    computed from the file as git does, memoised by path) and, when two differ, its summary
    (``physics.meshes.load_mesh``: bounding box and volume)."""

    def __init__(self, *sides: Side):
        self._digests: dict[str, str | None] = {}
        for side in sides:
            root = os.path.realpath(side.tree)
            for path, blob in side.blobs.items():
                self._digests[os.path.join(root, path)] = blob

    def _path(self, robot, geometry):
        from urdftool.physics.meshes import resolve

        try:
            path = resolve(robot, geometry)
        except Exception:  # noqa: BLE001 - an unresolvable URI: check reports it
            return None
        return path if path is not None and os.path.isfile(path) else None

    def digest(self, robot, geometry) -> str | None:
        path = self._path(robot, geometry)
        if path is None:
            return None
        key = real(path)
        if key not in self._digests:
            from urdftool.files import read_regular
            from urdftool.physics.meshes import MAX_MESH_BYTES

            try:
                data = read_regular(key, MAX_MESH_BYTES)
                self._digests[key] = hashlib.sha1(b"blob %d\0" % len(data) + data).hexdigest()
            except OSError:
                self._digests[key] = None
        return self._digests[key]

    def summary(self, robot, geometry):
        path = self._path(robot, geometry)
        if path is None:
            return None
        from urdftool.physics.meshes import load_mesh

        return load_mesh(path, need_volume=True)


_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _finding_key(d, side: Side) -> tuple:
    path = relative(d.path, side.tree)
    message = relative_text(d.message, side.tree)
    if side.entry_file is not None:
        name = os.path.basename(side.entry_file)
        if real(d.path) == real(side.entry_file):
            path = "<entry>"
        message = message.replace(name, "<entry>")
    return (d.rule, path, _NUMBER.sub("#", message))


def _findings_delta(base: Entry | None, head: Entry | None, base_tree: Side,
                    head_tree: Side) -> tuple[list, list]:
    """(introduced, fixed): findings of HEAD's check not at BASE and the reverse, matched by
    rule, file and message without its numbers (a finding whose value changed is the same)."""
    return _only_in(head, head_tree, base, base_tree), _only_in(base, base_tree, head, head_tree)


def _only_in(entry: Entry | None, side: Side, other: Entry | None, other_side: Side) -> list:
    """The diagnostics of ``entry`` that ``other`` does not have (as many times as it has
    fewer of them)."""
    from collections import Counter

    mine = list(entry.diagnostics) if entry else []
    left = Counter(_finding_key(d, side) for d in mine) - Counter(
        _finding_key(d, other_side) for d in (other.diagnostics if other else ()))
    found = []
    for d in mine:
        key = _finding_key(d, side)
        if left[key] > 0:
            left[key] -= 1
            found.append(d)
    return found


def _failure(entry: Entry) -> str | None:
    """Why an entry gives no robot a consumer can read (no links, or an XML or xacro error:
    check reads past it, xacro and the parsers do not), or None."""
    stopping = [d for d in entry.diagnostics if d.severity == "error"
                and d.rule.startswith(("xml.", "xacro."))]
    robot = entry.robot
    if robot is not None and robot.links and not stopping:
        return None
    errors = stopping or [d for d in entry.diagnostics if d.severity == "error"]
    if not errors:
        return "no robot (no links)"
    d = errors[0]
    where = f"{d.path}:{d.line}" if d.line else d.path
    return f"{where}: {d.rule}: {d.message}"


def diff_entries(base_side: Side, head_side: Side, base: dict, head: dict,
                 keys: list[tuple]) -> list[RobotDiff]:
    meshes = Meshes(base_side, head_side)
    robots = []
    for key in keys:
        a, b = base.get(key), head.get(key)
        introduced, fixed = _findings_delta(a, b, base_side, head_side)
        path, args = key[0], dict(key[1])
        if a is None or b is None:
            status = "added" if a is None else "removed"
            failure = _failure(b if a is None else a)
            reason = (f"{'HEAD' if a is None else 'BASE'} does not expand: "
                      f"{relative_text(failure, head_side.tree if a is None else base_side.tree)}"
                      if failure else None)
            robots.append(RobotDiff(path, args, status, [], reason, introduced, fixed, a, b))
            continue
        failures = [(label, relative_text(f, side.tree)) for label, f, side in
                    (("BASE", _failure(a), base_side), ("HEAD", _failure(b), head_side)) if f]
        if failures:
            reason = "; ".join(f"{label} does not expand: {f}" for label, f in failures)
            robots.append(RobotDiff(path, args, "error", [], reason, introduced, fixed, a, b))
            continue
        changes = compare(a.robot, b.robot, meshes)
        robots.append(RobotDiff(path, args, "changed" if changes else "unchanged", changes,
                                None, introduced, fixed, a, b))
    return robots


def diff_sides(base_side: Side, head_side: Side, options: CheckOptions,
               changed: list[str] | None, limits: list[str]) -> list[RobotDiff]:
    """The robots of two sides compared. ``changed``: the files the change touched (relative
    to the trees), or None for two snapshots (every entry of each)."""
    head, head_touched = side_entries(head_side, options, changed, limits)  # first: BASE's
    base, base_touched = side_entries(base_side, options, changed, limits)  # meshes share
    touched = base_touched | head_touched
    keys = sorted(touched)
    return diff_entries(base_side, head_side, base, head, keys)


def share_meshes(tree: Path, blobs: dict[str, str], other: Path,
                 other_blobs: dict[str, str]) -> None:
    """Mesh files of a revision's tree that hold the same git blob as a file of ``other`` (the
    working tree, or the other revision's tree): summarised once (``meshes.same_content``)."""
    from urdftool.physics.meshes import LOADABLE, same_content

    for path, blob in blobs.items():
        if other_blobs.get(path) == blob and os.path.splitext(path)[1].lower() in LOADABLE:
            same_content(tree / path, other / path)


def diff_snapshots(old: Path, new: Path, options: CheckOptions,
                   limits: list[str]) -> tuple[list[RobotDiff], Side, Side]:
    """Two files (one robot) or two directories (their entries), as the user gave them."""
    if old.is_file():
        base, head = Side(str(old), old.parent, str(old)), Side(str(new), new.parent, str(new))
        return diff_files(old, new, options), base, head
    base, head = Side(str(old), old), Side(str(new), new)
    return diff_sides(base, head, options, None, limits), base, head


@contextmanager
def diff_revisions(repo: Path, base_rev: str, head_rev: str | None, merge_base: bool,
                   options: CheckOptions, xacro_args: dict[str, str], limits: list[str]):
    """(robots, BASE side, HEAD side) of two revisions of ``repo`` (``head_rev`` None: the
    working tree), each read from git objects into a temporary tree that lives as long as
    the context (pictures are drawn from its meshes)."""
    from urdftool.diff import revisions as git

    base_commit = git.commit(repo, base_rev)
    head_commit = git.commit(repo, head_rev) if head_rev is not None else None
    if merge_base and head_commit is not None:
        base_commit = git.merge_base(repo, base_commit, head_commit)
    changed = git.changed_files(repo, base_commit, head_commit)
    worktree = git.worktree_blobs(repo)
    with ExitStack() as stack:
        base_dir = Path(stack.enter_context(git.temporary_tree("base")))
        base_blobs = git.materialize(repo, base_commit, base_dir, worktree)
        base = Side(base_rev, base_dir, blobs=base_blobs)
        if head_commit is None:
            head = Side(git.WORKTREE, repo, blobs=worktree)
            share_meshes(base.tree, base_blobs, repo, worktree)
        else:
            head_dir = Path(stack.enter_context(git.temporary_tree("head")))
            head_blobs = git.materialize(repo, head_commit, head_dir, worktree)
            head = Side(head_rev, head_dir, blobs=head_blobs)
            share_meshes(head.tree, head_blobs, repo, worktree)  # (CI: HEAD is checked out,
            share_meshes(base.tree, base_blobs, head.tree, head_blobs)  # its meshes cached)
        base = base._replace(args=side_args(xacro_args, repo, base.tree))
        head = head._replace(args=side_args(xacro_args, repo, head.tree))
        yield diff_sides(base, head, options, changed, limits), base, head


def diff_files(old: Path, new: Path, options: CheckOptions) -> list[RobotDiff]:
    """Two snapshot files (a regenerated URDF): one robot, each read as ``check`` reads it."""
    sides = []
    for file in (old, new):
        options_side = copy.copy(options)
        options_side.load = copy.copy(options.load)
        options_side.load.roots = run_roots([str(file)], options_side.load)
        options_side.config = load_config(file.parent)
        budget.start(options_side.load.timeout, 1)
        try:
            report, robot = check_model(str(file), options_side)
        finally:
            budget.stop()
        sides.append(Entry(file.name, {}, report, robot, list(report.diagnostics)))
    base_side = Side(str(old), old.parent, str(old))
    head_side = Side(str(new), new.parent, str(new))
    key = (new.name, ())
    robots = diff_entries(base_side, head_side, {key: sides[0]}, {key: sides[1]}, [key])
    return [r._replace(entry=relative(str(new), Path.cwd()) or str(new)) for r in robots]


def located(loc: Loc | None, tree: Path) -> tuple[str | None, int | None, list[str]]:
    """(path relative to the side's tree, line, call sites) of a location."""
    if loc is None:
        return None, None, []
    return relative(loc.path, tree), loc.line, [relative_text(v, tree) for v in loc.via]
