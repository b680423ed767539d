"""The loader (issue 20): the one place that decides what a run may read and how it is read.

- ``run_roots(paths, options)``: the roots of a run (``urdftool.roots.Roots``), computed once
  from two sources only: the operator (``-P``, ``--model-path``, the package and model path
  variables of the environment) and the repository of each path the operator gave. Nothing a
  repository file says (configuration, includes, launch files, model paths) widens them.
- ``load(path, options)``: one robot file into a ``Source``, in this process or (untrusted
  xacro, YAML and SDF) in the sandboxed reader (``urdftool.sandbox``), which lives in this
  layer and calls the readers.
- ``files_read()``: every file the run read (realpaths): inputs, includes, YAML, meshes,
  configuration, baseline, package.xml; the one writer refuses to write over any of them.

The readers below (``source``, ``xacro_expand``, ``sdf``, ``physics.meshes``, ``packages``,
``launch``, ``config``) never import this module or the sandbox.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from urdftool.errors import ToolError
from urdftool.packages import PackageResolver
from urdftool.roots import (
    MODEL_VARIABLES,
    PATH_VARIABLES,
    Roots,
    forget_resolved,
    own_repository,
    real,
    repository_for,
    resolved,
    tracked,
)
from urdftool.source import LoadOptions, Source, detect_kind, find_unread, parse_text, read_input

EXAMPLES = Path(__file__).resolve().parent / "physics" / "examples"  # the rule docs' meshes
_ROOTS: dict[tuple, Roots] = {}


def operator_paths(options: LoadOptions | None, environ=None) -> list[str]:
    """The directories the operator names: ``-P`` values, ``--model-path``, and every entry of
    the package and model path variables."""
    environ = os.environ if environ is None else environ
    found = [*(options.packages.values() if options is not None else ()),
             *(options.sdf_model_paths if options is not None else ())]
    for variable in PATH_VARIABLES:
        found.extend(entry for entry in environ.get(variable, "").split(os.pathsep) if entry)
    return found


def model_paths(options: LoadOptions | None, environ=None) -> list[str]:
    """Where ``model://`` is looked for: ``--model-path``, then the model path variables."""
    environ = os.environ if environ is None else environ
    found = list(options.sdf_model_paths) if options is not None else []
    for variable in MODEL_VARIABLES:
        found.extend(entry for entry in environ.get(variable, "").split(os.pathsep) if entry)
    return found


def run_roots(paths, options: LoadOptions | None = None, environ=None, *, named: bool = False,
              workspace=None) -> Roots:
    """The roots of a run, memoised per process: the operator's directories (``-P``,
    ``--model-path``, the path variables) and one of

    - ``workspace`` (the editor's workspace folder): that folder, nothing above it;
    - ``named`` (``paths`` are named by a change: ``check --changed``, the hook's files, the
      Action's changed files): the working directory's repository (``working_root``); the
      paths are data and decide nothing, whatever they are (a link to another checkout);
    - else the repository of each path the operator typed (``typed_root``).

    ``options.packages`` must be the operator's (-P), not a configuration's: call this before
    the configuration is merged (``check.check_paths``). Nothing read later widens them."""
    forget_resolved()  # a run starts: realpaths are asked again, changed meshes read again
    if "urdftool.packages" in sys.modules:  # and packages looked for again (a new package.xml)
        sys.modules["urdftool.packages"].forget()
    if "urdftool.physics.meshes" in sys.modules:  # (a run that read no mesh never imports it)
        sys.modules["urdftool.physics.meshes"].forget_changed()
    environ = os.environ if environ is None else environ
    operator = operator_paths(options, environ)
    here = os.getcwd()
    key = ("workspace", os.path.abspath(workspace)) if workspace is not None else \
        ("named", here) if named else \
        ("typed", here, tuple(os.path.abspath(os.fspath(p)) for p in paths))
    key = (*key, tuple(operator))
    roots = _ROOTS.get(key)
    if roots is None:
        if workspace is not None:
            repositories = [workspace]
        elif named:
            repositories = [working_root(here)]
        else:
            repositories = _repositories(paths, own_repository(here))
        roots = _ROOTS[key] = Roots(repositories, [*operator, EXAMPLES])
    return roots


def working_root(here: str) -> Path:
    """The root of a run in ``here`` (the working directory) whose paths decide nothing: its
    repository, or ``here`` itself outside any (or inside a work tree that does not hold it:
    a checkout without its own metadata)."""
    return own_repository(here) or Path(here)


def typed_root(path, working: Path | None) -> Path | None:
    """The root a path the operator typed gives, ``working`` being the working directory's
    repository. Its directory (a file's, or a link's: a link decides nothing) is

    - inside the working directory's repository (as written): that repository when it holds
      the directory (``roots.tracked``), else what ``roots.repository_for`` gives a place
      outside any repository, never reaching what the repository holds (a checkout without
      metadata in it: the directory given, a file's package or its directory; a package's
      data installed under a virtual environment in the work tree), or nothing when a link
      on the way leads elsewhere (repository content);
    - elsewhere: its own repository, the directory given, a file's package or its directory
      (``roots.repository_for``: version-control roots looked for without following links)."""
    absolute = os.path.abspath(os.fspath(path))
    link = os.path.islink(absolute)
    directory = absolute if os.path.isdir(absolute) and not link else os.path.dirname(absolute)
    if working is not None and (directory == str(working)
                                or directory.startswith(str(working) + os.sep)):
        if tracked(working, Path(directory)):
            return working
        return repository_for(absolute) if real(directory) == directory else None
    return repository_for(absolute)


