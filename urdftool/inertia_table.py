"""The ``urdftool inertia`` table: per link, the declared inertial, what the geometry gives,
their comparison, the findings of the `inertia` and `mesh` rules, and a corrected
``<inertial>`` for flagged links. Plain dicts and floats (JSON keeps full precision)."""

from __future__ import annotations

import math

from urdftool.findings import enclosing
from urdftool.physics import inertia as phys
from urdftool.physics import links as analysis

FAMILIES = ("inertia", "mesh")
_MOMENTS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


def _tensor_dict(tensor) -> dict | None:
    if tensor is None:
        return None
    return {"ixx": tensor[0][0], "ixy": tensor[0][1], "ixz": tensor[0][2],
            "iyy": tensor[1][1], "iyz": tensor[1][2], "izz": tensor[2][2]}


def _finite(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _findings(robot) -> list[tuple[str, str, object]]:
    """(rule id, severity, Finding) of the inertia and mesh rules."""
    from urdftool.rules import load_all, run

    enabled = [(r, r.severity) for r in load_all().values() if r.family in FAMILIES]
    return [(rule.id, finding.severity or severity, finding)
            for rule, severity, finding in run(robot, enabled)]


def _owners(links) -> dict[str, int]:
    """Element path -> index of the link written there."""
    return {link.loc.element: index for index, link in enumerate(links)
            if link.loc is not None and link.loc.element}


def inertia_data(robot, link: str | None = None, density: float | None = None) -> dict:
    """The table of ``urdftool inertia`` (all links, or the one named ``link``)."""
    results = analysis.analyse(robot)
    by_link: dict[int, list[dict]] = {}
    owners = _owners(robot.links)
    for rule_id, severity, finding in _findings(robot):
        loc = finding.loc
        index = enclosing(owners, loc.element if loc is not None else None)
        by_link.setdefault(index if index is not None else -1, []).append({
            "rule": rule_id, "severity": severity, "message": finding.message,
            "hint": finding.hint, "path": loc.path if loc else None,
            "line": loc.line if loc else None, "column": loc.column if loc else None})
    rows = []
    for index, a in results.items():
        if link is not None and a.link.name != link:
            continue
        rows.append(_row(a, by_link.get(index, []), density, force=link is not None))
    counts = {s: sum(f["severity"] == s for r in rows for f in r["findings"])
              for s in ("error", "warning", "info")}
    return _clean({"robot": robot.name, "density": density, "links": rows,
                   "summary": {"links": len(rows), "errors": counts["error"],
                               "warnings": counts["warning"], "infos": counts["info"]}})


def _clean(value):
    """Non-finite numbers (a nan written in the file) become None: JSON has no nan."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    return value


def _row(a, findings: list[dict], density: float | None, force: bool) -> dict:
    inertial = a.link.inertial
    declared = _tensor_dict(a.declared)
    row = {
        "link": a.link.name,
        "path": a.link.loc.path if a.link.loc else None,
        "line": (inertial.loc.line if inertial is not None and inertial.loc else None)
        or (a.link.loc.line if a.link.loc else None),
        "moving": a.moving,
        "mass": _finite(a.mass),
        "com": list(a.com) if inertial is not None else None,
        "rpy": list(inertial.origin.rpy) if inertial is not None else None,
        "declared": declared,
        "principal": list(a.principal) if a.principal is not None else None,
        "geometry": None,
        "ratios": list(a.ratios) if a.ratios is not None else None,
        "com_offset": None,
        "com_outside": a.com_distance if a.com_distance else None,
        "bound": None,
        "findings": findings,
        "corrected": None,
    }
    problems = [f"{s.shape.role}: {s.problem}" for s in a.shapes if s.problem]
    if problems:
        row["geometry_problems"] = problems
    if a.solid is not None:
        derived = a.derived
        row["geometry"] = {
            "from": a.derived_from, "volume": a.solid.volume,
            "centroid": list(a.solid.centroid),
            "tensor": _tensor_dict(derived),  # for the declared mass, in the inertial frame
            "principal": list(phys.principal_moments(derived)) if derived is not None else None,
        }
        if inertial is not None:
            row["com_offset"] = phys.norm(phys.sub(a.com, a.solid.centroid))
    if a.bound is not None:
        b = a.bound
        row["bound"] = {"axis": b.axis_name, "moment": b.moment, "bound": _finite(b.bound),
                        "reach": b.reach, "ratio": _finite(b.ratio)}
    flagged = any(f["severity"] in ("error", "warning") and f["rule"].startswith("inertia.")
                  for f in findings)
    if flagged or force:
        block = analysis.derived_inertial(a, density=density)
        if block is not None:
            block["xml"] = analysis.inertial_xml(block)
        row["corrected"] = block
    return row
