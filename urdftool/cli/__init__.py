"""The command line: a click group whose commands live one per module in this package and
are imported only when invoked (so ``urdftool check`` never pays for pybullet or pinocchio).

Commands are thin: parse options, call the library, print. Exit codes: 0 clean, 1 findings or a
failed check, 2 the tool could not do its job (one line on stderr, no traceback).
"""

from __future__ import annotations

import atexit
import gc
import importlib
import os
import sys

import click

from urdftool import __version__
from urdftool.errors import ToolError

# At exit the interpreter's last garbage collections walk every object of the process (lxml,
# click, the rules...): ~10 ms of a ~65 ms `urdftool check` (issue 2), to free memory the OS frees
# anyway. Frozen objects are skipped; files are closed by their `with` blocks, stdout is flushed.
atexit.register(gc.freeze)

COMMANDS = {
    "check": "lint robot files; all findings in one pass",
    "expand": "expand xacro to URDF, errors located in the xacro source",
    "inertia": "declared vs geometry-derived inertia per link",
    "limits": "joint-limit and mimic table",
    "tree": "kinematic tree",
    "convert": "convert SDF to URDF",
    "dh": "Denavit-Hartenberg table of a serial chain",
    "jacobian": "Jacobian table at a configuration (or symbolic)",
    "sim": "short PyBullet physics smoke test per model",
    "rules": "the rule catalogue",
    "doctor": "optional libraries and --untrusted sandbox layers on this machine",
    "lsp": "language server (LSP, stdio): the findings, fixes and numbers in the editor",
    "compare": "two descriptions of one robot (URDF, xacro, SDF, MJCF), body by body",
    "diff": "what a change does to each robot (git revisions or two snapshots)",
}
ALIASES = {"rule": "rules"}  # ruff's `ruff rule RULE`


class UsageError(ToolError):
    """A mistyped command line: one line on stderr, exit 2."""


class LazyGroup(click.Group):
    """Imports ``urdftool.cli.<name>`` (which defines ``command``) on first use."""

    def list_commands(self, ctx):
        return list(COMMANDS)

    def get_command(self, ctx, name):
        name = ALIASES.get(name, name)
        if name not in COMMANDS:
            return None
        module = importlib.import_module(f"urdftool.cli.{name}")
        return module.command

    def resolve_command(self, ctx, args):
        name = args[0] if args else ""
        if self.get_command(ctx, name) is None and not name.startswith("-"):
            import difflib

            close = (difflib.get_close_matches(name, list(COMMANDS), n=1, cutoff=0.6)
                     or difflib.get_close_matches(name, list(ALIASES), n=1, cutoff=0.6))
            hint = f"; did you mean '{close[0]}'?" if close else \
                f"; the commands: {', '.join(COMMANDS)}"
            raise UsageError(f"no command {name!r}{hint}")
        return super().resolve_command(ctx, args)

    def format_commands(self, ctx, formatter):
        rows = [(name, help_text) for name, help_text in COMMANDS.items()]
        with formatter.section("Commands"):
            formatter.write_dl(rows)


COLOR = {"when": "auto"}  # --color (the group's or a command's): auto, always, never


def _set_color(ctx, param, value):
    if value is not None:
        COLOR["when"] = value
    return value


def color_option(function):
    """``--color auto|always|never`` (ruff's): auto colours a terminal unless NO_COLOR is set;
    FORCE_COLOR colours a pipe too. Accepted before or after the command name."""
    return click.option("--color", type=click.Choice(("auto", "always", "never")),
                        default=None, expose_value=False, callback=_set_color, is_eager=True,
                        help="Colour the output: auto (a terminal, unless NO_COLOR is set; "
                             "FORCE_COLOR forces it), always, never.")(function)


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="urdftool")
@color_option
@click.option("--debug", is_flag=True, envvar="URDFTOOL_DEBUG",
              help="Show Python tracebacks (for reporting bugs in urdftool).")
