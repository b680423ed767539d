"""Rules of the `xacro` family: what xacro reports while expanding, located in the .xacro
source, and old-style xacro usage that modern xacro silently ignores.

Expansion errors are recorded while loading (``urdftool.xacro_expand`` files them under
``xacro.error``); the rule here says what went wrong — undefined property, undefined ``$(arg)``,
undefined macro, bad expression, missing include or package, wrong macro parameters — and how
to fix it. One rule id for all of them: any of them stops the expansion.

Old xacro (ROS Fuerte and earlier) accepted ``<property>``, ``<include>``, ``<macro>`` and macro
calls like ``<smartcar_body/>`` without the ``xacro:`` prefix. xacro 2 copies such elements
through unchanged: nothing is included, no property defined, no macro expanded, and the robot
can come out empty. They survive in the expanded tree, located in the .xacro file.
"""

from __future__ import annotations

import re
from pathlib import Path

from urdftool.findings import Finding
from urdftool.model import Robot
from urdftool.rules import INCLUDE_SKIPPED, include_failed, rule, source_rule
from urdftool.source import FOREIGN_BLOCKS

XACRO_NS = "http://www.ros.org/wiki/xacro"
_HEAD = f'<robot xmlns:xacro="{XACRO_NS}" name="r">\n'

# -- expansion errors --------------------------------------------------------------------------

# patterns as text, compiled on first use (re caches them): only a failed expansion needs them
_PATTERNS: list[tuple[str, str]] = [
    ("unknown-package", r"package '(?P<name>[^']+)' not found"),
    ("missing-include", (
        r"cannot include|cannot read|No such file or directory|matched no files|"
        r"Include tag's filename spec")),
    ("undefined-arg", r"Undefined substitution argument\s*(?P<name>\S+)?"),
    ("undefined-macro", r"unknown macro name:?\s*(?:xacro:)?(?P<name>\S+)"),
    ("macro-parameters", (
        r"Undefined parameters|Invalid parameter|Not enough blocks|Unused block|"
        r"Undefined block|were not set for macro|Undefined property to forward")),
    ("undefined-property", r"name '(?P<name>[^']+)' is not defined"),
    ("yaml-key", r"has no key '(?P<name>[^']+)'"),
    ("bad-expression", (
        r"when evaluating expression|invalid expression|not a boolean expression|"
        r"Use of invalid name|circular variable definition|invalid syntax")),
]

_EXPRESSION = "when evaluating expression '"


def _expressions(text: str) -> tuple[str, list[str]]:
    """(the message before xacro's context, the expressions it was evaluating: innermost
    first). xacro appends ``; when evaluating expression 'EXPR'`` at every level (a property
    read by another expression adds one), and an expression may hold quotes."""
    first = text.find(_EXPRESSION)
    if first < 0:
        return text, []
    pieces = text[first:].split(_EXPRESSION)[1:]
    expressions = []
    for index, piece in enumerate(pieces):
        if index < len(pieces) - 1:
            piece = piece.rstrip().removesuffix(";").rstrip()
        expressions.append(piece.rstrip().removesuffix("'"))
    return text[:first], expressions


def _defined_names(robot: Robot, kind: str) -> list[str]:
    """Names of xacro properties/args/macros defined in every file read for this robot."""
    pattern = re.compile(rf"<(?:xacro:)?{kind}\b[^<>]*?\bname\s*=\s*[\"']([^\"'$<]+)[\"']")
    names: set[str] = set()
    for text in robot.source.texts.values():
        names.update(pattern.findall(text))
    return sorted(names)


def _did_you_mean(name: str | None, candidates: list[str]) -> str:
    if not name:
        return ""
    import difflib  # only on this error path: keeps start-up lean

    close = difflib.get_close_matches(name, candidates, n=1, cutoff=0.6)
    return f"did you mean '{close[0]}'? " if close else ""


