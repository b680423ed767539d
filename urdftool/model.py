"""The robot model: typed, immutable records of links, joints and the rest, built once from a
parsed document and read by every rule and command. Every record keeps where it was written.

The records are ``NamedTuple``s (cheap to define: ``urdftool check`` starts in a pre-commit hook,
and cheap to build); ``Robot`` is a plain class holding its indexes. No ``from __future__ import
annotations`` here: ``NamedTuple`` would compile every field's annotation string at import.

Values that do not parse are kept as ``None`` here (the ``schema`` rules report them), so that
building a model never fails on bad input.
"""

import gc
import math
from typing import TYPE_CHECKING, Any, NamedTuple

from urdftool.findings import Loc  # re-exported: urdftool.model.Loc

if TYPE_CHECKING:  # pragma: no cover
    from lxml import etree

    from urdftool.source import Source

Vec3 = tuple[float, float, float]


class Pose(NamedTuple):
    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 = (0.0, 0.0, 0.0)

    @property
    def is_identity(self) -> bool:
        return self.xyz == (0.0, 0.0, 0.0) and self.rpy == (0.0, 0.0, 0.0)


class Geometry(NamedTuple):
    """One shape. ``kind`` is box, cylinder, sphere, mesh, capsule, or None when missing."""

    kind: str | None
    size: Vec3 | None = None  # box
    radius: float | None = None  # cylinder, sphere, capsule
    length: float | None = None  # cylinder, capsule
    filename: str | None = None  # mesh, as written
    scale: Vec3 = (1.0, 1.0, 1.0)  # mesh
    loc: Loc | None = None


class Shape(NamedTuple):
    """A visual or a collision: a geometry placed in the link frame."""

    role: str  # "visual" or "collision"
    name: str | None
    origin: Pose
    geometry: Geometry
    material: str | None = None  # visual only: the material name referenced or defined
    loc: Loc | None = None


class Inertial(NamedTuple):
    origin: Pose
    mass: float | None
    ixx: float | None
    ixy: float | None
    ixz: float | None
    iyy: float | None
    iyz: float | None
    izz: float | None
    loc: Loc | None = None
    mass_loc: Loc | None = None
    inertia_loc: Loc | None = None

    @property
    def tensor(self) -> tuple[tuple[float, float, float], ...] | None:
        """The 3x3 inertia tensor about the COM in the inertial frame, or None if incomplete."""
        values = (self.ixx, self.ixy, self.ixz, self.iyy, self.iyz, self.izz)
        if any(v is None or not math.isfinite(v) for v in values):
            return None
        ixx, ixy, ixz, iyy, iyz, izz = values  # type: ignore[misc]
        return ((ixx, ixy, ixz), (ixy, iyy, iyz), (ixz, iyz, izz))


class Link(NamedTuple):
    name: str | None
    inertial: Inertial | None
    visuals: tuple[Shape, ...]
    collisions: tuple[Shape, ...]
    loc: Loc | None = None

    @property
    def shapes(self) -> tuple[Shape, ...]:
        return self.visuals + self.collisions


class Limit(NamedTuple):
    lower: float | None
    upper: float | None
    effort: float | None
    velocity: float | None
    loc: Loc | None = None


class Mimic(NamedTuple):
    joint: str | None
    multiplier: float | None = 1.0
    offset: float | None = 0.0
    loc: Loc | None = None


class Dynamics(NamedTuple):
    damping: float | None = 0.0
    friction: float | None = 0.0
    loc: Loc | None = None


class SafetyController(NamedTuple):
    soft_lower_limit: float | None
    soft_upper_limit: float | None
    k_position: float | None
    k_velocity: float | None
    loc: Loc | None = None


class Calibration(NamedTuple):
    rising: float | None
    falling: float | None
    loc: Loc | None = None


MOVING_JOINT_TYPES = ("revolute", "continuous", "prismatic", "floating", "planar")
JOINT_TYPES = MOVING_JOINT_TYPES + ("fixed",)


