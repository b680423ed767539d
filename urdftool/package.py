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

import fnmatch
import itertools
import os
import re
from pathlib import Path
from typing import NamedTuple

from urdftool.config import find_config, parse_config
from urdftool.errors import ToolError
from urdftool.files import read_head, read_regular
from urdftool.report import FileReport
from urdftool.roots import is_file, real, resolved
from urdftool.source import _INCLUDE, ROBOT_SUFFIXES, shown_path
from urdftool.textscan import without_comments
from urdftool.uris import find_parts

# what a file that only defines things holds at its top level, once expanded
DEFINITION_TAGS = frozenset({"material", "gazebo", "ros2_control", "transmission",
                             "property", "macro", "include", "arg"})  # the last: old unprefixed xacro
# rules (or families) that need the whole robot: never run on a fragment alone
ALONE_SKIPS = ("structure", "gazebo", "transmission", "mimic", "material.undefined",
               "geometry.no-collision", "inertia.kinematics-only")  # the last: robot-wide


class Target(NamedTuple):
    """One check of a run: a file, its xacro arguments and packages (from the configuration)."""

    path: str
    args: dict[str, str] = {}  # noqa: RUF012 - never mutated (a NamedTuple field)
    packages: dict[str, str] = {}  # noqa: RUF012 - never mutated
    configured: bool = False  # listed in ``entries``: always an entry
    args_from: str = ""  # the launch file the arguments were read from (urdftool.launch)
    # a companion file (an SRDF: issue 31): the robot it describes (a path, or
    # ``package://NAME/PATH`` resolved by the loader), that robot's xacro arguments, and where the
    # pairing came from (or, with no robot, what was looked for)
    robot: str = ""
    robot_args: dict[str, str] = {}  # noqa: RUF012 - never mutated
    robot_note: str = ""


# companion files (issue 31): checked against the robot they describe, not as robots
SRDF_SUFFIXES = (".srdf", ".srdf.xacro")


def is_companion(path) -> bool:
    """Whether ``path`` names a companion file checked against a robot: a MoveIt SRDF (plain
    or xacro; found in directories like robot files), or a controllers YAML (checked when
    given by name; a robot's own check reads the one its simulator plugin names)."""
    return str(path).endswith(SRDF_SUFFIXES + (".yaml", ".yml")) or is_launch_file(path)


def is_srdf_file(path) -> bool:
    return str(path).endswith(SRDF_SUFFIXES)


def is_launch_file(path) -> bool:
    """A Python launch file (``*.launch.py``, or a ``.py`` in a ``launch`` folder): checked by
    the ``ros2_control`` rules given ``on="launch"`` (never run)."""
    path = Path(path)
    return path.name.endswith(".launch.py") or (path.suffix == ".py" and
                                                path.parent.name == "launch")


IGNORE_MARKERS = ("COLCON_IGNORE", "AMENT_IGNORE", "CATKIN_IGNORE")  # colcon/ament/catkin
# skipped unless --exclude replaces them (as ruff's defaults): hidden directories (.git...) and
# what a colcon workspace builds next to its sources (copies of the descriptions)
DEFAULT_EXCLUDE = (".*", "build", "install", "log", "__pycache__", "node_modules")
# folders of test data: what is under them is a fixture, not a robot of the package
TEST_DIRS = frozenset({"test", "tests", "testing", "test_data", "testdata", "fixtures"})
ROBOT_ROOTS = frozenset({"robot", "sdf"})  # the root elements a robot file has
HEAD_BYTES = 64 * 1024  # read to find a file's root element


class Selection:
    """Which files under a given directory are checked (issue 23.3), with ruff's names and
    semantics: ``exclude`` (the command line's ``--exclude`` replaces the configuration's, which
    replaces ``DEFAULT_EXCLUDE``) plus every ``extend-exclude``; gitignore-style globs (a
    pattern without a slash matches a file or folder name at any depth, one with a slash is
    anchored where it was written: the configuration's directory, or the working directory
    for the command line). Folders holding a ``COLCON_IGNORE``/``AMENT_IGNORE``/
    ``CATKIN_IGNORE`` file, and (``respect_gitignore``) what the ``.gitignore`` files of the
    git work tree and its ``.git/info/exclude`` ignore are skipped. Files given by name are
    always checked. Global git excludes are not read: the verdict must not depend on the
    machine (one verdict on a laptop and a CI runner)."""

    def __init__(self, exclude: list[str] | None = None, extend_exclude: list[str] = (),
                 respect_gitignore: bool | None = None, base: Path | None = None):
        self.exclude = list(exclude) if exclude is not None else None  # --exclude
        self.extend_exclude = list(extend_exclude)
        self.respect_gitignore = respect_gitignore  # None: the configuration's (else True)
        self.base = (base or Path.cwd()).resolve()
        self.skipped: dict[str, int] = {}  # reason -> robot files skipped
        self._matched: set[tuple[str, str]] = set()  # (where, pattern) that matched something
        self._given: list[tuple[str, str]] = []  # (where, pattern) to report when unused
        self._specs: dict = {}  # (base, pattern) -> compiled
        self._gitignores: dict[Path, object] = {}  # directory -> its compiled .gitignore
        self.walked = False  # a directory was searched (the run's roles are then counted)
        # (path as findings name it, why) of what planning refused unread for its size (issue
        # 21: a launch file over launch.MAX_BYTES): ``check.refused_reports`` reports each
        self.refused: list[tuple[str, str]] = []

    def patterns(self, config) -> list[tuple[Path, str, str]]:
        """(base, pattern, where it was written) of every exclusion that applies under
        ``config`` (None: no configuration)."""
        found = []
        cli = [(self.base, p, "--exclude") for p in self.exclude] if self.exclude is not None \
            else None
        if cli is None and config is not None and config.exclude is not None:
            cli = [(config.path.parent, p, f"{config.path.name}: exclude")
                   for p in config.exclude]
        found.extend(cli if cli is not None else
                     [(self.base, p, "") for p in DEFAULT_EXCLUDE])
        if config is not None:
            found.extend((config.path.parent, p, f"{config.path.name}: extend-exclude")
                         for p in config.extend_exclude)
        found.extend((self.base, p, "--extend-exclude") for p in self.extend_exclude)
        for _, pattern, where in found:
            if where and (where, pattern) not in self._given:
                self._given.append((where, pattern))
        return found

    def gitignore(self, config) -> bool:
        if self.respect_gitignore is not None:
            return self.respect_gitignore
        return config.respect_gitignore if config is not None else True

    def excluded(self, path: Path, patterns, is_dir: bool) -> str | None:
        """Where the pattern ``path`` matches was written ("" for a default one), or None
        (matches are recorded as used)."""
        hit = None
        for base, pattern, where in patterns:
            if _glob_matches(self._spec(pattern), path, base, is_dir, pattern):
                hit = where if hit is None or where else hit
                if where:
                    self._matched.add((where, pattern))
        return hit

    def _spec(self, pattern: str):
        spec = self._specs.get(pattern)
        if spec is None:
            if "/" not in pattern.rstrip("/") and not any(c in pattern for c in "[]\\"):
                spec = self._specs[pattern] = ("name", pattern.rstrip("/"))
            else:
                spec = self._specs[pattern] = ("glob", linear_spec([pattern]))
        return spec

    def ignored_by_git(self, path: Path, is_dir: bool, top: Path | None) -> bool:
        """Whether the ``.gitignore`` files between ``top`` (the work tree) and ``path``
        (and ``top/.git/info/exclude``) ignore ``path``: the deepest file that has a say
        decides, as git does."""
        if top is None:
            return False
        resolved = path.resolve()
        try:
            rel = resolved.relative_to(top)
        except ValueError:
            return False
        decision = None
        directory = top
        layers = [(top, self._gitignore_of(top / ".git" / "info" / "exclude", top))]
        for part in rel.parts[:-1]:
            layers.append((directory, self._gitignore_of(directory / ".gitignore", directory)))
            directory = directory / part
        layers.append((directory, self._gitignore_of(directory / ".gitignore", directory)))
        for base, spec in layers:
            if spec is None:
                continue
            name = resolved.relative_to(base).as_posix() + ("/" if is_dir else "")
            result = spec.check_file(name)
            if result.include is not None:
                decision = result.include
        return bool(decision)

    def _gitignore_of(self, file: Path, base: Path):
        key = file
        if key not in self._gitignores:
            spec = None
            try:
                text = read_regular(file, 1 << 20).decode("utf-8", errors="replace")
            except OSError:
                text = ""
            if text.strip():
                spec = linear_spec(text.splitlines())
            self._gitignores[key] = spec
        return self._gitignores[key]

    def skip(self, reason: str, count: int = 1) -> None:
        self.skipped[reason] = self.skipped.get(reason, 0) + count

    def unused(self) -> list[str]:
        """Warnings: the exclude patterns that matched nothing."""
        return [f"warning: {where} pattern {pattern!r} matches nothing"
                for where, pattern in self._given if (where, pattern) not in self._matched]


