"""SDFormat model -> URDF document.

URDF puts each child link's frame at its joint, so for every moving joint the child link's
frame becomes the joint frame and the child's visuals, collisions, inertial and sensors are
re-expressed in it. Root links and links hung on fixed joints keep their SDF link frame. Joint
origins go from the parent's URDF frame to the joint frame, all resolved through the SDF pose
graph at the zero configuration. Numbers are written with ``repr`` (never rounded).

What URDF cannot express gets an ``sdf.*`` diagnostic and the nearest safe form: split joints
for ball/universal/revolute2/screw, a mimic for gearbox, loops cut, capsules as a cylinder and
two spheres, ellipsoids and cones enclosed, planes and heightmaps dropped; sensors and plugins
are kept in ``<gazebo>`` blocks.
"""

from __future__ import annotations

import copy
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from urdftool.sdf.frames import WORLD, PoseGraph
from urdftool.sdf.reader import Entity, Reader, Scope
from urdftool.sdf.schema import JOINT_TYPES
from urdftool.sdf.transforms import IDENTITY, Transform
from urdftool.uris import parse_uri

UNBOUNDED = 1e16  # SDF's own "no limit" (the default of <lower>/<upper> up to 1.9)
DEFAULT_MASS = 1.0  # kg: SDFormat's mass of a link without <inertial> (inertia diag(1, 1, 1))
# sdf.default-inertial: a warning when the default masses are this share of the model's mass
# in Gazebo, an error when they are most of it (they dominate its dynamics)
DEFAULT_WARNING_SHARE, DEFAULT_ERROR_SHARE = 0.1, 0.5


def _static(scope: Scope) -> bool:
    """The scope's model, or a model it is nested in, is static: Gazebo never moves it."""
    while scope is not None:
        if scope.static:
            return True
        scope = scope.parent
    return False
MOVING = ("revolute", "continuous", "prismatic")
GAZEBO_MASSLESS = ("for Gazebo, give the links between the joints a small <inertial>: its URDF "
                   "reader drops moving links of zero mass")


class ModelChoiceError(Exception):
    """The file has no model, or several and none (or a missing one) was chosen."""


class LoopRefused(Exception):
    """The model has a kinematic loop and cutting was refused (--no-cut)."""


@dataclass
class ConvertOptions:
    model: str | None = None
    model_paths: list[str] = field(default_factory=list)
    package_uris: list[str] = field(default_factory=list)  # "PREFIX" or "MODEL=PREFIX"
    output_dir: Path | None = None  # relative mesh paths are written relative to this
    cut_loops: bool = True
    require_choice: bool = False  # several models and none chosen: error (convert) or first


def fmt(value: float) -> str:
    value = float(value) + 0.0
    if math.isfinite(value) and value == int(value) and abs(value) < 1e15:
        return repr(float(int(value)))
    return repr(value)


def fmtv(values) -> str:
    return " ".join(fmt(v) for v in values)


@dataclass
class JointInfo:
    entity: Entity
    type: str
    parent: str | None  # link key or WORLD
    child: str | None
    reversed: bool = False  # URDF parent is the SDF child (the tree needed it the other way)
    mimic_of: tuple[str, float] | None = None  # gearbox: (leader joint key, multiplier)

    @property
    def key(self) -> str:
        return self.entity.key

    @property
    def urdf_parent(self) -> str | None:
        return self.child if self.reversed else self.parent

    @property
    def urdf_child(self) -> str | None:
        return self.parent if self.reversed else self.child


