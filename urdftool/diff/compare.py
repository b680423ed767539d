"""What a change does to one robot (issue 30): two models of it (``model.Robot``, BASE and
HEAD) compared as a robot engineer names their differences, each located at both sides.

- Links and joints are matched by name, then (a rename) by their place in the tree: an
  unmatched link below a matched parent link is paired with the unmatched one below that parent
  at the other side whose joint, geometry and inertia agree best.
- Origins are compared as transforms (rpy written another way is no change) and carry their
  effect: how far the links below move at the zero configuration (``kinematics.fk``).
- Mass, centre of mass and inertia are physical quantities: the tensor is compared in the
  link frame (``R I Rᵀ``), so a tensor rewritten with another inertial ``rpy`` is no change;
  a change reports the principal moments and the relative change.
- Visual and collision shapes: kind, size, scale, origin, mesh file and the mesh's content
  (bounding box and volume from ``physics.meshes``' summaries).
- ``<gazebo>``, ``<ros2_control>`` and ``<transmission>`` blocks per element they refer to,
  compared as XML trees with numbers compared as numbers.

Numbers are the same when they differ by at most ``REL`` relatively (DESIGN.md: 1e-9) or by
at most ``ABS`` (a regenerated file writes 6.1e-17 for a zero). Analysis layer: pure functions
of two robots; reading mesh files goes through ``physics.meshes``.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

from urdftool.findings import Loc
from urdftool.model import Joint, Link, Pose, Robot, Shape
from urdftool.physics import inertia as phys

REL = 1e-9
ABS = 1e-12  # below this a number is written noise (a regenerated cos(pi/2))


class Change(NamedTuple):
    """One difference. ``loc`` is where it is written at HEAD (the new side), ``base_loc`` at
    BASE; ``extra`` holds aspect-specific fields (``effect``, ``relative_change``...);
    ``size`` orders changes by consequence (metres moved, relative change, 1 for structure)."""

    element: str
    name: str | None
    aspect: str
    before: Any
    after: Any
    loc: Loc | None
    base_loc: Loc | None
    summary: str
    extra: dict = {}  # noqa: RUF012 - never mutated
    size: float = 1.0


def same(a: float | None, b: float | None) -> bool:
    """The contract's number equality: within a relative ``REL`` (or both below ``ABS``)."""
    if a is None or b is None:
        return a is None and b is None
    difference = abs(a - b)
    return difference <= ABS or difference <= REL * max(abs(a), abs(b))


def same_vector(a, b) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))


def relative_change(a: float, b: float) -> float:
    """|b - a| / |a| (inf from zero to something)."""
    if a == 0:
        return 0.0 if b == 0 else math.inf
    return abs(b - a) / abs(a)


def _pose_json(pose: Pose) -> dict:
    return {"xyz": list(pose.xyz), "rpy": list(pose.rpy)}


def same_pose(a: Pose, b: Pose) -> bool:
    """The same transform: translations by ``same``, rotation matrices entry by entry within
    ``REL`` (entries are at most 1: rpy written another way is the same rotation)."""
    if not same_vector(a.xyz, b.xyz):
        return False
    ra, rb = phys.rpy_matrix(a.rpy), phys.rpy_matrix(b.rpy)
    return all(abs(x - y) <= REL for row_a, row_b in zip(ra, rb) for x, y in zip(row_a, row_b))


def rotation_angle(a: Pose, b: Pose) -> float:
    """The angle of the rotation that takes ``a``'s orientation to ``b``'s (radians)."""
    relative = phys.mat_mul(phys.transpose(phys.rpy_matrix(a.rpy)), phys.rpy_matrix(b.rpy))
    cosine = (phys.trace(relative) - 1.0) / 2.0
    return math.acos(max(-1.0, min(1.0, cosine)))


# -- matching links and joints ----------------------------------------------------------------


def _first_by_name(records) -> dict:
    found: dict = {}
    for record in records:
        if record.name is not None:
            found.setdefault(record.name, record)
    return found


def _tensor_in_link(link: Link):
    inertial = link.inertial
    if inertial is None or inertial.tensor is None:
        return None
    return phys.rotate_tensor(phys.rpy_matrix(inertial.origin.rpy), inertial.tensor)


def _shape_key(shape: Shape) -> tuple:
    g = shape.geometry
    name = (g.filename or "").replace("\\", "/").rsplit("/", 1)[-1]
    return (g.kind, g.size, g.radius, g.length, name, g.scale)