@click.pass_context
def cli(ctx, debug):
    """urdftool: validate and work with robot descriptions (URDF, xacro, SDF)."""
    ctx.ensure_object(dict)
    ctx.obj["debug"] = debug


# -- options shared by the commands ---------------------------------------------------------


def format_option(*choices: str, default: str = "text"):
    return click.option("--format", "--output-format", "fmt", type=click.Choice(choices),
                        default=default, show_default=True, help="Output format.")


def show_info_option(function):
    """``--show-info``: infos are listed only when asked, as ``check`` lists them (always
    counted, and always in JSON)."""
    return click.option("--show-info", is_flag=True,
                        help="Text: list infos too (they are always counted, and always in "
                             "JSON).")(function)


def print_findings(findings, show_info: bool, located=lambda f: (f["path"], f["line"])) -> None:
    """A command's findings (dicts with severity, rule, message, hint), errors first; infos
    only with ``show_info`` (``check`` hides them by default: one verdict, one look)."""
    order = ("error", "warning", "info")
    for f in sorted(findings, key=lambda f: order.index(f["severity"])):
        if f["severity"] == "info" and not show_info:
            continue
        path, line = located(f)
        print_finding(path, line, f.get("column"), f["severity"], f["rule"], f["message"],
                      f.get("hint"))


def info_summary(count: int, show_info: bool) -> str:
    """'N info', with where to see them when they were not listed."""
    return f"{count} info" + (" (listed with --show-info)" if count and not show_info else "")


def package_option(function):
    return click.option("-P", "--package", "packages", multiple=True, metavar="NAME=DIR",
                        help="Where package NAME lives (for package:// and $(find NAME)). "
                             "Repeatable.")(function)


_LITERAL_KEY = "urdftool.literal"


class PathsCommand(click.Command):
    """A command whose arguments after ``--``, and after ``--changed``, are file names: never
    an option (a committed file named ``--write-baseline=x.urdf`` or ``-o`` is checked as a
    file) and never a xacro ``NAME:=VALUE`` (``split_args``). The hook and the Action pass the
    names after ``--``: a pull request cannot set the gate's verdict."""

    def parse_args(self, ctx, args):
        args = list(args)
        cut = self._literal_start(ctx, args)
        if cut is not None:
            literal = args[cut:]
            args = args[:cut]
            if args[-1] == "--":
                args.pop()  # (put back below, once)
            args += ["--", *literal]
            ctx.meta[_LITERAL_KEY] = len(literal)
        return super().parse_args(ctx, args)

    def _literal_start(self, ctx, args: list[str]) -> int | None:
        """The index of the first file name that must not be parsed (after ``--`` or
        ``--changed``), or None. Option values are skipped: ``-o --changed`` names a file."""
        takes_value, short = set(), set()
        for param in self.get_params(ctx):
            if isinstance(param, click.Option) and not param.is_flag and not param.count:
                for opt in (*param.opts, *param.secondary_opts):
                    takes_value.add(opt)
                    if len(opt) == 2 and opt[0] == "-" and opt[1] != "-":
                        short.add(opt[1])
        index = 0
        while index < len(args):
            token = args[index]
            if token == "--":
                return index + 1
            if token == "--changed":  # (and a `--` after it is the same separator)
                return index + 2 if args[index + 1:index + 2] == ["--"] else index + 1
            if token.startswith("--"):
                if "=" not in token and token in takes_value:
                    index += 1
            elif token.startswith("-") and len(token) > 1:
                for position, letter in enumerate(token[1:], 1):
                    if letter in short:
                        if position == len(token) - 1:
                            index += 1
                        break
            index += 1
        return None


