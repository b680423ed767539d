"""Fuzzing: mutate real robot descriptions and run the commands on them.

``python -m urdftool.fuzz --cases N`` (or ``--minutes M``) takes the seed robots
(``robots/*/{published,corrected}``, the tests' xacro corpus, pybullet_data URDFs), applies 1-4
random mutations to one (delete, duplicate or swap text, truncate, break tags, insert attributes,
put NaN/huge numbers in, nest elements thousands deep, garble xacro expressions...) and runs
``check`` plus one of ``limits``, ``inertia``, ``tree`` in-process. Each must give a report or a
clean exit-2 message within a time bound: a Python traceback, an "internal error" (also a rule's,
which ``check`` reports as a diagnostic), another exit code or a timeout is a crash. Reproducers
are saved; the summary gives the number of cases, the crashes and the slowest case.
``tests/test_fuzz.py`` drives the same mutations from hypothesis.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import random
import re
import shutil
import signal
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

COMMANDS = ("limits", "inertia", "tree")
TIME_BOUND = 10.0  # seconds for one command on one case: above it, the case is a crash

NUMBERS = ["nan", "NaN", "-nan", "inf", "-inf", "Infinity", "1e308", "-1e308", "1e400",
           "1e-320", "0", "-0", "0.0", "-1", "9" * 400, "0x1F", "1_000", "", " ", "1e", ".",
           "-", "+", "1.2.3", "1,5", "١٢", "1e-7", "3.4028235e38", "nan nan nan", "1 2",
           "1 2 3 4 5", "-1e-300", "4.9e-324", "1e+", "--1", "${1/0}"]
ATTRIBUTES = ["name", "type", "value", "xyz", "rpy", "size", "radius", "length", "mass", "ixx",
              "iyy", "izz", "ixy", "lower", "upper", "effort", "velocity", "multiplier",
              "offset", "filename", "scale", "rgba", "link", "joint", "reference", "params",
              "damping", "friction", "xmlns:xacro", "xacro:name", "version", "k_velocity"]
JUNK = ["\x00", "\x01", "\x0b", "\ufeff", "\u202e", "\ud7ff", "é", "😀", "&", "&amp;", "&#0;",
        "&#x110000;", "&nbsp;", "<", ">", "]]>", "<![CDATA[", "<!--", "-->", "<?xml ", "?>",
        "<!DOCTYPE r [<!ENTITY e 'x'>]>", "&e;", "${", "}", "$(", ")", "$(arg x)",
        "$(find nowhere)", '"', "'", "=", "/>", "</", "\t", "\r\n", "\\", "%", "xacro:"]
EXPRESSIONS = ["**99", "**99999", ".real", "[0]", "[", "(", "python.type", ".gi_frame",
               "__class__", "'a'*999999999", "xacro.load_yaml('/etc/passwd')", "1/0",
               "undefined_name", " if ", "lambda: 0", ":=", "python.range(10**9)", ".format",
               "${", "'", "math.nan", "float('inf')", "-1e308*10"]


# -- mutations: (text, rng) -> text --------------------------------------------------------


def _position(text: str, rng: random.Random) -> int:
    return rng.randint(0, len(text))


def _span(text: str, rng: random.Random) -> tuple[int, int]:
    start = _position(text, rng)
    length = rng.choice((1, 1, 2, 5, 20, 100, 1000))
    return start, min(len(text), start + length)


def delete_span(text, rng):
    start, end = _span(text, rng)
    return text[:start] + text[end:]


def duplicate_span(text, rng):
    start, end = _span(text, rng)
    at = _position(text, rng)
    return text[:at] + text[start:end] + text[at:]


def swap_spans(text, rng):
    a, b = sorted((_span(text, rng), _span(text, rng)))
    if a[1] > b[0]:
        return text
    return text[:a[0]] + text[b[0]:b[1]] + text[a[1]:b[0]] + text[a[0]:a[1]] + text[b[1]:]


def truncate(text, rng):
    return text[:_position(text, rng)]


def break_tag(text, rng):
    spots = [m.start() for m in re.finditer(r"[<>/\"=]", text)]
    if not spots:
        return text
    at = rng.choice(spots)
    return text[:at] + rng.choice(("", "", " ", "<", ">", "\"", "'")) + text[at + 1:]


def insert_attribute(text, rng):
    tags = [m.end() for m in re.finditer(r"<[A-Za-z_][\w:.-]*", text)]
    if not tags:
        return text
    at = rng.choice(tags)
    name = rng.choice(ATTRIBUTES + [f"a{rng.randint(0, 99)}"])
    value = rng.choice(NUMBERS + JUNK)
    quote = rng.choice(('"', '"', "'"))
    return text[:at] + f" {name}={quote}{value}{quote}" + text[at:]


def replace_number(text, rng):
    numbers = list(re.finditer(r"-?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?", text))
    if not numbers:
        return text
    match = rng.choice(numbers)
    return text[:match.start()] + rng.choice(NUMBERS) + text[match.end():]


def deep_nesting(text, rng):
    tags = [m.start() for m in re.finditer(r"<(?:link|joint|visual|geometry|robot)\b", text)]
    at = rng.choice(tags) if tags else _position(text, rng)
    depth = rng.choice((10, 300, 3000, 20000))
    tag = rng.choice(("link", "a", "xacro:if value=\"1\"", "origin"))
    closing = tag.split()[0]
    close = f"</{closing}>" * depth if rng.random() < 0.7 else ""
    return text[:at] + f"<{tag}>" * depth + close + text[at:]


def insert_junk(text, rng):
    at = _position(text, rng)
    return text[:at] + "".join(rng.choice(JUNK) for _ in range(rng.randint(1, 3))) + text[at:]


def duplicate_element(text, rng):
    elements = list(re.finditer(r"<(link|joint|material|inertial|mimic|limit)\b[^>]*?(?:/>|>.*?"
                                r"</\1>)", text, re.DOTALL))
    if not elements:
        return text
    match = rng.choice(elements)
    at = rng.choice((match.start(), match.end()))
    return text[:at] + match.group(0) + text[at:]


def swap_names(text, rng):
    names = re.findall(r'(?:name|link|joint)="([^"]*)"', text)
    if len(names) < 2:
        return text
    old, new = rng.choice(names), rng.choice(names)
    matches = [m for m in re.finditer(r'(?:name|link|joint)="' + re.escape(old) + '"', text)]
    match = rng.choice(matches)
    return text[:match.start()] + match.group(0).replace(f'"{old}"', f'"{new}"') + \
        text[match.end():]


def garble_expression(text, rng):
    expressions = list(re.finditer(r"\$\{[^}]*\}", text))
    if not expressions:
        at = _position(text, rng)
        return text[:at] + "${" + rng.choice(EXPRESSIONS) + "}" + text[at:]
    match = rng.choice(expressions)
    at = rng.randint(match.start() + 2, match.end() - 1)
    return text[:at] + rng.choice(EXPRESSIONS) + text[at:]


# what a name may carry to hijack a terminal or a CI log (issue 12): entity-encoded line breaks
# before workflow commands, the legacy ##[ form, a C1 CSI, bidi overrides, rich markup
HOSTILE = ("&#10;::error::fuzz", "&#13;::stop-commands::tok", "&#x85;::warning::nel",
           "##[error]legacy", "&#x9B;31m", "&#x202E;&#x2066;", "[/]:smile:", "&#x2028;::x")


def hostile_name(text, rng):
    names = list(re.finditer(r'(?:name|link|joint)="[^"]*', text))
    if not names:
        return text
    at = rng.choice(names).end()
    return text[:at] + rng.choice(HOSTILE) + text[at:]


MUTATIONS = [delete_span, duplicate_span, swap_spans, truncate, break_tag, insert_attribute,
             replace_number, deep_nesting, insert_junk, duplicate_element, swap_names,
             garble_expression, hostile_name]


def mutate(text: str, rng: random.Random, count: int | None = None) -> tuple[str, list[str]]:
    """``text`` with ``count`` (default 1-4) random mutations; also their names."""
    applied = []
    for _ in range(count if count is not None else rng.randint(1, 4)):
        mutation = rng.choice(MUTATIONS)
        text = mutation(text, rng)
        applied.append(mutation.__name__)
    return text, applied


# -- seeds ---------------------------------------------------------------------------------


def _repository() -> Path:
    return Path(__file__).resolve().parent.parent


def seeds(include_pybullet: bool = True, limit_pybullet: int | None = None) -> list[Path]:
    """Robot files to mutate: the seed robots, the tests' xacro corpus, pybullet_data URDFs."""
    root = _repository()
    found = sorted(p for p in (root / "robots").glob("*/*/*")
                   if p.suffix in (".urdf", ".xacro") and p.is_file())
    found += sorted((root / "tests" / "data" / "xacro_safe").rglob("*.urdf.xacro"))
    if include_pybullet:
        try:
            import pybullet_data
        except ImportError:
            pybullet_data = None
        if pybullet_data is not None:
            base = Path(pybullet_data.getDataPath())
            extra = sorted(p for p in base.rglob("*.urdf") if "random_urdfs" not in p.parts
                           and p.stat().st_size < 400_000)
            found += extra[:limit_pybullet] if limit_pybullet else extra
    return found