def classify(message: str, robot: Robot | None = None) -> tuple[str, str, str | None]:
    """(kind, message, hint) for a xacro error message as recorded while loading; kind is one
    of the _PATTERNS names, or "other" (message unchanged, no hint)."""
    text = message.removeprefix("xacro:").strip()
    head, expressions = _expressions(text)
    expr = expressions[0].strip() if expressions else None
    head = head.strip().rstrip(".;,: ")
    # read through properties: the outermost use says where
    through = f" (used in ${{{expressions[-1].strip()}}})" if len(expressions) > 1 else ""
    for kind, pattern in _PATTERNS:
        match = re.search(pattern, text)
        if match is None:
            continue
        name = match.groupdict().get("name")
        if kind == "undefined-property":
            known = _defined_names(robot, "property") if robot else []
            where = (f" in ${{{expr}}}" if expr and expr != name else "") + through
            if name in known:
                return (kind, f"xacro: property '{name}' is used{where} before it is defined",
                        ("xacro reads top to bottom: move its <xacro:property> above the first "
                        "use (or it is a macro parameter used outside its macro)"))
            return (kind, f"xacro: undefined property '{name}'{where}",
                    (f"{_did_you_mean(name, known)}define it first: "
                     f'<xacro:property name="{name}" value="..."/> (or pass it as an argument)'))
        if kind == "undefined-arg":
            known = _defined_names(robot, "arg") if robot else []
            return (kind, f"xacro: $(arg {name}) is used but the argument is not defined",
                    (f"{_did_you_mean(name, known)}declare it: "
                    f'<xacro:arg name="{name}" default="..."/>, or pass {name}:=VALUE'))
        if kind == "undefined-macro":
            known = _defined_names(robot, "macro") if robot else []
            return (kind, f"xacro: macro '{name}' is called but never defined",
                    (f"{_did_you_mean(name, known)}define it with <xacro:macro name=\"{name}\" "
                    "params=\"...\">, or include the file that does"))
        if kind == "unknown-package":  # (at an include: skipped, the rest expanded)
            skipped = f"; {INCLUDE_SKIPPED}" if text.endswith(INCLUDE_SKIPPED) else ""
            return (kind, f"xacro: $(find {name}): package '{name}' not found{skipped}",
                    f"give it with -P {name}=DIR, or put the directory holding it on "
                    "ROS_PACKAGE_PATH / AMENT_PREFIX_PATH" + _tried(robot))
        if kind == "missing-include":
            return (kind, f"xacro: {head}",
                    ("check the filename (relative paths are relative to the including file), "
                    "or use $(find PACKAGE)/path"))
        if kind == "yaml-key":  # the interpreter named the file and its keys
            return (kind, f"xacro: {head}" + (f" in ${{{expr}}}" if expr else "") + through,
                    "use a key the YAML file has (they are listed), or add it to the file")
        if kind == "macro-parameters":
            return (kind, f"xacro: {head}",
                    ("pass exactly the macro's params (name=\"value\" attributes, and one child "
                    "block per *block parameter), or give defaults: params=\"x:=0\""))
        where = (f" in ${{{expr}}}" if expr else "") + through
        return (kind, f"xacro: {head}{where}",
                ("fix the expression (python syntax inside ${...}; "
                "conditions must be true/false/1/0)"))
    return "other", message, None


def _tried(robot) -> str:
    """Where ``$(find)`` looked (``PackageResolver.tried``)."""
    resolver = getattr(getattr(robot, "source", None), "resolver", None)
    tried = getattr(resolver, "tried", None)
    return f" (looked in: {tried()})" if tried is not None else ""


