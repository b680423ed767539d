"""Do two links of a robot touch anywhere in its joint space? A deterministic low-discrepancy
sample (Halton) of the joints between them, within their limits (mimic joints follow their
leaders), forward kinematics of their relative pose, and their collision shapes (primitives
and mesh hulls, ``physics.links``) tested for overlap by GJK (``physics.inertia``) on the
Minkowski difference; the penetration is the smallest separating translation found among a
fixed set of directions (an upper bound of the true depth).

A sample can show a collision; it never proves that there is none (issue 31: the ``srdf``
rule ``srdf.never-pair-collides`` says so)."""

from __future__ import annotations

import math
from typing import NamedTuple

from urdftool.physics.inertia import Extent, hull_distance

PRIMES = (2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53, 59, 61, 67, 71)


def halton(index: int, dimensions: int) -> list[float]:
    """The ``index``-th point (from 1) of the Halton sequence in [0, 1)^dimensions (radical
    inverses in the first primes; past 20 dimensions the primes repeat, shifted)."""
    point = []
    for d in range(dimensions):
        base = PRIMES[d % len(PRIMES)]
        n, f, value = index + d // len(PRIMES), 1.0, 0.0
        while n > 0:
            f /= base
            value += f * (n % base)
            n //= base
        point.append(value)
    return point


class Variable(NamedTuple):
    name: str  # the leading joint
    lower: float
    upper: float


class Step(NamedTuple):
    """One joint on the path from the common ancestor to a link."""

    origin: tuple  # 3x3 rotation, translation of the joint's origin
    kind: str  # "fixed", "revolute", "prismatic"
    axis: tuple[float, float, float]
    variable: int  # index into the variables (-1: fixed)
    multiplier: float
    offset: float


# -- small rigid transforms in plain Python (rotation as a 3x3 tuple, translation) ---------


def _rpy(rpy) -> tuple:
    roll, pitch, yaw = rpy
    cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return ((cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr),
            (sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr),
            (-sp, cp * sr, cp * cr))


def _mul(a, b):
    (ra, ta), (rb, tb) = a, b
    (a00, a01, a02), (a10, a11, a12), (a20, a21, a22) = ra
    (b00, b01, b02), (b10, b11, b12), (b20, b21, b22) = rb
    x, y, z = tb
    return (((a00 * b00 + a01 * b10 + a02 * b20, a00 * b01 + a01 * b11 + a02 * b21,
              a00 * b02 + a01 * b12 + a02 * b22),
             (a10 * b00 + a11 * b10 + a12 * b20, a10 * b01 + a11 * b11 + a12 * b21,
              a10 * b02 + a11 * b12 + a12 * b22),
             (a20 * b00 + a21 * b10 + a22 * b20, a20 * b01 + a21 * b11 + a22 * b21,
              a20 * b02 + a21 * b12 + a22 * b22)),
            (a00 * x + a01 * y + a02 * z + ta[0], a10 * x + a11 * y + a12 * z + ta[1],
             a20 * x + a21 * y + a22 * z + ta[2]))


def _inverse(a):
    rotation, t = a
    rt = tuple(tuple(rotation[j][i] for j in range(3)) for i in range(3))
    return rt, tuple(-sum(rt[i][k] * t[k] for k in range(3)) for i in range(3))


def _about(axis, angle) -> tuple:
    norm = math.sqrt(sum(v * v for v in axis)) or 1.0
    x, y, z = (v / norm for v in axis)
    c, s = math.cos(angle), math.sin(angle)
    v = 1.0 - c
    return ((c + x * x * v, x * y * v - z * s, x * z * v + y * s),
            (y * x * v + z * s, c + y * y * v, y * z * v - x * s),
            (z * x * v - y * s, z * y * v + x * s, c + z * z * v))


IDENTITY = (((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)), (0.0, 0.0, 0.0))


class Path(NamedTuple):
    """The joints from the lowest common ancestor of two links down to each of them."""

    to_a: tuple[Step, ...]
    to_b: tuple[Step, ...]
    variables: tuple[Variable, ...]
    joints: tuple[str, ...]  # the moving joints whose values change the relative pose


