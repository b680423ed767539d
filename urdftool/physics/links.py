"""Per-link inertia analysis shared by the ``inertia`` and ``mesh`` rules and the ``inertia``
command: the declared inertial, the geometry (each shape's unit-density solid and convex
extent in the link frame), the geometry-derived inertia for the declared mass, the physical
bound of the declared moments, the COM's distance from the geometry, and one verdict.

``analyse(robot)`` is computed once per robot (the rules of a run share it). Pure Python;
numpy and trimesh are imported only for meshes missing from the persistent cache.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from itertools import permutations
from pathlib import Path
from typing import NamedTuple

from urdftool import packages
from urdftool.physics import inertia as phys
from urdftool.physics.inertia import Extent, Mat3, Solid, Vec3

# thresholds (see the rule docs in urdftool/rules/inertia.py for the reasoning)
BOUND_TOLERANCE = 1.1  # up to 10% above the bound: rounding, decimated meshes
BOUND_ERROR = 2.0  # above 2x the bound: impossible even with undrawn parts
TRIANGLE_TOLERANCE = 1e-2  # relative to the largest principal moment
NEGATIVE_TOLERANCE = 1e-3  # a principal moment below -0.1% of the largest is negative
TINY_MOMENT = 1e-15  # kg·m²: numerically zero (a 0.1 g part 0.1 mm across has 1e-12)
PERMUTED_MATCH = 0.1  # relative tensor error of the best permutation
PERMUTED_MISMATCH = 0.3  # relative tensor error as written
UNIT_SLIPS = (1e3, 1e6, 1e-3, 1e-6)
UNIT_BAND = 10 ** 0.5  # "near 1e3": within a factor sqrt(10)
UNIT_SPREAD = 2.0  # a unit slip scales every axis alike: their ratios within this factor
MISMATCH_FACTOR = 10.0
DENSITY_LOW, DENSITY_HIGH = 10.0, 25000.0  # kg/m^3: lighter than foam, denser than osmium
COM_TOLERANCE = 0.25  # fraction of the body's width (along the way out) the COM may lie outside
AXIS_NAMES = ("x", "y", "z")
NO_TRIMESH = "trimesh is not installed"  # ShapeInfo.problem of a mesh that was not read
NO_LIBRARY = "an optional library it needs is not installed"  # (meshes.missing_library)
UNREAD_FORMAT = "a mesh format urdftool does not read"
NEGLIGIBLE_EFFECT = 0.01  # relative change of a merged body's principal moments
# issue 22.4: a tensor too large for its link's geometry, on a link lumped into a body, is an
# error only when it changes the body's principal moments by more than this fraction (the
# merged tensor itself stays possible: a sum of possible tensors, shifted, is one) (10%: the dynamics a simulator or controller computes for the body
# change by that much; below it, by less than CAD inertias typically differ from the part)
MERGED_ERROR_FRACTION = 0.10


@dataclass
class ShapeInfo:
    """One visual or collision of a link, as a solid and a convex extent in the link frame."""

    shape: object  # urdftool.model.Shape
    solid: Solid | None = None  # None: no volume (or unusable)
    extent: Extent | None = None  # None: unusable
    problem: str | None = None  # why the shape cannot be used
    path: Path | None = None  # mesh: the resolved file
    mesh: object = None  # mesh: its MeshInfo

    @property
    def usable(self) -> bool:
        return self.extent is not None


@dataclass
class BoundCheck:
    axis_name: str  # "x" of the inertial frame, or "principal 1"...
    axis: Vec3  # in the link frame
    moment: float
    bound: float  # m * max squared distance from the axis
    reach: float  # sqrt of the max squared distance

    @property
    def ratio(self) -> float:
        return self.moment / self.bound if self.bound > 0 else math.inf


@dataclass
class LinkAnalysis:
    link: object  # urdftool.model.Link
    moving: bool = False
    shapes: list[ShapeInfo] = field(default_factory=list)
    mass: float | None = None
    com: Vec3 = phys.ZERO3  # declared COM, link frame
    frame: Mat3 = phys.IDENTITY  # inertial frame -> link frame
    declared: Mat3 | None = None  # declared tensor, inertial frame
    principal: Vec3 | None = None
    principal_axes: tuple[Vec3, Vec3, Vec3] | None = None  # inertial frame
    derived_from: str | None = None  # "collision" or "visual"
    solid: Solid | None = None  # geometry used for the derived inertia, link frame
    derived: Mat3 | None = None  # for the declared mass, about its centroid, inertial frame
    volumes: dict[str, float] = field(default_factory=dict)  # role -> volume of complete sets
    bound: BoundCheck | None = None  # the worst axis
    # the geometry the bound was taken over: all of it, or only the collisions when a visual
    # could not be read (issue 22.3: a missing visual mesh must not hide what they allow)
    bound_over: str = "visual and collision"
    com_distance: float | None = None  # declared COM to the geometry's convex hull
    com_thickness: float | None = None  # the hull's width along the direction to the COM
    ratios: Vec3 | None = None  # declared / derived moment about each inertial axis
    permutation: tuple[int, int, int] | None = None  # declared axis i matches derived perm[i]
    unit_slip: float | None = None
    findings: dict[str, str] = field(default_factory=dict)  # rule name -> severity (verdict)

    @property
    def extents(self) -> list[Extent]:
        return [s.extent for s in self.shapes if s.extent is not None]

    @property
    def complete(self) -> bool:
        """Every visual and collision is usable (so bounds over their union are valid)."""
        return bool(self.shapes) and all(s.usable for s in self.shapes)


# -- shapes -------------------------------------------------------------------------------


def _positive(*values) -> bool:
    return all(v is not None and math.isfinite(v) and v > 0 for v in values)


class _MeshFiles:
    """The mesh files of one robot: each ``<mesh filename>`` resolved and looked up once (a
    file is often both a visual and a collision, and resolving walks the file system)."""

    def __init__(self, robot):
        self.robot = robot
        self._found: dict[tuple, tuple[Path | None, bool, str | None]] = {}

    def find(self, geometry) -> tuple[Path | None, bool, str | None]:
        """(the path ``meshes.resolve`` gives, whether it is a file, its resolved name)."""
        key = (geometry.filename, geometry.loc.path if geometry.loc is not None else None)
        found = self._found.get(key)
        if found is None:
            from urdftool.physics import meshes

            path = meshes.resolve(self.robot, geometry)
            is_file = path is not None and packages.is_file(path)
            found = self._found[key] = (path, is_file,
                                        packages.resolved(path) if is_file else None)
        return found


def _shape_info(robot, shape, need_volume: bool = True,
                volume_files: set[str] | frozenset = frozenset(),
                files: _MeshFiles | None = None) -> ShapeInfo:
    info = ShapeInfo(shape)
    g = shape.geometry
    origin = shape.origin
    if not all(math.isfinite(v) for v in origin.xyz + origin.rpy):
        info.problem = "origin is not finite"
        return info
    if g.kind == "mesh":
        _mesh_shape(files or _MeshFiles(robot), info, origin, need_volume, volume_files)
        return info
    # the same primitive at the same place recurs across a corpus's robots: placed once per
    # process (the key is the repr, so that -0.0 and 0.0 stay apart)
    key = repr((g[:4], origin))
    placed = _PRIMITIVES.get(key)
    if placed is None:
        placed = _PRIMITIVES[key] = _primitive(g, origin)
    info.solid, info.extent, info.problem = placed
    return info


def _primitive(g, origin) -> tuple[Solid | None, Extent | None, str | None]:
    """(solid, extent, problem) of a box, cylinder, capsule or sphere placed at ``origin``."""
    rotation = phys.rpy_matrix(origin.rpy)
    translation = origin.xyz
    if g.kind == "box":
        if g.size is None or not _positive(*g.size):
            return None, None, "box size missing or not positive"
        return (phys.box_solid(g.size).moved(rotation, translation),
                phys.BoxExtent(g.size, rotation, translation), None)
    if g.kind in ("cylinder", "capsule"):
        if not _positive(g.radius, g.length):
            return None, None, f"{g.kind} radius or length missing or not positive"
        make = phys.cylinder_solid if g.kind == "cylinder" else phys.capsule_solid
        return (make(g.radius, g.length).moved(rotation, translation),
                phys.CylinderExtent(g.radius, g.length, rotation, translation,
                                    capsule=g.kind == "capsule"), None)
    if g.kind == "sphere":
        if not _positive(g.radius):
            return None, None, "sphere radius missing or not positive"
        return (phys.sphere_solid(g.radius).moved(rotation, translation),
                phys.SphereExtent(g.radius, rotation, translation), None)
    return None, None, "no geometry" if g.kind is None else f"unknown geometry <{g.kind}>"


def _mesh_shape(files: _MeshFiles, info: ShapeInfo, origin, need_volume: bool,
                volume_files: set[str] | frozenset) -> None:
    from urdftool.physics import meshes

    g = info.shape.geometry
    scale = g.scale
    if not all(math.isfinite(s) and s != 0 for s in scale):
        info.problem = "mesh scale has a zero"
        return
    if not g.filename:
        info.problem = "mesh without filename"
        return
    path, is_file, resolved = files.find(g)
    info.path = path
    if path is None:
        info.problem = f"cannot resolve {g.filename!r}"
        return
    if not is_file:
        info.problem = f"no file at {path}"
        return
    if path.suffix.lower() not in meshes.LOADABLE:
        info.problem = UNREAD_FORMAT
        return
    if not meshes.trimesh_available():
        info.problem = NO_TRIMESH
        return
    need_volume = need_volume or resolved in volume_files
    mesh = meshes.load_mesh(resolved, need_volume=need_volume)
    info.mesh = mesh
    if not mesh.ok:
        info.problem = NO_LIBRARY if meshes.missing_library(mesh) else \
            f"cannot load {path.name}: {mesh.error}"
        return
    # placed once per process for each (summary, scale, origin); the summary is kept in the
    # value, so that its id in the key cannot be reused by another object
    key = (id(mesh), repr((scale, origin)))
    placed = _MESH_SHAPES.get(key)
    if placed is None:
        rotation = phys.rpy_matrix(origin.rpy)
        translation = origin.xyz
        solid = (mesh.solid.scaled(scale).moved(rotation, translation)
                 if mesh.solid is not None else None)
        placed = _MESH_SHAPES[key] = (solid, meshes.MeshExtent(mesh, scale, rotation,
                                                               translation), mesh)
    info.solid, info.extent, _ = placed


# -- analysis -------------------------------------------------------------------------------


def _moving_links(robot) -> set[str]:
    return {j.child for j in robot.joints if j.moving and j.child is not None}


def analyse_link(robot, link, moving: bool = False,
                 volume_files: set[str] | frozenset = frozenset(),
                 files: _MeshFiles | None = None) -> LinkAnalysis:
    a = LinkAnalysis(link, moving=moving)
    # the inertia is derived from the collisions, or the visuals when there is no collision:
    # only those meshes need their volume (the costly part of reading a mesh)
    volume_role = "collision" if link.collisions else "visual"
    files = files or _MeshFiles(robot)
    a.shapes = [_shape_info(robot, s, s.role == volume_role, volume_files, files)
                for s in link.shapes]
    if link.collisions and not all(s.solid is not None for s in a.shapes
                                   if s.shape.role == "collision"):
        a.shapes = [_shape_info(robot, s.shape, files=files) if s.shape.role == "visual" else s
                    for s in a.shapes]
    inertial = link.inertial
    # what follows depends on the shapes' placed solids and extents (shared objects, see
    # _shape_info), the inertial's values and ``moving`` only: a link met before (the same link
    # in another variant of a robot) takes that analysis with its own link and shapes
    key = (moving, repr(inertial[:8]) if inertial is not None else None,
           tuple((s.shape.role, id(s.solid), id(s.extent)) for s in a.shapes))
    known = _LINKS.get(key)
    if known is not None:
        return _rebound(known, link, a.shapes)
    if inertial is not None:
        a.mass = inertial.mass
        a.com = inertial.origin.xyz
        if all(math.isfinite(v) for v in inertial.origin.rpy):
            a.frame = phys.rpy_matrix(inertial.origin.rpy)
        a.declared = inertial.tensor
        if a.declared is not None:
            a.principal, a.principal_axes = phys.eigen_symmetric(a.declared)
    for role in ("collision", "visual"):
        infos = [s for s in a.shapes if s.shape.role == role]
        if infos and all(s.solid is not None for s in infos):
            a.volumes[role] = sum(s.solid.volume for s in infos)  # type: ignore[union-attr]
            if a.derived_from is None:
                a.derived_from = role
                a.solid = phys.combine([s.solid for s in infos])  # type: ignore[misc]
    _judge(a)
    if len(_LINKS) >= _MEMO_LIMIT or len(_MESH_SHAPES) >= _PLACED_LIMIT:
        _clear_memos()
    # the analysis keeps its shapes' solids and extents alive: the ids in the key stay theirs
    _LINKS[key] = a
    return _rebound(a, link, a.shapes)


def _rebound(a: LinkAnalysis, link, shapes: list[ShapeInfo]) -> LinkAnalysis:
    """A copy of analysis ``a`` for ``link`` and its ``shapes`` (its own locations)."""
    b = LinkAnalysis.__new__(LinkAnalysis)
    b.__dict__.update(a.__dict__)
    b.link, b.shapes = link, shapes
    b.volumes, b.findings = dict(a.volumes), dict(a.findings)
    return b


# per process, across robots (files of a corpus share links): placed primitives, placed meshes,
# link analyses (see analyse_link)
_PRIMITIVES: dict[str, tuple] = {}
_MESH_SHAPES: dict[tuple, tuple] = {}
_LINKS: dict[tuple, LinkAnalysis] = {}
_MEMO_LIMIT = 20000
# placed meshes hold their hull points in the link frame (~13 kB each on the test corpus, whose
# 164 files place 976): bounded like the rest, so that a run over thousands of robots stays small
_PLACED_LIMIT = 4000


def _clear_memos() -> None:
    _LINKS.clear()
    _PRIMITIVES.clear()
    _MESH_SHAPES.clear()


def _judge(a: LinkAnalysis) -> None:
    """Compare the declared inertial with the geometry; fills the verdict fields."""
    m = a.mass
    if a.link.inertial is None:
        return
    if m is None or not math.isfinite(m):
        return
    if m <= 0:
        a.findings["mass-not-positive"] = "error"
        return
    if a.declared is None or a.principal is None:
        return
    low, mid, high = a.principal
    if low < -max(NEGATIVE_TOLERANCE * abs(high), TINY_MOMENT):
        a.findings["not-positive-definite"] = "error"
        return
    if high <= TINY_MOMENT:  # a point mass
        if a.moving:
            a.findings["not-positive-definite"] = "warning"
        return
    if high - (low + mid) > max(TRIANGLE_TOLERANCE * high, TINY_MOMENT):
        a.findings["triangle-inequality"] = "error"
        return
    inertial_origin = a.link.inertial.origin
    if not all(math.isfinite(v) for v in inertial_origin.xyz + inertial_origin.rpy):
        return  # the schema rules report it; nothing can be placed
    # bound over the union of visual and collision geometry; when only a visual is unusable
    # (a mesh not found, not read), over the collisions: an error only far above their bound,
    # which the visual might have widened
    collisions = [s for s in a.shapes if s.shape.role == "collision"]
    collision_only = not a.complete and bool(collisions) and all(s.usable for s in collisions)
    if a.complete or collision_only:
        shapes = a.shapes if a.complete else collisions
        a.bound_over = "visual and collision" if a.complete else "collision"
        extents = [s.extent for s in shapes]
        axes: list[tuple[str, Vec3]] = [(AXIS_NAMES[i], phys.IDENTITY[i]) for i in range(3)]
        if a.principal_axes is not None and any(
                abs(x) > 1e-9 for i, row in enumerate(a.declared) for j, x in enumerate(row)
                if i != j):
            axes += [(f"principal {i + 1}", a.principal_axes[i]) for i in range(3)]
        worst = None
        link_axes = [phys.mat_vec(a.frame, axis) for _, axis in axes]
        for (name, axis), link_axis, reach2 in zip(axes, link_axes,
                                                   _reaches(shapes, a.com, link_axes)):
            moment = phys.dot(axis, phys.mat_vec(a.declared, axis))
            check = BoundCheck(name, link_axis, moment, m * reach2, math.sqrt(reach2))
            if worst is None or check.ratio > worst.ratio:
                worst = check
        a.bound = worst
        if collision_only:
            if worst is not None and worst.ratio > BOUND_ERROR:
                a.findings["exceeds-geometry"] = "warning"
        else:
            if worst is not None and worst.ratio > BOUND_TOLERANCE:
                a.findings["exceeds-geometry"] = \
                    "error" if worst.ratio > BOUND_ERROR else "warning"
            a.com_distance, a.com_thickness = phys.hull_escape(a.com, extents)
            if a.com_distance > COM_TOLERANCE * a.com_thickness:
                a.findings["com-outside-geometry"] = "warning"
    # geometry-derived inertia for the declared mass
    if a.solid is None:
        return
    derived_link = a.solid.inertia(m)
    a.derived = phys.rotate_tensor(phys.transpose(a.frame), derived_link)
    d_diag, g_diag = phys.diag(a.declared), phys.diag(a.derived)
    if min(g_diag) <= 0:
        return
    a.ratios = tuple(d / g for d, g in zip(d_diag, g_diag))  # type: ignore[assignment]
    # unit slip: every moment the geometry's times one power of 1000, alike on every axis, on a
    # tensor that was computed (a typed-in round placeholder is no unit slip: the bound says it)
    positive = [r for r in a.ratios if r > 0]
    if len(positive) == 3 and max(positive) / min(positive) <= UNIT_SPREAD \
            and not is_round_placeholder(a.declared):
        ratio = math.exp(sum(math.log(r) for r in positive) / 3)  # the factor, all axes alike
        for slip in UNIT_SLIPS:
            if slip / UNIT_BAND <= ratio <= slip * UNIT_BAND and (
                    slip < 1 or "exceeds-geometry" in a.findings):
                a.unit_slip = slip
                # one finding for the tensor: the slip, as grave as the bound it breaks
                a.findings["unit-scale"] = a.findings.pop("exceeds-geometry", "warning")
                break
    # permuted axes
    reference = phys.frobenius(a.derived)
    errors = {}
    for perm in permutations(range(3)):
        permuted = tuple(tuple(a.declared[perm[i]][perm[j]] for j in range(3)) for i in range(3))
        errors[perm] = phys.frobenius(phys.mat_add(permuted, phys.mat_scale(a.derived, -1.0)))
        errors[perm] /= reference
    as_written = errors[(0, 1, 2)]
    # among the permutations that fit, the simplest: a swap of two axes before a 3-cycle
    fitting = [p for p in errors if p != (0, 1, 2) and errors[p] <= PERMUTED_MATCH]
    if fitting and as_written >= PERMUTED_MISMATCH and "unit-scale" not in a.findings:
        a.permutation = min(fitting, key=lambda p: (sum(i != k for i, k in enumerate(p)),
                                                    errors[p]))
        a.findings["permuted-axes"] = "warning"
    # a large (possible) mismatch, when nothing above explains it
    if not a.findings and any(r > MISMATCH_FACTOR or r < 1 / MISMATCH_FACTOR
                              for r in a.ratios):
        a.findings["geometry-mismatch"] = "info"
    # density
    if a.volumes:
        smallest, largest = min(a.volumes.values()), max(a.volumes.values())
        too_light = smallest > 0 and m / smallest < DENSITY_LOW
        too_dense = largest > 0 and m / largest > DENSITY_HIGH
        if too_light or too_dense:
            a.findings["implausible-density"] = "info"


def _reaches(shapes: list[ShapeInfo], origin: Vec3, axes: list[Vec3]) -> list[float]:
    """``phys.max_sq_distance`` over the shapes' extents for each axis; a mesh's offsets from
    ``origin`` and their squared lengths are computed once for all the axes."""
    rows = [s.extent.max_sq_distances(origin, axes) if s.mesh is not None
            else [s.extent.max_sq_distance(origin, axis) for axis in axes] for s in shapes]
    return [max(row[k] for row in rows) for k in range(len(axes))]


def is_placeholder(tensor: Mat3) -> bool:
    """ixx = iyy = izz = a power of ten and no products: a value typed in, not computed."""
    d = phys.diag(tensor)
    if d[0] <= 0 or d[0] != d[1] or d[1] != d[2]:
        return False
    if any(tensor[i][j] != 0 for i in range(3) for j in range(3) if i != j):
        return False
    exponent = math.log10(d[0])
    return abs(exponent - round(exponent)) < 1e-9


def is_round_placeholder(tensor: Mat3) -> bool:
    """ixx = iyy = izz, no products, and a round number (at most two significant digits, to
    within rounding: ``${0.1*0.1}`` is 0.010000000000000002): a value typed in, not computed
    (a CAD export with a unit slip has the part's own, unequal, many-digit moments)."""
    d = phys.diag(tensor)
    if not d[0] > 0 or any(abs(x - d[0]) > 1e-9 * d[0] for x in d):
        return False
    if any(abs(tensor[i][j]) > 1e-12 * d[0] for i in range(3) for j in range(3) if i != j):
        return False
    rounded = float(f"{d[0]:.2g}")
    return abs(rounded - d[0]) <= 1e-9 * d[0]


_last: tuple[object, dict[int, LinkAnalysis]] | None = None


def _volume_files(robot, files: _MeshFiles) -> set[str]:
    """The mesh files some link derives its inertia from (read with their volume from the
    start, so that a file used as a visual here and a collision there is read once)."""
    names: set[str] = set()
    for link in robot.links:
        for shape in link.collisions or link.visuals:
            if shape.geometry.kind == "mesh" and shape.geometry.filename:
                path, is_file, resolved = files.find(shape.geometry)
                if path is not None:
                    names.add(resolved if is_file else packages.resolved(path))
    return names


def analyse(robot) -> dict[int, LinkAnalysis]:
    """The analysis of every link of ``robot`` keyed by its index in ``robot.links`` (cached
    for the last robot analysed, so that every rule of a check run shares it)."""
    global _last
    if _last is not None and _last[0] is robot:
        return _last[1]
    moving = _moving_links(robot)
    files = _MeshFiles(robot)
    volume_files = _volume_files(robot, files)
    result = {}
    with warnings.catch_warnings():  # numpy's overflow warnings on absurd sizes: the rules
        warnings.simplefilter("ignore", RuntimeWarning)  # report the sizes themselves
        for i, link in enumerate(robot.links):
            try:
                result[i] = analyse_link(robot, link, link.name in moving, volume_files, files)
            except (ArithmeticError, ValueError):  # numbers no analysis can use: say nothing
                result[i] = LinkAnalysis(link, moving=link.name in moving)
    _last = (robot, result)
    return result


def derived_inertial(a: LinkAnalysis, mass: float | None = None,
                     density: float | None = None) -> dict | None:
    """The inertial the geometry implies: mass (given, or density x volume, or the declared
    one), COM at the geometry's centroid, tensor about it in the link frame."""
    if a.solid is None:
        return None
    if density is not None:
        mass = density * a.solid.volume
    if mass is None:
        mass = a.mass
    if mass is None or not math.isfinite(mass) or mass <= 0:
        return None
    tensor = a.solid.inertia(mass)
    return {"mass": mass, "xyz": a.solid.centroid, "rpy": (0.0, 0.0, 0.0),
            "ixx": tensor[0][0], "ixy": tensor[0][1], "ixz": tensor[0][2],
            "iyy": tensor[1][1], "iyz": tensor[1][2], "izz": tensor[2][2],
            "from": a.derived_from, "volume": a.solid.volume}


class MergedBody(NamedTuple):
    root: str  # the link the group is lumped into
    links: int  # links with mass in the group
    mass: float
    com: Vec3  # in the root link's frame
    tensor: Mat3  # about ``com``, in the root link's frame
    principal: Vec3


class TensorEffect(NamedTuple):
    body: MergedBody  # with the link's tensor as declared
    without: MergedBody  # with the link as a point mass
    change: float  # largest relative change of the body's principal moments
    static: bool = False  # the body is welded to the world: its inertia never acts


class RigidBodies:
    """Links grouped into rigid bodies (joined by fixed joints), with their masses. One per
    robot (``of``): what it finds (bodies, members, sums) is kept for every rule and link."""

    @classmethod
    def of(cls, robot) -> RigidBodies:
        """The robot's one RigidBodies (``Robot.memo``; issue 28: one made per link lost every
        body found, a merge per link again)."""
        found = robot.memo.get("rigid_bodies")
        if found is None:
            found = robot.memo["rigid_bodies"] = cls(robot)
        return found

    def __init__(self, robot):
        self.robot = robot
        self.parent: dict[str, object] = {}
        self.children: dict[str, list] = {}
        for joint in robot.joints:
            if joint.child is not None and joint.child not in self.parent:
                self.parent[joint.child] = joint
            if joint.parent is not None:
                self.children.setdefault(joint.parent, []).append(joint)
        self._subtree: dict[str, float] | None = None  # link -> subtree mass, made once
        self._massive: set[str] | None = None  # links with mass at or below them
        # per body, made once (issue 28): link -> its body's root, root -> members, ...
        self._body_roots: dict[str, str] = {}
        self._body_members: dict[str, list] = {}
        self._member_index: dict[str, dict] = {}
        self._aggregates: dict[tuple, tuple | None] = {}
        self._static: dict[str, bool] = {}
        self._last_set: tuple = (None, frozenset())
        self.mass = {}
        for link in robot.links:
            m = link.inertial.mass if link.inertial is not None else None
            if link.name is not None and m is not None and math.isfinite(m) and m > 0:
                self.mass[link.name] = self.mass.get(link.name, 0.0) + m

    def _descendants(self, name: str, fixed_only: bool) -> list[str]:
        seen, stack = {name}, [name]
        while stack:
            for joint in self.children.get(stack.pop(), []):
                if fixed_only and joint.moving:
                    continue
                if joint.child is not None and joint.child not in seen:
                    seen.add(joint.child)
                    stack.append(joint.child)
        return list(seen)

    def subtree_mass(self, name: str) -> float:
        """Mass of a link and everything beyond it. On a tree every link's is summed once,
        children before parents (issue 15: a walk per link was quadratic, 16 s on a 10k-link
        chain); a link below two parents or in a loop is walked."""
        if self._subtree is None:
            self._subtree = self._subtree_masses()
        known = self._subtree.get(name)
        if known is not None:
            return known
        if name not in self._above_mass():  # nothing with mass below: no walk (issue 28)
            return 0.0
        return sum(self.mass.get(n, 0.0) for n in self._descendants(name, False))

    def _above_mass(self) -> set[str]:
        """The links with a mass of their own or below them (through any joint), found once:
        one walk up from every link with mass (a link below two parents, a loop: the walks
        per link that ``subtree_mass`` makes otherwise were quadratic)."""
        if self._massive is None:
            parents: dict[str, list[str]] = {}
            for joint in self.robot.joints:
                if joint.child is not None and joint.parent is not None:
                    parents.setdefault(joint.child, []).append(joint.parent)
            found = {name for name, m in self.mass.items() if m != 0}
            stack = list(found)
            while stack:
                for parent in parents.get(stack.pop(), ()):
                    if parent not in found:
                        found.add(parent)
                        stack.append(parent)
            self._massive = found
        return self._massive

    def _subtree_masses(self) -> dict[str, float]:
        """Subtree masses of the links below the roots when every link has at most one parent
        joint (otherwise none: ``subtree_mass`` walks)."""
        children = [j.child for j in self.robot.joints if j.child is not None]
        if len(children) != len(set(children)):
            return {}
        order, stack = [], [link.name for link in self.robot.links
                            if link.name is not None and link.name not in self.parent]
        while stack:  # parents before children
            name = stack.pop()
            order.append(name)
            stack.extend(j.child for j in self.children.get(name, []) if j.child is not None)
        totals: dict[str, float] = {}
        for name in reversed(order):
            totals[name] = self.mass.get(name, 0.0) + sum(
                totals[j.child] for j in self.children.get(name, []) if j.child is not None)
        return totals

    def body_root(self, name: str) -> str:
        """The link a fixed-joint chain from ``name`` leads up to: the body it is lumped into.
        Found once for every link on the way (issue 28: a walk per link was quadratic in a
        long fixed chain); in a loop of fixed joints, the link where the first walk closed it."""
        known = self._body_roots.get(name)
        if known is not None:
            return known
        path, seen = [name], {name}
        joint = self.parent.get(name)
        while joint is not None and not joint.moving and joint.parent is not None \
                and joint.parent not in seen:
            name = joint.parent
            known = self._body_roots.get(name)
            if known is not None:
                break
            path.append(name)
            seen.add(name)
            joint = self.parent.get(name)
        root = known if known is not None else name
        for member in path:
            self._body_roots[member] = root
        return root

    def _members(self, root: str) -> list[tuple[str, float, Vec3, Mat3]]:
        """(link, mass, COM, tensor about its COM) of every link with mass in the body of
        ``root``, in the root's frame: walked once per body."""
        found = self._body_members.get(root)
        if found is not None:
            return found
        members = []
        stack = [(root, phys.IDENTITY, phys.ZERO3)]
        seen = {root}
        while stack:
            link_name, rotation, position = stack.pop()
            link = self.robot.link(link_name)
            inertial = link.inertial if link is not None else None
            m = self.mass.get(link_name, 0.0)
            if inertial is not None and m > 0:
                frame = phys.rpy_matrix(inertial.origin.rpy)
                com = phys.add(position, phys.mat_vec(rotation, inertial.origin.xyz))
                tensor = inertial.tensor
                tensor = (phys.rotate_tensor(phys.mat_mul(rotation, frame), tensor)
                          if tensor is not None else phys.ZERO33)
                members.append((link_name, m, com, tensor))
            for joint in self.children.get(link_name, []):
                if joint.moving or joint.child is None or joint.child in seen:
                    continue
                seen.add(joint.child)
                stack.append((joint.child,
                              phys.mat_mul(rotation, phys.rpy_matrix(joint.origin.rpy)),
                              phys.add(position, phys.mat_vec(rotation, joint.origin.xyz))))
        self._body_members[root] = members
        return members

    def _aggregate(self, root: str, point_masses) -> tuple | None:
        """(links, total mass, COM, summed tensor, parallel-axis part) of ``root``'s body with
        the tensors of ``point_masses`` left out, once per body and set of point masses."""
        key = (root, point_masses if isinstance(point_masses, frozenset)
               else self._frozen(point_masses))
        if key in self._aggregates:
            return self._aggregates[key]
        members = self._members(root)
        total = sum(m for _, m, _, _ in members)
        result = None
        if total > 0 and math.isfinite(total):
            com = tuple(sum(m * c[k] for _, m, c, _ in members) / total for k in range(3))
            tensors, shift = phys.ZERO33, phys.ZERO33
            for name, m, c, t in members:
                if name not in key[1]:
                    tensors = phys.mat_add(tensors, t)
                shift = phys.mat_add(shift, phys.parallel_axis(phys.ZERO33, m, phys.sub(c, com)))
            result = (len(members), total, com, tensors, shift)
        self._aggregates[key] = result
        return result

    def _frozen(self, names) -> frozenset:
        """``names`` as a frozenset, made once for the same set object asked again (a rule
        passes one set for every link)."""
        if self._last_set[0] is not names:
            self._last_set = (names, frozenset(names))
        return self._last_set[1]

    def _body(self, root: str, aggregate: tuple, extra: Mat3 | None = None,
              less: Mat3 | None = None) -> MergedBody | None:
        links, total, com, tensors, shift = aggregate
        if extra is not None:
            tensors = phys.mat_add(tensors, extra)
        if less is not None:
            tensors = phys.mat_add(tensors, phys.mat_scale(less, -1.0))
        tensor = phys.mat_add(tensors, shift)
        if not all(math.isfinite(x) for row in tensor for x in row + com):
            return None
        return MergedBody(root, links, total, com, tensor, phys.principal_moments(tensor))

    def merged(self, name: str, point_masses: set | frozenset = frozenset()) -> MergedBody | None:
        """The body that link ``name`` is lumped into (its fixed-joint group), as Gazebo's URDF
        reader, Drake and MuJoCo (``fusestatic``) build it: total mass, centre of mass and
        inertia about it in the group root's frame (parallel-axis theorem). ``point_masses``:
        links whose own tensors are left out (their masses kept at their COMs). None when
        nothing in the group has a usable mass or a pose is not finite."""
        root = self.body_root(name)
        aggregate = self._aggregate(root, point_masses)
        return None if aggregate is None else self._body(root, aggregate)

    def _own_tensor(self, root: str, name: str) -> Mat3 | None:
        """``name``'s tensor in its body (root frame), or None when it has no mass there."""
        index = self._member_index.get(root)
        if index is None:
            index = self._member_index[root] = {n: t for n, _, _, t in self._members(root)}
        return index.get(name)

    def tensor_effect(self, name: str, suspects: set | frozenset = frozenset()) -> TensorEffect | None:
        """How much link ``name``'s own inertia tensor changes the body it is lumped into:
        the largest relative change of that body's principal moments between the tensor as
        declared and a point mass in its place (``math.inf`` when the body has no other
        rotational inertia; 0 for a body fixed to a root link called ``world``, which never
        moves). The other ``suspects`` (impossible tensors) are point masses in both, so that
        one placeholder does not hide another. None when the link is a body on its own.
        The body with every suspect a point mass is summed once: this link's tensor is added
        to it or taken from it (issue 28: a merge per link was quadratic)."""
        try:
            root = self.body_root(name)
            aggregate = self._aggregate(root, suspects)
            if aggregate is None:
                return None
            own = self._own_tensor(root, name)
            if name in suspects:
                without = self._body(root, aggregate)
                with_tensor = self._body(root, aggregate, extra=own)
            else:
                with_tensor = self._body(root, aggregate)
                without = self._body(root, aggregate, less=own)
        except (ArithmeticError, ValueError):  # an infinite angle (math.cos): no verdict
            return None
        if with_tensor is None or without is None:
            return None
        if with_tensor.root == "world" and with_tensor.root not in self.parent:
            return TensorEffect(with_tensor, without, 0.0, static=True)
        if with_tensor.links < 2:
            return None
        change = 0.0
        for a, b in zip(with_tensor.principal, without.principal):
            if b <= TINY_MOMENT:
                change = math.inf if abs(a - b) > TINY_MOMENT else change
            else:
                change = max(change, abs(a - b) / b)
        return TensorEffect(with_tensor, without, change)

    def is_static_root(self, name: str) -> bool:
        """The link belongs to the root's rigid body and nothing in that body has mass:
        PyBullet keeps such a body static (pybullet_data's tables and fixed bases). Found
        once per body."""
        root = self.body_root(name)
        if root in self.parent:
            return False
        known = self._static.get(root)
        if known is None:
            known = True
            for member in self._descendants(root, True):
                link = self.robot.link(member)
                inertial = link.inertial if link is not None else None
                if inertial is not None and inertial.mass != 0:  # mass, a negative or unread one
                    known = False
                    break
            self._static[root] = known
        return known

    def is_free_massless_base(self, name: str) -> bool:
        """A root link whose rigid body (it and what is fixed to it) has no mass, while joints
        move somewhere below it."""
        if name in self.parent:
            return False
        body = self._descendants(name, True)
        if sum(self.mass.get(n, 0.0) for n in body) > 0:
            return False
        below = self._descendants(name, False)
        return any(j.moving for n in below for j in self.children.get(n, []))


def _number(value: float) -> str:
    text = f"{value:.6g}"
    return "0" if text in ("-0", "0") else text


def inertial_xml(block: dict, compact: bool = False, indent: str = "  ") -> str:
    """An <inertial> element for a ``derived_inertial`` block (6 significant digits)."""
    xyz = " ".join(_number(v) for v in block["xyz"])
    rpy = " ".join(_number(v) for v in block["rpy"])
    moments = " ".join(f'{k}="{_number(block[k])}"'
                       for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))
    parts = [f'<origin xyz="{xyz}" rpy="{rpy}"/>', f'<mass value="{_number(block["mass"])}"/>',
             f"<inertia {moments}/>"]
    if compact:
        return "<inertial>" + "".join(parts) + "</inertial>"
    inner = "".join(f"\n{indent}{indent}{p}" for p in parts)
    return f"{indent}<inertial>{inner}\n{indent}</inertial>"
