"""Mesh files: resolve a ``<mesh filename>``, load it (binary STL directly with numpy, the rest
with trimesh, imported here, lazily: only when a mesh must be parsed) and keep what the rules
need: unit-density mass properties, convex hull vertices, extents, watertightness.

Each file is loaded once per process: ``load_mesh`` caches by resolved path (``LOADS`` counts
the real loads, for tests and benchmarks). The cache holds small summaries, not the meshes; they
are also kept between runs in the persistent cache (``urdftool.cache``), so that a repeated
``check`` parses no mesh at all.
"""

from __future__ import annotations

import math
import os
import re
import sys
import threading
import warnings
from array import array
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

from urdftool.errors import exception_text
from urdftool.packages import is_file, resolved
from urdftool.physics.inertia import Extent, Mat3, Solid, Vec3, sub

# formats trimesh reads (after pycollada for DAE); others (Ogre .mesh, VTK...) are not checked
LOADABLE = {".stl", ".obj", ".dae", ".ply", ".off", ".glb", ".gltf", ".3mf", ".zae"}
_UNIT_RE = re.compile(rb"<unit\b[^<>]*\bmeter\s*=\s*[\"']([^\"'<]+)[\"']")
# How a file's coordinates are read; part of every cache entry's key (``cache.stamp``): bump it
# when the reading changes (2: a COLLADA <up_axis> is no longer turned, see ``_collada_unit``;
# 3: COLLADA arrays over libxml2's 10 MB text limit read by the fast reader, not pycollada)
READING = 3

LOADS = 0  # how many files were actually read (cache misses)
# parses a file (path, need_volume) -> MeshInfo instead of this process: set by
# urdftool.sandbox under --untrusted (the sandboxed reader runs ``_load``)
PARSER = None
# parses a large file (path, need_volume) -> MeshInfo, or None to parse it here: set by the
# loader (the sandboxed reader in every mode, see IN_PROCESS_BYTES)
LARGE_PARSER = None
MAX_MESH_BYTES = 64 << 20  # a mesh file, or what a compressed one (.zae, .3mf) unpacks to
MAX_TRIANGLES = 5_000_000
TRANSIENT = "sandboxed reader: "  # an error of the reader, not of the file: never stored
TIMED_OUT = "took longer than"  # in a TRANSIENT error: stopped at --timeout, not known broken


# in an error: a library trimesh needs for this file is not installed (pycollada for DAE,
# scipy for the hull...): the mesh is not checked (mesh.not-checked), never unreadable, and
# the summary is never stored (installing the library must not leave the stale answer)
MISSING_LIBRARY = "needs the optional library "


def missing_library(info) -> str | None:
    """The import name of the library this mesh could not be read without, if that was why."""
    error = info.error or ""
    return error[len(MISSING_LIBRARY):] if error.startswith(MISSING_LIBRARY) else None


def _missing(path: Path, exc: ImportError) -> MeshInfo:
    name = (getattr(exc, "name", None) or "").split(".")[0] or _one_line(str(exc))
    return MeshInfo(str(path), error=MISSING_LIBRARY + name)


# a file Git LFS keeps as a pointer until `git lfs pull` (a clone without LFS, actions/checkout
# without `lfs: true`): not the description's defect, and no tool of this checkout reads it
LFS_POINTER = "a Git LFS pointer, not the mesh (the checkout did not pull it)"
_LFS_HEAD = b"version https://git-lfs.github.com/spec/"


def lfs_pointer(info) -> bool:
    return (info.error or "").startswith(LFS_POINTER)


