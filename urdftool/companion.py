"""The companion model (issue 31): a MoveIt SRDF, read by the loader like any robot file (plain
XML or ``.srdf.xacro``, every element located), as immutable records beside the ``Robot`` it
describes. Model layer: the ``srdf`` rules read it, never the XML.

What MoveIt reads of an SRDF (srdfdom ``src/model.cpp``): groups (links, joints, chains,
subgroups), group states, end effectors, virtual and passive joints, disabled and enabled
collision pairs, ``disable_default_collisions``, link sphere approximations and joint
properties. Values that do not parse are ``None`` (srdfdom reports and skips them)."""

from typing import Any, NamedTuple

from urdftool.findings import Loc
from urdftool.model import Robot


class Ref(NamedTuple):
    """A name an SRDF element gives in ``attribute`` of the ``<tag>`` written at ``loc``."""

    name: str | None
    tag: str
    attribute: str
    loc: Loc | None


class Chain(NamedTuple):
    base: Ref
    tip: Ref
    loc: Loc | None


class Group(NamedTuple):
    name: str | None
    links: tuple[Ref, ...]
    joints: tuple[Ref, ...]
    chains: tuple[Chain, ...]
    subgroups: tuple[Ref, ...]
    loc: Loc | None


class StateJoint(NamedTuple):
    ref: Ref
    values: tuple[float, ...] | None  # None: the value does not parse
    text: str | None


class GroupState(NamedTuple):
    name: str | None
    group: Ref
    joints: tuple[StateJoint, ...]
    loc: Loc | None


class EndEffector(NamedTuple):
    name: str | None
    group: Ref
    parent_link: Ref
    parent_group: Ref | None
    loc: Loc | None


class VirtualJoint(NamedTuple):
    name: str | None
    type: str | None
    parent_frame: str | None
    child: Ref
    loc: Loc | None


class Pair(NamedTuple):
    """A ``<disable_collisions>`` (or ``<enable_collisions>``) of two links."""

    link1: Ref
    link2: Ref
    reason: str | None
    enable: bool
    loc: Loc | None


class Srdf:
    """An SRDF and the robot it describes (``robot``: the URDF's model; ``robot_path``: where
    it was read). ``source`` is the SRDF's own ``Source`` (texts for edits, locations)."""

    __slots__ = ("default_disabled", "end_effectors", "group_states", "groups", "joint_properties",
                 "loc", "missing", "missing_hint", "name", "pairs", "passive_joints", "robot",
                 "robot_path", "root", "source", "spheres", "virtual_joints")

    def __init__(self, source: Any, robot: Robot | None, robot_path: str):
        self.source = source
        self.robot = robot
        self.robot_path = robot_path
        self.root = source.root
        self.name: str | None = None
        self.loc: Loc | None = None
        self.groups: tuple[Group, ...] = ()
        self.group_states: tuple[GroupState, ...] = ()
        self.end_effectors: tuple[EndEffector, ...] = ()
        self.virtual_joints: tuple[VirtualJoint, ...] = ()
        self.passive_joints: tuple[Ref, ...] = ()
        self.pairs: tuple[Pair, ...] = ()
        self.default_disabled: tuple[Ref, ...] = ()
        self.spheres: tuple[Ref, ...] = ()
        self.joint_properties: tuple[Ref, ...] = ()
        self.missing: str | None = None  # why no robot could be read (``srdf.no-robot``)
        self.missing_hint: str | None = None

    def group(self, name: str | None) -> Group | None:
        return next((g for g in self.groups if g.name == name), None) if name else None

    def loc_of(self, element) -> Loc:
        return self.source.loc(element)


def _ref(element, attribute: str, source) -> Ref:
    value = element.get(attribute)
    return Ref(value.strip() if value is not None else None, element.tag, attribute,
               source.loc(element))


def _values(text: str | None) -> tuple[float, ...] | None:
    if text is None:
        return None
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        return None
    return values or None


