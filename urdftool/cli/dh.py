"""`urdftool dh FILE [--base L] [--tip L] [--convention standard|modified]`: the
Denavit-Hartenberg table of the serial chain from base to tip, with base and tool transforms and
a self-check against the URDF's forward kinematics."""

from __future__ import annotations

import csv
import io
import math

import click

from urdftool.cli import (
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
from urdftool.display import clean, guard

SELF_CHECK_SAMPLES = 100
RESIDUAL_WARNING = 1e-9


def number(value: float) -> str:
    """Human display: 6 significant digits, noise below 1e-10 shown as 0 (JSON/CSV keep all)."""
    return "0" if abs(value) < 1e-10 else f"{value:.6g}"


def angle(value: float, latex: bool = False) -> str:
    """An angle, as a multiple of π/4 when it is one (within 1e-9)."""
    k = round(value / (math.pi / 4))
    if k != 0 and abs(value - k * math.pi / 4) < 1e-9 and abs(k) <= 4:
        sign = "-" if k < 0 else ""
        k = abs(k)
        if latex:
            text = {4: r"\pi", 2: r"\frac{\pi}{2}", 1: r"\frac{\pi}{4}", 3: r"\frac{3\pi}{4}"}[k]
        else:
            text = {4: "π", 2: "π/2", 1: "π/4", 3: "3π/4"}[k]
        return sign + text
    return number(value)


def _headers(convention: str) -> list[str]:
    if convention == "standard":
        return ["θ offset (rad)", "d (m)", "a (m)", "α (rad)"]
    return ["α(i-1) (rad)", "a(i-1) (m)", "θ offset (rad)", "d (m)"]


def _cells(row, convention: str) -> list[str]:
    theta, d, a, alpha = angle(row.theta), number(row.d), number(row.a), angle(row.alpha)
    return [theta, d, a, alpha] if convention == "standard" else [alpha, a, theta, d]


def _matrix_text(matrix) -> str:
    return "\n".join("  [" + "  ".join(f"{number(v):>10}" for v in row) + " ]" for row in matrix)


def render_text(chain, result, residual: float) -> None:
    from rich.table import Table

    console = stdout_console()
    formula = ("A_i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i)" if result.convention == "standard"
               else "A_i = Rx(α_(i-1)) Tx(a_(i-1)) Rz(θ_i) Tz(d_i)")
    table = Table()
    table.add_column("i", justify="right")
    table.add_column("joint")
    table.add_column("type")
    for header in _headers(result.convention):
        table.add_column(header, justify="right")
    table.add_column("variable")
    for i, row in enumerate(result.rows, start=1):
        variable = f"{'θ' if row.revolute else 'd'} + q{i}"
        if not row.variable.startswith("q_"):
            variable += f", q{i} = {shown(row.variable)}"
        table.add_row(str(i), shown(row.joint), shown(row.type), *_cells(row, result.convention),
                      variable)
    print_table(console, table, f"{shown(chain.robot or 'robot')}: {shown(chain.base)} → "
                                f"{shown(chain.tip)}, {result.convention} DH ({formula})")
    console.print("base (the base link's frame to DH frame 0):")
    console.print(_matrix_text(result.base))
    console.print(f"tool (DH frame {len(result.rows)} to the tip link's frame):")
    console.print(_matrix_text(result.tool))
    for note in result.notes:
        console.print(f"[dim]note: {shown(note)}[/]")
    verdict = "ok" if residual <= RESIDUAL_WARNING else "[bold red]MISMATCH[/]"
    console.print(f"self-check: base · Π A_i(q_i) · tool vs the URDF's forward kinematics, worst "
                  f"|Δ| over {SELF_CHECK_SAMPLES} random configurations within the limits: "
                  f"{residual:.3g} ({verdict})")


def render_csv(result) -> str:
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["joint", "type", "theta", "d", "a", "alpha", "variable"])
    for row in result.rows:
        writer.writerow([row.joint, row.type, repr(row.theta), repr(row.d), repr(row.a),
                         repr(row.alpha), row.variable])
    return out.getvalue()


def _tex_number(value: float) -> str:
    text = number(value)
    if "e" in text:
        mantissa, _, exponent = text.partition("e")
        return rf"{mantissa} \times 10^{{{int(exponent)}}}"
    return text


