"""The check of a companion file (issue 31): a MoveIt SRDF read by the loader (plain or xacro,
in this process or the sandboxed reader), the robot it describes read by the loader too (the
path or ``package://`` URI its pairing gives: ``package.Target.robot``, else ``--robot``), the
companion model built from both (``companion.build_srdf``) and the ``srdf`` rules run on it.
The SRDF's own reading problems are the ``xml``/``xacro`` rules' findings, as for any file;
the robot's are reported where the robot itself is checked. Runs layer, beside ``check``."""

from __future__ import annotations

import copy
import os
from pathlib import Path

from urdftool.errors import ToolError
from urdftool.loader import load, resolver_for
from urdftool.model import build_robot
from urdftool.package import SRDF_SUFFIXES, Target, is_launch_file
from urdftool.roots import real

READING_FAMILIES = ("xml", "xacro")  # what is said of the SRDF file itself
_ROBOTS: dict[tuple, tuple] = {}  # (path, args, packages) -> (robot, files): a few, per process
MAX_ROBOTS = 4
# the robot each SRDF (resolved path) was last checked against: the language server's
# go-to-definition from an SRDF name to the link or joint (a few, the last ones)
LAST_ROBOTS: dict[str, object] = {}


def _shown(path: Path) -> str:
    try:
        relative = os.path.relpath(path)
    except ValueError:
        return str(path)
    return str(path) if relative.startswith("..") else relative


def _robot_path(spec: str, srdf_path: str, load_options) -> tuple[Path | None, str | None]:
    """(the robot file ``spec`` names, None) or (None, why it was not found)."""
    if spec.startswith("package://"):
        resolver = resolver_for(srdf_path, load_options)
        found = resolver.resolve_uri(spec, Path(srdf_path).resolve().parent)
        if found is None or not found.is_file():
            name = spec[len("package://"):].split("/", 1)[0]
            where = f"package '{name}' was not found ({resolver.tried()})" if found is None \
                else f"no file at {_shown(found)}"
            return None, f"the robot {spec} was not found: {where}"
        return found, None
    path = Path(spec)
    if not path.is_file():
        return None, f"the robot {spec} was not found: no such file"
    return path, None


def _stamps(files) -> list:
    found = []
    for name in files:
        try:
            stat = os.stat(name)
            found.append((stat.st_size, stat.st_mtime_ns))
        except OSError:
            found.append(None)
    return found


def load_robot(spec: str, srdf_path: str, options, target: Target, pipeline):
    """(robot, its files resolved, shown path, None) or (None, (), spec, why not)."""
    srdf_options = pipeline.target_options(options, target)
    path, why = _robot_path(spec, srdf_path, srdf_options)
    if path is None:
        return None, (), spec, why
    robot_options = copy.copy(options.load)
    robot_options.xacro_args = {**target.robot_args, **options.load.xacro_args}
    robot_options.packages = {**target.packages, **options.load.packages}
    key = (real(path), tuple(sorted(robot_options.xacro_args.items())),
           tuple(sorted(robot_options.packages.items())), id(options.load.roots))
    shown = _shown(path)
    known = _ROBOTS.get(key)
    if known is not None and (robot_options.overlay or _stamps(known[1]) != known[2]):
        known = None  # a file of the robot changed (the language server lives long)
    if known is None:
        try:
            source = load(path, robot_options)
        except ToolError as exc:
            return None, (), shown, f"the robot {shown} could not be read: {exc}"
        robot = build_robot(source)
        files = tuple(sorted({real(p) for p in source.texts} | set(source.reads)))
        if len(_ROBOTS) >= MAX_ROBOTS:
            _ROBOTS.pop(next(iter(_ROBOTS)))
        known = _ROBOTS[key] = (robot, files, _stamps(files))
    robot, files, _ = known
    if not robot.links:
        return None, files, shown, (f"the robot {shown} could not be read (its own findings "
                                    "say why, where it is checked)")
    return robot, files, shown, None


HOW = ("name it in the MoveIt configuration's .setup_assistant (URDF: package, relative_path), "
       "in urdftool.toml (srdf = [{ file = \"...\", robot = \"...\" }]), or with --robot FILE")


