"""Joint limits and mimic relations as data: the ``urdftool limits`` table, and the interval
arithmetic the ``mimic`` rules use (leader chains, composed multipliers, images of ranges).

A mimic follower is driven to ``multiplier * q_leader + offset``; the *image* of the leader's
range is the interval the follower is driven through when the leader sweeps its limits.

Pure Python (no numpy): the ``mimic`` rules import this on every ``urdftool check``.
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


# -- the `urdftool limits` table ---------------------------------------------------------------


class JointRow(NamedTuple):
    name: str | None
    type: str | None
    lower: float | None
    upper: float | None
    range: float | None  # upper - lower (rad or m)
    unit: str  # "rad", "m" or ""
    effort: float | None
    velocity: float | None
    mimic: dict | None  # {"joint", "multiplier", "offset", "image"}
    findings: list[dict]  # {"rule", "severity", "message", "hint"}
    line: int | None = None
    path: str | None = None

    @property
    def verdict(self) -> str:
        """The worst severity among the joint's findings, or "ok"."""
        for severity in ("error", "warning", "info"):
            if any(f["severity"] == severity for f in self.findings):
                return severity
        return "ok"

    def to_json(self) -> dict:
        degrees = math.degrees(self.range) if self.unit == "rad" and self.range is not None \
            else None
        return {"name": self.name, "type": self.type, "lower": self.lower, "upper": self.upper,
                "range": self.range, "range_degrees": degrees, "unit": self.unit,
                "effort": self.effort, "velocity": self.velocity, "mimic": self.mimic,
                "verdict": self.verdict, "findings": self.findings,
                "path": self.path, "line": self.line}


def _finite(value: float | None) -> float | None:
    return value if value is not None and math.isfinite(value) else None


def _findings_by_joint(robot: Robot, families=("joint", "mimic")) -> dict[str, list[dict]]:
    """Run the rules of ``families`` and file each finding under the joint it is about (the
    finding's element path lies inside the joint's)."""
    from urdftool.rules import load_all

    paths = {j.loc.element: j for j in robot.joints if j.loc is not None and j.loc.element}
    result: dict[str, list[dict]] = {}
    for rule in load_all().values():
        if rule.family not in families:
            continue
        try:
            findings = list(rule.check(robot))
        except Exception:  # noqa: BLE001, S112 - `check` reports a broken rule; the table goes on
            continue
        for finding in findings:
            element = finding.loc.element if finding.loc is not None else None
            if not element:
                continue
            for path, joint in paths.items():
                if element == path or element.startswith(path + "/"):
                    result.setdefault(joint.loc.element, []).append(
                        {"rule": rule.id, "severity": finding.severity or rule.severity,
                         "message": finding.message, "hint": finding.hint,
                         "path": finding.loc.path, "line": finding.loc.line,
                         "column": finding.loc.column})
                    break
    return result


def limits_table(robot: Robot) -> list[JointRow]:
    """One row per moving joint, in document order, with the joint and mimic findings."""
    findings = _findings_by_joint(robot)
    rows = []
    for joint in robot.joints:
        # a fixed joint only appears when something is wrong with it (e.g. a fixed leader)
        if not joint.moving and (joint.loc is None or not findings.get(joint.loc.element)):
            continue
        limit = joint.limit
        bounded = joint.type in LIMITED_TYPES and limit is not None
        lower = _finite(limit.lower) if bounded else None
        upper = _finite(limit.upper) if bounded else None
        span = upper - lower if lower is not None and upper is not None else None
        unit = {"revolute": "rad", "continuous": "rad", "prismatic": "m"}.get(joint.type or "", "")
        mimic = None
        if joint.mimic is not None:
            mimic_info = mimic_image(robot, joint)
            mimic = {"joint": joint.mimic.joint, "multiplier": _finite(joint.mimic.multiplier),
                     "offset": _finite(joint.mimic.offset),
                     "image": list(mimic_info.image) if mimic_info else None}
        rows.append(JointRow(
            joint.name, joint.type, lower, upper, span, unit,
            _finite(limit.effort) if limit else None, _finite(limit.velocity) if limit else None,
            mimic, findings.get(joint.loc.element, []) if joint.loc else [],
            joint.loc.line if joint.loc else None, joint.loc.path if joint.loc else None))
    return rows


def limits_data(robot: Robot) -> dict:
    """The whole table as JSON-ready data (floats at full precision)."""
    rows = limits_table(robot)
    return {"robot": robot.name,
            "joints": [row.to_json() for row in rows],
            "summary": {"joints": len(rows),
                        "errors": _count(rows, "error"), "warnings": _count(rows, "warning"),
                        "infos": _count(rows, "info")}}


def _count(rows: list[JointRow], severity: str) -> int:
    return sum(f["severity"] == severity for row in rows for f in row.findings)
