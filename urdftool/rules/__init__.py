"""The rule registry. A rule is a small function ``(robot) -> iterable of Finding`` in its
family's module, registered with ``@rule`` together with its default severity and its
documentation (what it does, why it matters, a failing and a passing example). The ``rules``
command and the docs are generated from these registrations.

Adding a rule touches one file: its family's module.
"""


import importlib
from collections.abc import Callable, Iterable
from typing import NamedTuple

from urdftool.findings import SEVERITIES, Finding
from urdftool.model import Robot

Check = Callable[[Robot], Iterable[Finding]]  # a rule's function (annotations here are evaluated)

FAMILIES = ("xml", "schema", "structure", "joint", "mimic", "inertia", "geometry", "mesh",
            "material", "gazebo", "transmission", "xacro", "sdf")


class Rule(NamedTuple):
    id: str  # FAMILY.NAME
    severity: str
    summary: str  # one line
    doc: str  # why it matters, what to do
    bad: str  # an example that triggers it
    good: str  # the same example, fixed
    check: Check
    fix: str | None = None  # its findings' edits are "safe" or "unsafe" to apply (None: none)

    @property
    def family(self) -> str:
        return self.id.split(".", 1)[0]


REGISTRY: dict[str, Rule] = {}


def rule(rule_id: str, severity: str, summary: str, *, doc: str = "", bad: str = "", good: str = "",
         fix: str | None = None):
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

    def register(function: Check):
        if rule_id in REGISTRY:
            raise ValueError(f"rule {rule_id} registered twice")
        REGISTRY[rule_id] = Rule(rule_id, severity, summary, doc.strip(), bad.strip(),
                                 good.strip(), function, fix)
        return function

    return register


def source_rule(rule_id: str, severity: str, summary: str, **docs):
    """Register a rule whose findings are recorded while loading (xml repair, xacro errors):
    it reports ``robot.source.problems`` filed under its id."""

    def report_problems(robot: Robot) -> Iterable[Finding]:
        return robot.source.problems_for(rule_id)

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


def did_you_mean(name: str, candidates) -> str | None:
    """The one candidate ``name`` is a slip of: the single nearest by edit distance (a letter
    dropped, added, changed or two swapped count one: rapidfuzz's OSA distance), at most two
    edits (one per eight letters in a longer name) and one per three letters; None when none is
    that near or two are equally near (``joint7`` among ``joint1``..``joint6``). A name whose
    numbers differ is another part, never a slip (``wrist1.dae`` is not ``wrist3.dae``, even
    when it is the only file there: a fix would give one link another's mesh)."""
    import re

    from rapidfuzz.distance import OSA  # only on error paths: keeps start-up lean

    limit = min(max(2, len(name) // 8), (len(name) + 1) // 3)
    best: list[str] = []
    nearest = limit + 1
    numbers = re.findall(r"\d+", name)
    for candidate in dict.fromkeys(candidates):
        if not candidate or candidate == name or re.findall(r"\d+", candidate) != numbers:
            continue
        distance = OSA.distance(name, candidate, score_cutoff=nearest)
        if distance < nearest:
            best, nearest = [candidate], distance
        elif distance == nearest and nearest <= limit:
            best.append(candidate)
    return best[0] if len(best) == 1 else None


def rename_edits(robot: Robot, loc, tag: str, attribute: str, name: str, candidates,
                 joint_of_link: bool = False):
    """(edits, new name, note) naming in ``attribute`` of the ``<tag>`` at ``loc`` the one
    candidate ``name`` is a typo of (``did_you_mean``) or, with ``joint_of_link``, the joint
    that moves link ``name`` (``value_edits``: the note says why a computed value has no
    edit); ((), None, "") when there is no such name."""
    new = None
    if joint_of_link and robot.link(name) is not None:
        parent = robot.parent_joint(name)
        new = parent.name if parent is not None else None
    new = new or did_you_mean(name, candidates)
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
