"""``--untrusted``: where an untrusted input may read, and the sandboxed reader that parses it.

Under ``--untrusted`` every file whose parsing is more than bounded XML reading happens in a
separate, fresh Python interpreter (``urdftool.sandbox_child``), never a fork of this process
(which holds the CI secrets in its memory and environment):

- xacro and SDF inputs are read, expanded (xacro, YAML) and converted there; the Source comes
  back as tagged XML with its locations (JSON, never pickle);
- mesh files (trimesh, pycollada, the STL reader) are summarised there (``meshes.PARSER``);
- a plain URDF is read here, bounded (a regular file, at most 64 MB: ``source.read_text``),
  with the secure XML parser; only its meshes go to the child.

The child is started with ``python -I``, an environment holding only the ``--allow-env``
variables (and one-thread settings for the numeric libraries), no inherited descriptors, in a
session of its own. Before it reads anything it drops its capabilities, sets hard resource
limits, ``no_new_privs``, Landlock (read-only beneath the run's roots, ``Roots.landlock()``:
the repository without its version-control metadata and the operator's directories, and the
interpreter's own files) and a seccomp filter. Where the kernel lacks Landlock or seccomp, a
one-line notice says so. One child serves a whole run (per worker process); it is killed when
a request runs past ``--timeout``.

Part of the loader layer (``urdftool.loader`` computes the roots and calls this module; the
readers never import it).
"""

from __future__ import annotations

import json
import os
import select
import signal
import sys
import time
from pathlib import Path

from urdftool import roots as _roots
from urdftool.source import DEFAULT_TIMEOUT

IN_CHILD = False  # set by urdftool.sandbox_child: load() there does the work itself
GRACE_SECONDS = 1.0  # the child stops itself at the deadline; it is killed this much later
MESH_GRACE_SECONDS = 0.1  # a mesh parser (C code) never stops itself: killed at the deadline
START_SECONDS = 30.0  # a fresh interpreter importing lxml and xacro, on a loaded machine
CHILD_CPU_SECONDS = 120  # the child's whole CPU budget (it is replaced at half of it)
MAX_ANSWER_BYTES = 256 << 20
# variables the numeric libraries read: one thread each (the filter refuses processes, not
# threads, but a pool of them is only cost here)
CHILD_ENV = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
             "LC_ALL": "C.UTF-8"}
# where packages and models are (configuration, not secrets): the child finds packages and
# models as this process does; xacro's $(env)/$(optenv) still see only --allow-env ones
PATH_VARIABLES = _roots.PATH_VARIABLES
TEST_SWITCH = "URDFTOOL_SANDBOX_TEST"  # never passed by the CLI, even with --allow-env


class SandboxFailure(Exception):
    """The child died or sent something that is not an answer."""


def available() -> bool:
    return sys.platform.startswith("linux")


# -- the roots of the run (urdftool.loader computes them) -------------------------------------


_RUN: dict = {}  # the limits and roots of the untrusted run in this process


def use_for_meshes(roots, options=None) -> None:
    """Mesh files are from now on parsed in the sandboxed reader, whose Landlock gets
    ``roots.landlock()`` (``urdftool.roots.Roots``: the run's, computed once by the loader)."""
    if IN_CHILD or not available():
        return
    from urdftool.physics import meshes

    _RUN.update(roots=roots)
    if options is not None:
        _RUN.update(timeout=options.timeout, memory_mb=options.memory_mb,
                    allow_env=tuple(options.allow_env))
    meshes.PARSER = parse_mesh
    meshes.TRIANGLE_READER = read_triangles


