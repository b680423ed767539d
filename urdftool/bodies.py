"""A robot as rigid bodies and joints, whatever it was written in (issue 32): the neutral tree
that ``urdftool compare`` compares and ``convert --to mjcf`` verifies.

- ``tree_of_robot(robot)``: from urdftool's model (URDF, xacro, SDF converted): one body per
  link, located where the file writes it.
- ``tree_of_mujoco(model, locs)``: from a compiled ``mujoco.MjModel`` (MJCF read by MuJoCo
  itself, so defaults, classes and includes mean what MuJoCo makes of them): one body per MuJoCo
  body, body 0 being the world.
- ``groups(tree)``: bodies welded together (no moving joint between them) as one rigid body,
  with its mass, centre of mass and inertia tensor in its first body's frame (parallel-axis
  theorem: a fixed link lumped into its parent keeps what it weighs).
- ``poses(tree, values)``: every body's 4x4 pose in the tree's root frame at joint values.

Angles in radians, lengths in metres; a joint's ``axis`` and ``anchor`` are in its child body's
frame (URDF: the joint frame is the child link frame, anchor 0; MuJoCo: ``jnt_pos``).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from urdftool.findings import Loc
from urdftool.kinematics.fk import pose_matrix, rotation_about

# motion kinds: what a joint lets its child do (limits are the joint's range, not its kind)
HINGE, SLIDE, FIXED, FREE, BALL, PLANAR = "hinge", "slide", "fixed", "free", "ball", "planar"
URDF_KINDS = {"revolute": HINGE, "continuous": HINGE, "prismatic": SLIDE, "fixed": FIXED,
              "floating": FREE, "planar": PLANAR}


class Joint(NamedTuple):
    name: str | None
    kind: str  # HINGE, SLIDE, FIXED, FREE, BALL, PLANAR
    axis: np.ndarray  # unit, in the child body's frame
    anchor: np.ndarray  # a point of the axis, in the child body's frame
    range: tuple[float, float] | None  # None: unlimited
    mimic: tuple[str, float, float] | None = None  # (leader joint, multiplier, offset)
    damping: float = 0.0
    friction: float = 0.0
    armature: float = 0.0
    effort: float | None = None  # None: no force limit written
    velocity: float | None = None  # None: no velocity limit written
    loc: Loc | None = None
    locs: dict | None = None  # aspect -> Loc where it is written (limit, mimic, dynamics, axis)


class Body(NamedTuple):
    name: str | None
    parent: int | None  # index in Tree.bodies, None for the root
    origin: np.ndarray  # 4x4, in the parent body's frame, joints at zero
    joints: tuple[Joint, ...]
    mass: float
    com: np.ndarray  # in the body frame
    inertia: np.ndarray  # 3x3 about the COM, in the body frame
    collision: bool  # has collision geometry
    loc: Loc | None = None
    locs: dict | None = None  # aspect -> Loc (mass, inertia, com, collision)


class Tree:
    """Bodies in topological order (parents first); ``static_root``: the root body is welded to
    the world (a MuJoCo worldbody, a URDF root link named ``world``); ``expresses``: the limits
    this description can state at all (MuJoCo has no joint velocity limit without a velocity
    actuator): a limit the other side cannot express is not a difference."""

    def __init__(self, bodies: list[Body], path: str, static_root: bool,
                 expresses: frozenset = frozenset({"effort", "velocity", "armature"}),
                 kind: str = "urdf"):
        self.bodies = bodies
        self.path = path
        self.static_root = static_root
        self.expresses = expresses
        self.kind = kind
        self.index = {}
        for i, body in enumerate(bodies):
            if body.name is not None:
                self.index.setdefault(body.name, i)
        self.children: dict[int, list[int]] = {}
        for i, body in enumerate(bodies):
            if body.parent is not None:
                self.children.setdefault(body.parent, []).append(i)

    def joints(self) -> list[tuple[int, Joint]]:
        return [(i, joint) for i, body in enumerate(self.bodies) for joint in body.joints]

    def moving(self, i: int) -> bool:
        return any(joint.kind != FIXED for joint in self.bodies[i].joints)


def _unit(vector) -> np.ndarray:
    v = np.asarray(vector, dtype=float)
    n = float(np.linalg.norm(v))
    return v / n if n > 0 and math.isfinite(n) else np.array([1.0, 0.0, 0.0])


def _finite(value, default=0.0) -> float:
    return float(value) if value is not None and math.isfinite(value) else default


# -- from urdftool's model ------------------------------------------------------------------------


def tree_of_robot(robot, path: str | None = None) -> Tree:
    """The bodies of a URDF model (``model.build_robot``; xacro expanded, SDF converted): one
    per link reachable from the first root, parents first."""
    roots = robot.roots()
    if len(roots) != 1:
        from urdftool.errors import ToolError

        where = path or robot.source.path
        raise ToolError(f"{where}: no root link (every link is some joint's child)" if not roots
                        else f"{where}: {len(roots)} root links ({', '.join(roots[:3])}"
                        f"{', ...' if len(roots) > 3 else ''}): not one robot; run "
                        f"'urdftool check {where}'")
    bodies: list[Body] = []
    index: dict[str, int] = {}
    stack: list[tuple[str, int | None, object]] = [(roots[0], None, None)]
    while stack:
        name, parent, joint = stack.pop()
        if name in index:
            continue
        link = robot.link(name)
        index[name] = len(bodies)
        bodies.append(_link_body(robot, link, name, parent, joint))
        here = index[name]
        for child in reversed(robot.child_joints(name)):
            if child.child is not None and child.child not in index:
                stack.append((child.child, here, child))
    return Tree(bodies, path or robot.source.path, static_root=roots[0] == "world")


def _link_body(robot, link, name: str, parent: int | None, joint) -> Body:
    inertial = link.inertial if link is not None else None
    mass, com, inertia = 0.0, np.zeros(3), np.zeros((3, 3))
    locs: dict = {}
    if inertial is not None and inertial.mass is not None and inertial.mass > 0:
        mass = float(inertial.mass)
        com = np.array(inertial.origin.xyz, dtype=float)
        tensor = inertial.tensor
        if tensor is not None:
            rotation = pose_matrix(inertial.origin)[:3, :3]
            inertia = rotation @ np.array(tensor, dtype=float) @ rotation.T
        locs = {"mass": inertial.mass_loc or inertial.loc, "com": inertial.loc,
                "inertia": inertial.inertia_loc or inertial.loc}
    collisions = link.collisions if link is not None else ()
    if collisions:
        locs["collision"] = collisions[0].loc
    joints: tuple[Joint, ...] = ()
    origin = np.eye(4)
    if joint is not None:
        origin = pose_matrix(joint.origin)
        joints = (_urdf_joint(joint),)
    return Body(name, parent, origin, joints, mass, com, inertia, bool(collisions),
                link.loc if link is not None else None, locs)


def _urdf_joint(joint) -> Joint:
    kind = URDF_KINDS.get(joint.type or "", FIXED)
    limit, dynamics, mimic = joint.limit, joint.dynamics, joint.mimic
    span = None
    if joint.type in ("revolute", "prismatic") and limit is not None \
            and limit.lower is not None and limit.upper is not None:
        span = (float(limit.lower), float(limit.upper))
    locs = {"joint": joint.loc}
    if limit is not None:
        locs.update(range=limit.loc, effort=limit.loc, velocity=limit.loc)
    if dynamics is not None:
        locs.update(damping=dynamics.loc, friction=dynamics.loc)
    if mimic is not None:
        locs["mimic"] = mimic.loc
    effort = velocity = None
    if limit is not None and kind in (HINGE, SLIDE):
        effort = limit.effort
        velocity = limit.velocity
    return Joint(
        joint.name, kind, _unit(joint.axis_or_default), np.zeros(3), span,
        (mimic.joint, _finite(mimic.multiplier, 1.0), _finite(mimic.offset))
        if mimic is not None and mimic.joint is not None and kind in (HINGE, SLIDE) else None,
        _finite(dynamics.damping) if dynamics is not None else 0.0,
        _finite(dynamics.friction) if dynamics is not None else 0.0,
        0.0, effort, velocity, joint.loc, locs)


# -- from MuJoCo ----------------------------------------------------------------------------------


def _quat_matrix(q) -> np.ndarray:
    w, x, y, z = (float(v) for v in q)
    n = math.sqrt(w * w + x * x + y * y + z * z) or 1.0
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def tree_of_mujoco(model, path: str, locs: dict | None = None) -> Tree:
    """The bodies of a compiled MuJoCo model: body 0 is the world (static root); a body without
    joints is welded to its parent. ``locs``: (tag, name) -> Loc in the MJCF files."""
    import mujoco

    locs = locs or {}

    def name_of(kind, i):
        name = mujoco.mj_id2name(model, kind, i)
        return name if name else None

    equality = _joint_equalities(model, name_of)
    efforts, velocities, any_force = _actuator_limits(model)
    expresses = {"armature"}
    if any_force or bool(np.any(model.jnt_actfrclimited)):
        expresses.add("effort")
    if velocities:
        expresses.add("velocity")
    bodies = []
    for b in range(model.nbody):
        name = name_of(mujoco.mjtObj.mjOBJ_BODY, b)
        origin = np.eye(4)
        origin[:3, :3] = _quat_matrix(model.body_quat[b])
        origin[:3, 3] = model.body_pos[b]
        joints = []
        start, count = int(model.body_jntadr[b]), int(model.body_jntnum[b])
        for j in range(start, start + count) if start >= 0 else ():
            joints.append(_mujoco_joint(model, j, name_of(mujoco.mjtObj.mjOBJ_JOINT, j),
                                        equality, efforts, velocities, locs))
        rotation = _quat_matrix(model.body_iquat[b])
        inertia = rotation @ np.diag(model.body_inertia[b]) @ rotation.T
        collision = False
        gstart, gcount = int(model.body_geomadr[b]), int(model.body_geomnum[b])
        for g in range(gstart, gstart + gcount) if gstart >= 0 else ():
            if model.geom_contype[g] or model.geom_conaffinity[g]:
                collision = True
        body_loc = locs.get(("body", name)) if name else None
        bodies.append(Body(name, int(model.body_parentid[b]) if b else None, origin,
                           tuple(joints), float(model.body_mass[b]),
                           np.array(model.body_ipos[b], dtype=float), inertia, collision,
                           body_loc, {"mass": body_loc, "com": body_loc, "inertia": body_loc,
                                      "collision": body_loc}))
    return Tree(bodies, path, static_root=True, expresses=frozenset(expresses), kind="mjcf")


def _mujoco_joint(model, j: int, name, equality, efforts, velocities, locs) -> Joint:
    import mujoco

    types = {int(mujoco.mjtJoint.mjJNT_HINGE): HINGE, int(mujoco.mjtJoint.mjJNT_SLIDE): SLIDE,
             int(mujoco.mjtJoint.mjJNT_BALL): BALL, int(mujoco.mjtJoint.mjJNT_FREE): FREE}
    kind = types[int(model.jnt_type[j])]
    dof = int(model.jnt_dofadr[j])
    span = tuple(float(v) for v in model.jnt_range[j]) if model.jnt_limited[j] else None
    effort = None
    if model.jnt_actfrclimited[j]:
        lo, hi = (float(v) for v in model.jnt_actfrcrange[j])
        effort = max(abs(lo), abs(hi))
    if j in efforts:
        effort = efforts[j] if effort is None else min(effort, efforts[j])
    loc = locs.get(("joint", name)) if name else None
    return Joint(name, kind, _unit(model.jnt_axis[j]), np.array(model.jnt_pos[j], dtype=float),
                 span if kind in (HINGE, SLIDE) else None, equality.get(j),
                 float(model.dof_damping[dof]), float(model.dof_frictionloss[dof]),
                 float(model.dof_armature[dof]), effort, velocities.get(j), loc,
                 {aspect: loc for aspect in ("joint", "range", "damping", "friction", "armature",
                                             "effort", "velocity", "mimic")})


def _joint_equalities(model, name_of) -> dict[int, tuple[str, float, float]]:
    """follower joint id -> (leader name, multiplier, offset) of the active joint equalities
    that are a mimic (polycoef c0 + c1 q2, no higher terms)."""
    import mujoco

    found = {}
    for e in range(model.neq):
        if int(model.eq_type[e]) != int(mujoco.mjtEq.mjEQ_JOINT) or not model.eq_active0[e]:
            continue
        follower, leader = int(model.eq_obj1id[e]), int(model.eq_obj2id[e])
        if leader < 0:  # a joint held at c0
            continue
        c = [float(v) for v in model.eq_data[e][:5]]
        if any(abs(v) > 0 for v in c[2:]):
            continue  # a polynomial coupling is not a mimic: left unmatched, so reported
        found[follower] = (name_of(mujoco.mjtObj.mjOBJ_JOINT, leader), c[1], c[0])
    return found


def _actuator_limits(model) -> tuple[dict[int, float], dict[int, float], bool]:
    """(joint -> force limit, joint -> velocity limit, any actuator on a joint): a motor's
    force range (or its control range times its gear), a velocity servo's control range."""
    import mujoco

    efforts: dict[int, float] = {}
    velocities: dict[int, float] = {}
    any_force = False
    for a in range(model.nu):
        if int(model.actuator_trntype[a]) != int(mujoco.mjtTrn.mjTRN_JOINT):
            continue
        j = int(model.actuator_trnid[a][0])
        gear = abs(float(model.actuator_gear[a][0])) or 1.0
        any_force = True
        force = None
        if model.actuator_forcelimited[a]:
            lo, hi = (float(v) for v in model.actuator_forcerange[a])
            force = max(abs(lo), abs(hi)) * gear
        bias = int(model.actuator_biastype[a])
        gain = int(model.actuator_gaintype[a])
        prm = model.actuator_biasprm[a]
        if bias == int(mujoco.mjtBias.mjBIAS_NONE) and gain == int(mujoco.mjtGain.mjGAIN_FIXED) \
                and model.actuator_ctrllimited[a]:
            lo, hi = (float(v) for v in model.actuator_ctrlrange[a])
            motor = max(abs(lo), abs(hi)) * float(model.actuator_gainprm[a][0]) * gear
            force = motor if force is None else min(force, motor)
        if bias == int(mujoco.mjtBias.mjBIAS_AFFINE) and float(prm[1]) == 0 and float(prm[2]) < 0 \
                and model.actuator_ctrllimited[a]:
            lo, hi = (float(v) for v in model.actuator_ctrlrange[a])
            velocities[j] = max(abs(lo), abs(hi))
        if force is not None:
            efforts[j] = force if j not in efforts else min(efforts[j], force)
    return efforts, velocities, any_force


