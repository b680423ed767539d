"""Symbolic forward kinematics and geometric Jacobian of a chain with sympy, in the joint
variables q1..qn and named link lengths, printable as text, LaTeX and Python/NumPy code.

Link lengths are named after the constant offset they measure: ``l{k}`` is the translation from
the frame of the k-th moving joint's child link to the next moving joint (``l0``: from the base
link to the first joint; ``l{n}``: from the last joint to the tip), in the coordinates of that
frame. An offset along a single axis is one symbol ``l{k}``; one with several components gets
``l{k}_x``, ``l{k}_y``, ``l{k}_z``. Symbols stand for the magnitude, the sign is written in the
expression. Rotation entries within ``EXACT`` (1e-6) of 0 or ±1 are taken as exact: an angle
within about 1e-6 rad of a multiple of pi/2 (a vendor's rounded 1.570796327, whose cosine is
-2.05e-10, would otherwise leave terms like ``2.05e-10*sin(q2)`` everywhere); the output says
which origins were snapped and by how much at most (issue 23.7). Others stay floating-point
numbers at full precision. The numeric tables (``jacobian --q``) are never snapped.

sympy is imported here only: this module is loaded by ``--symbolic`` alone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from urdftool.display import clean
from urdftool.errors import ToolError, require
from urdftool.kinematics.chain import Chain

EXACT = 1e-6  # rotation entries this close to 0/±1 are exact (angles ~1e-6 rad of k*pi/2)


@dataclass
class Symbolic:
    chain: Chain
    q: list  # sympy symbols q1..qn
    lengths: dict  # symbol -> value in metres, in order of appearance
    position: object  # sympy 3x1 Matrix: the tip origin in the base frame
    jacobian: object  # sympy 6xn Matrix (rows vx vy vz wx wy wz)
    snapped: list[str]  # notes: what had rotation entries taken as exact, and by how much
    simplified: str = "none"  # the simplification applied: full, trig or none

    @property
    def symbols(self) -> list:
        return list(self.q) + list(self.lengths)

    def evaluate(self, q) -> tuple[np.ndarray, np.ndarray]:
        """(position, Jacobian) as numbers at ``q``, with the lengths at their URDF values."""
        sp = require("sympy", "kinematics")
        values = list(q) + [float(v) for v in self.lengths.values()]
        fp = sp.lambdify(self.symbols, self.position, "numpy")
        fj = sp.lambdify(self.symbols, self.jacobian, "numpy")
        return (np.array(fp(*values), dtype=float).reshape(3),
                np.array(fj(*values), dtype=float).reshape(6, self.chain.n))


def _number(sp, value: float):
    """An exact 0/±1 when the value is within EXACT of it, else a full-precision Float."""
    for exact in (0, 1, -1):
        if abs(value - exact) < EXACT:
            return sp.Integer(exact)
    return sp.Float(repr(float(value)))


def _scalar(sp, value: float):
    """Mimic multipliers and offsets: the decimal as written (0.1 -> 1/10, which trigsimp
    handles far better than a Float), or a full-precision Float for a long one."""
    text = repr(float(value))
    if len(text.lstrip("-").replace(".", "").lstrip("0")) <= 10 and "e" not in text:
        return sp.Rational(text)
    return sp.Float(text)


def _constant(sp, transform: np.ndarray, k: int, lengths: dict, snapped: dict, what: str):
    out = sp.eye(4)
    for r in range(3):
        for c in range(3):
            value = float(transform[r, c])
            entry = _number(sp, value)
            if entry.is_Integer and value != int(entry):
                snapped[what] = max(snapped.get(what, 0.0), abs(value - int(entry)))
            out[r, c] = entry
    offset = [float(v) for v in transform[:3, 3]]
    nonzero = [i for i, v in enumerate(offset) if abs(v) > 1e-12]
    for i in nonzero:
        name = f"l{k}" if len(nonzero) == 1 else f"l{k}_{'xyz'[i]}"
        symbol = sp.Symbol(name, positive=True)
        lengths[symbol] = abs(offset[i])
        out[i, 3] = symbol if offset[i] > 0 else -symbol
    return out


def _motion(sp, joint, value):
    axis = [_number(sp, float(v)) for v in joint.axis]
    out = sp.eye(4)
    if not joint.revolute:
        for i in range(3):
            out[i, 3] = axis[i] * value
        return out
    c, s = sp.cos(value), sp.sin(value)
    x, y, z = axis
    v = 1 - c
    rotation = sp.Matrix([
        [c + x * x * v, x * y * v - z * s, x * z * v + y * s],
        [y * x * v + z * s, c + y * y * v, y * z * v - x * s],
        [z * x * v - y * s, z * y * v + x * s, c + z * z * v],
    ])
    out[:3, :3] = rotation
    return out


SIMPLIFY_LEVELS = ("auto", "full", "trig", "none")
AUTO_TRIG_UP_TO = 6  # auto: trigsimp up to this many variables (ur5: seconds, panda: a minute)


MAX_NODES = 300_000  # expression-tree size of the tip position beyond which we give up


def _inexact(transform: np.ndarray, axis: np.ndarray | None = None) -> bool:
    """Whether a constant rotation (or an axis) has entries that are not 0 or ±1."""
    values = list(np.ravel(transform[:3, :3])) + (list(axis) if axis is not None else [])
    return any(min(abs(v), abs(abs(v) - 1)) >= EXACT for v in values)


def _simplifier(sp, level: str, chain: Chain):
    if level == "auto":
        inexact = (any(_inexact(j.origin, j.axis) for j in chain.joints)
                   or _inexact(chain.tool))
        level = "trig" if chain.n <= AUTO_TRIG_UP_TO and not inexact else "none"
    if level == "full":
        return level, sp.simplify
    if level == "trig":
        return level, sp.trigsimp
    return "none", None


def symbolic_kinematics(chain: Chain, simplify: str = "auto") -> Symbolic:
    """Tip position and geometric Jacobian as sympy matrices. ``simplify``: ``full``
    (sympy.simplify, slow), ``trig`` (trigsimp), ``none``, or ``auto``: trig up to six
    variables when every rotation is a multiple of pi/2, none otherwise (a 7-DoF arm takes
    minutes in trigsimp, and floating-point rotation entries leave nothing to simplify)."""
    sp = require("sympy", "kinematics")
    level, simplifier = _simplifier(sp, simplify, chain)
    q = list(sp.symbols(f"q1:{chain.n + 1}", real=True))
    lengths: dict = {}
    snapped: dict[str, float] = {}  # what -> the largest change made to one of its entries
    current = sp.eye(4)
    frames = []
    for k, joint in enumerate(chain.joints):
        current = current * _constant(sp, joint.origin, k, lengths, snapped,
                                      f"origin of '{joint.name}'")
        frames.append(current)
        value = q[joint.variable]
        if joint.mimic:
            value = _scalar(sp, joint.multiplier) * value + _scalar(sp, joint.offset)
        current = current * _motion(sp, joint, value)
        size = sum(1 for e in current[:3, 3] for _ in sp.preorder_traversal(e))
        if size > MAX_NODES:
            raise ToolError(
                f"the symbolic expressions grow beyond {MAX_NODES} terms at joint "
                f"'{joint.name}': rotations in the joint origins or axes that are not "
                "multiples of pi/2 leave no compact closed form; use the numeric Jacobian "
                "(--q)")
    current = current * _constant(sp, chain.tool, len(chain.joints), lengths, snapped,
                                  "tip transform")
    position = current[:3, 3]
    if simplifier is not None:
        position = position.applyfunc(simplifier)
    jacobian = sp.zeros(6, chain.n)
    for joint, frame in zip(chain.joints, frames):
        axis = frame[:3, :3] * sp.Matrix([_number(sp, float(v)) for v in joint.axis])
        multiplier = _scalar(sp, joint.multiplier)
        if joint.revolute:
            jacobian[3:, joint.variable] += multiplier * axis
        if simplifier is None:
            # from the geometry, z x (p - o) (z for prismatic joints): no product rule, so no
            # swell on long chains
            linear = axis.cross(position - frame[:3, 3]) if joint.revolute else axis
            jacobian[:3, joint.variable] += multiplier * linear
    if simplifier is not None:
        # differentiate the simplified position: compact, and it simplifies further
        jacobian[:3, :] = position.jacobian(q)
        jacobian = jacobian.applyfunc(simplifier)
    notes = [f"{what} (off by up to {off:.3g})" for what, off in sorted(snapped.items())]
    return Symbolic(chain, q, lengths, position, jacobian, notes, level)


# -- printing ---------------------------------------------------------------------------------

ROWS = ("vx", "vy", "vz", "wx", "wy", "wz")


def _legend(result: Symbolic, comment: str = "") -> list[str]:
    lines = []
    for symbol, variable in zip(result.q, result.chain.variables):
        unit = "rad" if variable.revolute else "m"
        lines.append(f"{comment}{symbol} = q_{clean(variable.name)} ({unit})")
    for symbol, value in result.lengths.items():
        lines.append(f"{comment}{symbol} = {value!r} m")
    for what in result.snapped:
        lines.append(f"{comment}note: rotation entries of the {what} taken as exact 0/±1: "
                     f"within {EXACT:g} of them, angles within about {EXACT:g} rad of a "
                     "multiple of pi/2 (the numeric tables use the values as written)")
    if result.simplified == "none":
        lines.append(f"{comment}note: not simplified (more than {AUTO_TRIG_UP_TO} variables, "
                     "rotations that are not multiples of pi/2, or --simplify none; "
                     "--simplify trig or full can take minutes)")
    return lines


def to_text(result: Symbolic) -> str:
    lines = [f"tip '{clean(result.chain.tip)}' in the frame of '{clean(result.chain.base)}'", ""]
    lines += _legend(result)
    lines.append("")
    for axis, expr in zip("xyz", result.position):
        lines.append(f"p{axis} = {expr}")
    lines.append("")
    for r, name in enumerate(ROWS):
        for c, symbol in enumerate(result.q):
            lines.append(f"J[{name}, {symbol}] = {result.jacobian[r, c]}")
    return "\n".join(lines) + "\n"


def _latex_names(sp, result: Symbolic) -> dict:
    names = {}
    for symbol in result.lengths:
        base, _, axis = symbol.name.partition("_")
        names[symbol] = f"l_{{{base[1:]}{axis}}}"
    for symbol in result.q:
        names[symbol] = f"q_{{{symbol.name[1:]}}}"
    return names


def to_latex(result: Symbolic) -> str:
    sp = require("sympy", "kinematics")
    names = _latex_names(sp, result)

    def tex(expr):
        return sp.latex(expr, symbol_names=names, mat_str="bmatrix", mat_delim="")

    lines = ["% " + line for line in _legend(result)]
    lines += [r"\begin{equation}", r"p = " + tex(result.position), r"\end{equation}",
              r"\begin{equation}", r"J = " + tex(result.jacobian), r"\end{equation}"]
    return "\n".join(lines) + "\n"


def to_numpy(result: Symbolic) -> str:
    sp = require("sympy", "kinematics")
    from sympy.printing.numpy import NumPyPrinter

    printer = NumPyPrinter({"fully_qualified_modules": False})
    q_names = ", ".join(str(s) for s in result.q) + ("," if len(result.q) == 1 else "")
    defaults = ", ".join(f"{s}={v!r}" for s, v in result.lengths.items())
    signature = f"q{', ' + defaults if defaults else ''}"

    def function(name: str, doc: str, matrix, shape: tuple[int, int]) -> list[str]:
        replacements, reduced = sp.cse(matrix)
        body = [f"def {name}({signature}):", f'    """{doc}"""', f"    {q_names} = q"]
        for symbol, expr in replacements:
            body.append(f"    {symbol} = {printer.doprint(expr)}")
        (expr,) = reduced
        rows = []
        for r in range(shape[0]):
            cells = ", ".join(printer.doprint(expr[r, c]) for c in range(shape[1]))
            rows.append(f"[{cells}]")
        if shape[1] == 1:
            body.append("    return array([" + ", ".join(r[1:-1] for r in rows) + "])")
        else:
            body.append("    return array([\n        " + ",\n        ".join(rows) + ",\n    ])")
        return body

    def quoted(name) -> str:  # a name from the file inside the docstring: no quote, no newline
        return str(name).encode("unicode_escape").decode("ascii").replace('"', '\\"')

    title = (f'"""Kinematics of {quoted(result.chain.robot or "the robot")}: tip '
             f"'{quoted(result.chain.tip)}' in the frame of '{quoted(result.chain.base)}' "
             '(generated by urdftool jacobian --symbolic)."""')
    lines = [title, "",
             "from numpy import array, cos, sin, sqrt  # noqa: F401", "", ""]
    lines += ["# " + line for line in _legend(result)] + [""]
    lines += function("tip_position", "Position of the tip origin [x, y, z] in metres.",
                      result.position, (3, 1))
    lines += ["", ""]
    lines += function("jacobian", "Geometric Jacobian (rows vx vy vz wx wy wz, one column per "
                      "q).", result.jacobian, (6, result.chain.n))
    return "\n".join(lines) + "\n"


def as_dict(result: Symbolic) -> dict:
    return {
        "tip": result.chain.tip,
        "joints": result.chain.variable_names,
        "frame": "world",
        "reference_point": "tip_origin",
        "variables": {str(s): v.name for s, v in zip(result.q, result.chain.variables)},
        "lengths": {str(s): v for s, v in result.lengths.items()},
        "position": [str(e) for e in result.position],
        "J": [[str(result.jacobian[r, c]) for c in range(result.chain.n)] for r in range(6)],
    }
