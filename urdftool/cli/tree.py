"""`urdftool tree FILE`: the kinematic tree."""

from __future__ import annotations

import click

from urdftool.cli import (
    format_option,
    load_robot,
    package_option,
    print_json,
    shown,
    split_args,
    stdout_console,
    untrusted_options,
)


def tree_data(robot) -> dict:
    """Nested {link, joint, type, children} from each root link."""

    def node(link: str, joint=None, seen=frozenset()) -> dict:
        children = [] if link in seen else [
            node(j.child, j, seen | {link}) for j in robot.child_joints(link) if j.child]
        entry = {"link": link, "children": children}
        if joint is not None:
            entry["joint"] = joint.name
            entry["type"] = joint.type
            if joint.mimic is not None:
                entry["mimic"] = joint.mimic.joint
        return entry

    return {"robot": robot.name, "roots": [node(root) for root in robot.roots()]}


@click.command("tree")
@click.argument("inputs", nargs=-1, required=True, metavar="FILE [NAME:=VALUE...]")
@format_option("text", "json")
@package_option
@untrusted_options
def command(inputs, fmt, packages):
    """Print the kinematic tree (like check_urdf, prettier)."""
    from urdftool.errors import ToolError

    paths, xacro_args = split_args(inputs)
    if len(paths) != 1:
        raise ToolError("tree takes exactly one FILE")
    robot = load_robot(paths[0], packages, xacro_args)
    data = tree_data(robot)
    if fmt == "json":
        print_json(data)
        return
    from rich.tree import Tree

    moving = sum(1 for j in robot.joints if j.moving)
    top = Tree(f"[bold]{shown(robot.name)}[/]: {len(robot.links)} links, {len(robot.joints)} "
               f"joints ({moving} moving)")

    def add(branch, entry):
        for child in entry["children"]:
            label = (f"[cyan]{shown(child['link'])}[/] [dim]via {shown(child['joint'])} "
                     f"({shown(child['type'])})")
            if "mimic" in child:
                label += f", mimics {shown(child['mimic'])}"
            add(branch.add(label + "[/]"), child)

    for root in data["roots"]:
        add(top.add(f"[bold cyan]{shown(root['link'])}[/] [dim](root)[/]"), root)
    stdout_console().print(top)