def linear_spec(lines: list[str]):
    """gitignore-style ``lines`` (a ``.gitignore``, an ``exclude`` pattern: a repository's
    text, untrusted) compiled to a matcher that takes linear time (issue 28.3): pathspec's
    parsing, matched by RE2 automata (google-re2), never by Python's backtracking ``re``, in
    which one 40-byte line with a few ``*`` and brackets ran for hours on a long file name."""
    import pathspec

    try:
        return pathspec.GitIgnoreSpec.from_lines(lines, backend="re2")
    except ImportError:  # never Python's backtracking matcher on a repository's patterns
        raise ToolError("matching exclude and .gitignore patterns needs google-re2: "
                        "pip install 'google-re2>=1.1,<2'") from None


def _glob_matches(spec, path: Path, base: Path, is_dir: bool, pattern: str) -> bool:
    kind, value = spec
    if kind == "name":
        if pattern.endswith("/") and not is_dir:
            return False
        return fnmatch.fnmatchcase(path.name, value)
    try:
        rel = path.resolve().relative_to(base.resolve()).as_posix()
    except ValueError:
        return False  # an anchored pattern never matches outside where it was written
    return bool(value.match_file(rel + ("/" if is_dir else "")))


def skipped_alone(file: Path, selection: Selection, memo: dict) -> bool:
    """Whether a file given by name (changed-files mode) lies where ``robot_files`` would not
    look: excluded, under an ignore marker, git-ignored, or a fixture of its package."""
    config = _config_of(file, memo)
    patterns = selection.patterns(config)
    top = git_top(file.parent) if selection.gitignore(config) else None
    root = package_root(file)
    stop = top if top is not None and top in root.parents else root
    if selection.excluded(file, patterns, False) is not None:
        return True
    for folder in file.resolve().parents:
        if any((folder / marker).exists() for marker in IGNORE_MARKERS) or (
                folder != stop and selection.excluded(folder, patterns, True) is not None):
            return True
        if folder == stop or folder == folder.parent:
            break
    if top is not None and selection.ignored_by_git(file, False, top):
        return True
    return file.name.endswith(ROBOT_SUFFIXES) and fixture_reason(file.resolve(), root) is not None


def git_top(directory: Path) -> Path | None:
    """The git work tree ``directory`` is in (a ``.git`` beside it or above), or None."""
    directory = directory.resolve()
    for parent in (directory, *directory.parents):
        if (parent / ".git").exists():
            return parent
    return None


def robot_files(directory: Path, selection: Selection | None = None,
                memo: dict | None = None) -> list[Path]:
    """Every ``*.urdf``, ``*.xacro``, ``*.sdf`` under ``directory`` that ``selection``
    keeps (default: ``DEFAULT_EXCLUDE``, the ignore markers, ``.gitignore``), in a stable
    order. What is skipped is counted in ``selection.skipped``."""
    selection = selection if selection is not None else Selection()
    memo = memo if memo is not None else {}
    top = None
    found = []
    for dirpath, dirnames, filenames in os.walk(directory):
        here = Path(dirpath)
        config = _config_of(here, memo)
        patterns = selection.patterns(config)
        gitignore = selection.gitignore(config)
        if gitignore and top is None:
            top = memo.setdefault("git", {}).setdefault(str(directory), git_top(directory)) \
                or False
        if here != Path(directory) and any(m in filenames for m in IGNORE_MARKERS):
            selection.skip("ignored (COLCON_IGNORE, AMENT_IGNORE, CATKIN_IGNORE)",
                           _count_robot_files(here))
            dirnames[:] = []
            continue
        kept = []
        for name in sorted(dirnames):
            sub = here / name
            where = selection.excluded(sub, patterns, True)
            if where is not None:  # (what the defaults skip, .git and the like: not counted)
                selection.skip("excluded", _count_robot_files(sub) if where else 0)
            elif gitignore and top and selection.ignored_by_git(sub, True, top):
                selection.skip("git-ignored", _count_robot_files(sub))
            else:
                kept.append(name)
        dirnames[:] = kept
        for name in sorted(filenames):
            if not name.endswith(ROBOT_SUFFIXES) and not is_srdf_file(name) and not \
                    is_launch_file(here / name):
                continue
            file = here / name
            if selection.excluded(file, patterns, False) is not None:
                selection.skip("excluded")
            elif gitignore and top and selection.ignored_by_git(file, False, top):
                selection.skip("git-ignored")
            else:
                found.append(file)
    return found


MAX_COUNTED = 20000  # directory entries looked at to count what a skipped folder holds


def _count_robot_files(directory: Path) -> int:
    count = seen = 0
    for _, dirnames, names in os.walk(directory):
        seen += len(names) + len(dirnames)
        count += sum(name.endswith(ROBOT_SUFFIXES) for name in names)
        if seen > MAX_COUNTED:
            break
    return count


def fixture_reason(file: Path, directory: Path) -> str | None:
    """Why a file found under ``directory`` is a test fixture or not a robot file at all
    (checked neither as a robot nor as a fragment), or None: under a test folder, or a root
    element other than ``<robot>``/``<sdf>``."""
    try:
        parts = file.relative_to(directory).parts[:-1]
    except ValueError:
        parts = ()
    if any(part.lower() in TEST_DIRS for part in parts):
        return "under a test folder"
    root, macros = root_tag(file)
    if root is not None and root not in ROBOT_ROOTS and not macros:
        return f"root <{root}>"  # (a macro file's root may be anything: <root> of old ones)
    return None