def split_args(values: tuple[str, ...]) -> tuple[list[str], dict[str, str]]:
    """Separate positional values into paths and xacro NAME:=VALUE arguments. Values given
    after ``--`` (``PathsCommand``) are paths, whatever they hold."""
    ctx = click.get_current_context(silent=True)
    literal = ctx.meta.get(_LITERAL_KEY, 0) if ctx is not None else 0
    paths, xacro_args = [], {}
    for index, value in enumerate(values):
        if index >= len(values) - literal:
            paths.append(value)
        elif ":=" in value:
            name, _, arg = value.partition(":=")
            xacro_args[name] = arg
        else:
            paths.append(value)
    return paths, xacro_args


def parse_packages(values: tuple[str, ...]) -> dict[str, str]:
    packages = {}
    for value in values:
        name, sep, directory = value.partition("=")
        if not sep or not name or not directory:
            raise ToolError(f"-P expects NAME=DIR, got {value!r}")
        packages[name] = directory
    return packages


# -- untrusted input (issue 8): options shared by the commands that load files ---------------

_UNTRUSTED_KEY = "urdftool.untrusted"


def _remember(ctx, param, value):
    ctx.meta.setdefault(_UNTRUSTED_KEY, {})[param.name] = value
    return value


def untrusted_options(function):
    """``--untrusted/--trusted``, ``--allow-env NAME``, ``--timeout S``, ``--memory-limit MB``.
    The values reach ``load_options`` through the click context, so a command only adds the
    decorator. Without ``--trusted``/``--untrusted`` the mode is untrusted when ``CI`` is set."""
    options = [
        click.option("--memory-limit", "memory_limit", type=click.IntRange(64), default=None,
                     metavar="MB", expose_value=False, callback=_remember,
                     help="Address space of the --untrusted sandboxed reader, which reads "
                          "xacro, YAML, SDF and meshes (default 1024 MB)."),
        click.option("--timeout", "timeout", type=click.FloatRange(0.1), default=None,
                     metavar="SECONDS", expose_value=False, callback=_remember,
                     help="Time limit of one xacro expansion, and under --untrusted of "
                          "one file or mesh read by the sandboxed reader (default 3 s)."),
        click.option("--allow-env", "allow_env", multiple=True, metavar="NAME",
                     expose_value=False, callback=_remember,
                     help="An environment variable $(env NAME) and $(optenv NAME) may read "
                          "(in every mode: by default a file reads none). Repeatable."),
        click.option("--untrusted/--trusted", "untrusted", default=None, expose_value=False,
                     callback=_remember,
                     help="Treat the input as hostile: read xacro, YAML, SDF and meshes in "
                          "a sandboxed process (time and memory limits, no environment, "
                          "Landlock and seccomp where the kernel has them, files only inside "
                          "the package roots; `urdftool doctor` lists the layers). Default: "
                          "--untrusted when the CI environment variable is set."),
    ]
    for option in options:
        function = option(function)
    return function


def untrusted_default() -> bool:
    """Untrusted unless told otherwise when running under CI (the ``CI`` variable is set)."""
    return os.environ.get("CI", "").strip().lower() not in ("", "0", "false", "no")


def load_options(packages: tuple[str, ...], xacro_args: dict[str, str]):
    from urdftool.source import LoadOptions

    options = LoadOptions(parse_packages(packages), xacro_args)
    ctx = click.get_current_context(silent=True)
    given = ctx.meta.get(_UNTRUSTED_KEY, {}) if ctx is not None else {}
    untrusted = given.get("untrusted")
    options.untrusted = untrusted_default() if untrusted is None else untrusted
    if options.untrusted or "urdftool.cache" in sys.modules:  # (else nothing to reset)
        from urdftool import cache

        # untrusted: no file written unless a cache directory is named for it
        cache.WRITABLE = not options.untrusted or bool(os.environ.get("URDFTOOL_CACHE_DIR"))
    meshes = sys.modules.get("urdftool.physics.meshes")
    if not options.untrusted and meshes is not None:  # a trusted run after an untrusted one
        meshes.PARSER = None  # (in one process: tests) parses its meshes itself
        meshes.TRIANGLE_READER = None
    options.allow_env = tuple(given.get("allow_env") or ())
    if given.get("timeout") is not None:
        options.timeout = given["timeout"]
    if given.get("memory_limit") is not None:
        options.memory_mb = given["memory_limit"]
    return options