def _similarity(a_robot: Robot, a: str, b_robot: Robot, b: str) -> int:
    """How many of (joint type, joint origin, joint axis, inertia, geometry) agree between
    link ``a`` of A and link ``b`` of B."""
    la, lb = a_robot.link(a), b_robot.link(b)
    ja, jb = a_robot.parent_joint(a), b_robot.parent_joint(b)
    score = 0
    if ja is not None and jb is not None:
        score += ja.type == jb.type
        score += same_pose(ja.origin, jb.origin)
        score += same_vector(_unit(ja.axis_or_default), _unit(jb.axis_or_default))
    if la is not None and lb is not None:
        ia, ib = la.inertial, lb.inertial
        if ia is not None and ib is not None and same(ia.mass, ib.mass) and \
                _same_tensor(_tensor_in_link(la), _tensor_in_link(lb)):
            score += 1
        if la.shapes and [_shape_key(s) for s in la.shapes] == [_shape_key(s) for s in lb.shapes]:
            score += 1
    return score


def match_links(a: Robot, b: Robot) -> dict[str, str]:
    """A link name -> B link name: by name, then renames by place in the tree (see the module
    docstring). Links met in B's tree order, so a renamed chain is matched from its top."""
    a_links, b_links = _first_by_name(a.links), _first_by_name(b.links)
    mapping = {name: name for name in a_links if name in b_links}
    # a name that moved to another link (base_link -> base_link_inertia, base_link_fixed ->
    # base_link): a new name at the other side is that link (four or five of joint type,
    # origin, axis, inertia, geometry agree), the link keeping the name is far less like it
    new_names = [n for n in b_links if n not in a_links]
    for name in list(mapping):
        if not new_names:
            break
        kept = _similarity(a, name, b, name)
        if kept >= 3:
            continue
        scored = sorted(((_similarity(a, name, b, n), n) for n in new_names), reverse=True)
        if scored[0][0] >= max(4, kept + 2) and (len(scored) == 1 or scored[1][0] < scored[0][0]):
            mapping[name] = scored[0][1]
            new_names.remove(scored[0][1])
    taken = set(mapping.values())
    order = _tree_order(b)
    changed = True
    while changed:
        changed = False
        unmatched_a = [n for n in a_links if n not in mapping]
        if not unmatched_a:
            break
        inverse = {v: k for k, v in mapping.items()}
        for name in order:
            if name in taken:
                continue
            joint = b.parent_joint(name)
            if joint is None:
                candidates = [n for n in unmatched_a if a.parent_joint(n) is None]
            elif joint.parent in inverse:
                parent = inverse[joint.parent]
                candidates = [n for n in unmatched_a if (a.parent_joint(n) is not None
                                                         and a.parent_joint(n).parent == parent)]
            else:
                continue
            candidates = [n for n in candidates if n not in mapping]
            if not candidates:
                continue
            scored = sorted(((_similarity(a, n, b, name), -i, n) for i, n in enumerate(candidates)),
                            reverse=True)
            best, _, chosen = scored[0]
            siblings = [n for n in order if n not in taken and _same_parent(b, n, name)]
            alone = len(candidates) == 1 and len(siblings) == 1
            if best >= 3 or (alone and (best >= 1 or joint is None)):  # (the one root left)
                mapping[chosen] = name
                taken.add(name)
                inverse[name] = chosen
                unmatched_a.remove(chosen)
                changed = True
    return mapping


def _same_parent(robot: Robot, one: str, other: str) -> bool:
    ja, jb = robot.parent_joint(one), robot.parent_joint(other)
    if ja is None or jb is None:
        return ja is None and jb is None
    return ja.parent == jb.parent


def _tree_order(robot: Robot) -> list[str]:
    """Link names from the roots down (breadth first), then any link not reached."""
    order, seen = [], set()
    todo = list(robot.roots())
    while todo:
        name = todo.pop(0)
        if name in seen:
            continue
        seen.add(name)
        order.append(name)
        todo.extend(j.child for j in robot.child_joints(name) if j.child is not None)
    order.extend(l.name for l in robot.links if l.name is not None and l.name not in seen)
    return order


