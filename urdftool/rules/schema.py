"""Rules of the `schema` family: the document checked against the URDF spec.

The spec is data, ``urdftool/schemas/urdf.json`` (also visible as ``schemas/`` at the repository
root): for every element its attributes (type, required, since which URDF version), its children
and how often each may appear. This module only interprets that table. One walk over the
document (``robot.root``, after xacro expansion) collects the findings of every schema rule; each
rule reports its share.

What is not URDF but is documented by a consumer (PyBullet's ``<contact>`` in a link, its
``group``/``mask``/``concave`` on a collision, ``<ros2_control>``, ``<gazebo>`` blocks which hold
SDF) is in the table and accepted. Namespaced or prefixed elements and attributes
(``xmlns:drake``, ``<drake:...>``, ``xacro:`` leftovers) are somebody else's extension: skipped.

Severity is graded by consequence: an unknown element or attribute that looks like a typo of an
allowed name (``ryp`` for ``rpy``) is a warning; one that resembles nothing URDF knows is probably
some tool's extension and only an info; an unknown geometry, which urdfdom rejects, is an error.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from urdftool.findings import Finding, Loc
from urdftool.rules import rule

SCHEMA_PATH = Path(__file__).resolve().parent.parent / "schemas" / "urdf.json"

_schema: dict | None = None


def schema() -> dict:
    """The spec table (loaded once)."""
    global _schema
    if _schema is None:
        with open(SCHEMA_PATH, encoding="utf-8") as handle:
            table = json.load(handle)
        for definition in table["elements"].values():
            children = {n: _child_spec(c) for n, c in definition.get("children", {}).items()}
            definition["children"] = children
            definition["_required"] = [n for n, c in children.items() if c.get("required")]
            definition.setdefault("attributes", {})
            definition["_required_attributes"] = [
                (n, a) for n, a in definition["attributes"].items()
                if a.get("required") and not a.get("reported_by")]
        table["_allowed_in"] = _allowed_in(table)
        _schema = table
    return _schema


def _child_spec(spec) -> dict:
    return {"ref": spec} if isinstance(spec, str) else spec


def _allowed_in(table: dict) -> dict[str, list[str]]:
    """Element name -> the parent element names where URDF (not an extension) allows it."""
    elements = table["elements"]
    tags: dict[str, set[str]] = {table["root"]: {table["root"]}}
    for definition in elements.values():
        for name, spec in definition.get("children", {}).items():
            tags.setdefault(_child_spec(spec)["ref"], set()).add(name)
    allowed: dict[str, set[str]] = {}
    for def_id, definition in elements.items():
        if definition.get("open") or def_id.startswith(("pybullet", "ros2_control")):
            continue
        for name, spec in definition.get("children", {}).items():
            spec = _child_spec(spec)
            if spec.get("extension") or elements[spec["ref"]].get("open"):
                continue
            allowed.setdefault(name, set()).update(tags.get(def_id, ()))
    return {name: sorted(parents) for name, parents in allowed.items()}


# -- values -------------------------------------------------------------------------------------

_NUMBER_RE = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_INT_RE = re.compile(r"[+-]?\d+")
_VERSION_RE = re.compile(r"(?<!\d)\d+\.\d+")
_NONFINITE = {"nan", "+nan", "-nan", "inf", "+inf", "-inf", "infinity", "+infinity", "-infinity"}


def number_problem(text: str) -> str | None:
    """Why ``text`` is not a number urdfdom accepts (None if it is one).

    urdfdom reads C-locale decimals: leading blanks are fine, trailing ones are not; nan and inf
    are rejected."""
    body = text.lstrip()
    if _NUMBER_RE.fullmatch(body):
        return None
    stripped = body.strip()
    if not stripped:
        return "is empty"
    if stripped.lower() in _NONFINITE:
        return "is not a finite number (urdfdom rejects nan and inf)"
    if _NUMBER_RE.fullmatch(stripped):
        return "has a trailing blank, which urdfdom rejects"
    if "${" in stripped or "$(" in stripped:
        return "is an unexpanded xacro expression"
    if "," in stripped and all(_NUMBER_RE.fullmatch(p.strip()) for p in stripped.split(",")):
        return "uses a comma; write a decimal point"
    return "is not a number"


def vector_problem(text: str, size: int) -> str | None:
    """Why ``text`` is not ``size`` numbers separated by spaces (None if it is)."""
    parts = text.split()
    for index, part in enumerate(parts):
        problem = number_problem(part)
        if problem is not None:
            if "," in part:
                return f"component {part!r} contains a comma: separate the numbers with spaces"
            return f"component {index + 1} ({part!r}) {problem}"
    if len(parts) != size:
        return f"has {len(parts)} number{'s' if len(parts) != 1 else ''}, {size} expected"
    return None


def rgba_problem(text: str) -> str | None:
    problem = vector_problem(text, 4)
    if problem is not None:
        return problem
    outside = [p for p in text.split() if not 0.0 <= float(p) <= 1.0]
    if outside:
        return (f"has {', '.join(outside)} outside [0, 1] (colours are fractions, not 0-255; "
                "urdfdom rejects the colour)")
    return None


def _rgba_from_255(text: str) -> str | None:
    """A 0-255 colour on the [0, 1] scale (alpha kept when it already is a fraction), or None
    when ``text`` is not four numbers in [0, 255] with a colour component above 1."""
    try:
        values = [float(p) for p in text.split()]
    except ValueError:
        return None
    if len(values) != 4 or not all(0.0 <= v <= 255.0 for v in values) \
            or not any(v > 1.0 for v in values[:3]):
        return None
    from urdftool.edits import number

    alpha = values[3] / 255.0 if values[3] > 1.0 else values[3]
    return " ".join(number(round(v / 255.0, 6)) for v in values[:3]) + " " + number(alpha)


def _version_tuple(text: str | None) -> tuple[int, int] | None:
    if text is None:
        return (1, 0)
    if not _VERSION_RE.fullmatch(text.strip()):
        return None
    major, minor = text.strip().split(".")
    return int(major), int(minor)


# -- the walk -----------------------------------------------------------------------------------


def _close_match(name: str, candidates: list[str]) -> str | None:
    """The allowed name ``name`` is most probably a typo of (case, one swapped or wrong letter).
    Memoised: the same unknown names recur in every file of a corpus."""
    key = (name, tuple(candidates))
    if key not in _CLOSE:
        _CLOSE[key] = _find_close_match(name, candidates)
    return _CLOSE[key]


_CLOSE: dict[tuple, str | None] = {}
# definition id -> (the table's elements, the definition, and what visit() asks of it)
_PLANS: dict[str, tuple] = {}


def _find_close_match(name: str, candidates: list[str]) -> str | None:
    import difflib  # only when something is unknown: keeps start-up lean
    for candidate in candidates:
        if candidate.lower() == name.lower():
            return candidate
    matches = difflib.get_close_matches(name, candidates, n=1, cutoff=0.6)
    if not matches:
        return None
    ratio = difflib.SequenceMatcher(None, name, matches[0]).ratio()
    # Short names differ by a letter at ratio ~0.67; long names must be closer.
    if len(name) > 5 and ratio < 0.75:
        return None
    return matches[0]


class _Walk:
    """One pass over the document; findings grouped by rule id."""

    def __init__(self, robot):
        self.robot = robot
        self.table = schema()
        self.elements = self.table["elements"]
        self.findings: dict[str, list[Finding]] = {}
        self.xacro_tags = set(self.table["xacro_tags"]["names"])
        self.version: tuple[int, int] | None = (1, 0)
        self._old_xacro: set | None = None

    def old_xacro(self, element) -> bool:
        """Whether the xacro family reports this element as unexpanded old-style xacro."""
        if self._old_xacro is None:
            from urdftool.rules.xacro import unexpanded_xacro

            self._old_xacro = set(unexpanded_xacro(self.robot))
        return element in self._old_xacro

    def add(self, rule_id: str, message: str, loc, hint: str | None = None,
            severity: str | None = None, edits: tuple = ()) -> None:
        """Record a finding; ``loc`` is a Loc or a function giving one (computed only here)."""
        if callable(loc):
            loc = loc()
        self.findings.setdefault(rule_id, []).append(Finding(message, loc, hint, severity, edits))

    def rename(self, element, old: str, new: str) -> tuple:
        """Edits renaming ``element`` (written <old>) to <new> where it was written."""
        from urdftool.edits import rename_element

        return rename_element(self.robot.source.texts, self.robot.loc(element), old, new)

    def attr_loc(self, element, name: str) -> Loc:
        """The element's place, moved to the attribute (on whichever line of its start tag it
        is written)."""
        from urdftool.edits import attribute_loc

        return attribute_loc(self.robot.source.texts, self.robot.loc(element), (), name)

    # -- entry ----------------------------------------------------------------------------------

    def run(self) -> dict[str, list[Finding]]:
        root = self.robot.root
        if root is None or self.robot.source.kind == "sdf" or not isinstance(root.tag, str):
            return self.findings
        if root.tag != self.table["root"]:
            self.add("schema.unknown-element",
                     f"the root element is <{root.tag}>; a URDF document is one <robot> element",
                     self.robot.loc(root), hint='write <robot name="..."> ... </robot>',
                     severity="error")
            return self.findings
        self.version = _version_tuple(root.get("version"))
        self.visit(root, self.table["root"])
        return self.findings

    # -- one element ----------------------------------------------------------------------------

    def visit(self, element, def_id: str, tag: str | None = None) -> None:
        plan = _PLANS.get(def_id)
        if plan is None or plan[0] is not self.elements:
            definition = self.elements[def_id]
            plan = _PLANS[def_id] = (
                self.elements, definition, bool(definition.get("open")),
                bool(definition["_required_attributes"]) or "required_when" in definition,
                definition.get("text"), bool(definition["_required"] or definition.get("shape")))
        _, definition, is_open, always_attributes, text, always_children = plan
        if is_open:
            return
        if tag is None:
            tag = element.tag
        attributes = element.attrib
        if always_attributes or attributes:
            self.check_attributes(element, tag, definition, attributes)
        if text:
            self.check_text(element, tag, text)
        if always_children or len(element):
            self.check_children(element, tag, definition)

    def check_attributes(self, element, tag: str, definition: dict, attributes) -> None:
        allowed = definition["attributes"]
        for name, value in attributes.items():
            spec = allowed.get(name)
            if spec is None:
                if name.startswith("{") or ":" in name:
                    continue
                if not definition.get("open_attributes"):
                    self.unknown_attribute(element, tag, name, allowed)
                continue
            if "since" in spec:
                self.check_since(spec, f"attribute {name!r} of <{tag}>",
                                 lambda name=name: self.attr_loc(element, name))
            kind = spec.get("type", "string")
            if kind == "string" or (kind == "float" and _NUMBER_RE.fullmatch(value.lstrip())):
                continue  # check_value's common cases, without the call
            self.check_value(element, tag, name, value, spec)
        for name, spec in definition["_required_attributes"]:
            if name not in attributes:
                self.missing_attribute(element, tag, name, spec)
        for group in definition.get("exclusive", ()):
            given = [name for name in group if name in attributes]
            if len(given) > 1:
                self.add("schema.bad-value",
                         f"<{tag}> gives both {' and '.join(given)}: urdfdom rejects it "
                         "(use one or the other)", lambda g=given: self.attr_loc(element, g[-1]),
                         hint=f"remove {given[-1]}= or {given[0]}=")
        if "required_when" not in definition:
            return
        parent = element.getparent()
        for condition in definition["required_when"]:
            needed = _version_tuple(condition["since"])
            if self.version is None or needed is None or self.version < needed:
                continue
            if parent is None or parent.get("type") not in condition["parent_type"]:
                continue
            for name in condition["attributes"]:
                if name not in element.attrib:
                    self.add("schema.missing-attribute",
                             f"<{tag}> of {parent.get('type')} joint '{parent.get('name')}' has "
                             f"no {name!r}: {condition['hint']}", self.robot.loc(element),
                             hint=f'add {name}="..."')

    def unknown_attribute(self, element, tag: str, name: str, allowed: dict) -> None:
        candidates = [a for a in allowed if a not in element.attrib]
        match = _close_match(name, candidates)
        names = ", ".join(a for a, s in allowed.items() if not s.get("extension")) or "none"
        loc = self.attr_loc(element, name)
        if match:
            from urdftool.edits import rename_attribute

            self.add("schema.unknown-attribute",
                     f"unknown attribute {name!r} on <{tag}>; did you mean {match!r}? "
                     f"(parsers ignore {name!r}, so {match!r} keeps its default)",
                     loc, hint=f"rename {name}= to {match}=",
                     edits=rename_attribute(self.robot.source.texts, self.robot.loc(element),
                                            (tag,), name, match))
        else:
            self.add("schema.unknown-attribute",
                     f"attribute {name!r} is not part of <{tag}> in URDF (allowed: {names}); "
                     "URDF parsers ignore it",
                     loc, hint="remove it, or keep it if a tool you use reads it", severity="info")

    def missing_attribute(self, element, tag: str, name: str, spec: dict) -> None:
        hint = f'add {name}="..."'
        text = (element.text or "").strip()
        if text and len(element.attrib) == 0 and number_problem(text) is None:
            hint = f'URDF writes <{tag} {name}="{text}"/>; text content is SDF syntax'
        what = {"link": "the link's name", "name": "a name"}.get(name, repr(name))
        self.add("schema.missing-attribute", f"<{tag}> has no {name!r} attribute "
                 f"(required: {what})", self.robot.loc(element), hint=hint)

    def check_value(self, element, tag: str, name: str, value: str, spec: dict) -> None:
        kind = spec.get("type", "string")
        if kind == "string" or (kind == "float" and _NUMBER_RE.fullmatch(value.lstrip())):
            return  # the common cases, without building the message parts
        if kind in ("vec3", "vec4"):
            parts = value.split()
            if len(parts) == (3 if kind == "vec3" else 4) and all(map(_NUMBER_RE.fullmatch, parts)):
                return
        where = f"{name}={value!r} on <{tag}>"

        def loc() -> Loc:
            return self.attr_loc(element, name)

        if kind == "float":
            problem = number_problem(value)
            if problem:
                self.add("schema.bad-number", f"{where} {problem}", loc,
                         hint=f"write a plain decimal number, e.g. {name}=\"0.5\"")
        elif kind in ("vec3", "vec4"):
            size = 3 if kind == "vec3" else 4
            problem = vector_problem(value, size)
            if problem:
                example = " ".join(["0"] * size)
                self.add("schema.bad-vector", f"{where} {problem}", loc,
                         hint=f'write {size} numbers separated by spaces, e.g. {name}="{example}"')
        elif kind == "rgba":
            problem = rgba_problem(value)
            if problem:
                hint, edits = 'write red, green, blue and alpha in [0, 1], e.g. rgba="1 0.5 0 1"', ()
                scaled = _rgba_from_255(value)
                if scaled is not None:
                    from urdftool.rules import value_edits

                    edits, note = value_edits(self.robot, self.robot.loc(element), (tag,),
                                              {name: scaled})
                    hint = f'write rgba="{scaled}" (0-255 scaled to [0, 1]){note}'
                self.add("schema.bad-rgba", f"{where} {problem}", loc, hint=hint, edits=edits)
        elif kind == "int":
            if not _INT_RE.fullmatch(value.lstrip()):
                self.add("schema.bad-value", f"{where} is not an integer", loc)
        elif kind == "enum":
            values = spec["values"]
            if value in values:
                return
            extension = spec.get("extension_values", {}).get(value)
            if extension:
                self.add("schema.bad-value", f"{where}: {value!r} is {extension}", loc,
                         hint=f"use one of {', '.join(values)}")
                return
            match = _close_match(value, values)
            self.add("schema.bad-value",
                     f"{where} is not one of {', '.join(values)}"
                     + (f"; did you mean {match!r}?" if match else ""),
                     loc, hint=f'write {name}="{match}"' if match else f"use one of {', '.join(values)}")
        elif kind == "version":
            version = _version_tuple(value)
            if version is None or value.strip() not in self.table["versions"]:
                self.add("schema.bad-value",
                         f"{where}: urdfdom reads URDF versions "
                         f"{', '.join(self.table['versions'])} ('x.y') and rejects the robot",
                         loc, hint='write version="1.0" (or leave it out)')

    def check_since(self, spec: dict, what: str, loc) -> None:
        since = spec.get("since")
        if not since or self.version is None:
            return
        needed = _version_tuple(since)
        if needed is not None and self.version < needed:
            have = ".".join(map(str, self.version))
            self.add("schema.needs-version",
                     f"{what} needs URDF {since}, but this robot is version {have}: urdfdom "
                     "ignores it", loc,
                     hint=f'add version="{since}" to <robot>')

    def check_text(self, element, tag: str, kind: str) -> None:
        if kind != "float":
            return
        text = element.text or ""
        problem = number_problem(text.strip()) if text.strip() else "is empty"
        if problem:
            self.add("schema.bad-number", f"<{tag}>{text.strip()}</{tag}>: the value {problem}",
                     self.robot.loc(element), hint=f"write <{tag}>1.0</{tag}>")

    def check_children(self, element, tag: str, definition: dict) -> None:
        children = definition["children"]
        shape = definition.get("shape")
        counts: dict[str, int] = {}  # a plain dict: a Counter costs ~1 us per element
        first_shape = None
        for child in element:
            child_tag = child.tag
            if not isinstance(child_tag, str) or child_tag.startswith("{") or ":" in child_tag:
                if shape and first_shape is None and isinstance(child_tag, str):
                    first_shape = child  # urdfdom takes the first element, whatever it is
                continue
            spec = children.get(child_tag)
            if shape:
                if first_shape is None:
                    first_shape = child
                    if spec is None:
                        self.unknown_shape(child, child_tag, children)
                        continue
                elif spec is not None:
                    first = first_shape.tag
                    self.add("schema.duplicate-element",
                             f"<{tag}> holds one shape: parsers use the first one (<{first}>) "
                             f"and ignore this <{child_tag}>", self.robot.loc(child),
                             hint=f"put the <{child_tag}> in its own <{element.getparent().tag}>"
                             if element.getparent() is not None else None)
                    continue
            if spec is None:
                if child_tag in self.xacro_tags or definition.get("open_children") \
                        or self.old_xacro(child):
                    continue
                self.unknown_child(element, tag, child, child_tag, definition, counts)
                continue
            count = counts[child_tag] = counts.get(child_tag, 0) + 1
            if spec.get("max") and count > spec["max"]:
                self.add("schema.duplicate-element",
                         f"a second <{child_tag}> in <{tag}>: parsers read the first one and "
                         "ignore this one", self.robot.loc(child),
                         hint=f"merge the two <{child_tag}> elements or remove one")
                continue
            if "since" in spec:
                self.check_since(spec, f"<{child_tag}>", lambda child=child: self.robot.loc(child))
            if spec.get("portable") is False:
                self.add("schema.vendor-extension",
                         f"<{child_tag}> in <{tag}> is a {spec.get('extension', 'vendor')} "
                         "extension: other URDF parsers (urdfdom: ROS, check_urdf, pinocchio) "
                         "reject it", self.robot.loc(child),
                         hint="keep this file for that simulator, or use a standard shape")
            self.visit(child, spec["ref"], child_tag)
        if shape and first_shape is None:
            shapes = ", ".join(f"<{n}>" for n, s in children.items()
                               if not _child_spec(s).get("extension"))
            self.add("schema.missing-element",
                     f"<{tag}> has no shape: urdfdom rejects the "
                     f"{element.getparent().tag if element.getparent() is not None else tag}",
                     self.robot.loc(element), hint=f"add one of {shapes}")
        for name in definition["_required"]:
            if not counts.get(name):
                self.add("schema.missing-element", f"<{tag}> has no <{name}> (required)",
                         self.robot.loc(element), hint=f"add a <{name}> element")

    def unknown_shape(self, child, child_tag: str, children: dict) -> None:
        shapes = [n for n, s in children.items() if not _child_spec(s).get("extension")]
        match = _close_match(child_tag, shapes)
        sdf_hint = self.table["sdf_elements"].get(child_tag)
        message = (f"unknown geometry <{child_tag}>: urdfdom rejects the shape "
                   "(\"Unknown geometry type\") and drops it")
        if match:
            message += f"; did you mean <{match}>?"
        self.add("schema.unknown-element", message, self.robot.loc(child),
                 hint=f"write <{match} .../>" if match else
                 (sdf_hint or f"use one of {', '.join('<' + s + '>' for s in shapes)}"),
                 severity="error", edits=self.rename(child, child_tag, match) if match else ())

    def unknown_child(self, element, tag: str, child, child_tag: str, definition: dict,
                      counts: dict[str, int]) -> None:
        children = definition.get("children", {})
        loc = self.robot.loc(child)
        ignored = definition.get("ignored_children", {}).get(child_tag)
        if ignored:
            self.add("schema.misplaced-element", f"<{child_tag}> in <{tag}>: {ignored}", loc,
                     hint=f"remove the <{child_tag}>", severity="info")
            return
        sdf_hint = self.table["sdf_elements"].get(child_tag)
        if sdf_hint:
            readers = _READ_BY.get((tag, child_tag))
            self.add("schema.sdf-element",
                     f"<{child_tag}> in <{tag}> is SDF, not URDF: " + (
                         f"{readers[0]}; {readers[1]} ignore it" if readers
                         else "URDF parsers ignore it"),
                     loc, hint=sdf_hint)
            return
        belongs = self.table["_allowed_in"].get(child_tag)
        if belongs and tag not in belongs:
            where = " or ".join(f"<{p}>" for p in belongs)
            self.add("schema.misplaced-element",
                     f"<{child_tag}> is not allowed in <{tag}> (it belongs in {where}): "
                     "parsers ignore it here", loc,
                     hint=f"move it into {where}")
            return
        candidates = []
        for name, spec in children.items():
            spec = _child_spec(spec)
            if spec.get("max") == 1 and (counts.get(name) or element.find(name) is not None):
                continue
            candidates.append(name)
        match = _close_match(child_tag, candidates)
        if match:
            self.add("schema.unknown-element",
                     f"unknown element <{child_tag}> in <{tag}>; did you mean <{match}>? "
                     "(parsers ignore it)", loc, hint=f"rename <{child_tag}> to <{match}>",
                     edits=self.rename(child, child_tag, match))
            return
        legacy = self.table["legacy_elements"].get(child_tag)
        edits = ()
        if legacy and child_tag in _LEGACY_RENAMES:  # pre-1.0 name of a URDF element
            new = _LEGACY_RENAMES[child_tag]
            if new in children and element.find(new) is None:
                edits = self.rename(child, child_tag, new)
        names = ", ".join(f"<{n}>" for n, s in children.items()
                          if not _child_spec(s).get("extension")) or "none"
        self.add("schema.unknown-element",
                 f"<{child_tag}> is not part of <{tag}> in URDF (allowed: {names}); "
                 "URDF parsers ignore it", loc,
                 hint=legacy or "remove it, or keep it if a tool you use reads it",
                 severity="info", edits=edits)


_LEGACY_RENAMES = {"joint_properties": "dynamics"}  # same attributes, new name

_last: tuple[object, dict[str, list[Finding]]] | None = None


def findings(robot, rule_id: str) -> list[Finding]:
    """The findings of ``rule_id`` for ``robot`` (one walk per robot, shared by the rules)."""
    global _last
    if _last is None or _last[0] is not robot:
        _last = (robot, _Walk(robot).run())
    return _last[1].get(rule_id, [])


# -- the rules ----------------------------------------------------------------------------------

_ROBOT = '<robot name="r">\n  <link name="base"/>\n  {}\n</robot>'


@rule("schema.unknown-element", "warning",
      "an element URDF does not define in this place (with did-you-mean)",
      doc="""