FAILED: list[str] = []  # files whose reading was refused in part (load_robot): exit 1


def load_robot(path: str, packages: tuple[str, ...] = (), xacro_args: dict | None = None):
    """Load one file into a Robot for the commands that work on a model (not ``check``).
    A file too broken to give a robot is an error (exit 2) located at the first problem."""
    from urdftool import budget
    from urdftool.check import REFUSING_RULES
    from urdftool.display import diagnostic_line
    from urdftool.loader import load
    from urdftool.model import build_robot

    options = load_options(packages, xacro_args or {})
    # one run budget for the readings (issue 21): the first, the safe-fix rounds and the last
    # share --timeout for the file plus one for the start, as check's run does
    own = budget.remaining() is None
    if own:
        budget.start(options.timeout, 1)
    try:
        source = load(path, options)
        robot = build_robot(source)
        # read it as check does: through its safe fixes; never again after a reading stopped
        # at a limit (no safe fix moves it, and a second reading spent the rest of the run's
        # budget on the same wall: `tree` took both --timeouts on a sort with a lambda key)
        stopped = any(rule == "xacro.limit-exceeded" for rule, _ in source.problems)
        if not stopped and (source.root is None or not robot.links or any(
                rule.startswith("xml.") for rule, _ in source.problems)):
            fixed = _through_safe_fixes(path, options)
            if fixed is not None:
                source, robot, count = fixed
                if source.root is not None and source.root.tag == "robot" and robot.links:
                    from urdftool.display import clean  # (a refusal below stays one line)

                    echo(f"urdftool: {clean(path)}: read through {count} safe fix(es), as "
                         f"check reads it ('urdftool check {clean(path)}' lists them)", err=True)
    finally:
        if own:
            budget.stop()
    # a refused expression or an exceeded limit: said, located, and the run fails (exit 1);
    # the robot is still shown with the expression's placeholder value where it can be built
    refusals = [finding for rule, finding in source.problems if rule in REFUSING_RULES]
    for rule, finding in source.problems:
        if rule in REFUSING_RULES:
            loc = finding.loc
            print_finding(loc.path if loc else path, loc.line if loc else None,
                          loc.column if loc else None, "error", rule, finding.message,
                          finding.hint, err=True)
    if refusals:
        FAILED.append(path)
    if source.root is not None and source.root.tag == "robot" and robot.links:
        from urdftool.rules import INCLUDE_SKIPPED
        from urdftool.rules.xacro import classify

        for rule, finding in source.problems:  # an include that could not be read (a file,
            if rule == "xacro.error" and finding.message.endswith(INCLUDE_SKIPPED):  # package)
                _, message, hint = classify(finding.message, robot)  # as check says it; the
                loc = finding.loc  # robot is what could be built without it
                print_finding(loc.path if loc else path, loc.line if loc else None,
                              loc.column if loc else None, finding.severity or "error", rule,
                              message, finding.hint or hint, err=True)
    if source.root is None or source.root.tag != "robot" or not robot.links:
        if refusals:
            raise click.exceptions.Exit(1)
        advice = f"cannot read a robot; run 'urdftool check {path}'"
        if not source.problems:
            raise ToolError(diagnostic_line(path, None, None, "error", None,
                                            f"no <robot> with links in it: {advice}"))
        rule, first = source.problems[0]
        loc = first.loc
        raise ToolError(diagnostic_line(
            loc.path if loc else path, loc.line if loc else None, loc.column if loc else None,
            "error", rule, f"{first.message} ({advice})"))
    return robot