def read_triangles(path: Path):
    """``meshes.read_triangles`` in the sandboxed reader (under ``--untrusted``)."""
    from urdftool.xacro_eval import LimitExceeded

    roots = _RUN.get("roots")
    if roots is None or not roots.readable(path):
        return "outside what the run may read"
    try:
        answer = _child(roots).ask({"op": "triangles", "path": os.fspath(path)},
                                   _RUN.get("timeout", DEFAULT_TIMEOUT),
                                   f"reading mesh {Path(path).name}", grace=MESH_GRACE_SECONDS)
        if "why" in answer:
            return str(answer["why"])
        import numpy as np

        vertices = np.asarray(answer["vertices"], dtype=np.float64).reshape(-1, 3)
        faces = np.asarray(answer["faces"], dtype=np.int64).reshape(-1, 3)
        if len(faces) and (faces.min() < 0 or faces.max() >= len(vertices)):
            return "malformed answer"
        return vertices, faces
    except (LimitExceeded, SandboxFailure, KeyError, TypeError, ValueError) as exc:
        return f"{exc}"


def parse_large_mesh(path: Path, need_volume: bool):
    """A large mesh (``meshes.LARGE_PARSER``): parsed in the sandboxed reader in every mode,
    where it can be stopped at --timeout and --memory-limit; None: parse it here (in the
    reader itself, or where there is no sandbox)."""
    if IN_CHILD or not available():
        return None
    return parse_mesh(path, need_volume)


# -- the child process ----------------------------------------------------------------------


def _child_env(allow_env: tuple[str, ...], test: bool = False) -> dict[str, str]:
    env = dict(CHILD_ENV)
    env.update((name, os.environ[name]) for name in (*PATH_VARIABLES, *allow_env)
               if name in os.environ and name != TEST_SWITCH)
    if test:
        env[TEST_SWITCH] = "1"
    return env


_BOOT = ("import sys; sys.path.insert(0, sys.argv[1]); "
         "from urdftool.sandbox_child import main; main()")


def _cwd() -> str:
    """The child runs where we run: the paths it is given and the paths it names in its
    findings are relative to it (Landlock, not the directory, bounds what it reads)."""
    try:
        return os.getcwd()
    except OSError:
        return "/"


