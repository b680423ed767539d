"""``urdftool diff``: what a change does to each robot (issue 30; DESIGN.md "urdftool diff")."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import click

from urdftool.cli import (
    PathsCommand,
    _colour,
    echo,
    format_option,
    load_options,
    package_option,
    print_json,
    untrusted_options,
)
from urdftool.errors import ToolError

_LITERAL_KEY = "urdftool.literal"


@click.command(cls=PathsCommand)
@click.argument("inputs", nargs=-1)
@format_option("text", "json", "markdown")
@package_option
@click.option("--render", "render_dir", type=click.Path(file_okay=False), metavar="DIR",
              help="Write before/after pictures of each changed robot (zero configuration, "
                   "changed links highlighted) into DIR; the markdown links them.")
@click.option("--exit-code", "exit_code", is_flag=True,
              help="Exit 1 when a robot changed (as git diff --exit-code).")
@untrusted_options
@click.pass_context
def command(ctx, inputs, fmt, packages, render_dir, exit_code):
    """What a change does to each robot: links and joints added, removed and renamed, origins
    (with how far the links below move), limits, masses, inertias, geometry and meshes,
    materials and <gazebo>/<ros2_control>/<transmission> blocks, located at both sides.

    \b
    urdftool diff                   HEAD vs the working tree
    urdftool diff BASE              BASE vs the working tree
    urdftool diff BASE..HEAD        two revisions (BASE...HEAD: from their merge base)
    urdftool diff OLD NEW           two files or two directories (snapshots)
    ... NAME:=VALUE                 xacro arguments for every robot
    ... -- PATH...                  only the robots of these files and directories

    Exit code 0 (with --exit-code: 1 when a robot changed); 2: the diff could not be made.
    """
    from contextlib import ExitStack

    from urdftool.check import CheckOptions
    from urdftool.diff import formats
    from urdftool.diff import revisions as git
    from urdftool.diff.run import diff_revisions, diff_snapshots

    literal = ctx.meta.get(_LITERAL_KEY, 0)
    values = list(inputs)
    limits = values[len(values) - literal:] if literal else []
    positional, xacro_args = [], {}
    for value in values[:len(values) - literal]:
        if ":=" in value:
            name, _, arg = value.partition(":=")
            xacro_args[name] = arg
        else:
            positional.append(value)
    options = CheckOptions(load_options(packages, xacro_args), debug=ctx.obj.get("debug", False))
    options.unsafe_edits = False
    with ExitStack() as stack:
        if len(positional) == 2 and _snapshots(*positional):
            robots, base, head = diff_snapshots(Path(positional[0]), Path(positional[1]),
                                                options, limits)
        elif len(positional) <= 1:
            repo = git.repository(Path.cwd())
            base_rev, head_rev, merge_base = _range(positional[0] if positional else "")
            robots, base, head = stack.enter_context(diff_revisions(
                repo, base_rev, head_rev, merge_base, options, xacro_args,
                [_in_repository(limit, repo) for limit in limits]))
        else:
            raise ToolError("give at most one revision range (BASE, BASE..HEAD), or two "
                            "existing files or two directories (OLD NEW)"
                            + (f"; {positional[1]!r} and the rest are not both files or "
                               "directories" if len(positional) == 2 else ""))
        pictures = {}
        if render_dir:  # (while the revisions' trees exist: the meshes are read there)
            from urdftool.diff.render import render_robots

            pictures = render_robots(robots, Path(render_dir))
        if fmt == "json":
            print_json(formats.to_json(robots, base, head))
        elif fmt == "markdown":
            echo(formats.markdown(robots, base, head, pictures), nl=False)
        else:
            lines = formats.text_lines(robots, base, head, _colour(sys.stdout))
            echo("\n".join(lines) if lines else "no robot reads a file this change touched")
    if exit_code and any(r.status != "unchanged" for r in robots):
        ctx.exit(1)


def _snapshots(old: str, new: str) -> bool:
    if os.path.isfile(old) and os.path.isfile(new):
        return True
    if os.path.isdir(old) and os.path.isdir(new):
        return True
    if os.path.exists(old) != os.path.exists(new) and ".." not in old:
        missing = new if os.path.exists(old) else old
        raise ToolError(f"{missing}: no such file or directory")
    return False


def _range(text: str) -> tuple[str, str | None, bool]:
    """(base, head or None for the working tree, from the merge base) of a revision range."""
    if not text:
        return "HEAD", None, False
    if "..." in text:
        base, _, head = text.partition("...")
        return base or "HEAD", head or "HEAD", True
    if ".." in text:
        base, _, head = text.partition("..")
        return base or "HEAD", head or "HEAD", False
    return text, None, False


def _in_repository(path: str, repo: Path) -> str:
    """A PATH limit given relative to the working directory, relative to the repository."""
    full = os.path.abspath(path)
    root = os.path.realpath(repo)
    for candidate in (full, os.path.realpath(full)):
        if candidate == root or candidate.startswith(root + os.sep):
            return Path(os.path.relpath(candidate, root)).as_posix()
    raise ToolError(f"{path}: not inside the repository {repo}")
