"""Mesh files: resolve a ``<mesh filename>``, load it with trimesh (imported here, lazily: only
when a robot has meshes) and keep what the rules need: unit-density mass properties, convex
hull vertices, extents, watertightness.

Each file is loaded once per process: ``load_mesh`` caches by resolved path (``LOADS`` counts
the real loads, for tests and benchmarks). The cache holds small summaries, not the meshes.
"""

from __future__ import annotations

import re
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


def load_mesh(path: Path | str) -> MeshInfo:
    """The summary of a mesh file, loaded once per process (cached by resolved path)."""
    key = str(Path(path).resolve())
    info = _CACHE.get(key)
    if info is None:
        info = _CACHE[key] = _load(Path(key))
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


def _load(path: Path) -> MeshInfo:
    global LOADS
    if path.suffix.lower() not in LOADABLE:
        return MeshInfo(str(path), unsupported=True)
    if not path.is_file():
        return MeshInfo(str(path), error="no such file")
    import numpy as np
    import trimesh

    LOADS += 1
    try:
        mesh = trimesh.load(str(path), force="mesh", skip_materials=True)
    except Exception as exc:  # noqa: BLE001 - any parser failure is a finding, not a crash
        return MeshInfo(str(path), error=f"{type(exc).__name__}: {exc}".strip())
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        return MeshInfo(str(path), error="no triangles in it")
    unit, up_rotation = _collada_frame(path)
    if unit != 1.0:
        mesh.apply_scale(unit)
    lower, upper = (tuple(float(x) for x in b) for b in mesh.bounds)
    watertight = bool(mesh.is_watertight)
    body, used_hull = mesh, False
    if not (watertight and mesh.is_winding_consistent):
        used_hull = True
    try:
        hull = mesh.convex_hull
        hull_points = np.asarray(hull.vertices, dtype=float)
    except Exception:  # noqa: BLE001 - flat or degenerate meshes have no 3-D hull
        hull, hull_points = None, np.asarray(mesh.vertices, dtype=float)
    if used_hull:
        body = hull
    solid = None
    if body is not None:
        props = body.mass_properties  # density 1
        volume = float(props["volume"])
        sign = 1.0 if volume >= 0 else -1.0  # closed but inside-out: same body
        if abs(volume) > 0:
            inertia = np.asarray(props["inertia"], dtype=float) * sign
            second = np.trace(inertia) / 2.0 * np.eye(3) - inertia
            solid = Solid(abs(volume), tuple(float(x) for x in props["center_mass"]),  # type: ignore[arg-type]
                          tuple(tuple(float(x) for x in row) for row in second))  # type: ignore[arg-type]
    return MeshInfo(str(path), solid=solid, watertight=watertight, used_hull=used_hull,
                    hull=hull_points, lower=lower, upper=upper, faces=len(mesh.faces),  # type: ignore[arg-type]
                    up_rotation=up_rotation)


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
