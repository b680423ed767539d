"""`urdftool inertia FILE [--link L] [--density RHO]`: declared vs geometry-derived inertia per
link, the findings of the `inertia` and `mesh` rules, and a corrected `<inertial>` block for
each flagged link (``urdftool.inertia_table`` computes it)."""

from __future__ import annotations

import click

from urdftool.cli import (
    format_option,
    info_summary,
    load_robot,
    package_option,
    print_finding,
    print_json,
    print_table,
    show_info_option,
    shown,
    shown_block,
    split_args,
    stdout_console,
    untrusted_options,
)

_STYLE = {"error": "bold red", "warning": "yellow", "info": "cyan"}
_ORDER = ("error", "warning", "info")


def _num(value, digits: int = 4) -> str:
    from urdftool.display import number

    return number(value, digits)


def _triple(values) -> str:
    return "-" if values is None else " ".join(_num(v) for v in values)


def _ratio(values) -> str:
    if not values:
        return "-"
    low, high = min(values), max(values)
    return f"{low:.3g}" if abs(high - low) <= 0.005 * abs(high) else f"{low:.3g}–{high:.3g}"


def _verdict(row: dict) -> str:
    if not row["findings"]:
        return "[green]ok[/]"
    findings = sorted(row["findings"], key=lambda f: _ORDER.index(f["severity"]))
    return "\n".join(f"[{_STYLE[f['severity']]}]{f['severity']}[/] {shown(f['rule'])}"
                     for f in findings)


@click.command("inertia")
@click.argument("inputs", nargs=-1, required=True, metavar="FILE [NAME:=VALUE...]")
@click.option("--link", "link", metavar="L", help="Only this link (its corrected block always "
                                                 "shown).")
@click.option("--density", type=float, metavar="KG_PER_M3",
              help="Corrected blocks from this density (mass = density x volume) instead "
                   "of the declared mass.")
@format_option("text", "json")
@package_option
@show_info_option
@untrusted_options
@click.option("--no-cache", is_flag=True,
              help="Parse every mesh again: neither read nor write the mesh-summary cache "
                   "($URDFTOOL_CACHE_DIR, else ~/.cache/urdftool).")
def command(inputs, link, density, fmt, packages, show_info, no_cache):
    """Declared vs geometry-derived inertia per link, with a corrected <inertial> block for
    every link the inertia checks flag.

    The geometry is the link's collision shapes (its visuals when it has no usable collision),
    uniform density, the declared mass. Exit code 1 when an error is shown, 0 otherwise, 2 when
    the file cannot be read or the link does not exist.
    """
    from urdftool import cache
    from urdftool.errors import ToolError
    from urdftool.inertia_table import inertia_data

    cache.ENABLED = not no_cache
    paths, xacro_args = split_args(inputs)
    if len(paths) != 1:
        raise ToolError("inertia takes exactly one FILE")
    if density is not None and not density > 0:
        raise ToolError(f"--density must be positive, got {density!r}")
    robot = load_robot(paths[0], packages, xacro_args)
    if link is not None and robot.link(link) is None:
        names = ", ".join(str(l.name) for l in robot.links[:20])
        raise ToolError(f"no link '{link}' in {paths[0]} (links: {names})")
    data = inertia_data(robot, link, density)
    if fmt == "json":
        print_json(data, allow_nan=False)
    else:
        _print(data, show_info)
    if data["summary"]["errors"]:
        raise click.exceptions.Exit(1)


def _print(data: dict, show_info: bool = False) -> None:
    from rich.table import Table

    console = stdout_console()
    table = Table()
    for name, justify in (("link", "left"), ("mass kg", "right"), ("declared", "right"),
                          ("geometry", "right"), ("from", "left"), ("ratio", "right"),
                          ("COM offset m", "right"), ("verdict", "left")):
        table.add_column(name, justify=justify, overflow="fold")
    for row in data["links"]:
        geometry = row["geometry"] or {}
        table.add_row(shown(row["link"]), _num(row["mass"]), _triple(row["principal"]),
                      _triple(geometry.get("principal")), shown(geometry.get("from") or "-"),
                      _ratio(row["ratios"]), _num(row["com_offset"], 3), _verdict(row))
    print_table(console, table, f"[bold]{shown(data['robot'])}[/]: {len(data['links'])} "
                                "link(s); moments in kg·m², principal, ascending")
    for row in data["links"]:
        for f in sorted(row["findings"], key=lambda f: _ORDER.index(f["severity"])):
            if f["severity"] == "info" and not show_info:
                continue  # as check lists them
            print_finding(f["path"], f["line"], f.get("column"), f["severity"], f["rule"],
                          f["message"])
    blocks = [row for row in data["links"] if row["corrected"] is not None]
    if blocks:
        source = (f"a uniform density of {data['density']:g} kg/m³"
                  if data["density"] is not None else "the declared mass spread uniformly")
        console.print(f"\n[bold]Corrected <inertial> blocks[/] ({source} over the geometry; "
                      "COM at its centroid, tensor about the COM in the link frame):")
        for row in blocks:
            block = row["corrected"]
            console.print(f"[dim]<!-- link '{shown(row['link'])}': from its "
                          f"{shown(block['from'])} geometry, {block['volume']:.4g} m³ -->[/]")
            console.print(shown_block(block["xml"]), highlight=False)
    missing = [row["link"] for row in data["links"]
               if row["corrected"] is None and any(
                   f["severity"] in ("error", "warning") and f["rule"].startswith("inertia.")
                   for f in row["findings"])]
    if missing:
        console.print("[dim]no corrected block for " + ", ".join(shown(m) for m in missing)
                      + " (no usable geometry, or no mass: try --density)[/]")
    s = data["summary"]
    colour = "red" if s["errors"] else ("yellow" if s["warnings"] else "green")
    console.print(f"[{colour}]{s['links']} link(s): {s['errors']} error(s), "
                  f"{s['warnings']} warning(s), {info_summary(s['infos'], show_info)}[/]")
