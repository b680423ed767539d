"""Denavit-Hartenberg parameters of a serial chain, standard and modified (Craig), with the base
and tool transforms that make ``base @ A_1(q_1) @ ... @ A_n(q_n) @ tool`` equal the URDF's
forward kinematics, and a self-check of that over random configurations.

Conventions (the joint variable ``q_i`` is the joint's own position, as in the URDF):

- standard: ``A_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``; joint i moves about/along
  ``z_{i-1}``; frame i sits on the axis of joint i+1.
- modified: ``A_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i)``; row i holds
  ``alpha_{i-1}, a_{i-1}, theta_i, d_i``; frame i sits on the axis of joint i.

The variable adds to ``theta`` (revolute, continuous) or ``d`` (prismatic). Every joint's DH z
axis points along its URDF axis, so +q in the URDF is +theta (or +d) in the table.

Degenerate geometry is resolved deterministically, and each choice is reported as a note:
parallel axes take the common normal through the previous frame's origin (d = 0), collinear
axes keep the previous x, intersecting axes take x = z_prev x z_next, frame 0 lies on the first
axis at the foot of the base origin with x along the base x axis projected (the base y axis if
that is degenerate), and the last frame points its x at the tip origin (alpha = 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from urdftool.kinematics.chain import Chain

PARALLEL_TOLERANCE = 1e-8  # |z_a x z_b| below this: parallel (sqrt of the float epsilon)
NEARLY_PARALLEL = 1e-4  # below this (and above the tolerance): exact but ill-conditioned
POINT_TOLERANCE = 1e-9  # metres: lines closer than this intersect, a point this near is on it
SNAP = 1e-15  # parameters and matrix entries smaller than this are written as 0


@dataclass(frozen=True)
class DHRow:
    joint: str
    type: str  # revolute, continuous, prismatic
    theta: float
    d: float
    a: float
    alpha: float
    variable: str  # what adds to theta or d: "q_<joint>", or the mimic expression

    @property
    def revolute(self) -> bool:
        return self.type != "prismatic"


@dataclass
class DHResult:
    convention: str
    base: np.ndarray
    tool: np.ndarray
    rows: list[DHRow]
    notes: list[str] = field(default_factory=list)

    def transforms(self, values) -> list[np.ndarray]:
        """A_i at the joint positions ``values`` (one per row)."""
        out = []
        for row, value in zip(self.rows, values):
            theta = row.theta + value if row.revolute else row.theta
            d = row.d if row.revolute else row.d + value
            out.append(dh_matrix(self.convention, theta, d, row.a, row.alpha))
        return out

    def forward(self, values) -> np.ndarray:
        """base @ prod A_i(values) @ tool."""
        result = self.base
        for a in self.transforms(values):
            result = result @ a
        return result @ self.tool

    def as_dict(self) -> dict:
        return {"convention": self.convention,
                "base": matrix_list(self.base), "tool": matrix_list(self.tool),
                "rows": [{"joint": r.joint, "type": r.type, "theta": r.theta, "d": r.d,
                          "a": r.a, "alpha": r.alpha} for r in self.rows]}


def _rz(theta: float) -> np.ndarray:
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def _rx(alpha: float) -> np.ndarray:
    c, s = math.cos(alpha), math.sin(alpha)
    return np.array([[1.0, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]])


def _t(x: float = 0.0, z: float = 0.0) -> np.ndarray:
    out = np.eye(4)
    out[0, 3], out[2, 3] = x, z
    return out


def dh_matrix(convention: str, theta: float, d: float, a: float, alpha: float) -> np.ndarray:
    """One row's transform: standard Rz Tz Tx Rx, modified Rx Tx Rz Tz."""
    if convention == "standard":
        return _rz(theta) @ _t(z=d) @ _t(x=a) @ _rx(alpha)
    return _rx(alpha) @ _t(x=a) @ _rz(theta) @ _t(z=d)


def snap(value: float) -> float:
    value = float(value)
    return 0.0 if abs(value) < SNAP else value


def matrix_list(matrix: np.ndarray) -> list[list[float]]:
    return [[snap(v) for v in row] for row in matrix]