def _repositories(paths, working: Path | None) -> list:
    """``typed_root`` of each path, asked once per directory for the files of one directory
    (a thousand files of one folder walked the same parents a thousand times)."""
    found: dict[str, object] = {}
    repositories = []
    for path in paths:
        absolute = os.path.abspath(os.fspath(path))
        key = absolute if os.path.isdir(absolute) else os.path.dirname(absolute)
        if key not in found:
            found[key] = typed_root(absolute, working)
        if found[key] is not None:
            repositories.append(found[key])
    return repositories


def roots_of(path, options: LoadOptions) -> Roots:
    """``options.roots`` (the run's), or the roots of a run over ``path`` alone."""
    return options.roots if options.roots is not None else run_roots([path], options)


def resolver_for(path, options: LoadOptions) -> PackageResolver:
    """The package resolver of one input, bounded by the run's roots."""
    return PackageResolver(options.packages, Path(path), roots=roots_of(path, options),
                           model_paths=tuple(model_paths(options)))


def check_input(path, roots: Roots) -> None:
    """An input file itself must be inside the roots (a link committed to a repository must
    not make urdftool read, and quote, a file of the machine): ToolError naming the path as
    given, never where it leads."""
    if not roots.readable(path):
        raise ToolError(f"{path}: outside the repository and the operator's directories (a "
                        "link out of it, or version-control metadata); not read")


def _parse_large_mesh(path, need_volume):
    from urdftool import sandbox

    return sandbox.parse_large_mesh(path, need_volume)


def _mesh_hook(source: Source) -> None:
    """Large meshes parsed in the sandboxed reader in every mode (``meshes.LARGE_PARSER``):
    set when a document has a mesh, so that a robot without one never imports the mesh
    module (check's start-up on a primitive robot, tests/test_startup.py)."""
    if source.root is not None and next(source.root.iter("mesh"), None) is not None:
        from urdftool.physics import meshes

        meshes.LARGE_PARSER = _parse_large_mesh

_FILES_READ: set[str] = set()


def note_read(names) -> None:
    for name in names:
        try:
            _FILES_READ.add(resolved(name))
        except (OSError, ValueError):
            continue


def files_read() -> set[str]:
    """Realpaths of every file the loads of this process read: each input, include and YAML
    file (in this process or reported by the sandboxed reader: ``Source.texts``,
    ``Source.unread``, ``Source.reads``) and each mesh summarised (``physics.meshes``)."""
    meshes = sys.modules.get("urdftool.physics.meshes")  # no mesh read: not imported
    return _FILES_READ | (set(meshes._CACHE) if meshes is not None else set())


def load(path: str | Path, options: LoadOptions | None = None) -> Source:
    """Read one robot file into a Source. Raises ToolError when the file cannot be read."""
    options = options or LoadOptions()
    file_path = Path(path)
    resolver = resolver_for(file_path, options)
    # refused before asking whether it exists: a committed link out of the repository answers
    # the same whether or not its target is there (no existence oracle)
    check_input(file_path, resolver.roots)
    if not file_path.exists():
        raise ToolError(f"{path}: no such file")
    if options.roots is None:
        options = _with_roots(options, resolver.roots)
    text = read_input(file_path, options)
    note_read([file_path])
    kind = detect_kind(file_path, text)
    if options.untrusted and not options.in_sandbox:
        from urdftool import sandbox

        sandbox.use_for_meshes(resolver.roots, options)
        if kind != "urdf" and text.strip() and sandbox.available():
            source = sandbox.load_source(file_path, options, resolver, kind)
            note_read([*source.texts, *source.unread, *source.reads])
            _mesh_hook(source)
            return source
    source = Source(str(path), kind, texts={str(path): text}, resolver=resolver)
    if not text.strip():
        parse_text(text, str(path), source)  # reports xml.no-root
        return source
    if kind == "urdf":
        root = parse_text(text, str(path), source)
        if root is not None:
            source.root = root
            source.lines = text
    elif kind == "xacro":
        from urdftool.xacro_expand import expand

        expand(source, file_path, options)
    if kind != "sdf":
        find_unread(source, options)
        from urdftool.controllers import read_companions

        read_companions(source, options)
    else:
        from urdftool.sdf import load_sdf

        load_sdf(source, file_path, text, options)
    note_read([*source.texts, *source.unread, *source.reads])
    _mesh_hook(source)
    return source


def _with_roots(options: LoadOptions, roots: Roots) -> LoadOptions:
    import copy

    options = copy.copy(options)
    options.roots = roots
    return options