def companion_once(pipeline, path: Path | str, options, load_options=None,
                   target: Target | None = None):
    """(source, the model of its document, diagnostics, the robot's files) of one reading of an
    SRDF: its reading's findings and the ``srdf`` rules against its robot (``target``'s, else
    ``--robot``, else what its package pairs it with: ``package.pair_srdf``). ``pipeline``:
    the ``check`` module (its ``run_rules``, ``target_options``, ``finish``), which calls this
    one."""
    from urdftool.companion import build_srdf, is_srdf
    from urdftool.package import pair_srdf

    if is_launch_file(path):
        return _launch_once(pipeline, path, options)
    if not str(path).endswith(SRDF_SUFFIXES):
        return _controllers_once(pipeline, path, options, target)
    if target is None or not target.robot:
        robot_spec, robot_args, note = pair_srdf(Path(path), {})
        target = (target or Target(str(path)))._replace(robot=robot_spec, robot_args=robot_args,
                                                        robot_note=note)
    source = load(path, load_options or pipeline.target_options(options, target))
    holder = build_robot(source)
    diagnostics = pipeline.run_rules(holder, source.path, options,
                            keep=lambda rule: rule.family in READING_FAMILIES)
    files: tuple[str, ...] = ()
    if is_srdf(source.root):
        spec = options.robot or target.robot or ""  # (the operator's --robot wins)
        robot, why = None, None
        if spec:
            robot, files, shown, why = load_robot(spec, source.path, options, target, pipeline)
        else:
            shown = ""
            why = "no robot is known for this SRDF" + (f" ({target.robot_note})"
                                                       if target.robot_note else "")
        srdf = build_srdf(source, robot, shown)
        if robot is not None:
            key = real(source.path)
            LAST_ROBOTS.pop(key, None)
            LAST_ROBOTS[key] = robot
            while len(LAST_ROBOTS) > 2 * MAX_ROBOTS:
                LAST_ROBOTS.pop(next(iter(LAST_ROBOTS)))
        if robot is None:
            srdf.missing = why + (f" (named by {target.robot_note})" if spec and
                                  target.robot_note else "")
            srdf.missing_hint = HOW
            diagnostics += pipeline.run_rules(srdf, source.path, options, on="srdf",
                                     keep=lambda rule: rule.id == "srdf.no-robot")
        else:
            diagnostics += pipeline.run_rules(srdf, source.path, options, on="srdf",
                                     keep=lambda rule: rule.id != "srdf.no-robot")
    return source, holder, diagnostics, files


MAX_LAUNCH_BYTES = 1 << 20


def _launch_once(pipeline, path: Path | str, options):
    """(source, holder, diagnostics, ()) of a Python launch file: its ``ast`` (never run)
    given to the rules registered ``on="launch"``."""
    import ast

    from urdftool.companion import Launch
    from urdftool.files import read_regular
    from urdftool.source import Source

    try:
        text = read_regular(Path(path), MAX_LAUNCH_BYTES).decode("utf-8", "replace")
    except OSError as exc:
        raise ToolError(f"{path}: {exc.strerror or exc}") from None
    source = Source(str(path), "urdf", texts={str(path): text})
    holder = build_robot(source)
    try:
        tree = ast.parse(text, str(path))
    except (SyntaxError, ValueError, RecursionError, MemoryError):
        tree = None  # (not judged: a launch file that does not parse fails on its own)
    diagnostics = pipeline.run_rules(Launch(str(path), text, tree, source), str(path), options,
                                     on="launch")
    return source, holder, diagnostics, ()


def _controllers_once(pipeline, path: Path | str, options, target: Target | None):
    """(source, holder, diagnostics, the robot's files) of a controllers YAML given by name:
    its controllers (``controllers.read_controllers``) against the robot named by ``--robot``
    (``srdf.no-robot``'s counterpart is a one-line ToolError: a YAML is checked only when its
    robot is given)."""
    from urdftool.companion import Controllers
    from urdftool.controllers import read_controllers
    from urdftool.files import read_regular
    from urdftool.source import Source

    target = target if target is not None else Target(str(path))
    spec = options.robot or target.robot
    if not spec:
        raise ToolError(f"{path}: a controllers YAML is checked against its robot: give --robot "
                        "FILE (a robot's own check reads the YAML its simulator plugin names)")
    try:
        text = read_regular(Path(path), 1 << 20).decode("utf-8", "replace")
    except OSError as exc:
        raise ToolError(f"{path}: {exc.strerror or exc}") from None
    source = Source(str(path), "urdf", texts={str(path): text})
    holder = build_robot(source)
    data = read_controllers(text, str(path))
    if isinstance(data, str):
        raise ToolError(f"{path}: not a YAML urdftool reads: {data}")
    robot, files, _, why = load_robot(spec, str(path), options, target, pipeline)
    if robot is None:
        raise ToolError(f"{path}: {why}")
    diagnostics = pipeline.run_rules(Controllers(data, robot), str(path), options,
                                     on="controllers")
    return source, holder, diagnostics, files


def check_companion(pipeline, path: Path | str, options, target: Target | None = None):
    """(the report of an SRDF, the model of its document for the language server)."""
    source, holder, diagnostics, files = companion_once(pipeline, path, options, None, target)
    report = pipeline.finish(source, holder, diagnostics, source.texts)
    report.args = target.args if target is not None else {}
    report.companion = files
    from urdftool.companion import is_srdf

    if report.role == "entry" or source.root is None or is_srdf(source.root):
        report.role = "companion"  # (never counted as a robot, never a fragment; an SRDF's
        # macro file, a <robot> of definitions only, stays a fragment of its includer)
    return report, holder