def _ancestry(robot, link: str) -> list:
    """The joints from the root down to ``link`` (first parent joint per link)."""
    joints, seen = [], {link}
    current = robot.parent_joint(link)
    while current is not None:
        joints.append(current)
        parent = current.parent
        if parent is None or parent in seen:
            break
        seen.add(parent)
        current = robot.parent_joint(parent)
    joints.reverse()
    return joints


def _leader(robot, joint):
    """(the joint whose value drives ``joint``, multiplier, offset): mimics composed."""
    multiplier, offset, seen = 1.0, 0.0, {joint.name}
    while joint.mimic is not None and joint.mimic.joint:
        leader = robot.joint(joint.mimic.joint)
        if leader is None or leader.name in seen:
            break
        m = joint.mimic.multiplier if joint.mimic.multiplier is not None else 1.0
        o = joint.mimic.offset if joint.mimic.offset is not None else 0.0
        multiplier, offset = multiplier * m, multiplier * o + offset
        seen.add(leader.name)
        joint = leader
    return joint, multiplier, offset


def path(robot, a: str, b: str) -> Path:
    """The joints between links ``a`` and ``b`` (floating and planar joints held at zero)."""
    up_a, up_b = _ancestry(robot, a), _ancestry(robot, b)
    common = 0
    while common < min(len(up_a), len(up_b)) and up_a[common] is up_b[common]:
        common += 1
    variables: list[Variable] = []
    index: dict[str, int] = {}
    moving: list[str] = []

    def step(joint) -> Step:
        origin = (_rpy(joint.origin.rpy), tuple(joint.origin.xyz))
        kind = {"revolute": "revolute", "continuous": "revolute",
                "prismatic": "prismatic"}.get(joint.type or "", "fixed")
        if kind == "fixed":
            return Step(origin, kind, (1.0, 0.0, 0.0), -1, 1.0, 0.0)
        leader, multiplier, offset = _leader(robot, joint)
        if leader.name not in index:
            limit = leader.limit
            if leader.type == "continuous" or limit is None or limit.lower is None \
                    or limit.upper is None or limit.lower >= limit.upper:
                low, high = (-math.pi, math.pi) if kind == "revolute" else (0.0, 0.0)
                if leader.type not in ("continuous",) and limit is not None and \
                        limit.lower is not None and limit.lower == limit.upper:
                    low = high = limit.lower
            else:
                low, high = limit.lower, limit.upper
            index[leader.name] = len(variables)
            variables.append(Variable(leader.name, low, high))
        moving.append(joint.name)
        return Step(origin, kind, tuple(joint.axis_or_default), index[leader.name],
                    multiplier, offset)

    to_a = tuple(step(j) for j in up_a[common:])
    to_b = tuple(step(j) for j in up_b[common:])
    return Path(to_a, to_b, tuple(variables), tuple(moving))


def _pose(steps, q) -> tuple:
    current = IDENTITY
    for s in steps:
        current = _mul(current, s.origin)
        if s.kind == "fixed":
            continue
        value = s.multiplier * q[s.variable] + s.offset
        if s.kind == "revolute":
            current = _mul(current, (_about(s.axis, value), (0.0, 0.0, 0.0)))
        else:
            norm = math.sqrt(sum(v * v for v in s.axis)) or 1.0
            current = _mul(current, (IDENTITY[0], tuple(v / norm * value for v in s.axis)))
    return current


def relative_pose(p: Path, q) -> tuple:
    """The pose of link b in link a's frame at the variables ``q``."""
    return _mul(_inverse(_pose(p.to_a, q)), _pose(p.to_b, q))


class _Placed(Extent):
    """An extent moved by a rigid transform (rotation, translation)."""

    def __init__(self, extent: Extent, pose):
        rotation, translation = pose
        super().__init__(rotation, translation)
        self.extent = extent

    def support(self, direction):
        r = self.rotation
        local = tuple(r[0][i] * direction[0] + r[1][i] * direction[1] + r[2][i] * direction[2]
                      for i in range(3))
        p = self.extent.support(local)
        t = self.translation
        return tuple(r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2] + t[i] for i in range(3))


