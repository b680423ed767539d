"""Rigid-body inertia in pure Python (``math`` only, so ``check`` stays fast on primitive robots).

- 3-vectors and 3x3 matrices as tuples; URDF ``rpy`` rotations (R = Rz(yaw) Ry(pitch) Rx(roll)).
- ``Solid``: the mass properties of a uniform-density body at unit density (volume, centroid,
  second moment about the centroid), closed form for box, cylinder, sphere and capsule; solids
  move, scale and combine exactly (parallel-axis theorem), and give an inertia tensor for a mass.
- ``eigen_symmetric``: principal moments (closed-form trigonometric method) and axes.
- Convex extents of shapes for physical bounds: ``max_sq_distance`` (largest squared distance
  of the shape from an axis) and ``support`` (for ``hull_distance``, a GJK distance from a point
  to the convex hull of several shapes).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

Vec3 = tuple[float, float, float]
Mat3 = tuple[Vec3, Vec3, Vec3]

IDENTITY: Mat3 = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
ZERO3: Vec3 = (0.0, 0.0, 0.0)
ZERO33: Mat3 = (ZERO3, ZERO3, ZERO3)


# -- vectors and matrices ---------------------------------------------------------------------


def add(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def mul(a: Vec3, s: float) -> Vec3:
    return (a[0] * s, a[1] * s, a[2] * s)


def dot(a: Vec3, b: Vec3) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a: Vec3, b: Vec3) -> Vec3:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a: Vec3) -> float:
    return math.sqrt(dot(a, a))


def unit(a: Vec3) -> Vec3:
    n = norm(a)
    return mul(a, 1.0 / n) if n > 0 else ZERO3


def transpose(m: Mat3) -> Mat3:
    return ((m[0][0], m[1][0], m[2][0]), (m[0][1], m[1][1], m[2][1]),
            (m[0][2], m[1][2], m[2][2]))


def mat_vec(m: Mat3, v: Vec3) -> Vec3:
    x, y, z = v
    return (m[0][0] * x + m[0][1] * y + m[0][2] * z, m[1][0] * x + m[1][1] * y + m[1][2] * z,
            m[2][0] * x + m[2][1] * y + m[2][2] * z)


def mat_mul(a: Mat3, b: Mat3) -> Mat3:
    bt = transpose(b)
    return (mat_vec(bt, a[0]), mat_vec(bt, a[1]), mat_vec(bt, a[2]))


def mat_add(a: Mat3, b: Mat3) -> Mat3:
    (a0, a1, a2), (b0, b1, b2) = a, b
    return ((a0[0] + b0[0], a0[1] + b0[1], a0[2] + b0[2]),
            (a1[0] + b1[0], a1[1] + b1[1], a1[2] + b1[2]),
            (a2[0] + b2[0], a2[1] + b2[1], a2[2] + b2[2]))


def mat_scale(a: Mat3, s: float) -> Mat3:
    return ((a[0][0] * s, a[0][1] * s, a[0][2] * s), (a[1][0] * s, a[1][1] * s, a[1][2] * s),
            (a[2][0] * s, a[2][1] * s, a[2][2] * s))


def outer(a: Vec3, b: Vec3) -> Mat3:
    return ((a[0] * b[0], a[0] * b[1], a[0] * b[2]), (a[1] * b[0], a[1] * b[1], a[1] * b[2]),
            (a[2] * b[0], a[2] * b[1], a[2] * b[2]))


def diag(m: Mat3) -> Vec3:
    return (m[0][0], m[1][1], m[2][2])


def trace(m: Mat3) -> float:
    return m[0][0] + m[1][1] + m[2][2]


def det(m: Mat3) -> float:
    return dot(m[0], cross(m[1], m[2]))


def frobenius(m: Mat3) -> float:
    return math.sqrt(sum(x * x for row in m for x in row))


def rpy_matrix(rpy: Vec3) -> Mat3:
    """The rotation of a URDF ``rpy`` (fixed axes x, y, z): R = Rz(yaw) Ry(pitch) Rx(roll)."""
    roll, pitch, yaw = rpy
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return ((cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr),
            (sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr),
            (-sp, cp * sr, cp * cr))


def matrix_rpy(r: Mat3) -> Vec3:
    """The URDF ``rpy`` of a rotation matrix (inverse of ``rpy_matrix``)."""
    pitch = math.atan2(-r[2][0], math.hypot(r[0][0], r[1][0]))
    if abs(math.cos(pitch)) < 1e-12:  # gimbal lock: put everything in yaw
        return (0.0, pitch, math.atan2(-r[0][1], r[1][1]))
    return (math.atan2(r[2][1], r[2][2]), pitch, math.atan2(r[1][0], r[0][0]))


def rotate_tensor(r: Mat3, tensor: Mat3) -> Mat3:
    """A tensor given in frame B re-expressed in frame A, where ``r`` maps B to A: R I R^T."""
    return mat_mul(mat_mul(r, tensor), transpose(r))


def parallel_axis(tensor: Mat3, mass: float, offset: Vec3) -> Mat3:
    """The inertia about a point at ``-offset`` from the COM (i.e. the COM at ``offset`` from
    the new reference point), from the inertia about the COM: I + m (|d|^2 E - d d^T)."""
    d2 = dot(offset, offset)
    shift = mat_add(mat_scale(IDENTITY, d2), mat_scale(outer(offset, offset), -1.0))
    return mat_add(tensor, mat_scale(shift, mass))


def tensor_from_second_moment(second: Mat3) -> Mat3:
    """Inertia tensor from the second-moment matrix C = integral of x x^T dm: tr(C) E - C."""
    t = trace(second)
    return mat_add(mat_scale(IDENTITY, t), mat_scale(second, -1.0))


# -- principal moments -----------------------------------------------------------------------


def principal_moments(tensor: Mat3) -> Vec3:
    """Eigenvalues of a symmetric 3x3 matrix, ascending (closed-form trigonometric method)."""
    a = tensor
    # x * x, not x ** 2: a float power raises OverflowError where a product gives inf
    p1 = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2]
    if p1 == 0.0:
        return tuple(sorted(diag(a)))  # type: ignore[return-value]
    q = trace(a) / 3.0
    d0, d1, d2 = a[0][0] - q, a[1][1] - q, a[2][2] - q
    p2 = d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * p1
    p = math.sqrt(p2 / 6.0)
    if p == 0.0:
        return (q, q, q)
    b = mat_scale(mat_add(a, mat_scale(IDENTITY, -q)), 1.0 / p)
    r = max(-1.0, min(1.0, det(b) / 2.0))
    phi = math.acos(r) / 3.0
    largest = q + 2.0 * p * math.cos(phi)
    smallest = q + 2.0 * p * math.cos(phi + 2.0 * math.pi / 3.0)
    middle = 3.0 * q - largest - smallest
    return tuple(sorted((smallest, middle, largest)))  # type: ignore[return-value]


def _null_vector(m: Mat3) -> Vec3:
    """A unit vector (nearly) in the null space of a rank-2 symmetric matrix."""
    candidates = (cross(m[0], m[1]), cross(m[0], m[2]), cross(m[1], m[2]))
    best = max(candidates, key=lambda c: dot(c, c))
    return unit(best) if dot(best, best) > 0 else (1.0, 0.0, 0.0)


def _orthonormal_pair(v: Vec3) -> tuple[Vec3, Vec3]:
    helper = (1.0, 0.0, 0.0) if abs(v[0]) < 0.9 else (0.0, 1.0, 0.0)
    e1 = unit(cross(v, helper))
    return e1, cross(v, e1)


def eigen_symmetric(tensor: Mat3) -> tuple[Vec3, tuple[Vec3, Vec3, Vec3]]:
    """Eigenvalues (ascending) and orthonormal eigenvectors of a symmetric 3x3 matrix."""
    values = principal_moments(tensor)
    scale = max(abs(v) for v in values) or 1.0
    gap_low, gap_high = values[1] - values[0], values[2] - values[1]
    if max(gap_low, gap_high) <= 1e-12 * scale:  # isotropic: any basis
        return values, IDENTITY
    # the best-isolated eigenvalue first, by the cross product of rows of (A - lambda E)
    index = 0 if gap_low >= gap_high else 2
    lam = values[index]
    first = _null_vector(mat_add(tensor, mat_scale(IDENTITY, -lam)))
    # the other two in the plane orthogonal to it: a 2x2 symmetric problem
    e1, e2 = _orthonormal_pair(first)
    a11 = dot(e1, mat_vec(tensor, e1))
    a22 = dot(e2, mat_vec(tensor, e2))
    a12 = dot(e1, mat_vec(tensor, e2))
    angle = 0.5 * math.atan2(2.0 * a12, a11 - a22)
    u = add(mul(e1, math.cos(angle)), mul(e2, math.sin(angle)))  # the larger of the two
    w = cross(first, u)
    others = sorted(((dot(u, mat_vec(tensor, u)), u), (dot(w, mat_vec(tensor, w)), w)))
    vectors = [others[0][1], others[1][1]]
    vectors.insert(0 if index == 0 else 2, first)
    # Rayleigh quotients: second-order accurate in the vectors, so near-double eigenvalues
    # (where the trigonometric formula loses half its digits) come out to full precision
    refined = sorted((dot(v, mat_vec(tensor, v)), i) for i, v in enumerate(vectors))
    ordered = tuple(vectors[i] for _, i in refined)
    return tuple(v for v, _ in refined), ordered  # type: ignore[return-value]


# -- solids at unit density ------------------------------------------------------------------


@dataclass(frozen=True)
class Solid:
    """Mass properties of a uniform body at density 1: volume, centroid and the second moment
    C = integral of (x - c)(x - c)^T dV about the centroid, all in one frame."""

    volume: float
    centroid: Vec3
    second: Mat3

    def moved(self, rotation: Mat3, translation: Vec3) -> Solid:
        """The same body placed by x -> R x + t."""
        return Solid(self.volume, add(mat_vec(rotation, self.centroid), translation),
                     rotate_tensor(rotation, self.second))

    def scaled(self, scale: Vec3) -> Solid:
        """The body stretched by diag(scale) about the frame's origin (mirroring allowed)."""
        factor = abs(scale[0] * scale[1] * scale[2])
        s = ((scale[0], 0.0, 0.0), (0.0, scale[1], 0.0), (0.0, 0.0, scale[2]))
        return Solid(self.volume * factor, mat_vec(s, self.centroid),
                     mat_scale(rotate_tensor(s, self.second), factor))

    def inertia(self, mass: float) -> Mat3:
        """The inertia tensor about the centroid when the body has ``mass``."""
        if self.volume <= 0:
            return ZERO33
        return tensor_from_second_moment(mat_scale(self.second, mass / self.volume))