@rule("xacro.error", "error", "xacro cannot expand the file",
      doc="""xacro stopped: an undefined property (`${name}` before `<xacro:property>`), an
      undefined `$(arg name)`, a call of a macro that is not defined, an expression that does not
      evaluate (syntax, division by zero, a condition that is not true/false), an include that
      cannot be read, a `$(find pkg)` whose package cannot be found (give it with `-P pkg=DIR`),
      or a macro call with missing or unknown parameters. The message says which, at the line
      where it happened (inside a macro: the macro body's line, with the call site), and the
      hint says how to fix it. Nothing after this point was expanded, so the robot is checked
      incompletely until this is fixed.""",
      bad=_HEAD + '  <link name="${base}"/>\n</robot>',
      good=_HEAD + '  <xacro:property name="base" value="base_link"/>\n  <link name="${base}"/>\n'
                   '</robot>')
def xacro_error(robot: Robot):
    old_style = sorted({tag for text in robot.source.texts.values()
                        for tag in _OLD_TAG_RE.findall(text)})
    held_back = include_failed(robot)
    for finding in robot.source.problems_for("xacro.error"):
        kind, message, hint = classify(finding.message, robot)
        if held_back and kind in ("undefined-property", "undefined-macro"):
            continue  # perhaps defined in the include that could not be read: that is the cause
        if held_back and kind in ("missing-include", "unknown-package") \
                and message.endswith(INCLUDE_SKIPPED):
            message += ("; what it may define is not checked until it is read (names, "
                        "properties and macros used here and defined nowhere else)")
        if old_style and kind in ("undefined-property", "undefined-macro", "undefined-arg"):
            tags = ", ".join(f"<{tag}>" for tag in old_style)
            hint = (f"{hint}; note: this file uses {tags} without the xacro: prefix, which "
                    "xacro 2 ignores (write <xacro:...>)")
        # the reader's own hint knows more than the message's class (a generated include)
        yield Finding(message, finding.loc, hint=finding.hint or hint, severity=finding.severity)


_OLD_TAG_RE = re.compile(r"<(property|macro|include|arg)\s[^<>]*?\b(?:name|filename)\s*=")


# -- old unprefixed xacro tags -----------------------------------------------------------------

XACRO_TAGS = ("property", "include", "macro", "arg", "if", "unless", "insert_block", "call",
              "element", "attribute")
# elements whose contents are not URDF: Gazebo/SDF blocks, ros2_control parameters
_FOREIGN = FOREIGN_BLOCKS
# every element URDF defines: a macro may share a name with one (e.g. "inertial"), but an
# element with that name is then URDF, not a call
URDF_ELEMENTS = {
    "robot", "link", "joint", "material", "gazebo", "transmission", "ros2_control",
    "inertial", "visual", "collision", "origin", "geometry", "box", "cylinder", "sphere", "mesh",
    "capsule", "color", "texture", "mass", "inertia", "parent", "child", "axis", "limit", "mimic",
    "dynamics", "safety_controller", "calibration", "version",
}


def _in_foreign_block(element) -> bool:
    node = element.getparent()
    while node is not None:
        if isinstance(node.tag, str) and node.tag in _FOREIGN:
            return True
        node = node.getparent()
    return False


def _start_tag(robot: Robot, element) -> str | None:
    """The element's start tag as written in its source file, or None."""
    loc = robot.loc(element)
    text = robot.source.texts.get(loc.path)
    if text is None or not loc.line:
        return None
    lines = text.splitlines()
    if loc.line > len(lines):
        return None
    rest = "\n".join(lines[loc.line - 1:loc.line + 20])
    start = rest.find("<" + element.tag, (loc.column - 1) if loc.column else 0)
    if start < 0:
        return None
    end = rest.find(">", start)
    if end < 0:
        return None
    return " ".join(rest[start:end + 1].split())


def _rewrite(robot: Robot, element, tag: str) -> str:
    written = _start_tag(robot, element)
    if written is None:
        attributes = " ".join(f'{k}="{v}"' for k, v in element.attrib.items())
        written = f"<{tag}{' ' + attributes if attributes else ''}{'/' if len(element) == 0 else ''}>"
    new = "<xacro:" + written[1:]
    if len(element) or (element.text or "").strip():
        new += f" ... </xacro:{tag}>"
    return new


