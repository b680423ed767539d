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


def matrix_rpy(r: Mat3) -> Vec3:
    """Roll, pitch, yaw of a rotation matrix (inverse of ``rpy_matrix``)."""
    sp = -r[2][0]
    if sp >= 1.0 - 1e-12 or sp <= -1.0 + 1e-12:  # gimbal lock: put everything in yaw
        pitch = math.copysign(math.pi / 2, sp)
        roll = 0.0
        yaw = math.atan2(-r[0][1], r[1][1])
        return (roll, pitch, yaw)
    pitch = math.asin(max(-1.0, min(1.0, sp)))
    roll = math.atan2(r[2][1], r[2][2])
    yaw = math.atan2(r[1][0], r[0][0])
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
