"""`urdftool convert MODEL.sdf [-o OUT.urdf] [--model NAME]`: SDFormat to URDF;
`urdftool convert ROBOT --to mjcf [-o OUT.xml]`: URDF, xacro or SDF to MJCF, verified
(``urdftool.cli.compare.convert_to_mjcf``)."""

from __future__ import annotations

import click

from urdftool.cli import (
    load_options,
    package_option,
    print_finding,
    print_json,
    split_args,
    untrusted_options,
)


@click.command("convert")
@click.argument("inputs", nargs=-1, required=True, metavar="MODEL.sdf | ROBOT [NAME:=VALUE...]")
@click.option("-o", "--output", type=click.Path(dir_okay=False),
              help="Write the URDF (MJCF) here, not to stdout (never over the input).")
@click.option("--to", "target", type=click.Choice(["urdf", "mjcf"]), default="urdf",
              show_default=True,
              help="urdf: an SDF model as URDF; mjcf: a URDF, xacro or SDF robot as MuJoCo MJCF, "
                   "read back by MuJoCo and compared with its input.")
@click.option("--model", "model", metavar="NAME",
              help="The model to convert, when the file (a world) has several.")
@click.option("--model-path", "model_paths", multiple=True, metavar="DIR",
              help="Where model:// includes and meshes are found (also GZ_SIM_RESOURCE_PATH, "
                   "IGN_GAZEBO_RESOURCE_PATH, GAZEBO_MODEL_PATH). Repeatable.")
@click.option("--package-uri", "package_uris", multiple=True, metavar="[MODEL=]URI",
              help="Rewrite model://MODEL/... meshes to URI/... (e.g. package://my_robot/models;"
                   " without MODEL=, model://M/... becomes URI/M/...). Repeatable.")
@click.option("--no-cut", is_flag=True,
              help="Refuse a model with a kinematic loop instead of cutting one joint.")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text",
              show_default=True, help="text: the URDF; json: the URDF and the diagnostics.")