def _prefix_edits(robot: Robot, element, tag: str) -> tuple:
    """Edits writing the element with the xacro: prefix (start and end tag), declaring the
    namespace on the file's root when it is not."""
    from urdftool.edits import declare_namespace, rename_element

    loc = robot.loc(element)
    texts = robot.source.texts
    edits = rename_element(texts, loc, tag, "xacro:" + tag)
    return edits + declare_namespace(texts, loc.path, "xacro", XACRO_NS) if edits else ()


def _namespace_note(robot: Robot, element) -> str:
    """A reminder to declare the xacro namespace when the element's file does not."""
    text = robot.source.texts.get(robot.loc(element).path)
    if text is not None and "xmlns:xacro" not in text:
        return f' (and declare xmlns:xacro="{XACRO_NS}" on <robot>)'
    return ""


_EFFECT = {
    "property": "the property is never defined",
    "include": "nothing is included",
    "macro": "the macro is never defined",
    "arg": "the argument is never declared",
    "if": "the condition is never evaluated: its contents are copied through",
    "unless": "the condition is never evaluated: its contents are copied through",
    "insert_block": "the block is never inserted",
    "call": "the macro is never called",
    "element": "the element is never generated",
    "attribute": "the attribute is never set",
}


@rule("xacro.unprefixed-tag", "warning", "an old xacro tag without the xacro: prefix",
      doc="""xacro before ROS Groovy accepted `<property>`, `<include>`, `<macro>`, `<arg>`,
      `<if>` and the rest without the `xacro:` prefix. Modern xacro ignores them silently and
      copies them into the URDF: the property is never defined, the file never included, the
      macro never defined. Write them with the prefix.""",
      bad=_HEAD + '  <property name="width" value="0.3"/>\n  <link name="a"/>\n</robot>',
      good=_HEAD + '  <xacro:property name="width" value="0.3"/>\n  <link name="a"/>\n</robot>',
      fix="safe")
def unprefixed_tag(robot: Robot):
    for element in _unprefixed_tags(robot):
        tag = element.tag
        yield Finding(f"<{tag}> without the xacro: prefix is ignored by xacro 2 and copied into "
                      f"the URDF: {_EFFECT[tag]}", robot.loc(element),
                      hint=f"write {_rewrite(robot, element, tag)}"
                           f"{_namespace_note(robot, element)}",
                      edits=_prefix_edits(robot, element, tag))
    yield from _unprefixed_in_unread_files(robot)


def _unprefixed_in_unread_files(robot: Robot):
    """Unprefixed tags of the files only unprefixed includes name (xacro never read them):
    found now, so that one pass repairs the whole chain of includes."""
    from lxml import etree

    from urdftool.edits import declare_namespace, rename_element
    from urdftool.findings import Loc
    from urdftool.xmlrepair import secure_parser

    if robot.root is None or next(robot.root.iter("include"), None) is None:
        return  # no unprefixed include: xacro read every file
    for path, text in robot_files(robot).items():
        if path in robot.source.texts:
            continue
        try:
            root = etree.fromstring(text.encode("utf-8"), secure_parser(recover=True))
        except (etree.XMLSyntaxError, ValueError):
            continue
        if root is None or root.tag != "robot":
            continue
        lines = text.splitlines()
        texts = {path: text}
        for element in root.iter(*XACRO_TAGS):
            if _in_foreign_block(element) or (element.tag == "include"
                                              and _is_sdf_include(element)):
                continue
            tag, line = element.tag, element.sourceline
            column = lines[line - 1].find("<" + tag) + 1 if line and line <= len(lines) else 0
            loc = Loc(path, line, column or None)
            edits = rename_element(texts, loc, tag, "xacro:" + tag)
            if edits:
                edits += declare_namespace(texts, path, "xacro", XACRO_NS)
            yield Finding(f"<{tag}> without the xacro: prefix is ignored by xacro 2 (in a file "
                          f"only an unprefixed <include> names): {_EFFECT[tag]}", loc,
                          hint=f"write <xacro:{tag} ...>", edits=edits)