class Workspace:
    """A scratch copy of a seed's directory where mutated copies of the seed are written, so
    includes, YAML files and meshes next to it still resolve."""

    def __init__(self, root: Path | None = None):
        self.root = Path(root or tempfile.mkdtemp(prefix="urdftool-fuzz-work-"))
        self._made: dict[Path, Path] = {}

    def target(self, seed: Path) -> Path:
        seed = seed.resolve()
        if seed not in self._made:
            directory = self.root / f"seed{len(self._made)}"
            directory.mkdir(parents=True)
            entries = list(seed.parent.iterdir())
            small = len(entries) < 40
            for entry in entries:
                destination = directory / entry.name
                if small and entry.is_dir():
                    shutil.copytree(entry, destination, symlinks=True)
                elif small:
                    shutil.copy(entry, destination)
                else:
                    destination.symlink_to(entry)
            self._made[seed] = directory / seed.name
        return self._made[seed]

    def write(self, seed: Path, text: str) -> Path:
        target = self.target(seed)
        if target.is_symlink():
            target.unlink()
        target.write_bytes(text.encode("utf-8", "surrogatepass"))
        return target

    def cleanup(self) -> None:
        shutil.rmtree(self.root, ignore_errors=True)


# -- running one case ----------------------------------------------------------------------