_ROOT_TAG = re.compile(r"<(?![?!])(?:[\w.-]+:)?([A-Za-z_][\w.-]*)")


def root_tag(file: Path) -> tuple[str | None, bool]:
    """(the local name of a file's root element, whether it defines xacro macros), from its
    first bytes (None: no element found, or unreadable: the check reports it)."""
    try:
        head = read_head(file, HEAD_BYTES).decode("utf-8", errors="replace")
    except OSError:
        return None, False
    head = without_comments(head, keep_unclosed=False)  # (a DTD's <!...: skipped below)
    match = _ROOT_TAG.search(head)
    return (match.group(1) if match else None), re.search(r"<(?:xacro:)?macro\s", head) is not None


def _placed(path: Path) -> Path:
    """``path`` resolved, except a link as its last part: where it is written (a changed link
    is data there, never where it leads: issue 28.1)."""
    if path.is_symlink():
        return Path(os.path.realpath(path.parent)) / path.name
    return path.resolve()


def package_root(path: Path) -> Path:
    """The package a file belongs to: the nearest directory above it with a ``package.xml`` or
    a configuration (an empty ``urdftool.toml`` marks one); else the file's own directory."""
    file = _placed(path)
    found = find_config(file)
    config_dir = found[0].parent if found else None
    for parent in file.parents:
        if (parent / "package.xml").is_file() or parent == config_dir:
            return parent
    return file.parent


def _config_of(path: Path, memo: dict):
    """The parsed configuration that applies to ``path`` (memoised per file), or None; with
    ``--config FILE`` (``memo["file"]``) that one."""
    chosen = memo.get("file")
    if chosen is not None:
        configs = memo.setdefault("configs", {})
        if chosen not in configs:
            from urdftool.config import load_config_file

            configs[chosen] = load_config_file(chosen)
        return configs[chosen]
    found = find_config(path, memo.setdefault("directories", {}))
    if found is None:
        return None
    configs = memo.setdefault("configs", {})
    if found[0] not in configs:
        configs[found[0]] = parse_config(found[1], found[0])
    return configs[found[0]]


def with_operator_args(targets: list[Target], args: dict[str, str]) -> list[Target]:
    """``targets`` with the operator's ``NAME:=VALUE`` arguments in place of their own (the
    command line wins over a configuration's entries and a launch file's choices); argument
    sets that became the same are checked once (``ur_type:=ur10`` on a file the launch file
    expands for nine ``ur_type`` choices is one expansion, reported with ``ur10``)."""
    if not args:
        return targets
    kept: dict[tuple, Target] = {}
    for target in targets:
        merged = target._replace(args={**target.args, **args}) if target.args else target
        key = (merged.path, tuple(sorted(merged.args.items())),
               tuple(sorted(merged.packages.items())))
        kept.setdefault(key, merged)
    return list(kept.values())


def plan(paths: list[str], changed: bool = False, selection: Selection | None = None,
         config_file: Path | None = None) -> tuple[list[Target], set[str] | None]:
    """The targets of a run, and in changed-files mode the given files (resolved). Files
    found in directories are kept or skipped by ``selection`` (exclusions, ignore markers,
    .gitignore; its ``skipped`` counts them) and test fixtures are skipped; files given by
    name are checked, except in changed-files mode (a hook names every file a commit
    changes: exclusions apply to them too). With ``config_file`` (``--config``) that
    configuration for every file."""
    selection = selection if selection is not None else Selection()
    configs: dict = {"file": config_file.resolve()} if config_file is not None else {}
    files: list[Path] = []
    given: set[str] | None = set() if changed else None

    def walk(directory: Path) -> list[Path]:
        kept = []
        for found in robot_files(directory, selection, configs):
            config = _config_of(found, configs)
            if fixture_reason(found, directory) is not None and not (config and any(
                    str(e.path) == str(found.resolve()) for e in config.entries)):
                selection.skip("fixture")
            else:
                kept.append(found)
        return kept

    for raw in paths:
        path = Path(raw)
        # (a changed name that is a link to a directory is data: never walked)
        if path.is_dir() and not (given is not None and path.is_symlink()):
            selection.walked = True
            files.extend(walk(path))
        elif path.exists() or path.is_symlink():  # a dangling link: the loader answers
            if given is not None and skipped_alone(path, selection, configs):
                continue
            if given is None or path.name.endswith(ROBOT_SUFFIXES) or is_srdf_file(path) or \
                    is_launch_file(path):
                files.append(path)  # (changed-files mode: a YAML, a mesh, a launch file only
            if given is not None:  # re-checks the entries that read it: ``triggered``; a
                # link is data where it is written, never where it leads: its package is the
                # repository's, not another checkout's)
                given.add(str(_placed(path)))
        elif given is not None:  # changed-files mode, a file the change deletes: the entries
            given.add(real(path))  # that read it are checked (its includers' errors shown)
        else:
            raise ToolError(f"{raw}: no such file or directory")
    if given is not None:
        roots = sorted({package_root(Path(p)) for p in given})
        known = {str(f.resolve()) for f in files}
        for root in roots:
            for found in walk(_shown(root, paths)):
                if str(found.resolve()) not in known:
                    known.add(str(found.resolve()))
                    files.append(found)
        # the SRDFs of the repository: one may describe a robot a given file is part of (their
        # recorded reads decide which are checked again: ``unaffected``)
        tops = {git_top(Path(p).parent) for p in given if os.path.lexists(Path(p).parent)}
        # and its robot files that name a given YAML (a controllers file a simulator plugin's
        # <parameters> gives: the robot's check reads it), found by the YAML's file name
        yaml_names = {Path(p).name for p in given if p.endswith((".yaml", ".yml"))}
        for top in sorted(t for t in tops if t is not None):
            for found in walk(_shown(top, paths)):
                if str(found.resolve()) in known:
                    continue
                if is_srdf_file(found) or (yaml_names and found.name.endswith(ROBOT_SUFFIXES)
                                           and _names_any(found, yaml_names)):
                    known.add(str(found.resolve()))
                    files.append(found)
    targets: list[Target] = []
    configured: set[str] = set()
    for file in files:
        config = _config_of(file, configs)
        resolved = real(file)
        packages = config.packages if config is not None else {}
        entries = [e for e in config.entries if str(e.path) == resolved] if config else []
        if is_srdf_file(file):  # (a .srdf.xacro with the arguments its launch files pass)
            robot, robot_args, note = pair_srdf(file, configs)
            targets.extend(Target(str(file), args, packages, args_from=where, robot=robot,
                                  robot_args=robot_args, robot_note=note)
                           for args, where in _launched(file, configs) or [({}, "")])
        elif entries:
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
    known = {shown for shown, _ in selection.refused}
    for path, why in configs.get("refused", []):
        shown = str(_shown(path, paths))
        if shown not in known:  # (the same plan asked twice: --fix plans again)
            known.add(shown)
            selection.refused.append((shown, why))
    return targets, given


SETUP_ASSISTANT = ".setup_assistant"  # a MoveIt configuration's record of its robot


