"""Hover, go to definition, references, document symbols and completion of ``urdftool lsp``.

Two sources, neither of them a second reading of any file:

- the robots of the last check (``engine.Result.checks``): the expanded elements indexed by
  where they were written (``Source.loc``), so a tag under the cursor, in a macro body too, is
  found with its value in every instance: a link's mass, declared inertia and the bound its
  geometry allows (``inertia_table.inertia_data``, the ``inertia`` command's table), a joint's
  limits and mimic image (``limits.mimic_image``), an attribute's expanded value;
- the texts the check read (and the open buffers), scanned for xacro definitions: macros and
  their parameters, properties, arguments, includes.

Only files the last check read are named in answers: under an untrusted workspace, nothing
outside the package roots.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import NamedTuple

from lsprotocol import types as lsp

from urdftool.lsp.engine import resolved
from urdftool.uris import find_parts

_TAG = re.compile(r"<(/?)([\w:.-]+)")
# (linear on any text, issue 21: a name starts where a run of name characters starts; a
# tag's text cannot run past the next '<')
_ATTR = re.compile(r"""(?<![\w:.-])([\w:.-]+)\s*=\s*("([^"]*)"|'([^']*)')""")
_DEFINITION = re.compile(r"<(?:xacro:)(macro|property|arg|include)\b([^<>]*)>")
_NAMED = re.compile(r"<(link|joint)\b([^<>]*)>")
_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
NAME_ATTRIBUTES = {("parent", "link"): "link", ("child", "link"): "link",
                   ("mimic", "joint"): "joint", ("gazebo", "reference"): "any",
                   ("joint", "name"): "joint", ("link", "name"): "link",
                   ("transmission", "joint"): "joint"}
MAX_INSTANCES = 8  # instances of a macro body shown in a hover


class Tag(NamedTuple):
    """The start tag around a position: its name, span, and attributes (name -> (value,
    value start, value end)), offsets in the document's text."""

    name: str
    start: int
    end: int
    attributes: dict[str, tuple[str, int, int]]


class Definition(NamedTuple):
    kind: str  # "macro", "property", "arg", "include", "link", "joint"
    name: str
    path: str
    line: int  # 0-based
    column: int
    end: int  # column of the name's end
    attributes: dict[str, str]


def tag_at(text: str, offset: int) -> Tag | None:
    """The start tag whose text holds ``offset``."""
    start = text.rfind("<", 0, offset + 1)
    if start < 0 or text.startswith("<!--", start) or ">" in text[start:offset]:
        return None
    end = text.find(">", start)
    end = len(text) if end < 0 else end + 1
    match = _TAG.match(text, start)
    if match is None or match.group(1):
        return None
    attributes = {}
    for attribute in _ATTR.finditer(text, match.end(), end):
        group = 3 if attribute.group(3) is not None else 4
        attributes[attribute.group(1)] = (attribute.group(group), attribute.start(group),
                                          attribute.end(group))
    return Tag(match.group(2), start, end, attributes)


def attribute_at(tag: Tag, offset: int) -> str | None:
    for name, (_, start, end) in tag.attributes.items():
        if start <= offset <= end:
            return name
    return None


def word_at(text: str, offset: int) -> tuple[str, int, int] | None:
    for match in _IDENTIFIER.finditer(text, max(0, offset - 200), offset + 200):
        if match.start() <= offset <= match.end():
            return match.group(0), match.start(), match.end()
    return None


def definitions(path: str, text: str) -> list[Definition]:
    """The xacro macros, properties, arguments and includes, links and joints written in a
    file (names as written)."""
    found = []
    starts = _line_starts(text)
    for pattern, prefix in ((_DEFINITION, "xacro"), (_NAMED, "")):
        for match in pattern.finditer(text):
            attributes = {a.group(1): a.group(3) if a.group(3) is not None else a.group(4)
                          for a in _ATTR.finditer(match.group(2))}
            key = "filename" if match.group(1) == "include" else "name"
            if key not in attributes:
                continue
            at = next(a for a in _ATTR.finditer(match.group(2)) if a.group(1) == key)
            offset = match.start(2) + at.start(2) + 1
            line = _line(starts, offset)
            column = offset - starts[line]
            found.append(Definition(match.group(1), attributes[key], path, line, column,
                                    column + len(attributes[key]), attributes))
    return found


