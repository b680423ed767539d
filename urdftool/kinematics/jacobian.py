"""The geometric Jacobian of a chain's tip origin, expressed in the base frame (rows vx vy vz
wx wy wz, one column per independent variable), and what it says about the configuration:
singular values, manipulability, condition number, nearness to a singularity. Also the parsing
of ``--q`` (values, ``name=value`` pairs, ``mid``, ``zero``) with the limit checks.
"""

from __future__ import annotations

import ast
import math
import operator
from dataclasses import dataclass

import numpy as np

from urdftool.errors import ToolError
from urdftool.kinematics.chain import Chain
from urdftool.kinematics.fk import joint_frames

ROWS = ("vx", "vy", "vz", "wx", "wy", "wz")


def geometric_jacobian(chain: Chain, q) -> np.ndarray:
    """6 x n: [linear velocity of the tip origin; angular velocity] per unit joint velocity,
    in the base frame. Mimic joints add ``multiplier *`` their column to their leader's."""
    frames, tip = joint_frames(chain, q)
    columns = np.zeros((chain.n, 6))
    if not frames:
        return columns.T.copy()
    # every joint at once (numpy per joint was 30 us a column: issue 15, a 50k-link chain)
    stack = np.array(frames)
    axes = np.einsum("mij,mj->mi", stack[:, :3, :3], np.array([j.axis for j in chain.joints]))
    revolute = np.array([j.revolute for j in chain.joints])[:, None]
    moment = np.cross(axes, tip[:3, 3] - stack[:, :3, 3])
    each = np.hstack([np.where(revolute, moment, axes), np.where(revolute, axes, 0.0)])
    each *= np.array([j.multiplier for j in chain.joints])[:, None]
    np.add.at(columns, [j.variable for j in chain.joints], each)  # mimics add to their leader
    return columns.T.copy()


@dataclass(frozen=True)
class Conditioning:
    """Singular-value analysis of one Jacobian (the full 6 x n one or its 3 position rows)."""

    rows: str  # "full" or "position"
    singular_values: tuple[float, ...]  # the min(rows, n) largest, descending
    manipulability: float  # product of those singular values (Yoshikawa's sqrt(det(J J^T)))
    condition: float  # largest / smallest singular value; inf when the smallest is 0
    rank: int  # numerical rank here
    generic_rank: int  # the rank the chain has at almost every configuration
    near_singular: bool  # the generic_rank-th singular value is below tolerance * largest

    @property
    def deficient(self) -> bool:
        """The chain can never give these rows full rank (e.g. too few joints, or a tip origin
        on the last joint's axis): not a singularity of the configuration."""
        return self.generic_rank < len(self.singular_values)


def _rank(sv: np.ndarray, shape: tuple[int, int]) -> int:
    if not sv.size:
        return 0
    return int(np.sum(sv > max(shape) * np.finfo(float).eps * max(float(sv[0]), 1e-300)))


def generic_ranks(chain: Chain, samples: int = 12, seed: int = 0) -> tuple[int, int]:
    """The largest rank of the full and the position Jacobian over random configurations:
    a configuration is singular when its rank falls below these."""
    rng = np.random.default_rng(seed)
    full = position = 0
    for q in chain.sample(rng, samples):
        jac = geometric_jacobian(chain, q)
        full = max(full, _rank(np.linalg.svd(jac, compute_uv=False), jac.shape))
        position = max(position, _rank(np.linalg.svd(jac[:3], compute_uv=False), (3, chain.n)))
    return full, position


def conditioning(jac: np.ndarray, rows: str, tolerance: float, generic_rank: int) -> Conditioning:
    sv = np.linalg.svd(jac, compute_uv=False)[: min(jac.shape)]
    largest = float(sv[0]) if sv.size else 0.0
    smallest = float(sv[-1]) if sv.size else 0.0
    rank = _rank(sv, jac.shape)
    condition = largest / smallest if rank == sv.size and smallest > 0 else math.inf
    near = generic_rank > 0 and float(sv[generic_rank - 1]) <= tolerance * largest
    return Conditioning(rows, tuple(float(s) for s in sv), float(np.prod(sv)), condition, rank,
                        generic_rank, bool(near))


