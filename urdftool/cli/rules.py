"""`urdftool rules [RULE]`: the rule catalogue, generated from the rules' registrations."""

from __future__ import annotations

import json

import click

from urdftool.cli import format_option, stdout_console


@click.command("rules")
@click.argument("rule_id", required=False, metavar="[RULE|FAMILY]")
@format_option("text", "json")
def command(rule_id, fmt):
    """List every rule, or explain one rule (or family) with a failing and a passing example."""
    from urdftool.errors import ToolError
    from urdftool.rules import load_all

    registry = load_all()
    rules = list(registry.values())
    if rule_id:
        rules = [r for r in rules if r.id == rule_id or r.family == rule_id]
        if not rules:
            import difflib

            close = difflib.get_close_matches(rule_id, list(registry), n=3)
            raise ToolError(f"no rule {rule_id!r}" + (f"; did you mean {', '.join(close)}?"
                                                      if close else ""))
    if fmt == "json":
        click.echo(json.dumps([{"rule": r.id, "severity": r.severity, "summary": r.summary,
                                "doc": r.doc, "bad": r.bad, "good": r.good, "fix": r.fix} for r in rules],
                              indent=2))
        return
    console = stdout_console()
    if not rule_id:
        from rich.table import Table

        table = Table("rule", "severity", "fix", "what it finds")
        for r in rules:
            table.add_row(r.id, r.severity, r.fix or "", r.summary)
        console.print(table)
        console.print(f"{len(rules)} rules. 'urdftool rules RULE' explains one.")
        return
    from rich.syntax import Syntax

    for r in rules:
        fix = f", {r.fix} fix" if r.fix else ""
        console.print(f"[bold]── {r.id}[/] ({r.severity}{fix}) ──")  # not a rule: as wide as
        # the console, which is unbounded when piped
        console.print(r.summary)
        if r.doc:
            console.print("\n" + " ".join(r.doc.split()))
        if r.bad:
            console.print("\n[red]Triggers it:[/]")
            console.print(Syntax(r.bad, "xml", theme="ansi_dark"))
        if r.good:
            console.print("[green]Use instead:[/]")
            console.print(Syntax(r.good, "xml", theme="ansi_dark"))