def match_joints(a: Robot, b: Robot, links: dict[str, str]) -> dict[str, str]:
    """A joint name -> B joint name: by name, then a renamed joint is the one whose child link
    is the (matched) child of the other."""
    a_joints, b_joints = _first_by_name(a.joints), _first_by_name(b.joints)
    mapping = {name: name for name in a_joints if name in b_joints}
    taken = set(mapping.values())
    by_child = {j.child: j.name for j in b_joints.values() if j.name not in taken}
    for name, joint in a_joints.items():
        if name in mapping or joint.child not in links:
            continue
        other = by_child.get(links[joint.child])
        if other is not None and other not in taken:
            mapping[name] = other
            taken.add(other)
    return mapping


# -- the comparison ---------------------------------------------------------------------------


class Comparison:
    """The changes between ``a`` (BASE) and ``b`` (HEAD). ``mesh`` reads a mesh geometry's
    content: ``digest(robot, geometry)`` (None when it cannot be read) and
    ``summary(robot, geometry)`` (a ``physics.meshes.MeshInfo``); without it mesh files are
    compared by name and scale only."""

    def __init__(self, a: Robot, b: Robot, mesh=None):
        self.a, self.b = a, b
        self.mesh = mesh
        self.changes: list[Change] = []
        self._elements: dict[tuple[int, str, str], Any] = {}

    # locations of sub-elements the model does not record (an origin, an axis)
    def _sub_loc(self, robot: Robot, tag: str, name: str | None, child: str, fallback):
        """Where ``child`` (a path of tags: "inertial/origin") of the first <tag name=...> of
        ``robot`` was written, else ``fallback``."""
        if robot.root is None or name is None:
            return fallback
        key = (id(robot), tag, name)
        if key not in self._elements:
            for element in robot.root:
                found = (id(robot), element.tag, element.get("name"))
                if element.tag in ("link", "joint") and found not in self._elements:
                    self._elements[found] = element
            self._elements.setdefault(key, None)
        element = self._elements[key]
        for step in child.split("/"):
            if element is None:
                return fallback
            element = next((sub for sub in element if sub.tag == step), None)
        return robot.loc(element) if element is not None else fallback

    def add(self, element, name, aspect, before, after, loc, base_loc, summary, size=1.0,
            **extra) -> None:
        self.changes.append(Change(element, name, aspect, before, after, loc, base_loc, summary,
                                   extra, size))

    def run(self) -> list[Change]:
        a, b = self.a, self.b
        if a.name != b.name:
            self.add("robot", b.name, "renamed", a.name, b.name, b.loc(b.root) if b.root is not
                     None else None, a.loc(a.root) if a.root is not None else None,
                     f"robot renamed from '{a.name}' to '{b.name}'")
        self.links = match_links(a, b)
        self.joints = match_joints(a, b, self.links)
        self._structure("link", _first_by_name(a.links), _first_by_name(b.links), self.links)
        self._structure("joint", _first_by_name(a.joints), _first_by_name(b.joints), self.joints)
        b_links = _first_by_name(b.links)
        for name_a, link_a in _first_by_name(a.links).items():
            if name_a in self.links:
                self._link(link_a, b_links[self.links[name_a]])
        b_joints = _first_by_name(b.joints)
        for name_a, joint_a in _first_by_name(a.joints).items():
            if name_a in self.joints:
                self._joint(joint_a, b_joints[self.joints[name_a]])
        self._materials()
        for tag, key in (("gazebo", "reference"), ("ros2_control", "name"),
                         ("transmission", "name")):
            self._blocks(tag, key)
        return self.changes

    def _structure(self, element: str, in_a: dict, in_b: dict, mapping: dict) -> None:
        matched_b = set(mapping.values())
        for name, record in in_a.items():
            if name not in mapping:
                self.add(element, name, "removed", name, None, None, record.loc,
                         f"{element} '{name}' removed", size=2.0)
            elif mapping[name] != name:
                self.add(element, mapping[name], "renamed", name, mapping[name],
                         in_b[mapping[name]].loc, record.loc,
                         f"{element} '{name}' renamed to '{mapping[name]}'", size=2.0)
        for name, record in in_b.items():
            if name not in matched_b:
                self.add(element, name, "added", None, name, record.loc, None,
                         f"{element} '{name}' added", size=2.0)

    # -- joints ---------------------------------------------------------------------------

    def _joint(self, ja: Joint, jb: Joint) -> None:
        name = jb.name
        if ja.type != jb.type:
            self.add("joint", name, "type", ja.type, jb.type, jb.loc, ja.loc,
                     f"joint '{name}' type {ja.type} -> {jb.type}", size=2.0)
        for aspect in ("parent", "child"):
            before, after = getattr(ja, aspect), getattr(jb, aspect)
            if self.links.get(before, before) != after:
                self.add("joint", name, aspect, before, after,
                         self._sub_loc(self.b, "joint", name, aspect, jb.loc),
                         self._sub_loc(self.a, "joint", ja.name, aspect, ja.loc),
                         f"joint '{name}' {aspect} '{before}' -> '{after}'", size=2.0)
        if not same_pose(ja.origin, jb.origin):
            self._origin(ja, jb)
        axis_a, axis_b = _unit(ja.axis_or_default), _unit(jb.axis_or_default)
        if not same_vector(axis_a, axis_b) and (ja.moving or jb.moving):
            angle = math.acos(max(-1.0, min(1.0, phys.dot(axis_a, axis_b)))) \
                if axis_a and axis_b else math.pi
            self.add("joint", name, "axis", list(ja.axis_or_default), list(jb.axis_or_default),
                     self._sub_loc(self.b, "joint", name, "axis", jb.loc),
                     self._sub_loc(self.a, "joint", ja.name, "axis", ja.loc),
                     f"joint '{name}' axis {_vec(ja.axis_or_default)} -> "
                     f"{_vec(jb.axis_or_default)} ({math.degrees(angle):.3g}°)",
                     size=max(angle, 1.0), angle=angle)
        self._limit(ja, jb)
        mimic_a = self._mimic(ja, mapped=True)
        mimic_b = self._mimic(jb)
        if mimic_a != mimic_b and not _same_dicts(mimic_a, mimic_b):
            self.add("joint", name, "mimic", self._mimic(ja), mimic_b,
                     jb.mimic.loc if jb.mimic else jb.loc, ja.mimic.loc if ja.mimic else ja.loc,
                     f"joint '{name}' mimic {_dict(self._mimic(ja))} -> {_dict(mimic_b)}")
        for aspect, field, defaults, keys in (
                ("dynamics", "dynamics", (0.0, 0.0), ("damping", "friction")),
                ("safety_controller", "safety", None,
                 ("soft_lower_limit", "soft_upper_limit", "k_position", "k_velocity")),
                ("calibration", "calibration", None, ("rising", "falling"))):
            ra, rb = getattr(ja, field), getattr(jb, field)
            va = _values(ra, keys, defaults)
            vb = _values(rb, keys, defaults)
            if not _same_dicts(va, vb):
                self.add("joint", name, aspect, va, vb, rb.loc if rb else jb.loc,
                         ra.loc if ra else ja.loc,
                         f"joint '{name}' {aspect} {_dict(va)} -> {_dict(vb)}",
                         size=_largest_relative(va, vb))

    def _mimic(self, joint: Joint, mapped: bool = False) -> dict | None:
        m = joint.mimic
        if m is None:
            return None
        leader = self.joints.get(m.joint, m.joint) if mapped else m.joint
        return {"joint": leader, "multiplier": m.multiplier, "offset": m.offset}

    def _limit(self, ja: Joint, jb: Joint) -> None:
        la, lb = ja.limit, jb.limit
        for field in ("lower", "upper", "effort", "velocity"):
            before = getattr(la, field) if la is not None else None
            after = getattr(lb, field) if lb is not None else None
            if field in ("lower", "upper") and "continuous" in (ja.type, jb.type) and \
                    ja.type == jb.type:
                continue  # a continuous joint's range is read by no consumer
            if not same(before, after):
                self.add("joint", jb.name, f"limit.{field}", before, after,
                         lb.loc if lb is not None else jb.loc,
                         la.loc if la is not None else ja.loc,
                         f"joint '{jb.name}' limit {field} {_num(before)} -> {_num(after)}",
                         size=_relative_size(before, after),
                         **({"relative_change": relative_change(before, after)}
                            if before is not None and after is not None else {}))

    def _origin(self, ja: Joint, jb: Joint) -> None:
        effect = origin_effect(self.b, jb, ja.origin)
        loc = self._sub_loc(self.b, "joint", jb.name, "origin", jb.loc)
        base = self._sub_loc(self.a, "joint", ja.name, "origin", ja.loc)
        self.add("joint", jb.name, "origin", _pose_json(ja.origin), _pose_json(jb.origin), loc,
                 base, f"joint '{jb.name}' origin {_pose_text(ja.origin)} -> "
                 f"{_pose_text(jb.origin)}: {effect['links_moved']} link(s) below move up to "
                 f"{effect['max_displacement'] * 1000:.4g} mm and turn up to "
                 f"{math.degrees(effect['max_rotation']):.4g}°",
                 size=effect["max_displacement"] + effect["max_rotation"] * 0.1, effect=effect)

    # -- links ----------------------------------------------------------------------------

    def _link(self, la: Link, lb: Link) -> None:
        name = lb.name
        ia, ib = la.inertial, lb.inertial
        mass_a = ia.mass if ia is not None else None
        mass_b = ib.mass if ib is not None else None
        if not same(mass_a, mass_b):
            rel = relative_change(mass_a, mass_b) if mass_a is not None and mass_b is not None \
                else None
            self.add("link", name, "mass", mass_a, mass_b,
                     (ib.mass_loc or ib.loc) if ib else lb.loc,
                     (ia.mass_loc or ia.loc) if ia else la.loc,
                     f"link '{name}' mass {_num(mass_a)} -> {_num(mass_b)} kg" + _rel_text(rel),
                     **_rel_fields(rel))
        com_a = ia.origin.xyz if ia is not None else None
        com_b = ib.origin.xyz if ib is not None else None
        if not same_vector(com_a, com_b) and not (com_a is None and com_b == (0.0, 0.0, 0.0)) \
                and not (com_b is None and com_a == (0.0, 0.0, 0.0)):
            distance = math.dist(com_a or (0, 0, 0), com_b or (0, 0, 0))
            self.add("link", name, "com", list(com_a) if com_a else None,
                     list(com_b) if com_b else None,
                     self._sub_loc(self.b, "link", lb.name, "inertial/origin",
                                   ib.loc if ib else lb.loc),
                     self._sub_loc(self.a, "link", la.name, "inertial/origin",
                                   ia.loc if ia else la.loc),
                     f"link '{name}' centre of mass moves {distance * 1000:.4g} mm",
                     size=distance, distance=distance)
        ta, tb = _tensor_in_link(la), _tensor_in_link(lb)
        if not _same_tensor(ta, tb):
            pa = list(phys.principal_moments(ta)) if ta is not None else None
            pb = list(phys.principal_moments(tb)) if tb is not None else None
            rel = None
            if ta is not None and tb is not None and phys.frobenius(ta) > 0:
                rel = phys.frobenius(phys.mat_add(tb, phys.mat_scale(ta, -1.0))) / \
                    phys.frobenius(ta)
            self.add("link", name, "inertia", pa, pb,
                     (ib.inertia_loc or ib.loc) if ib else lb.loc,
                     (ia.inertia_loc or ia.loc) if ia else la.loc,
                     f"link '{name}' inertia: principal moments {_vec(pa)} -> {_vec(pb)} kg·m²"
                     + _rel_text(rel), **_rel_fields(rel))
        for role in ("visual", "collision"):
            self._shapes(role, la, lb)

    def _shapes(self, role: str, la: Link, lb: Link) -> None:
        sa = la.visuals if role == "visual" else la.collisions
        sb = lb.visuals if role == "visual" else lb.collisions
        name = lb.name
        for index in range(max(len(sa), len(sb))):
            a = sa[index] if index < len(sa) else None
            b = sb[index] if index < len(sb) else None
            label = f"link '{name}' {role}" + (f" {index + 1}" if max(len(sa), len(sb)) > 1 else "")
            if a is None or b is None:
                self.add("link", name, role, _shape_json(a), _shape_json(b),
                         b.loc if b else lb.loc, a.loc if a else la.loc,
                         f"{label} {'added' if a is None else 'removed'}", size=1.0, index=index)
                continue
            what = _shape_differences(a, b)
            if what:
                self.add("link", name, role, _shape_json(a), _shape_json(b), b.loc, a.loc,
                         f"{label}: {', '.join(what)}", size=1.0, index=index,
                         differs=[w.split(" ", 1)[0] for w in what])
            elif a.geometry.kind == "mesh" and self.mesh is not None:
                self._mesh_content(label, name, role, index, a, b)
            if role == "visual" and self.links.get(la.name) is not None and \
                    a.material != b.material:
                self.add("link", name, "material", a.material, b.material, b.loc, a.loc,
                         f"{label} material '{a.material}' -> '{b.material}'", size=0.1,
                         index=index)

    def _mesh_content(self, label, name, role, index, a: Shape, b: Shape) -> None:
        before = self.mesh.digest(self.a, a.geometry)
        after = self.mesh.digest(self.b, b.geometry)
        if before is None or after is None or before == after:
            return
        sa = _mesh_json(self.mesh.summary(self.a, a.geometry))
        sb = _mesh_json(self.mesh.summary(self.b, b.geometry))
        if sa is not None and sb is not None and _same_dicts(sa, sb):
            return  # the file was written again with the same geometry
        size = 1.0
        text = "mesh content changed"
        if sa is not None and sb is not None:
            extent_a = [h - lo for lo, h in zip(*sa["bbox"])]
            extent_b = [h - lo for lo, h in zip(*sb["bbox"])]
            size = max((abs(y - x) for x, y in zip(extent_a, extent_b)), default=0.0)
            text += f" (bounding box {_vec(extent_a)} -> {_vec(extent_b)} m"
            if sa.get("volume") is not None and sb.get("volume") is not None:
                text += f", volume {_num(sa['volume'])} -> {_num(sb['volume'])} m³"
            text += ")"
        self.add("link", name, role, sa, sb, b.geometry.loc or b.loc, a.geometry.loc or a.loc,
                 f"{label}: {text}", size=size, index=index, mesh=b.geometry.filename,
                 differs=["mesh-content"])

    # -- materials and blocks -------------------------------------------------------------

    def _materials(self) -> None:
        in_a = _first_by_name(m for m in self.a.materials if m.rgba or m.texture)
        in_b = _first_by_name(m for m in self.b.materials if m.rgba or m.texture)
        for name in sorted(set(in_a) | set(in_b)):
            ma, mb = in_a.get(name), in_b.get(name)
            va = {"rgba": list(ma.rgba) if ma.rgba else None, "texture": ma.texture} \
                if ma else None
            vb = {"rgba": list(mb.rgba) if mb.rgba else None, "texture": mb.texture} \
                if mb else None
            if ma is None or mb is None:
                self.add("material", name, "added" if ma is None else "removed", va, vb,
                         mb.loc if mb else None, ma.loc if ma else None,
                         f"material '{name}' {'added' if ma is None else 'removed'}", size=0.1)
            elif not _same_dicts(va, vb):
                self.add("material", name, "material", va, vb, mb.loc, ma.loc,
                         f"material '{name}' {_dict(va)} -> {_dict(vb)}", size=0.1)

    def _blocks(self, tag: str, key: str) -> None:
        grouped_a = _group_blocks(self.a, tag, key)
        grouped_b = _group_blocks(self.b, tag, key)
        rename = self.links if tag == "gazebo" else {}
        rename_joints = self.joints if tag == "gazebo" else {}
        mapped_a = {rename.get(k, rename_joints.get(k, k)): v for k, v in grouped_a.items()}
        for name in sorted(set(mapped_a) | set(grouped_b), key=lambda n: (n is None, n or "")):
            ea, eb = mapped_a.get(name, []), grouped_b.get(name, [])
            what = _tree_differences(ea, eb)
            if not what:
                continue
            shown = name if name is not None else "(robot)"
            aspect = "added" if not ea else "removed" if not eb else "changed"
            self.add(tag, name, aspect, [_xml(e) for e in ea] or None,
                     [_xml(e) for e in eb] or None,
                     self.b.loc(eb[0]) if eb else None, self.a.loc(ea[0]) if ea else None,
                     f"<{tag}> {shown}: " + ("added" if aspect == "added" else "removed"
                                             if aspect == "removed" else "; ".join(what[:3])
                                             + (f" (+{len(what) - 3} more)" if len(what) > 3
                                                else "")),
                     size=0.5)