def analyse(chain: Chain, jac: np.ndarray, tolerance: float = 1e-3) -> list[Conditioning]:
    """The full Jacobian, and its position rows: a 3-DoF positioning arm is singular when the
    position rows lose rank even though the 6 x 3 matrix keeps rank 3. Singular means: below
    the rank the chain has almost everywhere (so a structurally deficient chain does not warn
    at every configuration)."""
    full, position = generic_ranks(chain)
    return [conditioning(jac, "full", tolerance, full),
            conditioning(jac[:3], "position", tolerance, position)]


# -- --q parsing --------------------------------------------------------------------------------

_OPS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
        ast.Div: operator.truediv, ast.USub: operator.neg, ast.UAdd: operator.pos}


def parse_number(text: str) -> float:
    """A float, or a small arithmetic expression with ``pi`` (``-pi/2``, ``3*pi/4``)."""
    text = text.strip()
    try:
        result = float(text)
    except ValueError:
        result = _expression(text)
    if not math.isfinite(result):
        raise ToolError(f"--q: {text!r} is not a finite number")
    return result


def _expression(text: str) -> float:
    """Numbers, pi, + - * / and parentheses: nothing else is evaluated."""

    def value(node):
        if isinstance(node, ast.Expression):
            return value(node.body)
        if isinstance(node, ast.Constant) and type(node.value) in (int, float):
            return float(node.value)
        if isinstance(node, ast.Name) and node.id in ("pi", "PI"):
            return math.pi
        if isinstance(node, ast.BinOp) and type(node.op) in _OPS:
            return _OPS[type(node.op)](value(node.left), value(node.right))
        if isinstance(node, ast.UnaryOp) and type(node.op) in _OPS:
            return _OPS[type(node.op)](value(node.operand))
        raise ValueError(text)

    try:
        if len(text) > 100:
            raise ValueError(text)
        result = value(ast.parse(text.replace("π", "pi"), mode="eval"))
    except (SyntaxError, ValueError, ZeroDivisionError, RecursionError, OverflowError):
        raise ToolError(f"--q: {text!r} is not a number") from None
    return result


def _fmt(value: float | None) -> str:
    return "-inf" if value is None else f"{value:g}"


def outside_limits(chain: Chain, q: np.ndarray, tolerance: float = 1e-12) -> list[str]:
    """The variables of ``q`` outside their joint limits, as "name = value outside [lo, hi]
    unit" (the Jacobian is defined there all the same: callers warn, not refuse)."""
    found = []
    for variable, value in zip(chain.variables, q):
        if variable.type == "continuous" or variable.lower is None or variable.upper is None:
            continue
        if not variable.lower - tolerance <= value <= variable.upper + tolerance:
            unit = "rad" if variable.revolute else "m"
            found.append(f"joint '{variable.name}' = {value:g} is outside its limits "
                         f"[{_fmt(variable.lower)}, {_fmt(variable.upper)}] {unit}")
    return found


def parse_q(chain: Chain, text: str | None) -> np.ndarray:
    """The configuration named by ``--q``: comma-separated values for the chain's variables in
    order, or ``name=value`` pairs (others 0), optionally after ``mid`` or ``zero``; ``None``
    means zero. Raises ToolError for a wrong count or an unknown name; values outside the
    limits are kept (``outside_limits`` names them)."""
    names = chain.variable_names
    q = np.zeros(chain.n)
    if text is None:
        return q
    items = [item.strip() for item in text.split(",")]
    start = items[0].lower() if items else ""
    if start in ("mid", "zero"):
        items.pop(0)
        if start == "mid":
            q = np.array([v.middle for v in chain.variables])
    items = [item for item in items if item]
    named = [item for item in items if "=" in item]
    if named and len(named) != len(items):
        raise ToolError("--q: give either all values in order or name=value pairs, not both")
    if named:
        followers = {j.name: j.leader for j in chain.joints if j.mimic}
        for item in named:
            name, _, raw = item.partition("=")
            name = name.strip()
            if name in followers:
                raise ToolError(f"--q: joint '{name}' mimics '{followers[name]}': give "
                                f"'{followers[name]}' instead")
            if name not in names:
                raise ToolError(f"--q: '{name}' is not a joint variable of the chain "
                                f"(variables: {', '.join(names)})")
            q[names.index(name)] = parse_number(raw)
    elif items:
        if len(items) != chain.n:
            raise ToolError(f"--q: {len(items)} value{'s' if len(items) != 1 else ''} for "
                            f"{chain.n} joint variable{'s' if chain.n != 1 else ''} "
                            f"({', '.join(names)})")
        q = np.array([parse_number(item) for item in items])
    return q