def combine(solids: list[Solid]) -> Solid | None:
    """Several bodies of the same density as one (overlaps are counted twice)."""
    volume = sum(s.volume for s in solids)
    if not solids or volume <= 0:
        return None
    centroid = mul(
        (sum(s.volume * s.centroid[0] for s in solids), sum(s.volume * s.centroid[1] for s in solids),
         sum(s.volume * s.centroid[2] for s in solids)), 1.0 / volume)
    second = ZERO33
    for s in solids:
        d = sub(s.centroid, centroid)
        second = mat_add(second, mat_add(s.second, mat_scale(outer(d, d), s.volume)))
    return Solid(volume, centroid, second)


def _diagonal(volume: float, cxx: float, cyy: float, czz: float) -> Solid:
    return Solid(volume, ZERO3, ((cxx, 0.0, 0.0), (0.0, cyy, 0.0), (0.0, 0.0, czz)))


def box_solid(size: Vec3) -> Solid:
    a, b, c = size
    v = a * b * c
    return _diagonal(v, v * a * a / 12.0, v * b * b / 12.0, v * c * c / 12.0)


def cylinder_solid(radius: float, length: float) -> Solid:
    """A cylinder along z, centred on the origin."""
    v = math.pi * radius * radius * length
    return _diagonal(v, v * radius * radius / 4.0, v * radius * radius / 4.0,
                     v * length * length / 12.0)