URDF parsers skip elements they do not know, so a misspelt element silently loses its content:
`<inertal>` leaves the link without mass, `<orign>` puts the shape at the link origin. When the
name is close to one allowed here (`cvlinder` for `cylinder`) the finding is a **warning** with
the likely name. Inside `<geometry>` it is an **error**: urdfdom rejects a shape it does not know
and drops the visual or collision. An element that resembles nothing in URDF is reported as
**info** only: it is probably an extension some tool reads.

Not reported: elements with a namespace prefix (`<drake:...>`, `<xacro:...>`), the content of
`<gazebo>` (SDF, checked by the gazebo family), extensions PyBullet documents (`<contact>` in a
link, `<plane>`), plugin-specific transmission children, and a root element other than
`<robot>`, which is an error.
""",
      bad=_ROBOT.format('<link name="wheel">\n    <visual>\n      <geometry>\n'
                        '        <cvlinder radius="0.1" length="0.05"/>\n'
                        '      </geometry>\n    </visual>\n  </link>\n'
                        '  <joint name="j" type="fixed"><parent link="base"/>'
                        '<child link="wheel"/></joint>'),
      good=_ROBOT.format('<link name="wheel">\n    <visual>\n      <geometry>\n'
                         '        <cylinder radius="0.1" length="0.05"/>\n'
                         '      </geometry>\n    </visual>\n  </link>\n'
                         '  <joint name="j" type="fixed"><parent link="base"/>'
                         '<child link="wheel"/></joint>'),
      fix="safe")
def unknown_element(robot):
    return findings(robot, "schema.unknown-element")


@rule("schema.unknown-attribute", "warning",
      "an attribute URDF does not define on this element (with did-you-mean)",
      doc="""