def _angle(a: np.ndarray, b: np.ndarray, about: np.ndarray) -> float:
    """Signed angle from a to b about the unit vector ``about`` (a, b perpendicular to it)."""
    angle = math.atan2(float(np.dot(np.cross(a, b), about)), float(np.dot(a, b)))
    return math.pi if angle <= -math.pi + 1e-15 else angle


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _orthogonal(v: np.ndarray, z: np.ndarray) -> np.ndarray:
    """v without its component along z, normalised."""
    return _unit(v - np.dot(v, z) * z)


def _frame(origin: np.ndarray, x: np.ndarray, z: np.ndarray) -> np.ndarray:
    out = np.eye(4)
    out[:3, 0], out[:3, 1], out[:3, 2], out[:3, 3] = x, np.cross(z, x), z, origin
    return out


@dataclass
class _Normal:
    foot_a: np.ndarray  # on line A
    foot_b: np.ndarray  # on line B
    x: np.ndarray  # unit, perpendicular to both (from A towards B when they are apart)
    kind: str  # skew, intersecting, parallel, collinear
    sine: float


def common_normal(pa, za, pb, zb, x_prev) -> _Normal:
    """The common normal of lines A (through pa, along za) and B. Parallel lines take the normal
    through pa; collinear ones keep ``x_prev`` (made perpendicular to zb)."""
    cross = np.cross(za, zb)
    sine = float(np.linalg.norm(cross))
    if sine > PARALLEL_TOLERANCE:
        w = pa - pb
        b, d, e = float(np.dot(za, zb)), float(np.dot(za, w)), float(np.dot(zb, w))
        denom = 1.0 - b * b
        t, u = (b * e - d) / denom, (e - b * d) / denom
        foot_a, foot_b = pa + t * za, pb + u * zb
        x = cross / sine
        gap = float(np.dot(foot_b - foot_a, x))
        if abs(gap) > POINT_TOLERANCE and gap < 0:
            x = -x
        return _Normal(foot_a, foot_b, x, "skew" if abs(gap) > POINT_TOLERANCE else "intersecting",
                       sine)
    foot_a = pa
    foot_b = pb + np.dot(pa - pb, zb) * zb
    v = foot_b - foot_a
    v = v - np.dot(v, za) * za
    if np.linalg.norm(v) > POINT_TOLERANCE:
        return _Normal(foot_a, foot_b, _orthogonal(v, zb), "parallel", sine)
    return _Normal(foot_a, foot_b, _orthogonal(x_prev, zb), "collinear", sine)


def _zero_geometry(chain: Chain):
    """Axis lines (point, unit direction) of every joint and the tip pose, in the base frame,
    with every joint at position 0."""
    current, points, axes = np.eye(4), [], []
    for joint in chain.joints:
        current = current @ joint.origin
        points.append(current[:3, 3].copy())
        axes.append(_unit(current[:3, :3] @ joint.axis))
    return points, axes, current @ chain.tool


def _base_x(z: np.ndarray) -> tuple[np.ndarray, str]:
    for vector, name in ((np.array([1.0, 0, 0]), "x"), (np.array([0, 1.0, 0]), "y")):
        rest = vector - np.dot(vector, z) * z
        if np.linalg.norm(rest) > 1e-6:
            return _unit(rest), name
    raise AssertionError("unreachable: z is a unit vector")


def _variable(chain: Chain, index: int) -> str:
    joint = chain.joints[index]
    if not joint.mimic:
        return f"q_{joint.name}"
    text = f"{joint.multiplier:g}*q_{joint.leader}"
    if joint.offset:
        text += f" {'+' if joint.offset > 0 else '-'} {abs(joint.offset):g}"
    return text


