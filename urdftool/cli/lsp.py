"""`urdftool lsp`: the Language Server Protocol server on stdio (``urdftool.lsp``)."""

from __future__ import annotations

import click

from urdftool.cli import package_option, parse_packages, split_args


@click.command("lsp")
@click.argument("xacro_args", nargs=-1, metavar="[NAME:=VALUE...]")
@package_option
@click.option("--select", multiple=True, metavar="RULE|FAMILY",
              help="Only these rules or families (repeatable, or comma-separated).")
@click.option("--ignore", multiple=True, metavar="RULE|FAMILY",
              help="Skip these rules or families (repeatable, or comma-separated).")
@click.option("--allow-env", "allow_env", multiple=True, metavar="NAME",
              help="An environment variable $(env NAME) and $(optenv NAME) may read. "
                   "Repeatable.")
@click.option("--timeout", type=click.FloatRange(0.1), default=None, metavar="SECONDS",
              help="Time limit of one xacro expansion, and of one file or mesh read by the "
                   "sandboxed reader (default 3 s).")
@click.option("--memory-limit", "memory_limit", type=click.IntRange(64), default=None,
              metavar="MB", help="Address space of the sandboxed reader (default 1024 MB).")
@click.option("--stdio", is_flag=True, hidden=True, help="Accepted for editors that pass it.")
def command(xacro_args, packages, select, ignore, allow_env, timeout, memory_limit, stdio):
    """Language Server Protocol server on stdio: the findings, fixes and numbers of `check`
    in the editor.

    A workspace is untrusted (read as with --untrusted) unless the client's
    initializationOptions say {"trusted": true}. The same options may be given as
    initializationOptions or workspace settings (section "urdftool"): packages, args, select,
    ignore, allowEnv, timeout, memoryLimit, debounce (ms), ruleDocsUrl.
    """
    from urdftool.config import check_rule_ids
    from urdftool.errors import ToolError, require

    paths, args = split_args(xacro_args)
    if paths:
        raise ToolError(f"lsp takes no paths (the editor opens files): {paths[0]!r}")

    def split(values):
        return [part.strip() for value in values for part in value.split(",") if part.strip()]

    check_rule_ids(split(select), "--select")
    check_rule_ids(split(ignore), "--ignore")
    require("pygls", "lsp")
    require("lsprotocol", "lsp")
    from urdftool.lsp.engine import Settings
    from urdftool.lsp.server import serve

    settings = Settings()
    settings.packages = parse_packages(packages)
    settings.args = args
    settings.select, settings.ignore = split(select), split(ignore)
    settings.allow_env = tuple(allow_env)
    settings.timeout = timeout
    settings.memory_mb = memory_limit
    serve(settings)