class _Difference(Extent):
    """The Minkowski difference A - B of two extents (the origin inside: they overlap)."""

    def __init__(self, a: Extent, b: Extent):
        super().__init__(IDENTITY[0], IDENTITY[1])
        self.a, self.b = a, b

    def support(self, direction):
        p = self.a.support(direction)
        q = self.b.support((-direction[0], -direction[1], -direction[2]))
        return (p[0] - q[0], p[1] - q[1], p[2] - q[2])


def _directions(count: int = 200) -> list[tuple[float, float, float]]:
    """``count`` unit vectors spread over the sphere (Fibonacci), and the six axes."""
    found = [(1.0, 0.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, -1.0, 0.0),
             (0.0, 0.0, 1.0), (0.0, 0.0, -1.0)]
    golden = math.pi * (3.0 - math.sqrt(5.0))
    for i in range(count):
        z = 1.0 - 2.0 * (i + 0.5) / count
        r = math.sqrt(max(0.0, 1.0 - z * z))
        found.append((r * math.cos(golden * i), r * math.sin(golden * i), z))
    return found


DIRECTIONS = _directions()


def penetration(a: Extent, b: Extent) -> float:
    """How far ``a`` and ``b`` overlap: the shortest translation among ``DIRECTIONS`` that
    separates them (0 when they do not overlap; an upper bound of the true depth)."""
    difference = _Difference(a, b)
    if hull_distance((0.0, 0.0, 0.0), [difference]) > 0.0:
        return 0.0
    best = math.inf
    for d in DIRECTIONS:
        p = difference.support(d)
        best = min(best, p[0] * d[0] + p[1] * d[1] + p[2] * d[2])
    return max(best, 0.0)


def bounding_sphere(extent: Extent) -> tuple[tuple[float, float, float], float]:
    """(centre, radius) of a sphere holding the extent (its axis-aligned box's)."""
    high = [extent.support(axis)[i] for i, axis in enumerate(DIRECTIONS[0:6:2])]
    low = [extent.support(axis)[i] for i, axis in enumerate(DIRECTIONS[1:6:2])]
    centre = tuple((h + lo) / 2 for h, lo in zip(high, low))
    radius = math.sqrt(sum(((h - lo) / 2) ** 2 for h, lo in zip(high, low)))
    return centre, radius  # type: ignore[return-value]


class Contact(NamedTuple):
    configuration: dict[str, float]  # leading joint -> value
    q: tuple[float, ...]  # the variables, in ``Path.variables`` order
    depth: float  # metres (upper bound, see ``penetration``)
    shapes: tuple[tuple[int, int], ...]  # (index in a's shapes, in b's) of the overlapping ones


def sample_count(dimensions: int) -> int:
    """Configurations tested for a pair moved by ``dimensions`` joints."""
    return min(512, 64 + 64 * dimensions)


def contacts(p: Path, shapes_a: list[Extent], shapes_b: list[Extent], overlap=None,
             spent=lambda: False) -> tuple[list[Contact], int]:
    """(the sampled configurations where shapes of links a and b overlap, deepest first; how
    many configurations were tested). ``overlap(i, j, pose)``: the depth of a's shape i into
    b's shape j placed at ``pose`` in a's frame (0: apart; default: GJK on the convex extents,
    ``penetration``); shapes whose bounding spheres are apart are not asked. ``spent()`` ends
    the sampling early (the run's budget)."""
    if overlap is None:
        def overlap(i, j, pose):
            return penetration(shapes_a[i], _Placed(shapes_b[j], pose))
    spheres_a = [bounding_sphere(e) for e in shapes_a]
    spheres_b = [bounding_sphere(e) for e in shapes_b]
    dims = len(p.variables)
    count = sample_count(dims) if dims else 1
    found: list[Contact] = []
    tested = 0
    for index in range(1, count + 1):
        if index % 16 == 0 and spent():
            break
        unit = halton(index, dims) if dims else []
        q = tuple(v.lower + (v.upper - v.lower) * u for v, u in zip(p.variables, unit))
        pose = relative_pose(p, q)
        tested += 1
        rotation = pose[0]
        deepest, overlapping = 0.0, []
        for i, (ca, ra) in enumerate(spheres_a):
            for j, (cb, rb) in enumerate(spheres_b):
                (_, moved) = _mul(pose, (rotation, cb))
                dx, dy, dz = moved[0] - ca[0], moved[1] - ca[1], moved[2] - ca[2]
                if dx * dx + dy * dy + dz * dz > (ra + rb) ** 2:
                    continue
                depth = overlap(i, j, pose)
                if depth > 0.0:
                    overlapping.append((i, j))
                    deepest = max(deepest, depth)
        if overlapping:
            found.append(Contact({v.name: value for v, value in zip(p.variables, q)}, q,
                                 deepest, tuple(overlapping)))
    found.sort(key=lambda c: -c.depth)
    return found, tested


