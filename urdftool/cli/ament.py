"""``urdftool-ament`` (also ``ament_urdftool``): ``urdftool check`` as an ament linter (issue 23),
with ``ament_xmllint``'s conventions: PATHs default to the current directory, ``--xunit-file``
writes the JUnit/xunit result ``colcon test-result`` reads (its test name ``<folder>.<file>``
from the file's name, as ament_xmllint names it), exit 0 clean / 1 findings / 2 could not check.

``main(argv)`` returns the exit code instead of exiting: an ``ament_python`` package's test is
``assert main(argv=[]) == 0`` (pytest shows what was printed when it fails), as with
``ament_xmllint.main``."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import click

from urdftool.cli import package_option, untrusted_options

SUFFIX = ".xunit.xml"


def _test_name(xunit_file: str) -> str:
    """``<folder>.<file>`` as ament_xmllint names its test (``.xunit.xml``/``.xml`` dropped)."""
    path = Path(xunit_file)
    name = path.name
    for suffix in (".xml", ".xunit"):
        name = name.removesuffix(suffix)
    return f"{path.parent.name}.{name}" if path.parent.name else name


def _xunit_target(value: str) -> str:
    """The --xunit-file as given, or a ToolError with the name it was probably meant to be."""
    from urdftool.errors import ToolError

    path = Path(value)
    if value.endswith(("/", "\\")) or path.is_dir():
        raise ToolError(f"--xunit-file {value}: a directory; did you mean "
                        f"{(path / ('urdftool' + SUFFIX)).as_posix()}?")
    if not path.name.endswith(".xml"):
        raise ToolError(f"--xunit-file {value}: colcon test-result reads *.xml files; did you "
                        f"mean {value}{SUFFIX}?")
    return value


@click.command("urdftool-ament", context_settings={"help_option_names": ["-h", "--help"]})
@click.argument("paths", nargs=-1, metavar="[PATH...]")
@click.option("--xunit-file", metavar="FILE",
              help="Write the result as JUnit/xunit XML (what colcon test-result reads).")
@click.option("--strict", is_flag=True, default=None, help="Warnings fail the test too.")
@click.option("--config", "config_file", type=click.Path(dir_okay=False), metavar="FILE",
              help="The configuration for every file (default: the nearest one above each).")
@package_option
@untrusted_options
def command(paths, xunit_file, strict, config_file, packages):
    """Check the robot descriptions under PATH (default: the current directory) as an ament
    linter test: the findings on stdout, the result in --xunit-file."""
    from urdftool.check import CheckOptions, check_paths
    from urdftool.cli import load_options
    from urdftool.config import load_config, load_config_file
    from urdftool.errors import NothingToCheck
    from urdftool.report import Report, format_junit, render_text

    start = time.monotonic()
    if xunit_file:
        _xunit_target(xunit_file)
    paths = list(paths) or ["."]
    config = load_config_file(Path(config_file)) if config_file else load_config(Path(paths[0]))
    options = CheckOptions(load_options(packages, {}), config=config)
    options.config_file = Path(config_file) if config_file else None
    try:
        report = check_paths(paths, options)
    except NothingToCheck as exc:
        report = Report([], [f"{exc}: nothing to check"])
    strict = strict if strict is not None else config.strict
    if config.baseline is not None:
        from urdftool.baseline import apply_baseline

        apply_baseline(report, config.baseline)
    from urdftool.cli import echo
    from urdftool.display import clean

    for note in report.notes:
        echo(clean(note), err=True)
    echo(render_text(report, summary=True), nl=False)
    if xunit_file:
        from urdftool.output import write_output

        Path(xunit_file).resolve().parent.mkdir(parents=True, exist_ok=True)
        write_output(format_junit(report, _test_name(xunit_file), strict,
                                  time.monotonic() - start) + "\n", xunit_file, inputs=paths)
    return report.exit_code(strict)


def main(argv: list[str] | None = None) -> int:
    """Run ``urdftool-ament`` with ``argv`` (default: the command line); return its exit code.
    Bad usage and tool errors: one line on stderr, 2."""
    from urdftool.cli import echo
    from urdftool.display import clean
    from urdftool.errors import ToolError

    try:
        code = command.main(args=argv if argv is not None else sys.argv[1:],
                            prog_name="urdftool-ament", standalone_mode=False)
    except click.exceptions.Exit as exc:
        return exc.exit_code
    except click.UsageError as exc:
        echo(f"urdftool-ament: {clean(exc.format_message())} (see 'urdftool-ament --help')",
             err=True)
        return 2
    except ToolError as exc:
        echo(f"urdftool-ament: {clean(exc)}", err=True)
        return 2
    return code if isinstance(code, int) else 0


def assert_clean(argv: list[str] | tuple[str, ...] = ()) -> None:
    """The pytest helper of an ``ament_python`` package (``test/test_urdftool.py``:
    ``assert_clean()``): raises AssertionError listing the findings (``path:line:col: severity
    rule: message``, what ``colcon test-result --verbose`` shows) unless ``main(argv)`` is 0."""
    import contextlib
    import io

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = main(list(argv))
    text = out.getvalue()
    sys.stdout.write(text)
    if code != 0:
        lines = [line for line in text.splitlines() if line and not line.startswith(" ")]
        raise AssertionError(" ".join(["urdftool-ament", *argv, "exited", str(code)])
                             + (" (see its stderr)" if code == 2 else "") + "\n"
                             + "\n".join(lines))


def run() -> None:
    """The console script."""
    sys.exit(main())


if __name__ == "__main__":
    run()