def pair_srdf(file: Path, memo: dict) -> tuple[str, dict[str, str], str]:
    """(the robot an SRDF describes: a path or ``package://NAME/PATH``, its xacro arguments,
    where that was read) from the configuration's ``srdf`` entries or the MoveIt
    configuration's ``.setup_assistant`` (in the SRDF's directory or above it, up to its
    package); ("", {}, what was looked for) when neither names one."""
    resolved_ = real(file)
    config = _config_of(file, memo)
    if config is not None:
        for companion in config.companions:
            if str(companion.path) == resolved_:
                return str(companion.robot), companion.args, f"{config.path.name}: srdf"
    root = package_root(file)
    directory = file.resolve().parent
    while True:
        candidate = directory / SETUP_ASSISTANT
        if is_file(candidate):
            found = _setup_assistant(candidate, memo)
            if found is not None:
                return found
        if directory == root or directory.parent == directory:
            break
        directory = directory.parent
    return "", {}, (f"no {SETUP_ASSISTANT} in {_shown(root, [str(file)]).as_posix() or '.'}" \
        " and no srdf entry in a urdftool.toml")


def _setup_assistant(path: Path, memo: dict) -> tuple[str, dict[str, str], str] | None:
    """What a ``.setup_assistant`` says of the robot (URDF: package, relative_path,
    xacro_args), or None when it does not say it."""
    known = memo.setdefault("assistants", {})
    if path in known:
        return known[path]
    import yaml

    found = None
    try:
        data = yaml.safe_load(read_regular(path, 1 << 20).decode("utf-8", "replace"))
        # MoveIt 1's Setup Assistant writes URDF:, MoveIt 2's urdf:
        config = data["moveit_setup_assistant_config"]
        urdf = next(value for key, value in config.items()
                    if isinstance(key, str) and key.lower() == "urdf")
        package, relative = urdf.get("package"), urdf.get("relative_path")
        if isinstance(package, str) and isinstance(relative, str) and package and relative:
            args: dict[str, str] = {}
            text = urdf.get("xacro_args") or ""
            for word in str(text).split():
                name, sep, value = word.partition(":=")
                if sep and name:
                    args[name] = value
            found = (f"package://{package}/{relative.lstrip('/')}", args,
                     f"{path.parent.name}/{SETUP_ASSISTANT}")
    except (OSError, ValueError, KeyError, TypeError, AttributeError, StopIteration,
            yaml.YAMLError):
        found = None
    known[path] = found
    return found


def _names_any(file: Path, names: set[str]) -> bool:
    try:
        text = read_head(file, HEAD_BYTES * 16).decode("utf-8", "replace")
    except OSError:
        return False
    return any(name in text for name in names)


def _launched(file: Path, memo: dict) -> list[tuple[dict[str, str], str]]:
    """The argument sets the launch files of ``file``'s package pass to it (memoised per
    package), for a xacro file the configuration does not list."""
    if not file.name.endswith(".xacro"):
        return []
    from urdftool.launch import launch_arguments

    root = package_root(file)
    found = memo.setdefault("launch", {})
    if root not in found:
        found[root] = launch_arguments(root, memo.setdefault("refused", []))
    try:
        rel = file.resolve().relative_to(root).as_posix()
    except ValueError:
        return []
    return found[root].get(rel, [])


def _shown(path: Path, given: list[str]) -> Path:
    """``path`` named as the given paths are (relative to the working directory unless every
    one was absolute), as findings name files."""
    relative = next((raw for raw in given if not os.path.isabs(raw)), None)
    return Path(shown_path(path, relative if relative is not None else os.sep))