def _expressions(text: str):
    """(start, end) of every ``${...}`` and ``$(arg ...)`` in ``text``, in order (``str.find``:
    an unclosed one repeated is looked at once, issue 21)."""
    position = 0
    closed = {"}": True, ")": True}  # a closer not found once is not found later either
    while True:
        start = text.find("$", position)
        if start < 0:
            return
        position = start + 1
        if text.startswith("${", start):
            closer, after = "}", start + 2
        elif text.startswith("$(arg", start) and text[start + 5:start + 6].isspace():
            closer, after = ")", start + 6
        else:
            continue
        end = text.find(closer, after) if closed[closer] else -1
        if end < 0:
            closed[closer] = False
            continue
        yield start, end + 1
        position = end + 1


def _line_starts(text: str) -> list[int]:
    return [0] + [m.end() for m in re.finditer("\n", text)]


def _line(starts: list[int], offset: int) -> int:
    from bisect import bisect_right

    return bisect_right(starts, offset) - 1


# -- the state the answers come from ---------------------------------------------------------


class View:
    """The last check's robots and texts for one document (its unit), and the document's
    text in the client."""

    def __init__(self, server, uri: str):
        self.server = server
        self.uri = uri
        self.path = server.path_of(uri)
        self.key = resolved(self.path) if self.path else None
        self.text = server.text_of(self.path) if self.path else None
        self.checks = []  # (report, robot) of every check that read the document
        self.texts: dict[str, str] = {}  # resolved path -> text, of every file those read
        self.shown: dict[str, str] = {}  # resolved path -> path as the check named it
        if self.key is None:
            return
        for result in list(server.engine.snapshot.values()):
            for report, robot in result.checks:
                names = {resolved(n): n for n in report.texts}
                if self.key not in names:
                    continue
                self.checks.append((report, robot))
                for key, name in names.items():
                    self.texts.setdefault(key, report.texts[name])
                    self.shown.setdefault(key, name)
        for key in list(self.texts):
            current = server.buffer(key)
            if current is not None:
                self.texts[key] = current
        if self.text is not None:
            self.texts[self.key] = self.text

    def offset(self, position: lsp.Position) -> int | None:
        if self.text is None:
            return None
        lines = self.text.split("\n")
        if position.line >= len(lines):
            return None
        column = self.server.char_column(lines, position)
        return sum(len(line) + 1 for line in lines[:position.line]) + column

    def line_of(self, offset: int) -> int:
        return self.text.count("\n", 0, offset)

    def definitions(self) -> list[Definition]:
        found = []
        for key, text in self.texts.items():
            found.extend(definitions(key, text))
        return found

    def location(self, path: str, line: int, column: int = 0, end: int | None = None):
        lines = (self.texts.get(resolved(path)) or "").split("\n")
        start = self.server.position(lines, line, column)
        stop = self.server.position(lines, line, end if end is not None else column)
        return lsp.Location(self.server.uri_of(path), lsp.Range(start, stop))

    def elements(self, tag: Tag) -> list[tuple[object, object]]:
        """(robot, expanded element) of every instance of the tag at the cursor."""
        line = self.line_of(tag.start) + 1
        name = tag.name.split(":", 1)[-1] if tag.name.startswith("xacro:") else tag.name
        found = []
        for _, robot in self.checks:
            if robot is None or robot.root is None:
                continue
            for element in _index(robot).get((self.key, line), ()):
                if element.tag == name:
                    found.append((robot, element))
        return found


_INDEXES: dict[int, tuple[object, dict]] = {}


def _index(robot) -> dict[tuple[str, int], list]:
    """(resolved path, line) -> the expanded elements written there, per robot (memoised for
    the last robots asked)."""
    known = _INDEXES.get(id(robot))
    if known is not None and known[0] is robot:
        return known[1]
    index: dict[tuple[str, int], list] = {}
    paths: dict[str, str] = {}
    for element in robot.root.iter():
        if not isinstance(element.tag, str):
            continue
        loc = robot.source.loc(element)
        if loc.line is None:
            continue
        key = paths.get(loc.path)
        if key is None:
            key = paths[loc.path] = resolved(loc.path)
        index.setdefault((key, loc.line), []).append(element)
    if len(_INDEXES) > 16:
        _INDEXES.clear()
    _INDEXES[id(robot)] = (robot, index)
    return index


# -- hover -----------------------------------------------------------------------------------