class Joint(NamedTuple):
    name: str | None
    type: str | None
    parent: str | None
    child: str | None
    origin: Pose
    axis: Vec3 | None  # None when the <axis> element is absent (URDF default is 1 0 0)
    limit: Limit | None = None
    mimic: Mimic | None = None
    dynamics: Dynamics | None = None
    safety: SafetyController | None = None
    calibration: Calibration | None = None
    loc: Loc | None = None

    @property
    def moving(self) -> bool:
        return self.type in MOVING_JOINT_TYPES

    @property
    def axis_or_default(self) -> Vec3:
        return self.axis if self.axis is not None else (1.0, 0.0, 0.0)


class Material(NamedTuple):
    name: str | None
    rgba: tuple[float, ...] | None
    texture: str | None
    loc: Loc | None = None


class Robot:
    """A robot as written. ``links`` and ``joints`` keep every element in document order,
    duplicates included; ``link``/``joint`` look one up by name (first definition wins)."""

    __slots__ = ("_children", "_elements", "_joint_index", "_link_index", "_parents", "joints",
                 "links", "materials", "memo", "name", "root", "source")

    def __init__(self, name: str | None, links: tuple[Link, ...], joints: tuple[Joint, ...],
                 materials: tuple[Material, ...], source: "Source", root: Any = None):
        self.name = name
        self.links = links
        self.joints = joints
        self.materials = materials  # top-level and inline material definitions
        self.source = source
        self.root = root  # the lxml root element of the (expanded) document, or None
        self._elements: dict[str, list] | None = None  # elements(), grouped on first use
        self._parents: dict[str | None, Joint] | None = None  # relations(), built on first use
        self._children: dict[str | None, list[Joint]] | None = None
        self._link_index: dict[str, Link] = {}
        self._joint_index: dict[str, Joint] = {}
        # what analyses derive from the whole robot once, for every rule (issue 28: mimic
        # chains, rigid bodies): key -> value, owned by the analysis that fills it
        self.memo: dict = {}
        for link in links:
            if link.name is not None:
                self._link_index.setdefault(link.name, link)
        for joint in joints:
            if joint.name is not None:
                self._joint_index.setdefault(joint.name, joint)

    def link(self, name: str | None) -> Link | None:
        return self._link_index.get(name) if name is not None else None

    def joint(self, name: str | None) -> Joint | None:
        return self._joint_index.get(name) if name is not None else None

    def _relations(self) -> None:
        """The joint maps, built once: child link -> its first joint (in document order),
        parent link -> its joints (so that every walk over the tree is linear)."""
        parents: dict[str | None, Joint] = {}
        children: dict[str | None, list[Joint]] = {}
        for joint in self.joints:
            parents.setdefault(joint.child, joint)
            children.setdefault(joint.parent, []).append(joint)
        self._parents, self._children = parents, children

    def child_joints(self, link_name: str) -> list[Joint]:
        """The joints whose parent is ``link_name``, in document order."""
        if self._children is None:
            self._relations()
        return list(self._children.get(link_name, ()))  # type: ignore[union-attr]

    def parent_joint(self, link_name: str) -> Joint | None:
        """The first joint (in document order) whose child is ``link_name``."""
        if self._parents is None:
            self._relations()
        return self._parents.get(link_name)  # type: ignore[union-attr]

    def roots(self) -> list[str]:
        """Links that are no joint's child, in document order."""
        children = {j.child for j in self.joints}
        return [l.name for l in self.links if l.name is not None and l.name not in children]

    def loc(self, element: "etree._Element") -> Loc:
        """Where an element of ``root`` was written."""
        return self.source.loc(element)

    def elements(self, tag: str) -> "list[etree._Element]":
        """Direct children of <robot> with this tag (e.g. gazebo, transmission)."""
        if self.root is None:
            return []
        if self._elements is None:  # every rule asks: the children grouped once
            grouped: dict[str, list] = {}
            for e in self.root:
                if isinstance(e.tag, str):
                    grouped.setdefault(e.tag, []).append(e)
            self._elements = grouped
        return list(self._elements.get(tag, ()))