def classify(targets: list[Target], reports: list[FileReport],
             given: set[str] | None = None,
             selection: Selection | None = None) -> tuple[list[FileReport], list[str]]:
    """The reports to show, and notes for the user. Every file has a role (issue 22.1):

    - entry: configured, or its expansion is a robot that no other file of the run includes;
    - fragment: read by an entry (its findings come through the entry, at its own lines), or
      included by another file (its include lines name it: ``static_includes``), or
      definitions only, or an add-on (its links hang from links it does not define). A
      fragment no entry read is shown once, alone, restricted to what it can be wrong about
      alone (not ``ALONE_SKIPS``, not the names its includer defines); one that a failed
      entry includes is not judged alone (the entry's failure is the finding);
    - fixture, excluded, ignored: skipped by ``plan`` (counted in ``selection.skipped``).

    In changed-files mode, only the reports that read a given file are kept, restricted to
    findings in the given files."""
    resolved = [real(t.path) for t in targets]
    contexts: dict[str, set[str]] = {}
    exact, wildcard = static_includes(reports, contexts)
    includers = {path: exact.get(path, set()) | wildcard.get(path, set())
                 for path in {*exact, *wildcard}}
    configured_files = {resolved[i] for i, t in enumerate(targets) if t.configured}
    roles = [_role_of(i, targets, reports, resolved, exact) for i in range(len(targets))]
    read_by_entry: dict[str, set[int]] = {}
    for i, role_ in enumerate(roles):
        if role_ == "entry":
            for path in reports[i].includes:
                read_by_entry.setdefault(path, set()).add(i)
    failed = {resolved[i] for i in range(len(reports)) if _failed(reports[i])}
    shown: list[int] = []
    fragments: set[str] = set()
    for i, report in enumerate(reports):
        if report.role == "companion":  # an SRDF, a launch file: shown, not a robot's role
            if report.diagnostics or not is_launch_file(report.path):  # (a launch file only
                shown.append(i)  # when it has something to say)
            continue
        if roles[i] == "entry" and (targets[i].configured or resolved[i] not in read_by_entry):
            shown.append(i)
            refused = bool(selection is not None and selection.refused)
            _name_missing_arguments(report, targets[i], refused)
            _name_template_arguments(report, targets[i], refused)
            continue
        if resolved[i] in configured_files:
            continue  # the same file with other arguments: configured, it is an entry
        fragments.add(resolved[i])
        if resolved[i] in read_by_entry:
            continue  # a fragment of an entry (or an entry included by another)
        if _above(resolved[i], includers, failed):
            continue  # an includer failed: its failure is the finding
        if any(resolved[i] in reports[j].includes and resolved[j] not in report.includes
               for j in range(len(reports)) if j != i):
            continue  # read by another fragment shown alone: checked once, through it
        report.role = "fragment"
        inside = contexts.get(resolved[i], set()) - {"robot"}
        if inside and "robot" not in contexts[resolved[i]]:
            # included only inside another element (<ros2_control>, <gazebo>, <link>): its
            # elements are that element's children, not a robot's (a ros2_control <joint>
            # has no type, parent or child): what it is wrong about as written is kept
            report.diagnostics = [d for d in report.diagnostics
                                  if d.rule.startswith(("xml.", "xacro."))]
        report.diagnostics = [d for d in report.diagnostics
                              if not _needs_robot(d.rule) and not _from_includer(d)]
        shown.append(i)
    notes = _launch_notes([(reports[i].path, targets[i]) for i in shown
                           if targets[i].args_from and roles[i] == "entry"])
    if selection is not None and selection.walked:
        notes.append(_roles_line(sum(1 for i in shown if roles[i] == "entry"), len(fragments),
                                 selection.skipped))
    if selection is not None:
        notes.extend(selection.unused())
    if given is not None:
        kept, elsewhere = [], 0
        for i in shown:
            report = reports[i]
            inputs = triggers(targets[i], report, given)
            # where the check asked for a given file that is not there (deleted): the include,
            # load_yaml or mesh line that now fails (the reads graph, issue 28.7)
            asked = {(real(path), line) for missing, where in report.missing.items()
                     if missing in given for path, line in where}
            if not inputs:
                if not ({resolved[i], *report.includes} & given) and not asked:
                    continue
                inside = [d for d in report.diagnostics
                          if real(d.path) in given or (real(d.path), d.line) in asked]
                elsewhere += len(report.diagnostics) - len(inside)
                report.diagnostics = inside
            else:  # a YAML, a mesh, a launch file: its values show in the entry's findings
                notes.append(_trigger_note(report.path, inputs, targets[i], given))
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
    file it reads. A check whose expansion failed (``_failed``) or was not done computed only
    some of the findings of the files it read (a macro of an include it never called): none of
    them is seen, whatever other checks read them."""
    unsure = {p for t, r in zip(targets, reports) if r is not None and _failed(r)
              for p in (real(t.path), *r.includes)}
    if given is None:
        return {p for t, r in zip(targets, reports) if r is not None and not _failed(r)
                for p in (real(t.path), *r.includes)} - unsure
    by_report = {id(r): t for t, r in zip(targets, reports)}
    seen: set[str] = set()
    for report in shown:
        if _failed(report):
            continue
        files = {real(report.path), *report.includes}
        target = by_report.get(id(report))
        if target is not None and triggers(target, report, given):
            seen |= files
        else:
            seen |= files & given
    return seen - unsure


def other_inputs(source, robot) -> tuple[set[str], dict[str, list[tuple[str, int | None]]]]:
    """The reads graph of a check besides XML files: (what it read, resolved: the YAML files
    its expansion loaded and the mesh files its robot names; what it asked for that is not
    there: resolved path -> the (file, line) of each place that asked: includes, YAML files,
    meshes). Changed-files mode re-checks an entry when one of them changes (issue 23: every
    input of an entry is a trigger), and keeps the findings where a deleted one was asked for
    (issue 28.7)."""
    found = set(getattr(source, "reads", ()))
    missing = {path: [(loc.path, loc.line) for loc in where if loc is not None]
               for path, where in getattr(source, "missing", {}).items()}
    if any(shape.geometry.filename for link in robot.links for shape in link.shapes):
        from urdftool.physics.meshes import resolve

        for link in robot.links:
            for shape in link.shapes:
                if shape.geometry.filename:
                    try:
                        path = resolve(robot, shape.geometry)
                    except Exception:  # noqa: BLE001 - an unresolvable URI is the rules' business
                        path = None
                    if path is not None and is_file(path):
                        found.add(resolved(path))
                    elif path is not None and shape.geometry.loc is not None and \
                            not os.path.lexists(path):
                        missing.setdefault(resolved(path), []).append(
                            (shape.geometry.loc.path, shape.geometry.loc.line))
    return found, missing


def triggers(target: Target, report: FileReport, given: set[str]) -> list[str]:
    """The given files other than robot files that the check of ``target`` read: YAML and
    meshes it read, launch files of its package (they choose a xacro file's arguments)."""
    found = [p for p in report.includes if p in given and not p.endswith(ROBOT_SUFFIXES)]
    found += [p for p in report.companion if p in given]  # the robot of an SRDF
    return found + _launch_triggers(target, given)


def _trigger_note(path: str, inputs: list[str], target: Target, given: set[str]) -> str:
    """Why a check is shown in changed-files mode: the files it reads (YAML, meshes) and the
    launch files that pass it its arguments (the launch file reads the xacro, not the other
    way round)."""
    launch = set(_launch_triggers(target, given))

    def shown(paths):
        return ", ".join(_shown(Path(p), [path]).as_posix() for p in paths)

    read = [p for p in inputs if p not in launch]
    parts = [f"it reads {shown(read)}"] if read else []
    passing = [p for p in inputs if p in launch]
    if passing:
        parts.append(f"{shown(passing)} {'passes' if len(passing) == 1 else 'pass'} "
                     "its xacro arguments")
    return f"{path}: checked because " + " and ".join(parts)


def _launch_triggers(target: Target, given: set[str]) -> list[str]:
    if not target.path.endswith(".xacro"):
        return []
    launch = [p for p in given if p.endswith((".launch.py", ".launch", ".launch.xml"))
              or (p.endswith(".py") and "launch" in Path(p).name)]
    if not launch:
        return []
    directory = str(package_root(Path(target.path)) / "launch") + os.sep
    return [p for p in launch if p.startswith(directory)]


def _roles_line(entries: int, fragments: int, skipped: dict[str, int]) -> str:
    """The one line of a directory check that counts the files per role."""
    def count(number: int, one: str, many: str) -> str:
        return f"{number} {one if number == 1 else many}"

    parts = [count(entries, "entry", "entries"), count(fragments, "fragment", "fragments"),
             count(skipped.get("fixture", 0), "fixture", "fixtures")]
    excluded = skipped.get("excluded", 0) + skipped.get("git-ignored", 0)
    ignored = skipped.get("ignored (COLCON_IGNORE, AMENT_IGNORE, CATKIN_IGNORE)", 0)
    parts.append(f"{excluded} excluded" + (f" ({skipped['git-ignored']} by .gitignore)"
                                           if skipped.get("git-ignored") else ""))
    if ignored:
        parts.append(f"{ignored} under COLCON_IGNORE/AMENT_IGNORE/CATKIN_IGNORE")
    return "roles: " + ", ".join(parts)


def _role_of(i: int, targets: list[Target], reports: list[FileReport], resolved: list[str],
             includers: dict[str, set[str]]) -> str:
    if targets[i].configured:
        return "entry"
    if reports[i].role != "entry":
        return "fragment"
    # named by another file's include line (not by a pattern): a fragment of that file
    return "fragment" if includers.get(resolved[i], set()) - {resolved[i]} else "entry"


def _above(path: str, includers: dict[str, set[str]], failed: set[str]) -> bool:
    """Whether a file that (transitively) includes ``path`` failed to expand."""
    seen, todo = {path}, [path]
    while todo:
        for parent in includers.get(todo.pop(), ()):
            if parent in failed:
                return True
            if parent not in seen:
                seen.add(parent)
                todo.append(parent)
    return False


def _failed(report: FileReport) -> bool:
    return any(d.rule in ("xacro.error", "xacro.limit-exceeded") for d in report.diagnostics)


# xacro errors about names a fragment's includer defines (properties, macros, arguments)
_FROM_INCLUDER = ("undefined property", "is called but never defined",
                  "argument is not defined")


def _from_includer(diagnostic) -> bool:
    """A finding about what a fragment's includer gives it: the names it defines, and the
    root element (an include keeps only what is inside it)."""
    if diagnostic.rule == "schema.unknown-element":
        return diagnostic.message.startswith("the root element is")
    return diagnostic.rule == "xacro.error" and any(
        text in diagnostic.message for text in _FROM_INCLUDER)


_MISSING_ARG = re.compile(r"\$\(arg ([A-Za-z_]\w*)\) is used but the argument is not defined")


def _name_missing_arguments(report: FileReport, target: Target, refused: bool = False) -> None:
    """An entry stopped by an argument it never declares, that no launch file of its package
    passes and the configuration does not give: one warning naming the argument and how to
    give it (not a defect of the robot: the gate was not told how the entry is expanded). An
    argument the file declares (after its use) stays the error it is."""
    for index, d in enumerate(report.diagnostics):
        match = _MISSING_ARG.search(d.message) if d.rule == "xacro.error" else None
        if match is None:
            continue
        name = match.group(1)
        if any(_declares(text, name) for text in report.texts.values()):
            continue
        how = (f"{target.args_from} does not pass it" if target.args_from else
               "no launch file urdftool read passes it (some were not read)" if refused else
               "no launch file of its package passes it")
        file = Path(target.path).as_posix()
        report.diagnostics[index] = d._replace(
            severity="warning",
            message=f"xacro: the entry needs the argument '{name}' ($(arg {name})), which it "
                    f"does not declare and {how}: it was not expanded",
            hint=f'give it in urdftool.toml: entries = [{{ file = "{file}", args = '
                 f'{{ {name} = "..." }} }}] (or pass {name}:=VALUE)')


_EMPTY_ARG = re.compile(r"<(?:xacro:)?arg\s[^<>]*?\bname\s*=\s*[\"']([A-Za-z_]\w*)[\"'][^<>]*?"
                        r"\bdefault\s*=\s*(?:\"\"|'')|<(?:xacro:)?arg\s[^<>]*?\bdefault\s*=\s*"
                        r"(?:\"\"|'')[^<>]*?\bname\s*=\s*[\"']([A-Za-z_]\w*)[\"']")
_PROPERTY = re.compile(r"<xacro:property\s[^<>]*?\bname\s*=\s*[\"']([A-Za-z_]\w*)[\"']"
                       r"[^<>]*?\bvalue\s*=\s*(\"[^\"<>]*\"|'[^'<>]*')")


def _name_template_arguments(report: FileReport, target: Target, refused: bool = False) -> None:
    """An argument template: an entry whose arguments default to ``""`` (another package's
    launch file passes them), expanded here with those empty defaults because nothing of its
    package passes them. The xacro errors that come from an empty argument (an include of
    ``$(arg file)``, ``float('$(arg length)')``, a property made of one) are one warning naming
    the arguments and how to give them; what was built without them is not judged (the
    expansion is not the robot)."""
    texts = report.texts.values()
    empty = {a or b for text in texts for a, b in _EMPTY_ARG.findall(text)} - set(target.args)
    if not empty:
        return
    # the names that carry an empty argument: the arguments, and the properties made of them
    # (to a fixed point: a property made of such a property)
    carriers = {name: name for name in empty}
    properties = [(name, value) for text in texts for name, value in _PROPERTY.findall(text)]
    changed = True
    while changed:
        changed = False
        for name, value in properties:
            if name not in carriers:
                cause = _mentions(value, carriers)
                if cause is not None:
                    carriers[name] = cause
                    changed = True
    causes: list[str] = []
    first = None
    kept = []
    from urdftool.rules.xacro import classify

    for d in report.diagnostics:
        cause = None
        kind = classify(d.message)[0] if d.rule == "xacro.error" and d.severity == "error" \
            else None
        if kind in ("bad-expression", "other"):  # the expression is in the message
            cause = _mentions(d.message, carriers)
        elif kind in ("missing-include", "unknown-package"):  # the include's file name
            cause = _mentions(d.message, carriers) or _mentions(
                _element_text(report.texts.get(d.path, ""), d.line, d.column), carriers)
        # (a macro's parameters, an undefined name: not what an empty value causes)
        if cause is None:
            kept.append(d)
            continue
        first = first or d
        if cause not in causes:
            causes.append(cause)
    if first is None:
        return
    names = ", ".join(f"'{name}'" for name in causes)
    how = (f"{target.args_from} does not pass {'it' if len(causes) == 1 else 'them'}"
           if target.args_from else
           "no launch file urdftool read passes them (some were not read)" if refused else
           "nothing in its package passes them (a launch file of another package may)")
    file = Path(target.path).as_posix()
    given = ", ".join(f'{name} = "..."' for name in causes)
    warning = first._replace(
        severity="warning", fix=None, instances=1, call_sites=(),
        message=f"xacro: the entry {file} is an argument template: {names} default"
                f"{'s' if len(causes) == 1 else ''} to \"\" and {how}; expanded with the "
                "empty default it fails, so it was not checked",
        hint=f'give the arguments its launch files pass in urdftool.toml: entries = [{{ file = '
             f'"{file}", args = {{ {given} }} }}] (or pass NAME:=VALUE)')
    # what the expansion built without the arguments is not the robot: only what the files
    # say as written (XML, xacro) is kept
    report.diagnostics = [warning] + [d for d in kept if d.rule.startswith(("xml.", "xacro."))]


def _mentions(text: str, carriers: dict[str, str]) -> str | None:
    """The empty argument ``text`` uses, through ``$(arg NAME)``, ``xacro.arg('NAME')`` or a
    property (``${NAME...}``) made of one."""
    if not text:
        return None
    for match in re.finditer(r"\$\(arg\s+([A-Za-z_]\w*)\s*\)|xacro\.arg\(\s*[\"']([A-Za-z_]\w*)",
                             text):
        name = match.group(1) or match.group(2)
        if name in carriers and carriers[name] == name:
            return name
    for match in re.finditer(r"\$\{([^{}]*)\}", text):
        for word in re.findall(r"(?<![\w.'\"])[A-Za-z_]\w*", match.group(1)):
            if word in carriers:  # a property made of an argument (often of its name)
                return carriers[word]
    return None


def _element_text(text: str, line: int | None, column: int | None) -> str:
    """The tag written at ``line`` (from the ``<`` at or before ``column``)."""
    if not text or not line:
        return ""
    lines = text.splitlines()
    if line > len(lines):
        return ""
    at = sum(len(t) + 1 for t in lines[:line - 1]) + max((column or 1) - 1, 0)
    start = text.rfind("<", 0, at + 1)
    end = text.find(">", at)
    return text[start:end + 1] if start >= 0 and end >= 0 else lines[line - 1]


def _declares(text: str, name: str) -> bool:
    """Whether ``text`` has an ``<xacro:arg name="NAME">`` (or an old unprefixed ``<arg>``)."""
    for match in re.finditer(rf"name\s*=\s*[\"']{re.escape(name)}[\"']", text):
        tag = text.rfind("<", max(0, match.start() - 400), match.start())
        if tag >= 0 and re.match(r"<(?:xacro:)?arg\s", text[tag:match.start()]):
            return True
    return False


# -- the include lines of every file ------------------------------------------------------------
# What an entry reads is known from its expansion; a file an include line names is a fragment
# even when no expansion reached it (a conditional include, an entry stopped by an error, an
# include inside a macro nobody calls, a name from an argument or an environment variable).
# Names built from substitutions are matched as wildcards: `${prefix}_macro.xacro` names every
# `*_macro.xacro` beside the includer.


def _launch_notes(expanded: list[tuple[str, Target]]) -> list[str]:
    """One note per file and launch file: the arguments it was expanded with, those that
    differ between its expansions listed once each (the UR description's nine ``ur_type``
    choices are one line, not nine)."""
    sets: dict[tuple[str, str], list[dict[str, str]]] = {}
    for path, target in expanded:
        sets.setdefault((path, target.args_from), []).append(dict(target.args))
    notes = []
    for (path, where), values in sets.items():
        same = {k: v for k, v in values[0].items() if all(a.get(k) == v for a in values)}
        text = " ".join(f"{k}:={v}" for k, v in same.items())
        if len(values) > 1:
            differ = " ".join(f"{k}:=" for k in values[0] if k not in same)
            choices = ["/".join(a.get(k, "") for k in values[0] if k not in same)
                       for a in values]
            text = (f"{len(values)} times with {text + ' and ' if text else ''}{differ} "
                    + ", ".join(choices[:6]) + (f" and {len(choices) - 6} more"
                                                if len(choices) > 6 else ""))
        else:
            text = "with " + text
        notes.append(f"{path}: expanded {text}, as {where} passes them (list it in "
                     "urdftool.toml's entries to choose)")
    return notes


def static_includes(reports: list[FileReport], contexts: dict[str, set[str]] | None = None,
                    ) -> tuple[dict[str, set[str]], dict[str, set[str]]]:
    """(resolved file -> the resolved files of the run whose include lines name it exactly,
    the same for names with wildcards: a file only a pattern names may be another entry).
    ``contexts`` gets, per included file, the elements its include lines are in (``robot``:
    at the top level, in a macro or a condition; ``ros2_control``, ``link``...: what the
    included elements are children of)."""
    by_name: dict[str, list[str]] = {}
    for report in reports:
        for name in {report.path, *report.texts}:
            resolved = real(name)
            known = by_name.setdefault(Path(resolved).name, [])
            if resolved not in known:
                known.append(resolved)
    exact: dict[str, set[str]] = {}
    wildcard: dict[str, set[str]] = {}
    seen: set[str] = set()
    for report in reports:
        for name, text in report.texts.items():
            resolved = real(name)
            if resolved in seen:
                continue
            seen.add(resolved)
            text = without_comments(text, keep_unclosed=False)
            defaults = _arg_defaults(text)
            found = list(re.finditer(_INCLUDE, text))
            where = _enclosing(text, [m.start() for m in found]) if contexts is not None \
                and found else []
            for index, match in enumerate(found):
                spec = _ARG.sub(lambda m, d=defaults: d.get(m.group(1), m.group()),
                                match.group(1))
                targets, pattern = _include_candidates(spec, Path(resolved).parent, by_name)
                for target in targets:
                    (wildcard if pattern else exact).setdefault(target, set()).add(resolved)
                    if contexts is not None:
                        contexts.setdefault(target, set()).add(where[index])
    return exact, wildcard


_TAG = re.compile(r"<(/?)([A-Za-z_][\w:.-]*)(?![\w:.-])([^<>]*)>")


def _enclosing(text: str, positions: list[int]) -> list[str]:
    """For each position (ascending) of ``text``, the nearest element around it that is not
    xacro's (a macro, a condition): ``robot`` at the top level."""
    result, stack = [], []
    tags = _TAG.finditer(text)
    tag = next(tags, None)
    for position in positions:
        while tag is not None and tag.start() < position:
            closing, name, rest = tag.groups()
            if closing:
                if name in stack:  # (a stray closer is ignored)
                    del stack[len(stack) - 1 - stack[::-1].index(name):]
            elif not rest.endswith("/"):
                stack.append(name)
            tag = next(tags, None)
        result.append(next((name for name in reversed(stack)
                            if not name.startswith("xacro:")), "robot"))
    return result


_ARG = re.compile(r"\$\(arg\s+([^)\s$]+)\s*\)")
_ARG_TAG = re.compile(r"<xacro:arg\s[^<>]*>")
_ATTRIBUTE = re.compile(r"""\b(name|default)\s*=\s*(?:"([^"]*)"|'([^']*)')""")


def _arg_defaults(text: str) -> dict[str, str]:
    """The defaults of a file's ``<xacro:arg>`` declarations without other arguments in
    them: ``$(arg extras)`` in an include line names the file its default names (husky's
    ``$(optenv HUSKY_URDF_EXTRAS empty.urdf)``), as xacro reads it when nothing is passed."""
    defaults = {}
    for tag in _ARG_TAG.findall(text):
        found = {key: a if a else b for key, a, b in _ATTRIBUTE.findall(tag)}
        if "name" in found and "default" in found and "$(arg" not in found["default"]:
            defaults.setdefault(found["name"], found["default"])
    return defaults


_SUBSTITUTION = re.compile(r"\$\{[^}$]*\}|\$\((?:arg|env|eval)\s[^)$]*\)")
_OPTENV = re.compile(r"\$\(optenv\s+[^\s)$]+(\s[^)$]*)?\)")


def _include_candidates(spec: str, base: Path, by_name: dict[str, list[str]],
                        ) -> tuple[list[str], bool]:
    """The files of the run an include's filename can name: ``$(find PKG)/rest`` as
    ``rest`` under a folder named PKG, substitutions as wildcards within one path part,
    ``$(optenv X default)`` as its default, other names relative to the including file."""
    spec = _OPTENV.sub(lambda m: (m.group(1) or "").strip() or "*", spec.strip())
    found = find_parts(spec)
    pattern = _SUBSTITUTION.sub("*", found[1] if found else spec)
    name = pattern.rsplit("/", 1)[-1]
    if not name or "$(" in pattern:
        return [], False
    names = [n for n in by_name if fnmatch.fnmatchcase(n, name)] if "*" in name else \
        ([name] if name in by_name else [])
    candidates = [path for n in names for path in by_name[n]]
    if found:  # rest under the package: a folder of that name, or its package.xml says so
        package, parts = found[0], [p for p in pattern.split("/") if p not in ("", ".")]
        result = [path for path in candidates if _tail_matches(path, parts) and (
            path.split("/")[-len(parts) - 1] == package or _package_name(Path(path)) == package)]
    else:
        full = pattern if pattern.startswith("/") else os.path.normpath(str(base / pattern))
        parts = full.split("/")
        result = [path for path in candidates
                  if len(path.split("/")) == len(parts) and _tail_matches(path, parts)]
    return result, "*" in pattern


def _tail_matches(path: str, parts: list[str]) -> bool:
    """Whether the last path parts of ``path`` match ``parts`` (``*`` within one part)."""
    own = path.split("/")
    return len(own) > len(parts) - 1 and all(
        fnmatch.fnmatchcase(mine, theirs) for mine, theirs in zip(own[-len(parts):], parts))


_PACKAGE_NAMES: dict[Path, str | None] = {}


def _package_name(file: Path) -> str | None:
    """The name in the package.xml of the package ``file`` belongs to (None: none)."""
    root = package_root(file)
    if root not in _PACKAGE_NAMES:
        name = None
        try:
            text = read_regular(root / "package.xml", 1 << 20).decode("utf-8", "replace")
            match = re.search(r"<name>\s*([^<\s]+)\s*</name>", text)
            name = match.group(1) if match else None
        except OSError:
            pass
        _PACKAGE_NAMES[root] = name
    return _PACKAGE_NAMES[root]


def _needs_robot(rule_id: str) -> bool:
    return rule_id in ALONE_SKIPS or rule_id.split(".", 1)[0] in ALONE_SKIPS


def role(source, robot=None) -> str:
    """'fragment' when the expanded file holds only definitions (macros, properties,
    materials, gazebo, ros2_control), or is an add-on (every link it defines hangs from a
    joint, and some joint's parent is a link it does not define: an end effector or tool for
    a robot defined elsewhere); else 'entry'. ``robot``: the model as read (past xacro errors:
    the look-through's), else ``source``'s root is looked at."""
    if robot is not None and (robot.links or robot.joints):
        defined = {link.name for link in robot.links}
        children = {joint.child for joint in robot.joints}
        if defined <= children and any(joint.parent and joint.parent not in defined
                                       for joint in robot.joints):
            return "fragment"  # (no link at all: joints to links of the includer)
    root = robot.root if robot is not None and robot.root is not None else source.root
    if source.kind == "xacro" and root is None:
        return _role_as_written(source.texts.get(source.path, ""))
    if source.kind != "xacro" or root is None:
        return "entry"
    for child in root:
        tag = child.tag
        if isinstance(tag, str) and tag not in DEFINITION_TAGS:
            return "entry"
    return "fragment"


_XACRO_KEYWORDS = frozenset({"macro", "property", "include", "arg", "if", "unless", "insert_block",
                             "element", "attribute", "call", "eval"})


MAX_MACROS = 2000  # macro definitions looked at (a hostile file may hold millions)
_MACRO_NAME = re.compile(r"\bname\s*=\s*[\"']([^\"']+)[\"']")


def _role_as_written(text: str) -> str:
    """The role of a xacro file that could not be expanded, from its text: no ``<link>``
    outside its macro definitions, but joints or calls of macros it does not define (they
    come from its includer) -> 'fragment'."""
    text = without_comments(text, keep_unclosed=False)
    outside = _outside_macros(text)
    if re.search(r"<link[\s>/]", outside):
        return "entry"
    called = {name for name in re.findall(r"<xacro:([\w.-]+)", outside)
              if name not in _XACRO_KEYWORDS}
    if called:  # minus the macros it defines itself (each looked for near its tag)
        for match in itertools.islice(re.finditer(r"<xacro:macro\b", text), MAX_MACROS):
            tag = text[match.end():match.end() + 400].split(">", 1)[0]
            found = _MACRO_NAME.search(tag) if "name" in tag else None
            if found:
                called.discard(found.group(1))
    return "fragment" if called or re.search(r"<joint[\s>]", outside) else "entry"


def _outside_macros(text: str) -> str:
    """``text`` without its ``<xacro:macro>`` definitions (nested ones too), in one pass."""
    kept, start, depth = [], 0, 0
    for match in re.finditer(r"<xacro:macro\b|</xacro:macro\s*>", text):
        if match.group().startswith("</"):
            if depth:
                depth -= 1
                if depth == 0:
                    start = match.end()
        else:
            if depth == 0:
                kept.append(text[start:match.start()])
            depth += 1
    if depth == 0:
        kept.append(text[start:])
    return "".join(kept)


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
               load_options) -> tuple[list[int], list, list[int]]:
    """(the indices of the targets to check, a report per target: for those that need no check
    in changed-files mode, what they read from the cache, None for the others; the indices of
    fragments whose check waits: ``settle``).

    A fragment that an entry read when last checked (even if a file changed since) is checked
    through that entry: its own check waits for the entries' (issue 23.8: a hook on an edited
    macro file checks the entries that include it, not every file between them)."""
    reports: list = [None] * len(targets)
    if given is None:
        return list(range(len(targets))), reports, []
    known = [cached_reads(target, load_options) for target in targets]
    last = [reads if reads is not None else cached_reads(target, load_options, stale=True)
            for target, reads in zip(targets, known)]
    read_by_others: set[str] = set()
    read_by_entries: set[str] = set()
    for target, reads in zip(targets, last):
        if reads is not None and not is_companion(target.path):
            read_by_others.update(reads[0])
            if reads[1] == "entry" or target.configured:
                read_by_entries.update(reads[0])
    todo, waiting = [], []
    for index, (target, reads) in enumerate(zip(targets, known)):
        resolved = str(Path(target.path).resolve())
        before = last[index]
        if before is not None and before[1] == "fragment" and not target.configured \
                and resolved in read_by_entries:
            waiting.append(index)
        elif reads is None or given.intersection(reads[0]) or _launch_triggers(target, given) or (
                resolved in given  # a given fragment that an entry reads
                and not (reads[1] == "fragment" and resolved in read_by_others)):  # is checked
            todo.append(index)  # through that entry only
        else:
            reports[index] = FileReport(target.path, None)
            reports[index].includes, reports[index].role = reads
            if is_companion(target.path):  # an SRDF's reads are its robot's files
                reports[index].includes, reports[index].companion = (), reads[0]
    return todo, reports, waiting