def _group_blocks(robot: Robot, tag: str, key: str) -> dict:
    grouped: dict = {}
    for element in robot.elements(tag):
        grouped.setdefault(element.get(key), []).append(element)
    return grouped


def _xml(element) -> str:
    from lxml import etree

    return etree.tostring(element, encoding="unicode", with_tail=False).strip()


def _tokens_equal(a: str | None, b: str | None) -> bool:
    """Text or attribute values: the same words, numbers compared as numbers."""
    wa, wb = (a or "").split(), (b or "").split()
    if len(wa) != len(wb):
        return False
    for x, y in zip(wa, wb):
        if x == y:
            continue
        try:
            if not same(float(x), float(y)):
                return False
        except ValueError:
            return False
    return True


def _child_key(element) -> tuple:
    return (element.tag, element.get("name") or element.get("reference") or "")


def _tree_differences(ea: list, eb: list, path: str = "") -> list[str]:
    """What differs between two lists of sibling elements, aligned by tag and name (a
    parameter taken out is one removal, not every later one shifted), as short phrases naming
    the element path."""
    import difflib

    what: list[str] = []
    ea = [e for e in ea if isinstance(e.tag, str)]
    eb = [e for e in eb if isinstance(e.tag, str)]
    matcher = difflib.SequenceMatcher(None, [_child_key(e) for e in ea],
                                      [_child_key(e) for e in eb], autojunk=False)
    for op, i1, i2, j1, j2 in matcher.get_opcodes():
        if op == "equal" or (op == "replace" and i2 - i1 == j2 - j1):
            for a, b in zip(ea[i1:i2], eb[j1:j2]):
                what.extend(_element_differences(a, b, path))
            continue
        what += [f"{path}/{_shown_key(e)} removed" for e in ea[i1:i2]]
        what += [f"{path}/{_shown_key(e)} added" for e in eb[j1:j2]]
    return what