def _is_lfs_pointer(path: Path) -> bool:
    """Whether the regular file ``path`` is a Git LFS pointer (its first bytes say so)."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except OSError:
        return False
    try:
        return os.read(fd, len(_LFS_HEAD)) == _LFS_HEAD
    except OSError:
        return False
    finally:
        os.close(fd)


def timed_out(info) -> bool:
    """The reader was stopped at the time limit: the mesh is not checked, not unreadable."""
    error = info.error or ""
    return error.startswith(TRANSIENT) and TIMED_OUT in error
_CACHE: dict[str, MeshInfo] = {}
_STAMPS: dict[str, tuple[int, int] | None] = {}  # (size, mtime) of each file in _CACHE, when read
_TRIMESH: bool | None = None  # trimesh_available(), found once


@dataclass(frozen=True)
class MeshInfo:
    """What the rules need of one mesh file, in the file's own coordinates (DAE ``<unit>``
    applied, URDF ``scale`` not)."""

    path: str
    error: str | None = None  # why it could not be loaded (None when loaded)
    unsupported: bool = False  # a format trimesh cannot read: not checked, not an error
    solid: Solid | None = None  # unit density; None when the mesh encloses no volume
    watertight: bool = False
    used_hull: bool = False  # mass properties are the convex hull's (mesh not a closed volume)
    # the convex hull's vertices, x y z after another (float64): kept flat, as the cache stores
    # it (numpy takes it as it is; ``hull`` makes tuples of a small one only when asked)
    flat: array = field(default_factory=lambda: array("d"), repr=False)
    lower: Vec3 = (0.0, 0.0, 0.0)
    upper: Vec3 = (0.0, 0.0, 0.0)
    faces: int = 0
    has_volume: bool = False  # the volume fields (solid, watertight, used_hull) are computed

    @property
    def ok(self) -> bool:
        return self.error is None and not self.unsupported

    @cached_property
    def hull(self) -> tuple:
        """The convex-hull vertices as (x, y, z) float tuples."""
        values = iter(self.flat)
        return tuple(zip(values, values, values))

    @property
    def hull_size(self) -> int:
        return len(self.flat) // 3

    @property
    def extents(self) -> Vec3:
        return sub(self.upper, self.lower)


def clear_cache() -> None:
    global LOADS
    _CACHE.clear()
    _STAMPS.clear()
    _SAME.clear()
    _COLUMNS.clear()
    LOADS = 0


def _stamp(path: str) -> tuple[int, int] | None:
    try:
        st = os.stat(path)
    except OSError:
        return None
    return st.st_size, st.st_mtime_ns


def forget_changed() -> None:
    """Forget the summaries of files changed since they were read (a run starts: a mesh
    exported again while the language server runs is read again)."""
    for key, stamp in list(_STAMPS.items()):
        if _stamp(key) != stamp:
            _CACHE.pop(key, None)
            del _STAMPS[key]


def trimesh_available() -> bool:
    """Whether trimesh is installed (without importing it: a warm run takes every mesh from the
    persistent cache and never needs it)."""
    global _TRIMESH
    if _TRIMESH is None:
        from importlib.util import find_spec

        try:
            _TRIMESH = find_spec("trimesh") is not None
        except (ImportError, ValueError):  # a finder that refuses it, a broken half-install
            _TRIMESH = False
    return _TRIMESH


def resolve(robot, geometry) -> Path | None:
    """The local path of a mesh geometry's file, or None when its URI cannot be resolved.
    Relative names are relative to the file where the ``<mesh>`` was written."""
    if not geometry.filename:
        return None
    base_dir = _directory(geometry.loc.path) if geometry.loc is not None else Path(".")
    resolver = robot.source.resolver
    if resolver is None:
        from urdftool.packages import PackageResolver

        resolver = PackageResolver(start=Path(robot.source.path))
    return resolver.resolve_uri(geometry.filename.strip(), base_dir)


_DIRECTORIES: dict[str, Path] = {}


def _directory(path: str) -> Path:
    """``Path(path).parent``, memoised (every mesh of a file asks)."""
    found = _DIRECTORIES.get(path)
    if found is None:
        found = _DIRECTORIES[path] = Path(path).parent
    return found


def load_mesh(path: Path | str, need_volume: bool = False) -> MeshInfo:
    """The summary of a mesh file, loaded once per process (cached by resolved path).

    The hull and extents are always computed; the enclosed volume and mass properties (which
    need the mesh's topology: watertightness, winding) only with ``need_volume``, for the
    meshes the inertia is derived from. An entry made without them is completed on demand
    (a second read, only for a file first met as a visual and later needed for its volume).
    """
    key = resolved(path)
    info = _CACHE.get(key)
    if info is None or (need_volume and not info.has_volume and info.ok):
        _STAMPS[key] = _stamp(key)
        known = _known(_SAME.get(key), need_volume)
        if known is not None:  # the same bytes elsewhere, already summarised
            from dataclasses import replace

            from urdftool import files

            files.note(key)
            info = _CACHE[key] = replace(known, path=key)
        else:
            from urdftool import budget

            with budget.paused():  # not the rules' time: the reader's own limits bound it
                info = _CACHE[key] = _stored_or_load(Path(key), need_volume)
    return info


def _known(path: str | None, need_volume: bool, depth: int = 0) -> MeshInfo | None:
    """A summary of ``path`` this process or the persistent cache already holds (following
    ``same_content``), never read from the file here; None when there is none."""
    if path is None or depth > 8:
        return None
    info = _CACHE.get(path)
    if info is None and Path(path).suffix.lower() in LOADABLE:
        from urdftool import cache

        key = cache.stamp(Path(path), READING)
        info = _decode(Path(path), cache.read("mesh", key)) if key is not None else None
    if info is not None and (info.has_volume or not need_volume or not info.ok) and \
            not missing_library(info) and not (info.error or "").startswith(TRANSIENT):
        return info
    return _known(_SAME.get(path), need_volume, depth + 1)


_SAME: dict[str, str] = {}  # a file -> another with the same bytes (``same_content``)


def same_content(path: Path | str, twin: Path | str) -> None:
    """Say that ``path`` holds the same bytes as ``twin`` (``urdftool diff``: a revision's
    temporary tree and the working tree or the other revision's tree, from their git blob
    ids): ``load_mesh(path)`` gives the summary this process or the persistent cache holds of
    ``twin`` (never reading ``twin`` itself: it may lie outside the run's roots), else reads
    ``path``."""
    _SAME[resolved(path)] = resolved(twin)


def _stored_or_load(path: Path, need_volume: bool) -> MeshInfo:
    """The summary from the persistent cache when it has a complete enough one, else loaded
    (and stored)."""
    from urdftool import cache, files

    files.note(path)  # the run's "files read": no output may overwrite a mesh it read
    key = cache.stamp(path, READING) if path.suffix.lower() in LOADABLE else None
    if key is None:
        return _load(path, need_volume)
    stored = _decode(path, cache.read("mesh", key))
    if stored is not None and (stored.has_volume or not need_volume or not stored.ok):
        return stored
    _READ.bytes = None
    info = _load(path, need_volume)
    read, _READ.bytes = _READ.bytes, None
    if not (info.error or "").startswith((TRANSIENT, MISSING_LIBRARY)):
        content = read[1] if read is not None and read[0] == str(path) else None
        cache.write("mesh", key, *_encode(info), content=content)
    return info


# the bytes this thread's reading of a mesh parsed, (path, bytes): the cache entry's SHA-256
# is theirs (the file is not read again to hash it, nor can a change meanwhile be hashed in)
_READ = threading.local()


def _file_bytes(path: Path) -> bytes:
    data = path.read_bytes()
    _READ.bytes = (str(path), data)
    return data


def _encode(info: MeshInfo) -> tuple[dict, object]:
    """(JSON header, the hull vertices' coordinates) of a summary, for ``urdftool.cache``."""
    solid = None if info.solid is None else [
        info.solid.volume, *info.solid.centroid, *(x for row in info.solid.second for x in row)]
    header = {"error": info.error, "faces": info.faces, "lower": info.lower,
              "upper": info.upper, "has_volume": info.has_volume,
              "watertight": info.watertight, "used_hull": info.used_hull, "solid": solid}
    return header, info.flat


def hull_text(values) -> str:
    """A summary's hull coordinates as text for the sandboxed reader's JSON answer: their
    little-endian float64 bytes in base64 (a JSON list of 600k floats took 0.57 s to write and
    read again over 309 COLLADA files, base64 0.12 s)."""
    import base64

    floats = array("d", values)
    if sys.byteorder == "big":
        floats.byteswap()
    return base64.b64encode(floats.tobytes()).decode("ascii")


def hull_values(text) -> array | None:
    """The coordinates ``hull_text`` wrote, or None when ``text`` is not such a text."""
    import base64
    import binascii

    if not isinstance(text, str):
        return None
    try:
        data = base64.b64decode(text, validate=True)
    except (binascii.Error, ValueError):
        return None
    if len(data) % 8:
        return None
    floats = array("d")
    floats.frombytes(data)
    if sys.byteorder == "big":
        floats.byteswap()
    return floats


def _floats(value, count: int) -> bool:
    return isinstance(value, list) and len(value) == count and \
        all(type(x) is float for x in value)


def _decode(path: Path, stored) -> MeshInfo | None:
    """The summary stored by ``_encode``; None unless every field has its type and shape (a
    corrupt entry is never trusted)."""
    if stored is None:
        return None
    header, values = stored
    error, solid = header.get("error"), header.get("solid")
    flags = [header.get(k) for k in ("has_volume", "watertight", "used_hull")]
    if not (error is None or isinstance(error, str)) or type(header.get("faces")) is not int \
            or not all(type(f) is bool for f in flags) \
            or not _floats(header.get("lower"), 3) or not _floats(header.get("upper"), 3) \
            or not (solid is None or _floats(solid, 13)):
        return None
    if error is not None:
        return MeshInfo(str(path), error=error)
    if len(values) == 0 or len(values) % 3:
        return None
    second = tuple(tuple(solid[4 + 3 * i:7 + 3 * i]) for i in range(3)) if solid else None
    return MeshInfo(str(path), flat=values if type(values) is array else array("d", values),
                    lower=tuple(header["lower"]),
                    upper=tuple(header["upper"]), faces=header["faces"],
                    has_volume=flags[0], watertight=flags[1], used_hull=flags[2],
                    solid=Solid(solid[0], tuple(solid[1:4]), second) if solid else None)


def _collada_unit(path: Path) -> float:
    """A COLLADA file's ``<unit meter>`` (1 when it has none): every ROS tool scales by it.

    Its ``<up_axis>`` is NOT applied, as the ROS tools read the file: assimp turns a non-Y-up
    scene in its root node's transform, which RViz drops (rviz ``src/rviz/mesh_loader.cpp``,
    ``buildMesh``: "don't rotate to y-up orientation", it keeps the root's scale) and MoveIt's
    geometric_shapes resets (``src/mesh_operations.cpp``, ``createMeshFromBinary``: the root
    transform set to identity before ``aiProcess_OptimizeGraph``); Gazebo classic's own
    ``common/ColladaLoader.cc`` reads ``<unit meter>`` and never ``<up_axis>``. So a Y_UP file is
    drawn, collided and measured in its own coordinates, and so is it checked here."""
    if path.suffix.lower() != ".dae":
        return 1.0
    try:
        with path.open("rb") as handle:
            head = handle.read(16384)
    except OSError:
        return 1.0
    match = _UNIT_RE.search(head)
    try:
        unit = float(match.group(1)) if match else 1.0
    except ValueError:
        unit = 1.0
    return unit if unit > 0 and math.isfinite(unit) else 1.0


def _load(path: Path, need_volume: bool) -> MeshInfo:
    global LOADS
    if path.suffix.lower() not in LOADABLE:
        return MeshInfo(str(path), unsupported=True)
    if not is_file(path):
        return MeshInfo(str(path), error="no such file")
    if _is_lfs_pointer(path):
        return MeshInfo(str(path), error=LFS_POINTER)
    import numpy as np

    LOADS += 1
    if PARSER is not None:
        return PARSER(path, need_volume)
    if LARGE_PARSER is not None and _large(path):  # trusted too: a parse that can be stopped
        info = LARGE_PARSER(path, need_volume)  # at --timeout and --memory-limit
        if info is not None:
            return info
    with _LibraryLog() as log:
        try:
            _check_size(path)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                triangles = _read(path)
        except ImportError as exc:  # an optional library is missing: not the file's fault
            return _missing(path, exc)
        except Refused as exc:
            return MeshInfo(str(path), error=str(exc))
        except Exception as exc:  # noqa: BLE001 - any parser failure is a finding, not a crash
            return MeshInfo(str(path), error=exception_text(exc))
        if triangles is None:
            return MeshInfo(str(path), error="no triangles in it" + log.cause())
        if len(triangles[1]) > MAX_TRIANGLES:
            return MeshInfo(str(path), error=f"{len(triangles[1])} triangles, more than the "
                                             f"{MAX_TRIANGLES} urdftool reads")
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            try:
                return _summarise(path, *triangles, need_volume)
            except ImportError as exc:  # scipy (the hull)
                return _missing(path, exc)


MAX_COLLISION_TRIANGLES = 200_000  # a collision mesh tested triangle by triangle (issue 31)
# reads a mesh's triangles in the sandboxed reader (set under --untrusted, as ``PARSER``)
TRIANGLE_READER = None


def read_triangles(path: Path):
    """(vertices N x 3, faces M x 3: numpy arrays) of a mesh file as the summaries read it (a
    DAE's unit applied, ``_collada_unit``), or why not (a one-line string). For collision
    tests of the meshes themselves (the ``srdf`` rules' sampling): in the sandboxed reader
    under --untrusted, like every mesh parse."""
    if TRIANGLE_READER is not None:
        return TRIANGLE_READER(path)
    return _triangles_here(path)


def _triangles_here(path: Path):
    if path.suffix.lower() not in LOADABLE or not is_file(path):
        return "not a mesh file urdftool reads"
    unit = _collada_unit(path)  # (as every ROS tool reads a COLLADA file: no up-axis turn)
    with _LibraryLog():
        try:
            _check_size(path)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                triangles = _read(path)
        except Exception as exc:  # noqa: BLE001 - any parser failure: not tested
            return _one_line(f"{type(exc).__name__}: {exc}")
    if triangles is None:
        return "no triangles in it"
    vertices, faces = triangles[0], triangles[1]
    if len(faces) > MAX_COLLISION_TRIANGLES:
        return f"{len(faces)} triangles, more than {MAX_COLLISION_TRIANGLES}"
    import numpy as np

    return (np.asarray(vertices, dtype=np.float64).reshape(-1, 3) * unit,
            np.asarray(faces, dtype=np.int64).reshape(-1, 3))


# larger meshes, and archives, are parsed in the sandboxed reader in every mode (go1's 28 MB
# trunk.dae, 351k faces, takes 2.8 s: real meshes this size stay in-process with --trusted)
IN_PROCESS_BYTES = 32 << 20


def _large(path: Path) -> bool:
    """Parsing this mesh may take many seconds and gigabytes (32 MB of OBJ text is ~4M
    faces)."""
    try:
        return path.suffix.lower() in (".zae", ".3mf") or path.stat().st_size > IN_PROCESS_BYTES
    except OSError:
        return False


def _one_line(text: str) -> str:
    lines = [line.strip() for line in str(text).strip().splitlines() if line.strip()]
    return lines[0] if lines else "unknown error"


class _LibraryLog:
    """While a mesh is read, what trimesh and pycollada log (warnings with tracebacks, on a
    logger Python would otherwise print to stderr) is kept here instead: the first line of the
    first message becomes the cause of a load error; messages about a mesh that loads
    (textures, materials, normals the checks never read) are dropped."""

    LOGGERS = ("trimesh", "collada", "PIL")

    def __enter__(self):
        import logging

        class Keep(logging.Handler):
            def emit(handler, record):  # "handler": self is the _LibraryLog
                try:
                    self.messages.append(_one_line(record.getMessage()))
                except Exception:  # noqa: BLE001 - a message that cannot be formatted
                    self.messages.append(record.msg if isinstance(record.msg, str) else "")

        self.messages: list[str] = []
        self.handler = Keep(logging.WARNING)
        self.saved = []
        for name in self.LOGGERS:
            logger = logging.getLogger(name)
            self.saved.append((logger, logger.propagate))
            logger.addHandler(self.handler)
            logger.propagate = False
        return self

    def __exit__(self, *exc):
        for logger, propagate in self.saved:
            logger.removeHandler(self.handler)
            logger.propagate = propagate
        return False

    def cause(self) -> str:
        return f" ({self.messages[0]})" if self.messages and self.messages[0] else ""


class TooLarge(Exception):
    pass


def _check_size(path: Path) -> None:
    """Refuse, before parsing, a file over MAX_MESH_BYTES and an archive (.zae, .3mf) whose
    members unpack to more (the sizes its directory declares: Python's zipfile stops at them)."""
    size = path.stat().st_size
    if size > MAX_MESH_BYTES:
        raise TooLarge(f"{size >> 20} MB, larger than the {MAX_MESH_BYTES >> 20} MB urdftool "
                       "reads")
    if path.suffix.lower() in (".zae", ".3mf"):
        import zipfile

        with zipfile.ZipFile(path) as archive:
            unpacked = sum(member.file_size for member in archive.infolist())
        if unpacked > MAX_MESH_BYTES:
            raise TooLarge(f"unpacks to {unpacked >> 20} MB, more than the "
                           f"{MAX_MESH_BYTES >> 20} MB urdftool reads")


def _read(path: Path):
    """(vertices, faces, the trimesh mesh or None) of the file's triangles as one mesh (scene
    graph transforms applied), without merging vertices and without reading textures (trimesh
    is given the bytes, not the file: it finds no image beside them to decode, which made a
    tenth of the time of reading a DAE); None when it has no triangles."""
    if path.suffix.lower() == ".stl":
        stl = _binary_stl(path)
        if stl is not None:
            return (*stl, None)
    data = _file_bytes(path)
    file_type = path.suffix.lower().lstrip(".")
    if file_type == "dae":
        data = _without_lead(data)
        found = _collada_triangles(data)
        if found is not None:
            return (*found, None) if len(found[1]) else None
    try:
        mesh = _trimesh_load(data, file_type)
    except ImportError:
        raise
    except Exception as exc:
        recovered = _recovered_xml(data) if file_type == "dae" else None
        if recovered is None:
            raise Refused(_reader(file_type), exc) from exc
        data = recovered  # what assimp's lenient XML reader reads
        try:
            mesh = _trimesh_load(data, file_type)
        except ImportError:
            raise
        except Exception as again:
            raise Refused(_reader(file_type), again, lenient=True) from again
    if _empty(mesh) and file_type == "dae":
        mesh = _load_collada_geometry_only(data)
    return None if _empty(mesh) else (mesh.vertices, mesh.faces, mesh)


class _Unsupported(Exception):
    """Something the fast COLLADA reader leaves to pycollada (through trimesh)."""


def _collada_triangles(data: bytes):
    """(vertices, faces) of a COLLADA document's triangles as trimesh reads them through
    pycollada (``trimesh.exchange.dae``: the <triangles>, <polylist> and <polygons> of every
    <instance_geometry> of the scene's nodes, placed by the nodes' transforms, polygons as fans
    from their first corner, one vertex per corner, positions as float32 like pycollada), read
    with lxml and numpy only: no normals, texture coordinates or materials parsed, no trimesh
    objects made (they were most of the time of reading a large COLLADA file). No triangles
    (empty arrays) when its scene's nodes place none (PR2's convex/*.dae: a node without
    geometry; pycollada took 21 ms each to say so). None when the
    document holds something this reader leaves to pycollada (controllers, strips, a
    transform it does not know, a broken reference...) or is not well-formed: the caller then
    reads it through trimesh, which also reports what is wrong."""
    import numpy as np
    from lxml import etree

    from urdftool.xmlrepair import secure_parser

    try:
        root = etree.fromstring(data, secure_parser(huge_text=True))  # arrays over 10 MB
        ids = {}
        for element in root.iterfind(".//*[@id]"):
            ids.setdefault(element.get("id"), element)
        scene = _child(root, "scene")
        instance = _child(scene, "instance_visual_scene") if scene is not None else None
        visual = _ref(ids, instance.get("url")) if instance is not None else None
        if visual is None:
            return None
        parts: list = []
        stack = [(node, np.eye(4)) for node in _children(visual, "node")][::-1]
        seen = 0
        while stack:
            node, parent = stack.pop()
            seen += 1
            if seen > 100_000:
                raise _Unsupported("too many nodes")
            matrix = _product(parent, _node_matrix(node))
            children = []
            for child in node:
                tag = _local(child)
                if tag == "node":
                    children.append((child, matrix))
                elif tag == "instance_node":
                    target = _ref(ids, child.get("url"))
                    if target is None:
                        raise _Unsupported("broken instance_node")
                    children.append((target, matrix))
                elif tag == "instance_geometry":
                    geometry = _ref(ids, child.get("url"))
                    if geometry is None:
                        raise _Unsupported("broken instance_geometry")
                    parts.extend((_placed(points, matrix), triangles)
                                 for points, triangles in _geometry_corners(ids, geometry))
                elif tag in ("instance_controller",):
                    raise _Unsupported(tag)
            stack.extend(reversed(children))
    except (_Unsupported, etree.XMLSyntaxError, ValueError, IndexError, TypeError):
        return None
    parts = [(points, triangles) for points, triangles in parts if len(triangles)]
    if not parts:  # the whole scene read: pycollada would find no triangles either
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    offsets = np.cumsum([0] + [len(points) for points, _ in parts])
    vertices = np.concatenate([points for points, _ in parts])
    faces = np.concatenate([triangles + offset for (_, triangles), offset in zip(parts, offsets)])
    return vertices, faces


def _placed(points, matrix):
    """``points`` (n x 3) transformed by a 4 x 4 matrix, element by element (a BLAS product of
    this shape costs more, in CPU of its threads, than the arithmetic)."""
    if (matrix == _EYE4).all():
        return points
    x, y, z = points[:, 0], points[:, 1], points[:, 2]
    import numpy as np

    return np.stack([matrix[k, 0] * x + matrix[k, 1] * y + matrix[k, 2] * z + matrix[k, 3]
                     for k in range(3)], axis=1)


_EYE4 = ((1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0), (0.0, 0.0, 0.0, 1.0))


def _local(element) -> str:
    tag = element.tag
    return tag.rpartition("}")[2] if isinstance(tag, str) else ""


def _child(element, name: str):
    return next((c for c in element if _local(c) == name), None)


def _children(element, name: str) -> list:
    return [c for c in element if _local(c) == name]


def _ref(ids: dict, url: str | None):
    return ids.get(url[1:]) if url and url.startswith("#") else None


def _numbers(element, dtype="float32"):
    """An element's text as numbers (numpy's C parser, as pycollada reads them); a text it
    cannot read to its end is left to pycollada."""
    import numpy as np

    text = (element.text or "") if element is not None else ""
    if not text.strip():
        return np.zeros(0, dtype)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # "string or file could not be read to its end"
        try:
            return np.fromstring(text, dtype=dtype, sep=" ")
        except (DeprecationWarning, ValueError) as exc:
            raise _Unsupported("numbers") from exc


def _node_matrix(node):
    """A node's transform: its <matrix>, <translate>, <rotate> and <scale> elements composed
    in document order (float32 values, as pycollada reads them)."""
    import numpy as np

    matrix = np.eye(4)
    for element in node:
        tag = _local(element)
        if tag not in ("matrix", "translate", "rotate", "scale", "lookat", "skew"):
            continue
        if tag in ("lookat", "skew"):
            raise _Unsupported(tag)
        values = _numbers(element).astype(float)
        step = np.eye(4)
        if tag == "matrix":
            if len(values) != 16:
                raise _Unsupported("matrix")
            step = values.reshape(4, 4)
        elif tag == "translate":
            if len(values) != 3:
                raise _Unsupported("translate")
            step[:3, 3] = values
        elif tag == "scale":
            if len(values) != 3:
                raise _Unsupported("scale")
            step[:3, :3] = np.diag(values)
        else:
            if len(values) != 4:
                raise _Unsupported("rotate")
            step[:3, :3] = _axis_angle(values[:3], math.radians(values[3]))
        matrix = _product(matrix, step)
    return matrix


def _product(a, b):
    """The 4 x 4 product without BLAS (see ``_placed``)."""
    return (a[:, :, None] * b[None, :, :]).sum(axis=1)


def _axis_angle(axis, angle: float):
    import numpy as np

    norm = float(np.linalg.norm(axis))
    if norm == 0:
        return np.eye(3)
    x, y, z = axis / norm
    c, s, t = math.cos(angle), math.sin(angle), 1 - math.cos(angle)
    return np.array([[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
                     [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
                     [t * x * z - s * y, t * y * z + s * x, t * z * z + c]])


def _geometry_corners(ids: dict, geometry) -> list:
    """The triangles of a <geometry>'s <mesh>: (positions used, n x 3 floats; triangles,
    m x 3 indices into them) for each primitive."""
    import numpy as np

    mesh = _child(geometry, "mesh")
    if mesh is None:
        if _child(geometry, "convex_mesh") is not None or _child(geometry, "spline") is not None:
            raise _Unsupported("not a <mesh>")
        return []
    found = []
    for primitive in mesh:
        tag = _local(primitive)
        if tag in ("lines", "linestrips", "source", "vertices", "extra") or not tag:
            continue
        if tag not in ("triangles", "polylist", "polygons"):
            raise _Unsupported(tag)
        inputs = _children(primitive, "input")
        if not inputs:
            continue
        stride = 1 + max(int(i.get("offset") or 0) for i in inputs)
        vertex = next((i for i in inputs if i.get("semantic") == "VERTEX"), None)
        if vertex is None:
            continue  # pycollada: no vertex, nothing drawn
        positions = _positions(ids, vertex.get("source"))
        offset = int(vertex.get("offset") or 0)
        if tag == "polygons":
            if _children(primitive, "ph"):
                raise _Unsupported("polygon holes")
            polygons = [_numbers(p, "int64") for p in _children(primitive, "p")]
            counts = np.array([len(p) // stride for p in polygons], dtype=np.int64)
            index = np.concatenate(polygons) if polygons else np.zeros(0, np.int64)
        else:
            index = _numbers(_child(primitive, "p"), "int64")
            counts = None
            if tag == "polylist":
                counts = _numbers(_child(primitive, "vcount"), "int64")
        if len(index) % stride:
            raise _Unsupported("index count")
        corners = index.reshape(-1, stride)[:, offset]
        if counts is None:
            if len(corners) % 3:
                raise _Unsupported("triangle count")
            triangles = corners.reshape(-1, 3)
        else:
            if counts.sum() != len(corners) or (counts < 3).any():
                raise _Unsupported("polygon counts")
            triangles = _fans(corners, counts)
        if len(triangles) and (triangles.min() < 0 or triangles.max() >= len(positions)):
            raise _Unsupported("index out of range")
        # the positions the triangles use (a hull of every position would count unused ones)
        used = np.zeros(len(positions), dtype=bool)
        used[triangles.ravel()] = True
        renumber = np.cumsum(used) - 1
        found.append((positions[used].astype(float), renumber[triangles]))
    return found


def _fans(corners, counts):
    """Triangles (first, i, i + 1) of polygons given as runs of ``counts`` corners (what
    pycollada's ``Polylist.triangleset`` makes)."""
    import numpy as np

    starts = np.concatenate(([0], np.cumsum(counts)[:-1]))
    per = counts - 2
    first = np.repeat(starts, per)
    step = np.arange(int(per.sum())) - np.repeat(np.cumsum(per) - per, per) + 1
    return np.stack([corners[first], corners[first + step], corners[first + step + 1]], axis=1)


def _positions(ids: dict, url: str | None):
    """The POSITION source of a <vertices> element: (n, 3) float32, its accessor's stride."""
    vertices = _ref(ids, url)
    if vertices is None:
        raise _Unsupported("broken VERTEX source")
    if _local(vertices) == "source":
        source = vertices
    else:
        position = next((i for i in _children(vertices, "input")
                         if i.get("semantic") == "POSITION"), None)
        source = _ref(ids, position.get("source")) if position is not None else None
    if source is None:
        raise _Unsupported("no POSITION source")
    values = _numbers(_child(source, "float_array"))
    technique = _child(source, "technique_common")
    accessor = _child(technique, "accessor") if technique is not None else None
    stride = int(accessor.get("stride") or 1) if accessor is not None else 3
    if stride < 3 or len(values) % stride:
        raise _Unsupported("position stride")
    return values.reshape(-1, stride)[:, :3]


def _trimesh_load(data: bytes, file_type: str):
    import io

    import trimesh

    try:
        return trimesh.load(io.BytesIO(data), file_type=file_type, force="mesh", process=False,
                            skip_materials=True)
    except ImportError:  # joining a scene copies its textures, which needs Pillow
        return _geometry_only(trimesh.load(io.BytesIO(data), file_type=file_type,
                                           force="scene", process=False, skip_materials=True))


def _reader(file_type: str) -> str:
    return "pycollada (trimesh's COLLADA reader)" if file_type in ("dae", "zae") else "trimesh"


# the start of an error of a COLLADA file that is XML (read in recover mode) which pycollada
# still refuses: RViz and Gazebo read COLLADA with other readers (assimp's, Gazebo's own) that
# may well display it, so it is not an error (``mesh.unreadable`` grades it)
LENIENT = "an XML document the ROS tools' lenient readers may display; "


class Refused(Exception):
    """A reader refused the file: its message names the reader, and the library's exception
    without repeating its class name (pycollada's messages start with it)."""

    def __init__(self, reader: str, exc: Exception, lenient: bool = False):
        super().__init__((LENIENT if lenient else "") + f"{reader} refused it: "
                         + exception_text(exc))


def _without_lead(data: bytes) -> bytes:
    """A COLLADA file's bytes without the byte-order mark and white space before its XML
    declaration (which a strict XML parser refuses and assimp's reader skips)."""
    head = data[:4096]
    start = head.lstrip()
    if start.startswith(b"\xef\xbb\xbf"):
        start = start[3:].lstrip()
    if not start.startswith(b"<") or len(start) == len(head):
        return data
    return data[len(head) - len(start):]


def _recovered_xml(data: bytes) -> bytes | None:
    """The document lxml reads in recover mode (an attribute holding '<', as in an exporter's
    ``<node id="<STL_BINARY>">``, an unclosed tag...), written again as well-formed XML; None
    when no <COLLADA> document is left (not XML at all: no reader displays it)."""
    from lxml import etree

    from urdftool.xmlrepair import secure_parser

    try:
        root = etree.fromstring(data, secure_parser(recover=True))
    except (etree.XMLSyntaxError, ValueError):
        return None
    if root is None or not isinstance(root.tag, str) or etree.QName(root).localname != "COLLADA":
        return None
    return etree.tostring(root, xml_declaration=True, encoding="utf-8")


_STL_RECORD = [("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")]


def _binary_stl(path: Path):
    """(vertices, faces) of a binary STL (an 80-byte header, a triangle count, 50-byte
    records) read directly: 3x faster than trimesh's loader, with the same vertices
    (float32 corners, unmerged). None for anything else (ASCII STL, a wrong length, no
    triangles): trimesh then reads or rejects it."""
    import numpy as np

    data = _file_bytes(path)
    count = int.from_bytes(data[80:84], "little") if len(data) >= 84 else 0
    if count == 0 or len(data) != 84 + 50 * count:
        return None
    records = np.frombuffer(data, dtype=np.dtype(_STL_RECORD), count=count, offset=84)
    return records["vertices"].reshape(-1, 3), np.arange(3 * count).reshape(-1, 3)


def _empty(mesh) -> bool:
    import trimesh

    return not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0


def _geometry_only(scene):
    """A scene's meshes placed by its graph and joined into one mesh, as trimesh's
    ``Scene.to_mesh`` joins them, without copying their materials: copying a texture needs
    Pillow, an optional library the checks do not need. Texture coordinates are kept, so
    vertices are merged as trimesh merges them when it joins the scene itself."""
    import numpy as np
    import trimesh

    vertices, faces, uvs, offset = [], [], [], 0
    for node in scene.graph.nodes_geometry:
        transform, name = scene.graph[node]
        part = scene.geometry.get(name)
        if not isinstance(part, trimesh.Trimesh) or len(part.faces) == 0:
            continue
        points = np.asarray(part.vertices, dtype=float)
        vertices.append(points @ transform[:3, :3].T + transform[:3, 3])
        faces.append(np.asarray(part.faces) + offset)
        uv = getattr(part.visual, "uv", None) if part.visual.kind == "texture" else None
        uvs.append(None if uv is None or len(uv) != len(points) else np.asarray(uv))
        offset += len(points)
    if not faces:
        return None
    visual = None
    if all(uv is not None for uv in uvs):
        visual = trimesh.visual.TextureVisuals(uv=np.vstack(uvs))
    return trimesh.Trimesh(np.vstack(vertices), np.vstack(faces), visual=visual, process=False)


def _load_collada_geometry_only(data: bytes):
    """pycollada drops a node whose <bind_material> names a missing material or texture (the
    node's geometry then vanishes); rviz and Gazebo still draw it. Materials do not matter
    here: read the file again without them."""
    import io

    import trimesh

    data = _without_elements(data, b"bind_material")
    return trimesh.load(io.BytesIO(data), file_type="dae", force="mesh", process=False)


def _without_elements(data: bytes, name: bytes) -> bytes:
    """``data`` without its ``<name>...</name>`` elements (``str.find``: linear; an unclosed
    one is left)."""
    opener, closer = b"<" + name + b">", b"</" + name + b">"
    pieces, position = [], 0
    while True:
        start = data.find(opener, position)
        end = data.find(closer, start) if start >= 0 else -1
        if end < 0:
            pieces.append(data[position:])
            return b"".join(pieces)
        pieces.append(data[position:start])
        position = end + len(closer)


def _solid(points, faces=None, inside_out: bool = False) -> Solid | None:
    """The unit-density solid a closed surface of triangles bounds: volume, centroid and second
    moments about it, by Eberly's polyhedral mass properties (what trimesh's
    ``triangles.mass_properties`` computes, in a third of its time: no cross-product helper, no
    stacked subexpressions, no tensor shifted and turned back). The triangles are ``points``
    (n x 3 x 3), or ``faces`` (m x 3 indices) into ``points`` (n x 3): their corners are then
    taken from contiguous coordinate columns (the arithmetic on strided n x 3 x 3 views took
    twice as long). ``inside_out``: a surface wound inward bounds the same body (its negative
    volume made positive, every moment negated with it, exactly). None when it bounds no
    volume."""
    import numpy as np

    if faces is None:
        t = np.asarray(points, dtype=float)
        x0, y0, z0 = t[:, 0, 0], t[:, 0, 1], t[:, 0, 2]
        x1, y1, z1 = t[:, 1, 0], t[:, 1, 1], t[:, 1, 2]
        x2, y2, z2 = t[:, 2, 0], t[:, 2, 1], t[:, 2, 2]
    else:
        columns = [np.ascontiguousarray(points[:, k], dtype=float) for k in range(3)]
        corners = [np.ascontiguousarray(faces[:, k]) for k in range(3)]
        (x0, y0, z0), (x1, y1, z1), (x2, y2, z2) = (
            [column[corner] for column in columns] for corner in corners)
    ax, ay, az, bx, by, bz = x1 - x0, y1 - y0, z1 - z0, x2 - x0, y2 - y0, z2 - z0
    dx, dy, dz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx

    def terms(w0, w1, w2):
        t0 = w0 + w1
        f1 = t0 + w2
        t1 = w0 * w0
        t2 = t1 + w1 * t0
        f2 = t2 + w2 * f1
        f3 = w0 * t1 + w1 * t2 + w2 * f2
        return f1, f2, f3, f2 + w0 * (f1 + w0), f2 + w1 * (f1 + w1), f2 + w2 * (f1 + w2)

    f1x, f2x, f3x, g0x, g1x, g2x = terms(x0, x1, x2)
    _, f2y, f3y, g0y, g1y, g2y = terms(y0, y1, y2)
    _, f2z, f3z, g0z, g1z, g2z = terms(z0, z1, z2)
    volume = float((dx * f1x).sum()) / 6
    sign = 1.0 if volume > 0 or not inside_out else -1.0
    volume *= sign
    if not volume > 0:
        return None
    first = [sign * float((d * f).sum()) / 24 for d, f in ((dx, f2x), (dy, f2y), (dz, f2z))]
    xx, yy, zz = (sign * float((d * f).sum()) / 60 for d, f in ((dx, f3x), (dy, f3y), (dz, f3z)))
    xy = sign * float((dx * (y0 * g0x + y1 * g1x + y2 * g2x)).sum()) / 120
    yz = sign * float((dy * (z0 * g0y + z1 * g1y + z2 * g2y)).sum()) / 120
    zx = sign * float((dz * (x0 * g0z + x1 * g1z + x2 * g2z)).sum()) / 120
    c = tuple(f / volume for f in first)
    about_origin = ((xx, xy, zx), (xy, yy, yz), (zx, yz, zz))
    second = tuple(tuple(about_origin[i][j] - volume * c[i] * c[j] for j in range(3))
                   for i in range(3))
    return Solid(volume, c, second)  # type: ignore[arg-type]


def _distinct(vertices):
    """(the distinct rows of ``vertices`` in order of first occurrence, each row's index among
    them), by bitwise equality (-0.0 and 0.0 apart). An STL repeats each corner ~6 times: qhull
    then takes half the time, and the hull is the same point set (support values agree to 1e-16
    on the corpus; only the order of the points, and so of qhull's work, changes)."""
    import numpy as np

    rows = np.ascontiguousarray(vertices, dtype=np.float64).view(np.int64)
    member, group = _grouped(rows, last=False)
    return vertices[member], group


def _merged(vertices):
    """(one vertex of each group of vertices equal to 8 decimals, in order of the groups' first
    occurrence; each vertex's group): trimesh's ``merge_vertices`` by position (``tol.merge``;
    it keeps the first of a group, here the last, within 1e-8 of it)."""
    import numpy as np

    if not np.isfinite(vertices).all() or max(vertices.max(), -vertices.min()) > 1e10:
        return _distinct(vertices)  # rounding would overflow: bitwise equality then
    member, group = _grouped(np.round(vertices * 1e8).astype(np.int64), last=True)
    return vertices[member], group


def _grouped(rows, last: bool):
    """(one row index per group of equal rows of ``rows`` (n x 3 int64): the first or the
    ``last`` of its group; each row's group), the groups numbered in order of first occurrence.

    One sort of n 64-bit words, each a row's hash in its high bits and the row's index in its
    low bits (numpy's vectorised sort of plain integers: a few times faster than the argsort
    ``np.unique`` makes for its inverse); rows of one group are then adjacent and in index
    order. Equal hashes of different rows are found by comparing the rows (then ``np.unique``
    over the rows, exactly)."""
    import numpy as np

    count = len(rows)
    bits = max(1, (count - 1).bit_length())
    if count == 0 or bits > 31:
        return _grouped_exactly(rows, last)
    low = np.uint64((1 << bits) - 1)
    words = np.sort((_row_keys(rows) & ~low) | np.arange(count, dtype=np.uint64))
    order = (words & low).astype(np.intp)  # row indices, group after group
    starts = np.empty(count, dtype=bool)  # where a group starts in ``order``
    starts[0] = True
    np.not_equal(words[1:] & ~low, words[:-1] & ~low, out=starts[1:])
    rank = np.cumsum(starts) - 1  # the group of each position of ``order`` (in hash order)
    begin = np.flatnonzero(starts)
    first = order[begin]
    if not np.array_equal(rows[order], rows[first[rank]]):  # two rows' hashes collide
        return _grouped_exactly(rows, last)
    # number the groups by first occurrence: one more sort, of (first index, group) words
    groups = len(first)
    by_first = (np.sort((first.astype(np.uint64) << np.uint64(bits)) |
                        np.arange(groups, dtype=np.uint64)) & low).astype(np.intp)
    renumber = np.empty(groups, dtype=np.intp)
    renumber[by_first] = np.arange(groups)
    group = np.empty(count, dtype=np.intp)
    group[order] = renumber[rank]
    chosen = order[np.append(begin[1:], count) - 1] if last else first
    return chosen[by_first], group


def _grouped_exactly(rows, last: bool):
    """``_grouped`` by ``np.unique`` over the rows (no hash)."""
    import numpy as np

    _, first, group = np.unique(rows, axis=0, return_index=True, return_inverse=True)
    group = group.ravel()
    by_first = np.argsort(first, kind="stable")
    renumber = np.empty(len(first), dtype=np.intp)
    renumber[by_first] = np.arange(len(first))
    if last:
        chosen = np.empty(len(first), dtype=np.intp)
        chosen[group] = np.arange(len(group))  # the last assignment of each group stays
    else:
        chosen = first
    return chosen[by_first], renumber[group]


def _closed(faces) -> bool:
    """Whether the triangles ``faces`` (indices of merged vertices) make a closed, consistently
    wound surface, as trimesh's ``is_watertight and is_winding_consistent`` say: every edge
    shared by exactly two faces, which run it in opposite directions. Two sorts of integer
    keys, no trimesh object (its construction, vertex merging and cache hashing were a third
    of the time of reading a large mesh)."""
    import numpy as np

    edges = faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    if len(edges) == 0:
        return False
    count = int(faces.max()) + 1
    start, end = edges[:, 0], edges[:, 1]
    low, high = np.minimum(start, end), np.maximum(start, end)
    if len(edges) % 2:
        return False
    if (start != end).all():  # one sort: each edge's key and, in its lowest bit, its direction
        keys = np.sort((low * count + high) * 2 + (start > end)).reshape(-1, 2)
        return bool((keys[:, 0] >> 1 == keys[:, 1] >> 1).all() and
                    not (keys[1:, 0] >> 1 == keys[:-1, 1] >> 1).any() and
                    (keys[:, 1] - keys[:, 0] == 1).all())  # the two run opposite ways
    pairs = np.sort(low * count + high)
    pairs = pairs.reshape(-1, 2)
    if not (pairs[:, 0] == pairs[:, 1]).all() or (pairs[1:, 0] == pairs[:-1, 1]).any():
        return False
    # each edge twice: opposite directions unless a face runs one the same way as the other
    # (an edge from a vertex to itself, in a degenerate face, has no direction: trimesh lets
    # it pass)
    proper = edges[:, 0] != edges[:, 1]
    directed = np.sort(edges[proper, 0] * count + edges[proper, 1])
    return not (directed[1:] == directed[:-1]).any()


def _row_keys(rows):
    """One uint64 per row of three 64-bit integers: a multiply-xorshift hash of the rows'
    bits (collisions are checked by the caller; an earlier XOR of three products made
    (-a, -b, 0) and (a, b, 0) collide, which sent a third of real meshes to the slow path)."""
    import numpy as np

    bits = np.ascontiguousarray(rows).view(np.uint64)
    shift = np.uint64(31)
    key = bits[:, 0] * np.uint64(0x9E3779B97F4A7C15)
    key ^= key >> shift
    key += bits[:, 1]
    key *= np.uint64(0xC2B2AE3D27D4EB4F)
    key ^= key >> shift
    key += bits[:, 2]
    key *= np.uint64(0x165667B19E3779F9)
    key ^= key >> shift
    return key


# scipy's extension modules the hull needs, loaded alone (``_qhull``): (package, module)
_QHULL_MODULES = (("scipy.linalg", "cython_lapack"), ("scipy.spatial", "_qhull"))


def _qhull():
    """scipy's qhull module (``ConvexHull``, ``QhullError``), loaded without the packages around
    it when they are not imported yet: ``scipy.spatial``'s ``__init__`` imports the k-d tree,
    scipy.sparse, distances and rotations, and ``scipy.linalg``'s (which qhull's LAPACK
    routines come from, ``cython_lapack``) imports numpy.f2py through scipy's array API layer:
    0.49 s of CPU against 0.02 s for the two extension modules alone, paid by every process
    that reads a mesh cold, each sandboxed reader included. The modules are scipy's own,
    registered under their own names, so that a later ``import scipy.spatial`` or
    ``scipy.linalg`` takes them as they are; on any surprise (another scipy layout)
    ``scipy.spatial`` is imported. Loaded once, under a lock (threads of the language server:
    none may take a module still being loaded)."""
    global _QHULL
    if _QHULL is None:
        with _QHULL_LOCK:
            if _QHULL is None:
                _QHULL = _load_qhull()
    for package, name in _QHULL_MODULES:  # a package imported after its module was alone
        parent = sys.modules.get(package)
        if parent is not None and not hasattr(parent, name) and \
                f"{package}.{name}" in sys.modules:
            setattr(parent, name, sys.modules[f"{package}.{name}"])
    return _QHULL


_QHULL = None
_QHULL_LOCK = threading.Lock()


def _load_qhull():
    """``_qhull``'s loading."""
    module = sys.modules.get("scipy.spatial._qhull")
    if module is not None:
        return module
    import scipy  # an ImportError here: scipy is missing (mesh.not-checked names it)

    if "scipy.spatial" not in sys.modules:
        import importlib.machinery
        import importlib.util

        added = []
        try:
            for package, name in _QHULL_MODULES:
                full = f"{package}.{name}"
                if package in sys.modules or full in sys.modules:
                    continue
                finder = importlib.machinery.FileFinder(
                    os.path.join(os.path.dirname(scipy.__file__), package.split(".")[1]),
                    (importlib.machinery.ExtensionFileLoader,
                     importlib.machinery.EXTENSION_SUFFIXES))
                spec = finder.find_spec(full)
                module = importlib.util.module_from_spec(spec)
                sys.modules[full] = module
                added.append(full)
                spec.loader.exec_module(module)
            module = sys.modules["scipy.spatial._qhull"]
        except Exception:  # noqa: BLE001 - any other layout: the package's own import below
            module = None
        if module is not None and hasattr(module, "ConvexHull") and \
                hasattr(module, "QhullError"):
            return module
        for full in added:
            sys.modules.pop(full, None)
    import scipy.spatial

    return scipy.spatial


def _hull(vertices):
    """(hull vertices, oriented hull triangles) by qhull; (unique vertices, None) when the
    points span no volume (a flat or degenerate mesh)."""
    import numpy as np

    qhull = _qhull()
    try:
        hull = qhull.ConvexHull(vertices)
    except (qhull.QhullError, ValueError):
        return np.unique(vertices, axis=0), None
    triangles = vertices[hull.simplices]
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    flip = np.einsum("ij,ij->i", normals, hull.equations[:, :3]) < 0
    triangles[flip] = triangles[flip][:, ::-1]
    # the vertices of its triangles in input order: scipy's ``hull.vertices`` (np.unique of
    # the triangles, a hash table and a sort) as a mask
    used = np.zeros(len(vertices), dtype=bool)
    used[hull.simplices] = True
    return vertices[used], triangles


def _summarise(path: Path, vertices, faces, mesh, need_volume: bool) -> MeshInfo:
    """The summary of a file's triangles; ``mesh`` is trimesh's (with what it read beside the
    triangles), or None when the file was read directly."""
    import numpy as np

    unit = _collada_unit(path)
    vertices = np.asarray(vertices, dtype=float) * unit
    faces = np.asarray(faces)
    # column by column: numpy's min(axis=0) of an n x 3 array is 4x slower than three
    columns = [vertices[:, k] for k in range(3)]
    lower = tuple(float(c.min()) for c in columns)
    upper = tuple(float(c.max()) for c in columns)
    # a hull needs distinct points; the volume, vertices merged as trimesh merges them (the
    # hull of their first points is the same to 1e-8 m)
    merge = need_volume and mesh is None
    points, index = _merged(vertices) if merge else _distinct(vertices)
    hull_points, hull_triangles = _hull(points)
    flat = array("d")
    flat.frombytes(np.ascontiguousarray(hull_points, dtype=np.float64).tobytes())
    info = {"path": str(path), "flat": flat, "lower": lower, "upper": upper,
            "faces": len(faces)}
    if not need_volume:
        return MeshInfo(**info)  # type: ignore[arg-type]
    if merge:  # no texture coordinates to keep apart: merged by position alone
        merged = index[faces]
        watertight, corners, triangles = _closed(merged), points, merged
    else:
        mesh.vertices = vertices
        mesh.merge_vertices()  # STL repeats every vertex: merge before asking about topology
        watertight = bool(mesh.is_watertight) and bool(mesh.is_winding_consistent)
        corners, triangles = mesh.triangles, None
    solid = None
    if watertight:  # (wound inside-out: the same body)
        solid = _solid(corners, triangles, inside_out=True)
    used_hull = solid is None
    if used_hull and hull_triangles is not None:
        solid = _solid(hull_triangles)
    return MeshInfo(**info, has_volume=True, solid=solid, watertight=watertight,  # type: ignore[arg-type]
                    used_hull=used_hull)


# hulls with more vertices are placed and queried with numpy: above ``VECTOR_POINTS``, or
# above ``VECTOR_POINTS_LOADED`` once numpy is imported (a run over many meshes: its arrays
# are then cheaper than Python's loops from a few dozen vertices on; a check of one small
# robot need not import it)
VECTOR_POINTS = 128
VECTOR_POINTS_LOADED = 24


def _columns(info: MeshInfo):
    """The hull's (x, y, z) columns as float64 arrays, made once per mesh summary."""
    columns = _COLUMNS.get(id(info))
    if columns is None or columns[0] is not info:
        import numpy as np

        points = np.frombuffer(info.flat, dtype=np.float64).reshape(-1, 3)
        columns = _COLUMNS[id(info)] = (info, points[:, 0].copy(), points[:, 1].copy(),
                                        points[:, 2].copy())
    return columns[1:]


_COLUMNS: dict[int, tuple] = {}  # id(MeshInfo) -> (the info, its hull's columns)


class MeshExtent(Extent):
    """A mesh's convex hull placed in the link frame (scale, then rotation and translation).
    Plain Python over a small hull (a run whose meshes all
    come from the persistent cache and are small imports no numpy); numpy over one of more than
    ``VECTOR_POINTS`` vertices, with the same arithmetic element by element (the same floats,
    the same vertex chosen among equals)."""

    def __init__(self, info: MeshInfo, scale: Vec3, rotation: Mat3, translation: Vec3):
        super().__init__(rotation, translation)
        count = info.hull_size
        sx, sy, sz = scale
        (a, b, c), (d, e, f), (g, h, i) = rotation
        tx, ty, tz = translation
        self.columns = None
        if count > (VECTOR_POINTS_LOADED if "numpy" in sys.modules else VECTOR_POINTS):
            x, y, z = _columns(info)
            x, y, z = x * sx, y * sy, z * sz
            self.columns = (a * x + b * y + c * z + tx, d * x + e * y + f * z + ty,
                            g * x + h * y + i * z + tz)
            self.points = None
            return
        points = []
        for x, y, z in info.hull:
            x, y, z = x * sx, y * sy, z * sz
            points.append((a * x + b * y + c * z + tx, d * x + e * y + f * z + ty,
                           g * x + h * y + i * z + tz))
        self.points = points

    def support(self, direction: Vec3) -> Vec3:
        """The vertex farthest along ``direction`` (the first of equals; the first whose
        projection is nan, as numpy's argmax: a mesh of nan vertices stays nan)."""
        dx, dy, dz = direction
        if self.columns is not None:
            x, y, z = self.columns
            k = int((x * dx + y * dy + z * dz).argmax())
            return (float(x[k]), float(y[k]), float(z[k]))
        best, found = -math.inf, self.points[0]
        for p in self.points:
            value = p[0] * dx + p[1] * dy + p[2] * dz
            if value > best:
                best, found = value, p
            elif math.isnan(value):
                return p
        return found

    def max_sq_distance(self, origin: Vec3, axis: Vec3) -> float:
        return self.max_sq_distances(origin, [axis])[0]

    def max_sq_distances(self, origin: Vec3, axes: list[Vec3]) -> list[float]:
        """The largest squared distance of a hull vertex from the line (origin, unit axis),
        for each axis (each vertex's offset and its squared length computed once); nan when
        one is nan (as numpy's max)."""
        ox, oy, oz = origin
        if self.columns is not None:
            x, y, z = self.columns
            rx, ry, rz = x - ox, y - oy, z - oz
            square = rx * rx + ry * ry + rz * rz
            result = []
            for ax, ay, az in axes:
                along = rx * ax + ry * ay + rz * az
                result.append(float((square - along * along).max()))
            return result
        best = [-math.inf] * len(axes)
        for x, y, z in self.points:
            rx, ry, rz = x - ox, y - oy, z - oz
            square = rx * rx + ry * ry + rz * rz
            for k, (ax, ay, az) in enumerate(axes):
                along = rx * ax + ry * ay + rz * az
                value = square - along * along
                if value > best[k] or math.isnan(value):  # once nan, nothing is greater
                    best[k] = value
        return best