def _pair_note(kind: str, sine: float, first: str, second: str, convention: str) -> str | None:
    if kind == "parallel":
        where = ("through the previous frame's origin" if convention == "standard"
                 else "where the previous normal meets the first axis")
        return (f"'{first}' and '{second}' have parallel axes: the common normal is not unique; "
                f"chose the one {where} (d = 0)")
    if kind == "collinear":
        return (f"'{first}' and '{second}' have collinear axes: x kept from the previous frame "
                "(a = 0, alpha = 0)")
    if kind == "intersecting":
        return f"'{first}' and '{second}' have intersecting axes: x = z({first}) x z({second}) (a = 0)"
    if sine < NEARLY_PARALLEL:
        return (f"'{first}' and '{second}' have nearly parallel axes (angle {sine:.3g} rad): "
                "the common normal lies far away and d, a are large and ill-conditioned; "
                "are rotations in the URDF rounded (e.g. 1.5708 for pi/2)?")
    return None


def extract_dh(chain: Chain, convention: str = "standard") -> DHResult:
    if convention not in ("standard", "modified"):
        raise ValueError(convention)
    points, axes, tip = _zero_geometry(chain)
    names = [j.name for j in chain.joints]
    n = len(names)
    notes: list[str] = []
    tip_point = tip[:3, 3]

    x0, which = _base_x(axes[0])
    origin0 = points[0] + np.dot(-points[0], axes[0]) * axes[0]
    base = _frame(origin0, x0, axes[0])
    notes.append(f"frame 0: on the axis of '{names[0]}' at the foot of the base origin, x along "
                 f"the base {which} axis projected")

    # frames[i]: (origin, x, z) of DH frame i; params[i]: (theta, d, a, alpha) of row i+1
    params: list[tuple[float, float, float, float]] = []
    origin, x, z = origin0, x0, axes[0]
    if convention == "standard":
        for i in range(1, n + 1):
            if i < n:
                normal = common_normal(origin, z, points[i], axes[i], x)
                note = _pair_note(normal.kind, normal.sine, names[i - 1], names[i], convention)
                new_z = axes[i]
            else:
                foot = origin + np.dot(tip_point - origin, z) * z
                away = tip_point - foot
                away = away - np.dot(away, z) * z
                far = np.linalg.norm(away) > POINT_TOLERANCE
                normal = _Normal(foot, foot + away if far else foot,
                                 _unit(away) if far else x, "", 1.0)
                note, new_z = None, z
            if note:
                notes.append(note)
            d = float(np.dot(normal.foot_a - origin, z))
            theta = _angle(x, normal.x, z)
            a = float(np.dot(normal.foot_b - normal.foot_a, normal.x))
            alpha = _angle(z, new_z, normal.x)
            params.append((theta, d, a, alpha))
            origin, x, z = normal.foot_b, normal.x, new_z
    else:
        prev_origin, prev_x, prev_z = origin0, x0, axes[0]
        foot_prev = origin0  # where the previous common normal meets the current axis
        for i in range(n):
            z = axes[i]
            if i + 1 < n:
                normal = common_normal(foot_prev, z, points[i + 1], axes[i + 1], prev_x)
                note = _pair_note(normal.kind, normal.sine, names[i], names[i + 1], convention)
            else:
                foot = foot_prev + np.dot(tip_point - foot_prev, z) * z
                away = tip_point - foot
                away = away - np.dot(away, z) * z
                far = np.linalg.norm(away) > POINT_TOLERANCE
                normal = _Normal(foot, foot + away if far else foot,
                                 _unit(away) if far else _orthogonal(prev_x, z), "", 1.0)
                note = None
            if note:
                notes.append(note)
            alpha = _angle(prev_z, z, prev_x)
            a = float(np.dot(foot_prev - prev_origin, prev_x))
            theta = _angle(prev_x, normal.x, z)
            d = float(np.dot(normal.foot_a - foot_prev, z))
            params.append((theta, d, a, alpha))
            prev_origin, prev_x, prev_z = normal.foot_a, normal.x, z
            foot_prev = normal.foot_b

    rows = [DHRow(joint.name, joint.type, *(snap(v) for v in p), _variable(chain, i))
            for i, (joint, p) in enumerate(zip(chain.joints, params))]
    result = DHResult(convention, base, np.eye(4), rows, notes)
    at_zero = result.forward(np.zeros(n))
    result.tool = np.linalg.inv(at_zero) @ tip
    result.base = np.array(matrix_list(base))
    result.tool = np.array(matrix_list(result.tool))
    for joint in chain.joints:
        if joint.mimic:
            notes.append(f"'{joint.name}' mimics '{joint.leader}': its variable is "
                         f"{_variable(chain, chain.joints.index(joint))}")
    folded = [name for joint in chain.joints for name in joint.folded] + list(chain.tool_folded)
    if folded:
        notes.append(f"fixed joints folded into the neighbouring transforms: {', '.join(folded)}")
    return result