def build_srdf(source, robot: Robot | None, robot_path: str) -> Srdf:
    """The model of a loaded SRDF against ``robot``. Never raises: a broken document gives an
    empty model (the xml/xacro findings of the reading say why)."""
    srdf = Srdf(source, robot, robot_path)
    root = source.root
    if root is None:
        return srdf
    srdf.name = root.get("name")
    srdf.loc = source.loc(root)
    groups, states, effectors, virtuals, passive, pairs = [], [], [], [], [], []
    default, spheres, properties = [], [], []
    for element in root:
        tag = element.tag
        if not isinstance(tag, str):
            continue
        loc = source.loc(element)
        if tag == "group":
            links, joints, chains, subgroups = [], [], [], []
            for item in element:
                if item.tag == "link":
                    links.append(_ref(item, "name", source))
                elif item.tag == "joint":
                    joints.append(_ref(item, "name", source))
                elif item.tag == "chain":
                    chains.append(Chain(_ref(item, "base_link", source),
                                        _ref(item, "tip_link", source), source.loc(item)))
                elif item.tag == "group":
                    subgroups.append(_ref(item, "name", source))
            groups.append(Group(element.get("name"), tuple(links), tuple(joints), tuple(chains),
                                tuple(subgroups), loc))
        elif tag == "group_state":
            joints = [StateJoint(_ref(j, "name", source), _values(j.get("value")), j.get("value"))
                      for j in element if j.tag == "joint"]
            states.append(GroupState(element.get("name"), _ref(element, "group", source),
                                     tuple(joints), loc))
        elif tag == "end_effector":
            effectors.append(EndEffector(
                element.get("name"), _ref(element, "group", source),
                _ref(element, "parent_link", source),
                _ref(element, "parent_group", source)
                if element.get("parent_group") is not None else None, loc))
        elif tag == "virtual_joint":
            virtuals.append(VirtualJoint(element.get("name"), element.get("type"),
                                         element.get("parent_frame"),
                                         _ref(element, "child_link", source), loc))
        elif tag == "passive_joint":
            passive.append(_ref(element, "name", source))
        elif tag in ("disable_collisions", "enable_collisions"):
            pairs.append(Pair(_ref(element, "link1", source), _ref(element, "link2", source),
                              element.get("reason"), tag == "enable_collisions", loc))
        elif tag == "disable_default_collisions":
            default.append(_ref(element, "link", source))
        elif tag == "link_sphere_approximation":
            spheres.append(_ref(element, "link", source))
        elif tag == "joint_property":
            properties.append(_ref(element, "joint_name", source))
    srdf.groups, srdf.group_states = tuple(groups), tuple(states)
    srdf.end_effectors, srdf.virtual_joints = tuple(effectors), tuple(virtuals)
    srdf.passive_joints, srdf.pairs = tuple(passive), tuple(pairs)
    srdf.default_disabled, srdf.spheres = tuple(default), tuple(spheres)
    srdf.joint_properties = tuple(properties)
    return srdf


def is_srdf(root) -> bool:
    """Whether a parsed ``<robot>`` document is an SRDF (MoveIt's elements, no ``<link>``)."""
    if root is None or root.tag != "robot":
        return False
    tags = {child.tag for child in root if isinstance(child.tag, str)}
    return "link" not in tags and bool(tags & SRDF_TAGS)


SRDF_TAGS = frozenset({"group", "group_state", "end_effector", "virtual_joint", "passive_joint",
                       "disable_collisions", "enable_collisions", "disable_default_collisions",
                       "link_sphere_approximation", "joint_property"})


class Controllers:
    """A controllers YAML (``controllers.read_controllers``' data) and the robot whose
    ``<ros2_control>`` it drives: what the ``ros2_control`` rules registered ``on="controllers"``
    are given. ``source`` is the robot's (a YAML finding carries its own location)."""

    __slots__ = ("data", "robot", "source")

    def __init__(self, data: dict, robot: Robot):
        self.data = data
        self.robot = robot
        self.source = robot.source


class Launch:
    """A Python launch file (its text and ``ast`` tree: never run): what the ``ros2_control``
    rules registered ``on="launch"`` are given."""

    __slots__ = ("path", "source", "text", "tree")

    def __init__(self, path: str, text: str, tree, source):
        self.path = path
        self.text = text
        self.tree = tree  # None when it does not parse
        self.source = source