class Builder:
    def __init__(self, source, reader: Reader, top: Scope, options: ConvertOptions):
        self.source = source
        self.reader = reader
        self.top = top
        self.options = options
        self.graph = PoseGraph(top, reader)
        # an element whose name an earlier one took (sdf.duplicate-name) is left out, as
        # libsdformat leaves it out: a URDF cannot hold two links or joints of one name
        self.links: list[Entity] = [e for s in top.walk() for e in s.links if self.named(e)]
        self.frames: list[Entity] = [e for s in top.walk() for e in s.frames if self.named(e)]
        self.link_keys = {e.key for e in self.links}
        self.names: dict[str, str] = {}  # scoped key -> URDF link name
        self.joint_names: dict[str, str] = {}
        self._used_links: set[str] = set()
        self._used_joints: set[str] = set()
        self.frame_of: dict[str, Transform] = {}  # URDF link name -> pose in the top model frame
        self.root = etree.Element("robot", name=top.name or "robot")
        self.materials: dict[tuple, str] = {}
        self.material_elements: list = []
        self.unlimited: list[tuple[str, object]] = []
        # meshes kept as written, by what is missing (a model, the network): reported once each
        self.unread_meshes: dict[str, list[tuple[str, object]]] = {}
        self.defaulted: list[Entity] = []  # links of moving models without <inertial>
        self.authored_mass = 0.0  # what the <inertial>s of moving models declare

    def named(self, entity: Entity) -> bool:
        node = self.graph.nodes.get(entity.key)
        return node is not None and node.entity is entity

    # -- helpers ----------------------------------------------------------------------------

    def mark(self, urdf_element, sdf_element) -> None:
        if sdf_element is not None:
            self.source.locs[urdf_element] = self.reader.loc(sdf_element)

    def report(self, rule, message, element, hint=None, severity=None) -> None:
        self.reader.report(rule, message, element, hint, severity)

    def _unique(self, wanted: str, used: set[str]) -> str:
        name, n = wanted, 2
        while name in used:
            name = f"{wanted}_{n}"
            n += 1
        used.add(name)
        return name

    def link_name(self, key: str) -> str:
        if key not in self.names:
            wanted = "world" if key == WORLD else key.replace("::", "__")
            self.names[key] = self._unique(wanted, self._used_links)
        return self.names[key]

    def joint_name(self, key: str, suffix: str = "") -> str:
        full = key + suffix
        if full not in self.joint_names:
            self.joint_names[full] = self._unique(full.replace("::", "__"), self._used_joints)
        return self.joint_names[full]

    def sub(self, parent, tag: str, sdf_element=None, **attrs):
        element = etree.SubElement(parent, tag, {k: v for k, v in attrs.items() if v is not None})
        self.mark(element, sdf_element)
        return element

    def origin(self, parent, transform: Transform, sdf_element) -> None:
        if transform.is_identity:
            return
        self.sub(parent, "origin", sdf_element, xyz=fmtv(transform.xyz), rpy=fmtv(transform.rpy))

    def placed(self, scope: Scope, default_key: str, element) -> Transform:
        """Pose (in the top model frame) of a visual, collision, sensor... of a link."""
        raw, pose_element, relative_to = self.reader.pose(element, scope.version)
        base = default_key
        if relative_to:
            key = self.graph.reference(scope, relative_to, pose_element, "relative_to")
            if key is not None:
                base = key
        return self.graph.pose(base) * raw

    # -- the conversion ---------------------------------------------------------------------

    def build(self) -> etree._Element:
        for entity in self.links:
            self.link_name(entity.key)
        joints = self.read_joints()
        self.apply_gearboxes(joints)
        kept = self.choose_tree(joints)
        parent_joint = {j.urdf_child: j for j in kept}
        # URDF frames: a moving joint's child sits at the joint frame
        for entity in self.links:
            joint = parent_joint.get(entity.key)
            if joint is not None and joint.type != "fixed":
                self.frame_of[self.names[entity.key]] = self.graph.pose(joint.key)
            else:
                self.frame_of[self.names[entity.key]] = self.graph.pose(entity.key)
        if any(j.urdf_parent == WORLD for j in kept):
            world = self.link_name(WORLD)
            self.frame_of[world] = self.graph.pose(WORLD)
            element = self.sub(self.root, "link", None, name=world)
            self.source.locs[element] = self.reader.loc(self.top.element)
        for entity in self.links:
            self.emit_link(entity, parent_joint.get(entity.key))
        for joint in kept:
            self.emit_joint(joint)
        self.attach_roots(kept)
        self.emit_frames()
        self.emit_model_extras()
        self.report_unlimited()
        self.report_unread_meshes()
        self.report_defaults()
        for element in reversed(self.material_elements):
            self.root.insert(0, element)
        self.add_name_comment()
        return self.root

    # -- joints -----------------------------------------------------------------------------

    def read_joints(self) -> list[JointInfo]:
        result = []
        for scope in self.top.walk():
            for entity in filter(self.named, scope.joints):
                info = self.read_joint(entity)
                if info is not None:
                    result.append(info)
        return result

    def read_joint(self, entity: Entity) -> JointInfo | None:
        element = entity.element
        joint_type = (element.get("type") or "").strip()
        if not joint_type:
            self.report("sdf.missing-element", f"joint '{entity.name}' has no type", element,
                        hint='write type="revolute" (or fixed, prismatic, continuous, ...)')
            return None
        if joint_type not in JOINT_TYPES:
            import difflib

            guess = difflib.get_close_matches(joint_type, JOINT_TYPES, n=1)
            self.report("sdf.bad-value", f"joint '{entity.name}' has unknown type '{joint_type}'",
                        element, hint=f"did you mean '{guess[0]}'?" if guess else
                        "types: " + ", ".join(JOINT_TYPES))
            return None
        ends = []
        for tag in ("parent", "child"):
            child = element.find(tag)
            name = (child.text or "").strip() if child is not None else ""
            if not name:
                self.report("sdf.missing-element", f"joint '{entity.name}' has no <{tag}>",
                            child if child is not None else element,
                            hint=f"write <{tag}>LINK</{tag}>")
                return None
            if name == "world" and entity.scope.prefix + "world" not in self.graph.nodes:
                if tag == "child":
                    self.report("sdf.bad-value", f"joint '{entity.name}': the child cannot be "
                                "'world'", child, hint="swap parent and child")
                    return None
                ends.append(WORLD)
                continue
            key = self.graph.link_written(entity.scope, name) or \
                self.graph.reference(entity.scope, name, child, f"joint {tag}")
            if key is None:
                if self.reader.is_lost(entity.scope.prefix + name):
                    self.reader.lost.append(entity.key)  # left out with the include
                return None
            link = self.graph.attached_link(key)
            if link is None:
                return None
            ends.append(link)
        if ends[0] == ends[1]:
            self.report("sdf.bad-value", f"joint '{entity.name}' joins link "
                        f"'{ends[0]}' to itself", element, hint="name two different links")
            return None
        return JointInfo(entity, joint_type, ends[0], ends[1])

    def apply_gearboxes(self, joints: list[JointInfo]) -> None:
        """A gearbox couples two joints hinged on a reference body: theta2 = -ratio * theta1.
        URDF: the child's hinge mimics the parent's; the gearbox joint itself is dropped."""
        by_child = {}
        for joint in joints:
            if joint.type != "gearbox":
                by_child.setdefault(joint.child, []).append(joint)
        for joint in [j for j in joints if j.type == "gearbox"]:
            element = joint.entity.element
            ratio = self.reader.number(element, "gearbox_ratio", 1.0)
            reference = (element.findtext("gearbox_reference_body") or "").strip()
            ref_key = self.graph.lookup(joint.entity.scope, reference) if reference else None
            ref_link = self.graph.attached_link(ref_key) if ref_key else None
            leader = [j for j in by_child.get(joint.parent, []) if j.parent == ref_link
                      and j.type in ("revolute", "continuous")]
            follower = [j for j in by_child.get(joint.child, []) if j.parent == ref_link
                        and j.type in ("revolute", "continuous")]
            joints.remove(joint)
            if leader and follower and follower[0].mimic_of is None:
                follower[0].mimic_of = (leader[0].key, -ratio)
                self.report("sdf.unsupported-joint",
                            f"gearbox joint '{joint.entity.name}' has no URDF equivalent: "
                            f"joint '{follower[0].entity.name}' now mimics "
                            f"'{leader[0].entity.name}' with multiplier {-ratio:g}, and the "
                            "gearbox joint is dropped", element)
            else:
                self.report("sdf.unsupported-joint",
                            f"gearbox joint '{joint.entity.name}' has no URDF equivalent and "
                            "its links are not both hinged on the reference body "
                            f"'{reference}': dropped", element,
                            hint="add a <mimic> between the two hinges by hand")

    def choose_tree(self, joints: list[JointInfo]) -> list[JointInfo]:
        """The joints URDF keeps: a spanning tree of each connected group of links, grown from
        its root (the world, else the link no joint hangs, canonical first) by always taking
        the next joint that hangs a new link the SDF way round, in document order, and only
        then one that must be reversed. A joint whose two links are already attached closes a
        loop and is cut; every other link stays attached (reversed joints where needed)."""
        import heapq

        index = {id(j): i for i, j in enumerate(joints)}
        edges: dict[str, list[JointInfo]] = {}
        has_parent: set[str] = set()
        for joint in joints:
            edges.setdefault(joint.parent, []).append(joint)
            edges.setdefault(joint.child, []).append(joint)
            has_parent.add(joint.child)
        canonical = self.graph.canonical_link(self.top)
        position = {e.key: i for i, e in enumerate(self.links)}
        order = ([WORLD] if WORLD in edges else []) + \
            ([canonical] if canonical in self.link_keys else []) + [e.key for e in self.links]
        tree_parent: dict[str, tuple[str, JointInfo]] = {}  # link -> (URDF parent, joint)
        visited: set[str] = set()
        decided: set[int] = set()
        self.root_of: dict[str, str] = {}
        cut: list[JointInfo] = []
        for start in order:
            if start in visited:
                continue
            if start != WORLD and start in has_parent:  # grow from the world or an SDF root
                group = self._group(start, edges)
                roots = sorted((k for k in group if k not in has_parent),
                               key=lambda k: (k != canonical, position.get(k, -1)))
                start = roots[0] if roots else start
            self.root_of[start] = start
            visited.add(start)
            heap = [(j.child == start, index[id(j)], start, j) for j in edges.get(start, ())
                    if id(j) not in decided]
            heapq.heapify(heap)
            while heap:
                reversed_, _, node, joint = heapq.heappop(heap)
                if id(joint) in decided:
                    continue
                decided.add(id(joint))
                other = joint.parent if reversed_ else joint.child
                if other in visited:
                    cut.append(joint)
                    continue
                joint.reversed = bool(reversed_)
                tree_parent[other] = (node, joint)
                self.root_of[other] = self.root_of[node]
                visited.add(other)
                for j in edges.get(other, ()):
                    if id(j) not in decided:
                        heapq.heappush(heap, (j.child == other, index[id(j)], other, j))
        cut_ids = {id(j) for j in cut}
        kept = [j for j in joints if id(j) not in cut_ids]
        for joint in kept:
            if joint.reversed:
                self.report_reversed(joint, tree_parent)
        for joint in sorted(cut, key=lambda j: index[id(j)]):
            loop = self._loop(joint, tree_parent)
            if not self.options.cut_loops:
                raise LoopRefused(
                    f"joint '{joint.entity.name}' closes the kinematic loop {loop}; URDF is a "
                    "tree. Without --no-cut, urdftool cuts that joint.")
            self.report("sdf.kinematic-loop",
                        f"joint '{joint.entity.name}' closes the kinematic loop {loop}; URDF is "
                        "a tree, so it is cut (both its links are already attached through the "
                        "other joints of the loop, so every link stays attached) and the loop is "
                        "left open (Gazebo simulates the closed loop; URDF tools see the open "
                        "chain)", joint.entity.element,
                        hint="close the loop in the simulator (e.g. a joint constraint plugin "
                             "between the two links)")
        self.tree_parent = tree_parent
        return kept

    @staticmethod
    def _group(start: str, edges: dict[str, list[JointInfo]]) -> list[str]:
        """The links joined to ``start`` through any joints (either way round)."""
        seen, todo = {start}, [start]
        while todo:
            node = todo.pop()
            for joint in edges.get(node, ()):
                for other in (joint.parent, joint.child):
                    if other not in seen:
                        seen.add(other)
                        todo.append(other)
        return list(seen)

    def _loop(self, joint: JointInfo, tree_parent) -> str:
        """'a -> b -> c -> a' through the tree between the cut joint's links (shortest way)."""
        def up(node: str) -> list[str]:
            path = [node]
            while node in tree_parent:
                node = tree_parent[node][0]
                path.append(node)
            return path

        a, b = up(joint.parent), up(joint.child)
        common = next((n for n in a if n in set(b)), None)
        path = a[:a.index(common) + 1] + list(reversed(b[:b.index(common)])) if common else a
        names = [self.link_name(n) if n == WORLD else n for n in path]
        return " - ".join(f"'{n}'" for n in names + names[:1])

    def report_reversed(self, joint: JointInfo, tree_parent) -> None:
        name = joint.entity.name
        self.report("sdf.reversed-joint",
                    f"joint '{name}' is written reversed (parent '{joint.child}', child "
                    f"'{joint.parent}'): in SDF link '{joint.child}' already hangs on joint "
                    f"'{tree_parent[joint.child][1].entity.name}', and URDF gives a link one "
                    f"parent, so '{joint.parent}' hangs on '{joint.child}' instead. The origin "
                    "is inverted and the axis flipped, so +q is the same motion as in the SDF",
                    joint.entity.element, severity="info",
                    hint=f"write the joint with <parent>{joint.child}</parent> and "
                         f"<child>{joint.parent}</child> if that is what you mean")

    def limits(self, axis, joint_type: str):
        """lower, upper, effort, velocity (None where unbounded/unlimited)."""
        if axis is None:
            return None, None, None, None
        limit = axis.find("limit")
        if limit is None:
            return None, None, None, None
        values = []
        for tag in ("lower", "upper", "effort", "velocity"):
            value = self.reader.number(limit, tag, None)
            if value is not None and (math.isinf(value) or abs(value) >= UNBOUNDED
                                      or (tag in ("effort", "velocity") and value < 0)):
                value = None
            values.append(value)
        return tuple(values)

    def axis_vector(self, joint: JointInfo, axis) -> tuple[float, float, float]:
        scope = joint.entity.scope
        if axis is None:
            return (0.0, 0.0, 1.0)
        xyz = axis.find("xyz")
        vector = (0.0, 0.0, 1.0)
        if xyz is not None:
            vector = self.reader.parse_vector(xyz, 3, (0.0, 0.0, 1.0))
        expressed_in = None
        version = scope.version
        use_parent = axis.find("use_parent_model_frame")
        if version >= (1, 7):
            expressed_in = xyz.get("expressed_in") if xyz is not None else None
            if use_parent is not None:
                self.report("sdf.version-feature", "use_parent_model_frame was removed in "
                            "SDFormat 1.7 (the axis is in the joint frame); ignored", use_parent,
                            hint='write <xyz expressed_in="__model__"> instead')
        else:
            if xyz is not None and xyz.get("expressed_in") is not None:
                self.report("sdf.version-feature", "xyz/@expressed_in needs SDFormat 1.7; a "
                            f"{version[0]}.{version[1]} reader ignores it", xyz,
                            hint="write use_parent_model_frame, or version 1.7 or newer")
            if version == (1, 4) or (use_parent is not None and self.reader.boolean(
                    axis, "use_parent_model_frame", False)):
                expressed_in = "__model__"
        if expressed_in:
            key = self.graph.reference(scope, expressed_in, xyz if xyz is not None else axis,
                                       "expressed_in")
            if key is not None:
                rotation = self.graph.pose(key).seen_from(self.graph.pose(joint.key))
                vector = Transform(rot=rotation.rot, rpy_hint=None).rotate(vector)
        return vector

    def emit_joint(self, joint: JointInfo) -> None:
        entity = joint.entity
        element = entity.element
        parent_name = self.link_name(joint.urdf_parent)
        child_name = self.names[joint.urdf_child]
        frame = self.graph.pose(joint.key)
        if joint.type == "fixed":
            origin = self.frame_of[child_name].seen_from(self.frame_of[parent_name])
            j = self.sub(self.root, "joint", element, name=self.joint_name(joint.key), type="fixed")
            self.origin(j, origin, entity.pose_element)
            self.sub(j, "parent", element.find("parent"), link=parent_name)
            self.sub(j, "child", element.find("child"), link=child_name)
            return
        origin = frame.seen_from(self.frame_of[parent_name])
        axis = element.find("axis")
        axis2 = element.find("axis2")
        # the single URDF joints from the SDF parent to the SDF child: (name, type, <axis>,
        # vector, extra keyword arguments of ``single``)
        name = entity.name
        middle: list[str] = []
        if joint.type in MOVING:
            steps = [(self.joint_name(joint.key), joint.type, axis,
                      self.axis_vector(joint, axis), {})]
        elif joint.type in ("universal", "revolute2"):
            middle = [self.extra_link(f"{joint.key}__link", element, frame)]
            steps = [(self.joint_name(joint.key), "revolute", axis,
                      self.axis_vector(joint, axis), {}),
                     (self.joint_name(joint.key, "__axis2"), "revolute", axis2,
                      self.axis_vector(joint, axis2), {"axis2": True})]
            self.check_two_axes(joint, axis, axis2, steps[0][3], steps[1][3])
            self.report("sdf.unsupported-joint",
                        f"{joint.type} joint '{name}' has no URDF equivalent: written as two "
                        f"revolute joints '{steps[0][0]}' and '{steps[1][0]}' through the "
                        f"massless link '{middle[0]}'", element, hint=GAZEBO_MASSLESS)
        elif joint.type == "ball":
            middle = [self.extra_link(f"{joint.key}__link1", element, frame),
                      self.extra_link(f"{joint.key}__link2", element, frame)]
            steps = [(self.joint_name(joint.key, suffix), "continuous", None, vector, {})
                     for suffix, vector in (("", (1.0, 0.0, 0.0)), ("__y", (0.0, 1.0, 0.0)),
                                            ("__z", (0.0, 0.0, 1.0)))]
            self.report("sdf.unsupported-joint",
                        f"ball joint '{name}' has no URDF equivalent: written as three "
                        "continuous joints about x, y, z of the joint frame "
                        f"({', '.join(step[0] for step in steps)}) through two massless links; "
                        "the chain has a singularity where the ball has none", element,
                        hint=GAZEBO_MASSLESS)
        elif joint.type == "screw":
            middle = [self.extra_link(f"{joint.key}__link", element, frame)]
            leader = self.joint_name(joint.key)
            vector = self.axis_vector(joint, axis)
            pitch = self.screw_pitch(joint)  # metres per revolution
            multiplier = pitch / (2 * math.pi)
            lower, upper, _, _ = self.limits(axis, "revolute")
            image = None
            if lower is not None and upper is not None:
                image = sorted((lower * multiplier, upper * multiplier))
            follower = self.joint_name(joint.key, "__translation")
            steps = [(leader, "revolute", axis, vector, {}),
                     (follower, "prismatic", axis, vector,
                      {"mimic": (leader, multiplier, 0.0), "bounds": image or (None, None),
                       "dynamics": False})]
            self.report("sdf.unsupported-joint",
                        f"screw joint '{name}' has no URDF equivalent: written as revolute "
                        f"'{leader}' and prismatic '{follower}' mimicking it "
                        f"({multiplier:g} m/rad) through the massless link '{middle[0]}'",
                        element, hint=GAZEBO_MASSLESS)
        else:
            return
        chain = [self.link_name(joint.parent), *middle, self.names[joint.child]]
        if joint.reversed:
            # the inverse motion: the same single joints in the opposite order, each about the
            # opposite axis, so that each keeps its value (+q is the same motion)
            steps = [(n, kind, ax, tuple(-v + 0.0 for v in vector), extra)
                     for n, kind, ax, vector, extra in reversed(steps)]
            chain.reverse()
        for index, (joint_name, kind, axis_element, vector, extra) in enumerate(steps):
            self.single(joint, joint_name, chain[index], chain[index + 1],
                        origin if index == 0 else IDENTITY, kind, axis_element, vector, **extra)

    def check_two_axes(self, joint: JointInfo, axis, axis2, vector, vector2) -> None:
        """A universal or revolute2 joint needs two axes that are not parallel."""
        missing = [tag for tag, element in (("axis", axis), ("axis2", axis2)) if element is None]
        cross = (vector[1] * vector2[2] - vector[2] * vector2[1],
                 vector[2] * vector2[0] - vector[0] * vector2[2],
                 vector[0] * vector2[1] - vector[1] * vector2[0])
        norms = math.hypot(*vector) * math.hypot(*vector2)
        parallel = norms > 0 and math.hypot(*cross) <= 1e-9 * norms
        if not missing and not parallel:
            return
        what = (f"has no <{'> and no <'.join(missing)}>: libsdformat takes SDFormat's default "
                "0 0 1 for each missing axis" if missing else "has parallel axes")
        self.report("sdf.unsupported-joint",
                    f"{joint.type} joint '{joint.entity.name}' {what}"
                    + (", so its two rotations are about the same line: it turns about one axis "
                       "where two were meant (Gazebo builds that degenerate joint; Drake refuses "
                       "the file: 'Both axis and axis2 must be specified')" if parallel else
                       " (Drake refuses the file: 'Both axis and axis2 must be specified')")
                    + "; the URDF repeats what libsdformat reads", joint.entity.element,
                    severity="warning",
                    hint="give both <axis><xyz> and <axis2><xyz>, perpendicular (e.g. 1 0 0 "
                         "and 0 1 0)")

    def screw_pitch(self, joint: JointInfo) -> float:
        element = joint.entity.element
        if element.find("screw_thread_pitch") is not None and joint.entity.scope.version >= (1, 10):
            return self.reader.number(element, "screw_thread_pitch", 1.0)
        thread = self.reader.number(element, "thread_pitch", 1.0)  # rad/m, left-handed
        return -2 * math.pi / thread if thread else 0.0

    def extra_link(self, key: str, sdf_element, frame: Transform) -> str:
        """A link between the single joints of a ball/universal/screw joint. It has no mass
        in SDF, and says so with a zero <inertial>: a URDF link without one gets 1 kg and
        1 kg·m² in PyBullet. (Gazebo's URDF reader drops moving links of zero mass either way:
        the warning's hint says so.)"""
        name = self.link_name(key)
        link = self.sub(self.root, "link", sdf_element, name=name)
        inertial = self.sub(link, "inertial", sdf_element)
        self.sub(inertial, "mass", sdf_element, value=fmt(0.0))
        self.sub(inertial, "inertia", sdf_element, ixx="0.0", ixy="0.0", ixz="0.0", iyy="0.0",
                 iyz="0.0", izz="0.0")
        self.frame_of[name] = frame
        return name

    def single(self, joint: JointInfo, name: str, parent: str, child: str, origin: Transform,
               kind: str, axis, vector, axis2: bool = False, mimic=None, bounds=None,
               dynamics: bool = True) -> None:
        element = joint.entity.element
        lower, upper, effort, velocity = self.limits(axis, kind)
        if bounds is not None:
            lower, upper = bounds
        if kind == "revolute" and (lower is None or upper is None):
            if (lower is None) != (upper is None):
                self.report("sdf.not-in-urdf",
                            f"joint '{joint.entity.name}' is limited on one side only "
                            f"(lower {lower}, upper {upper}); URDF cannot express that: "
                            "written as continuous, without the limit",
                            axis.find("limit") if axis is not None else element,
                            severity="warning")
            kind = "continuous"
        j = self.sub(self.root, "joint", element, name=name, type=kind)
        self.origin(j, origin, joint.entity.pose_element)
        self.sub(j, "parent", element.find("parent"), link=parent)
        self.sub(j, "child", element.find("child"), link=child)
        xyz = axis.find("xyz") if axis is not None else None
        self.sub(j, "axis", xyz if xyz is not None else axis, xyz=fmtv(vector))
        limit_element = axis.find("limit") if axis is not None else None
        if kind in ("revolute", "prismatic") or effort is not None or velocity is not None:
            if kind == "prismatic" and (lower is None or upper is None):
                lower = -UNBOUNDED if lower is None else lower
                upper = UNBOUNDED if upper is None else upper
                self.unlimited.append((f"{name} (range)", limit_element if limit_element
                                       is not None else element))
            if effort is None or velocity is None:
                self.unlimited.append((name, limit_element if limit_element is not None
                                       else element))
            attrs = {"effort": fmt(UNBOUNDED if effort is None else effort),
                     "velocity": fmt(UNBOUNDED if velocity is None else velocity)}
            if kind != "continuous":
                attrs = {"lower": fmt(lower), "upper": fmt(upper), **attrs}
            self.sub(j, "limit", limit_element if limit_element is not None else element, **attrs)
        if axis is not None and dynamics:
            self.dynamics(j, joint, axis)
        self.mimic(j, joint, axis, mimic)

    def dynamics(self, urdf_joint, joint: JointInfo, axis) -> None:
        dynamics = axis.find("dynamics")
        if dynamics is None:
            return
        damping = self.reader.number(dynamics, "damping", 0.0)
        friction = self.reader.number(dynamics, "friction", 0.0)
        if dynamics.find("damping") is not None or dynamics.find("friction") is not None:
            self.sub(urdf_joint, "dynamics", dynamics, damping=fmt(damping),
                     friction=fmt(friction))
        stiffness = self.reader.number(dynamics, "spring_stiffness", 0.0)
        if stiffness:
            self.report("sdf.not-in-urdf",
                        f"joint '{joint.entity.name}' has a spring (stiffness {stiffness:g}, "
                        f"reference {self.reader.number(dynamics, 'spring_reference', 0.0):g}); "
                        "URDF has no joint springs: dropped", dynamics.find("spring_stiffness"),
                        severity="warning", hint="model the spring in a controller or plugin")

    def mimic(self, urdf_joint, joint: JointInfo, axis, mimic) -> None:
        if mimic is not None:
            leader, multiplier, offset = mimic
            self.sub(urdf_joint, "mimic", joint.entity.element, joint=leader,
                     multiplier=fmt(multiplier), offset=fmt(offset))
            return
        if joint.mimic_of is not None:
            leader_key, multiplier = joint.mimic_of
            self.sub(urdf_joint, "mimic", joint.entity.element,
                     joint=self.joint_name(leader_key), multiplier=fmt(multiplier),
                     offset=fmt(0.0))
            return
        element = axis.find("mimic") if axis is not None else None
        if element is None:
            return
        if joint.entity.scope.version < (1, 11):
            self.report("sdf.version-feature", "axis/mimic needs SDFormat 1.11; ignored",
                        element, hint='write <sdf version="1.11">')
            return
        leader = (element.get("joint") or "").strip()
        key = self.graph.reference(joint.entity.scope, leader, element, "mimic joint")
        if key is None:
            return
        multiplier = self.reader.number(element, "multiplier", 1.0)
        offset = self.reader.number(element, "offset", 0.0)
        reference = self.reader.number(element, "reference", 0.0)
        suffix = "__axis2" if (element.get("axis") or "axis") == "axis2" else ""
        # SDF: follower = m (leader - reference) + offset; URDF: follower = m leader + offset
        self.sub(urdf_joint, "mimic", element, joint=self.joint_name(key, suffix),
                 multiplier=fmt(multiplier), offset=fmt(offset - multiplier * reference))

    def attach_roots(self, kept: list[JointInfo]) -> None:
        """URDF has one root: a link (with the links hung on it) that no joint joins to the
        main tree hangs on the main root by a floating joint (fixed in a static model)."""
        children = {j.urdf_child for j in kept}
        roots = [e for e in self.links if e.key not in children]
        if not roots:
            return
        canonical = self.graph.canonical_link(self.top)
        if WORLD in self.root_of:
            main = WORLD
        elif canonical in self.root_of:
            main = self.root_of[canonical]
        else:
            main = canonical if canonical is not None else roots[0].key
        main_name = self.link_name(main)
        hanging: dict[str, int] = {}  # root -> links joined to it (once: many roots, issue 21)
        for k, r in self.root_of.items():
            if k != r:
                hanging[r] = hanging.get(r, 0) + 1
        for entity in roots:
            if entity.key == main:
                continue
            name = self.names[entity.key]
            kind = "fixed" if self.top.static else "floating"
            joint = self.sub(self.root, "joint", entity.element,
                             name=self.joint_name(entity.key, "__" + kind), type=kind)
            self.origin(joint, self.frame_of[name].seen_from(self.frame_of[main_name]),
                        entity.pose_element)
            self.sub(joint, "parent", entity.element, link=main_name)
            self.sub(joint, "child", entity.element, link=name)
            if kind == "floating":
                hung = hanging.get(entity.key, 0)
                also = f" (nor are the {hung} link(s) joined to it)" if hung else ""
                self.report("sdf.disconnected-link",
                            f"link '{entity.key}' is joined by no joint to '{main_name}' or "
                            f"anything joined to it{also}: a free body in SDF. URDF has one "
                            f"root: joined to '{main_name}' by the floating joint "
                            f"'{joint.get('name')}'", entity.element,
                            hint="add the joint that holds it, or put it in its own model")

    # -- links ------------------------------------------------------------------------------

    def emit_link(self, entity: Entity, parent_joint: JointInfo | None) -> None:
        name = self.names[entity.key]
        link = self.sub(self.root, "link", entity.element, name=name)
        frame = self.frame_of[name]
        scope, element = entity.scope, entity.element
        self.inertial(link, entity, self.graph.pose(entity.key).seen_from(frame))
        for tag in ("visual", "collision"):
            for shape in element.findall(tag):
                self.shape(link, entity, shape,
                           self.placed(scope, entity.key, shape).seen_from(frame))
        self.link_extras(entity, name, frame)

    def inertial(self, link, entity: Entity, link_pose: Transform) -> None:
        inertial = entity.element.find("inertial")
        static = _static(entity.scope)
        if inertial is None:
            self.source.defaults[link.get("name")] = static
            if not static:  # Gazebo never integrates a static model: its mass does not act
                self.defaulted.append(entity)
            out = self.sub(link, "inertial", entity.element)
            self.origin(out, link_pose, None)
            self.sub(out, "mass", entity.element, value=fmt(1.0))
            self.sub(out, "inertia", entity.element, ixx="1.0", ixy="0.0", ixz="0.0",
                     iyy="1.0", iyz="0.0", izz="1.0")
            return
        version = entity.scope.version
        raw, pose_element, relative_to = self.reader.pose(inertial, version)
        if relative_to:
            key = self.graph.reference(entity.scope, relative_to, pose_element, "relative_to")
            base = self.graph.pose(key).seen_from(self.frame_of[self.names[entity.key]]) \
                if key else link_pose
        else:
            base = link_pose
        if (inertial.get("auto") or "").strip().lower() in ("true", "1"):
            self.report("sdf.not-in-urdf",
                        f"link '{entity.key}': <inertial auto=\"true\"> asks the simulator to "
                        "compute mass and inertia from the collisions; URDF has no such thing: "
                        "the values written in the file (or the defaults) are used",
                        inertial, severity="warning",
                        hint="run 'urdftool inertia' on the result and paste its <inertial>")
        out = self.sub(link, "inertial", inertial)
        self.origin(out, base * raw, pose_element if pose_element is not None else inertial)
        mass = self.reader.number(inertial, "mass", 1.0)
        if not static and math.isfinite(mass) and mass > 0:
            self.authored_mass += mass
        mass_element = inertial.find("mass")
        self.sub(out, "mass", mass_element if mass_element is not None else inertial,
                 value=fmt(mass))
        inertia = inertial.find("inertia")
        values = {}
        for tag, default in (("ixx", 1.0), ("ixy", 0.0), ("ixz", 0.0), ("iyy", 1.0),
                             ("iyz", 0.0), ("izz", 1.0)):
            values[tag] = fmt(self.reader.number(inertia, tag, default)
                              if inertia is not None else default)
        self.sub(out, "inertia", inertia if inertia is not None else inertial, **values)

    def shape(self, link, entity: Entity, element, pose: Transform) -> None:
        tag = element.tag
        name = element.get("name")
        geometry = element.find("geometry")
        shape = next((c for c in geometry if isinstance(c.tag, str)), None) \
            if geometry is not None else None
        if shape is None:
            self.report("sdf.missing-element", f"{tag} '{name}' of link '{entity.key}' has no "
                        "geometry", geometry if geometry is not None else element,
                        hint="write <geometry><box><size>...</size></box></geometry>")
            return
        kind = shape.tag
        where = f"{tag} '{name}' of link '{entity.key}'"
        parts: list[tuple[Transform, str, dict]] = []
        if kind == "box":
            parts.append((pose, "box", {"size": fmtv(self.reader.vector(
                shape, "size", 3, (1.0, 1.0, 1.0)))}))
        elif kind == "sphere":
            parts.append((pose, "sphere", {"radius": fmt(self.reader.number(shape, "radius", 1.0))}))
        elif kind == "cylinder":
            parts.append((pose, "cylinder", {
                "radius": fmt(self.reader.number(shape, "radius", 1.0)),
                "length": fmt(self.reader.number(shape, "length", 1.0))}))
        elif kind == "capsule":
            radius = self.reader.number(shape, "radius", 0.5)
            length = self.reader.number(shape, "length", 1.0)
            parts.append((pose, "cylinder", {"radius": fmt(radius), "length": fmt(length)}))
            for sign in (1.0, -1.0):
                cap = pose * Transform.from_rpy((0.0, 0.0, sign * length / 2), (0.0, 0.0, 0.0))
                parts.append((cap, "sphere", {"radius": fmt(radius)}))
            self.report("sdf.unsupported-geometry",
                        f"{where} is a capsule, which URDF has not got: written as a cylinder "
                        "and two spheres (the same solid)", shape, severity="info")
        elif kind in ("ellipsoid", "cone"):
            if kind == "ellipsoid":
                radii = self.reader.vector(shape, "radii", 3, (1.0, 1.0, 1.0))
                parts.append((pose, "sphere", {"radius": fmt(max(radii))}))
                what = f"a sphere of radius {max(radii):g} that encloses it"
            else:
                radius = self.reader.number(shape, "radius", 1.0)
                length = self.reader.number(shape, "length", 1.0)
                parts.append((pose, "cylinder", {"radius": fmt(radius), "length": fmt(length)}))
                what = "the cylinder that encloses it"
            self.report("sdf.unsupported-geometry",
                        f"{where} is a {kind}, which URDF has not got: approximated by {what}",
                        shape, hint="replace it with a mesh for an exact shape")
        elif kind == "mesh":
            uri = self.reader.text_of(shape, "uri") or ""
            if not uri:
                self.report("sdf.missing-element", f"{where}: <mesh> has no <uri>", shape)
                return
            attrs = {"filename": self.mesh_filename(uri, shape)}
            scale = self.reader.vector(shape, "scale", 3, None)
            if scale is not None:
                attrs["scale"] = fmtv(scale)
            if shape.find("submesh") is not None:
                self.report("sdf.not-in-urdf", f"{where} uses a submesh of its mesh; URDF "
                            "takes whole meshes: the whole mesh is used", shape.find("submesh"),
                            severity="warning", hint="export the submesh to its own file")
            parts.append((pose, "mesh", attrs))
        elif kind == "empty":
            return
        else:  # plane, heightmap, polyline, image
            self.report("sdf.unsupported-geometry",
                        f"{where} is a {kind}, which URDF cannot express: dropped", shape,
                        hint="a ground plane belongs in the world, not in the robot"
                        if kind in ("plane", "heightmap") else "replace it with a mesh")
            return
        for index, (part_pose, urdf_kind, attrs) in enumerate(parts):
            part_name = name if index == 0 or name is None else f"{name}__cap{index}"
            out = self.sub(link, tag, element, name=part_name)
            self.origin(out, part_pose, element.find("pose"))
            geo = self.sub(out, "geometry", geometry)
            self.sub(geo, urdf_kind, shape, **attrs)
            if tag == "visual":
                self.material(out, entity, element)
        if tag == "collision":
            self.surface(entity, element)

    def material(self, visual, entity: Entity, element) -> None:
        material = element.find("material")
        if material is None:
            return
        color_element = material.find("diffuse")
        if color_element is None:
            color_element = material.find("ambient")
        script = material.find("script")
        if color_element is None:
            if script is not None and script.findtext("name"):
                self.gazebo(self.names[entity.key], material,
                            ("material", script.findtext("name").strip()))
            return
        values = self.reader.parse_vector(color_element, 4, None, sizes=(3,))
        if values is None:
            return
        rgba = tuple(values) + ((1.0,) if len(values) == 3 else ())
        name = self.materials.get(rgba)
        if name is None:
            name = "rgba_" + "_".join(fmt(v) for v in rgba)
            self.materials[rgba] = name
            top = etree.Element("material", name=name)
            self.mark(top, material)
            color = etree.SubElement(top, "color", rgba=fmtv(rgba))
            self.mark(color, color_element)
            self.material_elements.append(top)
        self.sub(visual, "material", material, name=name)

    def surface(self, entity: Entity, collision) -> None:
        friction = collision.find("surface/friction/ode")
        if friction is None:
            return
        name = self.names[entity.key]
        for tag, urdf_tag in (("mu", "mu1"), ("mu2", "mu2")):
            if friction.find(tag) is not None:
                value = self.reader.number(friction, tag, None)
                if value is not None:
                    self.gazebo(name, friction.find(tag), (urdf_tag, fmt(value)), once=True)

    def link_extras(self, entity: Entity, name: str, frame: Transform) -> None:
        element = entity.element
        if element.find("gravity") is not None and not self.reader.boolean(element, "gravity", True):
            self.gazebo(name, element.find("gravity"), ("turnGravityOff", "true"))
            self.report("sdf.not-in-urdf", f"link '{entity.key}' ignores gravity; URDF cannot "
                        "say so: kept as <turnGravityOff> in a <gazebo> block (other tools "
                        "apply gravity)", element.find("gravity"), severity="info")
        if self.reader.boolean(element, "kinematic", False):
            self.gazebo(name, element.find("kinematic"), ("kinematic", "true"))
            self.report("sdf.not-in-urdf", f"link '{entity.key}' is kinematic (moved, not "
                        "simulated); URDF cannot say so: kept in a <gazebo> block",
                        element.find("kinematic"), severity="info")
        if self.reader.boolean(element, "self_collide", False):
            self.gazebo(name, element.find("self_collide"), ("selfCollide", "true"))
        for sensor in element.findall("sensor"):
            pose = self.placed(entity.scope, entity.key, sensor).seen_from(frame)
            copied = copy.deepcopy(sensor)
            for old in copied.findall("pose"):
                copied.remove(old)
            if not pose.is_identity:
                new_pose = etree.Element("pose")
                new_pose.text = fmtv(pose.xyz + pose.rpy)
                copied.insert(0, new_pose)
            self.gazebo(name, sensor, copied)
            self.report("sdf.not-in-urdf", f"sensor '{sensor.get('name')}' of link "
                        f"'{entity.key}' is kept in a <gazebo reference=\"{name}\"> block "
                        "(Gazebo reads it; other URDF tools do not)", sensor, severity="info")
        for tag in ("light", "projector", "audio_sink", "audio_source", "battery",
                    "particle_emitter"):
            for extra in element.findall(tag):
                self.report("sdf.not-in-urdf", f"<{tag}> of link '{entity.key}' has no place "
                            "in URDF: dropped", extra, severity="info")
        if element.find("velocity_decay") is not None:
            self.report("sdf.not-in-urdf", f"<velocity_decay> of link '{entity.key}' has no "
                        "place in URDF: dropped", element.find("velocity_decay"), severity="info")

    def gazebo(self, reference: str | None, sdf_element, content, once: bool = False) -> None:
        block = None
        for existing in self.root.findall("gazebo"):
            if existing.get("reference") == reference:
                block = existing
                break
        if block is None:
            block = self.sub(self.root, "gazebo", sdf_element,
                             **({"reference": reference} if reference else {}))
        if isinstance(content, tuple):
            tag, text = content
            if once and block.find(tag) is not None:
                return
            child = etree.SubElement(block, tag)
            child.text = text
        else:
            child = content
            block.append(child)
        self.mark(child, sdf_element)

    # -- frames and the model ---------------------------------------------------------------

    def emit_frames(self) -> None:
        for entity in self.frames:
            link = self.graph.attached_link(entity.key)
            if link is None or link == WORLD or link not in self.names:
                continue
            parent = self.names[link]
            name = self.link_name(entity.key)
            self.sub(self.root, "link", entity.element, name=name)
            self.frame_of[name] = self.graph.pose(entity.key)
            joint = self.sub(self.root, "joint", entity.element,
                             name=self.joint_name(entity.key, "__frame"), type="fixed")
            self.origin(joint, self.frame_of[name].seen_from(self.frame_of[parent]),
                        entity.pose_element)
            self.sub(joint, "parent", entity.element, link=parent)
            self.sub(joint, "child", entity.element, link=name)

    def emit_model_extras(self) -> None:
        if self.top.static:
            self.gazebo(None, self.top.element.find("static"), ("static", "true"))
            self.report("sdf.not-in-urdf", f"model '{self.top.name}' is static (fixed in the "
                        "world); kept as <static> in a <gazebo> block",
                        self.top.element.find("static"), severity="info")
        for scope in self.top.walk():
            for plugin in scope.plugins:
                self.gazebo(None, plugin, copy.deepcopy(plugin))
                self.report("sdf.not-in-urdf", f"plugin '{plugin.get('name')}' is kept in a "
                            "<gazebo> block (Gazebo runs it; other URDF tools do not)", plugin,
                            severity="info")

    def report_defaults(self) -> None:
        """sdf.default-inertial, graded by what SDFormat's default 1 kg per link does to the
        model's mass in Gazebo: the share of the simulated mass that nobody wrote."""
        if not self.defaulted:
            return
        count = len(self.defaulted)
        total = self.authored_mass + count * DEFAULT_MASS
        share = count * DEFAULT_MASS / total
        if self.authored_mass <= 0:
            severity = "warning"
            effect = (f"no link of the model declares an <inertial>: Gazebo simulates each of "
                      f"its {count} links as {DEFAULT_MASS:g} kg with 1 kg·m²")
        else:
            severity = ("error" if share >= DEFAULT_ERROR_SHARE else
                        "warning" if share >= DEFAULT_WARNING_SHARE else "info")
            effect = (f"the {count} link{'s' if count > 1 else ''} without one add "
                      f"{count * DEFAULT_MASS:g} kg to the {self.authored_mass:.4g} kg the model "
                      f"declares: {share:.0%} of its mass in Gazebo")
        for entity in self.defaulted:
            self.report("sdf.default-inertial",
                        f"link '{entity.key}' has no <inertial>: SDFormat's default gives it "
                        f"mass {DEFAULT_MASS:g} kg and inertia diag(1, 1, 1) kg·m² (written "
                        f"out explicitly); {effect}", entity.element, severity=severity,
                        hint="give the link its real <inertial>; a massless reference frame "
                             "is a <frame>, not a <link>")

    def report_unlimited(self) -> None:
        if not self.unlimited:
            return
        names = sorted({name for name, _ in self.unlimited})
        self.report("sdf.not-in-urdf",
                    f"{len(names)} joint limit(s) are unlimited in SDF ({', '.join(names)}); "
                    f"URDF requires a number: wrote {UNBOUNDED:g} (SDF's own 'no limit')",
                    self.unlimited[0][1], severity="info",
                    hint="write the real effort and velocity limits in <axis><limit>")

    def add_name_comment(self) -> None:
        lines = []
        for key, name in self.names.items():
            if key != name and key != WORLD:
                lines.append(f"  link '{key}' -> '{name}'")
        for key, name in self.joint_names.items():
            if key != name and "::" in key:
                lines.append(f"  joint '{key}' -> '{name}'")
        if lines:
            comment = etree.Comment(" SDF names made URDF-safe:\n" + "\n".join(lines) + "\n")
            self.root.insert(0, comment)

    # -- meshes -----------------------------------------------------------------------------

    def report_unread_meshes(self) -> None:
        """One sdf.mesh-uri per missing model (one --model-path finds all its meshes) and one
        for the network meshes, at the first, counting the rest."""
        for missing, meshes in self.unread_meshes.items():
            uri, element = meshes[0]
            more = (f" (and {len(meshes) - 1} more mesh{'es' if len(meshes) > 2 else ''} "
                    "like it)") if len(meshes) > 1 else ""
            if missing:
                self.report("sdf.mesh-uri", f"mesh '{uri}'{more} is not found in the model "
                            "paths; URDF tools do not read model:// URIs: kept as written",
                            element, hint="give --model-path DIR, or --package-uri "
                                          "package://PKG/models")
            else:
                self.report("sdf.mesh-uri", f"mesh '{uri}'{more} is on the network; URDF "
                            "tools read local files and package:// URIs: kept as written",
                            element, hint="download it next to the model and use a relative "
                                          "path")

    def mesh_filename(self, uri: str, element) -> str:
        doc = self.reader.doc_of(element)
        base = doc.directory if doc is not None else Path.cwd()
        parsed = parse_uri(uri)
        if parsed.scheme == "package":
            return uri
        if parsed.scheme == "model":
            rest = uri[len("model://"):]
            model, inner = parsed.name, parsed.rest
            general = None
            for mapping in self.options.package_uris:
                name, sep, prefix = mapping.partition("=")
                if sep and name == model:
                    return prefix.rstrip("/") + "/" + inner
                if not sep:
                    general = mapping
            if general is not None:
                return general.rstrip("/") + "/" + rest
            found = self.reader.resolve_uri(uri, base)
            if found is None:
                self.unread_meshes.setdefault(f"model://{model}", []).append((uri, element))
                return uri
            return self._relative(found)
        if parsed.scheme in ("http", "https"):
            self.unread_meshes.setdefault("", []).append((uri, element))
            return uri
        if parsed.scheme == "file":
            uri = parsed.rest
        if os.path.isabs(uri):
            return uri  # kept as written, found or not
        if self.options.output_dir is None:
            return uri  # check: relative to the file it was written in, as the mesh rules read it
        return self._relative(base / uri)

    def _relative(self, path: Path) -> str:
        target = self.options.output_dir
        if target is None:
            return str(path.resolve() if path.exists() else path)
        try:
            return os.path.relpath(path.resolve() if path.exists() else path, target.resolve())
        except ValueError:
            return str(path)


def to_text(root) -> str:
    """The URDF document as text, indented (in place: a copy doubled the memory of a big
    model, issue 15), with an XML declaration."""
    etree.indent(root, space="  ")
    body = etree.tostring(root, encoding="unicode")
    return '<?xml version="1.0" encoding="utf-8"?>\n' + body + "\n"