def _number(value, digits: int = 6) -> str:
    """As the CLI's tables show it (``display.number``: ``limits`` 6 significant digits)."""
    from urdftool.display import number

    return number(value, digits, "—")


def _inertia_number(value) -> str:
    """As ``urdftool inertia`` shows it (4 significant digits)."""
    return _number(value, 4)


def link_hover(robot, name: str) -> str | None:
    link = robot.link(name)
    if link is None:
        return None
    from urdftool.inertia_table import inertia_data

    lines = [f"**link** `{name}`"]
    try:
        rows = inertia_data(robot, link=name)["links"]
    except Exception:  # noqa: BLE001 - a hover without the numbers, never a failed request
        rows = []
    row = rows[0] if rows else None
    inertial = link.inertial
    if inertial is None:
        lines.append("no `<inertial>`: massless for a simulator")
    elif row is not None:
        lines.append(f"mass: {_inertia_number(row['mass'])} kg")
        declared = row.get("declared")
        if declared:
            lines.append("declared inertia (kg·m²): " + ", ".join(
                f"{k} {_inertia_number(v)}" for k, v in declared.items()))
        geometry = row.get("geometry")
        if geometry and geometry.get("tensor"):
            lines.append(f"from the {geometry['from']} geometry at this mass: " + ", ".join(
                f"{k} {_inertia_number(v)}" for k, v in geometry["tensor"].items()))
        bound = row.get("bound")
        if bound:
            lines.append(f"largest moment the geometry allows about {bound['axis']}: "
                         f"{_inertia_number(bound['bound'])} (mass × reach² = reach "
                         f"{_inertia_number(bound['reach'])} m); declared {_inertia_number(bound['moment'])}, "
                         f"ratio {_inertia_number(bound['ratio'])}")
    parent = robot.parent_joint(name)
    if parent is not None:
        lines.append(f"child of `{parent.parent}` through joint `{parent.name}` ({parent.type})")
    return "  \n".join(lines)


def joint_hover(robot, name: str) -> str | None:
    joint = robot.joint(name)
    if joint is None:
        return None
    lines = [f"**joint** `{name}`: {joint.type}, `{joint.parent}` → `{joint.child}`"]
    if joint.axis is not None:
        lines.append("axis: " + " ".join(_number(v) for v in joint.axis))
    if joint.limit is not None:
        limit = joint.limit
        lines.append(f"limits: lower {_number(limit.lower)}, upper {_number(limit.upper)}, "
                     f"effort {_number(limit.effort)}, velocity {_number(limit.velocity)}")
    if joint.mimic is not None:
        from urdftool.ranges import mimic_image

        mimic = joint.mimic
        lines.append(f"mimics `{mimic.joint}`: multiplier {_number(mimic.multiplier)}, "
                     f"offset {_number(mimic.offset)}")
        image = mimic_image(robot, joint)
        if image is not None:
            verdict = "" if image.follower_range is None else \
                (" — outside this joint's limits" if image.violates else " — inside its limits")
            lines.append(f"image of `{image.leader.name}`'s range "
                         f"[{_number(image.leader_range[0])}, {_number(image.leader_range[1])}]:"
                         f" [{_number(image.image[0])}, {_number(image.image[1])}]{verdict}")
    return "  \n".join(lines)


def named_hover(robot, kind: str, name: str) -> str | None:
    if kind in ("link", "any"):
        found = link_hover(robot, name)
        if found is not None:
            return found
    if kind in ("joint", "any"):
        return joint_hover(robot, name)
    return None