An unknown attribute is ignored, and the attribute that was meant keeps its default: with
`<origin ryp="0 0 1.57"/>` the rotation is silently zero. A name close to an allowed one that is
not already present is a **warning** with the likely spelling (`ryp` -> `rpy`, `xvz` -> `xyz`,
`ixv` -> `ixy`); a name unlike anything allowed is **info** (probably read by some other tool).
Namespaced attributes (`drake:...`) and PyBullet's documented `group`, `mask` and `concave` on
`<collision>` are not reported.
""",
      bad=_ROBOT.format('<link name="arm"/>\n  <joint name="j" type="fixed">\n'
                        '    <origin xyz="0 0 0.1" ryp="0 0 1.57"/>\n'
                        '    <parent link="base"/><child link="arm"/>\n  </joint>'),
      good=_ROBOT.format('<link name="arm"/>\n  <joint name="j" type="fixed">\n'
                         '    <origin xyz="0 0 0.1" rpy="0 0 1.57"/>\n'
                         '    <parent link="base"/><child link="arm"/>\n  </joint>'),
      fix="safe")
def unknown_attribute(robot):
    return findings(robot, "schema.unknown-attribute")


@rule("schema.misplaced-element", "warning",
      "a URDF element in a place where it is not allowed",
      doc="""
