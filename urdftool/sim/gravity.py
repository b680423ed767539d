"""Gravity torques at the home pose from pinocchio's RNEA: what each joint must deliver to hold
the pose with the base held still, to set against the URDF's effort limit."""

from __future__ import annotations

import math


def gravity_torques(urdf_text: str, home: dict[str, float]) -> dict[str, float]:
    """Joint name -> generalized gravity torque (N·m, or N for prismatic) at ``home`` (other
    joints at zero), base fixed. Joints with more than one degree of freedom are left out."""
    import numpy as np
    import pinocchio

    model = pinocchio.buildModelFromXML(urdf_text)
    data = model.createData()
    q = pinocchio.neutral(model)
    for joint_id in range(1, model.njoints):
        name = model.names[joint_id]
        joint = model.joints[joint_id]
        value = home.get(name, 0.0)
        if joint.nq == 1:
            q[joint.idx_q] = value
        elif joint.nq == 2 and joint.nv == 1:  # continuous: cos, sin
            q[joint.idx_q], q[joint.idx_q + 1] = math.cos(value), math.sin(value)
    tau = pinocchio.rnea(model, data, q, np.zeros(model.nv), np.zeros(model.nv))
    return {model.names[j]: float(tau[model.joints[j].idx_v])
            for j in range(1, model.njoints) if model.joints[j].nv == 1}