def hover(view: View, position: lsp.Position) -> lsp.Hover | None:
    offset = view.offset(position)
    if offset is None:
        return None
    tag = tag_at(view.text, offset)
    if tag is None:
        return None
    attribute = attribute_at(tag, offset)
    parts: list[str] = []
    if tag.name.startswith("xacro:") and tag.name not in (
            "xacro:property", "xacro:macro", "xacro:include", "xacro:arg", "xacro:if",
            "xacro:unless", "xacro:insert_block", "xacro:element", "xacro:attribute"):
        macro = tag.name.split(":", 1)[1]
        for d in view.definitions():
            if d.kind == "macro" and d.name == macro:
                parts.append(f"**macro** `{macro}`: params `{d.attributes.get('params', '')}`"
                             f"  \ndefined in {Path(d.path).name}:{d.line + 1}")
    elif tag.name == "xacro:property" and attribute in ("name", "value"):
        name = tag.attributes.get("name", ("",))[0]
        value = tag.attributes.get("value", (None,))[0]
        parts.append(f"**property** `{name}` = `{value}`" if value is not None
                     else f"**property** `{name}` (a block)")
        if value is not None and "$" in value:
            parts.extend(f"= `{v}`" for v in property_values(view, name))
    else:
        name = _expression_name(view, offset) if attribute is not None else None
        raw = tag.attributes[attribute][0] if attribute is not None else ""
        if name is not None and raw.strip() != "${" + name + "}":
            parts.extend(f"`{name}` = `{v}`" for v in property_values(view, name))
    instances = view.elements(tag)
    seen = set()
    for robot, element in instances[:MAX_INSTANCES]:
        where = robot.source.loc(element)
        via = f" (instance called at {', '.join(where.via)})" if where.via else ""
        text = None
        if attribute is not None:
            kind = NAME_ATTRIBUTES.get((element.tag, attribute))
            value = element.get(attribute)
            if kind is not None and value is not None:
                text = named_hover(robot, kind, value)
            raw = tag.attributes[attribute][0]
            if value is not None and ("${" in raw or "$(" in raw):
                text = (text + "  \n" if text else "") + f"`{attribute}` = `{value}`"
        if text is None and element.tag in ("link", "joint") and element.get("name"):
            text = named_hover(robot, element.tag, element.get("name"))
        if element.tag == "mimic" and element.getparent() is not None:
            follower = joint_hover(robot, element.getparent().get("name"))
            if follower is not None:  # the follower, with the image of the leader's range
                text = follower if text is None else follower + "\n\n" + text
        if text is not None and (text, via) not in seen:
            seen.add((text, via))
            parts.append(text + via)
    if len(instances) > MAX_INSTANCES:
        parts.append(f"… and {len(instances) - MAX_INSTANCES} more instances")
    if not parts:
        return None
    return lsp.Hover(lsp.MarkupContent(lsp.MarkupKind.Markdown, "\n\n---\n\n".join(parts)))


def property_values(view: View, name: str) -> list[str]:
    """The values a property took, read off the expanded robots where an attribute (or one
    whitespace-separated part of it, as in ``xyz="${a} ${b} ${c}"``) is exactly ``${name}``:
    what the expansion wrote there, no second evaluation of xacro."""
    values: list[str] = []
    token = "${" + name + "}"
    for key, text in view.texts.items():
        if token not in text:
            continue
        starts = _line_starts(text)
        for attribute in _ATTR.finditer(text):
            raw = attribute.group(3) if attribute.group(3) is not None else attribute.group(4)
            parts = raw.split()
            if token not in parts:
                continue
            start = text.rfind("<", 0, attribute.start())
            tag = _TAG.match(text, start) if start >= 0 else None
            if tag is None:
                continue
            line = _line(starts, start) + 1
            for _, robot in view.checks:
                if robot is None or robot.root is None:
                    continue
                for element in _index(robot).get((key, line), ()):
                    value = element.get(attribute.group(1))
                    if element.tag != tag.group(2) or value is None:
                        continue
                    written = value.split()
                    if len(written) == len(parts):
                        found = written[parts.index(token)]
                        if found not in values:
                            values.append(found)
            if len(values) >= MAX_INSTANCES:
                return values
    return values


# -- definitions and references --------------------------------------------------------------


def _expression_name(view: View, offset: int) -> str | None:
    """The identifier under the cursor when it is inside ``${...}`` or ``$(arg ...)``."""
    found = word_at(view.text, offset)
    if found is None:
        return None
    opening = view.text.rfind("${", 0, found[1])
    closing = view.text.rfind("}", 0, found[1])
    argument = view.text.rfind("$(arg", 0, found[1])
    if opening >= 0 and opening > closing:
        return found[0]
    if argument >= 0 and ")" not in view.text[argument:found[1]]:
        return found[0]
    return None