class _Timeout(BaseException):
    pass


@contextlib.contextmanager
def _time_bound(seconds: float):
    if not hasattr(signal, "SIGALRM") or seconds <= 0:
        yield
        return

    def expired(signum, frame):
        raise _Timeout()

    previous = signal.signal(signal.SIGALRM, expired)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


@dataclass
class Outcome:
    command: list[str]
    code: int
    out: str
    err: str
    seconds: float
    problem: str | None = None  # why this is a crash (None: fine)


def run_command(args: list[str], bound: float = TIME_BOUND) -> Outcome:
    """``urdftool ARGS`` in-process, judged: a report or a clean exit-2 message, in time."""
    from urdftool.cli import main

    out, err = io.StringIO(), io.StringIO()
    started = time.perf_counter()
    code, problem = 0, None
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), \
                _time_bound(bound):
            try:
                main(args)
            except SystemExit as exc:
                code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    except _Timeout:
        code, problem = -1, f"no answer within {bound:g} s"
    except BaseException as exc:  # noqa: BLE001 - escaping main() is the crash being looked for
        code, problem = -2, f"{type(exc).__name__} escaped main(): {exc}"
    seconds = time.perf_counter() - started
    stdout, stderr = out.getvalue(), err.getvalue()
    if problem is None:
        problem = judge(args, code, stdout, stderr)
    return Outcome(args, code, stdout, stderr, seconds, problem)


