"""The rule registry. A rule is a small function ``(robot) -> iterable of Finding`` in its
family's module, registered with ``@rule`` together with its default severity and its
documentation (what it does, why it matters, a failing and a passing example). The ``rules``
command and the docs are generated from these registrations.

Adding a rule touches one file: its family's module.
"""


import importlib
import time
from collections.abc import Callable, Iterable
from typing import NamedTuple

from urdftool.findings import SEVERITIES, Finding
from urdftool.model import Robot

Check = Callable[[Robot], Iterable[Finding]]  # a rule's function (annotations here are evaluated)

FAMILIES = ("xml", "schema", "structure", "joint", "mimic", "inertia", "geometry", "mesh",
            "material", "gazebo", "transmission", "xacro", "sdf", "srdf", "ros2_control")
# what a rule's function is given: the robot, or a companion file read beside it (issue 31:
# ``companion.Srdf`` for "srdf"; ``companion.Controllers`` for "controllers"; the launch file's
# ``companion.Launch`` for "launch")
SUBJECTS = ("robot", "srdf", "controllers", "launch")


class Rule(NamedTuple):
    id: str  # FAMILY.NAME
    severity: str
    summary: str  # one line
    doc: str  # why it matters, what to do
    bad: str  # an example that triggers it
    good: str  # the same example, fixed
    check: Check
    fix: str | None = None  # its findings' edits are "safe" or "unsafe" to apply (None: none)
    on: str = "robot"  # what ``check`` gives it (``SUBJECTS``)

    @property
    def family(self) -> str:
        return self.id.split(".", 1)[0]


REGISTRY: dict[str, Rule] = {}


def rule(rule_id: str, severity: str, summary: str, *, doc: str = "", bad: str = "", good: str = "",
         fix: str | None = None, on: str = "robot"):
    """Register a rule function under ``rule_id`` (``FAMILY.NAME``). ``fix``: whether the edits
    its findings carry are ``"safe"`` (the intent is unambiguous, nothing beyond the defect
    changes: applied when checking and by ``check --fix``) or ``"unsafe"`` (they change values
    a person chose: only with ``--unsafe-fixes``)."""
    family = rule_id.split(".", 1)[0]
    if family not in FAMILIES or "." not in rule_id:
        raise ValueError(f"rule id {rule_id!r} must be FAMILY.NAME with FAMILY in {FAMILIES}")
    if severity not in SEVERITIES:
        raise ValueError(f"severity {severity!r} of {rule_id}")
    if fix not in (None, "safe", "unsafe"):
        raise ValueError(f"fix {fix!r} of {rule_id}")
    if on not in SUBJECTS:
        raise ValueError(f"subject {on!r} of {rule_id}")

    def register(function: Check):
        if rule_id in REGISTRY:
            raise ValueError(f"rule {rule_id} registered twice")
        REGISTRY[rule_id] = Rule(rule_id, severity, summary, doc.strip(), bad.strip(),
                                 good.strip(), function, fix, on)
        return function

    return register


def source_rule(rule_id: str, severity: str, summary: str, **docs):
    """Register a rule whose findings are recorded while loading (xml repair, xacro errors):
    it reports ``robot.source.problems`` filed under its id."""

    def report_problems(robot: Robot) -> Iterable[Finding]:
        return robot.source.problems_for(rule_id)

    report_problems.from_source = True  # ``run`` reports these first: they only list
    rule(rule_id, severity, summary, **docs)(report_problems)


# whether a run's output shows the edits of unsafe fixes (--fix, --diff, JSON, SARIF, the
# editor): rules whose unsafe edits are costly to derive skip them when not (``check.check_once``
# sets it from ``CheckOptions.unsafe_edits``; the hint is the same either way)
UNSAFE_EDITS = True