def definition(view: View, position: lsp.Position) -> list[lsp.Location] | None:
    offset = view.offset(position)
    if offset is None:
        return None
    tag = tag_at(view.text, offset)
    attribute = attribute_at(tag, offset) if tag is not None else None
    defined = view.definitions()
    found: list[lsp.Location] = []
    if tag is not None and tag.name.startswith("xacro:") and attribute is None:
        macro = tag.name.split(":", 1)[1]
        found = [view.location(d.path, d.line, d.column, d.end) for d in defined
                 if d.kind == "macro" and d.name == macro]
    elif tag is not None and tag.name == "xacro:include" and attribute == "filename":
        found = [lsp.Location(view.server.uri_of(view.shown.get(key, key)),
                              lsp.Range(lsp.Position(0, 0), lsp.Position(0, 0)))
                 for key in _included(view, tag)]
    if not found:
        name = _expression_name(view, offset)
        if name is not None:
            found = _symbol_definitions(view, defined, name, offset)
    if not found and tag is not None and attribute is not None:
        for robot, element in view.elements(tag):
            kind = NAME_ATTRIBUTES.get((element.tag, attribute))
            value = element.get(attribute)
            if kind is None or value is None:
                continue
            for target in _named_elements(robot, kind, value):
                loc = robot.source.loc(target)
                if loc.line is not None:
                    location = view.location(loc.path, loc.line - 1, (loc.column or 1) - 1)
                    if location not in found:
                        found.append(location)
    if not found:
        found = _companion_definition(view, tag, attribute, offset)
    return found or None


# issue 31: the names an SRDF gives (tag, attribute) -> what they name
SRDF_NAMES = {("link", "name"): "link", ("chain", "base_link"): "link",
              ("chain", "tip_link"): "link", ("end_effector", "parent_link"): "link",
              ("virtual_joint", "child_link"): "link", ("disable_collisions", "link1"): "link",
              ("disable_collisions", "link2"): "link", ("enable_collisions", "link1"): "link",
              ("enable_collisions", "link2"): "link", ("disable_default_collisions", "link"): "link",
              ("link_sphere_approximation", "link"): "link", ("joint", "name"): "joint",
              ("passive_joint", "name"): "joint", ("joint_property", "joint_name"): "joint"}


def _companion_definition(view: View, tag, attribute, offset: int) -> list[lsp.Location]:
    """Go-to-definition from a name in a companion file to the robot's link or joint: an SRDF
    (its robot: the one its last check read, ``companion_check.LAST_ROBOTS``), a controllers
    YAML (the robots whose checks read it: a joint name under the cursor)."""
    from urdftool.companion_check import LAST_ROBOTS

    if view.key is None or view.text is None:
        return []
    robots, kinds, name = [], ("link", "joint"), None
    if view.key.endswith((".srdf", ".srdf.xacro")) and tag is not None and attribute:
        robot = LAST_ROBOTS.get(view.key)
        kind = SRDF_NAMES.get((tag.name, attribute))
        if robot is None or kind is None:
            return []
        robots, kinds, name = [robot], (kind,), tag.attributes[attribute][0].strip()
    elif view.key.endswith((".yaml", ".yml")):
        word = word_at(view.text, offset)
        if word is None:
            return []
        name = word[0]
        robots = [robot for result in list(view.server.engine.snapshot.values())
                  for report, robot in result.checks
                  if robot is not None and view.key in report.includes]
        kinds = ("joint",)
    found: list[lsp.Location] = []
    for robot in robots:
        for kind in kinds:
            for target in _named_elements(robot, kind, name):
                loc = robot.source.loc(target)
                if loc.line is None:
                    continue
                lines = (view.server.text_of(loc.path) or "").split("\n")
                start = view.server.position(lines, loc.line - 1, (loc.column or 1) - 1)
                location = lsp.Location(view.server.uri_of(loc.path), lsp.Range(start, start))
                if location not in found:
                    found.append(location)
    return found


def _included(view: View, tag: Tag) -> list[str]:
    """The files the check read that an include's filename names (``$(find pkg)/x`` or a
    relative path): matched by their trailing path, among the files read only."""
    spec = tag.attributes["filename"][0]
    found = find_parts(spec)
    tail = found[1] if found is not None else spec
    if "${" in tail or "$(" in tail:
        tail = Path(tail).name
    tail = tail.lstrip("./")
    return [key for key in view.texts if key != view.key and key.endswith("/" + tail)]


