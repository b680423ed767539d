"""SDFormat input: read an SDF file (1.4 to 1.11), convert the chosen model to a URDF document
with every element mapped back to the SDF line it came from, and report ``sdf.*`` problems.

``load_sdf`` is what ``urdftool.source.load`` calls for SDF input (so every URDF rule runs on
the converted model and reports at SDF lines); ``convert_file`` is ``urdftool convert``.
No numpy here: ``check`` on an SDF file must start fast.
"""

from __future__ import annotations

from pathlib import Path

from urdftool.findings import Finding, Loc
from urdftool.sdf.builder import (
    Builder,
    ConvertOptions,
    LoopRefused,
    ModelChoiceError,
    to_text,
)
from urdftool.sdf.reader import Reader

__all__ = ["ConvertOptions", "LoopRefused", "ModelChoiceError", "convert_source", "load_sdf",
           "to_text"]


def convert_source(source, path: Path, text: str, options: ConvertOptions):
    """Read the SDF text of ``source`` and set ``source.root`` to the converted URDF.

    Raises ModelChoiceError (no model, or an ambiguous/missing choice when
    ``options.require_choice``) and LoopRefused (``cut_loops`` off and a loop found).
    """
    reader = Reader(source, options.model_paths)
    doc = reader.read_root(path, text)
    if doc is None or doc.root.tag != "sdf":
        if doc is not None:
            raise ModelChoiceError("the file is not SDFormat (its root is not <sdf>)")
        raise ModelChoiceError("the file cannot be parsed")
    reader.check_schema(doc.root)
    candidates = reader.models_in(doc)
    if not candidates:
        where = "the world" if doc.root.find("world") is not None else "the file"
        reader.report("sdf.no-model", f"{where} has no <model> to convert", doc.root,
                      hint="an SDF robot is a <model> with links and joints")
        raise ModelChoiceError(f"{where} has no <model>")
    names = [name for _, name in candidates]
    _same_names(reader, candidates)
    if options.model is not None:
        chosen = [c for c in candidates if c[1] == options.model]
        if not chosen:
            raise ModelChoiceError(f"no model named '{options.model}' (models: "
                                   f"{', '.join(names)})")
        element, name = chosen[0]
    else:
        if len(candidates) > 1:
            if options.require_choice:
                raise ModelChoiceError(f"the file has {len(candidates)} models "
                                       f"({', '.join(names)}); choose one with --model NAME")
            reader.report("sdf.several-models",
                          f"the file has {len(candidates)} models ({', '.join(names)}); "
                          f"the URDF rules check the first, '{names[0]}'", candidates[1][0],
                          hint="choose another with --model NAME")
        element, name = candidates[0]
    if element.tag == "include":
        top = reader.read_include(element, None)
        if top is None:
            raise ModelChoiceError(f"the included model '{name}' cannot be read")
    else:
        top = reader.read_model(element, doc)
    builder = Builder(source, reader, top, options)
    source.root = builder.build()
    reader.finish()
    source.forget_xpaths()  # the paths named SDF elements: the SDF document can go
    return builder


def load_sdf(source, path: Path, text: str, options) -> None:
    """Called by ``urdftool.loader.load`` for SDF input. Never raises on bad input."""
    convert_options = ConvertOptions(
        model=getattr(options, "sdf_model", None),
        model_paths=list(getattr(options, "sdf_model_paths", None) or []),
    )
    try:
        convert_guarded(source, path, text, convert_options)
    except ModelChoiceError as exc:
        if not any(rule.startswith(("sdf.", "xml.")) and finding.severity in (None, "error")
                   for rule, finding in source.problems):
            source.add("sdf.no-model", Finding(str(exc), Loc(str(source.path), 1, 1)))
    except LoopRefused:  # pragma: no cover - check always cuts
        pass


def convert_guarded(source, path: Path, text: str, options: ConvertOptions):
    """``convert_source`` that never raises on bad input beyond its two refusals: a value
    the converter cannot take (a name with control characters, frames nested past Python's
    recursion) is an ``sdf.bad-value`` finding and no URDF (check and convert alike)."""
    try:
        return convert_source(source, path, text, options)
    except (ArithmeticError, ValueError, RecursionError) as exc:
        source.root = None
        source.add("sdf.bad-value", Finding(
            f"the model cannot be converted: {type(exc).__name__}: {exc}",
            Loc(str(source.path), 1, 1), hint="report this file to urdftool's developers"))
        return None


def _same_names(reader: Reader, candidates) -> None:
    """The models of a world need names of their own: one finding per model whose name an
    earlier one has (the same model included again without ``<name>``), at its ``<include>``
    (or ``<model>``) line, never inside the included file."""
    first: dict[str, object] = {}
    for element, name in candidates:
        if not name:
            continue
        if name not in first:
            first[name] = element
            continue
        number = 2
        while f"{name}_{number}" in first:
            number += 1
        first[f"{name}_{number}"] = element  # the next clash gets the next number
        earlier = reader.loc(first[name]).line
        if element.tag == "include":
            written = reader.text_of(element, "name")
            message = (f"this <include> names its model '{name}'"
                       + ("" if written else " (the included model's own name: the <include> "
                          "has no <name>)")
                       + f", as does the one at line {earlier}: Gazebo refuses a second model "
                       "of one name in a world")
            hint = f"give each <include> a name of its own: <name>{name}_{number}</name>"
        else:
            message = (f"model '{name}' has the name of the model at line {earlier}: Gazebo "
                       "refuses a second model of one name in a world")
            hint = f'rename it <model name="{name}_{number}">'
        reader.report("sdf.duplicate-name", message, element, hint=hint, severity="warning")

