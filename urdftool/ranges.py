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
    """Where following a joint's mimic leads: the joints followed in order, and how it ends."""

    joints: tuple[Joint, ...]  # the follower first, then each leader in turn
    end: str  # "root" (last joint is not a mimic), "missing", "self", "cycle", "unparsed"
    missing: str | None = None  # the name that is not a joint, when end == "missing"

    @property
    def root(self) -> Joint | None:
        return self.joints[-1] if self.end == "root" else None


def mimic_chain(robot: Robot, joint: Joint) -> Chain:
    """Follow ``joint``'s mimic leaders until a joint that mimics nothing."""
    joints = [joint]
    seen = {id(joint)}
    current = joint
    while current.mimic is not None:
        name = current.mimic.joint
        if name is None:
            return Chain(tuple(joints), "unparsed")
        leader = robot.joint(name)
        if leader is None:
            return Chain(tuple(joints), "missing", name)
        if leader is current:
            return Chain(tuple(joints), "self")
        if id(leader) in seen:
            joints.append(leader)
            return Chain(tuple(joints), "cycle")
        joints.append(leader)
        seen.add(id(leader))
        current = leader
    return Chain(tuple(joints), "root")


def composed(chain: Chain) -> tuple[float, float] | None:
    """(multiplier, offset) of the follower relative to the chain's root, or None when the chain
    does not end at a root or a value did not parse."""
    if chain.end != "root":
        return None
    multiplier, offset = 1.0, 0.0
    # follower = m1 * (m2 * (... root ...) + o2) + o1: fold from the root outwards
    for joint in reversed(chain.joints[:-1]):
        mimic = joint.mimic
        if mimic is None or mimic.multiplier is None or mimic.offset is None:
            return None
        multiplier, offset = mimic.multiplier * multiplier, mimic.multiplier * offset + mimic.offset
    return multiplier, offset


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
