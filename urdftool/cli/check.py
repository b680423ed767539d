"""`urdftool check PATH...`: lint files and directories."""

from __future__ import annotations

import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import NamedTuple

import click

from urdftool.cli import (
    PathsCommand,
    _colour,
    color_option,
    format_option,
    load_options,
    package_option,
    split_args,
    untrusted_options,
)


# -- the report formats: --format/--output-format and --extra-output FORMAT:FILE read this one
# table (issue 33: a format added here works in all three). name -> (render, shows_edits):
# render(report, how) -> the text; shows_edits: the format carries the edits of unsafe fixes
# (text and GitHub annotations show a fix's hint only: those edits are not derived for them).
class _How(NamedTuple):
    show_info: bool
    colour: bool
    quiet: bool
    annotate: set[str] | None  # github: annotate only these files (see format_github)
    strict: bool  # junit: warnings are failures too


def _text(report, how: _How) -> str:
    from urdftool.report import render_text

    return render_text(report, show_info=how.show_info, colour=how.colour, summary=not how.quiet)


def _json(report, how: _How) -> str:
    from urdftool.report import format_json

    return format_json(report) + "\n"


def _sarif(report, how: _How) -> str:
    from urdftool.report import format_sarif
    from urdftool.rules import load_all

    return format_sarif(report, load_all()) + "\n"


def _github(report, how: _How) -> str:
    from urdftool.report import format_github

    text = format_github(report, how.annotate, summary=not how.quiet)
    return text + ("\n" if text else "")


def _markdown(report, how: _How) -> str:
    from urdftool.report import format_markdown

    return format_markdown(report, show_info=how.show_info)


def _junit(report, how: _How) -> str:
    from urdftool.report import format_junit

    return format_junit(report, strict=how.strict) + "\n"


FORMATS: dict[str, tuple[Callable[[object, _How], str], bool]] = {
    "text": (_text, False), "json": (_json, True), "sarif": (_sarif, True),
    "github": (_github, False), "junit": (_junit, False), "markdown": (_markdown, False)}


@click.command("check", cls=PathsCommand)
@click.argument("inputs", nargs=-1, metavar="[PATH...] [NAME:=VALUE...]")
@format_option(*FORMATS)
@color_option
@click.option("--config", "config_file", type=click.Path(dir_okay=False), metavar="FILE",
              help="The configuration (urdftool.toml, or a pyproject.toml's [tool.urdftool]) "
                   "for every file of the run, instead of the nearest one above each.")
@package_option
@untrusted_options
@click.option("--strict", is_flag=True, default=None, help="Warnings fail the run too (exit 1).")
@click.option("--select", multiple=True, metavar="RULE|FAMILY",
              help="Only these rules or families (repeatable, or comma-separated).")
@click.option("--ignore", multiple=True, metavar="RULE|FAMILY",
              help="Skip these rules or families (repeatable, or comma-separated).")
@click.option("--fix", is_flag=True,
              help="Apply the safe fixes of the findings (needs -o FILE or --in-place); the "
                   "report is then what remains.")
@click.option("--unsafe-fixes", is_flag=True,
              help="With --fix or --diff: also the fixes that change values a person chose "
                   "(derived inertias, swapped limits, mimic offsets...).")
@click.option("--diff", is_flag=True,
              help="Print the unified diff of what --fix would change and write nothing "
                   "(exit 1 when something would change).")
@click.option("-o", "--output", type=click.Path(dir_okay=False), metavar="FILE",
              help="Write the report to FILE (any --format), not stdout. With --fix: where "
                   "the fixed file goes (a single-file input only; the report then goes to "
                   "stdout or --output-file).")
@click.option("--output-file", type=click.Path(dir_okay=False), metavar="FILE",
              help="Write the report to FILE, also with --fix.")
@click.option("--extra-output", "extra_outputs", multiple=True, metavar="FORMAT:FILE",
              help=f"Also write the report in FORMAT ({', '.join(FORMATS)}) to FILE, from "
                   "the same run (e.g. --format github --extra-output sarif:urdftool.sarif). "
                   "Repeatable.")
@click.option("--show-info", is_flag=True,
              help="Text: list infos too (they are always counted, and always in JSON and "
                   "SARIF).")
@click.option("--statistics", is_flag=True,
              help="Print the number of findings per rule and severity instead of the "
                   "findings (text or --format json).")
@click.option("--exit-zero", is_flag=True,
              help="Exit 0 even when findings fail the run (2 still means could not check).")
@click.option("-q", "--quiet", is_flag=True,
              help="Print the findings only: no summary line, no progress.")
@click.option("--in-place", is_flag=True,
              help="With --fix: rewrite the files themselves (atomically), included files too; "
                   "every file changed is listed.")
