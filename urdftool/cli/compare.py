"""`urdftool compare A B [NAME:=VALUE...]`: two descriptions of one robot (URDF, xacro, SDF,
MJCF) compared body by body over sampled configurations (issue 32)."""

from __future__ import annotations

import click

from urdftool.cli import (
    echo,
    format_option,
    load_options,
    load_robot,
    package_option,
    print_json,
    split_args,
    untrusted_options,
)


def load_tree(path: str, packages: tuple[str, ...] = (), xacro_args: dict | None = None):
    """The neutral body tree of one description: MJCF compiled by MuJoCo (after its files are
    checked against the run's roots), anything else through urdftool's loader and model."""
    from pathlib import Path

    from urdftool import loader
    from urdftool.bodies import tree_of_mujoco, tree_of_robot
    from urdftool.errors import ToolError
    from urdftool.files import read_regular
    from urdftool.mjcf.reader import compile_model, is_mjcf

    options = load_options(packages, xacro_args or {})
    roots = loader.run_roots([path], options)
    loader.check_input(path, roots)  # refused before asking whether it exists
    try:
        head = read_regular(path)[:8192].decode("utf-8", errors="replace")
    except FileNotFoundError:
        raise ToolError(f"{path}: no such file") from None
    except OSError as exc:
        raise ToolError(f"{path}: {exc.strerror or exc}") from None
    if is_mjcf(head):
        model, files, locs = compile_model(Path(path), roots)
        loader.note_read(files)
        return tree_of_mujoco(model, path, locs)
    robot = load_robot(path, packages, xacro_args)
    return tree_of_robot(robot, path)


def result_data(result) -> dict:
    return {"verdict": result.verdict, "samples": result.samples,
            "largest_error": result.largest, "matched_bodies": result.matched,
            "differences": [d.as_dict() for d in result.differences], "notes": result.notes}


def print_differences(result, err: bool = False) -> None:
    from urdftool.display import clean

    for d in result.differences:
        where = f"{d.loc.path}:{d.loc.line}: " if d.loc is not None else ""
        other = f" (B: {d.other})" if d.other is not None and d.other != d.name else ""
        error = f" [max error {d.max_error:.6g}]" if d.max_error is not None else ""
        echo(clean(f"{where}{d.kind} {d.name}{other}: {d.message}{error}"), err=err)


def print_notes(result, err: bool = False) -> None:
    from urdftool.display import clean

    for note in result.notes:
        echo(clean(f"note: {note}"), err=err)


@click.command("compare")
@click.argument("inputs", nargs=-1, required=True, metavar="A B [NAME:=VALUE...]")
@click.option("--samples", type=click.IntRange(0, 100000), default=20, show_default=True,
              help="Random configurations within A's limits, besides the zero configuration.")
@click.option("--tolerance", type=click.FloatRange(0.0), default=1e-5, show_default=True,
              help="Largest error that is no difference (metres, radians, or relative).")
@format_option("text", "json")
@package_option
@untrusted_options
@click.pass_context
def command(ctx, inputs, samples, tolerance, fmt, packages):
    """Compare two descriptions of one robot, body by body.

    A and B are URDF, xacro, SDF or MJCF (read by MuJoCo itself). Bodies are matched by name,
    then by joint name, then by place; fixed links are lumped as the other side lumps them.
    Exit code 0: equivalent; 1: different; 2: a description could not be read.
    """
    from urdftool.compare import compare
    from urdftool.errors import ToolError
    from urdftool.mjcf.reader import WARNINGS

    WARNINGS.clear()  # (a process may run several commands: tests)
    paths, xacro_args = split_args(inputs)
    if len(paths) != 2:
        raise ToolError("compare takes two descriptions: A B")
    tree_a = load_tree(paths[0], packages, xacro_args)
    tree_b = load_tree(paths[1], packages, xacro_args)
    result = compare(tree_a, tree_b, samples=samples, tolerance=tolerance)
    if fmt == "json":
        print_json(result_data(result))
    else:
        print_differences(result)
        from urdftool.display import clean

        if result.differences:
            echo(f"different: {len(result.differences)} difference(s) between "
                 f"{clean(paths[0])} and {clean(paths[1])} ({result.matched} bodies matched, "
                 f"{samples} sampled configurations)")
        else:
            echo(f"equivalent: {result.matched} bodies matched, largest error "
                 f"{result.largest:.3g} over {samples + 1} configurations")
        print_notes(result)
        for warning in dict.fromkeys(WARNINGS):
            echo(clean(f"note: MuJoCo warned: {warning}"))
    ctx.exit(1 if result.differences else 0)


def convert_to_mjcf(ctx, path: str, output: str | None, fmt: str, packages, xacro_args: dict,
                    samples: int = 20, tolerance: float = 1e-5) -> None:
    """`urdftool convert ROBOT --to mjcf [-o OUT.xml]`: the MJCF written, then read back by
    MuJoCo and compared with the input: "verified" with the largest error, or what was lost
    (exit 1)."""
    from pathlib import Path

    from urdftool.bodies import tree_of_mujoco, tree_of_robot
    from urdftool.compare import compare
    from urdftool.display import clean, xml_guard
    from urdftool.errors import require
    from urdftool.mjcf.export import export
    from urdftool.mjcf.reader import WARNINGS, compiled
    from urdftool.output import check_target, write_file, write_output

    mujoco = require("mujoco", "mjcf")
    WARNINGS.clear()
    robot = load_robot(path, packages, xacro_args)
    tree_a = tree_of_robot(robot, path)
    out = Path(output) if output not in (None, "-") else None
    if out is not None:
        check_target(out, inputs=[path])  # refused before any work
    result = export(robot, tree_a, out)
    for mesh_path, data in result.meshes.items():
        write_file(mesh_path, data, inputs=[path], make_dirs=True)
    if out is not None:
        write_output(result.text, output, inputs=[path], offer_in_place=False)
    elif fmt != "json":
        write_output(xml_guard(result.text), None)
    refused = comparison = None
    try:
        model = compiled(mujoco, out, result.text)
    except (ValueError, RuntimeError) as exc:
        refused = " ".join(str(exc).split())
    else:
        comparison = compare(tree_a, tree_of_mujoco(model, str(out or "<stdout>")),
                             samples=samples, tolerance=tolerance)
    verified = refused is None and not comparison.differences and not result.lost
    if fmt == "json":
        data = {"output": str(out) if out is not None else None,
                "mjcf": result.text if out is None else None, "verified": verified,
                "refused": refused, "lost": result.lost, "notes": result.notes,
                "meshes": sorted(result.meshes),
                "comparison": result_data(comparison) if comparison is not None else None}
        print_json(data)
    else:
        for item in result.lost:
            echo(clean(f"lost: {item}"), err=True)
        if refused is not None:
            echo(clean(f"urdftool: MuJoCo cannot load the MJCF written: {refused}"), err=True)
        else:
            print_differences(comparison, err=True)
            where = clean(str(out)) if out is not None else "the MJCF"
            if verified:
                echo(f"verified: {where} has the bodies, joints, limits, masses and inertias of "
                     f"{clean(path)} (largest error {comparison.largest:.3g} over "
                     f"{samples + 1} configurations)", err=True)
            else:
                echo(f"not verified: {where} differs from {clean(path)} in "
                     f"{len(comparison.differences) + len(result.lost)} way(s)", err=True)
        for note in result.notes:
            echo(clean(f"note: {note}"), err=True)
        for warning in dict.fromkeys(WARNINGS):
            echo(clean(f"note: MuJoCo warned: {warning}"), err=True)
    ctx.exit(0 if verified else 1)