def _shown_key(element) -> str:
    tag, name = _child_key(element)
    return f"{tag}[{name}]" if name else tag


def _element_differences(a, b, path: str) -> list[str]:
    here = f"{path}/{_shown_key(b)}"
    if a.tag != b.tag:
        return [f"{path}/{a.tag} -> {b.tag}"]
    what = []
    for attribute in sorted(set(a.attrib) | set(b.attrib)):
        if not _tokens_equal(a.get(attribute), b.get(attribute)) or \
                (a.get(attribute) is None) != (b.get(attribute) is None):
            what.append(f"{here}@{attribute} {a.get(attribute)!r} -> {b.get(attribute)!r}")
    if not _tokens_equal(a.text, b.text):
        what.append(f"{here} {(a.text or '').strip()!r} -> {(b.text or '').strip()!r}")
    what.extend(_tree_differences(list(a), list(b), here))
    return what


# -- small helpers ----------------------------------------------------------------------------


def _unit(v):
    length = phys.norm(v) if v is not None else 0.0
    return phys.mul(v, 1.0 / length) if length > 0 else None


def _same_tensor(ta, tb) -> bool:
    if ta is None or tb is None:
        return ta is None and tb is None
    scale = max(phys.frobenius(ta), phys.frobenius(tb))
    difference = phys.frobenius(phys.mat_add(tb, phys.mat_scale(ta, -1.0)))
    return difference <= ABS or difference <= REL * scale