def sphere_solid(radius: float) -> Solid:
    v = 4.0 / 3.0 * math.pi * radius ** 3
    c = v * radius * radius / 5.0
    return _diagonal(v, c, c, c)


def capsule_solid(radius: float, length: float) -> Solid:
    """A cylinder of ``length`` along z with hemispherical caps (total length + 2 radius)."""
    r, h = radius, length
    v_cyl = math.pi * r * r * h
    v_half = 2.0 / 3.0 * math.pi * r ** 3
    cxx = v_cyl * r * r / 4.0 + 2.0 * v_half * r * r / 5.0
    czz = v_cyl * h * h / 12.0 + 2.0 * v_half * (h * h / 4.0 + 3.0 * r * h / 8.0 + r * r / 5.0)
    return _diagonal(v_cyl + 2.0 * v_half, cxx, cxx, czz)


# -- convex extents: bounds and hull distance ------------------------------------------------

_RIM_SAMPLES = 256
_RIM_TABLE = [(math.cos(t), math.sin(t), math.cos(2 * t), math.sin(2 * t))
              for t in (2.0 * math.pi * k / _RIM_SAMPLES for k in range(_RIM_SAMPLES))]
# the samples in blocks of 16, each probed at its middle sample (at most 8 steps from the others)
_RIM_BLOCK = 16
_RIM_BLOCKS = [_RIM_TABLE[k:k + _RIM_BLOCK] for k in range(0, _RIM_SAMPLES, _RIM_BLOCK)]
_RIM_PROBES = [block[_RIM_BLOCK // 2] for block in _RIM_BLOCKS]
_RIM_REACH = _RIM_BLOCK // 2 * 2.0 * math.pi / _RIM_SAMPLES  # probe to the farthest sample, rad


def _perp(v: Vec3, axis: Vec3) -> Vec3:
    return sub(v, mul(axis, dot(v, axis)))


def _sq_distance(point: Vec3, origin: Vec3, axis: Vec3) -> float:
    perp = _perp(sub(point, origin), axis)
    return dot(perp, perp)


def _rim_max(centre: Vec3, a: Vec3, b: Vec3, radius: float, origin: Vec3, axis: Vec3) -> float:
    """An upper bound (within 0.01%) of the largest squared distance from the line
    (origin, axis) over the circle centre + radius (cos t a + sin t b)."""
    w = _perp(sub(centre, origin), axis)
    ap, bp = _perp(a, axis), _perp(b, axis)
    r2 = radius * radius
    c0 = dot(w, w) + r2 * (dot(ap, ap) + dot(bp, bp)) / 2.0
    c1, s1 = 2.0 * radius * dot(w, ap), 2.0 * radius * dot(w, bp)
    c2, s2 = r2 * (dot(ap, ap) - dot(bp, bp)) / 2.0, r2 * dot(ap, bp)
    coefficients = (c0, c1, s1, c2, s2)
    if all(math.isfinite(x) for x in coefficients):
        # the largest sample, evaluated only in the blocks that may hold it: within a block,
        # f moves at most |f'|max times the distance from its probe (plus rounding)
        probes = [c0 + c1 * c + s1 * s + c2 * cc + s2 * ss for c, s, cc, ss in _RIM_PROBES]
        top = max(probes)
        slack = ((abs(c1) + abs(s1) + 2.0 * (abs(c2) + abs(s2))) * _RIM_REACH
                 + 1e-9 * sum(abs(x) for x in coefficients))
        best = max(top, *(c0 + c1 * c + s1 * s + c2 * cc + s2 * ss
                          for probe, block in zip(probes, _RIM_BLOCKS) if probe + slack >= top
                          for c, s, cc, ss in block))
    else:
        best = max(c0 + c1 * c + s1 * s + c2 * cc + s2 * ss for c, s, cc, ss in _RIM_TABLE)
    # the maximum is a critical point (f' = 0) within half a step of a sample, so sampling
    # misses at most |f''|max (step / 2)^2 / 2
    curvature = abs(c1) + abs(s1) + 4.0 * (abs(c2) + abs(s2))
    return best + curvature * (math.pi / _RIM_SAMPLES) ** 2 / 2.0


class Extent:
    """A convex body placed in the link frame (rotation R, translation t)."""

    def __init__(self, rotation: Mat3, translation: Vec3):
        self.rotation = rotation
        self.translation = translation
        self._inverse = transpose(rotation)

    def support(self, direction: Vec3) -> Vec3:  # pragma: no cover - abstract
        raise NotImplementedError

    def max_sq_distance(self, origin: Vec3, axis: Vec3) -> float:  # pragma: no cover
        raise NotImplementedError

    def _local(self, direction: Vec3) -> Vec3:
        return mat_vec(self._inverse, direction)

    def _world(self, point: Vec3) -> Vec3:
        return add(mat_vec(self.rotation, point), self.translation)


class BoxExtent(Extent):
    def __init__(self, size: Vec3, rotation: Mat3 = IDENTITY, translation: Vec3 = ZERO3):
        super().__init__(rotation, translation)
        self.half = mul(size, 0.5)
        hx, hy, hz = self.half
        self.vertices = [self._world((sx * hx, sy * hy, sz * hz))
                         for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]

    def support(self, direction: Vec3) -> Vec3:
        d = self._local(direction)
        return self._world(tuple(h if c >= 0 else -h for c, h in zip(d, self.half)))  # type: ignore[arg-type]

    def max_sq_distance(self, origin: Vec3, axis: Vec3) -> float:
        return max(_sq_distance(v, origin, axis) for v in self.vertices)


class SphereExtent(Extent):
    def __init__(self, radius: float, rotation: Mat3 = IDENTITY, translation: Vec3 = ZERO3):
        super().__init__(rotation, translation)
        self.radius = radius

    def support(self, direction: Vec3) -> Vec3:
        return add(self.translation, mul(unit(direction), self.radius))

    def max_sq_distance(self, origin: Vec3, axis: Vec3) -> float:
        reach = math.sqrt(_sq_distance(self.translation, origin, axis)) + self.radius
        return reach * reach


class CylinderExtent(Extent):
    """A cylinder along its local z; ``capsule`` adds hemispherical caps."""

    def __init__(self, radius: float, length: float, rotation: Mat3 = IDENTITY,
                 translation: Vec3 = ZERO3, capsule: bool = False):
        super().__init__(rotation, translation)
        self.radius, self.length, self.capsule = radius, length, capsule
        self.ends = (self._world((0.0, 0.0, -length / 2)), self._world((0.0, 0.0, length / 2)))

    def support(self, direction: Vec3) -> Vec3:
        d = self._local(direction)
        z = self.length / 2 if d[2] >= 0 else -self.length / 2
        if self.capsule:
            return add(self._world((0.0, 0.0, z)), mul(unit(direction), self.radius))
        radial = math.hypot(d[0], d[1])
        if radial > 0:
            return self._world((self.radius * d[0] / radial, self.radius * d[1] / radial, z))
        return self._world((self.radius, 0.0, z))

    def max_sq_distance(self, origin: Vec3, axis: Vec3) -> float:
        if self.capsule:
            reach = max(math.sqrt(_sq_distance(e, origin, axis)) for e in self.ends) + self.radius
            return reach * reach
        a = mat_vec(self.rotation, (1.0, 0.0, 0.0))
        b = mat_vec(self.rotation, (0.0, 1.0, 0.0))
        return max(_rim_max(e, a, b, self.radius, origin, axis) for e in self.ends)


class PointsExtent(Extent):
    """The convex hull of points (a mesh's hull vertices), already in the link frame."""

    def __init__(self, points: list[Vec3]):
        super().__init__(IDENTITY, ZERO3)
        self.points = points

    def support(self, direction: Vec3) -> Vec3:
        dx, dy, dz = direction
        return max(self.points, key=lambda p: p[0] * dx + p[1] * dy + p[2] * dz)

    def max_sq_distance(self, origin: Vec3, axis: Vec3) -> float:
        return max(_sq_distance(p, origin, axis) for p in self.points)


def max_sq_distance(extents: list[Extent], origin: Vec3, axis: Vec3) -> float:
    """Largest squared distance from the line (origin, unit axis) over the union of extents."""
    return max(e.max_sq_distance(origin, axis) for e in extents)


# the non-empty subsets of 1-4 points, as index lists, in the order of their bit masks
_SUBSETS = {n: [[i for i in range(n) if mask >> i & 1] for mask in range(1, 1 << n)]
            for n in range(1, 5)}


def _closest_on_simplex(points: list[Vec3]) -> tuple[Vec3, list[Vec3]]:
    """The point of the convex hull of 1-4 points closest to the origin, and the smallest
    subset of points whose hull contains it (brute force over the faces)."""
    best_d2 = 0.0
    best: tuple[Vec3, list[int]] | None = None
    for indices in _SUBSETS[len(points)]:
        base = points[indices[0]]
        bx, by, bz = base
        if len(indices) == 1:
            point = base
        elif len(indices) == 2:  # a segment: _solve's one-unknown case, written out
            p = points[indices[1]]
            ex, ey, ez = p[0] - bx, p[1] - by, p[2] - bz
            g = ex * ex + ey * ey + ez * ez
            scale = abs(g)
            if scale == 0.0 or scale <= 1e-12 * scale:
                continue
            w = -(ex * bx + ey * by + ez * bz) / g
            if w < -1e-12 or w > 1 + 1e-12:
                continue
            point = (bx + ex * w, by + ey * w, bz + ez * w)
        else:
            edges = [(p[0] - bx, p[1] - by, p[2] - bz) for p in (points[i] for i in indices[1:])]
            # minimise |base + sum w_i e_i|: Gram system G w = -E^T base
            gram = [[a[0] * b[0] + a[1] * b[1] + a[2] * b[2] for b in edges] for a in edges]
            rhs = [-(e[0] * bx + e[1] * by + e[2] * bz) for e in edges]
            weights = _solve(gram, rhs)
            if weights is None:
                continue
            if any(w < -1e-12 for w in weights) or sum(weights) > 1 + 1e-12:
                continue
            x, y, z = base
            for w, e in zip(weights, edges):
                x, y, z = x + e[0] * w, y + e[1] * w, z + e[2] * w
            point = (x, y, z)
        d2 = point[0] * point[0] + point[1] * point[1] + point[2] * point[2]
        if best is None or d2 < best_d2 - 1e-30:
            best_d2, best = d2, (point, indices)
    assert best is not None
    return best[0], [points[i] for i in best[1]]


def _strictly_inside(points: list[Vec3]) -> bool:
    """Whether the origin lies inside the tetrahedron of four points, away from its faces (each
    barycentric weight above 1e-9): there ``_closest_on_simplex`` finds the whole tetrahedron
    closest (every face is farther than the rounding of the inside point), so GJK ends."""
    bx, by, bz = points[0]
    edges = [(p[0] - bx, p[1] - by, p[2] - bz) for p in points[1:]]
    gram = [[a[0] * b[0] + a[1] * b[1] + a[2] * b[2] for b in edges] for a in edges]
    rhs = [-(e[0] * bx + e[1] * by + e[2] * bz) for e in edges]
    weights = _solve(gram, rhs)
    return weights is not None and all(w > 1e-9 for w in weights) and sum(weights) < 1 - 1e-9


def _solve(a: list[list[float]], b: list[float]) -> list[float] | None:
    """Gaussian elimination with partial pivoting; None when (nearly) singular."""
    n = len(b)
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    scale = max((abs(x) for row in a for x in row), default=0.0)
    if scale == 0.0:
        return None
    for col in range(n):
        pivot, largest = col, abs(m[col][col])
        for r in range(col + 1, n):
            if abs(m[r][col]) > largest:
                pivot, largest = r, abs(m[r][col])
        if largest <= 1e-12 * scale:
            return None
        m[col], m[pivot] = m[pivot], m[col]
        row = m[col]
        for r in range(n):
            if r != col:
                target = m[r]
                f = target[col] / row[col]
                for c in range(col, n + 1):
                    target[c] -= f * row[c]
    return [m[i][n] / m[i][i] for i in range(n)]


def _hull_offset(point: Vec3, extents: list[Extent], tolerance: float = 1e-9) -> Vec3:
    """closest hull point - ``point`` (zero inside), by the Gilbert-Johnson-Keerthi algorithm
    on the shapes' support functions."""

    px, py, pz = point
    only = extents[0] if len(extents) == 1 else None  # the usual link: one shape, no max

    def support(direction: Vec3) -> Vec3:
        if only is not None:
            best = only.support(direction)
        else:
            dx, dy, dz = direction
            best = max((e.support(direction) for e in extents),
                       key=lambda p: p[0] * dx + p[1] * dy + p[2] * dz)
        return (best[0] - px, best[1] - py, best[2] - pz)

    v = support((1.0, 0.0, 0.0))
    simplex = [v]
    for _ in range(100):
        vv = dot(v, v)
        if vv <= 1e-24:
            return ZERO3
        w = support((-v[0], -v[1], -v[2]))
        # v.v - v.w is an upper bound of |v|^2 - distance^2
        if vv - dot(v, w) <= tolerance * max(vv, 1e-30):
            break
        if any(dot(d, d) <= 1e-24 for d in (sub(w, s) for s in simplex)):
            break
        simplex.append(w)
        if len(simplex) == 4 and _strictly_inside(simplex):
            return ZERO3  # what the search over its faces below ends in, without the search
        v, simplex = _closest_on_simplex(simplex)
        if len(simplex) == 4:
            return ZERO3
    return v


def hull_distance(point: Vec3, extents: list[Extent]) -> float:
    """Distance from ``point`` to the convex hull of the union of ``extents`` (0 inside)."""
    return norm(_hull_offset(point, extents))


def hull_escape(point: Vec3, extents: list[Extent]) -> tuple[float, float]:
    """How far ``point`` lies outside the convex hull of ``extents``, and the hull's thickness
    along that direction (the width of the body the point has left; 0, 0 inside)."""
    offset = _hull_offset(point, extents)
    distance = norm(offset)
    if distance <= 0:
        return 0.0, 0.0
    n = mul(offset, -1.0 / distance)  # from the hull towards the point
    high = max(dot(e.support(n), n) for e in extents)
    low = -max(dot(e.support(mul(n, -1.0)), mul(n, -1.0)) for e in extents)
    return distance, high - low
