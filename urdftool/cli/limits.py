"""`urdftool limits FILE`: the joint-limit and mimic table (``urdftool.limits`` computes it)."""

from __future__ import annotations

import click

from urdftool.cli import (
    format_option,
    info_summary,
    load_robot,
    package_option,
    print_findings,
    print_json,
    print_table,
    show_info_option,
    shown,
    split_args,
    stdout_console,
    untrusted_options,
)


def _num(value: float | None, digits: int = 6) -> str:
    from urdftool.display import number

    return number(value, digits)


def _range(row: dict) -> str:
    if row["range"] is None:
        return "unlimited" if row["type"] == "continuous" else "-"
    if row["unit"] == "rad":
        return f"{row['range']:.4g} rad ({row['range_degrees']:.0f}°)"
    return f"{row['range']:.4g} {row['unit']}".strip()


def _image(mimic: dict | None) -> str:
    if mimic is None or mimic.get("image") is None:
        return "-"
    lo, hi = mimic["image"]
    return f"[{_num(lo, 5)}, {_num(hi, 5)}]"


_STYLE = {"error": "bold red", "warning": "yellow", "info": "cyan", "ok": "green"}
_ORDER = ("error", "warning", "info")


def _sorted(findings: list[dict]) -> list[dict]:
    return sorted(findings, key=lambda f: _ORDER.index(f["severity"]))


def _verdict(row: dict) -> str:
    if not row["findings"]:
        return "[green]ok[/]"
    return "\n".join(f"[{_STYLE[f['severity']]}]{f['severity']}[/] {shown(f['rule'])}"
                     for f in _sorted(row["findings"]))


@click.command("limits")
@click.argument("inputs", nargs=-1, required=True, metavar="FILE [NAME:=VALUE...]")
@format_option("text", "json")
@package_option
@show_info_option
@untrusted_options
def command(inputs, fmt, packages, show_info):
    """Joint-limit and mimic table: ranges, efforts, velocities, mimic images, verdicts.

    Exit code 1 when a joint or mimic check finds an error (e.g. a mimic follower driven
    outside its limits), 0 otherwise, 2 when the file cannot be read.
    """
    from urdftool.errors import ToolError
    from urdftool.limits import limits_data

    paths, xacro_args = split_args(inputs)
    if len(paths) != 1:
        raise ToolError("limits takes exactly one FILE")
    robot = load_robot(paths[0], packages, xacro_args)
    data = limits_data(robot)
    failed = data["summary"]["errors"] > 0
    if fmt == "json":
        print_json(data, allow_nan=False)
    else:
        _print_table(robot, data, show_info)
    if failed:
        raise click.exceptions.Exit(1)


def _print_table(robot, data: dict, show_info: bool = False) -> None:
    from rich.table import Table

    console = stdout_console()
    table = Table()
    for name, justify in (("joint", "left"), ("type", "left"), ("lower", "right"),
                          ("upper", "right"), ("range", "right"), ("effort", "right"),
                          ("velocity", "right"), ("mimics", "left"), ("multiplier", "right"),
                          ("offset", "right"), ("image of leader range", "right"),
                          ("verdict", "left")):
        table.add_column(name, justify=justify, overflow="fold")
    for row in data["joints"]:
        mimic = row["mimic"]
        table.add_row(
            shown(row["name"]), shown(row["type"] or "?"), _num(row["lower"]),
            _num(row["upper"]), _range(row), _num(row["effort"]), _num(row["velocity"]),
            shown(mimic["joint"]) if mimic else "-",
            _num(mimic["multiplier"]) if mimic else "-",
            _num(mimic["offset"], 10) if mimic else "-",
            _image(mimic), _verdict(row))
    print_table(console, table, f"[bold]{shown(data['robot'])}[/]: {len(data['joints'])} "
                                "moving joint(s)")
    for row in data["joints"]:
        print_findings(row["findings"], show_info,
                       lambda f, row=row: (f.get("path") or row["path"], f.get("line") or row["line"]))
    summary = data["summary"]
    colour = "red" if summary["errors"] else ("yellow" if summary["warnings"] else "green")
    console.print(f"[{colour}]{summary['joints']} joint(s): {summary['errors']} error(s), "
                  f"{summary['warnings']} warning(s), "
                  f"{info_summary(summary['infos'], show_info)}[/]")
