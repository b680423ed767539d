"""Forward kinematics with numpy: URDF poses (xyz + fixed-axis roll-pitch-yaw) as 4x4
homogeneous transforms, joint motions, and the pose of every joint frame and of the tip of a
:class:`~urdftool.kinematics.chain.Chain` at a configuration.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from urdftool.kinematics.chain import Chain
    from urdftool.model import Pose


def rpy_matrix(rpy) -> np.ndarray:
    """URDF's rotation: roll about x, then pitch about y, then yaw about z (fixed axes),
    i.e. Rz(yaw) @ Ry(pitch) @ Rx(roll)."""
    roll, pitch, yaw = (float(v) for v in rpy)
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])


def pose_matrix(pose: Pose) -> np.ndarray:
    """The 4x4 transform of a URDF <origin>."""
    transform = np.eye(4)
    transform[:3, :3] = rpy_matrix(pose.rpy)
    transform[:3, 3] = [float(v) for v in pose.xyz]
    return transform


def rotation_about(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation by ``angle`` about the unit vector ``axis`` (Rodrigues)."""
    x, y, z = axis
    c, s = math.cos(angle), math.sin(angle)
    v = 1.0 - c
    return np.array([
        [c + x * x * v, x * y * v - z * s, x * z * v + y * s],
        [y * x * v + z * s, c + y * y * v, y * z * v - x * s],
        [z * x * v - y * s, z * y * v + x * s, c + z * z * v],
    ])


def joint_motion(revolute: bool, axis: np.ndarray, value: float) -> np.ndarray:
    """The 4x4 motion of a joint at ``value``: a rotation about, or a translation along, its
    unit axis (expressed in the joint frame)."""
    transform = np.eye(4)
    if revolute:
        transform[:3, :3] = rotation_about(axis, value)
    else:
        transform[:3, 3] = axis * value
    return transform


def joint_frames(chain: Chain, q) -> tuple[list[np.ndarray], np.ndarray]:
    """Poses in the base frame of every moving joint's frame (after its origin, before its
    motion) and of the tip, at the independent variables ``q``."""
    values = chain.joint_values(q)
    current = np.eye(4)
    frames = []
    for joint, value in zip(chain.joints, values):
        current = current @ joint.origin
        frames.append(current)
        current = current @ joint_motion(joint.revolute, joint.axis, value)
    return frames, current @ chain.tool


def forward(chain: Chain, q) -> np.ndarray:
    """The 4x4 pose of the tip link in the base link's frame at ``q``."""
    return joint_frames(chain, q)[1]
