"""`urdftool jacobian FILE [--base L] [--tip L] [--q v1,v2,...] [--symbolic]`: the geometric
Jacobian of the tip link's origin in the base link's frame (default: the root link), at a configuration (with singular values,
manipulability and condition number) or as sympy expressions."""

from __future__ import annotations

import math

import click

from urdftool.cli import (
    echo,
    format_option,
    load_robot,
    package_option,
    print_finding,
    print_json,
    print_table,
    shown,
    split_args,
    stdout_console,
    untrusted_options,
)
from urdftool.display import clean

ROWS = ("vx", "vy", "vz", "wx", "wy", "wz")


def _number(value: float) -> str:
    return "0" if abs(value) < 1e-12 else f"{value:.6g}"


def _outside_limits(chain, q) -> list[str]:
    out = []
    for variable, value in zip(chain.variables, q):
        if variable.bounded and not variable.lower <= value <= variable.upper:
            out.append(f"{variable.name} [{variable.lower:g}, {variable.upper:g}]")
    return out


def _warnings(chain, q, analysis, q_text) -> list[str]:
    from urdftool.kinematics.jacobian import outside_limits

    warnings = []
    if q_text is None and (outside := _outside_limits(chain, q)):
        warnings.append(f"q = 0 lies outside the limits of {', '.join(outside)}; "
                        "use --q mid or give values")
    elif q_text is not None:  # computed all the same: the Jacobian is defined there
        warnings.extend(f"--q: {text}; the Jacobian is computed there all the same"
                        for text in outside_limits(chain, q))
    for item in analysis:
        if item.near_singular:
            what = "the Jacobian" if item.rows == "full" else "its position rows (vx vy vz)"
            verb = "loses" if item.rows == "full" else "lose"
            value = item.singular_values[item.generic_rank - 1]
            warnings.append(f"near a singularity: {what} {verb} rank (singular value "
                            f"{item.generic_rank} is {value:.3g}; rank here {item.rank}, "
                            f"elsewhere {item.generic_rank})")
    return warnings


def render_numeric_text(path, chain, q, jac, tip_pose, analysis, warnings, tolerance) -> None:
    from rich.table import Table

    console = stdout_console()
    console.print(f"[bold]{shown(chain.robot or 'robot')}[/]: geometric Jacobian of the origin "
                  f"of '{shown(chain.tip)}' in the frame of '{shown(chain.base)}'"
                  + (" (world)" if chain.base_is_root else ""))
    config = Table()
    for header in ("", "joint", "type", "q", "limits"):
        config.add_column(header)
    for i, (variable, value) in enumerate(zip(chain.variables, q), start=1):
        limits = (f"[{variable.lower:g}, {variable.upper:g}]" if variable.bounded else "none")
        config.add_row(f"q{i}", shown(variable.name) + ("" if variable.in_chain
                                                         else " (mimic leader)"),
                       shown(variable.type), _number(value), shown(limits))
    print_table(console, config, "configuration")
    table = Table()
    table.add_column("")
    for i in range(chain.n):
        table.add_column(f"q{i + 1}", justify="right")
    for name, row in zip(ROWS, jac):
        table.add_row(name, *(_number(v) for v in row))
    print_table(console, table, "J (v: m/s or m/m per unit q; w: rad/s)")
    x, y, z = tip_pose[:3, 3]
    console.print(f"tip origin: [{_number(x)}, {_number(y)}, {_number(z)}] m")
    for item in analysis:
        label = "6 x n (mixed units)" if item.rows == "full" else "position rows, 3 x n"
        condition = "inf" if math.isinf(item.condition) else f"{item.condition:.6g}"
        values = shown(f"[{', '.join(f'{s:.6g}' for s in item.singular_values)}]")
        console.print(f"{label}: singular values {values}, "
                      f"manipulability {item.manipulability:.6g}, condition number {condition}")
        if item.deficient:
            console.print(f"[dim]  (rank {item.generic_rank} at most for this chain, at any "
                          "configuration: not a singularity of this one)[/]")
    for warning in warnings:
        print_finding(path, None, None, "warning", None, warning)
    if not warnings:
        console.print(f"[dim]not near a singularity (singular values above {tolerance:g} x "
                      "the largest, up to the chain's rank)[/]")