# -- rigid groups and poses -----------------------------------------------------------------------


class Group(NamedTuple):
    root: int  # the body whose frame the group is expressed in
    members: tuple[int, ...]  # bodies welded to it (root first)
    mass: float
    com: np.ndarray  # in the root body's frame
    inertia: np.ndarray  # about com, in the root body's frame
    collision: bool


def group_roots(tree: Tree) -> list[int]:
    """The body each body is welded into: itself when it moves (or is the root)."""
    roots = []
    for i, body in enumerate(tree.bodies):
        if body.parent is None or tree.moving(i):
            roots.append(i)
        else:
            roots.append(roots[body.parent])
    return roots


def groups(tree: Tree) -> dict[int, Group]:
    """Root body index -> the rigid group (lumped mass, COM and inertia in the root's frame)."""
    roots = group_roots(tree)
    placed: dict[int, np.ndarray] = {}  # body -> pose in its group root's frame
    members: dict[int, list[int]] = {}
    for i, body in enumerate(tree.bodies):
        r = roots[i]
        placed[i] = np.eye(4) if r == i else placed[body.parent] @ body.origin
        members.setdefault(r, []).append(i)
    found = {}
    for r, group in members.items():
        mass = sum(tree.bodies[i].mass for i in group)
        com = np.zeros(3)
        if mass > 0:
            for i in group:
                com += tree.bodies[i].mass * (placed[i][:3, :3] @ tree.bodies[i].com
                                              + placed[i][:3, 3])
            com /= mass
        inertia = np.zeros((3, 3))
        for i in group:
            body = tree.bodies[i]
            if body.mass <= 0:
                continue
            rotation = placed[i][:3, :3]
            offset = rotation @ body.com + placed[i][:3, 3] - com
            inertia += rotation @ body.inertia @ rotation.T + body.mass * (
                float(offset @ offset) * np.eye(3) - np.outer(offset, offset))
        found[r] = Group(r, tuple(group), mass, com, inertia,
                         any(tree.bodies[i].collision for i in group))
    return found


def joint_motion(joint: Joint, value: float) -> np.ndarray:
    """The 4x4 motion of one joint at ``value`` about (along) its axis through its anchor."""
    motion = np.eye(4)
    if joint.kind == HINGE and value:
        rotation = rotation_about(joint.axis, value)
        motion[:3, :3] = rotation
        motion[:3, 3] = joint.anchor - rotation @ joint.anchor
    elif joint.kind == SLIDE and value:
        motion[:3, 3] = joint.axis * value
    return motion


def poses(tree: Tree, values: dict[tuple[int, int], float] | None = None) -> list[np.ndarray]:
    """Every body's pose in the root body's frame; ``values``: (body, joint of that body) ->
    value (others 0)."""
    values = values or {}
    found: list[np.ndarray] = []
    for i, body in enumerate(tree.bodies):
        pose = found[body.parent] @ body.origin if body.parent is not None else np.eye(4)
        for k, joint in enumerate(body.joints):
            value = values.get((i, k), 0.0)
            if value:
                pose = pose @ joint_motion(joint, value)
        found.append(pose)
    return found
