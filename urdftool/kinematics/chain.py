"""The serial chain between a base link and a tip link, taken from the robot model.

Fixed joints are folded into the constant transform of the next moving joint (or into the tool
transform after the last one). A mimic joint is expressed through its leader (chains of mimics
are composed): its value is ``multiplier * q_leader + offset``, and the leader, wherever it is
in the tree, is one of the chain's independent variables. Anything that keeps the selection from
being a serial chain of revolute, continuous, prismatic and fixed joints is a ToolError with one
clear line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from urdftool.errors import ToolError
from urdftool.kinematics.fk import pose_matrix

MOVABLE = ("revolute", "continuous", "prismatic")
SERIAL = MOVABLE + ("fixed",)


@dataclass(frozen=True)
class Variable:
    """An independent joint variable: a moving joint of the chain, or the leader of a mimic."""

    name: str
    type: str  # revolute, continuous or prismatic
    lower: float | None
    upper: float | None
    in_chain: bool = True

    @property
    def revolute(self) -> bool:
        return self.type != "prismatic"

    @property
    def bounded(self) -> bool:
        return (self.type != "continuous" and self.lower is not None and self.upper is not None
                and math.isfinite(self.lower) and math.isfinite(self.upper))

    def sample_range(self) -> tuple[float, float]:
        """Where random configurations are drawn from: the limits, else ±π (revolute) or ±1."""
        if self.bounded:
            return self.lower, self.upper  # type: ignore[return-value]
        return (-math.pi, math.pi) if self.revolute else (-1.0, 1.0)

    @property
    def middle(self) -> float:
        return 0.5 * (self.lower + self.upper) if self.bounded else 0.0  # type: ignore[operator]


@dataclass(frozen=True, eq=False)
class ChainJoint:
    """A moving joint of the chain. ``origin`` is the constant 4x4 transform from the previous
    moving joint's child frame (or the base link's frame) to this joint's frame, fixed joints
    in between folded in; ``axis`` is the unit axis in this joint's frame."""

    name: str
    type: str
    child: str
    origin: np.ndarray
    axis: np.ndarray
    variable: int  # index into Chain.variables
    multiplier: float = 1.0
    offset: float = 0.0
    folded: tuple[str, ...] = ()  # fixed joints folded into ``origin``
    leader: str = ""  # the joint whose variable drives this one (itself unless a mimic)

    @property
    def revolute(self) -> bool:
        return self.type != "prismatic"

    @property
    def mimic(self) -> bool:
        return self.leader != self.name


@dataclass(frozen=True, eq=False)
class Chain:
    robot: str | None
    base: str
    tip: str
    base_is_root: bool
    links: tuple[str, ...]  # base .. tip
    joints: tuple[ChainJoint, ...]
    tool: np.ndarray  # from the last moving joint's child frame to the tip link's frame
    tool_folded: tuple[str, ...]
    variables: tuple[Variable, ...]

    @property
    def n(self) -> int:
        return len(self.variables)

    @property
    def variable_names(self) -> list[str]:
        return [v.name for v in self.variables]

    def joint_values(self, q) -> np.ndarray:
        """The position of every moving joint of the chain, given the independent variables."""
        q = np.asarray(q, dtype=float)
        return np.array([j.multiplier * q[j.variable] + j.offset for j in self.joints])

    def sample(self, rng: np.random.Generator, count: int) -> np.ndarray:
        """``count`` random configurations within the limits."""
        lows, highs = zip(*(v.sample_range() for v in self.variables))
        # swapped limits (lower > upper: a defect check reports) sample the span they name
        lows, highs = np.minimum(lows, highs), np.maximum(lows, highs)
        return rng.uniform(lows, highs, size=(count, self.n))


def _names(items, limit: int = 12) -> str:
    items = list(items)
    shown = ", ".join(str(i) for i in items[:limit])
    return shown + (f", ... ({len(items)} in all)" if len(items) > limit else "")


class _Tree:
    """Parent/child lookups over the model, tolerant of broken trees (reported, not crashed)."""

    def __init__(self, robot):
        self.robot = robot
        self.parents: dict[str, list] = {}
        self.children: dict[str, list] = {}
        for joint in robot.joints:
            if joint.child is not None:
                self.parents.setdefault(joint.child, []).append(joint)
            if joint.parent is not None:
                self.children.setdefault(joint.parent, []).append(joint)
        self.links = [link.name for link in robot.links if link.name is not None]

    def require_link(self, name: str, role: str) -> None:
        if self.robot.link(name) is None:
            raise ToolError(f"no link named '{name}' ({role}); links: {_names(self.links)}")

    def parent_joint(self, link: str):
        joints = self.parents.get(link, [])
        if len(joints) > 1:
            raise ToolError(f"link '{link}' is the child of several joints "
                            f"({_names(j.name for j in joints)}): not a tree; "
                            "run 'urdftool check'")
        return joints[0] if joints else None

    def path_to_root(self, link: str) -> list:
        """Joints from ``link`` up to its root, nearest first."""
        path, seen = [], {link}
        while (joint := self.parent_joint(link)) is not None:
            link = joint.parent
            if link is None:
                raise ToolError(f"joint '{joint.name}' has no parent link; run 'urdftool check'")
            if link in seen:
                raise ToolError(f"the joints above link '{link}' form a loop; "
                                "run 'urdftool check'")
            seen.add(link)
            path.append(joint)
        return path

    def root_of(self, link: str) -> str:
        path = self.path_to_root(link)
        return path[-1].parent if path else link

    def leaves(self, base: str) -> list[tuple[str, bool]]:
        """Leaf links under ``base`` in document order, each with whether a moving joint lies
        between base and the leaf."""
        leaves, stack, seen = [], [(base, False)], set()
        while stack:
            link, moved = stack.pop()
            if link in seen:
                continue
            seen.add(link)
            kids = [j for j in self.children.get(link, []) if j.child is not None]
            if not kids:
                leaves.append((link, moved))
            for joint in reversed(kids):
                stack.append((joint.child, moved or joint.moving))
        order = {name: i for i, name in enumerate(self.links)}
        return sorted(leaves, key=lambda item: order.get(item[0], len(order)))