# -- building the model from a parsed document --------------------------------------------------


def parse_float(text: str | None) -> float | None:
    """A finite float, or None when absent, unparsable or nan/inf (urdfdom rejects those too;
    the schema rules report them)."""
    if text is None:
        return None
    try:
        value = float(text.strip())
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def parse_vector(text: str | None, size: int = 3) -> tuple[float, ...] | None:
    if text is None:
        return None
    parts = text.split()
    if len(parts) != size:
        return None
    try:
        values = tuple(map(float, parts))
    except ValueError:
        return None
    return values if all(map(math.isfinite, values)) else None


def _child(element, tag: str):
    for child in element:
        if child.tag == tag:
            return child
    return None


def _firsts(element) -> dict:
    """Tag -> the first child with it (what ``_child`` finds), in one pass over the children."""
    found: dict = {}
    for child in element:
        tag = child.tag
        if tag not in found:
            found[tag] = child
    return found


def _pose_of(origin) -> Pose:
    """The pose an <origin> element (or None) gives."""
    if origin is None:
        return Pose()
    xyz = parse_vector(origin.get("xyz")) or (0.0, 0.0, 0.0)
    rpy = parse_vector(origin.get("rpy")) or (0.0, 0.0, 0.0)
    return Pose(xyz, rpy)  # type: ignore[arg-type]


def _geometry(element, source: "Source", geometry) -> Geometry:
    """The shape in ``geometry`` (the first <geometry> of ``element``, or None)."""
    shape = None
    if geometry is not None:
        shape = next((c for c in geometry if isinstance(c.tag, str)), None)
    if shape is None:
        return Geometry(None, loc=source.loc(geometry if geometry is not None else element))
    loc = source.loc(shape)
    kind = shape.tag
    if kind == "box":
        return Geometry(kind, size=parse_vector(shape.get("size")), loc=loc)  # type: ignore[arg-type]
    if kind in ("cylinder", "capsule"):
        return Geometry(kind, radius=parse_float(shape.get("radius")),
                        length=parse_float(shape.get("length")), loc=loc)
    if kind == "sphere":
        return Geometry(kind, radius=parse_float(shape.get("radius")), loc=loc)
    if kind == "mesh":
        scale = parse_vector(shape.get("scale")) if shape.get("scale") is not None else (1.0, 1.0, 1.0)
        return Geometry(kind, filename=shape.get("filename"), scale=scale or (1.0, 1.0, 1.0),  # type: ignore[arg-type]
                        loc=loc)
    return Geometry(kind, loc=loc)


def _material(element, source: "Source") -> Material:
    color = _child(element, "color")
    texture = _child(element, "texture")
    rgba = parse_vector(color.get("rgba"), 4) if color is not None else None
    return Material(element.get("name"), rgba, texture.get("filename") if texture is not None else None,
                    source.loc(element))


def _shape(element, source: "Source", materials: list[Material]) -> Shape:
    firsts = _firsts(element)
    material_name = None
    material = firsts.get("material")
    if material is not None:
        material_name = material.get("name")
        if _child(material, "color") is not None or _child(material, "texture") is not None:
            materials.append(_material(material, source))
    return Shape(element.tag, element.get("name"), _pose_of(firsts.get("origin")),
                 _geometry(element, source, firsts.get("geometry")), material_name,
                 source.loc(element))


def _inertial(inertial, source: "Source") -> Inertial | None:
    """The record of a link's first <inertial> (or None)."""
    if inertial is None:
        return None
    firsts = _firsts(inertial)
    mass = firsts.get("mass")
    inertia = firsts.get("inertia")

    def moment(name: str) -> float | None:
        return parse_float(inertia.get(name)) if inertia is not None else None

    return Inertial(_pose_of(firsts.get("origin")), parse_float(mass.get("value")) if mass is not None else None,
                    moment("ixx"), moment("ixy"), moment("ixz"), moment("iyy"), moment("iyz"),
                    moment("izz"), source.loc(inertial),
                    source.loc(mass) if mass is not None else None,
                    source.loc(inertia) if inertia is not None else None)