def judge(args: list[str], code: int, out: str, err: str) -> str | None:
    """What is wrong with this result, or None."""
    if code not in (0, 1, 2):
        return f"exit code {code}"
    if "Traceback (most recent call last)" in out + err:
        return "a Python traceback"
    if "internal error" in err:
        return "internal error: " + err.strip().splitlines()[-1]
    if code == 2:
        lines = err.strip().splitlines()
        if len(lines) != 1 or not lines[0].startswith(("urdftool: ", "Error: ", "Usage: ")):
            return f"exit 2 without one clean line on stderr: {err.strip()[:300]!r}"
        return None
    if args and args[0] == "check" and "--format" in args:
        try:
            report = json.loads(out)
        except ValueError:
            return "check --format json printed something that is not JSON"
        for file in report.get("files", []):
            for diagnostic in file.get("diagnostics", []):
                if diagnostic.get("message", "").startswith("internal error in rule"):
                    return f"{diagnostic['rule']}: {diagnostic['message']}"
    elif "internal error" in out:
        return "internal error in the output"
    if "--format" not in args:  # human output: file content escaped, nothing a CI runner runs
        return hijackable(out + err)
    return None


def hijackable(text: str) -> str | None:
    """What in human-readable output a terminal or a CI runner would obey, or None: a raw
    control or format character, a line starting with '::' (GitHub Actions), '##[' anywhere."""
    import unicodedata

    raw = sorted({f"U+{ord(c):04X}" for c in text if c != "\n"
                  and unicodedata.category(c) in ("Cc", "Cf", "Zl", "Zp")})
    if raw:
        return f"raw control characters in the output: {', '.join(raw)}"
    if "##[" in text:
        return "'##[' (a CI runner command) in the output"
    if any(line.lstrip().startswith("::") for line in text.split("\n")):
        return "a line starting with '::' (a GitHub Actions command) in the output"
    return None


def run_case(path: Path, extra: str, untrusted: bool = False,
             bound: float = TIME_BOUND) -> list[Outcome]:
    """``check`` and one ``extra`` command on ``path``."""
    mode = "--untrusted" if untrusted else "--trusted"
    outcomes = [run_command(["check", "--format", "json", mode, str(path)], bound)]
    if outcomes[0].code == -1:
        return outcomes  # it hung reading the file: the other command would hang the same way
    args = [extra, str(path)]
    if extra == "inertia":
        args.insert(1, "--format=json")
    outcomes.append(run_command(args, bound))
    return outcomes


# -- the campaign ---------------------------------------------------------------------------


@dataclass
class Summary:
    cases: int = 0
    runs: int = 0
    crashes: list[dict] = field(default_factory=list)
    slowest: tuple[float, str] = (0.0, "")


def _save(directory: Path, number: int, seed: Path, text: str, mutations: list[str],
          outcome: Outcome) -> Path:
    directory.mkdir(parents=True, exist_ok=True)
    suffix = "".join(seed.suffixes[-2:]) if seed.name.endswith(".urdf.xacro") else seed.suffix
    case = directory / f"crash{number:04d}{suffix}"
    case.write_bytes(text.encode("utf-8", "surrogatepass"))
    (directory / f"crash{number:04d}.txt").write_text(
        f"seed: {seed}\nmutations: {', '.join(mutations)}\n"
        f"command: urdftool {' '.join(outcome.command[:-1])} {case.name}\n"
        f"(run it next to a copy of the seed's directory so its includes resolve)\n"
        f"exit code: {outcome.code}\nproblem: {outcome.problem}\n--- stderr ---\n{outcome.err}"
        f"\n--- stdout (head) ---\n{outcome.out[:4000]}\n", encoding="utf-8")
    return case


