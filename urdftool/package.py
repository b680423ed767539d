"""Description packages: which files of a check run are entries (they make a robot) and which
are fragments (files the entries include, or files holding only definitions), from what the real
expansion read; and changed-files mode (issue 13).

The plan (``plan``): every robot file under the given directories, the configured ``entries``
with their argument sets (a configured file is expanded with those, not alone), and, in
changed-files mode, every robot file of the packages the given files belong to.

After the files are checked, ``classify`` keeps:

- entries: configured ones, and files whose expansion has links (or anything other than
  definitions) that no other entry reads;
- lone fragments, that no entry reads: only what can be checked alone (``ALONE_SKIPS`` are not:
  they need the includer's links and joints; "the robot has no links" is never said of them);
- not the files an entry reads: their findings come through the entry, at their own lines.

In changed-files mode, only the checks that read a given file are kept, and only findings in the
given files are reported; how many lie elsewhere is said in a note.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import NamedTuple

from urdftool.config import find_config, parse_config
from urdftool.errors import ToolError
from urdftool.report import FileReport
from urdftool.roots import resolved
from urdftool.source import ROBOT_SUFFIXES, shown_path

# what a file that only defines things holds at its top level, once expanded
DEFINITION_TAGS = frozenset({"material", "gazebo", "ros2_control", "transmission",
                             "property", "macro", "include", "arg"})  # the last: old unprefixed xacro
# rules (or families) that need the whole robot: never run on a fragment alone
ALONE_SKIPS = ("structure", "gazebo", "transmission", "mimic", "material.undefined")


class Target(NamedTuple):
    """One check of a run: a file, its xacro arguments and packages (from the configuration)."""

    path: str
    args: dict[str, str] = {}  # noqa: RUF012 - never mutated (a NamedTuple field)
    packages: dict[str, str] = {}  # noqa: RUF012 - never mutated
    configured: bool = False  # listed in ``entries``: always an entry
    args_from: str = ""  # the launch file the arguments were read from (urdftool.launch)


def robot_files(directory: Path) -> list[Path]:
    """Every ``*.urdf``, ``*.xacro``, ``*.sdf`` under ``directory`` (hidden ones skipped),
    in a stable order."""
    found = []
    for dirpath, dirnames, filenames in os.walk(directory):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith("."))
        found.extend(Path(dirpath) / name for name in sorted(filenames)
                     if name.endswith(ROBOT_SUFFIXES))
    return found


def package_root(path: Path) -> Path:
    """The package a file belongs to: the nearest directory above it with a ``package.xml`` or
    a configuration (an empty ``urdftool.toml`` marks one); else the file's own directory."""
    file = path.resolve()
    found = find_config(file)
    config_dir = found[0].parent if found else None
    for parent in file.parents:
        if (parent / "package.xml").is_file() or parent == config_dir:
            return parent
    return file.parent


def _config_of(path: Path, memo: dict):
    """The parsed configuration that applies to ``path`` (memoised per file), or None."""
    found = find_config(path, memo.setdefault("directories", {}))
    if found is None:
        return None
    configs = memo.setdefault("configs", {})
    if found[0] not in configs:
        configs[found[0]] = parse_config(found[1], found[0])
    return configs[found[0]]


def plan(paths: list[str], changed: bool = False) -> tuple[list[Target], set[str] | None]:
    """The targets of a run, and in changed-files mode the given files (resolved)."""
    files: list[Path] = []
    given: set[str] | None = set() if changed else None
    for raw in paths:
        path = Path(raw)
        if path.is_dir():
            files.extend(robot_files(path))
        elif path.exists() or path.is_symlink():  # a dangling link: the loader answers
            if given is None or path.name.endswith(ROBOT_SUFFIXES):
                files.append(path)  # (changed-files mode: a YAML, a mesh, a launch file only
            if given is not None:  # re-checks the entries that read it: ``triggered``)
                given.add(str(path.resolve()))
        else:
            raise ToolError(f"{raw}: no such file or directory")
    if given is not None:
        roots = sorted({package_root(Path(p)) for p in given})
        known = {str(f.resolve()) for f in files}
        for root in roots:
            for found in robot_files(_shown(root, paths)):
                if str(found.resolve()) not in known:
                    known.add(str(found.resolve()))
                    files.append(found)
    configs: dict = {}
    targets: list[Target] = []
    configured: set[str] = set()
    for file in files:
        config = _config_of(file, configs)
        resolved = str(file.resolve())
        packages = config.packages if config is not None else {}
        entries = [e for e in config.entries if str(e.path) == resolved] if config else []
        if entries:
            configured.add(resolved)
            targets.extend(Target(str(file), e.args, packages, True) for e in entries)
        elif launched := _launched(file, configs):
            targets.extend(Target(str(file), args, packages, args_from=where)
                           for args, where in launched)
        else:
            targets.append(Target(str(file), {}, packages))
    # configured entries not among the files (outside the directories given): added in
    # changed-files mode (they may read a given file)
    if given is not None:
        for config in configs.get("configs", {}).values():
            for entry in config.entries:
                if str(entry.path) not in configured:
                    targets.append(Target(str(_shown(entry.path, paths)), entry.args, config.packages,
                                          True))
    return targets, given