A URDF element written under the wrong parent is ignored there: `<origin>` directly in a
`<link>` (links have no pose of their own: put it in the visual, collision or inertial),
`<material>` inside `<geometry>` instead of `<visual>`, `<mass>` without its `<inertial>`,
a `<joint>` nested in a `<link>`. The message says where the element belongs.
""",
      bad=_ROBOT.format('<link name="arm">\n    <origin xyz="0 0 0.5"/>\n'
                        '    <visual><geometry><box size="0.1 0.1 1"/></geometry></visual>\n'
                        '  </link>\n  <joint name="j" type="fixed"><parent link="base"/>'
                        '<child link="arm"/></joint>'),
      good=_ROBOT.format('<link name="arm">\n    <visual>\n      <origin xyz="0 0 0.5"/>\n'
                         '      <geometry><box size="0.1 0.1 1"/></geometry>\n    </visual>\n'
                         '  </link>\n  <joint name="j" type="fixed"><parent link="base"/>'
                         '<child link="arm"/></joint>'))
def misplaced_element(robot):
    return findings(robot, "schema.misplaced-element")


# SDF elements some URDF consumer reads after all: (parent, tag) -> (who reads it, who ignores it)
# (checked with Drake's parser: <robot><frame name link xyz rpy/> is a frame fixed to the link)
_READ_BY = {
    ("robot", "frame"): ("Drake's URDF parser reads it (a frame fixed to its link)",
                         ("urdfdom (ROS: robot_state_publisher, rviz, MoveIt), Gazebo, "
                          "PyBullet and pinocchio")),
}


@rule("schema.sdf-element", "warning", "an SDF-only element inside URDF",
      doc="""
