"""`urdftool compare A B` (issue 32): two descriptions of one robot, body by body.

``compare(a, b)`` takes two ``bodies.Tree``s and returns their differences, each of one kind of
``KINDS`` (the contract of DESIGN.md), named by A's link or joint and B's, with its largest
error and where A writes it.

- Matching: bodies by name, then moving bodies by their joint's name, then by place (the
  unmatched child groups of matched groups, in order, when they are as many on both sides).
- Fixed links are lumped as the other side lumps them: what is compared for mass, COM and
  inertia is the rigid group (a moving body and everything welded to it), so a description
  that merges fixed links and keeps their mass and inertia is equivalent, one that drops them
  is not. A welded body present on one side only is no difference (lumped on purpose).
- Poses: every matched body relative to the first matched body (the root), at the zero
  configuration and at ``samples`` random configurations within A's limits (mimics applied;
  a fixed seed: the same run gives the same configurations). A pose difference is reported
  where it arises (the body whose pose relative to its nearest matched ancestor differs), not
  again at every body below it; a body whose own joint already differs in kind or axis is
  judged at the zero configuration only (one finding per cause).
- Errors: poses in metres and radians (the larger of the two), axes in radians (a reversed
  axis is pi), ranges in the joint's unit, mass and inertia relative, COM in metres, damping,
  friction, armature, effort and velocity relative to max(1, |a|, |b|). A presence/absence
  difference (a body, a limit, a mimic, collision geometry) has ``max_error`` None.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from urdftool.bodies import FIXED, FREE, HINGE, SLIDE, Tree, group_roots, groups, poses
from urdftool.findings import Loc

KINDS = ("missing-body", "extra-body", "pose", "joint-type", "axis", "range", "mimic", "mass",
         "com", "inertia", "damping", "friction", "armature", "effort", "velocity", "collision")
DEFAULT_SAMPLES = 20
DEFAULT_TOLERANCE = 1e-5  # MuJoCo writes 6 significant digits (mj_saveLastXML)
SEED = 0
UNLIMITED_HINGE = math.pi  # sampled range of a joint without limits
UNLIMITED_SLIDE = 0.5


class Difference(NamedTuple):
    kind: str
    name: str | None  # A's link or joint (B's for an extra body)
    other: str | None  # B's
    max_error: float | None
    message: str
    loc: Loc | None = None  # where A writes it

    def as_dict(self) -> dict:
        return {"kind": self.kind, "name": self.name, "other": self.other,
                "max_error": self.max_error, "path": self.loc.path if self.loc else None,
                "line": self.loc.line if self.loc else None, "message": self.message}


class Result(NamedTuple):
    differences: list[Difference]
    samples: int
    largest: float  # the largest error over everything compared (0 when identical)
    notes: list[str]  # what could not be compared, and why
    matched: int  # bodies matched

    @property
    def verdict(self) -> str:
        return "different" if self.differences else "equivalent"


def _relative(a: float, b: float) -> float:
    return abs(a - b) / max(1.0, abs(a), abs(b))


def _angle(ra: np.ndarray, rb: np.ndarray) -> float:
    """The rotation angle between two rotation matrices (stable near 0)."""
    chord = float(np.linalg.norm(ra - rb)) / (2.0 * math.sqrt(2.0))
    return 2.0 * math.asin(min(1.0, chord))


def _pose_error(ta: np.ndarray, tb: np.ndarray) -> tuple[float, float]:
    return float(np.linalg.norm(ta[:3, 3] - tb[:3, 3])), _angle(ta[:3, :3], tb[:3, :3])


def _inverse(t: np.ndarray) -> np.ndarray:
    inv = np.eye(4)
    inv[:3, :3] = t[:3, :3].T
    inv[:3, 3] = -t[:3, :3].T @ t[:3, 3]
    return inv


def _fmt(value) -> str:
    return "unlimited" if value is None else f"[{value[0]:.9g}, {value[1]:.9g}]"


# -- matching -------------------------------------------------------------------------------------


def match_bodies(a: Tree, b: Tree) -> dict[int, int]:
    """A body index -> B body index: by name, then moving bodies by joint name, then by place."""
    matched: dict[int, int] = {}
    taken: set[int] = set()
    for i, body in enumerate(a.bodies):
        j = b.index.get(body.name) if body.name is not None else None
        if j is not None and j not in taken and a.index.get(body.name) == i:
            matched[i] = j
            taken.add(j)
    by_joint: dict[str, int] = {}
    for j, body in enumerate(b.bodies):
        for joint in body.joints:
            if joint.name is not None and joint.kind != FIXED:
                by_joint.setdefault(joint.name, j)
    for i, body in enumerate(a.bodies):
        if i in matched or not a.moving(i):
            continue
        for joint in body.joints:
            j = by_joint.get(joint.name) if joint.name is not None else None
            if j is not None and j not in taken:
                matched[i] = j
                taken.add(j)
                break
    if 0 not in matched and 0 not in taken:
        matched[0] = 0  # the roots: a root fused into the world is the world
        taken.add(0)
    ra, rb = group_roots(a), group_roots(b)
    a_kids, b_kids = _group_children(a, ra), _group_children(b, rb)
    changed = True
    while changed:  # by place: unmatched child groups of matched groups, in order
        changed = False
        for i, j in list(matched.items()):
            if ra[i] != i:
                continue
            left = [c for c in a_kids.get(i, []) if c not in matched]
            right = [c for c in b_kids.get(rb[j], []) if c not in taken]
            if left and len(left) == len(right):
                for c, d in zip(left, right):
                    matched[c] = d
                    taken.add(d)
                changed = True
    return matched


def _group_children(tree: Tree, roots: list[int]) -> dict[int, list[int]]:
    """Group root -> the group roots directly below its group, in order."""
    found: dict[int, list[int]] = {}
    for i, body in enumerate(tree.bodies):
        if body.parent is not None and roots[i] == i:
            found.setdefault(roots[body.parent], []).append(i)
    return found


def _pair_joints(a: Tree, b: Tree, matched: dict[int, int]):
    """[(A (body, k), B (body, l) or None)] for every A joint of a matched body, and the B
    joints of matched bodies left unpaired."""
    pairs = []
    extra = []
    for i, j in matched.items():
        ja, jb = a.bodies[i].joints, b.bodies[j].joints
        free_b = list(range(len(jb)))
        found: dict[int, int] = {}
        for k, joint in enumerate(ja):
            for l in free_b:
                if joint.name is not None and jb[l].name == joint.name:
                    found[k] = l
                    free_b.remove(l)
                    break
        for k in range(len(ja)):
            if k not in found and free_b:
                found[k] = free_b.pop(0)
        for k in range(len(ja)):
            pairs.append(((i, k), (j, found[k]) if k in found else None))
        extra.extend((j, l) for l in free_b)
    return pairs, extra


# -- configurations -------------------------------------------------------------------------------


def configurations(a: Tree, count: int, seed: int = SEED) -> list[dict[tuple[int, int], float]]:
    """The zero configuration and ``count`` random ones within A's limits (unlimited: +-pi,
    +-0.5 m), mimic followers set from their leaders."""
    rng = np.random.default_rng(seed)
    joints = [((i, k), joint) for i, body in enumerate(a.bodies)
              for k, joint in enumerate(body.joints)]
    by_name = {joint.name: key for key, joint in joints if joint.name is not None}
    found = []
    for n in range(count + 1):
        values: dict[tuple[int, int], float] = {}
        for key, joint in joints:
            if joint.kind not in (HINGE, SLIDE) or n == 0:
                continue
            if joint.range is not None and joint.range[0] <= joint.range[1]:
                lo, hi = joint.range
            else:
                half = UNLIMITED_HINGE if joint.kind == HINGE else UNLIMITED_SLIDE
                lo, hi = -half, half
            values[key] = float(rng.uniform(lo, hi))
        for _ in range(8):  # mimics (chained ones too), applied until settled
            for key, joint in joints:
                if joint.mimic is not None and joint.mimic[0] in by_name:
                    leader = values.get(by_name[joint.mimic[0]], 0.0)
                    values[key] = joint.mimic[1] * leader + joint.mimic[2]
        found.append(values)
    return found


# -- the comparison -------------------------------------------------------------------------------


class _Collector:
    def __init__(self, tolerance: float):
        self.tolerance = tolerance
        self.differences: list[Difference] = []
        self.largest = 0.0

    def error(self, kind, name, other, error: float, message: str, loc) -> None:
        if math.isfinite(error):
            self.largest = max(self.largest, error)
        if not error <= self.tolerance:  # nan counts as a difference
            self.differences.append(Difference(kind, name, other, float(error), message, loc))

    def absent(self, kind, name, other, message: str, loc) -> None:
        self.differences.append(Difference(kind, name, other, None, message, loc))


def compare(a: Tree, b: Tree, samples: int = DEFAULT_SAMPLES,
            tolerance: float = DEFAULT_TOLERANCE, seed: int = SEED) -> Result:
    out = _Collector(tolerance)
    notes: list[str] = []
    matched = match_bodies(a, b)
    ra, rb = group_roots(a), group_roots(b)
    pairs, extra_joints = _pair_joints(a, b, matched)
    joint_differs: set[int] = set()  # A bodies whose own joint differs in kind or axis
    _compare_joints(a, b, pairs, extra_joints, out, notes, joint_differs)
    _compare_bodies(a, b, matched, ra, rb, out)
    configs = configurations(a, samples, seed)
    _compare_poses(a, b, matched, pairs, configs, joint_differs, out)
    order = {kind: n for n, kind in enumerate(KINDS)}
    out.differences.sort(key=lambda d: (order[d.kind], d.loc.path if d.loc else "",
                                        d.loc.line or 0 if d.loc else 0, d.name or ""))
    return Result(out.differences, samples, out.largest, notes, len(matched))


def _compare_joints(a, b, pairs, extra_joints, out, notes, joint_differs) -> None:
    a_names = {}  # A joint name -> B joint name (mimic leaders are named on each side)
    for (i, k), other in pairs:
        if other is not None:
            a_names[a.bodies[i].joints[k].name] = b.bodies[other[0]].joints[other[1]].name
    unexpressed: dict[str, list[str]] = {}
    for (i, k), other in pairs:
        ja = a.bodies[i].joints[k]
        locs = ja.locs or {}
        loc = locs.get("joint") or ja.loc or a.bodies[i].loc
        if other is None:
            if ja.kind == FREE and a.bodies[i].parent in (0, None):
                notes.append(_FREE_ROOT.format(side="A"))
                continue
            if ja.kind != FIXED:
                joint_differs.add(i)
                out.absent("joint-type", ja.name, None,
                           f"{ja.kind} joint, welded (no joint) in B", loc)
            continue
        jb = b.bodies[other[0]].joints[other[1]]
        if ja.kind != jb.kind:
            joint_differs.add(i)
            out.absent("joint-type", ja.name, jb.name, f"{ja.kind} in A, {jb.kind} in B", loc)
            continue
        if ja.kind not in (HINGE, SLIDE):
            continue
        angle = _angle_between(ja.axis, jb.axis)
        out.error("axis", ja.name, jb.name, angle,
                  f"axis ({_vec(ja.axis)}) in A, ({_vec(jb.axis)}) in B: {angle:.6g} rad apart",
                  locs.get("axis") or loc)
        if angle > out.tolerance:
            joint_differs.add(i)
        range_b = jb.range
        if range_b is not None and ja.range is not None and angle > math.pi / 2:
            reversed_b = (-range_b[1], -range_b[0])  # a reversed axis with its range reversed
            if _range_error(ja.range, reversed_b) < _range_error(ja.range, range_b):
                range_b = reversed_b  # is one difference (the axis)
        _compare_range(ja, jb, range_b, out, locs.get("range") or loc)
        _compare_mimic(ja, jb, a_names, out, locs.get("mimic") or loc)
        for aspect in ("damping", "friction", "armature"):
            va, vb = getattr(ja, aspect), getattr(jb, aspect)
            out.error(aspect, ja.name, jb.name, _relative(va, vb),
                      f"{aspect} {va!r} in A, {vb!r} in B", locs.get(aspect) or loc)
        for aspect in ("effort", "velocity"):
            va, vb = getattr(ja, aspect), getattr(jb, aspect)
            if va is not None and vb is not None:
                out.error(aspect, ja.name, jb.name, _relative(va, vb),
                          f"{aspect} limit {va!r} in A, {vb!r} in B", locs.get(aspect) or loc)
            elif (va is None) != (vb is None):
                lacking = b if va is not None else a
                if aspect not in lacking.expresses:
                    unexpressed.setdefault(aspect, []).append(ja.name or "?")
                    continue
                out.absent(aspect, ja.name, jb.name,
                           f"{aspect} limit {va!r} in A, none in B" if va is not None
                           else f"no {aspect} limit in A, {vb!r} in B", locs.get(aspect) or loc)
    for j, l in extra_joints:
        jb = b.bodies[j].joints[l]
        if jb.kind == FREE and b.bodies[j].parent in (0, None):
            notes.append(_FREE_ROOT.format(side="B"))
            continue
        if jb.kind != FIXED:
            out.absent("joint-type", b.bodies[j].name, jb.name,
                       f"no joint in A, {jb.kind} joint {jb.name!r} in B", None)
    for aspect, names in unexpressed.items():
        notes.append(f"{aspect} limits of {len(names)} joint(s) not compared: the other "
                     f"description states none at all ({', '.join(names[:5])}"
                     f"{', ...' if len(names) > 5 else ''})")


_FREE_ROOT = ("the root body is free in {side} (a free joint) and not attached in the other: "
              "whether a URDF's root floats is the simulator's choice, not a difference")


def _vec(v) -> str:
    return " ".join(f"{float(x):.6g}" for x in v)


def _angle_between(u: np.ndarray, v: np.ndarray) -> float:
    """Angle between unit vectors (stable near 0 and pi)."""
    return 2.0 * math.atan2(float(np.linalg.norm(u - v)), float(np.linalg.norm(u + v)))


def _compare_range(ja, jb, range_b, out, loc) -> None:
    if ja.range is None and range_b is None:
        return
    if ja.range is None or range_b is None:
        out.absent("range", ja.name, jb.name, f"{_fmt(ja.range)} in A, {_fmt(range_b)} in B", loc)
        return
    error = _range_error(ja.range, range_b)
    out.error("range", ja.name, jb.name, error,
              f"{_fmt(ja.range)} in A, {_fmt(range_b)} in B", loc)


def _range_error(a, b) -> float:
    return max(abs(a[0] - b[0]), abs(a[1] - b[1]))


def _compare_mimic(ja, jb, a_names, out, loc) -> None:
    ma, mb = ja.mimic, jb.mimic
    if ma is None and mb is None:
        return
    if ma is None or mb is None:
        said = (f"mimics {ma[0]!r} (x{ma[1]:.9g} {ma[2]:+.9g}) in A, independent in B"
                if ma is not None else f"independent in A, mimics {mb[0]!r} in B")
        out.absent("mimic", ja.name, jb.name, said, loc)
        return
    if a_names.get(ma[0], ma[0]) != mb[0]:
        out.absent("mimic", ja.name, jb.name, f"mimics {ma[0]!r} in A, {mb[0]!r} in B", loc)
        return
    error = max(abs(ma[1] - mb[1]), abs(ma[2] - mb[2]))
    out.error("mimic", ja.name, jb.name, error,
              f"multiplier {ma[1]!r}, offset {ma[2]!r} in A; {mb[1]!r}, {mb[2]!r} in B", loc)


def _placed(tree: Tree, roots: list[int]) -> list[np.ndarray]:
    """Each body's pose in its group root's frame."""
    found: list[np.ndarray] = []
    for i, body in enumerate(tree.bodies):
        found.append(np.eye(4) if roots[i] == i else found[body.parent] @ body.origin)
    return found


def _compare_bodies(a, b, matched, ra, rb, out) -> None:
    ga, gb = groups(a), groups(b)
    _pa, pb = _placed(a, ra), _placed(b, rb)
    taken = set(matched.values())
    for i, body in enumerate(a.bodies):
        if ra[i] != i:
            continue
        j = matched.get(i)
        if j is None:
            out.absent("missing-body", body.name, None,
                       f"moving body {body.name!r} (joint "
                       f"{', '.join(repr(x.name) for x in body.joints)}) has no counterpart in B",
                       body.loc)
            continue
        if rb[j] != j and i != 0:
            continue  # moving in A, welded in B: the joint's difference says it
        _compare_group(a, b, i, j, ga[i], gb[rb[j]], pb[j], out)
    for j, body in enumerate(b.bodies):
        if rb[j] == j and j not in taken and body.parent is not None:
            out.absent("extra-body", body.name, body.name,
                       f"moving body {body.name!r} of B has no counterpart in A", None)


def _compare_group(a, b, i, j, group_a, group_b, placed_j, out) -> None:
    body = a.bodies[i]
    other = b.bodies[j].name
    locs = body.locs or {}
    if i == 0 and a.static_root and b.static_root:
        pass  # both welded to the world: their mass never acts
    else:
        ma, mb = group_a.mass, group_b.mass
        mass_error = abs(ma - mb) / max(ma, mb) if max(ma, mb) > 0 else 0.0
        com_error = inertia_error = 0.0
        com_b, inertia_b = group_b.com, group_b.inertia
        if ma > 0 and mb > 0:
            # B's group is expressed in its root's frame: moved into the matched body's
            to_j = _inverse(placed_j)
            com_b = to_j[:3, :3] @ group_b.com + to_j[:3, 3]
            inertia_b = to_j[:3, :3] @ group_b.inertia @ to_j[:3, :3].T
            com_error = float(np.linalg.norm(group_a.com - com_b))
            scale = max(float(np.linalg.norm(group_a.inertia)), float(np.linalg.norm(inertia_b)))
            inertia_error = (float(np.linalg.norm(group_a.inertia - inertia_b)) / scale
                             if scale > 0 else 0.0)
        elif max(ma, mb) > 0:
            inertia_error = 1.0
        lumped = f" ({len(group_a.members)} links lumped)" if len(group_a.members) > 1 else ""
        # one finding per cause: a mass that differs moves the COM and the inertia of a lumped
        # body; a COM that differs changes the lumped inertia about it (said in the message)
        also = [f"{what} differs too ({value:.3g})" for what, value, tolerance in
                (("centre of mass", com_error, out.tolerance),
                 ("inertia", inertia_error, out.tolerance)) if value > tolerance]
        if mass_error > out.tolerance:
            out.error("mass", body.name, other, mass_error,
                      f"mass {ma!r} kg in A{lumped}, {mb!r} kg in B"
                      + (f"; {', '.join(also)}" if also else ""), locs.get("mass") or body.loc)
        elif com_error > out.tolerance:
            out.error("com", body.name, other, com_error,
                      f"centre of mass ({_vec(group_a.com)}) in A{lumped}, ({_vec(com_b)}) in B: "
                      f"{com_error:.6g} m apart" + (f"; {also[-1]}" if len(also) > 1 else ""),
                      locs.get("com") or body.loc)
        else:
            out.error("inertia", body.name, other, inertia_error,
                      f"inertia tensor {_tensor(group_a.inertia)} in A{lumped}, "
                      f"{_tensor(inertia_b)} in B (relative difference {inertia_error:.3g})",
                      locs.get("inertia") or body.loc)
        out.largest = max(out.largest, mass_error, com_error, inertia_error)
    if group_a.collision != group_b.collision:
        out.absent("collision", body.name, other,
                   "collision geometry in A, none in B" if group_a.collision
                   else "no collision geometry in A, some in B",
                   locs.get("collision") or body.loc)


def _tensor(m: np.ndarray) -> str:
    return "(" + " ".join(f"{m[r][c]:.6g}" for r, c in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2),
                                                        (1, 2))) + ")"


def _compare_poses(a, b, matched, pairs, configs, joint_differs, out) -> None:
    key_b = {key: other for key, other in pairs if other is not None}
    first = min(matched)  # the root frame: the first matched body on each side
    ancestor = {}  # A body -> its nearest matched ancestor
    for i in sorted(matched):
        p = a.bodies[i].parent
        while p is not None and p not in matched:
            p = a.bodies[p].parent
        ancestor[i] = p
    worst: dict[int, tuple[float, float, float, float]] = {}  # root trans, rot, local t, local r
    zero_a, zero_b = poses(a), poses(b)  # every joint at 0, mimic offsets too
    for n, values in enumerate(configs):
        values_b = {key_b[key]: value for key, value in values.items() if key in key_b}
        pose_a, pose_b = poses(a, values), poses(b, values_b)
        frame_a, frame_b = _inverse(pose_a[first]), _inverse(pose_b[matched[first]])
        for i, j in matched.items():
            if i == first:
                continue
            trans, rot = _pose_error(frame_a @ pose_a[i], frame_b @ pose_b[j])
            p = ancestor[i]
            if p is None:
                local_t, local_r = trans, rot
            elif i in joint_differs:  # its joint's difference moves it (said there): its
                # placement judged with every joint at zero
                local_t, local_r = _pose_error(_inverse(zero_a[p]) @ zero_a[i],
                                               _inverse(zero_b[matched[p]]) @ zero_b[j])
            else:
                local_t, local_r = _pose_error(_inverse(pose_a[p]) @ pose_a[i],
                                               _inverse(pose_b[matched[p]]) @ pose_b[j])
            old = worst.get(i, (0.0, 0.0, 0.0, 0.0))
            worst[i] = (max(old[0], trans), max(old[1], rot), max(old[2], local_t),
                        max(old[3], local_r))
    for i, (trans, rot, local_t, local_r) in worst.items():
        body = a.bodies[i]
        error = max(trans, rot)
        out.largest = max(out.largest, error) if math.isfinite(error) else out.largest
        if max(local_t, local_r) > out.tolerance:
            joint = body.joints[0] if body.joints else None
            loc = ((joint.locs or {}).get("joint") or joint.loc) if joint is not None else None
            out.error("pose", body.name, b.bodies[matched[i]].name, error,
                      f"pose relative to the root differs by up to {trans:.6g} m and "
                      f"{rot:.6g} rad over {len(configs)} configurations", loc or body.loc)
