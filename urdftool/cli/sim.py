"""`urdftool sim PATH...`: a short PyBullet physics smoke test per model, with a verdict."""

from __future__ import annotations

import math
import time

import click

from urdftool.cli import (
    PathsCommand,
    Progress,
    format_option,
    load_options,
    package_option,
    parse_packages,
    print_finding,
    print_json,
    print_table,
    shown,
    split_args,
    untrusted_options,
)


def _size(value: str) -> tuple[int, int]:
    from urdftool.errors import ToolError

    width, sep, height = value.lower().partition("x")
    try:
        size = (int(width), int(height))
    except ValueError:
        size = (0, 0)
    if not sep or not (16 <= size[0] <= 4096 and 16 <= size[1] <= 4096):
        raise ToolError(f"--size expects WIDTHxHEIGHT (16..4096 pixels), got {value!r}")
    return size


def _pairs(values: tuple[str, ...]) -> tuple[tuple[str, str], ...]:
    from urdftool.errors import ToolError

    pairs = []
    for value in values:
        for item in value.split(","):
            a, sep, b = item.strip().partition(":")
            if not sep or not a or not b:
                raise ToolError(f"--allow-collision expects LINK_A:LINK_B, got {item!r}")
            pairs.append((a, b))
    return tuple(pairs)


@click.command("sim", cls=PathsCommand)
@click.argument("inputs", nargs=-1, required=True, metavar="PATH... [NAME:=VALUE...]")
@click.option("--duration", type=click.FloatRange(min=0, min_open=True, max=600), default=1.0,
              show_default=True, help="Simulated seconds.")
@click.option("--rate", type=click.FloatRange(min=10, max=10000), default=240.0,
              show_default=True, help="Simulation steps per second.")
@click.option("--fixed-base/--free", "fixed_base", default=None,
              help="Fix the base in place, or let it fall (even when the root link is "
                   "'world'). Default: fixed when the root link is 'world'.")
@click.option("--allow-collision", multiple=True, metavar="A:B",
              help="Links A and B may overlap at the home pose (SRDF-style). Repeatable.")
@click.option("--srdf", type=click.Path(exists=True, dir_okay=False), metavar="FILE",
              help="Allow the pairs in this SRDF's <disable_collisions>. Default: NAME.srdf "
                   "beside the model or in a srdf/ folder next to it, if there is one.")
@click.option("--no-srdf", is_flag=True, help="Do not look for an SRDF.")
@click.option("--strict-collision/--no-strict-collision", default=True, show_default=True,
              help="Fail on overlaps between a link and its ancestors two or more joints up "
                   "(MoveIt checks those pairs unless the SRDF disables them); with "
                   "--no-strict-collision they are reported but not counted, as PyBullet's "
                   "URDF_USE_SELF_COLLISION_EXCLUDE_ALL_PARENTS ignores them.")
@click.option("--repaired", is_flag=True,
              help="Simulate the XML as urdftool repairs it in memory, past the XML errors "
                   "that keep PyBullet from loading the file as written.")
@click.option("--render", type=click.Path(), metavar="PNG",
              help="Write a picture of each model at rest (and NAME-collision.png of its "
                   "collision geometry). Several models, or a directory: one picture per model.")
@click.option("--size", default="640x480", show_default=True, metavar="WxH",
              help="Picture size in pixels.")
@click.option("-j", "--jobs", type=click.IntRange(min=1, max=256), default=None,
              help="Models simulated in parallel processes (default: by the amount of work, "
                   "at most one per CPU, as `check`).")
@click.option("--model", "sdf_model", metavar="NAME",
              help="SDF input: the model of a world to simulate (default: the first).")
@click.option("--model-path", "model_paths", multiple=True, metavar="DIR",
              help="SDF input: where model:// includes and meshes are found. Repeatable.")