@package_option
@untrusted_options
@click.pass_context
def command(ctx, inputs, output, target, model, model_paths, package_uris, no_cut, fmt,
            packages):
    """Convert an SDFormat model (1.4 to 1.11) to URDF, or a robot to MJCF (--to mjcf).

    Frames are resolved through the SDF pose graph; what URDF cannot express is said on stderr
    (the sdf rules) and written in its nearest safe form. Exit code 0: converted; 1: converted
    with errors in the SDF, or refused (--no-cut and a loop); 2: could not convert.
    --to mjcf: exit 0 when MuJoCo's reading of the MJCF matches the input ("verified"), 1 when
    something was lost (listed).
    """
    from pathlib import Path

    from urdftool.display import xml_guard
    from urdftool.errors import ToolError
    from urdftool.output import write_output
    from urdftool.report import SEVERITIES
    from urdftool.rules import load_all
    from urdftool.sdf import ConvertOptions, LoopRefused, ModelChoiceError, convert_guarded, to_text
    from urdftool.source import Source, detect_kind, read_text

    paths, xacro_args = split_args(inputs)
    if target == "mjcf":
        if len(paths) != 1:
            raise ToolError("convert --to mjcf takes exactly one ROBOT")
        from urdftool.cli.compare import convert_to_mjcf

        convert_to_mjcf(ctx, paths[0], output, fmt, packages, xacro_args)
        return
    if len(paths) != 1:
        raise ToolError("convert takes exactly one MODEL.sdf")
    path = Path(paths[0])
    from urdftool import loader

    load = load_options(packages, {})
    load.sdf_model_paths = list(model_paths)  # the operator's: roots of the run
    load.roots = loader.run_roots([path], load)
    # refused before asking whether it exists: a committed link out answers the same either way
    loader.check_input(path, load.roots)
    if not path.exists():
        raise ToolError(f"{path}: no such file")
    resolver = loader.resolver_for(path, load)  # includes and meshes inside the run's roots
    if load.untrusted:
        from urdftool import sandbox

        sandbox.use_for_meshes(load.roots, load)
    text = read_text(path)
    if detect_kind(path, text) != "sdf":
        raise ToolError(f"{path}: not an SDFormat file (no <sdf> element)")
    output_dir = Path(output).resolve().parent if output and output != "-" else path.resolve().parent
    options = ConvertOptions(model=model, model_paths=list(model_paths),
                             package_uris=list(package_uris), output_dir=output_dir,
                             cut_loops=not no_cut, require_choice=True)
    refused = None
    if load.untrusted and sandbox.available():  # read and converted in the sandboxed reader
        source, refused, choice = sandbox.convert_in_child(path, options, load, resolver)
        if choice is not None:
            raise ToolError(f"{path}: {choice}")
    else:
        source = Source(str(path), "sdf", texts={str(path): text}, resolver=resolver)
        try:
            convert_guarded(source, path, text, options)
        except ModelChoiceError as exc:
            raise ToolError(f"{path}: {exc}") from None
        except LoopRefused as exc:
            refused = str(exc)
    registry = load_all()
    problems = []
    for rule_id, finding in source.problems:
        rule = registry.get(rule_id)
        severity = finding.severity or (rule.severity if rule else "error")
        problems.append((rule_id, severity if severity in SEVERITIES else "error", finding))
    if refused:
        problems.append(("sdf.kinematic-loop", "error", None))
    errors = [p for p in problems if p[1] == "error"]
    urdf = None
    if source.root is not None and refused is None:
        header = (f" Converted by urdftool from {path.name}"
                  + (f", model '{model}'" if model else "") + ". ")
        from lxml import etree

        source.root.insert(0, etree.Comment(header))
        urdf = to_text(source.root)
    # output proportional to findings (issue 21), as check's: at most LISTED_PER_RULE findings
    # of one rule in one file on stderr, MACHINE_PER_RULE in JSON, the rest counted
    from urdftool.display import clip
    from urdftool.report import LISTED_PER_RULE, MACHINE_PER_RULE

    listed, omitted = _capped(problems, MACHINE_PER_RULE if fmt == "json" else LISTED_PER_RULE,
                              str(path))
    if fmt == "json":
        data = {
            "path": str(path), "urdf": urdf, "refused": refused,
            "diagnostics": [{"rule": r, "severity": s,
                             "message": clip(f.message) if f else refused,
                             "path": f.loc.path if f and f.loc else str(path),
                             "line": f.loc.line if f and f.loc else None,
                             "column": f.loc.column if f and f.loc else None,
                             "hint": clip(f.hint) if f else None} for r, s, f in listed]}
        if omitted:
            data["omitted"] = omitted
        print_json(data)
    else:
        for rule_id, severity, finding in listed:
            loc = finding.loc if finding is not None else None
            print_finding(loc.path if loc else path, loc.line if loc else None,
                          loc.column if loc else None, severity, rule_id,
                          finding.message if finding is not None else refused,
                          finding.hint if finding is not None else None, err=True)
        if omitted:
            click.echo(f"{sum(omitted.values())} more finding(s) not listed (at most "
                       f"{LISTED_PER_RULE} per rule and file; --format json lists more): "
                       + ", ".join(f"{rule} {count}" for rule, count in omitted.items()),
                       err=True)
        if urdf is not None:
            if output in (None, "-"):  # a CI log: no line a runner executes, same XML
                urdf = xml_guard(urdf)
            write_output(urdf, output, inputs=[str(path), *source.texts], offer_in_place=False)
    ctx.exit(1 if errors or urdf is None else 0)


def _capped(problems: list, per_rule: int, path: str) -> tuple[list, dict[str, int]]:
    """(the problems listed, rule -> how many more of it are not): at most ``per_rule`` of one
    rule in one file."""
    counts: dict[tuple[str, str], int] = {}
    listed, omitted = [], {}
    for problem in problems:
        rule_id, _, finding = problem
        key = (rule_id, finding.loc.path if finding is not None and finding.loc else path)
        counts[key] = counts.get(key, 0) + 1
        if counts[key] > per_rule:
            omitted[rule_id] = omitted.get(rule_id, 0) + 1
        else:
            listed.append(problem)
    return listed, omitted