def _symbol_definitions(view: View, defined: list[Definition], name: str,
                        offset: int) -> list[lsp.Location]:
    found = []
    for d in defined:
        if d.kind in ("property", "arg") and d.name == name:
            found.append(view.location(d.path, d.line, d.column, d.end))
    # a parameter of the macro the cursor is in
    before = view.text.rfind("<xacro:macro", 0, offset)
    if before >= 0 and view.text.rfind("</xacro:macro>", 0, offset) < before:
        for d in defined:
            if d.kind == "macro" and d.path == view.key and d.line == view.line_of(before) \
                    and re.search(rf"(^|\s){re.escape(name)}(:=|=|\s|$)",
                                  d.attributes.get("params", "")):
                found.insert(0, view.location(d.path, d.line, d.column, d.end))
    return found


def _named_elements(robot, kind: str, name: str) -> list:
    tags = ("link", "joint") if kind == "any" else (kind,)
    return [e for tag in tags for e in robot.elements(tag) if e.get("name") == name]


def references(view: View, position: lsp.Position) -> list[lsp.Location] | None:
    """Where a link, joint, macro or property is used (and defined)."""
    offset = view.offset(position)
    if offset is None:
        return None
    tag = tag_at(view.text, offset)
    attribute = attribute_at(tag, offset) if tag is not None else None
    found: list[lsp.Location] = []

    def add(location):
        if location not in found:
            found.append(location)

    if tag is not None and tag.name in ("xacro:macro",) and attribute == "name":
        macro = tag.attributes["name"][0]
        for key, text in view.texts.items():
            starts = _line_starts(text)
            for match in re.finditer(rf"<xacro:{re.escape(macro)}\b", text):
                line = _line(starts, match.start())
                add(view.location(key, line, match.start() - starts[line] + 1,
                                  match.end() - starts[line]))
        return found or None
    name = _expression_name(view, offset)
    if name is None and tag is not None and tag.name == "xacro:property" and attribute == "name":
        name = tag.attributes["name"][0]
    if name is not None:
        for key, text in view.texts.items():
            starts = _line_starts(text)
            for first, last in _expressions(text):
                for match in re.finditer(rf"\b{re.escape(name)}\b", text[first:last]):
                    at = first + match.start()
                    line = _line(starts, at)
                    add(view.location(key, line, at - starts[line],
                                      at - starts[line] + len(name)))
        return found or None
    if tag is None or attribute is None:
        return None
    for robot, element in view.elements(tag):
        kind = NAME_ATTRIBUTES.get((element.tag, attribute))
        value = element.get(attribute)
        if kind is None or value is None:
            continue
        for target in [*_named_elements(robot, kind, value), *(
                e for e in robot.root.iter() if isinstance(e.tag, str)
                and any(NAME_ATTRIBUTES.get((e.tag, a)) in (kind, "any")
                        and e.get(a) == value for a in ("link", "joint", "reference")))]:
            loc = robot.source.loc(target)
            if loc.line is not None:
                named = "name" if target.get("name") == value else next(
                    (a for a in ("link", "joint", "reference") if target.get(a) == value), "name")
                add(_name_location(view, loc, target.tag, named, value))
    return found or None


def _name_location(view: View, loc, tag: str, attribute: str, value: str) -> lsp.Location:
    """The range of the name ``value`` written in ``attribute`` of the tag at ``loc`` (issue
    29: references were zero-width); the tag's name when the value is not written there as
    it is (a ``${...}`` expression, an attribute on another line)."""
    line, column = loc.line - 1, (loc.column or 1) - 1
    lines = (view.texts.get(resolved(loc.path)) or "").split("\n")
    text = lines[line] if 0 <= line < len(lines) else ""
    written = re.compile(rf"\b{re.escape(attribute)}\s*=\s*[\"']").search(text, column)
    if written is not None and text.startswith(value, written.end()):
        return view.location(loc.path, line, written.end(), written.end() + len(value))
    start = column + 1 if text.startswith("<", column) else column
    return view.location(loc.path, line, start, start + len(tag))


# -- symbols and completion ------------------------------------------------------------------

_SYMBOL_KIND = {"link": lsp.SymbolKind.Struct, "joint": lsp.SymbolKind.Interface,
                "macro": lsp.SymbolKind.Function, "property": lsp.SymbolKind.Constant,
                "arg": lsp.SymbolKind.Variable, "include": lsp.SymbolKind.File}