def _unprefixed_tags(robot: Robot):
    if robot.root is None or robot.root.tag != "robot":
        return
    for element in robot.root.iter(*XACRO_TAGS):  # without a namespace: unprefixed
        tag = element.tag
        if element is robot.root or _in_foreign_block(element):
            continue
        if tag == "include" and _is_sdf_include(element):
            continue
        yield element


def _is_sdf_include(element) -> bool:
    """An SDF-style <include><uri>...</uri></include> (not a xacro include)."""
    return element.get("filename") is None and any(
        isinstance(c.tag, str) and c.tag == "uri" for c in element)


# macro calls without the prefix ----------------------------------------------------------------

_MACRO_RE = re.compile(r"<(?:xacro:)?macro\b[^<>]*?\bname\s*=\s*[\"']([^\"'<]+)[\"']")


def robot_files(robot: Robot) -> dict[str, str]:
    """Every file of the robot: those xacro read, and those that unprefixed (hence never
    processed) <include>s name, transitively (path -> text; ``source.find_unread``)."""
    return {**robot.source.texts, **robot.source.unread}


def macro_names(robot: Robot) -> dict[str, str]:
    """Macro name -> file defining it, from every file of the robot (``robot_files``)."""
    found: dict[str, str] = {}
    for path, text in robot_files(robot).items():
        for name in _MACRO_RE.findall(text):
            found.setdefault(name, path)
    return found


@rule("xacro.unprefixed-macro-call", "warning", "a xacro macro called without the xacro: prefix",
      doc="""Old xacro expanded `<wheel/>` as a call of macro `wheel`; xacro 2 only expands
      `<xacro:wheel/>` and copies the unprefixed element into the URDF as an unknown element:
      the macro's links and joints never appear. When nothing else defines links the robot comes
      out empty, which every consumer refuses (error).""",
      bad=_HEAD + '  <xacro:macro name="body"><link name="base"/></xacro:macro>\n'
                  '  <link name="world"/>\n  <body/>\n</robot>',
      good=_HEAD + '  <xacro:macro name="body"><link name="base"/></xacro:macro>\n'
                   '  <link name="world"/>\n  <xacro:body/>\n</robot>',
      fix="safe")
def unprefixed_macro_call(robot: Robot):
    empty = not robot.links
    for element, defined_in in _unprefixed_calls(robot):
        tag = element.tag
        where = Path(defined_in).name
        message = (f"<{tag}> calls macro '{tag}' (defined in {where}) without the xacro: prefix; "
                   "xacro 2 copies it through unexpanded")
        if empty:
            message += f", so robot '{robot.name}' comes out with no links at all"
        yield Finding(message, robot.loc(element),
                      hint=f"write {_rewrite(robot, element, tag)}"
                           f"{_namespace_note(robot, element)}",
                      severity="error" if empty else None,
                      edits=_prefix_edits(robot, element, tag))


def _unprefixed_calls(robot: Robot):
    """(element, file defining the macro) for each macro called without the xacro: prefix."""
    if robot.root is None or robot.root.tag != "robot":
        return
    candidates = []
    for element in robot.root.iter():
        tag = element.tag
        if (not isinstance(tag, str) or tag.startswith("{") or tag in XACRO_TAGS
                or tag in URDF_ELEMENTS or element is robot.root):
            continue
        if not _in_foreign_block(element):
            candidates.append(element)
    if not candidates:
        return
    macros = macro_names(robot)
    for element in candidates:
        if element.tag in macros:
            yield element, macros[element.tag]


def unexpanded_xacro(robot: Robot) -> set:
    """The elements the xacro rules report as old unprefixed xacro (tags and macro calls), for
    other families to leave alone (e.g. not to call them unknown URDF elements)."""
    return set(_unprefixed_tags(robot)) | {element for element, _ in _unprefixed_calls(robot)}