def _axis(joint) -> np.ndarray:
    axis = np.array(joint.axis_or_default, dtype=float)
    norm = float(np.linalg.norm(axis))
    if not math.isfinite(norm) or norm < 1e-12:
        raise ToolError(f"joint '{joint.name}' has a zero axis {tuple(joint.axis_or_default)}")
    return axis / norm


def _limits(joint) -> tuple[float | None, float | None]:
    if joint.type == "continuous" or joint.limit is None:
        return None, None
    return joint.limit.lower, joint.limit.upper


def _resolve_mimic(robot, joint) -> tuple[object, float, float]:
    """The independent joint that drives ``joint`` and the composed multiplier and offset."""
    multiplier, offset, current, seen = 1.0, 0.0, joint, [joint.name]
    while current.mimic is not None:
        mimic = current.mimic
        leader = robot.joint(mimic.joint)
        if leader is None:
            raise ToolError(f"joint '{current.name}' mimics '{mimic.joint}', which does not exist")
        if mimic.multiplier is None or mimic.offset is None:
            raise ToolError(f"joint '{current.name}': the mimic multiplier or offset does not "
                            "parse; run 'urdftool check'")
        if leader.name in seen:
            raise ToolError(f"mimic cycle: {' -> '.join(seen + [leader.name])}")
        if leader.type not in MOVABLE:
            raise ToolError(f"joint '{current.name}' mimics '{leader.name}' of type "
                            f"{leader.type}: a mimic needs a revolute, continuous or "
                            "prismatic leader")
        # value(current) = m * value(leader) + o, and value(joint) = M * value(current) + O
        offset = multiplier * mimic.offset + offset
        multiplier = multiplier * mimic.multiplier
        seen.append(leader.name)
        current = leader
    return current, multiplier, offset


def extract_chain(robot, base: str | None = None, tip: str | None = None) -> Chain:
    """The serial chain from ``base`` (default: the root) to ``tip`` (default: the single leaf
    below the base reached through a moving joint)."""
    tree = _Tree(robot)
    if not tree.links:
        raise ToolError("the robot has no links")
    if base is not None:
        tree.require_link(base, "--base")
    if tip is not None:
        tree.require_link(tip, "--tip")

    if base is None:
        if tip is not None:
            base = tree.root_of(tip)
        else:
            roots = robot.roots()
            if not roots:
                raise ToolError("no root link: every link is some joint's child (a loop); "
                                "run 'urdftool check'")
            if len(roots) > 1:
                raise ToolError(f"several root links ({_names(roots)}): choose one with --base")
            base = roots[0]
    if tip is None:
        leaves = tree.leaves(base)
        moving = [name for name, moved in leaves if moved]
        if len(moving) != 1:
            if not moving:
                raise ToolError(f"no moving joint below '{base}': nothing to compute")
            raise ToolError(f"the tree below '{base}' has {len(moving)} leaves "
                            f"({_names(moving)}): not a serial chain; choose one with --tip")
        tip = moving[0]
    if tip == base:
        raise ToolError(f"--base and --tip are the same link '{base}'")

    up = tree.path_to_root(tip)
    path = []
    for joint in up:
        path.append(joint)
        if joint.parent == base:
            break
    else:
        above = " <- ".join([tip] + [j.parent for j in up])
        raise ToolError(f"link '{tip}' is not downstream of '{base}' (from the tip up: {above})")
    path.reverse()

    for joint in path:
        if joint.type not in SERIAL:
            kind = joint.type if joint.type is not None else "no type"
            raise ToolError(f"joint '{joint.name}' ({kind}) lies between '{base}' and '{tip}': "
                            "a serial chain takes only revolute, continuous, prismatic and "
                            "fixed joints")

    variables: list[Variable] = []
    index: dict[str, int] = {}
    joints: list[ChainJoint] = []
    pending = np.eye(4)
    folded: list[str] = []
    on_path = {id(joint) for joint in path}
    for joint in path:
        pending = pending @ pose_matrix(joint.origin)
        if joint.type == "fixed":
            folded.append(str(joint.name))
            continue
        leader, multiplier, offset = _resolve_mimic(robot, joint)
        if leader.name not in index:
            lower, upper = _limits(leader)
            index[leader.name] = len(variables)
            variables.append(Variable(str(leader.name), str(leader.type), lower, upper,
                                      in_chain=id(leader) in on_path))
        joints.append(ChainJoint(str(joint.name), str(joint.type), str(joint.child), pending,
                                 _axis(joint), index[leader.name], multiplier, offset,
                                 tuple(folded), leader=str(leader.name)))
        pending, folded = np.eye(4), []
    if not joints:
        raise ToolError(f"no moving joint between '{base}' and '{tip}': nothing to compute")
    links = tuple([base] + [str(j.child) for j in path])
    return Chain(robot.name, base, tip, tree.parent_joint(base) is None, links, tuple(joints),
                 pending, tuple(folded), tuple(variables))