def campaign(cases: int, seed: int = 0, out_dir: Path | None = None,
             bound: float = TIME_BOUND, progress=None,
             minutes: float | None = None) -> tuple[Summary, Path]:
    """Run ``cases`` mutated cases (fewer if ``minutes`` run out first); crashes are saved under
    ``out_dir``."""
    stop_at = time.monotonic() + minutes * 60 if minutes else None
    rng = random.Random(seed)
    corpus = seeds()
    texts = {}
    for path in corpus:
        try:
            texts[path] = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            continue
    corpus = list(texts)
    out_dir = Path(out_dir or tempfile.mkdtemp(prefix="urdftool-fuzz-"))
    workspace = Workspace()
    summary = Summary()
    os.environ.pop("CI", None)  # the commands without --trusted/--untrusted: trusted
    try:
        for number in range(cases):
            if stop_at is not None and time.monotonic() > stop_at:
                break
            seed_path = rng.choice(corpus)
            text, mutations = mutate(texts[seed_path], rng)
            path = workspace.write(seed_path, text)
            untrusted = path.name.endswith(".xacro") and rng.random() < 0.15
            extra = COMMANDS[number % len(COMMANDS)]
            for outcome in run_case(path, extra, untrusted, bound):
                summary.runs += 1
                label = f"{seed_path.name} [{', '.join(mutations)}] {outcome.command[0]}"
                if outcome.seconds > summary.slowest[0]:
                    summary.slowest = (outcome.seconds, label)
                if outcome.problem:
                    saved = _save(out_dir, len(summary.crashes), seed_path, text, mutations,
                                  outcome)
                    summary.crashes.append({"case": number, "seed": str(seed_path),
                                            "mutations": mutations,
                                            "command": outcome.command[0],
                                            "problem": outcome.problem,
                                            "reproducer": str(saved)})
            summary.cases += 1
            if progress and (number + 1) % 500 == 0:
                progress(summary)
    finally:
        workspace.cleanup()
    return summary, out_dir


# -- the command line: python -m urdftool.fuzz (make fuzz); a developer's tool, not a command --

def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m urdftool.fuzz",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=1000, help="how many mutated cases")
    parser.add_argument("--minutes", type=float, default=None,
                        help="stop after this long even if --cases are not all run")
    parser.add_argument("--seed", type=int, default=0, help="random seed (reproducible runs)")
    parser.add_argument("--out", type=Path, default=None, help="where crash reproducers go")
    parser.add_argument("--time-bound", type=float, default=TIME_BOUND,
                        help="seconds one command may take on one case")
    options = parser.parse_args(argv)
    started = time.monotonic()

    def progress(summary: Summary) -> None:
        print(f"  {summary.cases} cases, {len(summary.crashes)} crashes, "
              f"{time.monotonic() - started:.0f} s", file=sys.stderr, flush=True)

    summary, out_dir = campaign(options.cases, options.seed, options.out, options.time_bound,
                           progress, options.minutes)
    elapsed = time.monotonic() - started
    print(f"fuzz: {summary.cases} cases ({summary.runs} command runs) in {elapsed:.0f} s")
    print(f"crashes: {len(summary.crashes)}")
    for crash in summary.crashes[:50]:
        print(f"  case {crash['case']}: {crash['command']} on {Path(crash['seed']).name} "
              f"[{', '.join(crash['mutations'])}]: {crash['problem'][:200]}\n"
              f"    reproducer: {crash['reproducer']}")
    if summary.crashes:
        print(f"reproducers in {out_dir}")
    print(f"slowest: {summary.slowest[0]:.2f} s ({summary.slowest[1]})")
    return 1 if summary.crashes else 0


if __name__ == "__main__":  # python -m urdftool.fuzz: a front end (layer 7), its exit code
    raise SystemExit(main())