SDF and URDF look alike, and SDF elements pasted into a URDF are ignored without a word: a
`<pose>` in a link does not move anything (URDF has no `<pose>`; use `<origin xyz rpy>` on the
inertial/visual/collision, or on the joint), `<gravity>`, `<kinematic>`, `<self_collide>` and
`<surface>` in a link do nothing outside a `<gazebo reference="LINK">` block, `<ixx>` elements
inside `<inertia>` leave the inertia unset. The hint gives the URDF way to say it. Where a
consumer reads such an element after all, the message says which: `<frame name link xyz rpy>`
under `<robot>` is read by Drake's URDF parser (a frame fixed to a link) and ignored by urdfdom
(so by ROS tools), Gazebo, PyBullet and pinocchio.
""",
      bad='<robot name="r">\n  <link name="base">\n    <pose>0 0 0.1 0 0 0</pose>\n'
          '    <visual><geometry><box size="1 1 0.2"/></geometry></visual>\n  </link>\n</robot>',
      good='<robot name="r">\n  <link name="base">\n    <visual>\n'
           '      <origin xyz="0 0 0.1" rpy="0 0 0"/>\n'
           '      <geometry><box size="1 1 0.2"/></geometry>\n    </visual>\n  </link>\n</robot>')
def sdf_element(robot):
    return findings(robot, "schema.sdf-element")


@rule("schema.missing-attribute", "error", "a required attribute is missing",
      doc="""