def _through_safe_fixes(path: str, options):
    """(source, robot, fixes applied) of ``path`` read through its safe fixes, in memory, as
    ``check`` looks through them (issue 23.7: a reading command refuses only what check cannot
    read either); None when no safe fix changes it."""
    from urdftool.check import CheckOptions, overlay_options
    from urdftool.fix import fix_file
    from urdftool.loader import load
    from urdftool.model import build_robot

    result = fix_file(path, CheckOptions(load=options), unsafe=False)
    changed = result.changed()
    if not changed:
        return None
    reading = overlay_options(options, {n: result.texts[n] for n in changed})
    source = load(path, reading)
    if source.kind == "xacro" and source.root is None and any(  # past an undefined name (a
            rule == "xacro.error" and "is not defined" in f.message  # missing include's
            for rule, f in source.problems):  # property), as check reads on
        reading.lenient = True
        source = load(path, reading)
    return source, build_robot(source), result.fixed


def stdout_console():
    """The rich console of human output (stdout). On a terminal: its width and colours.
    Otherwise (a pipe, a file, a CI log): nothing wrapped or cut, no colour. Never interprets
    emoji codes; every line goes through ``display.guard``. Put file content in markup with
    ``shown(value)``."""
    from rich.console import Console

    from urdftool.display import GuardedStream

    console = Console(file=GuardedStream(sys.stdout), highlight=False, emoji=False)
    if not console.is_terminal:
        console.width = 1_000_000  # no wrapping, no cropping: each row on one line
    return console


def print_table(console, table, title: str | None = None) -> None:
    """A rich table after its title line (a rich title would be wrapped to the table's width).
    Nothing is cut: on a terminal long cells fold onto more lines; elsewhere the console is
    unbounded (``stdout_console``) and every row is one line."""
    from urdftool.cli.table import drawn

    if title:
        console.print(title)
    for column in table.columns:
        column.overflow = "fold"
    console.print(drawn(table))  # a big table without rich's per-cell measurement (issue 15)


def shown(value) -> str:
    """File content (a name, a path, a message) for rich markup: escaped by ``display.clean``
    and for the markup (a name like ``[/]`` is text)."""
    from rich.markup import escape

    from urdftool.display import clean

    return escape(clean("" if value is None else value))


def shown_block(text: str) -> str:
    """Several lines (an XML block we wrote, with names from the file in it): each line
    escaped like ``shown``."""
    return "\n".join(shown(line) for line in str(text).split("\n"))


def echo(text: str, err: bool = False, nl: bool = True) -> None:
    """One or more lines of human output without rich (``display.guard``ed)."""
    from urdftool.display import guard

    click.echo(guard(text), err=err, nl=nl)


def print_json(data, **options) -> None:
    """A JSON document of a command: exact values, no CI command in it
    (``display.json_safe``)."""
    import json

    from urdftool.display import json_safe

    click.echo(json_safe(json.dumps(data, indent=2, **options)))


def print_finding(path, line, column, severity: str, rule: str | None, message: str,
                  hint: str | None = None, err: bool = False) -> None:
    """A finding of any command, located as ``check`` does (``display.diagnostic_line``), with
    its hint on the next line; coloured on a terminal (unless NO_COLOR)."""
    from urdftool.display import clean, clip, diagnostic_line

    stream = sys.stderr if err else sys.stdout
    colour = _colour(stream)
    # clipped as check's report clips (a message that lists 50,000 joint names is one line)
    text = diagnostic_line(path, line, column, severity, rule, clip(message), colour)
    if hint:
        text += "\n        " + (click.style("fix:", fg="green") if colour else "fix:") + \
            " " + clean(clip(hint))
    echo(text, err=err)


def _colour(stream) -> bool:
    """Whether to colour what goes to ``stream``: --color always/never, else NO_COLOR (set and
    not empty: no colour), FORCE_COLOR (set and not empty: colour), else a terminal."""
    when = COLOR["when"]
    if when != "auto":
        return when == "always"
    if os.environ.get("NO_COLOR"):
        return False
    if os.environ.get("FORCE_COLOR"):
        return True
    isatty = getattr(stream, "isatty", None)
    return bool(isatty and isatty())