# -- `{name}` written for `${name}` ------------------------------------------------------------

_BRACED = re.compile(r"(?<![$\w{])\{([A-Za-z_]\w*)\}(?!\})")
_MACRO_TAG = re.compile(r"<(/?)xacro:macro(?![\w:.-])([^<>]*)>")
_PARAMS = re.compile(r"""\bparams\s*=\s*(?:"([^"]*)"|'([^']*)')""")


@rule("xacro.missing-dollar", "error", "`{name}` written where `${name}` is meant",
      doc="""Inside a macro, `{side}` is not a substitution: xacro copies the braces and the name
      literally, so the link, joint or file name comes out as `{side}_finger` in every instance
      (a joint then names a link that does not exist, two instances collide). It is reported
      when the name in braces is a parameter of the macro it is written in, or a property of the
      files read; the fix inserts the `$`. In an attribute (names, references, numbers) it is an
      error, in element text a warning.""",
      bad=_HEAD + '  <xacro:macro name="finger" params="side">\n'
                  '    <link name="{side}_finger"/>\n  </xacro:macro>\n'
                  '  <xacro:finger side="left"/>\n</robot>',
      good=_HEAD + '  <xacro:macro name="finger" params="side">\n'
                   '    <link name="${side}_finger"/>\n  </xacro:macro>\n'
                   '  <xacro:finger side="left"/>\n</robot>',
      fix="safe")
def missing_dollar(robot: Robot):
    from urdftool.edits import edit, line_starts
    from urdftool.findings import Loc
    from urdftool.textscan import markup_split

    texts = robot.source.texts
    if not any("{" in text for text in texts.values()):
        return
    properties = set(_defined_names(robot, "property"))
    for path, written in texts.items():
        if "{" not in written or "xacro" not in written:
            continue
        # comments and CDATA blanked (the same length: positions are the file's)
        text = "".join(piece if index % 2 == 0 else re.sub(r"[^\n]", " ", piece)
                       for index, piece in enumerate(markup_split(written)))
        macros: list[tuple[int, set[str]]] = []  # open macros: (start, parameter names)
        spans: list[tuple[int, int, set[str]]] = []
        for tag in _MACRO_TAG.finditer(text):
            if tag.group(1):
                if macros:
                    start, names = macros.pop()
                    spans.append((start, tag.start(), names))
            elif not tag.group(2).rstrip().endswith("/"):
                found = _PARAMS.search(tag.group(2))
                params = (found.group(1) or found.group(2) or "") if found else ""
                names = {re.split(r"[:=]", word.lstrip("*^"))[0] for word in params.split()}
                macros.append((tag.end(), names))
        starts = None
        for match in _BRACED.finditer(text):
            name, at = match.group(1), match.start()
            inside = any(start <= at < end and name in names for start, end, names in spans)
            if not inside and name not in properties:
                continue
            if _in_expression(text, at):
                continue
            starts = starts or line_starts(written)
            fix = edit(path, written, at, at, "$", starts)
            in_attribute = _in_attribute(text, at)
            yield Finding(
                f"'{{{name}}}' is written where '${{{name}}}' is meant: xacro copies it as is "
                f"(the {name} {'parameter' if inside else 'property'} is not substituted)",
                Loc(path, fix.line, fix.column), hint=f"write ${{{name}}}", edits=(fix,),
                severity="error" if in_attribute else "warning")


def _in_attribute(text: str, at: int) -> bool:
    """Whether ``at`` is inside a tag (an attribute value), not element text."""
    return text.rfind("<", 0, at) > text.rfind(">", 0, at)


def _in_expression(text: str, at: int) -> bool:
    """Whether ``at`` is inside ``$(eval ...)`` or a ``${...}`` (a str.format template)."""
    line_start = text.rfind("\n", 0, at) + 1
    before = text[max(line_start, at - 2000):at]
    opened = max(before.rfind("$("), before.rfind("${"))
    return opened >= 0 and ")" not in before[opened:] and "}" not in before[opened:]