def _link(element, source: "Source", materials: list[Material]) -> Link:
    visual_elements, collision_elements, inertial = [], [], None
    for c in element:  # one pass over the children
        tag = c.tag
        if tag == "visual":
            visual_elements.append(c)
        elif tag == "collision":
            collision_elements.append(c)
        elif tag == "inertial" and inertial is None:
            inertial = c
    # visuals before collisions: their inline materials are listed in that order
    visuals = tuple(_shape(c, source, materials) for c in visual_elements)
    collisions = tuple(_shape(c, source, materials) for c in collision_elements)
    return Link(element.get("name"), _inertial(inertial, source), visuals, collisions,
                source.loc(element))


def _joint(element, source: "Source") -> Joint:
    firsts = _firsts(element)
    parent = firsts.get("parent")
    child = firsts.get("child")
    axis = firsts.get("axis")
    limit = firsts.get("limit")
    mimic = firsts.get("mimic")
    dynamics = firsts.get("dynamics")
    safety = firsts.get("safety_controller")
    calibration = firsts.get("calibration")

    def get(e, name, default=None):
        if e is None or e.get(name) is None:
            return default
        return parse_float(e.get(name))

    return Joint(
        name=element.get("name"),
        type=element.get("type"),
        parent=parent.get("link") if parent is not None else None,
        child=child.get("link") if child is not None else None,
        origin=_pose_of(firsts.get("origin")),
        axis=(parse_vector(axis.get("xyz")) if axis.get("xyz") is not None else (1.0, 0.0, 0.0))
        if axis is not None else None,  # type: ignore[arg-type]
        limit=Limit(get(limit, "lower", 0.0), get(limit, "upper", 0.0), get(limit, "effort"),
                    get(limit, "velocity"), source.loc(limit)) if limit is not None else None,
        mimic=Mimic(mimic.get("joint"), get(mimic, "multiplier", 1.0), get(mimic, "offset", 0.0),
                    source.loc(mimic)) if mimic is not None else None,
        dynamics=Dynamics(get(dynamics, "damping", 0.0), get(dynamics, "friction", 0.0),
                          source.loc(dynamics)) if dynamics is not None else None,
        safety=SafetyController(get(safety, "soft_lower_limit", 0.0),
                                get(safety, "soft_upper_limit", 0.0), get(safety, "k_position", 0.0),
                                get(safety, "k_velocity"), source.loc(safety))
        if safety is not None else None,
        calibration=Calibration(get(calibration, "rising"), get(calibration, "falling"),
                                source.loc(calibration)) if calibration is not None else None,
        loc=source.loc(element),
    )


def build_robot(source: "Source") -> Robot:
    """The model of a loaded source. Never raises: a missing or broken document gives an empty
    robot, and the problems recorded while loading are reported by the xml/xacro rules."""
    root = source.root
    if root is None or root.tag != "robot":
        return Robot(root.get("name") if root is not None else None, (), (), (), source, root)
    materials: list[Material] = []
    links, joints = [], []
    # the records hold no reference cycles: the cyclic GC would only walk the growing model
    # over and over (half the time of building a 10k-link robot, and more the bigger it is)
    collecting = gc.isenabled()
    gc.disable()
    try:
        for element in root:
            if element.tag == "link":
                links.append(_link(element, source, materials))
            elif element.tag == "joint":
                joints.append(_joint(element, source))
            elif element.tag == "material":
                materials.append(_material(element, source))
    finally:
        if collecting:
            gc.enable()
    return Robot(root.get("name"), tuple(links), tuple(joints), tuple(materials), source, root)