def _values(record, keys, defaults) -> dict | None:
    if record is None:
        return dict(zip(keys, defaults)) if defaults is not None else None
    return {k: getattr(record, k) for k in keys}


def _same_dicts(a, b) -> bool:
    if a is None or b is None:
        return a is None and b is None
    if set(a) != set(b):
        return False
    for key in a:
        x, y = a[key], b[key]
        if isinstance(x, (int, float)) or isinstance(y, (int, float)):
            if not same(x, y):
                return False
        elif isinstance(x, (list, tuple)) and isinstance(y, (list, tuple)):
            flat_x, flat_y = _flatten(x), _flatten(y)
            if len(flat_x) != len(flat_y) or not all(
                    same(p, q) if isinstance(p, float) or isinstance(q, float) else p == q
                    for p, q in zip(flat_x, flat_y)):
                return False
        elif x != y:
            return False
    return True


def _flatten(values) -> list:
    out = []
    for value in values:
        if isinstance(value, (list, tuple)):
            out.extend(_flatten(value))
        else:
            out.append(value)
    return out


def _largest_relative(a: dict | None, b: dict | None) -> float:
    if a is None or b is None:
        return 1.0
    return max((_relative_size(a.get(k), b.get(k)) for k in a), default=0.0)


def _relative_size(a, b) -> float:
    if a is None or b is None:
        return 1.0
    change = relative_change(a, b)
    return 1.0 if math.isinf(change) else change


