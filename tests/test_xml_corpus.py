"""The `xml` family on real files (pybullet_data, example-robot-data): no false alarms, the dirty
but accepted files give warnings only; the fast path costs one strict parse; and no input, however
broken, makes repair() raise, hang, or move a line."""

from __future__ import annotations

import json
import random
import re
import subprocess
import sys
import time

import pytest
from conftest import ROBOTS, example_robot_urdfs, pybullet_urdfs
from lxml import etree

from urdftool import xmlrepair
from urdftool.check import CheckOptions, check_file
from urdftool.source import read_text
from urdftool.textscan import declared_utf8
from urdftool.xmlrepair import repair

# Files of the corpora that are genuinely not well-formed XML: each problem (rule, line), and
# why. Every robot tool accepts them, so urdftool warns (never an error): the rest of each file
# is checked.
DIRTY = {
    "biped/biped2d_pybullet.urdf": ([("xml.declaration", 4)],
                                    "three blank lines before <?xml ...?>"),
    "differential/diff_ring.urdf": ([("xml.declaration", 2)], "a blank line before <?xml ...?>"),
    "humanoid/humanoid.urdf": ([("xml.bad-character", 288)], "a NUL byte after </robot>"),
}


def _corpus():
    return pybullet_urdfs() + example_robot_urdfs()


def _name(path) -> str:
    return "/".join(path.parts[-2:])


@pytest.fixture(scope="module")
def corpus():
    return [(path, read_text(path)) for path in _corpus()]


def test_corpus_has_no_xml_errors_and_warnings_only_where_named(corpus):
    version_zero, dirty = [], []
    for path, text in corpus:
        fixed, problems = repair(text, str(path))
        assert fixed.count("\n") == text.count("\n")
        severities = {(rule, finding.severity) for rule, finding in problems}
        assert all(rule in ("xml.declaration", "xml.bad-character") for rule, _ in severities), \
            (path, problems)
        # xml.declaration is a warning by its rule; a trailing NUL is graded down to a warning
        assert all(rule == "xml.declaration" or severity == "warning"
                   for rule, severity in severities), (path, problems)
        if re.match(r"<\?xml version=[\"']0\.0", text):
            version_zero.append(path)
            assert [r for r, _ in problems] == ["xml.declaration"]
            assert fixed.splitlines()[1:] == text.splitlines()[1:]  # only line 1 touched
        elif problems or _name(path) in DIRTY:
            assert _name(path) in DIRTY, (path, problems)
            dirty.append(_name(path))
            # each problem named by its line: one more in a dirty file fails, and so does one gone
            assert [(rule, finding.loc.line) for rule, finding in problems] == \
                DIRTY[_name(path)][0], (path, problems)
    assert len(version_zero) == 26, [p.name for p in version_zero]
    assert sorted(dirty) == sorted(DIRTY)


def test_version_zero_files_check_with_a_warning_only():
    files = [p for p in pybullet_urdfs() if read_text(p).startswith(('<?xml version="0.0"',
                                                                      "<?xml version='0.0'"))]
    assert len(files) == 26
    for path in files:
        report = check_file(path, CheckOptions(select=["xml"]))
        assert [(d.rule, d.severity, d.line) for d in report.diagnostics] == [
            ("xml.declaration", "warning", 1)], path
        assert report.robot  # the document was read: the robot has its name


def test_fast_path_is_one_strict_parse_and_no_scan(corpus, monkeypatch):
    """A well-formed file costs one strict parse (plus two C-level character counts)."""
    parses = []
    real_parse = xmlrepair._strict_parse
    monkeypatch.setattr(xmlrepair, "_strict_parse", lambda text: parses.append(1) or real_parse(text))

    class NoScanner:
        def __init__(self, *args):
            raise AssertionError("the scanner ran on a well-formed file")

    monkeypatch.setattr(xmlrepair, "_Scanner", NoScanner)
    well_formed = [(p, t) for p, t in corpus if _wellformed(t)]
    assert len(well_formed) > 100
    for path, text in well_formed:
        parses.clear()
        fixed, problems = repair(text, str(path))
        assert (fixed, problems, len(parses)) == (text, [], 1), path