def _tex_matrix(matrix) -> str:
    rows = [" & ".join(_tex_number(v) for v in row) for row in matrix]
    return r"\begin{bmatrix}" + r" \\ ".join(rows) + r"\end{bmatrix}"


def render_latex(chain, result, residual: float) -> str:
    def offset(variable: str, constant: str) -> str:
        if constant == "0":
            return variable
        return f"{variable} - {constant[1:]}" if constant.startswith("-") else \
            f"{variable} + {constant}"

    # names from the file only in comments, escaped: a newline would end the comment
    lines = [(f"% urdftool dh: {clean(chain.robot or 'robot')}, {clean(chain.base)} -> "
              f"{clean(chain.tip)}, {result.convention} convention")]
    for i, row in enumerate(result.rows, start=1):
        lines.append(f"% q_{i} = {clean(row.variable)} ({'rad' if row.revolute else 'm'})")
    for note in result.notes:
        lines.append(f"% note: {clean(note)}")
    lines.append(f"% self-check: worst |delta| over {SELF_CHECK_SAMPLES} random configurations: "
                 f"{residual:.3g}")
    if result.convention == "standard":
        header = r"$i$ & $\theta_i$ & $d_i$ & $a_i$ & $\alpha_i$ \\"
    else:
        header = r"$i$ & $\alpha_{i-1}$ & $a_{i-1}$ & $\theta_i$ & $d_i$ \\"
    lines += [r"\begin{tabular}{rcccc}", r"\hline", header, r"\hline"]
    for i, row in enumerate(result.rows, start=1):
        theta = angle(row.theta, latex=True)
        d = _tex_number(row.d)
        if row.revolute:
            theta = offset(f"q_{{{i}}}", theta)
        else:
            d = offset(f"q_{{{i}}}", d)
        a, alpha = _tex_number(row.a), angle(row.alpha, latex=True)
        cells = [theta, d, a, alpha] if result.convention == "standard" else [alpha, a, theta, d]
        lines.append(f"{i} & " + " & ".join(f"${c}$" for c in cells) + r" \\")
    lines += [r"\hline", r"\end{tabular}", "",
              r"\begin{equation}", r"T_\mathrm{base} = " + _tex_matrix(result.base) + r",\quad",
              r"T_\mathrm{tool} = " + _tex_matrix(result.tool), r"\end{equation}"]
    return "\n".join(lines) + "\n"


@click.command("dh")
@click.argument("inputs", nargs=-1, required=True, metavar="FILE [NAME:=VALUE...]")
@click.option("--base", metavar="LINK", help="First link of the chain (default: the root).")
@click.option("--tip", metavar="LINK",
              help="Last link of the chain (default: the single leaf below the base).")
@click.option("--convention", type=click.Choice(["standard", "modified"]), default="standard",
              show_default=True,
              help="standard: Rz(θ)Tz(d)Tx(a)Rx(α); modified (Craig): Rx(α)Tx(a)Rz(θ)Tz(d).")
@format_option("text", "json", "csv", "latex")
@package_option
@untrusted_options
def command(inputs, base, tip, convention, fmt, packages):
    """Denavit-Hartenberg table of the serial chain from --base to --tip.

    Fixed joints are folded into the neighbouring transforms, mimic joints are expressed
    through their leader, and the base and tool transforms make base · Π A_i(q_i) · tool equal
    the URDF's forward kinematics (checked over random configurations)."""
    from urdftool.errors import ToolError
    from urdftool.kinematics.chain import extract_chain
    from urdftool.kinematics.dh import extract_dh, self_check

    paths, xacro_args = split_args(inputs)
    if len(paths) != 1:
        raise ToolError("dh takes exactly one FILE")
    robot = load_robot(paths[0], packages, xacro_args)
    chain = extract_chain(robot, base, tip)
    result = extract_dh(chain, convention)
    residual = self_check(chain, result, SELF_CHECK_SAMPLES)
    if fmt == "text":
        render_text(chain, result, residual)
        return
    if fmt == "json":
        print_json(result.as_dict())
    elif fmt == "csv":  # exact but for a runner command a joint name would start a line with
        click.echo(guard(render_csv(result)), nl=False)
    else:
        click.echo(guard(render_latex(chain, result, residual)), nl=False)
    if residual > RESIDUAL_WARNING:
        print_finding(paths[0], None, None, "warning", None, "the DH model differs from the "
                      f"URDF's forward kinematics by up to {residual:.3g} (see the notes of "
                      "--format text)", err=True)