# -- the meshes themselves (coal, as MoveIt's FCL checks them) -------------------------------

_EXACT: dict[tuple, object] = {}  # (mesh file, scale) -> coal BVH model, or why not (a str)


def coal_available() -> bool:
    try:
        import coal  # noqa: F401
    except ImportError:
        return False
    return True


def exact_geometry(shape, path) -> object:
    """The coal geometry of a collision shape (primitives as such, a mesh as its triangles),
    or why there is none (a str)."""
    import coal
    import numpy as np

    g = shape.geometry
    if g.kind == "box" and g.size:
        return coal.Box(*g.size)
    if g.kind == "sphere" and g.radius:
        return coal.Sphere(g.radius)
    if g.kind == "cylinder" and g.radius and g.length:
        return coal.Cylinder(g.radius, g.length)
    if g.kind == "capsule" and g.radius and g.length:
        return coal.Capsule(g.radius, g.length)
    if g.kind != "mesh" or path is None:
        return "not a shape urdftool places"
    key = (str(path), tuple(g.scale))
    if key not in _EXACT:
        from urdftool.physics.meshes import read_triangles

        found = read_triangles(path)
        if isinstance(found, str):
            _EXACT[key] = found
        else:
            vertices = np.ascontiguousarray(found[0] * np.asarray(g.scale, dtype=np.float64))
            faces = np.asarray(found[1], dtype=np.int32).reshape(-1, 3)
            model = coal.BVHModelOBBRSS()
            model.beginModel(len(faces), len(vertices))
            model.addVertices(vertices)
            model.addTriangles(faces)
            model.endModel()
            _EXACT[key] = model
    return _EXACT[key]


def _transform(pose):
    import coal
    import numpy as np

    rotation, translation = pose
    return coal.Transform3s(np.array(rotation, dtype=np.float64),
                            np.array(translation, dtype=np.float64))


def exact_overlap(infos_a: list, infos_b: list):
    """``overlap(i, j, pose)`` for ``contacts`` testing the shapes themselves with coal (the
    library MoveIt's FCL became; meshes as triangles, as MoveIt checks them; a mesh is read
    when its bounding sphere first meets the other's). ``infos_*``: ``physics.links.ShapeInfo``. A
    collision's depth is coal's penetration (at least 1e-12: touching counts); a shape that
    cannot be tested (a mesh that cannot be read) never collides (``why`` says why)."""
    import coal

    made: dict[tuple[int, int], object] = {}
    why: list[str] = []

    def geometry(side: int, index: int):
        if (side, index) not in made:
            info = (infos_a, infos_b)[side][index]
            found = exact_geometry(info.shape, info.path)
            if isinstance(found, str):
                why.append(f"{info.path.name if info.path is not None else 'a shape'}: {found}")
                found = None
            else:
                origin = (_rpy(info.shape.origin.rpy), tuple(info.shape.origin.xyz))
                found = (found, origin, _transform(origin))
            made[(side, index)] = found
        return made[(side, index)]

    request = coal.CollisionRequest()
    request.enable_contact = True

    def overlap(i, j, pose):
        a, b = geometry(0, i), geometry(1, j)
        if a is None or b is None:
            return 0.0
        result = coal.CollisionResult()
        coal.collide(a[0], a[2], b[0], _transform(_mul(pose, b[1])), request, result)
        if not result.isCollision():
            return 0.0
        return max([abs(c.penetration_depth) for c in result.getContacts()] + [1e-12])

    overlap.why = why  # type: ignore[attr-defined]
    return overlap