def value_edits(robot: Robot, loc, names: tuple[str, ...], values: dict[str, str]):
    """(edits, note) setting attributes of the element written at ``loc`` (its tag one of
    ``names``) where each value was written (``urdftool.edits.value_edit``): all of them, or no
    edit and a note saying why ("fix by hand: computed from `${...}`") to add to the hint."""
    from urdftool.edits import ByHand, value_edit

    edits, notes = [], []
    for attribute, value in values.items():
        made = value_edit(robot.source.texts, loc, names, attribute, value)
        if isinstance(made, ByHand):
            notes.append(str(made))
        elif made is None:
            return (), ""
        else:
            edits.append(made)
    return ((), "; " + "; ".join(notes)) if notes else (tuple(edits), "")


# candidate names a did-you-mean index compares in all (issue 28): a file of N unknown names
# among N defined ones asked N x N comparisons; past this the index suggests nothing more
COMPARISONS = 50_000


class Names:
    """Candidate names for did-you-mean (``did_you_mean``, ``close``), indexed once per rule
    run: by the numbers they hold (a slip keeps its numbers) and by length (an edit distance is
    at least the difference of lengths). Every query pays the candidates it compares out of
    ``COMPARISONS``; a query that would pass it gets no suggestion (``exhausted`` then says so),
    so that a rule's suggestions take linear time whatever the file holds."""

    def __init__(self, names):
        self.names = list(dict.fromkeys(n for n in names if n))
        self.left = COMPARISONS
        self.exhausted = False
        self._groups: dict | None = None

    def _pay(self, count: int) -> bool:
        if count > self.left:
            self.exhausted = True
            return False
        self.left -= count
        return True

    def did_you_mean(self, name: str, exclude=()) -> str | None:
        import re

        from rapidfuzz.distance import OSA  # only on error paths: keeps start-up lean

        if self._groups is None:
            self._groups = {}
            for candidate in self.names:
                key = tuple(re.findall(r"\d+", candidate))
                self._groups.setdefault(key, {}).setdefault(len(candidate), []).append(candidate)
        limit = min(max(2, len(name) // 8), (len(name) + 1) // 3)
        by_length = self._groups.get(tuple(re.findall(r"\d+", name)), {})
        pool = [c for size in range(len(name) - limit, len(name) + limit + 1)
                for c in by_length.get(size, ())]
        if not self._pay(len(pool)):
            return None
        best: list[str] = []
        nearest = limit + 1
        for candidate in pool:
            if candidate == name or candidate in exclude:
                continue
            distance = OSA.distance(name, candidate, score_cutoff=nearest)
            if distance < nearest:
                best, nearest = [candidate], distance
            elif distance == nearest and nearest <= limit:
                best.append(candidate)
        return best[0] if len(best) == 1 else None

    def close(self, name: str, cutoff: float = 0.6) -> str | None:
        """The closest name by ``difflib``'s ratio (at least ``cutoff``), counted as above."""
        import difflib  # only on error paths: keeps start-up lean

        if not self._pay(len(self.names)):
            return None
        found = difflib.get_close_matches(name, self.names, n=1, cutoff=cutoff)
        return found[0] if found else None


def did_you_mean(name: str, candidates, exclude=()) -> str | None:
    """The one candidate ``name`` is a slip of: the single nearest by edit distance (a letter
    dropped, added, changed or two swapped count one: rapidfuzz's OSA distance), at most two
    edits (one per eight letters in a longer name) and one per three letters; None when none is
    that near or two are equally near (``joint7`` among ``joint1``..``joint6``). A name whose
    numbers differ is another part, never a slip (``wrist1.dae`` is not ``wrist3.dae``, even
    when it is the only file there: a fix would give one link another's mesh). ``candidates``:
    a ``Names`` (a rule asking for many names builds one) or any iterable of names;
    ``exclude``: names never suggested (the asking joint's own)."""
    if not isinstance(candidates, Names):
        candidates = Names(candidates)
    exclude = (exclude,) if isinstance(exclude, str) else exclude
    return candidates.did_you_mean(name, exclude)


def rename_edits(robot: Robot, loc, tag: str, attribute: str, name: str, candidates,
                 joint_of_link: bool = False, exclude=()):
    """(edits, new name, note) naming in ``attribute`` of the ``<tag>`` at ``loc`` the one
    candidate ``name`` is a typo of (``did_you_mean``) or, with ``joint_of_link``, the joint
    that moves link ``name`` (``value_edits``: the note says why a computed value has no
    edit); ((), None, "") when there is no such name."""
    new = None
    if joint_of_link and robot.link(name) is not None:
        parent = robot.parent_joint(name)
        new = parent.name if parent is not None else None
    new = new or did_you_mean(name, candidates, exclude)
    if new is None:
        return (), None, ""
    edits, note = value_edits(robot, loc, (tag,), {attribute: new})
    return edits, new, note


def child_loc(robot: Robot, loc, tag: str):
    """Where the first ``<tag>`` child of the element written at ``loc`` was written (found by
    the element path the Loc carries), or None."""
    if robot.root is None or loc is None or not loc.element:
        return None
    try:
        found = robot.root.getroottree().xpath(loc.element + "/" + tag)
    except Exception:  # noqa: BLE001 - an odd path: no child found
        return None
    return robot.loc(found[0]) if found else None


# the end of a xacro.error for an include that could not be read (urdftool.xacro_expand)
INCLUDE_SKIPPED = "skipped, the rest is expanded without it"


def include_failed(robot: Robot) -> bool:
    """Whether an <xacro:include> of this robot could not be read (the rest was expanded)."""
    return any(rule == "xacro.error" and finding.message.endswith(INCLUDE_SKIPPED)
               for rule, finding in robot.source.problems)


def lost(robot: Robot, name: str | None) -> bool:
    """One finding per cause (issue 22.3): whether an undefined ``name`` (of a link, joint,
    frame or model) may be what an include that could not be read defines. In SDF the include
    names its model, so exactly the names in it (and the joints left out with it) are; in xacro
    an include's content is unknown until it is read, so any undefined name may be. That
    include's finding is the one finding: the others are held back until it is read."""
    if name is None:
        return False
    if any(name == key or name.startswith(key + "::") for key in robot.source.lost):
        return True
    return robot.source.kind == "xacro" and include_failed(robot)


class OutOfTime(BaseException):
    """A rule ran past the time ``run`` gave the rules (a BaseException: a rule's own
    ``except Exception`` does not swallow it)."""


class Ran(NamedTuple):
    """One finding of a rule run: the rule, its severity (configured or default), the finding."""

    rule: Rule
    severity: str
    finding: Finding


# where the rules' watchdog may stop a rule (besides the rule's own module): urdftool's own
# analysis and the pure-Python libraries it calls (never a mesh library, the sandboxed reader's pipes or an import)
WATCHED = ("/urdftool/rules/", "/urdftool/physics/links.py", "/urdftool/physics/inertia.py",
           "/urdftool/limits.py", "/urdftool/kinematics/", "/urdftool/model.py",
           "/urdftool/edits.py", "/urdftool/findings.py", "/difflib.py")

# the rule whose finding says that the rules ran out of time (as a file left unread does)
OUT_OF_TIME_RULE = "xacro.limit-exceeded"


def run(robot: Robot, enabled: Iterable[tuple[Rule, str]], seconds: float | None = None,
        debug: bool = False) -> list[Ran]:
    """The one way to run rules (``check``, the language server through it, ``limits``,
    ``inertia``): every rule of ``enabled`` ((rule, severity) pairs, in order; the rules
    that list what reading found first) on ``robot``, inside a budget (issue 28): all of them
    together get ``seconds`` (the file's ``--timeout``; ``source.DEFAULT_TIMEOUT`` when None)
    of CPU time of the thread that runs them, less the time meshes take to read for them
    (``budget.paused``: the mesh reader's own limits bound it). CPU time, not the wall clock:
    a loaded machine (a CI runner, an editor's busy laptop) does not stop a rule that a quiet
    one finishes, and a quadratic rule is stopped all the same. A watchdog stops a rule that
    runs past it, only while the analysis itself runs (``WATCHED`` and the rule's own module:
    never while a mesh is read by its library or the sandboxed reader is waited on). A rule
    that runs out keeps the findings it made and is ONE finding (``OUT_OF_TIME_RULE``, an
    error: the gate must not pass what it did not check) naming it and the rules not run
    after it. A rule that raises is a warning finding naming it (raised again with
    ``debug``); the other rules run."""
    from urdftool import budget

    if seconds is None:
        from urdftool.source import DEFAULT_TIMEOUT

        seconds = DEFAULT_TIMEOUT
    limit = seconds
    paused = budget.paused_total()
    started = time.thread_time()

    def left() -> float:  # the rules' own CPU time left (a mesh read for them does not count)
        return limit - (time.thread_time() - started) + (budget.paused_total() - paused)

    # what reading found first (a list, made while reading): a run out of time still says it
    enabled = sorted(enabled, key=lambda pair: not getattr(pair[0].check, "from_source", False))
    found: list[Ran] = []
    for index, (current, severity) in enumerate(enabled):
        findings: list[Finding] = []
        try:
            if left() <= 0:
                raise OutOfTime
            own = getattr(getattr(current.check, "__code__", None), "co_filename", "")
            with budget.watchdog(left(), OutOfTime, (*WATCHED, own) if own else WATCHED,
                                 due=lambda: left() <= 0):
                findings.extend(current.check(robot))  # (kept as made: an interrupt keeps them)
        except OutOfTime:
            found.extend(Ran(current, severity, f) for f in findings)
            found.append(_out_of_time(robot, current, [r for r, _ in enabled[index + 1:]],
                                      limit))
            return found
        except Exception as exc:  # a rule must never take the whole run down
            if debug:
                raise
            from urdftool.errors import exception_text

            findings.append(Finding(f"internal error in rule {current.id}: "
                                    f"{exception_text(exc)}", None, severity="warning"))
        found.extend(Ran(current, severity, f) for f in findings)
    return found


def _out_of_time(robot: Robot, late: Rule, rest: list[Rule], limit: float | None) -> Ran:
    from urdftool.findings import Loc

    rest_text = (f"the {len(rest)} rule(s) after it were not run ("
                 + ", ".join(r.id for r in rest[:5]) + (", ..." if len(rest) > 5 else "") + ")"
                 if rest else "every other rule was run")
    message = (f"rule {late.id} ran out of time ({limit:g} s of CPU for the rules of this "
               f"file); its findings so far are kept, {rest_text}")
    limit_rule = REGISTRY.get(OUT_OF_TIME_RULE, late)
    path = robot.source.path if robot.source is not None else None
    return Ran(limit_rule, "error", Finding(message, Loc(path, None, None),
                                            hint="raise --timeout, or split the file"))


_loaded = False


def load_all() -> dict[str, Rule]:
    """Import every family module (each registers its rules) and return the registry."""
    global _loaded
    if not _loaded:
        for family in FAMILIES:
            importlib.import_module(f"urdftool.rules.{family}")
        _loaded = True
    return REGISTRY


def selected(rule_id: str, select: Iterable[str] = (), ignore: Iterable[str] = ()) -> bool:
    """Whether a rule is on, given ``--select``/``--ignore`` lists of rule ids or families."""

    def matches(patterns: Iterable[str]) -> bool:
        family = rule_id.split(".", 1)[0]
        return any(p == rule_id or p == family for p in patterns)

    select, ignore = list(select), list(ignore)
    if select and not matches(select):
        return False
    return not matches(ignore)
