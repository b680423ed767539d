"""Mesh files: resolve a ``<mesh filename>``, load it with trimesh (imported here, lazily: only
when a robot has meshes) and keep what the rules need: unit-density mass properties, convex
hull vertices, extents, watertightness.

Each file is loaded once per process: ``load_mesh`` caches by resolved path (``LOADS`` counts
the real loads, for tests and benchmarks). The cache holds small summaries, not the meshes.
"""

from __future__ import annotations

import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path

from urdftool.physics.inertia import Extent, Mat3, Solid, Vec3, sub

# formats trimesh reads (after pycollada for DAE); others (Ogre .mesh, VTK...) are not checked
LOADABLE = {".stl", ".obj", ".dae", ".ply", ".off", ".glb", ".gltf", ".3mf", ".zae"}
_UNIT_RE = re.compile(rb"<unit\b[^>]*\bmeter\s*=\s*[\"']([^\"']+)[\"']")
_UP_RE = re.compile(rb"<up_axis>\s*([XYZ])_UP\s*</up_axis>")
# COLLADA up axis -> the rotation that makes it z (what assimp-based ROS tools do)
_UP_ROTATIONS = {b"Y": ((1.0, 0.0, 0.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0)),
                 b"X": ((0.0, 0.0, -1.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0))}

LOADS = 0  # how many files were actually read (cache misses)
_CACHE: dict[str, MeshInfo] = {}


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
    hull: object = field(default=None, repr=False)  # numpy (n, 3) convex-hull vertices
    lower: Vec3 = (0.0, 0.0, 0.0)
    upper: Vec3 = (0.0, 0.0, 0.0)
    faces: int = 0
    # a COLLADA up axis other than Z: tools disagree (rviz and DART keep the file's
    # coordinates, assimp's default and others turn the up axis to z), so both are possible
    up_rotation: Mat3 | None = None
    has_volume: bool = False  # the volume fields (solid, watertight, used_hull) are computed

    @property
    def ok(self) -> bool:
        return self.error is None and not self.unsupported

    @property
    def extents(self) -> Vec3:
        return sub(self.upper, self.lower)


def clear_cache() -> None:
    global LOADS
    _CACHE.clear()
    LOADS = 0


def trimesh_available() -> bool:
    try:
        import trimesh  # noqa: F401
    except ImportError:
        return False
    return True


def resolve(robot, geometry) -> Path | None:
    """The local path of a mesh geometry's file, or None when its URI cannot be resolved.
    Relative names are relative to the file where the ``<mesh>`` was written."""
    if not geometry.filename:
        return None
    base_dir = Path(geometry.loc.path).parent if geometry.loc is not None else Path(".")
    resolver = robot.source.resolver
    if resolver is None:
        from urdftool.packages import PackageResolver

        resolver = PackageResolver(start=Path(robot.source.path))
    uri = geometry.filename.strip()
    path = resolver.resolve_uri(uri, base_dir)
    if path is None and uri.startswith("package://"):
        path = _package_by_directory(uri, base_dir)
        roots = getattr(resolver, "confined_roots", None)
        if path is not None and roots is not None:  # --untrusted: the package roots only
            from urdftool.sandbox import REFUSED, inside

            if not inside(path, roots):
                resolved = path.resolve()
                path = REFUSED / resolved.relative_to(resolved.anchor)
    return path


def _package_by_directory(uri: str, start: Path) -> Path | None:
    """``package://NAME/...`` where NAME is a directory above the file or beside one of its
    ancestors (how pinocchio's package_dirs and ROS_PACKAGE_PATH trees are laid out, e.g.
    example-robot-data, whose package.xml names it differently)."""
    name, _, rest = uri[len("package://"):].partition("/")
    if not name:  # package:///path: tools that accept it read it as a path in some package
        name, _, rest = rest.lstrip("/").partition("/")
        if not name:
            return None
    if name == "urdftool":  # urdftool's own example meshes (used in the rule docs)
        return Path(__file__).resolve().parent.parent / rest
    directory = start.resolve()
    for ancestor in (directory, *directory.parents):
        if ancestor.name == name:
            return ancestor / rest
        if (ancestor / name).is_dir():
            return ancestor / name / rest
    return None


def load_mesh(path: Path | str, need_volume: bool = False) -> MeshInfo:
    """The summary of a mesh file, loaded once per process (cached by resolved path).

    The hull and extents are always computed; the enclosed volume and mass properties (which
    need the mesh's topology: watertightness, winding) only with ``need_volume``, for the
    meshes the inertia is derived from. An entry made without them is completed on demand
    (a second read, only for a file first met as a visual and later needed for its volume).
    """
    key = str(Path(path).resolve())
    info = _CACHE.get(key)
    if info is None or (need_volume and not info.has_volume and info.ok):
        info = _CACHE[key] = _load(Path(key), need_volume)
    return info


def _collada_frame(path: Path) -> tuple[float, Mat3 | None]:
    """COLLADA files may declare their unit (<unit meter="0.001"/>) and up axis (Y_UP): ROS
    tools (rviz, Gazebo, assimp-based loaders) honour both; trimesh does not."""
    if path.suffix.lower() != ".dae":
        return 1.0, None
    try:
        with path.open("rb") as handle:
            head = handle.read(16384)
    except OSError:
        return 1.0, None
    match = _UNIT_RE.search(head)
    try:
        unit = float(match.group(1)) if match else 1.0
    except ValueError:
        unit = 1.0
    up = _UP_RE.search(head)
    rotation = _UP_ROTATIONS.get(up.group(1)) if up else None
    return (unit if unit > 0 else 1.0), rotation


