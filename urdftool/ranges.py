"""Joint ranges and mimic relations: the interval arithmetic of the ``mimic`` rules and of the
``urdftool limits`` table (leader chains, composed multipliers, images of ranges).

A mimic follower is driven to ``multiplier * q_leader + offset``; the *image* of the leader's
range is the interval the follower is driven through when the leader sweeps its limits.

Pure Python (no numpy): the ``mimic`` rules import this on every ``urdftool check``. Below the
rules (``urdftool.limits``, which runs them for its table, imports this, never the reverse).
"""


import math
from typing import NamedTuple

from urdftool.model import Joint, Robot

LIMITED_TYPES = ("revolute", "prismatic")


class Chain(NamedTuple):
    """Where following a joint's mimic leads (``mimic_chain``): how the walk ends, its length
    and its last joint; the joints in between are found by following the leaders
    (``chain_path``). Every joint's chain is found in one walk over the robot (issue 28: a walk
    per joint was quadratic in a long chain)."""

    follower: Joint
    end: str  # "root" (last joint is not a mimic), "missing", "self", "cycle", "unparsed"
    length: int  # joints followed, the follower and the last one included
    last: Joint  # the root, the joint whose leader is missing/unparsed/itself, or in a cycle
    missing: str | None = None  # the name that is not a joint, when end == "missing"
    composed: tuple[float, float] | None = None  # (multiplier, offset) relative to the root
    cycle: tuple[Joint, ...] = ()  # end == "cycle": the joints of the cycle, from its entry

    @property
    def root(self) -> Joint | None:
        return self.last if self.end == "root" else None


def _leader(robot: Robot, joint: Joint) -> Joint | None:
    mimic = joint.mimic
    return robot.joint(mimic.joint) if mimic is not None and mimic.joint is not None else None


def mimic_chains(robot: Robot) -> dict[int, Chain]:
    """id(joint) -> its Chain, for every joint with a ``<mimic>``: found once per robot
    (``Robot.memo``), each joint visited once."""
    found = robot.memo.get("mimic_chains")
    if found is not None:
        return found
    chains: dict[int, Chain] = {}
    for start in robot.joints:
        if start.mimic is None or id(start) in chains:
            continue
        path: list[Joint] = []  # followed from start, none of them known yet
        on_path: dict[int, int] = {}
        current = start
        while True:
            if id(current) in chains:
                tail = chains[id(current)]
                break
            if current.mimic is None:  # the root: a chain of one
                tail = Chain(current, "root", 1, current, composed=(1.0, 0.0))
                break
            on_path[id(current)] = len(path)
            path.append(current)
            name = current.mimic.joint
            leader = _leader(robot, current)
            if name is None:
                tail = Chain(current, "unparsed", 1, current)
                path.pop()
                break
            if leader is None:
                tail = Chain(current, "missing", 1, current, missing=name)
                path.pop()
                break
            if leader is current:
                tail = Chain(current, "self", 1, current)
                path.pop()
                break
            if id(leader) in on_path:  # a cycle: its members from leader's place on
                members = tuple(path[on_path[id(leader)]:])
                for member in members:
                    chains[id(member)] = Chain(member, "cycle", len(members) + 1, leader,
                                               cycle=members)
                del path[on_path[id(leader)]:]
                tail = chains[id(leader)]  # the lead-in joints lead to the cycle's entry
                break
            current = leader
        chains.setdefault(id(tail.follower), tail)
        for joint in reversed(path):  # each one leads into the chain after it
            chains[id(joint)] = tail = _extended(joint, tail)
    robot.memo["mimic_chains"] = chains
    return chains


def _extended(joint: Joint, tail: Chain) -> Chain:
    """The chain of ``joint``, whose leader's chain is ``tail``."""
    composed = None
    mimic = joint.mimic
    if tail.composed is not None and mimic is not None and mimic.multiplier is not None \
            and mimic.offset is not None:
        # follower = m1 * (m2 * (... root ...) + o2) + o1
        multiplier, offset = tail.composed
        composed = (mimic.multiplier * multiplier, mimic.multiplier * offset + mimic.offset)
    return Chain(joint, tail.end, tail.length + 1, tail.last, tail.missing, composed,
                 tail.cycle)