class Progress:
    """Progress of a run over many items (``update(done, total)`` as items finish) on stderr,
    with rich, shown only when stderr is a terminal and the run has lasted a second: nothing
    is imported or drawn otherwise. No refresh thread (the commands fork worker processes)."""

    def __init__(self, what: str, enabled: bool = True):
        import time

        self._clock = time.monotonic
        self._start = self._clock()
        self.what = what
        self.enabled = enabled and sys.stderr.isatty()
        self._bar = self._task = None

    def update(self, done: int, total: int) -> None:
        if not self.enabled or total < 2:
            return
        if self._bar is None:
            if self._clock() - self._start < 1.0:
                return
            from rich.console import Console
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                TextColumn,
                TimeElapsedColumn,
            )
            from rich.progress import Progress as Bar

            self._bar = Bar(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                            TimeElapsedColumn(), console=Console(stderr=True), transient=True,
                            auto_refresh=False, redirect_stdout=False, redirect_stderr=False)
            self._bar.start()
            self._task = self._bar.add_task(self.what, total=total)
        self._bar.update(self._task, completed=done, total=total)
        self._bar.refresh()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if self._bar is not None:
            self._bar.stop()
            self._bar = None


def main(argv: list[str] | None = None) -> None:
    """Entry point: runs the group and turns ToolError into exit code 2."""
    given = sys.argv[1:] if argv is None else argv
    command = next((i for i, a in enumerate(given) if not a.startswith("-")), len(given))
    debug = bool(os.environ.get("URDFTOOL_DEBUG")) or "--debug" in given[:command]  # (a file
    # named --debug is not the group's option)
    # a command builds one model and tables of records, with few reference cycles: the young
    # generation collected every 700 allocations walks them again and again (a third of `tree`
    # on a 10k-link robot, growing with the size); every 20000 keeps cycles collected (issue 15)
    gc.set_threshold(max(gc.get_threshold()[0], 20000), *gc.get_threshold()[1:])
    FAILED.clear()
    from urdftool import files

    files.READ.clear()  # the "files read" set of this run (a process may run several: tests)
    COLOR["when"] = "auto"
    try:
        code = cli.main(args=argv, prog_name="urdftool", standalone_mode=False)
        if FAILED and not code:
            code = 1
    except click.exceptions.Exit as exc:
        sys.exit(exc.exit_code)
    except click.UsageError as exc:  # one line (click's own: usage, a blank line, the error)
        from urdftool.display import clean

        where = exc.ctx.command_path if exc.ctx is not None else "urdftool"
        echo(f"{clean(where)}: {clean(exc.format_message())} (see '{clean(where)} --help')",
             err=True)
        sys.exit(2)
    except click.ClickException as exc:
        exc.show()
        sys.exit(2)
    except click.exceptions.Abort:
        click.echo("urdftool: aborted", err=True)
        sys.exit(2)
    except ToolError as exc:
        if debug:
            raise
        from urdftool.display import clean

        echo(f"urdftool: {clean(exc)}", err=True)
        sys.exit(1 if FAILED else 2)  # after a refusal: its consequence, the finding is said
    except BrokenPipeError:
        sys.exit(1)
    except OSError as exc:  # the file system refused (a name too long, a permission...)
        if debug:
            raise
        from urdftool.display import clean

        where = f"{exc.filename}: " if exc.filename else ""
        echo(f"urdftool: {clean(where)}{clean(exc.strerror or exc)}", err=True)
        sys.exit(2)
    except Exception as exc:
        if debug:
            raise
        from urdftool.display import clean

        echo(f"urdftool: internal error: {type(exc).__name__}: {clean(exc)} "
             "(run with --debug for details)", err=True)
        sys.exit(2)
    sys.exit(code if isinstance(code, int) else 0)