def _launched(file: Path, memo: dict) -> list[tuple[dict[str, str], str]]:
    """The argument sets the launch files of ``file``'s package pass to it (memoised per
    package), for a xacro file the configuration does not list."""
    if not file.name.endswith(".xacro"):
        return []
    from urdftool.launch import launch_arguments

    root = package_root(file)
    found = memo.setdefault("launch", {})
    if root not in found:
        found[root] = launch_arguments(root)
    return found[root].get(file.name, [])


def _shown(path: Path, given: list[str]) -> Path:
    """``path`` named as the given paths are (relative to the working directory unless every
    one was absolute), as findings name files."""
    relative = next((raw for raw in given if not os.path.isabs(raw)), None)
    return Path(shown_path(path, relative if relative is not None else os.sep))


def classify(targets: list[Target], reports: list[FileReport],
             given: set[str] | None = None) -> tuple[list[FileReport], list[str]]:
    """The reports to show (entries, lone fragments restricted to what can be checked alone;
    in changed-files mode those that read a given file, restricted to findings in the given
    files), and notes for the user."""
    resolved = [str(Path(t.path).resolve()) for t in targets]
    entries = [i for i, (t, r) in enumerate(zip(targets, reports))
               if t.configured or r.role == "entry"]
    read_by_entry: dict[str, set[int]] = {}
    for i in entries:
        for path in reports[i].includes:
            read_by_entry.setdefault(path, set()).add(i)
    shown: list[int] = []
    for i, (target, report) in enumerate(zip(targets, reports)):
        if target.configured:
            shown.append(i)
        elif resolved[i] in read_by_entry:
            continue  # a fragment of an entry (or an entry included by another)
        elif report.role == "entry":
            shown.append(i)
        elif not any(resolved[i] in reports[j].includes and resolved[j] not in reports[i].includes
                     for j in range(len(reports)) if j != i):
            report.diagnostics = [d for d in report.diagnostics if not _needs_robot(d.rule)]
            shown.append(i)
    notes = [f"{reports[i].path}: expanded with "
             f"{' '.join(f'{k}:={v}' for k, v in targets[i].args.items())}, as "
             f"{targets[i].args_from} passes them (list it in urdftool.toml's entries to choose)"
             for i in shown if targets[i].args_from]
    if given is not None:
        kept, elsewhere = [], 0
        for i in shown:
            report = reports[i]
            inputs = triggers(targets[i], report, given)
            if not inputs:
                if not ({resolved[i], *report.includes} & given):
                    continue
                inside = [d for d in report.diagnostics if str(Path(d.path).resolve()) in given]
                elsewhere += len(report.diagnostics) - len(inside)
                report.diagnostics = inside
            else:  # a YAML, a mesh, a launch file: its values show in the entry's findings
                notes.append(f"{report.path}: checked because it reads "
                             + ", ".join(_shown(Path(p), [report.path]).as_posix()
                                         for p in inputs))
            kept.append(i)
        shown = kept
        if elsewhere:
            notes.append(f"{elsewhere} finding(s) in files that were not given are not shown "
                         "(check the package to see them)")
    return [reports[i] for i in shown], notes


def seen_files(targets: list[Target], shown: list[FileReport], reports: list[FileReport],
               given: set[str] | None) -> set[str]:
    """The files (resolved) whose findings a run reports in full (a baseline compares only
    those, ``urdftool.baseline``): every file the checks read; in changed-files mode, the given
    files the shown checks read, and every file of a check shown for a YAML, mesh or launch
    file it reads."""
    if given is None:
        return {p for t, r in zip(targets, reports) if r is not None
                for p in (str(Path(t.path).resolve()), *r.includes)}
    by_report = {id(r): t for t, r in zip(targets, reports)}
    seen: set[str] = set()
    for report in shown:
        files = {str(Path(report.path).resolve()), *report.includes}
        target = by_report.get(id(report))
        if target is not None and triggers(target, report, given):
            seen |= files
        else:
            seen |= files & given
    return seen


def other_inputs(source, robot) -> set[str]:
    """What a check read besides XML files (resolved): the YAML files its expansion loaded and
    the mesh files its robot names (they exist). Changed-files mode re-checks an entry when one
    of them changes (issue 23: every input of an entry is a trigger)."""
    found = set(getattr(source, "reads", ()))
    if any(shape.geometry.filename for link in robot.links for shape in link.shapes):
        from urdftool.physics.meshes import resolve

        for link in robot.links:
            for shape in link.shapes:
                if shape.geometry.filename:
                    try:
                        path = resolve(robot, shape.geometry)
                    except Exception:  # noqa: BLE001 - an unresolvable URI is the rules' business
                        path = None
                    if path is not None and path.is_file():
                        found.add(resolved(path))
    return found