def _shape_json(shape: Shape | None) -> dict | None:
    if shape is None:
        return None
    g = shape.geometry
    data: dict = {"kind": g.kind, "origin": _pose_json(shape.origin)}
    if g.kind == "box":
        data["size"] = list(g.size) if g.size else None
    elif g.kind in ("cylinder", "capsule"):
        data["radius"], data["length"] = g.radius, g.length
    elif g.kind == "sphere":
        data["radius"] = g.radius
    elif g.kind == "mesh":
        data["filename"], data["scale"] = g.filename, list(g.scale)
    if shape.name:
        data["name"] = shape.name
    return data


def _shape_differences(a: Shape, b: Shape) -> list[str]:
    ga, gb = a.geometry, b.geometry
    what = []
    if ga.kind != gb.kind:
        return [f"geometry {ga.kind} -> {gb.kind}"]
    if ga.kind == "box" and not same_vector(ga.size, gb.size):
        what.append(f"size {_vec(ga.size)} -> {_vec(gb.size)}")
    if ga.kind in ("cylinder", "capsule", "sphere") and not same(ga.radius, gb.radius):
        what.append(f"radius {_num(ga.radius)} -> {_num(gb.radius)}")
    if ga.kind in ("cylinder", "capsule") and not same(ga.length, gb.length):
        what.append(f"length {_num(ga.length)} -> {_num(gb.length)}")
    if ga.kind == "mesh":
        if (ga.filename or "").strip() != (gb.filename or "").strip():
            what.append(f"mesh {ga.filename} -> {gb.filename}")
        if not same_vector(ga.scale, gb.scale):
            what.append(f"scale {_vec(ga.scale)} -> {_vec(gb.scale)}")
    if not same_pose(a.origin, b.origin):
        what.append(f"origin {_pose_text(a.origin)} -> {_pose_text(b.origin)}")
    return what


