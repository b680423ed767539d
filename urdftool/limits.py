"""The ``urdftool limits`` table: one row per moving joint with its range, effort, velocity,
mimic image (``urdftool.ranges`` computes it) and the findings of the ``joint`` and ``mimic``
rules about it.
"""


import math
from typing import NamedTuple

from urdftool.findings import enclosing
from urdftool.model import Robot
from urdftool.ranges import LIMITED_TYPES, mimic_image


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
    from urdftool.rules import load_all, run

    paths = {j.loc.element: j for j in robot.joints if j.loc is not None and j.loc.element}
    result: dict[str, list[dict]] = {}
    enabled = [(r, r.severity) for r in load_all().values() if r.family in families]
    for rule, severity, finding in run(robot, enabled):
        if finding.message.startswith("internal error in rule"):
            continue  # `check` reports a broken rule; the table goes on
        joint = enclosing(paths, finding.loc.element if finding.loc is not None else None)
        if joint is None:
            continue
        result.setdefault(joint.loc.element, []).append(
            {"rule": rule.id, "severity": finding.severity or severity,
             "message": finding.message, "hint": finding.hint,
             "path": finding.loc.path, "line": finding.loc.line,
             "column": finding.loc.column})
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
