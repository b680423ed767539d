"""`urdftool expand FILE.xacro [NAME:=VALUE...] [-o OUT]`: xacro to URDF."""

from __future__ import annotations

import click

from urdftool.cli import load_options, package_option, split_args, untrusted_options


@click.command("expand")
@click.argument("inputs", nargs=-1, required=True, metavar="FILE.xacro [NAME:=VALUE...]")
@package_option
@untrusted_options
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Write here, not stdout.")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text",
              help="text: the URDF; json: the URDF and the problems found.")
@click.pass_context
def command(ctx, inputs, packages, output, fmt):
    """Expand a xacro file to URDF. Errors point into the .xacro source (exit 1)."""
    import json

    from urdftool.errors import ToolError
    from urdftool.output import write_output
    from urdftool.source import load
    from urdftool.xacro_expand import expanded_xml

    paths, xacro_args = split_args(inputs)
    if len(paths) != 1:
        raise ToolError("expand takes exactly one FILE")
    source = load(paths[0], load_options(packages, xacro_args))
    errors = [(rule, f) for rule, f in source.problems
              if rule.startswith(("xacro.", "xml.")) and rule != "xml.declaration"]
    text = expanded_xml(source)
    if fmt == "json":
        problems = [{"rule": rule, "message": f.message, "path": f.loc.path if f.loc else None,
                     "line": f.loc.line if f.loc else None,
                     "column": f.loc.column if f.loc else None} for rule, f in source.problems]
        click.echo(json.dumps({"path": source.path, "urdf": text, "problems": problems}, indent=2))
    else:
        for rule, finding in errors:
            loc = finding.loc
            where = f"{loc.path}:{loc.line}: " if loc and loc.line else f"{source.path}: "
            click.echo(f"{where}error: {finding.message} [{rule}]", err=True)
        if text and not errors:
            write_output(text + "\n", output, inputs=[*paths, *source.texts])
    ctx.exit(1 if errors or not text else 0)