def symbols(view: View) -> list[lsp.DocumentSymbol] | None:
    if view.text is None:
        return None
    lines = view.text.split("\n")
    result = []
    for d in definitions(view.key, view.text):
        start = view.server.position(lines, d.line, d.column)
        end = view.server.position(lines, d.line, d.end)
        detail = d.attributes.get("params") if d.kind == "macro" else \
            d.attributes.get("type") if d.kind == "joint" else \
            d.attributes.get("value") if d.kind == "property" else None
        result.append(lsp.DocumentSymbol(
            name=d.name or "?", kind=_SYMBOL_KIND[d.kind], range=lsp.Range(start, end),
            selection_range=lsp.Range(start, end),
            detail=f"{d.kind}" + (f" {detail}" if detail else "")))
    return result


def completion(view: View, position: lsp.Position) -> lsp.CompletionList | None:
    """Link names in ``parent``/``child link=""``, joint names in ``mimic joint=""``, both in
    ``<gazebo reference="">``; macro names after ``<xacro:``, and in a macro call the
    parameters not given yet."""
    offset = view.offset(position)
    if offset is None:
        return None
    line_start = view.text.rfind("\n", 0, offset) + 1
    typed = re.search(r"<xacro:([\w.-]*)$", view.text[line_start:offset])
    if typed is not None:
        items = []
        for d in view.definitions():
            if d.kind == "macro" and d.name not in {i.label for i in items}:
                items.append(lsp.CompletionItem(d.name, kind=lsp.CompletionItemKind.Function,
                                                detail=f"params: {d.attributes.get('params', '')}"))
        return lsp.CompletionList(False, items) if items else None
    tag = tag_at(view.text, offset)
    if tag is None:
        return None
    attribute = attribute_at(tag, offset)
    if attribute is None and tag.name.startswith("xacro:"):  # a macro call's parameters
        items = []
        for d in view.definitions():
            if d.kind == "macro" and d.name == tag.name.split(":", 1)[1]:
                for param in d.attributes.get("params", "").split():
                    name, _, default = param.partition(":=")
                    name = name.partition("=")[0]
                    if name and not name.startswith("*") and name not in tag.attributes \
                            and name not in {i.label for i in items}:
                        items.append(lsp.CompletionItem(
                            name, kind=lsp.CompletionItemKind.Property,
                            detail=f"default {default}" if default else "required",
                            insert_text=f'{name}=""'))
        return lsp.CompletionList(False, items) if items else None
    kind = NAME_ATTRIBUTES.get((tag.name, attribute))
    if kind is None or attribute == "name":
        return None
    names: dict[str, lsp.CompletionItemKind] = {}
    for _, robot in view.checks:
        if robot is None:
            continue
        if kind in ("link", "any"):
            names.update((link.name, lsp.CompletionItemKind.Struct) for link in robot.links
                         if link.name)
        if kind in ("joint", "any"):
            names.update((joint.name, lsp.CompletionItemKind.Interface)
                         for joint in robot.joints if joint.name)
    if not names:
        for d in view.definitions():  # no robot (a xacro error): the names as written
            if d.kind in (("link", "joint") if kind == "any" else (kind,)):
                names.setdefault(d.name, _SYMBOL_KIND[d.kind])
    items = [lsp.CompletionItem(name, kind=k) for name, k in sorted(names.items())]
    return lsp.CompletionList(False, items) if items else None


def register(server, guarded) -> None:
    @server.feature(lsp.TEXT_DOCUMENT_HOVER)
    @guarded
    def on_hover(ls, params: lsp.HoverParams):
        return hover(View(ls, params.text_document.uri), params.position)

    @server.feature(lsp.TEXT_DOCUMENT_DEFINITION)
    @guarded
    def on_definition(ls, params: lsp.DefinitionParams):
        return definition(View(ls, params.text_document.uri), params.position)

    @server.feature(lsp.TEXT_DOCUMENT_REFERENCES)
    @guarded
    def on_references(ls, params: lsp.ReferenceParams):
        return references(View(ls, params.text_document.uri), params.position)

    @server.feature(lsp.TEXT_DOCUMENT_DOCUMENT_SYMBOL)
    @guarded
    def on_symbols(ls, params: lsp.DocumentSymbolParams):
        return symbols(View(ls, params.text_document.uri))

    @server.feature(lsp.TEXT_DOCUMENT_COMPLETION,
                    lsp.CompletionOptions(trigger_characters=['"', ":"]))
    @guarded
    def on_completion(ls, params: lsp.CompletionParams):
        return completion(View(ls, params.text_document.uri), params.position)