URDF requires some attributes, and parsers reject the element without them: a link's or
joint's `name`, a joint's `type`, `link` on `<parent>`/`<child>`, `filename` on `<mesh>`,
`size` on `<box>`, `radius` and `length` on `<cylinder>`, all six moments of `<inertia>`,
`effort` and `velocity` on `<limit>` (and `lower`/`upper` of revolute and prismatic joints in
URDF 1.2), `name` on `<material>`. urdfdom drops the element (a visual, an inertial) or rejects
the whole robot (a joint). A `<mimic>` without `joint` and a `<safety_controller>` without
`k_velocity` are reported by `mimic.unknown-joint` and `joint.safety-gains`.
""",
      bad=_ROBOT.format('<link name="arm">\n    <inertial>\n      <mass value="1"/>\n'
                        '      <inertia ixx="0.1" iyy="0.1" izz="0.1"/>\n    </inertial>\n'
                        '  </link>\n  <joint name="j" type="fixed"><parent link="base"/>'
                        '<child link="arm"/></joint>'),
      good=_ROBOT.format('<link name="arm">\n    <inertial>\n      <mass value="1"/>\n'
                         '      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/>\n'
                         '    </inertial>\n  </link>\n  <joint name="j" type="fixed">'
                         '<parent link="base"/><child link="arm"/></joint>'))
def missing_attribute(robot):
    return findings(robot, "schema.missing-attribute")


@rule("schema.missing-element", "error", "a required child element is missing",
      doc="""