def triggers(target: Target, report: FileReport, given: set[str]) -> list[str]:
    """The given files other than robot files that the check of ``target`` read: YAML and
    meshes it read, launch files of its package (they choose a xacro file's arguments)."""
    found = [p for p in report.includes if p in given and not p.endswith(ROBOT_SUFFIXES)]
    return found + _launch_triggers(target, given)


def _launch_triggers(target: Target, given: set[str]) -> list[str]:
    if not target.path.endswith(".xacro"):
        return []
    launch = [p for p in given if p.endswith((".launch.py", ".launch", ".launch.xml"))
              or (p.endswith(".py") and "launch" in Path(p).name)]
    if not launch:
        return []
    directory = str(package_root(Path(target.path)) / "launch") + os.sep
    return [p for p in launch if p.startswith(directory)]


def _needs_robot(rule_id: str) -> bool:
    return rule_id in ALONE_SKIPS or rule_id.split(".", 1)[0] in ALONE_SKIPS


def role(source) -> str:
    """'entry' when the expanded file is a robot (or not xacro at all), 'fragment' when it
    holds only definitions (macros, properties, materials, gazebo, ros2_control)."""
    root = source.root
    if source.kind != "xacro" or root is None:
        return "entry"
    for child in root:
        tag = child.tag
        if isinstance(tag, str) and tag not in DEFINITION_TAGS:
            return "entry"
    return "fragment"


# -- what each check read, kept between runs (changed-files mode) -----------------------------
# A hook run on a changed file must know which entries read it. Expanding every entry for that
# costs as much as checking the package; the files each check read (with their size and
# modification time) are kept in the persistent cache instead, so that the next run checks only
# the entries that read a given file, and the checks whose files changed since (or that had a
# xacro error: an include that failed may succeed now).


def _reads_entry(target: Target, load_options) -> Path:
    import hashlib
    import json

    from urdftool import __version__, cache

    key = json.dumps([str(Path(target.path).resolve()), target.args, target.packages,
                      load_options.xacro_args, load_options.packages, load_options.untrusted,
                      os.environ.get("ROS_PACKAGE_PATH", ""),
                      os.environ.get("AMENT_PREFIX_PATH", ""), __version__], sort_keys=True)
    return cache.directory() / "reads" / hashlib.sha256(key.encode()).hexdigest()[:40]


def _stamp(path: str) -> list | None:
    try:
        st = os.stat(path)
    except OSError:
        return None
    return [path, st.st_size, st.st_mtime_ns]


def unaffected(targets: list[Target], given: set[str] | None,
               load_options) -> tuple[list[int], list]:
    """(the indices of the targets to check, a report per target: for those that need no check
    in changed-files mode, what they read from the cache; None for the others)."""
    reports: list = [None] * len(targets)
    if given is None:
        return list(range(len(targets))), reports
    known = [cached_reads(target, load_options) for target in targets]
    read_by_others: set[str] = set()
    for reads in known:
        if reads is not None:
            read_by_others.update(reads[0])
    todo = []
    for index, (target, reads) in enumerate(zip(targets, known)):
        if reads is None or given.intersection(reads[0]) or _launch_triggers(target, given) or (
                str(Path(target.path).resolve()) in given  # a given fragment that an entry
                and not (reads[1] == "fragment" and str(Path(target.path).resolve())  # reads
                         in read_by_others)):  # is checked through that entry only
            todo.append(index)
        else:
            reports[index] = FileReport(target.path, None)
            reports[index].includes, reports[index].role = reads
    return todo, reports


def cached_reads(target: Target, load_options) -> tuple[tuple[str, ...], str] | None:
    """(the files a check of ``target`` read besides itself, its role) when recorded and none
    of those files changed since; else None."""
    import json

    from urdftool import cache

    if not cache.ENABLED:
        return None
    try:
        data = json.loads(_reads_entry(target, load_options).read_text(encoding="utf-8"))
        stamps, role = data["files"], data["role"]
        if not all(isinstance(s, list) and _stamp(s[0]) == s for s in stamps):
            return None
        return tuple(s[0] for s in stamps[1:]), role
    except (OSError, ValueError, KeyError, TypeError, IndexError, RuntimeError):
        return None


def store_reads(target: Target, load_options, report: FileReport) -> None:
    """Record what the check of ``target`` read (nothing when it had a xacro error; nothing
    in an untrusted run without ``$URDFTOOL_CACHE_DIR``: ``cache.store``)."""
    import json

    from urdftool import cache

    if not (cache.ENABLED and cache.WRITABLE) or any(
            d.rule in ("xacro.error", "xacro.limit-exceeded") for d in report.diagnostics):
        return
    stamps = [_stamp(str(Path(target.path).resolve()))] + [_stamp(p) for p in report.includes]
    if any(s is None for s in stamps):
        return
    cache.store(_reads_entry(target, load_options),
                json.dumps({"files": stamps, "role": report.role}).encode("utf-8"))