def gone(targets: list[Target], load_options) -> set[str]:
    """The files that the last checks of ``targets`` read (the reads cache) and that are no
    longer there: deleted since. A commit that deletes an include does not name it (pre-commit
    gives a hook no deleted file); the entries that read it find it in their reads graph."""
    found: set[str] = set()
    for target in targets:
        before = cached_reads(target, load_options, stale=True)
        if before is not None:
            found.update(p for p in before[0] if not os.path.lexists(p))
    return found


def settle(targets: list[Target], reports: list, waiting: list[int], load_options) -> list[int]:
    """The waiting fragments (``unaffected``) that no entry read this time, to check now; the
    others get the report of their last check's reads (``classify`` shows them through their
    entries)."""
    read = {p for t, r in zip(targets, reports) if r is not None
            and (r.role == "entry" or t.configured) for p in r.includes}
    todo = []
    for index in waiting:
        target = targets[index]
        before = cached_reads(target, load_options, stale=True)
        if before is None or str(Path(target.path).resolve()) not in read:
            todo.append(index)
        else:
            reports[index] = FileReport(target.path, None)
            reports[index].includes, reports[index].role = before
    return todo


def cached_reads(target: Target, load_options,
                 stale: bool = False) -> tuple[tuple[str, ...], str] | None:
    """(the files a check of ``target`` read besides itself, its role) when recorded and none
    of those files changed since (``stale``: even if some did); else None."""
    import json

    from urdftool import cache

    if not cache.ENABLED:
        return None
    try:
        data = json.loads(_reads_entry(target, load_options).read_text(encoding="utf-8"))
        stamps, role = data["files"], data["role"]
        if not all(isinstance(s, list) and (stale or _stamp(s[0]) == s) for s in stamps):
            return None
        if not all(isinstance(s[0], str) for s in stamps):
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
    stamps = [_stamp(str(Path(target.path).resolve()))] + [
        _stamp(p) for p in (*report.includes, *report.companion)]
    if any(s is None for s in stamps):
        return
    cache.store(_reads_entry(target, load_options),
                json.dumps({"files": stamps, "role": report.role}).encode("utf-8"))