def render_numeric_latex(chain, q, jac) -> str:
    # names from the file only in comments, escaped: a newline would end the comment
    lines = [(f"% urdftool jacobian: {clean(chain.robot or 'robot')}, tip {clean(chain.tip)}, "
              f"frame {clean(chain.base)}")]
    for i, (variable, value) in enumerate(zip(chain.variables, q), start=1):
        lines.append(f"% q_{i} = {clean(variable.name)} = {value!r}")
    rows = [" & ".join(_number(v) for v in row) for row in jac]
    lines += [r"\begin{equation}", r"J = \begin{bmatrix}" + r" \\ ".join(rows) + r"\end{bmatrix}",
              r"\end{equation}"]
    return "\n".join(lines) + "\n"


def run_symbolic(chain, fmt: str, simplify: str) -> None:
    from urdftool.errors import require

    require("sympy", "kinematics")
    from urdftool.kinematics import symbolic

    result = symbolic.symbolic_kinematics(chain, simplify)
    if fmt == "json":
        print_json(symbolic.as_dict(result))
    elif fmt == "latex":
        click.echo(symbolic.to_latex(result), nl=False)
    elif fmt == "numpy":
        click.echo(symbolic.to_numpy(result), nl=False)
    else:
        echo(symbolic.to_text(result), nl=False)


@click.command("jacobian")
@click.argument("inputs", nargs=-1, required=True, metavar="FILE [NAME:=VALUE...]")
@click.option("--base", metavar="LINK",
              help="First link of the chain; the Jacobian is expressed in its frame "
                   "(default: the root).")
@click.option("--tip", metavar="LINK",
              help="The link whose origin is the reference point (default: the single leaf).")
@click.option("--q", "q_text", metavar="V1,V2,...|NAME=V,...|mid",
              help="Configuration: values of the chain's joint variables in order (write a "
                   "leading minus as --q=-0.5,1.2 or --q -0.5,1.2; pi works: -pi/2), or "
                   "name=value pairs (others 0), or 'mid' (middle of the limits). Default 0.")
@click.option("--symbolic", is_flag=True,
              help="Tip position and Jacobian as sympy expressions in q1..qn and link lengths.")
@click.option("--simplify", type=click.Choice(["auto", "full", "trig", "none"]), default="auto",
              show_default=True,
              help="With --symbolic: auto = trigsimp up to 6 variables, none beyond.")
@click.option("--tolerance", type=float, default=1e-3, show_default=True,
              help="Warn of a singularity when smallest/largest singular value is below this.")
@format_option("text", "json", "latex", "numpy")
@package_option
@untrusted_options
def command(inputs, base, tip, q_text, symbolic, simplify, tolerance, fmt, packages):
    """Geometric Jacobian of the tip origin in the base link's frame (rows vx vy vz wx wy wz,
    one column per joint variable), with singular values, manipulability and condition number;
    or, with --symbolic, as simplified expressions (text, LaTeX, NumPy code)."""
    from urdftool.errors import ToolError
    from urdftool.kinematics.chain import extract_chain
    from urdftool.kinematics.fk import forward
    from urdftool.kinematics.jacobian import analyse, geometric_jacobian, parse_q

    paths, xacro_args = split_args(inputs)
    if len(paths) != 1:
        raise ToolError("jacobian takes exactly one FILE")
    if not (tolerance >= 0 and math.isfinite(tolerance)):
        raise ToolError("--tolerance must be a finite number >= 0")
    robot = load_robot(paths[0], packages, xacro_args)
    chain = extract_chain(robot, base, tip)
    if symbolic:
        if q_text is not None:
            raise ToolError("--symbolic gives expressions in q1..qn: leave out --q")
        run_symbolic(chain, fmt, simplify)
        return
    if fmt == "numpy":
        raise ToolError("--format numpy writes code for --symbolic; add --symbolic")
    q = parse_q(chain, q_text)
    jac = geometric_jacobian(chain, q)
    analysis = analyse(chain, jac, tolerance)
    warnings = _warnings(chain, q, analysis, q_text)
    if fmt == "text":
        render_numeric_text(paths[0], chain, q, jac, forward(chain, q), analysis, warnings,
                            tolerance)
        return
    if fmt == "json":
        data = {"tip": chain.tip, "q": [float(v) for v in q], "joints": chain.variable_names,
                "frame": "world" if chain.base_is_root else chain.base, "reference_point": "tip_origin",
                "J": [[float(v) for v in row] for row in jac]}
        print_json(data)
    else:
        click.echo(render_numeric_latex(chain, q, jac), nl=False)
    for warning in warnings:
        print_finding(paths[0], None, None, "warning", None, warning, err=True)