def _mesh_json(info) -> dict | None:
    if info is None or not getattr(info, "ok", False):
        return None
    data = {"bbox": [list(info.lower), list(info.upper)], "faces": info.faces}
    if info.solid is not None:
        data["volume"] = info.solid.volume
    return data


def _num(value) -> str:
    return "none" if value is None else f"{value:.6g}"


def _vec(values) -> str:
    return "none" if values is None else "(" + " ".join(f"{v:.6g}" for v in values) + ")"


def _pose_text(pose: Pose) -> str:
    return f"xyz {_vec(pose.xyz)} rpy {_vec(pose.rpy)}"


def _dict(values: dict | None) -> str:
    if values is None:
        return "none"
    return "{" + ", ".join(f"{k} {_num(v) if isinstance(v, float) else v}"
                           for k, v in values.items()) + "}"


def _rel_text(rel: float | None) -> str:
    return f" ({_percent(rel)})" if rel is not None else ""


def _rel_fields(rel: float | None) -> dict:
    """``size`` and ``relative_change`` of a change with a relative size (1 when unknown)."""
    return {"size": 1.0} if rel is None else {"size": rel, "relative_change": rel}


def _percent(rel: float) -> str:
    return "new" if math.isinf(rel) else f"{rel * 100:.3g} %"


# -- the effect of an origin ------------------------------------------------------------------


def subtree_poses(robot: Robot, link: str) -> list[tuple[str, Any]]:
    """(link, 4x4 pose in ``link``'s frame) of ``link`` and every link below it at the zero
    configuration: the product of the joint origins (``kinematics.fk.pose_matrix``)."""
    import numpy as np

    from urdftool.kinematics.fk import pose_matrix

    found = [(link, np.eye(4))]
    todo = [(link, np.eye(4))]
    seen = {link}
    while todo:
        name, pose = todo.pop()
        for joint in robot.child_joints(name):
            if joint.child is None or joint.child in seen:
                continue
            seen.add(joint.child)
            below = pose @ pose_matrix(joint.origin)
            found.append((joint.child, below))
            todo.append((joint.child, below))
    return found


def origin_effect(robot: Robot, joint: Joint, before: Pose) -> dict:
    """How the links below ``joint`` (of ``robot``, the new side) move in its parent's frame
    when its origin goes from ``before`` to ``joint.origin``, at the zero configuration."""
    import numpy as np

    from urdftool.kinematics.fk import pose_matrix

    old, new = pose_matrix(before), pose_matrix(joint.origin)
    moved, largest = 0, 0.0
    turn = rotation_angle(before, joint.origin)
    if joint.child is None:
        return {"links_moved": 0, "max_displacement": 0.0, "max_rotation": turn}
    for _, pose in subtree_poses(robot, joint.child):
        displacement = float(np.linalg.norm((new @ pose)[:3, 3] - (old @ pose)[:3, 3]))
        if displacement > ABS or turn > REL:
            moved += 1
        largest = max(largest, displacement)
    return {"links_moved": moved, "max_displacement": largest, "max_rotation": turn}


def compare(a: Robot, b: Robot, mesh=None) -> list[Change]:
    """The changes from robot ``a`` (BASE) to robot ``b`` (HEAD)."""
    return Comparison(a, b, mesh).run()