def self_check(chain: Chain, result: DHResult, count: int = 100, seed: int = 0) -> float:
    """The largest difference (any entry of the 4x4 pose: metres or rotation-matrix units)
    between the DH product and the URDF's forward kinematics, over ``count`` random
    configurations within the limits (and the zero configuration). All configurations advance
    together joint by joint (one pass over a chain of any length)."""
    rng = np.random.default_rng(seed)
    samples = np.vstack([np.zeros((1, chain.n)), chain.sample(rng, count)])
    size = len(samples)
    urdf = np.broadcast_to(np.eye(4), (size, 4, 4)).copy()
    dh = np.broadcast_to(result.base, (size, 4, 4)).copy()
    for joint, row in zip(chain.joints, result.rows):
        values = joint.multiplier * samples[:, joint.variable] + joint.offset
        urdf = urdf @ joint.origin @ _joint_motions(joint.revolute, joint.axis, values)
        if row.revolute:
            theta, d = row.theta + values, np.full(size, row.d)
        else:
            theta, d = np.full(size, row.theta), row.d + values
        dh = dh @ _dh_matrices(result.convention, theta, d, row.a, row.alpha)
    return float(np.max(np.abs(dh @ result.tool - urdf @ chain.tool)))


def _joint_motions(revolute: bool, axis: np.ndarray, values: np.ndarray) -> np.ndarray:
    """``fk.joint_motion`` at each of ``values``: (len(values), 4, 4)."""
    out = np.broadcast_to(np.eye(4), (len(values), 4, 4)).copy()
    if not revolute:
        out[:, :3, 3] = np.outer(values, axis)
        return out
    x, y, z = axis
    c, s = np.cos(values), np.sin(values)
    v = 1.0 - c
    out[:, 0, 0], out[:, 0, 1], out[:, 0, 2] = c + x * x * v, x * y * v - z * s, x * z * v + y * s
    out[:, 1, 0], out[:, 1, 1], out[:, 1, 2] = y * x * v + z * s, c + y * y * v, y * z * v - x * s
    out[:, 2, 0], out[:, 2, 1], out[:, 2, 2] = z * x * v - y * s, z * y * v + x * s, c + z * z * v
    return out


def _dh_matrices(convention: str, theta: np.ndarray, d: np.ndarray, a: float,
                 alpha: float) -> np.ndarray:
    """``dh_matrix`` at each (theta, d), multiplied out: (len(theta), 4, 4)."""
    ct, st = np.cos(theta), np.sin(theta)
    ca, sa = math.cos(alpha), math.sin(alpha)
    out = np.zeros((len(theta), 4, 4))
    out[:, 3, 3] = 1.0
    if convention == "standard":  # Rz(theta) Tz(d) Tx(a) Rx(alpha)
        out[:, 0] = np.stack([ct, -st * ca, st * sa, a * ct], axis=1)
        out[:, 1] = np.stack([st, ct * ca, -ct * sa, a * st], axis=1)
        out[:, 2, 1], out[:, 2, 2], out[:, 2, 3] = sa, ca, d
    else:  # Rx(alpha) Tx(a) Rz(theta) Tz(d)
        out[:, 0, 0], out[:, 0, 1], out[:, 0, 3] = ct, -st, a
        out[:, 1] = np.stack([st * ca, ct * ca, np.full_like(ct, -sa), -sa * d], axis=1)
        out[:, 2] = np.stack([st * sa, ct * sa, np.full_like(ct, ca), ca * d], axis=1)
    return out