Some elements need children: a `<joint>` its `<parent>` and `<child>`, an `<inertial>` its
`<mass>` and `<inertia>`, a `<visual>` or `<collision>` its `<geometry>`, a `<geometry>` one
shape, a `<ros2_control>` its `<hardware>`. Without them urdfdom drops the element or rejects
the robot. (A top-level `<material>` without colour is `material.no-color`.)
""",
      bad=_ROBOT.format('<link name="arm">\n    <collision>\n      <origin xyz="0 0 0.5"/>\n'
                        '    </collision>\n  </link>\n  <joint name="j" type="fixed">'
                        '<parent link="base"/><child link="arm"/></joint>'),
      good=_ROBOT.format('<link name="arm">\n    <collision>\n      <origin xyz="0 0 0.5"/>\n'
                         '      <geometry><box size="0.1 0.1 1"/></geometry>\n'
                         '    </collision>\n  </link>\n  <joint name="j" type="fixed">'
                         '<parent link="base"/><child link="arm"/></joint>'))
def missing_element(robot):
    return findings(robot, "schema.missing-element")


@rule("schema.duplicate-element", "warning",
      "an element that may appear once appears again (the second is ignored)",
      doc="""
A link has at most one `<inertial>`, a joint one `<origin>`, `<axis>`, `<limit>`, ...; a
`<geometry>` holds exactly one shape. Parsers read the first and silently ignore the rest, so
the second `<origin>` or the second shape has no effect. Merge them, or give the extra shape its
own `<visual>`/`<collision>`.
""",
      bad=_ROBOT.format('<link name="arm"/>\n  <joint name="j" type="fixed">\n'
                        '    <origin xyz="0 0 0.1"/>\n    <origin rpy="0 0 1.57"/>\n'
                        '    <parent link="base"/><child link="arm"/>\n  </joint>'),
      good=_ROBOT.format('<link name="arm"/>\n  <joint name="j" type="fixed">\n'
                         '    <origin xyz="0 0 0.1" rpy="0 0 1.57"/>\n'
                         '    <parent link="base"/><child link="arm"/>\n  </joint>'))
def duplicate_element(robot):
    return findings(robot, "schema.duplicate-element")


@rule("schema.bad-number", "error", "a numeric attribute that does not parse as a finite number",
      doc="""
Numbers are C-locale decimals (`0.5`, `-1e-3`, `.5`). urdfdom rejects `nan`, `inf`, a decimal
comma (`0,5`), a trailing blank (`"1 "`), a doubled point (`-1.57.`) and unexpanded xacro
(`${pi/2}` in a plain URDF); depending on the element it drops a visual or inertial or
rejects the whole robot.
""",
      bad=_ROBOT.format('<link name="arm"/>\n  <joint name="j" type="revolute">\n'
                        '    <parent link="base"/><child link="arm"/>\n'
                        '    <limit lower="-1.57." upper="1.57" effort="10" velocity="1"/>\n'
                        '  </joint>'),
      good=_ROBOT.format('<link name="arm"/>\n  <joint name="j" type="revolute">\n'
                         '    <parent link="base"/><child link="arm"/>\n'
                         '    <limit lower="-1.57" upper="1.57" effort="10" velocity="1"/>\n'
                         '  </joint>'))
def bad_number(robot):
    return findings(robot, "schema.bad-number")


@rule("schema.bad-vector", "error", "a vector attribute without the right count of numbers",
      doc="""