def test_import_and_well_formed_files_need_no_regex_nor_difflib(corpus):
    """Importing xmlrepair (every ``check``) compiles nothing; a well-formed file, with or
    without one of the usual declarations, compiles no regular expression and does not import
    difflib or bisect (the repair's tools: built on the first malformed file)."""
    texts = [t for _, t in corpus if _wellformed(t)][:40]
    texts += [f'{d}\n<robot name="r"><link name="a"/></robot>\n'
              for d in xmlrepair._USUAL_DECLARATIONS]
    assert any(t.startswith("<?xml") for t in texts[:40])
    assert any(t.startswith("<robot") for t in texts)
    script = (
        "import json, sys\n"
        "import urdftool.xmlrepair as x\n"
        "before = sorted(vars(x._RE))\n"
        "results = [x.repair(t, 'f.urdf') == (t, []) for t in json.load(sys.stdin)]\n"
        "print(json.dumps([before, sorted(vars(x._RE)), all(results),"
        " [m for m in ('difflib', 'bisect') if m in sys.modules]]))\n")
    done = subprocess.run([sys.executable, "-c", script], input=json.dumps(texts),
                          capture_output=True, text=True, check=True)
    assert json.loads(done.stdout) == [[], [], True, []]
    # and the repair of a broken file builds what it needs
    _, problems = repair('<robot name="r">\n<link name=a/>\n</robot>\n', "f.urdf")
    assert [r for r, _ in problems] == ["xml.bad-attribute"] and "name" in vars(xmlrepair._RE)


@pytest.mark.parametrize("declaration", xmlrepair._USUAL_DECLARATIONS)
def test_usual_declarations_are_what_the_full_check_accepts(declaration):
    match = xmlrepair._RE.good_declaration.fullmatch(declaration)
    assert match and match.group(2) == "1.0"
    text = declaration + '\n<robot name="r"><link name="a"/></robot>\n'
    assert _wellformed(text)
    if "encoding" in declaration:  # the rewrite the shortcut skips would change nothing
        rewritten = declared_utf8(text)
        assert rewritten.lower() == text.lower()


def _wellformed(text: str) -> bool:
    try:
        etree.fromstring(text.encode(), xmlrepair.secure_parser())
        return True
    except etree.XMLSyntaxError:
        return False


# --- robustness --------------------------------------------------------------------------------

def _mutations(text: str, rng: random.Random):
    """Damage of the kinds people and text extraction make."""
    positions = [m.start() for m in re.finditer(r"[<>/\"=&]", text)]
    for _ in range(3):
        at = rng.choice(positions)
        yield text[:at] + text[at + 1:]  # lose one markup character
        yield text[:at] + rng.choice(["<", ">", "&", '"', "</", "/>", "\x0c", "--"]) + text[at:]
        yield text[:at]  # truncated
    lines = text.splitlines(keepends=True)
    cut = rng.randrange(len(lines))
    yield "".join(lines[:cut] + lines[cut + 1:])  # a line lost
    yield "".join(lines[:cut] + [lines[cut]] * 2 + lines[cut + 1:])  # a line doubled
    chars = list(text)
    for at in rng.sample(range(len(chars)), 20):
        chars[at] = rng.choice("<>/&\"' =\n")  # noise
    yield "".join(chars)


@pytest.mark.parametrize("seed", range(4))
def test_damaged_robots_never_raise_hang_or_move_lines(seed):
    rng = random.Random(seed)
    sources = sorted(p for p in ROBOTS.glob("*/*/*") if p.suffix in (".urdf", ".xacro"))
    sources += rng.sample(pybullet_urdfs(), 5)
    for path in sources:
        text = read_text(path)
        for damaged in _mutations(text, rng):
            start = time.process_time()  # CPU: the machine's other load does not count
            fixed, problems = repair(damaged, "x.urdf")
            assert time.process_time() - start < 5
            assert fixed.count("\n") == damaged.count("\n")
            assert len(problems) <= xmlrepair.MAX_REPAIRS + 3
            for rule, finding in problems:
                assert rule.startswith("xml.") and finding.message
                assert finding.loc.line is None or 1 <= finding.loc.line <= damaged.count("\n") + 1


_LONG_NAMES = ["".join(random.Random(seed).choices([chr(0x4E00 + i) for i in range(150)], k=20000))
               for seed in (1, 2)]