@click.option("--model", "sdf_model", metavar="NAME",
              help="SDF input: the model of a world to check (default: the first).")
@click.option("--model-path", "model_paths", multiple=True, metavar="DIR",
              help="SDF input: where model:// includes and meshes are found. Repeatable.")
@click.option("--no-cache", is_flag=True,
              help="Parse every mesh again: neither read nor write the mesh-summary cache "
                   "($URDFTOOL_CACHE_DIR, else ~/.cache/urdftool).")
@click.option("-j", "--jobs", type=click.IntRange(min=1), metavar="N",
              help="Check files in N processes (default: the CPUs available; 1: in this "
                   "process).")
@click.option("--changed", is_flag=True,
              help="The PATHs are changed files (pre-commit, pull requests): check every entry "
                   "of their packages that reads one of them; report the findings in them "
                   "(--format github annotates only them). "
                   "Every argument after --changed is a file name (never an option).")
@click.option("--baseline", "baseline", type=click.Path(dir_okay=False), metavar="FILE",
              help="Fail only on findings not recorded in FILE (see --write-baseline); say how "
                   "many recorded ones are gone. Default: the configuration's `baseline`.")
@click.option("--write-baseline", "write_baseline", type=click.Path(dir_okay=False),
              metavar="FILE", help="Record today's findings in FILE and exit 0.")
@click.option("--exclude", "exclude", multiple=True, metavar="PATTERN",
              help="Files and folders not to check in the directories given (glob, as ruff's; "
                   "repeatable or comma-separated). Replaces the configuration's `exclude` and "
                   "the defaults (hidden folders, build, install, log).")
@click.option("--extend-exclude", "extend_exclude", multiple=True, metavar="PATTERN",
              help="Like --exclude, but added to the excluded patterns.")
@click.option("--respect-gitignore/--no-respect-gitignore", "respect_gitignore", default=None,
              help="Skip what .gitignore files ignore (default: yes, or the configuration's "
                   "`respect-gitignore`). Folders with COLCON_IGNORE, AMENT_IGNORE or "
                   "CATKIN_IGNORE are always skipped.")
@click.option("--robot", "robot", type=click.Path(dir_okay=False), metavar="FILE",
              help="The robot (URDF or xacro) the SRDFs given describe, in place of what their "
                   "MoveIt configuration (.setup_assistant) or urdftool.toml (srdf) names.")