`xyz`, `rpy`, `size`, `scale` and `axis` are three numbers separated by spaces (`quat_xyzw`
four). Commas (`"0.07, 0, 0"`), a missing or extra component (`rpy="-3.14 1.57 0 0"`) or
`nan` make urdfdom reject the element, and for a joint origin the whole robot.
""",
      bad=_ROBOT.format('<link name="arm"/>\n  <joint name="j" type="fixed">\n'
                        '    <origin xyz="0.07, 0, 0"/>\n'
                        '    <parent link="base"/><child link="arm"/>\n  </joint>'),
      good=_ROBOT.format('<link name="arm"/>\n  <joint name="j" type="fixed">\n'
                         '    <origin xyz="0.07 0 0"/>\n'
                         '    <parent link="base"/><child link="arm"/>\n  </joint>'))
def bad_vector(robot):
    return findings(robot, "schema.bad-vector")


@rule("schema.bad-rgba", "error", "a colour that is not four numbers in [0, 1]",
      doc="""
`<color rgba="r g b a"/>` takes four fractions between 0 and 1. Colours written as 0-255
(`rgba="255 128 0 1"`) or with three components are rejected by urdfdom and the material is
lost.
""",
      bad='<robot name="r">\n  <material name="orange">\n    <color rgba="255 128 0 1"/>\n'
          '  </material>\n  <link name="base"/>\n</robot>',
      good='<robot name="r">\n  <material name="orange">\n    <color rgba="1 0.5 0 1"/>\n'
           '  </material>\n  <link name="base"/>\n</robot>',
      fix="safe")
def bad_rgba(robot):
    return findings(robot, "schema.bad-rgba")


@rule("schema.bad-value", "error",
      "an attribute outside its allowed values (joint type, URDF version, integers)",
      doc="""
A joint's `type` is one of revolute, continuous, prismatic, fixed, floating, planar (PyBullet
also reads `spherical`, which every urdfdom-based tool rejects); `<robot version>` is 1.0, 1.1
or 1.2; `group`/`mask`/`size`/`rw_rate` are integers. urdfdom rejects the robot otherwise.
""",
      bad=_ROBOT.format('<link name="arm"/>\n  <joint name="j" type="revolut">\n'
                        '    <parent link="base"/><child link="arm"/>\n'
                        '    <limit lower="-1" upper="1" effort="1" velocity="1"/>\n  </joint>'),
      good=_ROBOT.format('<link name="arm"/>\n  <joint name="j" type="revolute">\n'
                         '    <parent link="base"/><child link="arm"/>\n'
                         '    <limit lower="-1" upper="1" effort="1" velocity="1"/>\n  </joint>'))
def bad_value(robot):
    return findings(robot, "schema.bad-value")


@rule("schema.needs-version", "error",
      "a URDF 1.1/1.2 feature in a robot that does not declare that version",
      doc="""
`<capsule>` and `quat_xyzw` came with URDF 1.1, the `acceleration`, `deceleration` and `jerk`
limits with 1.2. In a robot without `version="1.1"` (or later) urdfdom ignores them: a capsule
collision is dropped, a quaternion orientation becomes identity. Declare the version on
`<robot>`.
""",
      bad='<robot name="r">\n  <link name="base">\n    <collision>\n'
          '      <geometry><capsule radius="0.05" length="0.3"/></geometry>\n'
          '    </collision>\n  </link>\n</robot>',
      good='<robot name="r" version="1.1">\n  <link name="base">\n    <collision>\n'
           '      <geometry><capsule radius="0.05" length="0.3"/></geometry>\n'
           '    </collision>\n  </link>\n</robot>')
def needs_version(robot):
    return findings(robot, "schema.needs-version")


@rule("schema.vendor-extension", "info",
      "an element only one simulator reads, which other URDF parsers reject",
      doc="""
PyBullet reads `<plane normal>` and `<cdf filename>` geometries that are not URDF: urdfdom
(ROS, check_urdf, pinocchio, MoveIt) rejects the shape. Fine for a PyBullet-only file; use a
box or a mesh when the robot is shared.
""",
      bad='<robot name="r">\n  <link name="floor">\n    <collision>\n'
          '      <geometry><plane normal="0 0 1"/></geometry>\n    </collision>\n'
          '  </link>\n</robot>',
      good='<robot name="r">\n  <link name="floor">\n    <collision>\n'
           '      <geometry><box size="10 10 0.01"/></geometry>\n    </collision>\n'
           '  </link>\n</robot>')
def vendor_extension(robot):
    return findings(robot, "schema.vendor-extension")