PATHOLOGICAL = {
    "deeply-nested": '<robot name="r">' + "<a>" * 5000 + "</a>" * 5000 + "</robot>",
    "deeply-unclosed": '<robot name="r">' + "<a>" * 5000,
    "thousands-of-breakages": '<robot name="r">\n' + '<link name=a>\n' * 3000,
    "binary-ish": "".join(chr(i % 250 + 1) for i in range(100000)),
    "unterminated-comments": '<robot name="r">\n' + "<!-- x\n" * 20000 + "</robot>",
    "lt-soup": "<" * 50000,
    "tag-like-lines": '<robot name="r">\n' + 'a b="c">\n' * 20000 + "</robot>",
    "unclosed-quote": '<robot name="r"><link name="' + "a" * 500000,
    # difflib compared the names of mistyped end tags: 3 s a pair of 20k-char names
    "long-mistyped-end-tags": '<robot name="r">\n<' + _LONG_NAMES[0] + ">\n"
                              + f"</{_LONG_NAMES[1]}>\n" * 20 + "</robot>\n",
}


@pytest.mark.parametrize("name", PATHOLOGICAL)
def test_pathological_inputs_return_quickly(name):
    text = PATHOLOGICAL[name]
    start = time.process_time()  # CPU: the machine's other load does not count
    fixed, problems = repair(text, "x.urdf")
    assert time.process_time() - start < 10
    assert fixed.count("\n") == text.count("\n")
    assert problems and len(problems) <= xmlrepair.MAX_REPAIRS + 3


def _nested_unclosed(n: int) -> str:
    return '<robot name="r">\n' + "<link>" * n + "\n</robot>\n"


def _siblings_one_broken(n: int) -> str:
    return ('<robot name="r">\n' + '<link name="a"/>\n' * n
            + '<joint name="j">\nimit effort="1"/>\n</joint>\n</robot>\n')


def _distinct_unclosed_then_typos(n: int) -> str:
    return ('<robot name="r">\n' + "".join(f"<a{i}>" for i in range(n)) + "\n"
            + "</zz>\n" * 300 + "</robot>\n")


def _fastest_repair(text: str, runs: int = 3) -> float:
    """The least CPU time of ``runs`` repairs, garbage collection off: what the algorithm
    costs, not what the other processes of a loaded machine or a collection took."""
    import gc

    times = []
    enabled = gc.isenabled()
    gc.disable()
    try:
        for _ in range(runs):
            start = time.process_time()
            repair(text, "x.urdf")
            times.append(time.process_time() - start)
    finally:
        if enabled:
            gc.enable()
    return min(times)


@pytest.mark.parametrize("make", [_nested_unclosed, _siblings_one_broken,
                                  _distinct_unclosed_then_typos], ids=lambda m: m.__name__[1:])
def test_repair_time_grows_linearly_with_size(make):
    """40k nested unclosed <link> took 22 s, 40k siblings 22 s (an XPath per element; unclosed
    children handed up level by level), 20k distinct unclosed elements then mistyped end tags
    27 s (each compared with every open element): 8x the size may cost about 8x the time, not
    64x (CPU time, the fastest of several runs: a loaded machine stretches wall time)."""
    small, large = _fastest_repair(make(2500), runs=5), _fastest_repair(make(20000))
    assert large < 10
    assert large / small < 24, (small, large)


def test_xpath_of_a_finding_among_many_siblings():
    text = ('<robot name="r">\n' + '<link name="a"/>\n' * 1000 + '<link name="b"\n'
            + '<link name="c"/>\n' * 5 + "</robot>\n")
    fixed, problems = repair(text, "x.urdf")
    assert [(rule, f.loc.line) for rule, f in problems] == [
        ("xml.missing-close-bracket", 1002), ("xml.unclosed-tag", 1002)]
    element = etree.fromstring(fixed.encode())[1000]
    assert element.get("name") == "b" and element.sourceline == 1002
    assert element.getroottree().getpath(element) == "/robot/link[1001]"
    assert {f.loc.element for _, f in problems} == {"/robot/link[1001]"}


def test_repair_budget_is_bounded_and_said():
    text = '<robot name="r">\n' + '<link name=a/>\n' * 500 + "</robot>\n"
    _, problems = repair(text, "x.urdf")
    repaired = [r for r, _ in problems if r != "xml.syntax"]
    assert repaired == ["xml.bad-attribute"] * xmlrepair.MAX_REPAIRS
    syntax = [f.message for r, f in problems if r == "xml.syntax"]
    assert "stopped" in syntax[0] and len(syntax) == 2  # the budget note, the parser's leftover


def test_check_on_pathological_files_gives_diagnostics_not_tracebacks(write):
    for name, text in PATHOLOGICAL.items():
        report = check_file(write(text, f"{name}.urdf"))
        assert any(d.rule.startswith("xml.") for d in report.diagnostics), name
