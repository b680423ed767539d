"""`urdftool tree FILE`: the kinematic tree."""

from __future__ import annotations

import json

import click

from urdftool.cli import (
    format_option,
    load_robot,
    package_option,
    split_args,
    stdout_console,
    untrusted_options,
)


def tree_data(robot) -> dict:
    """Nested {link, joint, type, children} from each root link. Iterative (a chain of any
    depth); a link already on the path from its root is listed, not expanded again."""

    def entry(link: str, joint=None) -> dict:
        node = {"link": link, "children": []}
        if joint is not None:
            node["joint"] = joint.name
            node["type"] = joint.type
            if joint.mimic is not None:
                node["mimic"] = joint.mimic.joint
        return node

    roots = []
    for root in robot.roots():
        top = entry(root)
        roots.append(top)
        on_path = {root}
        # (node, its link, the child joints left to expand); a link leaves the path when its
        # children are done
        stack = [(top, root, iter(robot.child_joints(root)))]
        while stack:
            node, link, joints = stack[-1]
            joint = next((j for j in joints if j.child), None)
            if joint is None:
                stack.pop()
                on_path.discard(link)
                continue
            child = entry(joint.child, joint)
            node["children"].append(child)
            if joint.child not in on_path:
                on_path.add(joint.child)
                stack.append((child, joint.child, iter(robot.child_joints(joint.child))))
    return {"robot": robot.name, "roots": roots}


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
        from urdftool.display import json_safe

        click.echo(json_safe(dumps(data)))
        return
    _print_tree(robot, data)


# nesting deeper than this is not indented further (a chain of n links would otherwise print
# O(n^2) characters); the depth is then written on the line
MAX_INDENT = 40


def dumps(value) -> str:
    """``json.dumps(value, indent=2)`` without recursion (a 50k-link chain nests 100k deep),
    and with the indentation stopping at ``MAX_INDENT`` levels of the tree (still JSON)."""
    from json.encoder import encode_basestring_ascii

    parts: list[str] = []
    end = object()
    stack: list[list] = []  # [items, depth, closer, first, is_dict]

    def put(item, depth: int) -> None:
        if isinstance(item, dict) and item:
            parts.append("{")
            stack.append([iter(item.items()), depth + 1, "}", True, True])
        elif isinstance(item, list) and item:
            parts.append("[")
            stack.append([iter(item), depth + 1, "]", True, False])
        elif isinstance(item, str):
            parts.append(encode_basestring_ascii(item))
        else:
            parts.append(json.dumps(item))

    def pad(depth: int) -> str:
        return "\n" + "  " * min(depth, 2 * MAX_INDENT + 2)

    put(value, 0)
    while stack:
        frame = stack[-1]
        item = next(frame[0], end)
        if item is end:
            stack.pop()
            parts.append(pad(frame[1] - 1) + frame[2])
            continue
        parts.append(pad(frame[1]) if frame[3] else "," + pad(frame[1]))
        frame[3] = False
        if frame[4]:
            key, item = item
            parts.append(encode_basestring_ascii(key) + ": ")
        put(item, frame[1])
    return "".join(parts)


def _print_tree(robot, data: dict) -> None:
    """The tree drawn as rich's ``Tree`` draws it (same guides and styles), line by line
    without recursion; below ``MAX_INDENT`` levels the guides stop growing and the line says
    its depth."""
    from rich.text import Text

    from urdftool.display import clean

    console = stdout_console()
    ascii_only = not console.encoding.lower().startswith("utf")
    fork, last, bar, space = ("+-- ", "`-- ", "|   ", "    ") if ascii_only else \
        ("\u251c\u2500\u2500 ", "\u2514\u2500\u2500 ", "\u2502   ", "    ")
    moving = sum(1 for j in robot.joints if j.moving)
    text = Text()
    text.append(clean("" if robot.name is None else robot.name), "bold")
    text.append(f": {len(robot.links)} links, {len(robot.joints)} joints ({moving} moving)")
    guides: list[str] = []  # the prefix of the current depth's children
    stack = [_with_more(data["roots"])]  # per depth: (node, whether a sibling follows it)
    while stack:
        item = next(stack[-1], None)
        if item is None:
            stack.pop()
            if guides:
                guides.pop()
            continue
        node, more = item
        depth = len(stack) - 1
        text.append("\n")
        text.append("".join(guides[-MAX_INDENT:]) + (fork if more else last))
        if depth > MAX_INDENT:
            text.append(f"[depth {depth}] ", "dim")
        if "joint" in node:
            text.append(clean(node["link"]), "cyan")
            text.append(" ")
            label = f"via {clean(str(node['joint']))} ({clean(str(node['type']))})"
            if "mimic" in node:
                label += f", mimics {clean(str(node['mimic']))}"
            text.append(label, "dim")
        else:
            text.append(clean(node["link"]), "bold cyan")
            text.append(" ")
            text.append("(root)", "dim")
        if node["children"]:
            guides.append(bar if more else space)
            stack.append(_with_more(node["children"]))
    if console.color_system is None:  # no styles to draw: the text as is, without rich's
        console.file.write(text.plain + "\n")  # rendering of it (a third of a big tree)
    else:
        console.print(text)


def _with_more(nodes: list):
    """(node, whether a sibling follows it) for each node."""
    return ((node, i < len(nodes) - 1) for i, node in enumerate(nodes))