@click.pass_context
def command(ctx, inputs, fmt, config_file, packages, strict, select, ignore, fix, unsafe_fixes,
            diff, output, output_file, extra_outputs,
            show_info, statistics, exit_zero, quiet, in_place, sdf_model, model_paths, no_cache,
            jobs, changed, baseline, write_baseline, exclude, extend_exclude, respect_gitignore,
            robot):
    """Lint robot descriptions (*.urdf, *.xacro, *.urdf.xacro, *.sdf); all findings in one pass.
    Without PATH: the current directory.

    Exit code 0: no errors (with --strict: no warnings either); 1: findings; 2: could not check.
    """
    from urdftool import cache
    from urdftool.check import CheckOptions
    from urdftool.config import check_rule_ids, load_config
    from urdftool.errors import ToolError

    cache.ENABLED = not no_cache
    paths, xacro_args = split_args(inputs)
    if not paths:
        if changed:  # a hook given no files: nothing changed
            ctx.exit(0)
        paths = ["."]
    if config_file:
        from urdftool.config import load_config_file

        config = load_config_file(Path(config_file))
    else:
        config = load_config(Path(paths[0]))

    def split(values):
        return [part.strip() for value in values for part in value.split(",") if part.strip()]

    check_rule_ids(split(select), "--select")
    check_rule_ids(split(ignore), "--ignore")
    options = CheckOptions(load_options(packages, xacro_args), split(select), split(ignore),
                           config, ctx.obj.get("debug", False))
    options.changed = changed
    options.config_file = Path(config_file) if config_file else None
    options.load.sdf_model = sdf_model
    options.load.sdf_model_paths = list(model_paths)
    options.jobs = jobs
    options.robot = robot
    # text and GitHub annotations show a fix's hint, not its edits
    shows_edits = [FORMATS[fmt][1] and not statistics] + [
        FORMATS.get(value.split(":", 1)[0], (None, False))[1] for value in extra_outputs]
    options.unsafe_edits = bool(fix or diff) or any(shows_edits)
    from urdftool.package import Selection

    options.selection = Selection(split(exclude) if exclude else None, split(extend_exclude),
                                  respect_gitignore)
    if in_place and not fix:
        raise ToolError("--in-place goes with --fix")
    report_to = output_file or (None if fix else output)  # -o is the repaired file with --fix
    if output_file and output and not fix:
        raise ToolError("-o and --output-file both name the report: give one")
    if statistics and fmt not in ("text", "json"):
        raise ToolError(f"--statistics prints text or json, not {fmt}")
    if unsafe_fixes and not (fix or diff):
        raise ToolError("--unsafe-fixes goes with --fix or --diff")
    if diff and (output or output_file or in_place or extra_outputs):
        raise ToolError("--diff prints the changes and writes nothing: no -o, --output-file, "
                        "--extra-output or --in-place with it")
    extras = _extra_outputs(extra_outputs)
    # every file this run writes, refused now if it is a link or an input (nothing is checked)
    # and again once all is read (nothing is written unless every one of them may be)
    from urdftool.output import check_target

    targets = [t for t in (report_to, write_baseline, output if fix else None) if t and t != "-"]
    targets += [target for _, target in extras]
    for target in targets:
        check_target(target, paths, hint=" (use --in-place)" if fix and target == output else "")
    if fix or diff:
        report = _fix(paths, options, output, in_place, unsafe_fixes, diff, targets)
        if diff:
            ctx.exit(1 if report is None else 0)
    else:
        report = _run(paths, options, fmt, report_to, quiet, extras)
    for target in targets:
        check_target(target, paths)
    if write_baseline:
        from urdftool.baseline import write_baseline as write

        write(report, Path(write_baseline))
        click.echo(f"baseline: {len(report.diagnostics())} finding(s) recorded in "
                   f"{write_baseline}", err=True)
        ctx.exit(0)
    baseline = Path(baseline) if baseline else config.baseline
    if baseline is not None:
        from urdftool.baseline import apply_baseline

        apply_baseline(report, baseline)
    if not quiet:
        from urdftool.cli import echo
        from urdftool.display import clean

        for note in report.notes:
            echo(clean(note), err=True)
    from urdftool.report import format_statistics, summary_line
    from urdftool.rules import load_all

    colour = fmt == "text" and report_to in (None, "-") and _colour(sys.stdout)
    # changed files (a pull request's): GitHub annotations only on them, the rest in the log
    annotate = {os.path.realpath(p) for p in paths} if changed else None
    strict = strict if strict is not None else config.strict
    if statistics:
        text = format_statistics(report, fmt == "json", load_all())
        if fmt == "text" and not quiet:
            text += ("\n" if text else "") + summary_line(report, True, colour)
        text += "\n" if text else ""
    else:
        text = FORMATS[fmt][0](report, _How(show_info, colour,  # changed files no check reads:
                                            quiet or (changed and not report.files),  # silent
                                            annotate, strict))
    for target in targets:  # once more: the baseline compared with was read since
        check_target(target, paths)
    for extra_fmt, target in extras:
        _write(FORMATS[extra_fmt][0](report, _How(show_info, False, quiet, annotate, strict)),
               target, paths)
    _write(text, report_to, paths)
    if exit_zero:
        ctx.exit(0)
    ctx.exit(report.exit_code(strict))


def _extra_outputs(values) -> list[tuple[str, str]]:
    """``--extra-output FORMAT:FILE`` values as (format, file)."""
    from urdftool.errors import ToolError

    extras = []
    for value in values:
        fmt, sep, target = value.partition(":")
        if not sep or fmt not in FORMATS or not target:
            raise ToolError(f"--extra-output expects FORMAT:FILE with FORMAT one of "
                            f"{', '.join(FORMATS)}, got {value!r}")
        extras.append((fmt, target))
    return extras


def _run(paths, options, fmt: str, report_to: str | None, quiet: bool, extras=()):
    """check_paths with a progress display on a terminal; a file that cannot be read is still
    a SARIF document (its error a tool execution notification) before the exit code 2."""
    from urdftool.check import check_paths
    from urdftool.cli import Progress
    from urdftool.errors import NothingToCheck, ToolError
    from urdftool.report import Report

    try:
        with Progress("checking", enabled=not quiet) as progress:
            return check_paths(paths, options, progress=progress.update)
    except NothingToCheck as exc:  # ruff: a folder without Python files is not an error
        report = Report([], [f"{exc}: nothing to check"])
        report.seen = set()
        return report
    except ToolError as exc:
        sarif = [target for extra_fmt, target in extras if extra_fmt == "sarif"]
        if fmt == "sarif":
            sarif.append(report_to)
        if sarif:
            from urdftool.display import clean
            from urdftool.report import format_sarif

            for target in sarif:
                _write(format_sarif(None, tool_error=clean(exc)) + "\n", target, paths)
        raise


def _write(text: str, report_to: str | None, paths: list[str]) -> None:
    """The report on stdout, or written (atomically, never over an input) to ``report_to``."""
    from urdftool.output import write_output

    write_output(text, report_to, inputs=paths, offer_in_place=False)