@format_option("text", "json")
@package_option
@untrusted_options
def command(inputs, duration, rate, fixed_base, allow_collision, srdf, no_srdf,
            strict_collision, repaired, render, size, jobs, sdf_model, model_paths, fmt,
            packages):
    """Drop each model into PyBullet (headless) and judge what happens.

    \b
    Setup: DIRECT mode, 240 Hz, gravity, a ground plane, inertia from the file; the base fixed
    when the root link is 'world' (or zero-mass), otherwise dropped from just above its lowest
    point; joints held at the home pose (zero clamped into the limits) by position control
    with the URDF's effort limits.

    \b
    Checks (each a sim.* result with its numbers): load, mass, self-collision (at the home
    pose), nan, explosion, joint-limits, hold (the home pose, with the joints that saturate
    their effort), settle, sink and drift (free models only).
    Exit code 0: every model passed; 1: a check failed or a model did not load; 2: could not
    run.
    """
    from urdftool.errors import ToolError
    from urdftool.sim import SimOptions
    from urdftool.sim.runner import simulate

    paths, xacro_args = split_args(inputs)
    if not paths:
        raise ToolError("sim needs at least one PATH")
    options = SimOptions(duration=duration, rate=rate, fixed_base=fixed_base,
                         allow_collision=_pairs(allow_collision),
                         srdf=False if no_srdf else srdf, strict_collision=strict_collision,
                         repaired=repaired, render=render,
                         size=_size(size), jobs=jobs, packages=parse_packages(packages),
                         xacro_args=xacro_args, sdf_model=sdf_model,
                         sdf_model_paths=tuple(model_paths))
    load = load_options(packages, xacro_args)
    options.untrusted, options.allow_env = load.untrusted, load.allow_env
    options.timeout, options.memory_mb = load.timeout, load.memory_mb
    started = time.perf_counter()
    with Progress("simulating") as progress:
        results = simulate(paths, options, progress.update)
    wall = time.perf_counter() - started
    if fmt == "json":
        print_json(_finite(report_json(results, options, wall)))
    else:
        print_text(results, wall)
    failed = any(r.verdict == "fail" for r in results)
    raise click.exceptions.Exit(1 if failed else 0)


def _finite(value):
    """NaN and infinities (a model whose state blew up) as null: JSON has no such numbers."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    return value


def report_json(results, options, wall: float) -> dict:
    from urdftool import __version__

    return {
        "tool": "urdftool", "version": __version__, "command": "sim",
        "settings": {"duration_s": options.duration, "rate_hz": options.rate,
                     "fixed_base": options.fixed_base, "jobs": options.jobs,
                     "allow_collision": [list(p) for p in options.allow_collision],
                     "thresholds": vars(options.thresholds)},
        "models": [r.to_json() for r in results],
        "summary": {"models": len(results),
                    "passed": sum(r.verdict == "pass" for r in results),
                    "failed": sum(r.verdict == "fail" for r in results),
                    "skipped": sum(r.verdict == "skip" for r in results),
                    "wall_s": wall},
    }


def print_text(results, wall: float) -> None:
    from rich.table import Table

    from urdftool.cli import stdout_console

    console = stdout_console()
    table = Table(show_edge=False, pad_edge=False, header_style="bold")
    table.add_column("model")
    table.add_column("verdict")
    table.add_column("failed checks")
    table.add_column("time", justify="right")
    table.add_column("real-time", justify="right")
    for result in results:
        name = shown(result.path)
        if result.robot and result.robot != result.path.rsplit("/", 1)[-1].split(".")[0]:
            name += f" [dim]({shown(result.robot)})[/]"
        verdict = {"pass": "[green]pass[/]", "fail": "[bold red]FAIL[/]",
                   "skip": "[yellow]not simulated[/]"}[result.verdict]
        failed = ", ".join(f"[red]{shown(c.check.removeprefix('sim.'))}[/]"
                           for c in result.failures())
        timing = result.timing
        taken = f"{timing.get('total', 0):.2f} s"
        if "load" in timing:
            taken += f" [dim](load {timing['load']:.2f})[/]"
        factor = f"{result.real_time_factor:.0f}x" if result.real_time_factor else ""
        table.add_row(name, verdict, failed, taken, factor)
    print_table(console, table)
    for result in results:
        if result.verdict == "skip":
            console.print()
            console.print(f"[bold]{shown(result.path)}[/]: "
                          f"{shown(result.checks[0].message)}")
            continue
        if result.verdict != "fail" and not result.images:
            continue
        console.print()
        head = f"[bold]{shown(result.path)}[/]"
        if result.anchored is not None:
            head += " [dim]" + (f"anchored: {shown(result.anchor_reason or '')}"
                                if result.anchored else "free, dropped onto the ground") + "[/]"
        if result.real_time_factor:
            head += f" [dim]real-time factor {result.real_time_factor:.0f}x[/]"
        console.print(head)
        for check in result.failures():
            print_finding(result.path, None, None, "error", check.check, check.message)
        for note in result.notes:
            console.print(f"  [dim]note: {shown(note)}[/]")
        for image in result.images:
            console.print(f"  picture: {shown(image)}")
    passed = sum(r.verdict == "pass" for r in results)
    failed = sum(r.verdict == "fail" for r in results)
    skipped = sum(r.verdict == "skip" for r in results)
    console.print()
    console.print(f"{len(results)} model(s): [green]{passed} passed[/], "
                  f"{'[red]' if failed else ''}{failed} failed{'[/]' if failed else ''}"
                  + (f", {skipped} not simulated" if skipped else "")
                  + f" in {wall:.2f} s")