class Child:
    """One sandboxed reader process and its pipes."""

    def __init__(self, read: list[Path], memory_mb: int, allow_env: tuple[str, ...] = (),
                 test: bool = False):
        import subprocess

        self.read = [Path(p) for p in read]
        self.settings = (int(memory_mb), tuple(allow_env))
        self.owner = os.getpid()
        self.cwd = os.getcwd()  # relative paths in requests are the parent's: same directory
        self.buffer = b""
        self.requests = 0
        package_parent = str(Path(__file__).resolve().parent.parent)
        started = time.monotonic()
        try:
            self.process = subprocess.Popen(
                [sys.executable, "-I", "-c", _BOOT, package_parent], stdin=subprocess.PIPE,
                stdout=subprocess.PIPE, close_fds=True, env=_child_env(allow_env, test),
                stderr=None if os.environ.get("URDFTOOL_DEBUG") else subprocess.DEVNULL,
                cwd=_cwd(), start_new_session=True)
        except OSError as exc:
            raise SandboxFailure(f"the sandboxed reader cannot start: {exc}") from None
        setup = {"read": [str(p) for p in self.read], "memory_mb": int(memory_mb),
                 "cpu_seconds": CHILD_CPU_SECONDS, "test_payload_allowed": test}
        answer = self._exchange(setup, START_SECONDS, "start")
        layers = answer.get("layers")
        if not isinstance(layers, dict):
            self.close()
            raise SandboxFailure("the sandboxed reader did not start")
        self.layers = {str(k): str(v) for k, v in layers.items()}
        self.start_seconds = time.monotonic() - started
        _notice(self.layers)

    def alive(self) -> bool:
        return self.process.poll() is None and self.owner == os.getpid()

    def cpu_seconds(self) -> float:
        try:
            with open(f"/proc/{self.process.pid}/stat", encoding="ascii") as stat:
                fields = stat.read().rsplit(")", 1)[1].split()
            return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
        except (OSError, ValueError, IndexError):
            return 0.0

    def ask(self, request: dict, timeout: float | None, what: str,
            grace: float = GRACE_SECONDS) -> dict:
        """Send ``request``; its answer, or LimitExceeded/SandboxFailure (the child is then
        gone: the next request starts another)."""
        self.requests += 1
        answer = self._exchange(request, timeout, what, grace)
        if "limit" in answer:
            from urdftool.xacro_eval import LimitExceeded

            raise LimitExceeded(str(answer["limit"]))
        if "tool_error" in answer:
            from urdftool.errors import ToolError

            raise ToolError(str(answer["tool_error"]))
        if "error" in answer:
            raise SandboxFailure(str(answer["error"]))
        return answer.get("ok")

    def _exchange(self, request: dict, timeout: float | None, what: str,
                  grace: float = GRACE_SECONDS) -> dict:
        from urdftool import budget
        from urdftool.xacro_eval import LimitExceeded

        timeout = budget.clamp(timeout)  # at most what the run has left (issue 21)
        try:
            self.process.stdin.write(json.dumps(request).encode("utf-8") + b"\n")
            self.process.stdin.flush()
        except OSError:
            self.close()
            raise SandboxFailure(f"the sandboxed reader is gone ({what})") from None
        deadline = time.monotonic() + timeout + grace if timeout else None
        out = self.process.stdout.fileno()
        while b"\n" not in self.buffer:
            remaining = None if deadline is None else deadline - time.monotonic()
            if remaining is not None and remaining <= 0:
                self.close()
                raise LimitExceeded(f"{what} took longer than {timeout:g} s (the sandboxed "
                                    "reader was stopped; --timeout sets the limit)")
            ready, _, _ = select.select([out], [], [], remaining)
            if not ready:
                continue
            chunk = os.read(out, 1 << 20)
            if not chunk:
                status = self.process.wait()
                self.close()
                if status in (-signal.SIGKILL, -signal.SIGXCPU, -signal.SIGSEGV, -signal.SIGABRT):
                    raise LimitExceeded(f"{what} ran out of memory or CPU time (the sandboxed "
                                        f"reader died of signal {-status})")
                raise SandboxFailure(f"the sandboxed reader died ({what}, status {status})")
            self.buffer += chunk
            if len(self.buffer) > MAX_ANSWER_BYTES:
                self.close()
                raise LimitExceeded(f"{what}: the answer is larger than "
                                    f"{MAX_ANSWER_BYTES >> 20} MB")
        line, _, self.buffer = self.buffer.partition(b"\n")
        try:
            answer = json.loads(line)
        except ValueError:
            answer = None
        if not isinstance(answer, dict):
            self.close()
            raise SandboxFailure(f"the sandboxed reader sent an unreadable answer ({what})")
        return answer

    def close(self) -> None:
        if self.owner != os.getpid():  # a forked worker's copy: the parent's child, not ours
            return
        if self.process.poll() is None:
            try:
                os.killpg(self.process.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                self.process.kill()
        for stream in (self.process.stdin, self.process.stdout):
            try:
                stream.close()
            except OSError:
                pass
        self.process.wait()


_CHILD: list[Child] = []  # this process's reader (a forked worker starts its own)


def _child(roots) -> Child:
    """The run's reader: Landlock gets exactly ``roots.landlock()`` (the run's roots, without
    version-control metadata) and the interpreter's files."""
    current = _CHILD[0] if _CHILD else None
    # the variables it is started with are part of what it is: a reader started before
    # GZ_SIM_RESOURCE_PATH changed finds models elsewhere (in-process runs: tests, the LSP)
    settings = (int(_RUN.get("memory_mb", 1024)), tuple(_RUN.get("allow_env", ())),
                tuple(os.environ.get(name) for name in PATH_VARIABLES))
    read = roots.landlock()
    if current is not None and current.alive() and current.read == read \
            and current.settings == settings and current.cwd == os.getcwd() \
            and current.cpu_seconds() < CHILD_CPU_SECONDS / 2:
        return current
    if current is not None:
        current.close()
        _CHILD.clear()
    child = Child(read, *settings[:2])
    child.settings = settings
    _CHILD[:] = [child]
    return child


def _close_children() -> None:
    for child in _CHILD:
        child.close()


import atexit

atexit.register(_close_children)

_NOTICED: set[str] = set()


def _notice(layers: dict[str, str]) -> None:
    """One line on stderr per missing layer and process: degraded, never in silence."""
    for layer, state in layers.items():
        if state.startswith("off") and layer not in _NOTICED:
            _NOTICED.add(layer)
            sys.stderr.write(f"urdftool: note: --untrusted without {layer} ({state[4:].strip()}); "
                             "the other layers still hold (urdftool doctor lists them)\n")


# -- requests -------------------------------------------------------------------------------


def load_source(path: Path, options, resolver, kind: str):
    """A xacro or SDF input read, expanded and converted in the sandboxed reader."""
    from urdftool import budget
    from urdftool.findings import Finding, Loc
    from urdftool.source import Source
    from urdftool.xacro_eval import LimitExceeded

    _RUN.update(timeout=options.timeout, memory_mb=options.memory_mb,
                allow_env=tuple(options.allow_env))
    request = {"op": "load", "path": os.fspath(path), "packages": dict(options.packages),
               "xacro_args": dict(options.xacro_args), "sdf_model": options.sdf_model,
               "sdf_model_paths": list(options.sdf_model_paths),
               "allow_env": list(options.allow_env), "timeout": budget.clamp(options.timeout),
               "overlay": dict(options.overlay), "lenient": options.lenient,
               "roots": resolver.roots.to_json(), "crawls": _crawls(resolver.roots)}
    what = "xacro expansion" if kind == "xacro" else "SDF reading"
    limit_rule, failure_rule = (("xacro.limit-exceeded", "xacro.error") if kind == "xacro"
                                else ("sdf.bad-value", "sdf.bad-value"))
    try:
        answer = _child(resolver.roots).ask(request, options.timeout, what)
        source = source_from_json(answer, str(path))
        # files the reader says it read: inside the roots, or not taken (a fix may write them)
        for files in (source.texts, source.unread):
            for name in [n for n in files if not resolver.allows(Path(n))]:
                del files[name]
        # the reader sees no variable: a default taken for a variable that is not set here
        # is what xacro itself would take, not a finding
        source.problems = [(rule, f) for rule, f in source.problems
                           if rule != "xacro.env-not-allowed"
                           or (f.hint or "").rpartition(" ")[2] in os.environ]
    except LimitExceeded as exc:
        source = Source(str(path), kind)
        source.add(limit_rule, Finding(f"{kind}: {exc}; reading stopped",
                                       Loc(str(path), None, None)))
    except SandboxFailure as exc:
        source = Source(str(path), kind)
        source.add(failure_rule, Finding(f"{kind}: {exc}", Loc(str(path), None, None)))
    source.resolver = resolver
    return source


def _crawls(roots) -> dict:
    """The packages of each repository, crawled here: the reader's Landlock holds a
    repository's entries but not the repository directory itself (that would hold its
    ``.git``), so it cannot list it."""
    from urdftool.packages import crawl

    return {str(root): {name: str(path) for name, path in crawl(root).items()}
            for root in roots.repositories}


def convert_in_child(path: Path, options, load, resolver):
    """``urdftool convert`` of an untrusted SDF file, in the sandboxed reader: (Source, why
    the conversion was refused or None, why no model could be chosen or None)."""
    from urdftool.xacro_eval import LimitExceeded

    _RUN.update(timeout=load.timeout, memory_mb=load.memory_mb, allow_env=tuple(load.allow_env))
    request = {"op": "convert", "path": os.fspath(path), "packages": dict(load.packages),
               "model": options.model, "model_paths": list(options.model_paths),
               "package_uris": list(options.package_uris),
               "output_dir": os.fspath(options.output_dir), "cut_loops": options.cut_loops,
               "roots": resolver.roots.to_json(), "crawls": _crawls(resolver.roots)}
    try:
        answer = _child(resolver.roots).ask(request, load.timeout, "SDF conversion")
        source = source_from_json(answer["source"], str(path))
        refused, choice = answer["refused"], answer["choice"]
        if not (refused is None or isinstance(refused, str)) \
                or not (choice is None or isinstance(choice, str)):
            raise SandboxFailure("malformed answer from the sandboxed reader")
    except (LimitExceeded, SandboxFailure, KeyError, TypeError) as exc:
        from urdftool.errors import ToolError

        raise ToolError(f"{path}: cannot convert: {exc}") from None
    source.resolver = resolver
    return source, refused, choice


def parse_mesh(path: Path, need_volume: bool):
    """``meshes._load`` in the sandboxed reader (``meshes.PARSER`` under ``--untrusted``)."""
    from urdftool.physics import meshes
    from urdftool.xacro_eval import LimitExceeded

    roots = _RUN.get("roots")
    if roots is None or not roots.readable(path):  # a large mesh of a trusted library call
        roots = _roots.Roots([Path(path).resolve().parent])
    request = {"op": "mesh", "path": os.fspath(path), "need_volume": need_volume}
    what = f"reading mesh {Path(path).name}"
    try:
        child = _child(roots)
        try:
            answer = child.ask(request, _RUN.get("timeout", DEFAULT_TIMEOUT), what,
                               grace=MESH_GRACE_SECONDS)
        except LimitExceeded as exc:
            # big meshes read before leave the reader's address space fragmented: a mesh
            # that fits is asked once more of a fresh reader before it is said unreadable
            if child.requests == 1 or "out of memory" not in str(exc):
                raise
            child.close()
            answer = _child(roots).ask(request, _RUN.get("timeout", DEFAULT_TIMEOUT), what,
                                       grace=MESH_GRACE_SECONDS)
        header, hull = answer["header"], meshes.hull_values(answer["hull"])
        if not isinstance(header, dict) or hull is None:
            raise SandboxFailure("malformed mesh summary")
        info = meshes._decode(Path(path), (header, hull))
        if info is None:
            raise SandboxFailure("malformed mesh summary")
        return info
    except (LimitExceeded, SandboxFailure, KeyError, TypeError) as exc:
        return meshes.MeshInfo(str(path), error=f"{meshes.TRANSIENT}{exc}")


# -- a Source as JSON (the child's answer to ``load``) --------------------------------------

_LOC_INDEX = "urdftool-sandbox-loc"


def _loc_json(loc):
    return None if loc is None else [loc.path, loc.line, loc.column, loc.element,
                                     list(loc.via)]


def source_to_json(source) -> dict:
    """In the child: the Source as JSON, its tree as XML with each element's location index in
    an attribute."""
    from lxml import etree

    locs = []
    text = None
    if source.root is not None:
        for element in source.root.iter():
            if not isinstance(element.tag, str):
                continue
            element.attrib.pop(_LOC_INDEX, None)
            if element in source.locs:
                element.set(_LOC_INDEX, str(len(locs)))
                locs.append(_loc_json(source.locs[element]))
        # the comments beside the root too: expand prints them, as xacro does
        root = source.root
        nodes = [*reversed(list(root.itersiblings(preceding=True))), root, *root.itersiblings()]
        text = "".join(etree.tostring(node, encoding="unicode", with_tail=False)
                       for node in nodes)
    from urdftool import files

    files_read = files.read_paths()  # all read here: for the parent's "files read" set
    files.READ.clear()
    return {"kind": source.kind, "root": text, "locs": locs, "texts": source.texts,
            "unread": source.unread, "reads": sorted(source.reads),
            "missing": {path: [_loc_json(loc) for loc in where]
                        for path, where in source.missing.items()},
            "controllers": source.controllers,
            "files_read": files_read, "lost": list(source.lost),
            "defaults": source.defaults,
            "problems": [[rule, f.message, _loc_json(f.loc), f.hint, f.severity,
                          [list(e) for e in f.edits]] for rule, f in source.problems]}


def source_from_json(data, path: str):
    """In the parent: the child's Source, checked field by field (it is data from a process
    that read an untrusted file); its XML is read with the secure parser."""
    from lxml import etree

    from urdftool.edits import Edit
    from urdftool.findings import Finding, Loc
    from urdftool.source import Source, _utf8_bytes
    from urdftool.xmlrepair import secure_parser

    bad = SandboxFailure("malformed answer from the sandboxed reader")

    def text(value, optional=True):
        if (value is None and optional) or isinstance(value, str):
            return value
        raise bad

    def number(value):
        if value is None or (isinstance(value, int) and not isinstance(value, bool)):
            return value
        raise bad

    def loc(value):
        if value is None:
            return None
        where, line, column, element, via = value
        return Loc(text(where, False), number(line), number(column), text(element),
                   tuple(text(v, False) for v in via))

    def edit(value):
        path, line, column, end_line, end_column, replacement = value
        return Edit(text(path, False), *(number(n) or 0 for n in (line, column, end_line,
                                                                  end_column)),
                    text(replacement, False))

    try:
        if data.get("kind") not in ("xacro", "sdf", "urdf"):
            raise bad
        source = Source(path, data["kind"], texts={text(k, False): text(v, False)
                                                   for k, v in data["texts"].items()})
        source.unread = {text(k, False): text(v, False) for k, v in data["unread"].items()}
        source.reads = {text(p, False) for p in data.get("reads", ())}
        source.missing = {text(p, False): [loc(where) for where in sites]
                          for p, sites in data.get("missing", {}).items()}
        from urdftool import files

        for read in data.get("files_read", ()):
            files.note(text(read, False))
        source.lost = tuple(text(n, False) for n in data.get("lost", ()))
        source.defaults = {text(n, False): static is True
                           for n, static in dict(data.get("defaults", {})).items()}
        from urdftool.controllers import checked

        source.controllers = checked(data.get("controllers"))
        for rule, message, where, hint, severity, edits in data["problems"]:
            source.add(text(rule, False), Finding(text(message, False), loc(where), text(hint),
                                                  text(severity), tuple(map(edit, edits))))
        locs = [loc(value) for value in data["locs"]]
        xml = text(data["root"])
    except (KeyError, TypeError, ValueError, AttributeError):
        raise bad from None
    if xml is None:
        return source
    try:
        root = etree.fromstring(_utf8_bytes(xml), secure_parser())
    except etree.XMLSyntaxError as exc:
        source.add("xacro.limit-exceeded" if source.kind == "xacro" else "sdf.bad-value", Finding(
            f"the document read cannot be read back ({exc.msg}); nested too deeply or too "
            "large", Loc(path, None, None)))
        return source
    for element in root.iter():
        if not isinstance(element.tag, str):
            continue
        index = element.attrib.pop(_LOC_INDEX, None)
        if index is not None and index.isdigit() and int(index) < len(locs):
            source.locs[element] = locs[int(index)]
    source.root = root
    return source


# -- what holds here (urdftool doctor) and the tests' way in --------------------------------


def layers() -> dict[str, str]:
    """The layers a sandboxed reader gets on this machine (starts one)."""
    if not available():
        return {"sandbox": f"off: {sys.platform} is not Linux; --untrusted reads in-process"}
    child = Child([], 1024)
    try:
        return dict(child.layers)
    finally:
        child.close()


def run_test_payload(code: str, read: list[Path], memory_mb: int = 1024,
                     allow_env: tuple[str, ...] = ()) -> dict:
    """Tests only: run Python ``code`` inside a confined reader (exactly the CLI's, plus a
    switch in its environment that no CLI option sets) and return ``{"layers": ...,
    "ok"|"error": ...}`` (``ok``: the payload's ``result``): the sandbox attacked without
    going through the xacro interpreter."""
    child = Child(read, memory_mb, allow_env, test=True)
    try:
        return {"layers": child.layers, **child._exchange(code, 30.0, "a test payload")}
    finally:
        child.close()
