"""Rigid transforms in pure Python (no numpy: SDF input is read by ``check``, which must start
fast). A ``Transform`` maps child-frame coordinates to parent-frame coordinates.

``rpy`` is kept as written when a transform is only ever composed with pure translations, so
that a value such as ``1.5708`` is written back unchanged rather than as ``1.5708000000000002``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from urdftool.physics.inertia import rpy_matrix

Vec3 = tuple[float, float, float]
Mat3 = tuple[Vec3, Vec3, Vec3]

IDENTITY_R: Mat3 = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def quat_matrix(x: float, y: float, z: float, w: float) -> Mat3:
    """Rotation matrix of a quaternion (normalised first)."""
    n = math.sqrt(x * x + y * y + z * z + w * w)
    if n == 0.0:
        return IDENTITY_R
    x, y, z, w = x / n, y / n, z / n, w / n
    return ((1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
            (2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
            (2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)))


def matrix_quat(r: Mat3) -> tuple[float, float, float, float]:
    """Unit quaternion (w, x, y, z) of a rotation matrix (Shepperd: the largest of w, x, y, z
    is found first and divides the others, so no branch loses precision)."""
    trace = r[0][0] + r[1][1] + r[2][2]
    cases = (trace, r[0][0], r[1][1], r[2][2])
    k = max(range(4), key=cases.__getitem__)
    if k == 0:
        s = 2.0 * math.sqrt(1.0 + trace)
        q = (s / 4, (r[2][1] - r[1][2]) / s, (r[0][2] - r[2][0]) / s, (r[1][0] - r[0][1]) / s)
    elif k == 1:
        s = 2.0 * math.sqrt(max(0.0, 1.0 + r[0][0] - r[1][1] - r[2][2]))
        q = ((r[2][1] - r[1][2]) / s, s / 4, (r[0][1] + r[1][0]) / s, (r[0][2] + r[2][0]) / s)
    elif k == 2:
        s = 2.0 * math.sqrt(max(0.0, 1.0 - r[0][0] + r[1][1] - r[2][2]))
        q = ((r[0][2] - r[2][0]) / s, (r[0][1] + r[1][0]) / s, s / 4, (r[1][2] + r[2][1]) / s)
    else:
        s = 2.0 * math.sqrt(max(0.0, 1.0 - r[0][0] - r[1][1] + r[2][2]))
        q = ((r[1][0] - r[0][1]) / s, (r[0][2] + r[2][0]) / s, (r[1][2] + r[2][1]) / s, s / 4)
    n = math.sqrt(sum(v * v for v in q))
    return tuple(v / n for v in q)  # type: ignore[return-value]


def matrix_rpy(r: Mat3) -> Vec3:
    """Roll, pitch, yaw of a rotation matrix (inverse of ``rpy_matrix``), without snapping.

    The pitch comes from atan2 of -r20 over the norm of the four entries that carry cos(pitch)
    (well conditioned even at pitch = ±pi/2 - 1e-7); roll and yaw from the half-angle sums of
    the quaternion, which stay exact where asin and the r10/r00, r21/r22 ratios do not."""
    w, x, y, z = matrix_quat(r)
    cos_pitch = math.sqrt((r[0][0] ** 2 + r[1][0] ** 2 + r[2][1] ** 2 + r[2][2] ** 2) / 2)
    pitch = math.atan2(-r[2][0], cos_pitch)
    # roll = zA - zB, yaw = zA + zB with zA = atan2(x + z, w - y), zB = atan2(z - x, w + y)
    za = math.atan2(x + z, w - y) if (x + z or w - y) else 0.0
    zb = math.atan2(z - x, w + y) if (z - x or w + y) else 0.0
    roll, yaw = za - zb, za + zb
    roll = roll - 2 * math.pi if roll > math.pi else roll + 2 * math.pi if roll < -math.pi else roll
    yaw = yaw - 2 * math.pi if yaw > math.pi else yaw + 2 * math.pi if yaw < -math.pi else yaw
    return (roll, pitch, yaw)


def matmul(a: Mat3, b: Mat3) -> Mat3:
    return tuple(tuple(a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j]
                       for j in range(3)) for i in range(3))  # type: ignore[return-value]


def transpose(a: Mat3) -> Mat3:
    return ((a[0][0], a[1][0], a[2][0]), (a[0][1], a[1][1], a[2][1]), (a[0][2], a[1][2], a[2][2]))


def apply(a: Mat3, v: Vec3) -> Vec3:
    return (a[0][0] * v[0] + a[0][1] * v[1] + a[0][2] * v[2],
            a[1][0] * v[0] + a[1][1] * v[1] + a[1][2] * v[2],
            a[2][0] * v[0] + a[2][1] * v[1] + a[2][2] * v[2])


def _clean(value: float) -> float:
    return value + 0.0  # -0.0 -> 0.0


@dataclass(frozen=True)
class Transform:
    xyz: Vec3 = (0.0, 0.0, 0.0)
    rot: Mat3 = IDENTITY_R
    rpy_hint: Vec3 | None = (0.0, 0.0, 0.0)  # the rpy as written, while still exact

    @staticmethod
    def from_rpy(xyz: Vec3, rpy: Vec3) -> Transform:
        return Transform(tuple(_clean(v) for v in xyz), rpy_matrix(rpy),  # type: ignore[arg-type]
                         tuple(_clean(v) for v in rpy))  # type: ignore[arg-type]

    @staticmethod
    def from_quat(xyz: Vec3, quat_xyzw: tuple[float, float, float, float]) -> Transform:
        return Transform(tuple(_clean(v) for v in xyz), quat_matrix(*quat_xyzw), None)  # type: ignore[arg-type]

    @property
    def pure_translation(self) -> bool:
        return self.rot == IDENTITY_R

    @property
    def rpy(self) -> Vec3:
        if self.rpy_hint is not None:
            return self.rpy_hint
        return tuple(_clean(v) for v in matrix_rpy(self.rot))  # type: ignore[return-value]

    def __mul__(self, other: Transform) -> Transform:
        rotated = apply(self.rot, other.xyz)
        xyz = tuple(_clean(self.xyz[i] + rotated[i]) for i in range(3))
        if self.pure_translation:
            return Transform(xyz, other.rot, other.rpy_hint)  # type: ignore[arg-type]
        if other.pure_translation:
            return Transform(xyz, self.rot, self.rpy_hint)  # type: ignore[arg-type]
        return Transform(xyz, matmul(self.rot, other.rot), None)  # type: ignore[arg-type]

    def inverse(self) -> Transform:
        rt = transpose(self.rot)
        moved = apply(rt, self.xyz)
        xyz = tuple(_clean(-v) for v in moved)
        if self.pure_translation:
            return Transform(xyz, IDENTITY_R, (0.0, 0.0, 0.0))  # type: ignore[arg-type]
        return Transform(xyz, rt, None)  # type: ignore[arg-type]

    def seen_from(self, frame: Transform) -> Transform:
        """This pose expressed in ``frame`` (``frame.inverse() * self``), exact when equal."""
        if self == frame:
            return IDENTITY
        if frame.pure_translation:
            return Transform(tuple(_clean(self.xyz[i] - frame.xyz[i]) for i in range(3)),  # type: ignore[arg-type]
                             self.rot, self.rpy_hint)
        return frame.inverse() * self

    def rotate(self, vector: Vec3) -> Vec3:
        return tuple(_clean(v) for v in apply(self.rot, vector))  # type: ignore[return-value]

    @property
    def is_identity(self) -> bool:
        return self.xyz == (0.0, 0.0, 0.0) and self.pure_translation


IDENTITY = Transform()