# -- untrusted input (issue 8: urdftool.xacro_eval, urdftool.sandbox) ---------------------------

source_rule(
    "xacro.unsafe-expression", "error", "a xacro expression that could run code; not evaluated",
    doc="""xacro evaluates `${...}` and `$(eval ...)` with Python's `eval`. Its only guard, no
    names starting with `__`, is easy to get round: a generator's `gi_frame.f_back.f_globals`
    reaches xacro's module globals and `os`, `str.format` walks `__globals__` inside a string,
    `$(eval ...)` sees every builtin (`exec`, `open`). A file that does this runs commands as
    whoever expands it: on a CI runner, as the CI user.

    urdftool validates every expression before it is evaluated and allows literals, names,
    operators, conditional expressions, subscripts, slices, comprehensions, lambdas, the
    functions xacro documents (math, `python.*` but `vars` and three-argument `type`,
    `xacro.*`), the methods of strings, lists, dicts, sets and numbers, and attributes of
    namespaces and YAML data. `:=`, dunder names, frame / code / generator attributes and
    anything else are refused; the expression's value is not used. Real robot descriptions never need any of it: rewrite the expression with
    properties and arithmetic.""",
    bad='<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">\n'
        '  <link name="${[*(g:=(g.gi_frame.f_back.f_back.f_globals for _ in [1]))]}"/>\n'
        '</robot>',
    good='<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">\n'
         '  <xacro:property name="side" value="left"/>\n'
         '  <link name="${side.upper()}_${\'%02d\' % (2 * 3)}"/>\n</robot>',
)

source_rule(
    "xacro.env-not-allowed", "warning",
    "`$(optenv NAME default)` took its default because urdftool hides NAME",
    doc="""In every mode xacro's `$(env NAME)` and `$(optenv NAME)` see only the variables named
    with `--allow-env`: the environment of a CI runner holds its secrets, and a file checked
    with `--trusted` is still never let print one. A description that picks an accessory, a mesh folder or a
    variant with `$(optenv NAME default)` is then checked with the default even though NAME is
    set, so the robot checked is not the robot your environment builds. urdftool says so
    rather than check another robot in silence. If the variable is not secret and the robot
    should be checked with its value, allow it: `--allow-env NAME`.""",
    bad='<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">\n'
        '  <link name="base_$(optenv HOME default)"/>\n</robot>',
    good='<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">\n'
         '  <xacro:arg name="suffix" default="default"/>\n'
         '  <link name="base_$(arg suffix)"/>\n</robot>',
)

source_rule(
    "xacro.limit-exceeded", "error", "xacro expansion ran past a time, size or depth limit",
    doc="""A macro that calls itself, macros that double at each level, a number like
    `10**10**10` or a gigantic include make xacro run for ever or exhaust memory; a CI gate must
    not hang on them. urdftool stops the expansion when it takes longer than `--timeout`
    (default 3 s), nests macros deeper than Python's recursion limit, builds numbers or strings
    beyond a sane size, reads a file over 64 MB, grows the expanded document past 32 MB (macro
    bodies copied, files included, counted as xacro makes them) or builds an element or
    attribute name over 1024 characters, or (with `--untrusted`) uses more memory than
    `--memory-limit`. Nothing after the stop is checked: fix the recursion or the size. It is
    also the warning at a launch file too large to read for the xacro arguments it passes.""",
    bad='<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">\n'
        '  <xacro:macro name="loop"><xacro:loop/></xacro:macro>\n'
        '  <link name="base"/>\n  <xacro:loop/>\n</robot>',
    good='<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">\n'
         '  <xacro:macro name="segment" params="i"><link name="link${i}"/></xacro:macro>\n'
         '  <link name="base"/>\n  <xacro:segment i="1"/>\n</robot>',
)