def mimic_chain(robot: Robot, joint: Joint) -> Chain:
    """Where following ``joint``'s mimic leaders leads (a joint without a mimic: itself)."""
    if joint.mimic is None:
        return Chain(joint, "root", 1, joint, composed=(1.0, 0.0))
    return mimic_chains(robot)[id(joint)]


def chain_joints(robot: Robot, chain: Chain) -> tuple[Joint, ...]:
    """Every joint of ``chain``, the follower first (a walk of the chain's length)."""
    joints, current = [chain.follower], chain.follower
    while len(joints) < chain.length:
        current = _leader(robot, current) or current
        joints.append(current)
    return tuple(joints)


def chain_path(robot: Robot, chain: Chain, most: int = 6) -> str:
    """The chain's joints as ``'a' -> 'b' -> ...``: at most ``most`` names (the first ones and
    the last), the number of the others said."""
    names, current = [], chain.follower
    while len(names) < min(chain.length, most - 1):
        names.append(f"'{current.name}'")
        current = _leader(robot, current) or current
    if chain.length > most:
        names.append(f"... ({chain.length - most} more)")
    if chain.length >= most:
        names.append(f"'{chain.last.name}'")
    return " -> ".join(names)


def composed(chain: Chain) -> tuple[float, float] | None:
    """(multiplier, offset) of the follower relative to the chain's root, or None when the chain
    does not end at a root or a value did not parse."""
    return chain.composed if chain.end == "root" else None


def joint_range(joint: Joint) -> tuple[float, float] | None:
    """[lower, upper] of a revolute or prismatic joint, or None (no limits, unparsed, empty)."""
    limit = joint.limit
    if joint.type not in LIMITED_TYPES or limit is None:
        return None
    if limit.lower is None or limit.upper is None or limit.lower > limit.upper:
        return None
    if not (math.isfinite(limit.lower) and math.isfinite(limit.upper)):
        return None
    return limit.lower, limit.upper


def image(interval: tuple[float, float], multiplier: float, offset: float) -> tuple[float, float]:
    """The image of [lo, hi] under q -> multiplier * q + offset."""
    a, b = multiplier * interval[0] + offset, multiplier * interval[1] + offset
    return (a, b) if a <= b else (b, a)


def tolerance(interval: tuple[float, float]) -> float:
    """How far outside an interval still counts as inside (rounding in written offsets)."""
    return 1e-6 * max(1.0, abs(interval[0]), abs(interval[1]))


def inside(inner: tuple[float, float], outer: tuple[float, float]) -> bool:
    eps = tolerance(outer)
    return inner[0] >= outer[0] - eps and inner[1] <= outer[1] + eps


class MimicImage(NamedTuple):
    """A follower's image of its direct leader's range, compared with its own limits."""

    leader: Joint
    multiplier: float
    offset: float
    leader_range: tuple[float, float]
    image: tuple[float, float]
    follower_range: tuple[float, float] | None  # None: the follower has no limits to violate

    @property
    def violates(self) -> bool:
        return self.follower_range is not None and not inside(self.image, self.follower_range)

    @property
    def disjoint(self) -> bool:
        if self.follower_range is None:
            return False
        eps = tolerance(self.follower_range)
        return self.image[0] > self.follower_range[1] + eps or \
            self.image[1] < self.follower_range[0] - eps


def mimic_image(robot: Robot, joint: Joint) -> MimicImage | None:
    """The image of ``joint``'s direct leader's range, or None when it cannot be computed
    (no mimic, unknown leader, leader without a range, values that did not parse)."""
    mimic = joint.mimic
    if mimic is None or mimic.multiplier is None or mimic.offset is None:
        return None
    leader = robot.joint(mimic.joint)
    if leader is None or leader is joint:
        return None
    leader_range = joint_range(leader)
    if leader_range is None:
        return None
    follower_range = joint_range(joint) if joint.type in LIMITED_TYPES else None
    return MimicImage(leader, mimic.multiplier, mimic.offset, leader_range,
                      image(leader_range, mimic.multiplier, mimic.offset), follower_range)
