"""`urdftool inertia`: placeholder until its issue lands."""

from __future__ import annotations

import click


@click.command("inertia", context_settings={"ignore_unknown_options": True})
@click.argument("args", nargs=-1)
def command(args):
    """Not implemented yet."""
    from urdftool.errors import ToolError

    raise ToolError("'inertia' is not implemented yet")