def _fix(paths, options, output, in_place, unsafe, diff, targets=()):
    """--fix / --diff of one file: write (or show) the fixed files; the report of what remains
    (None for a --diff that changes something)."""
    from urdftool.display import clean
    from urdftool.errors import ToolError
    from urdftool.fix import encoded, unified_diff
    from urdftool.output import check_target, write_output

    single = len(paths) == 1 and not Path(paths[0]).is_dir() and not options.changed
    if output and in_place:
        raise ToolError("give -o OUT or --in-place, not both")
    if output and not single:
        raise ToolError("-o OUT is where one fixed file goes: for several files or a "
                        "directory use --in-place (or --diff to see the changes)")
    if not (diff or output or in_place):
        raise ToolError("--fix writes the fixed files: add --in-place (or -o OUT for one "
                        "file, or use --diff to see the changes)")
    # planned as check plans (one verdict): a named file's launch-file arguments and
    # configured entries, a fragment fixed without the rules that need its includer
    result, seen = _fix_many(paths, options, unsafe)
    changed = result.changed()
    remaining = len(_remaining(result, seen).diagnostics())
    summary = f"{result.fixed} {'would be fixed' if diff else 'fixed'}, {remaining} remaining"
    if diff:
        text = unified_diff(result)
        if text:
            click.echo(text, nl=False)
        click.echo(summary + ("" if changed else " (nothing to change)"), err=True)
        return None if changed else _remaining(result, seen)
    top = Path(paths[0]).resolve()
    others = [name for name in changed if Path(name).resolve() != top]
    if output:
        if others:
            raise ToolError("the fixes also change " + ", ".join(map(clean, others)) + ": with -o only a "
                            "single-file input is fixed (use --in-place, or --diff to see them)")
        name = next((n for n in result.texts if Path(n).resolve() == top), None)
        if name is None:
            raise ToolError(f"{paths[0]}: nothing was read")
        text, encoding = encoded(name, result.originals[name], result.texts[name])
        for target in targets:  # the report's files too: nothing written unless all may be
            check_target(target, list(result.originals),
                         hint=" (use --in-place)" if target == output else "")
        write_output(text, output, inputs=list(result.originals), encoding=encoding)
    else:
        for target in targets:
            check_target(target, list(result.originals))
        for name in changed:  # (each checked before the first is written)
            check_target(name, list(result.originals), may_replace=(name,))
        for name in changed:
            text, encoding = encoded(name, result.originals[name], result.texts[name])
            write_output(text, name, inputs=list(result.originals), in_place=True,
                         encoding=encoding)
            click.echo(f"fixed {clean(name)}", err=True)
    click.echo(summary, err=True)
    return _remaining(result, seen)


def _remaining(result, seen):
    """The report of what the fixes left (one file, or every check of several), whose findings
    are complete for the files ``seen`` (those of the run the fixes started from: a baseline's
    records of other files are not "gone")."""
    from urdftool.report import Report, merge_repeats

    remaining = result.remaining
    report = Report(merge_repeats(list(remaining)) if isinstance(remaining, list)
                    else [remaining])
    report.seen = seen
    return report


def _fix_many(paths, options, unsafe):
    """--fix / --diff over several files and directories (issue 23): the checks a run shows
    (entries with their arguments, lone fragments without the rules that need the includer's
    robot; with --changed, those that read a given file) are fixed one after the other, each
    reading the files the ones before fixed; with --changed only the given files change."""
    import copy

    from urdftool.check import check_paths, overlay_options, target_options
    from urdftool.fix import FixResult, fix_file
    from urdftool.package import ALONE_SKIPS, plan

    report = check_paths(paths, options)
    targets, given = plan(paths, options.changed, options.selection, options.config_file)
    by_path = {}
    for target in targets:
        by_path.setdefault((str(Path(target.path).resolve()), tuple(target.args.items())), target)
    originals: dict[str, str] = {}
    texts: dict[str, str] = {}
    fixed, remaining = 0, []
    for shown in report.files:
        if shown.role == "refused":  # not read (a launch file over its size limit): no fix
            remaining.append(shown)
            continue
        target = by_path.get((str(Path(shown.path).resolve()), tuple(shown.args.items())))
        these = copy.copy(options)
        these.load = overlay_options(target_options(options, target), texts)
        if shown.role == "fragment":  # checked alone: nothing that needs the includer
            these.ignore = [*options.ignore, *ALONE_SKIPS]
        result = fix_file(shown.path, these, unsafe)
        for name, text in result.texts.items():
            if given is not None and str(Path(name).resolve()) not in given:
                continue  # changed files mode: the others are not the commit's
            originals.setdefault(name, result.originals[name])
            texts[name] = text
        fixed += result.fixed
        remaining.append(result.remaining)
    return FixResult(originals, texts, fixed, remaining), report.seen