def _load(path: Path, need_volume: bool) -> MeshInfo:
    global LOADS
    if path.suffix.lower() not in LOADABLE:
        return MeshInfo(str(path), unsupported=True)
    if not path.is_file():
        return MeshInfo(str(path), error="no such file")
    import numpy as np
    import trimesh

    LOADS += 1
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            mesh = _read(path)
            if _empty(mesh) and path.suffix.lower() == ".dae":
                mesh = _load_collada_geometry_only(path)
    except Exception as exc:  # noqa: BLE001 - any parser failure is a finding, not a crash
        return MeshInfo(str(path), error=f"{type(exc).__name__}: {exc}".strip())
    if not isinstance(mesh, trimesh.Trimesh) or _empty(mesh):
        return MeshInfo(str(path), error="no triangles in it")
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        return _summarise(path, mesh, need_volume)


def _read(path: Path):
    """The file's triangles as one mesh (scene graph transforms applied), without merging
    vertices and without reading textures (an open file has no resolver for them)."""
    import trimesh

    with path.open("rb") as handle:
        return trimesh.load(handle, file_type=path.suffix.lower().lstrip("."), force="mesh",
                            process=False, skip_materials=True)


def _empty(mesh) -> bool:
    import trimesh

    return not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0


def _load_collada_geometry_only(path: Path):
    """pycollada drops a node whose <bind_material> names a missing material or texture (the
    node's geometry then vanishes); rviz and Gazebo still draw it. Materials do not matter
    here: read the file again without them."""
    import io

    import trimesh

    data = re.sub(rb"<bind_material>.*?</bind_material>", b"", path.read_bytes(), flags=re.DOTALL)
    return trimesh.load(io.BytesIO(data), file_type="dae", force="mesh", process=False)


def _solid(props, sign: float = 1.0) -> Solid | None:
    import numpy as np

    volume = float(props["volume"]) * sign
    if not volume > 0:
        return None
    inertia = np.asarray(props["inertia"], dtype=float) * sign
    second = np.trace(inertia) / 2.0 * np.eye(3) - inertia
    return Solid(volume, tuple(float(x) for x in props["center_mass"]),  # type: ignore[arg-type]
                 tuple(tuple(float(x) for x in row) for row in second))  # type: ignore[arg-type]


def _hull(vertices):
    """(hull vertices, oriented hull triangles) by qhull; (unique vertices, None) when the
    points span no volume (a flat or degenerate mesh)."""
    import numpy as np
    from scipy.spatial import ConvexHull, QhullError

    try:
        hull = ConvexHull(vertices)
    except (QhullError, ValueError):
        return np.unique(vertices, axis=0), None
    triangles = vertices[hull.simplices]
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    flip = np.einsum("ij,ij->i", normals, hull.equations[:, :3]) < 0
    triangles[flip] = triangles[flip][:, ::-1]
    return vertices[hull.vertices], triangles


def _summarise(path: Path, mesh, need_volume: bool) -> MeshInfo:
    import numpy as np
    from trimesh.triangles import mass_properties

    unit, up_rotation = _collada_frame(path)
    vertices = np.asarray(mesh.vertices, dtype=float) * unit
    faces = np.asarray(mesh.faces)
    lower = tuple(float(x) for x in vertices.min(axis=0))
    upper = tuple(float(x) for x in vertices.max(axis=0))
    hull_points, hull_triangles = _hull(vertices)
    info = {"path": str(path), "hull": hull_points, "lower": lower, "upper": upper,
            "faces": len(faces), "up_rotation": up_rotation}
    if not need_volume:
        return MeshInfo(**info)  # type: ignore[arg-type]
    mesh.vertices = vertices
    mesh.merge_vertices()  # STL repeats every vertex: merge before asking about topology
    watertight = bool(mesh.is_watertight) and bool(mesh.is_winding_consistent)
    solid = None
    if watertight:
        props = mass_properties(mesh.triangles)
        solid = _solid(props, 1.0 if props["volume"] >= 0 else -1.0)  # inside-out: same body
    used_hull = solid is None
    if used_hull and hull_triangles is not None:
        solid = _solid(mass_properties(hull_triangles))
    return MeshInfo(**info, has_volume=True, solid=solid, watertight=watertight,  # type: ignore[arg-type]
                    used_hull=used_hull)


class MeshExtent(Extent):
    """A mesh's convex hull placed in the link frame (scale, then rotation and translation).
    When the file's up axis is ambiguous, the hull of both readings (a superset: bounds and
    inside tests stay on the safe side)."""

    def __init__(self, info: MeshInfo, scale: Vec3, rotation: Mat3, translation: Vec3):
        import numpy as np

        super().__init__(rotation, translation)
        points = np.asarray(info.hull, dtype=float)
        if info.up_rotation is not None:  # either orientation: the union of both
            points = np.vstack([points, points @ np.asarray(info.up_rotation).T])
        points = points * np.asarray(scale, dtype=float)
        self.points = points @ np.asarray(rotation, dtype=float).T + np.asarray(translation)

    def support(self, direction: Vec3) -> Vec3:
        import numpy as np

        index = int(np.argmax(self.points @ np.asarray(direction, dtype=float)))
        return tuple(float(x) for x in self.points[index])  # type: ignore[return-value]

    def max_sq_distance(self, origin: Vec3, axis: Vec3) -> float:
        import numpy as np

        rel = self.points - np.asarray(origin, dtype=float)
        along = rel @ np.asarray(axis, dtype=float)
        return float(np.max(np.einsum("ij,ij->i", rel, rel) - along * along))
