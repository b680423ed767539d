"""Find every malformed tag in a file, repair what is recognised in memory, and say so.

``repair(text, path)`` returns the repaired text and the problems found (rule id + Finding), so
that the rest of the file stays checkable (lxml's ``recover=True`` alone nests everything after
the first broken tag inside the wrong parent).

How it works:

- Fast path: one strict parse. A well-formed file is returned as is, unless one cheap regex sees
  a line that looks like a tag which lost its ``<`` (``imit effort="1" velocity="1"/>`` inside a
  ``<joint>`` is well-formed text, but it is a broken ``<limit>``).
- Otherwise a tolerant scanner walks the text once, keeping its own stack of open elements. It
  recognises each breakage (unclosed and mismatched tags, tags that lost ``<`` or ``>``, bad
  attributes, entities, comments, stray text, content after the root...), records an in-memory
  edit for it and a finding, and carries on as if the edit had been made. The edits are applied
  and the text is parsed strictly again; this repeats (bounded) until the parser accepts the text
  or nothing more is recognised. What the parser still rejects is reported as ``xml.syntax`` with
  its own message, and the caller falls back to ``recover=True``.
- Edits never add or remove a newline, so every line number of the repaired text is the
  original's; columns of findings are mapped back to the original text.
"""

from __future__ import annotations

import re
from collections import deque

from lxml import etree

from urdftool.findings import Finding, Loc
from urdftool.textscan import declared_utf8, tag_closes

MAX_REPAIRS = 200  # recognised breakages per file; then stop and let the parser speak
MAX_ROUNDS = 8  # scan -> edit -> strict parse rounds
SIMILAR_DEPTH = 50  # open elements an end tag with a typo may have meant (innermost first)
SIMILAR_LENGTH = 100  # longest name compared for typos (see _similar)

_SPACE = " \t\r\n"
_PREDEFINED_ENTITIES = {"amp", "lt", "gt", "quot", "apos"}
# XML 1.0 declarations as most files write them: nothing to check (and no regex to compile)
_USUAL_DECLARATIONS = tuple(f"<?xml version={q}1.0{q}{encoding}{space}?>" for q in "\"'"
                            for encoding in ("", f" encoding={q}UTF-8{q}", f" encoding={q}utf-8{q}")
                            for space in ("", " "))
_UTF8_DECLARATIONS = tuple(d for d in _USUAL_DECLARATIONS if "encoding" in d)


# The regular expressions, by name; ``_RE.<name>`` compiles one on first use.
_PATTERNS = {
    "good_declaration": (r"""<\?xml\s+version\s*=\s*(["'])([^"'\n<>?]*)\1"""
                         r"""(?:\s+encoding\s*=\s*(["'])[A-Za-z][-\w.]*\3)?"""
                         r"""(?:\s+standalone\s*=\s*(["'])(?:yes|no)\4)?\s*\?>"""),
    "name": r"[^\W\d][-\w.:]*",
    "bad_chars": "[\x00-\x08\x0b\x0c\x0e-\x1f\ufffe\uffff\ud800-\udfff]+",
    "entity": r"&(?:#[0-9]+|#x[0-9a-fA-F]+|([^\W\d][-\w.:]*));",
    # (a name starts where a run of name characters starts: one try per run, linear)
    "attribute": r"(?<![-\w.:])([^\W\d][-\w.:]*)\s*=\s*(\"[^\"]*\"|'[^']*')",
    # A line of text that is a tag without its '<': 'link name="a">', 'imit effort="1"/>',
    # '/link>'. Only text at the start of a line is considered.
    "taglike": (r"""(?m)^[ \t]*(?P<slash>/)?(?P<name>[^\s<>"'=/&]+)"""
                r"""(?P<attrs>(?:\s+[^\W\d][-\w.:]*\s*=\s*(?:"[^"<]*"|'[^'<]*'))*)"""
                r"""\s*(?P<close>/?>)[ \t]*(?=\r?\n|$)"""),
    # Fast-path filter for "taglike" in a well-formed file (a superset: what it finds is confirmed
    # by the scanner): lines with a '>' and no '<' (cheap), then a closer look at their start.
    # Continuation lines of multi-line tags start with 'attr=' and do not pass the closer look.
    "gt_line": r"\n[^<\n]*>",
    "taglike_hint": (r"""\n[ \t]*(?:[^\s<>"'=/&]+[ \t]+[^\W\d][-\w.:]*[ \t]*=[ \t]*["']"""
                     r"""|/?[^\W\d][-\w.:]*[ \t]*/?>)"""),
}


class _Patterns:
    """``_PATTERNS``, each compiled on first use: importing this module (every ``check``)
    compiles nothing, and a well-formed file needs none of them."""

    def __getattr__(self, name: str) -> re.Pattern:
        if name not in _PATTERNS:
            raise AttributeError(name)
        pattern = re.compile(_PATTERNS[name])
        setattr(self, name, pattern)  # found directly from now on
        return pattern


_RE = _Patterns()

# What URDF allows where: used to name the element a broken tag most likely was (did-you-mean)
# and to decide where an unclosed element ends. Keys are "parent/child" for context-dependent
# elements, else the element name.
_CHILDREN: dict[str, tuple[str, ...]] = {
    "": ("robot", "sdf"),
    "robot": ("link", "joint", "material", "transmission", "gazebo", "ros2_control"),
    "link": ("inertial", "visual", "collision"),
    "inertial": ("origin", "mass", "inertia"),
    "visual": ("origin", "geometry", "material"),
    "collision": ("origin", "geometry"),
    "geometry": ("box", "cylinder", "sphere", "mesh", "capsule"),
    "material": ("color", "texture"),
    "joint": ("origin", "parent", "child", "axis", "calibration", "dynamics", "limit",
              "safety_controller", "mimic"),
    "transmission": ("type", "joint", "actuator", "leftActuator", "rightActuator", "flexJoint",
                     "rollJoint", "use_simulation_duration", "mechanicalReduction"),
    "transmission/joint": ("hardwareInterface", "role"),
    "actuator": ("hardwareInterface", "mechanicalReduction", "role"),
}
_ATTRIBUTES: dict[str, tuple[str, ...]] = {
    "robot": ("name", "version"), "link": ("name", "type"), "joint": ("name", "type"),
    "origin": ("xyz", "rpy"), "parent": ("link",), "child": ("link",), "axis": ("xyz",),
    "limit": ("lower", "upper", "effort", "velocity"), "dynamics": ("damping", "friction"),
    "calibration": ("rising", "falling", "reference_position"),
    "safety_controller": ("soft_lower_limit", "soft_upper_limit", "k_position", "k_velocity"),
    "mimic": ("joint", "multiplier", "offset"), "mass": ("value",),
    "inertia": ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"), "box": ("size",),
    "cylinder": ("radius", "length"), "sphere": ("radius",), "mesh": ("filename", "scale"),
    "capsule": ("radius", "length"), "material": ("name",), "color": ("rgba",),
    "texture": ("filename",), "visual": ("name",), "collision": ("name",),
    "transmission": ("name",), "actuator": ("name",), "gazebo": ("reference",),
}
# Elements URDF defines as empty: an unclosed one is most likely a missing '/' in '/>'.
_EMPTY = {"origin", "parent", "child", "axis", "calibration", "dynamics", "limit",
          "safety_controller", "mimic", "mass", "inertia", "box", "cylinder", "sphere", "mesh",
          "capsule", "color", "texture"}
_KNOWN = ({name for names in _CHILDREN.values() for name in names}
          | {key.split("/")[-1] for key in _CHILDREN if key} | set(_ATTRIBUTES))
_NAMESPACES = {"xacro": "http://www.ros.org/wiki/xacro"}


def secure_parser(recover: bool = False, huge_text: bool = False) -> etree.XMLParser:
    """The only XML parser urdftool uses: no entities, no network, no DTD, no huge trees.

    ``huge_text``: for mesh geometry only (the COLLADA reader), where one text node holds a
    whole float or index array and exporters write them past libxml2's 10 MB limit (MeshLab:
    28 MB in example-robot-data's Go1 trunk); pycollada, which such files otherwise went to,
    parses them with huge trees anyway. Still no entity is resolved (nothing amplifies); the
    text is the file's, already read whole."""
    return etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False,
                           huge_tree=huge_text, remove_blank_text=False, recover=recover)


def _xml_bytes(text: str) -> bytes:
    """The text as UTF-8 bytes with any encoding declaration made to agree."""
    if "encoding" in text[:300] and not text.startswith(_UTF8_DECLARATIONS):
        text = declared_utf8(text)
    return text.encode("utf-8", "surrogatepass")


def _strict_parse(text: str):
    """(root, None) if the strict parser accepts ``text``, else (None, the XMLSyntaxError)."""
    try:
        return etree.fromstring(_xml_bytes(text), secure_parser()), None
    except etree.XMLSyntaxError as exc:
        return None, exc
    except (ValueError, UnicodeError) as exc:  # lxml refuses some inputs outright
        return None, exc


def _fix_declaration(text: str, path: str, problems: list) -> tuple[str, dict]:
    """Repair the XML declaration at the start of the file (version other than 1.0, or damaged);
    returns the text and the column shifts of the edit (see ``_apply``)."""
    if text.startswith(_USUAL_DECLARATIONS):
        return text, {}
    head = len(text) - len(text.lstrip())
    if not text.startswith("<?", head):
        return text, {}
    line_end = text.find("\n", head)
    first = text[head:line_end if line_end >= 0 else len(text)]
    target = re.match(r"<\?([^\s?>]*)", first).group(1)
    if target.lower() != "xml" and ("version" not in first or _RE.name.fullmatch(target)
                                    and _similar(target, "xml") < 0.6):
        return text, {}  # another processing instruction
    line = text.count("\n", 0, head) + 1
    good = _RE.good_declaration.match(text, head)
    if good is None:
        question, gt = first.find("?>"), first.find(">")
        end = head + (question + 2 if question >= 0 else gt + 1 if gt >= 0 else len(first.rstrip()))
        encoding = re.search(r"encoding\s*=\s*[\"']([A-Za-z][-\w.]*)[\"']", text[head:end])
        fixed = '<?xml version="1.0"' + (f' encoding="{encoding.group(1)}"' if encoding else "") + "?>"
        problems.append(("xml.declaration", Finding(
            f"the XML declaration '{_short(text[head:end])}' is malformed (robot tools skip it, "
            "strict XML parsers reject the file)", Loc(path, line, 1), hint=f"write {fixed}")))
        return _apply(text, [(head, end, fixed, 0)])
    version = good.group(2)
    if version == "1.0":
        return text, {}
    start = good.start(2)
    problems.append(("xml.declaration", Finding(
        f"XML declaration says version \"{version}\"; only 1.0 is valid "
        "(robot tools accept it, strict XML parsers do not)",
        Loc(path, line, start - (text.rfind("\n", 0, start) + 1) + 1),
        hint='write <?xml version="1.0"?>')))
    return _apply(text, [(start, good.end(2), "1.0", 0)])


def _blank(text: str) -> str:
    """Same length, newlines kept, everything else a space."""
    return re.sub(r"[^\r\n]", " ", text)


def _short(text: str, limit: int = 40) -> str:
    text = " ".join(text.split())
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _tail(text: str, limit: int = 40) -> str:
    text = " ".join(text.split())
    return text if len(text) <= limit else "..." + text[-(limit - 3):]


def _attrs(text: str) -> str:
    return " " + _short(text.strip(), 60) if text.strip() else ""


def _similar(a: str, b: str) -> float:
    """How alike two names are (0..1); names longer than ``SIMILAR_LENGTH`` are only equal or
    not (difflib's time grows with the product of the lengths: seconds for two 20k-char names)."""
    a, b = a.lower(), b.lower()
    if len(a) > SIMILAR_LENGTH or len(b) > SIMILAR_LENGTH:
        return 1.0 if a == b else 0.0
    import difflib  # only a malformed file needs it

    return difflib.SequenceMatcher(None, a, b).ratio()


def _suggest(name: str, attributes: list[str], candidates) -> str | None:
    """The element a garbled tag most likely was: by name (did-you-mean, including a name that
    lost its first letters) and by the attributes it carries."""
    best, best_score = None, 0.0
    for candidate in sorted(candidates):
        name_score = _similar(name, candidate)
        if len(name) >= 2 and candidate.lower().endswith(name.lower()):
            name_score = max(name_score, 0.9)
        known = _ATTRIBUTES.get(candidate, ())
        attr_score = (sum(a in known for a in attributes) / len(attributes)) if attributes else 0.0
        if name_score < 0.6 and attr_score < 0.5:
            continue
        if name_score + attr_score > best_score:
            best, best_score = candidate, name_score + attr_score
    return best


class _Problem:
    __slots__ = ("anchor", "hint", "message", "offset", "rule", "severity")

    def __init__(self, rule: str, message: str, offset: int, hint: str | None = None,
                 anchor: tuple[int, str] | None = None, severity: str | None = None):
        self.rule = rule
        self.message = message
        self.offset = offset  # in the text of the round that found it
        self.hint = hint
        self.anchor = anchor  # (offset of the element's '<', its name) for the xpath
        self.severity = severity


class _Open:
    """An element open on the scanner's stack."""

    __slots__ = ("children", "first_text", "gt_inserted", "name", "prefixes", "reopened", "start",
                 "tag_end")

    def __init__(self, name: str, start: int, tag_end: int, prefixes: set,
                 children: deque | None = None):
        self.name = name
        self.start = start  # offset of '<'
        self.tag_end = tag_end  # offset just after '>'
        self.prefixes = prefixes  # namespace prefixes in scope here (inherited)
        self.children = deque() if children is None else children  # (name, start offset)
        self.first_text: tuple[int, int] | None = None  # non-blank text before the first child
        self.reopened = False
        self.gt_inserted = False  # its '>' is a repair (so there is no '>' at tag_end - 1)


class _Scanner:
    """One tolerant pass over ``text``: ``edits`` to make and ``problems`` found."""

    def __init__(self, text: str, budget: int):
        self.t = text
        self.n = len(text)
        self.budget = budget
        self.edits: list[tuple[int, int, str, int]] = []  # (start, end, text, priority)
        self.problems: list[_Problem] = []
        self.stack: list[_Open] = []
        self.root: _Open | None = None
        self.root_end: tuple[int, int] | None = None  # span of the root's end tag
        self.after_root_reported = False
        self.entities_declared = "<!ENTITY" in text
        self.undeclared: set[str] = set()
        self.stopped = False
        self.gt_inserted = False
        self.no_comment_end = False
        self._line_starts: list[int] | None = None

    # -- helpers --------------------------------------------------------------------------
    def line_of(self, offset: int) -> int:
        if self._line_starts is None:
            self._line_starts = _line_starts(self.t)
        return _line_number(self._line_starts, offset)

    def edit(self, start: int, end: int, replacement: str, first: bool = False,
             opening: bool = False) -> None:
        """Replace text[start:end]. Of several insertions at one offset, those that finish the
        current token (a quote, a '>') go first, then ``first`` ones (end tags closing an
        element), then ``opening`` ones (a start tag's '<'); each group in the order made."""
        self.edits.append((start, end, replacement, 1 if first else 2 if opening else 0))

    def report(self, rule: str, message: str, offset: int, hint: str | None = None,
               anchor: tuple[int, str] | None = None, severity: str | None = None) -> None:
        self.problems.append(_Problem(rule, message, offset, hint, anchor, severity))
        if len(self.problems) >= self.budget:
            self.stopped = True

    def skip_space(self, k: int) -> int:
        t, n = self.t, self.n
        while k < n and t[k] in _SPACE:
            k += 1
        return k

    def allowed(self, depth: int | None = None) -> tuple[str, ...] | None:
        """Children allowed in the element at ``depth`` of the stack (default: the top)."""
        if not self.stack:
            return _CHILDREN[""]
        index = len(self.stack) - 1 if depth is None else depth
        name = self.stack[index].name
        if index > 0:
            key = f"{self.stack[index - 1].name}/{name}"
            if key in _CHILDREN:
                return _CHILDREN[key]
        return _CHILDREN.get(name)

    # -- main loop ------------------------------------------------------------------------
    def scan(self) -> None:
        t, n = self.t, self.n
        i = 0
        while i < n and not self.stopped:
            j = t.find("<", i)
            if j < 0:
                j = n
            if j > i:
                self.text(i, j)
            if j >= n or self.stopped:
                break
            i = self.markup(j)
        if not self.stopped:
            self.end_of_file()

    def markup(self, j: int) -> int:
        t = self.t
        if t.startswith("<!--", j):
            return self.comment(j)
        if t.startswith("<![CDATA[", j):
            k = t.find("]]>", j + 9)
            if k < 0:  # swallows the rest of the file: leave it to the parser's message
                self.stopped = True
                return self.n
            return k + 3
        if t.startswith("<!", j):
            line_end = t.find("\n", j)
            close = t.find("-->", j, line_end if line_end >= 0 else self.n)
            if close >= 0 and not t.startswith(("<!DOCTYPE", "<!doctype"), j):
                opener = re.compile(r"<![^\s\w]*").match(t, j).end()  # '<!-', '<!"-'...
                self.report("xml.bad-comment", "a comment must start with <!--", j,
                            hint="write <!--")
                self.edit(j, opener, "<!--")
                self.check_comment_body(j, opener, close)
                return close + 3
            return self.doctype(j)
        if t.startswith("<?", j):
            return self.processing_instruction(j)
        if t.startswith("</", j):
            return self.end_tag(j)
        match = _RE.name.match(t, j + 1)
        if match:
            return self.start_tag(j, match)
        spaced = re.compile(r"<[ \t]+([^\W\d][-\w.:]*)").match(t, j)
        if spaced and tag_closes(t, spaced.end()):
            self.report("xml.bad-tag", f"space between '<' and the tag name '{spaced.group(1)}'",
                        j, hint=f"write <{spaced.group(1)} without the space")
            self.edit(j + 1, spaced.start(1), "")
            name_match = _RE.name.match(t, spaced.start(1))
            return self.start_tag(j, name_match)
        self.report("xml.bad-entity", "a '<' that starts no tag", j,
                    hint="write &lt; for a literal '<', or complete the tag",
                    anchor=self.anchor())
        self.edit(j, j + 1, "&lt;")
        return j + 1

    def anchor(self) -> tuple[int, str] | None:
        return (self.stack[-1].start, self.stack[-1].name) if self.stack else None

    # -- comments, declarations, doctype --------------------------------------------------
    def comment(self, j: int) -> int:
        t = self.t
        end = -1 if self.no_comment_end else t.find("-->", j + 4)
        if end < 0:
            self.no_comment_end = True  # never search to the end of the file twice
            return self.unterminated_comment(j, self.n)
        inner = t.find("<!--", j + 4, end)
        if inner >= 0:  # lost its end: the next comment's '-->' would swallow what is between
            return self.unterminated_comment(j, inner)
        self.check_comment_body(j, j + 4, end)
        return end + 3

    def unterminated_comment(self, j: int, limit: int) -> int:
        """A comment with no '-->' before ``limit``: end it where it most likely ended."""
        t = self.t
        self.report("xml.bad-comment", "this comment is never closed", j,
                    hint="end the comment with -->")
        line_end = t.find("\n", j, limit)
        first = t[j + 4:line_end if line_end >= 0 else limit].rstrip()
        at = j + 4 + len(first)
        if first.endswith("--"):  # '<!-- text --' lost its '>'
            self.edit(at, at, ">")
            self.check_comment_body(j, j + 4, at - 2)
            return at
        if first.endswith("-"):  # '<!-- text -' or '<!-- text ->'
            self.edit(at, at, "->")
            self.check_comment_body(j, j + 4, at - 1)
            return at
        after = t[line_end:limit].lstrip() if line_end >= 0 else ""
        if first.strip() and after.startswith("<"):  # a one-line comment; markup follows
            self.edit(at, at, " -->")
            self.check_comment_body(j, j + 4, at)
            return at
        gt = t.find(">", j + 4, limit)
        if gt >= 0:
            if t[gt - 1] == "-":
                self.edit(gt, gt, "-")  # '->' becomes '-->'
                self.check_comment_body(j, j + 4, gt - 1)
            else:
                self.edit(gt, gt, " --")
                self.check_comment_body(j, j + 4, gt)
            return gt + 1
        at = j + 4 + len(t[j + 4:limit].rstrip())
        self.edit(at, at, " -->")
        self.check_comment_body(j, j + 4, at)
        return at

    def check_comment_body(self, j: int, start: int, end: int) -> None:
        body = self.t[start:end]
        if "--" in body or body.endswith("-"):
            fixed = body
            while "--" in fixed:
                fixed = fixed.replace("--", "= ")
            if fixed.endswith("-"):
                fixed = fixed[:-1] + " "
            where = body.find("--") if "--" in body else len(body) - 1
            self.report("xml.bad-comment", "'--' is not allowed inside a comment",
                        start + where, hint="use single dashes or '=' inside comments")
            self.edit(start, end, fixed)

    def doctype(self, j: int) -> int:
        t, n = self.t, self.n
        depth, quote, k = 0, None, j + 2
        while k < n:
            c = t[k]
            if quote:
                if c == quote:
                    quote = None
            elif c in "\"'":
                quote = c
            elif c == "[":
                depth += 1
            elif c == "]":
                depth -= 1
            elif c == ">" and depth <= 0:
                return k + 1
            k += 1
        return n

    def processing_instruction(self, j: int) -> int:
        t = self.t
        end = t.find("?>", j + 2)
        if end < 0:  # swallows the rest of the file: leave it to the parser's message
            self.stopped = True
            return self.n
        if re.compile(r"<\?xml[\s?]").match(t, j) and j > 0:
            declaration = t[j:end + 2]
            before = t[:j]
            if not before.strip():
                lines = before.count("\n")
                self.report("xml.declaration",
                            f"the XML declaration must be the first thing in the file; "
                            f"{lines} blank line(s) come before it" if lines else
                            "the XML declaration must be the first thing in the file; "
                            "spaces come before it", j,
                            hint="remove what comes before <?xml ...?>")
                # move it to the very start, keeping every newline where it was
                self.edit(0, end + 2, declaration + _blank(before))
            else:
                self.report("xml.declaration",
                            "an XML declaration is only allowed at the start of the file", j,
                            hint="remove this <?xml ...?>")
                self.edit(j, end + 2, _blank(declaration))
        return end + 2

    # -- tags -----------------------------------------------------------------------------
    def start_tag(self, j: int, match) -> int:
        t, n = self.t, self.n
        name = match.group()
        k = match.end()
        last_end = k
        attributes: dict[str, int] = {}
        selfclose = False
        while True:
            ws_start = k
            k = self.skip_space(k)
            c = t[k] if k < n else ""
            if c == ">":
                tag_end = k + 1
                break
            if c == "/":
                after = self.skip_space(k + 1)
                if after < n and t[after] == ">":
                    if after > k + 1:
                        self.report("xml.bad-tag", f"space inside '/>' of <{name}>", k,
                                    hint="write />")
                        self.edit(k + 1, after, "")
                    selfclose, tag_end = True, after + 1
                    break
                if after >= n or t[after] == "<":
                    self.missing_close_bracket(name, j, k + 1, ">")
                    selfclose, tag_end = True, k + 1
                    break
                self.report("xml.bad-tag", f"unexpected '/' inside the <{name}> tag", k,
                            hint="remove it")
                self.edit(k, k + 1, " ")
                k += 1
                continue
            if c == "" or c == "<":
                close = "/>" if name in _EMPTY else ">"
                self.missing_close_bracket(name, j, last_end, close)
                selfclose, tag_end = close == "/>", last_end
                self.gt_inserted = True
                break
            attribute = _RE.name.match(t, k)
            if not attribute:
                self.report("xml.bad-tag", f"unexpected {c!r} inside the <{name}> tag", k,
                            hint="remove it")
                self.edit(k, k + 1, " " if c not in "\r\n" else c)
                k += 1
                continue
            if k == ws_start and attributes:
                self.report("xml.bad-attribute",
                            f"no space before attribute '{attribute.group()}' of <{name}>", k,
                            hint=f"write a space before {attribute.group()}=")
                self.edit(k, k, " ")
            k = self.attribute(name, j, attribute, attributes)
            last_end = k
        declared = self.check_prefixes(name, j, attributes)
        self.open(name, j, tag_end, selfclose, declared)
        if self.gt_inserted and self.stack and self.stack[-1].start == j:
            self.stack[-1].gt_inserted = True
        self.gt_inserted = False
        return tag_end

    def missing_close_bracket(self, name: str, j: int, at: int, close: str) -> None:
        self.report("xml.missing-close-bracket", f"the <{name}> tag has no closing '>'", j,
                    hint=f"end the tag with '{close}'", anchor=(j, name))
        self.edit(at, at, close)

    def attribute(self, tag: str, j: int, match, attributes: dict) -> int:
        """Read one attribute at ``match``; returns the offset after it."""
        t, n = self.t, self.n
        name, start = match.group(), match.start()
        p = self.skip_space(match.end())
        if p < n and t[p] == "=":
            p = self.skip_space(p + 1)
        elif p < n and t[p] in "\"'":
            self.report("xml.bad-attribute", f"attribute '{name}' of <{tag}> has no '='", start,
                        hint=f"write {name}=\"...\"", anchor=(j, tag))
            self.edit(match.end(), match.end(), "=")
        else:
            self.report("xml.bad-attribute", f"attribute '{name}' of <{tag}> has no value",
                        start, hint=f"write {name}=\"VALUE\" or remove it", anchor=(j, tag))
            self.edit(start, match.end(), _blank(name))
            return match.end()
        quote = t[p] if p < n else ""
        if quote in ("\"", "'"):
            end = t.find(quote, p + 1)
            value = t[p + 1:end] if end >= 0 else ""
            if end < 0 or ("\n" in value and re.search(r"<[/\w]", value)):
                line_end = t.find("\n", p + 1)
                line_end = n if line_end < 0 else line_end
                gt = t.find(">", p + 1, line_end)
                if gt >= 0:
                    close_at = gt - 1 if t[gt - 1] == "/" else gt
                else:
                    close_at = p + 1 + len(t[p + 1:line_end].rstrip())
                self.report("xml.bad-attribute",
                            f"the value of attribute '{name}' of <{tag}> has no closing quote",
                            p, hint=f"write the closing {quote} after "
                                    f"'{_tail(t[p + 1:close_at])}'", anchor=(j, tag))
                self.edit(close_at, close_at, quote)
                end_offset = close_at
            else:
                self.check_value(j, tag, p + 1, end)
                end_offset = end + 1
        elif p < n and t[p] not in "<>" and not t.startswith("/>", p):
            value = re.compile(r"[^\s<>\"']+").match(t, p)
            value_end = value.end() if value else p + 1
            if t[value_end - 1] == "/" and t.startswith(">", value_end) and value_end - 1 > p:
                value_end -= 1
            raw = t[p:value_end]
            self.report("xml.bad-attribute",
                        f"the value of attribute '{name}' of <{tag}> is not quoted", p,
                        hint=f"write {name}=\"{_short(raw)}\"", anchor=(j, tag))
            self.edit(p, p, "\"")
            self.edit(value_end, value_end, "\"")
            self.check_value(j, tag, p, value_end)
            end_offset = value_end
        else:
            self.report("xml.bad-attribute", f"attribute '{name}' of <{tag}> has no value", start,
                        hint=f"write {name}=\"VALUE\" or remove it", anchor=(j, tag))
            self.edit(start, p, _blank(t[start:p]))
            return p
        if name in attributes:
            self.report("xml.bad-attribute",
                        f"attribute '{name}' appears twice in <{tag}>", start,
                        hint=f"keep one {name}=... (the first one is used here)",
                        anchor=(j, tag))
            self.edit(start, end_offset, _blank(t[start:end_offset]))
        else:
            attributes[name] = start
        return end_offset

    def check_value(self, j: int, tag: str, start: int, end: int) -> None:
        t = self.t
        lt = t.find("<", start, end)
        while lt >= 0:
            self.report("xml.bad-entity", f"a '<' inside an attribute value of <{tag}>", lt,
                        hint="write &lt;", anchor=(j, tag))
            self.edit(lt, lt + 1, "&lt;")
            lt = t.find("<", lt + 1, end)
        self.check_entities(start, end, (j, tag), f"in an attribute value of <{tag}>")

    def check_entities(self, start: int, end: int, anchor, where: str = "in the text") -> None:
        t = self.t
        amp = t.find("&", start, end)
        while amp >= 0 and not self.stopped:
            match = _RE.entity.match(t, amp, end)
            if t.startswith("&nbsp", amp):  # HTML's non-breaking space, copied from a web page
                length = 6 if t.startswith("&nbsp;", amp) else 5
                self.report("xml.bad-entity", f"'{t[amp:amp + length]}' {where}: XML has no "
                            "&nbsp entity", amp, hint="write a plain space", anchor=anchor)
                self.edit(amp, amp + length, " ")
            elif match is None:
                word = re.compile(r"&[^\W\d][-\w.]*").match(t, amp, end)
                shown = f" ('{_short(word.group(), 20)}')" if word else ""
                self.report("xml.bad-entity", f"bare '&'{shown} {where}", amp,
                            hint="write &amp; for a literal '&'", anchor=anchor)
                self.edit(amp, amp + 1, "&amp;")
            elif match.group(1) and match.group(1) not in _PREDEFINED_ENTITIES \
                    and not self.entities_declared:
                entity = match.group(1)
                self.report("xml.bad-entity", f"entity '&{entity};' {where} is not defined in XML",
                            amp, hint=f"write the character itself, or &amp;{entity}; for the "
                                      "literal text", anchor=anchor)
                self.edit(amp, amp + 1, "&amp;")
            amp = t.find("&", amp + 1, end)

    def check_prefixes(self, name: str, j: int, attributes) -> set:
        """Report namespace prefixes used but never declared; returns those declared here."""
        declared = {a.split(":", 1)[1] for a in attributes if a.startswith("xmlns:")}
        used = [q for q in [name, *attributes] if ":" in q and not q.startswith(("xmlns", "xml:"))]
        if not used:
            return declared
        known = declared | self.stack[-1].prefixes if self.stack else declared
        for qname in used:
            prefix = qname.split(":", 1)[0]
            if prefix in known or prefix in self.undeclared or prefix == "xml":
                continue
            self.undeclared.add(prefix)
            uri = _NAMESPACES.get(prefix, f"urn:undeclared:{prefix}")
            root_name, root_start = (self.root.name, self.root.start) if self.root else (name, j)
            self.report("xml.undefined-prefix",
                        f"namespace prefix '{prefix}' (in '{qname}') is never declared", j,
                        hint=f"add xmlns:{prefix}=\"{uri}\" to <{root_name}>", anchor=(j, name))
            at = root_start + 1 + len(root_name)
            self.edit(at, at, f" xmlns:{prefix}=\"{uri}\"")
        return declared

    def open(self, name: str, start: int, tag_end: int, selfclose: bool, declared: set) -> None:
        if not self.stack:
            if self.root is None:
                self.root = _Open(name, start, tag_end, declared)
                if selfclose:
                    self.root_end = (tag_end, tag_end)
                else:
                    self.stack.append(self.root)
                return
            if not self.after_root(name, start):
                return
        self.stack[-1].children.append((name, start))
        if not selfclose:
            inherited = self.stack[-1].prefixes
            self.stack.append(_Open(name, start, tag_end,
                                    inherited | declared if declared else inherited))

    def after_root(self, name: str, start: int) -> bool:
        """An element after the root ended: reopen the root (True) or drop the rest."""
        root = self.root
        allowed = _CHILDREN.get(root.name)
        if self.root_end and self.root_end[1] > self.root_end[0] and allowed and name in allowed \
                and not root.reopened:
            end_start, end_end = self.root_end
            self.report("xml.content-after-root",
                        f"</{root.name}> ends the document here, but <{name}> follows at line "
                        f"{self.line_of(start)}", end_start,
                        hint=f"remove this </{root.name}> (one at the end of the file is enough)",
                        anchor=(root.start, root.name))
            self.edit(end_start, end_end, _blank(self.t[end_start:end_end]))
            root.reopened = True
            self.stack.append(root)
            return True
        self.drop_after_root(start, f"<{name}>")
        return False

    def drop_after_root(self, start: int, what: str) -> None:
        self.report("xml.content-after-root",
                    f"{what} after the end of the root element <{self.root.name}>", start,
                    hint="remove everything after the root element's end tag "
                         "(one file holds one document)")
        self.edit(start, self.n, _blank(self.t[start:]))
        self.stopped = True

    def end_tag(self, j: int) -> int:
        t, n = self.t, self.n
        match = _RE.name.match(t, j + 2)
        if not match:
            gt = t.find(">", j + 2)
            line_end = t.find("\n", j + 2)
            end = gt + 1 if gt >= 0 and (line_end < 0 or gt < line_end) else j + 2
            self.report("xml.bad-tag", "'</' without a tag name", j, hint="remove it",
                        anchor=self.anchor())
            self.edit(j, end, _blank(t[j:end]))
            return end
        name = match.group()
        k = self.skip_space(match.end())
        if k < n and t[k] == ">":
            end = k + 1
        else:
            gt = t.find(">", k)
            lt = t.find("<", k)
            line_end = t.find("\n", k)
            if gt >= 0 and (lt < 0 or gt < lt) and (line_end < 0 or gt < line_end):
                self.report("xml.bad-tag", f"the end tag </{name}> cannot carry anything but "
                            "its name", k, hint=f"write </{name}>")
                self.edit(k, gt, _blank(t[k:gt]))
                end = gt + 1
            else:
                self.report("xml.missing-close-bracket", f"the end tag </{name}> has no '>'", j,
                            hint=f"write </{name}>")
                self.edit(match.end(), match.end(), ">")
                end = match.end()
        self.close(name, j, end, match)
        return end

    def close(self, name: str, start: int, end: int, match) -> None:
        stack = self.stack
        if not stack:
            if self.root is not None and self.root_end is not None:
                self.drop_after_root(start, f"</{name}>")
            else:
                self.report("xml.mismatched-tag", f"</{name}> closes nothing: no <{name}> is open",
                            start, hint=f"remove </{name}>")
                self.edit(start, end, _blank(self.t[start:end]))
            return
        if stack[-1].name == name:
            self.pop(start, end)
            return
        index = next((i for i in range(len(stack) - 1, -1, -1) if stack[i].name == name), None)
        if index is None:
            innermost = range(max(0, len(stack) - SIMILAR_DEPTH), len(stack))
            scores = [(_similar(name, stack[i].name), i) for i in innermost]
            close = [(score, i) for score, i in scores if score >= 0.75]
            if close:
                index = max(close, key=lambda s: (s[0], s[1]))[1]
                meant = stack[index].name
                self.report("xml.mismatched-tag",
                            f"</{name}> does not match <{meant}> opened at line "
                            f"{self.line_of(stack[index].start)}", start,
                            hint=f"write </{meant}>", anchor=(stack[index].start, meant))
                self.edit(match.start(), match.end(), meant)
        if index is None and self.missing_start_tag(name, start):
            self.pop(start, end)
            return
        if index is None:
            top = stack[-1]
            self.report("xml.mismatched-tag",
                        f"</{name}> closes nothing: no <{name}> is open (the innermost open "
                        f"element is <{top.name}> from line {self.line_of(top.start)})", start,
                        hint=f"remove </{name}>, or write the missing <{name}> where it starts",
                        anchor=(top.start, top.name))
            self.edit(start, end, _blank(self.t[start:end]))
            return
        while len(stack) - 1 > index:
            self.force_close(before=start, closing=f"</{stack[index].name}>")
        self.pop(start, end)

    def missing_start_tag(self, name: str, start: int) -> bool:
        """``</name>`` closes nothing, but the open element's last children are what a <name>
        holds (a <box/> directly in <visual>, then </geometry>): put <name> back before them."""
        inside = _CHILDREN.get(name)
        top = self.stack[-1]
        allowed_here = self.allowed()
        if not inside or not top.children or (allowed_here is not None and name not in allowed_here):
            return False
        moved: deque = deque()
        while top.children and top.children[-1][0] in inside:
            moved.appendleft(top.children.pop())
        if not moved:
            return False
        child, child_start = moved[0]
        self.report("xml.mismatched-tag",
                    f"<{name}> is missing here: </{name}> at line {self.line_of(start)} closes "
                    "an element that was never opened", child_start,
                    hint=f"write <{name}> before <{child}>", anchor=(child_start, name))
        self.edit(child_start, child_start, f"<{name}>", opening=True)
        top.children.append((name, child_start))
        self.stack.append(_Open(name, child_start, child_start, top.prefixes, children=moved))
        return True

    def pop(self, start: int, end: int) -> None:
        self.stack.pop()
        if not self.stack:
            self.root_end = (start, end)

    def force_close(self, before: int, closing: str | None) -> None:
        """Close the innermost open element whose end tag is missing; say where it ends."""
        t = self.t
        element = self.stack.pop()
        name = element.name
        line = self.line_of
        moved: deque = deque()
        message = f"<{name}> opened here is never closed"
        anchor = (element.start, name)
        if element.first_text:
            start, end = element.first_text
            segment = t[start:end]
            lost = (re.compile(r"<?/" + re.escape(name) + r"(?:[ \t]*>)?").search(segment)
                    or re.compile(re.escape(name) + r"[ \t]*>").search(segment))
            if lost:
                before_text = segment[:lost.start()]
                self.edit(start + lost.start(), start + lost.end(), f"</{name}>")
            else:
                before_text = segment.rstrip()
                at = start + len(before_text)
                self.edit(at, at, f"</{name}>", first=True)
            hint = f"write </{name}> after '{_tail(before_text)}'"
            moved = element.children
        elif name in _EMPTY or not element.children:
            if element.gt_inserted:
                self.edit(element.tag_end, element.tag_end, f"</{name}>", first=True)
            else:
                self.edit(element.tag_end - 1, element.tag_end - 1, "/")
            hint = f"end the tag with '/>' (<{name} .../>)" if name in _EMPTY else \
                f"end the tag with '/>', or write </{name}> where it ends"
            moved = element.children
        else:
            allowed = _CHILDREN.get(name)
            if self.stack and f"{self.stack[-1].name}/{name}" in _CHILDREN:
                allowed = _CHILDREN[f"{self.stack[-1].name}/{name}"]
            stray = None
            if allowed:
                stray = next(((i, child) for i, child in enumerate(element.children)
                              if ":" not in child[0] and child[0] not in allowed), None)
            if stray:
                index, (child, child_start) = stray
                self.edit(child_start, child_start, f"</{name}>", first=True)
                hint = f"write </{name}> before <{child}> at line {line(child_start)}"
                moved = element.children
                for _ in range(index):
                    moved.popleft()
            elif closing is None:
                self.edit(self.n, self.n, f"</{name}>", first=True)
                hint = f"write </{name}> at the end of the file"
            else:
                self.edit(before, before, f"</{name}>", first=True)
                hint = f"write </{name}> before {closing} at line {line(before)}"
        if element.reopened:  # its early end tag was removed: closing it at the end is silent
            return
        self.report("xml.unclosed-tag", message, element.start, hint=hint, anchor=anchor)
        if self.stack:
            _adopt(self.stack[-1], moved)

    def end_of_file(self) -> None:
        if self.root is None:  # text only: one finding says it all
            self.problems = [p for p in self.problems if p.rule != "xml.stray-text"]
            self.report("xml.no-root", "the file has no XML element", 0,
                        hint="a URDF starts with <robot name=\"...\">")
            return
        while self.stack and not self.stopped:
            self.force_close(before=self.n, closing=None)

    # -- text -----------------------------------------------------------------------------
    def text(self, i: int, j: int) -> None:
        t = self.t
        if not t[i:j].strip():
            return
        if self.stack:
            self.check_entities(i, j, self.anchor())
            if "]]>" in t[i:j]:
                at = t.find("]]>", i, j)
                self.report("xml.bad-entity", "']]>' is not allowed in text", at,
                            hint="write ]]&gt;", anchor=self.anchor())
                self.edit(at + 2, at + 3, "&gt;")
        position = i
        for match in _RE.taglike.finditer(t, i, j):
            if self.stopped:
                return
            if self.taglike(match):
                self.plain_text(position, match.start())
                position = match.end()
        self.plain_text(position, j)

    def plain_text(self, i: int, j: int) -> None:
        t = self.t
        segment = t[i:j]
        if not segment.strip():
            return
        if not self.stack:
            first = i + len(segment) - len(segment.lstrip())
            if self.root is None:
                self.report("xml.stray-text",
                            f"text '{_short(segment)}' before the root element", first,
                            hint="remove it: a URDF starts with <robot name=\"...\">")
                self.edit(i, j, _blank(segment))
            elif not self.after_root_reported:
                self.after_root_reported = True
                self.report("xml.content-after-root",
                            f"text '{_short(segment)}' after the end of the root element "
                            f"<{self.root.name}>", first, hint="remove it")
                self.edit(i, j, _blank(segment))
            else:
                self.edit(i, j, _blank(segment))
            return
        top = self.stack[-1]
        if top.first_text is None and not top.children:
            top.first_text = (i, j)

    def taglike(self, match) -> bool:
        """Text at a line start that reads as a tag without its '<'. True if handled."""
        t = self.t
        name = match.group("name")
        name_start = match.start("name")
        attrs_text = match.group("attrs")
        attributes = [a for a, _ in _RE.attribute.findall(attrs_text)]
        close = match.group("close")
        valid = _RE.name.fullmatch(name) is not None
        allowed = self.allowed()
        parent = self.stack[-1].name if self.stack else None
        where = f"inside <{parent}>" if parent else "before the root element"
        if match.group("slash"):
            if valid and not attributes and any(e.name == name for e in self.stack):
                slash = match.start("slash")
                self.report("xml.missing-open-bracket", f"the end tag </{name}> lost its '<'",
                            slash, hint=f"write </{name}>")
                self.edit(slash, slash, "<")
                self.close(name, slash, match.end(), _FakeMatch(name_start, match.end("name")))
                return True
            return False
        if valid and not attributes and close == ">" and self.stack and self.stack[-1].name == name:
            self.report("xml.missing-open-bracket",
                        f"the end tag </{name}> lost its '</'", name_start, hint=f"write </{name}>")
            self.close(name, name_start, match.end(), _FakeMatch(name_start, match.end("name")))
            self.edit(name_start, name_start, "</")
            return True
        known = name in _KNOWN or (allowed is not None and name in allowed)
        if not attributes and not (valid and known):
            return False
        if valid and (known or allowed is None or ":" in name):
            self.report("xml.missing-open-bracket",
                        f"'{_short(t[name_start:match.end()])}' {where} is a <{name}> tag that "
                        "lost its '<' (it is read as text)", name_start,
                        hint=f"write <{name}{_attrs(attrs_text)}{close}",
                        anchor=(name_start, name))
            self.edit(name_start, name_start, "<", opening=True)
            self.synthetic(name, name_start, match, close, attrs_text)
            return True
        if not self.stack and self.root is not None:
            return False
        suggestion = _suggest(name, attributes, allowed if allowed else _KNOWN)
        excerpt = _short(t[name_start:match.end()])
        if suggestion:
            self.report("xml.stray-text",
                        f"stray text '{excerpt}' {where} looks like a <{suggestion}> tag that "
                        "lost its '<'", name_start,
                        hint=f"write <{suggestion}{_attrs(attrs_text)}{close}",
                        anchor=(name_start, suggestion))
            self.edit(name_start, match.end("name"), "<" + suggestion, opening=True)
            self.synthetic(suggestion, name_start, match, close, attrs_text)
            return True
        if valid:
            self.report("xml.stray-text",
                        f"stray text '{excerpt}' {where} looks like a tag that lost its '<'",
                        name_start, hint=f"write <{name}{_attrs(attrs_text)}{close}, or "
                                         "remove the line", anchor=(name_start, name))
            self.edit(name_start, name_start, "<", opening=True)
            self.synthetic(name, name_start, match, close, attrs_text)
            return True
        self.report("xml.stray-text", f"stray text '{excerpt}' {where}", name_start,
                    hint="remove it, or restore the tag it was", anchor=self.anchor())
        self.edit(name_start, match.end(), _blank(t[name_start:match.end()]))
        return True

    def synthetic(self, name: str, start: int, match, close: str, attrs_text: str) -> None:
        attributes = [a for a, _ in _RE.attribute.findall(attrs_text)]
        declared = self.check_prefixes(name, start, attributes)
        self.open(name, start, match.end("close"), close == "/>", declared)


def _adopt(parent: _Open, moved: deque) -> None:
    """Append ``moved`` to the children of ``parent`` in time proportional to the shorter of the
    two: thousands of nested unclosed elements hand a growing list up one level each."""
    if len(moved) > len(parent.children):
        moved.extendleft(reversed(parent.children))
        parent.children = moved
    else:
        parent.children.extend(moved)


class _FakeMatch:
    """The span of a name, where ``close`` expects the match of an end tag's name."""

    __slots__ = ("_end", "_start")

    def __init__(self, start: int, end: int):
        self._start = start
        self._end = end

    def start(self):
        return self._start

    def end(self):
        return self._end


def _apply(text: str, edits: list[tuple[int, int, str, int]]):
    """Apply non-overlapping edits (later overlapping ones are dropped). Returns the new text
    and, per line, the edits that changed a length: [(new_start_col, new_end_col, delta)]."""
    ordered = sorted(enumerate(edits), key=lambda e: (e[1][0], e[1][1] > e[1][0], e[1][3], e[0]))
    parts: list[str] = []
    position = 0
    shifts: list[tuple[int, int, int]] = []  # (new offset start, new offset end, delta)
    new_length = 0
    for _, (start, end, replacement, _priority) in ordered:
        if start < position:
            continue
        if text.count("\n", start, end) != replacement.count("\n"):
            continue  # an edit must never move a line
        parts.append(text[position:start])
        new_length += start - position
        delta = len(replacement) - (end - start)
        if delta:
            shifts.append((new_length, new_length + len(replacement), delta))
        parts.append(replacement)
        new_length += len(replacement)
        position = end
    parts.append(text[position:])
    new = "".join(parts)
    line_starts = _line_starts(new)
    per_line: dict[int, list[tuple[int, int, int]]] = {}
    for start, end, delta in shifts:
        line = _line_number(line_starts, start)
        base = line_starts[line - 1]
        per_line.setdefault(line, []).append((start - base, end - base, delta))
    return new, per_line


def _map_back(line: int, column0: int, history: list[dict]) -> int:
    """A 0-based column of a later round's text, in the original text."""
    for per_line in reversed(history):
        for start, end, delta in reversed(per_line.get(line, ())):
            if column0 >= end:
                column0 -= delta
            elif column0 > start:
                column0 = start
    return max(column0, 0)


def _line_starts(text: str) -> list[int]:
    """The offset where each line of ``text`` starts (for ``_position``)."""
    return [0] + [m.end() for m in re.finditer("\n", text)]


def _line_number(starts: list[int], offset: int) -> int:
    """1-based line of an offset, given the text's ``_line_starts``."""
    from bisect import bisect_right  # only a malformed file needs it

    return bisect_right(starts, offset)


def _position(starts: list[int], offset: int) -> tuple[int, int]:
    """1-based line and 0-based column of an offset, given the text's ``_line_starts``."""
    line = _line_number(starts, offset)
    return line, offset - starts[line - 1]


def _qualified(element) -> str:
    local = etree.QName(element).localname
    return f"{element.prefix}:{local}" if element.prefix else local


def _may_hold_taglike_text(text: str) -> bool:
    """Whether a well-formed text may hold a line that reads as a tag without its '<'. Every
    '<' of well-formed XML opens markup closed by one '>'; only text, attribute values, comments
    and CDATA can add a '>'. So equal counts (two passes in C) rule it out for nearly every file;
    the line regex runs only on the rest."""
    if text.count(">") <= text.count("<"):
        return False
    return any(_RE.taglike_hint.match(text, line.start()) for line in _RE.gt_line.finditer(text))


def repair(text: str, path: str) -> tuple[str, list[tuple[str, Finding]]]:
    """Repair recognised breakages; report each one, plus whatever the parser still rejects."""
    fixed, problems, _ = repair_and_parse(text, path)
    return fixed, problems


def repair_and_parse(text: str, path: str):
    """``repair`` plus the root element of the strictly parsed repaired text (None when the
    parser still rejects it): callers need not parse a well-formed file a second time."""
    problems: list[tuple[str, Finding]] = []
    try:
        return _repair(text, path, problems)
    except RecursionError:  # pragma: no cover - nothing here recurses; belt and braces
        problems.append(("xml.syntax", Finding("document too deeply nested", Loc(path, 1, 1))))
        return text, problems, None


def _repair(text: str, path: str, problems: list):
    written = text
    fixed, _, root = _repair_text(text, path, problems)
    if problems and fixed != written:
        problems[:] = _attach_edits(written, fixed, path, problems)
    return fixed, problems, root


def _attach_edits(written: str, fixed: str, path: str, problems: list) -> list:
    """Each problem with the edits that repair it, in the text as written: the repaired text
    differs from it within lines only (no line moves), so each changed run of a line is one
    edit, given to the nearest problem at or before it (a repair is made where the problem is
    found, or after it: an end tag inserted where the element should end)."""
    from urdftool.edits import edit, line_starts

    old_lines, new_lines = written.split("\n"), fixed.split("\n")
    if len(old_lines) != len(new_lines):
        return problems
    starts = line_starts(written)
    targets = sorted((f.loc.line or 0, f.loc.column or 0, index)
                     for index, (rule, f) in enumerate(problems)
                     if rule != "xml.syntax" and f.loc is not None)
    if not targets:
        return problems
    attached: dict[int, list] = {}
    for number, (old, new) in enumerate(zip(old_lines, new_lines), start=1):
        if old == new:
            continue
        base = starts[number - 1]
        for tag, i1, i2, j1, j2 in _line_changes(old, new):
            if tag == "equal":
                continue
            position = (number, i1 + 1)
            owner = targets[0][2]
            for line, column, index in targets:
                if (line, column) > position:
                    break
                owner = index
            attached.setdefault(owner, []).append(
                edit(path, written, base + i1, base + i2, new[j1:j2], starts))
    return [(rule, f._replace(edits=tuple(attached[index])) if index in attached else f)
            for index, (rule, f) in enumerate(problems)]


def _line_changes(old: str, new: str) -> list:
    """The changed runs of a line (difflib opcodes). A long line (a hostile one-line file) is
    one run between the common prefix and suffix: difflib is quadratic."""
    if len(old) + len(new) <= 4000:
        from difflib import SequenceMatcher

        return SequenceMatcher(None, old, new, autojunk=False).get_opcodes()
    head = 0
    while head < min(len(old), len(new)) and old[head] == new[head]:
        head += 1
    tail = 0
    while tail < min(len(old), len(new)) - head and old[-1 - tail] == new[-1 - tail]:
        tail += 1
    return [("replace", head, len(old) - tail, head, len(new) - tail)]


def _repair_text(text: str, path: str, problems: list):
    text, declaration_shift = _fix_declaration(text, path, problems)
    root, error = _strict_parse(text)
    if error is None and not _may_hold_taglike_text(text):
        return text, problems, root  # fast path: well-formed, nothing looks like a broken tag
    if not text.strip():
        problems.append(("xml.no-root", Finding("the file is empty", Loc(path, 1, 1),
                                                hint="a URDF starts with <robot name=\"...\">")))
        return text, problems, None
    original = text
    found: list[tuple[str, str, int, int, str | None, tuple | None, str | None]] = []
    text = _replace_bad_characters(text, found)
    history: list[dict] = [declaration_shift] if declaration_shift else []
    seen_keys: set = set()
    if found:
        root, error = _strict_parse(text)
    scanned = False
    for _ in range(MAX_ROUNDS):
        if error is None and (scanned or not _may_hold_taglike_text(text)):
            break
        budget = MAX_REPAIRS - len(found)
        if budget <= 0:
            break
        scanner = _Scanner(text, budget)
        scanner.scan()
        scanned = True
        starts = _line_starts(text)
        fresh = []
        for problem in scanner.problems:
            line, column0 = _position(starts, problem.offset)
            key = (problem.rule, problem.message, line, _map_back(line, column0, history))
            if key not in seen_keys:
                seen_keys.add(key)
                fresh.append(problem)
        if not fresh:
            break  # nothing new recognised: repeating the same repairs would not help
        fresh = fresh[:budget]
        for problem in fresh:
            line, column0 = _position(starts, problem.offset)
            column0 = _map_back(line, column0, history)
            anchor = None
            if problem.anchor:
                anchor = (_position(starts, problem.anchor[0])[0], problem.anchor[1])
            found.append((problem.rule, problem.message, line, column0 + 1, problem.hint, anchor,
                          problem.severity))
        text, per_line = _apply(text, scanner.edits)
        history.append(per_line)
        root, error = _strict_parse(text)
    elements = _anchored_paths(root, {f[5] for f in found if f[5]}) if root is not None else {}
    seen = set()
    for rule, message, line, column, hint, anchor, severity in found:
        key = (rule, message, line, column)
        if key in seen:
            continue
        seen.add(key)
        xpath = elements.get(anchor) if anchor else None
        problems.append((rule, Finding(message, Loc(path, line, column, xpath), hint=hint,
                                       severity=severity)))
    if len(found) >= MAX_REPAIRS:
        problems.append(("xml.syntax", Finding(
            f"more than {MAX_REPAIRS} XML problems; stopped repairing here",
            Loc(path, found[-1][2], found[-1][3]))))
    if error is not None and not any(f[0] == "xml.no-root" for f in found):
        problems.append(("xml.syntax", _syntax_finding(error, path, history, original)))
    return text, problems, root if error is None else None


def _anchored_paths(root, anchors: set) -> dict[tuple[int, str], str]:
    """The XPath of the first element at each (line, qualified name) of ``anchors``. Only those:
    ``getpath`` counts an element's preceding siblings, so one per element is quadratic."""
    lines = {line for line, _ in anchors}
    tree = root.getroottree()
    paths: dict[tuple[int, str], str] = {}
    for element in root.iter():
        if element.sourceline in lines and isinstance(element.tag, str):
            key = (element.sourceline, _qualified(element))
            if key in anchors and key not in paths:
                paths[key] = tree.getpath(element)
    return paths


def _syntax_finding(error, path: str, history: list, original: str) -> Finding:
    position = getattr(error, "position", None)
    message = getattr(error, "msg", None) or str(error)
    message = re.sub(r", line \d+, column \d+$", "", message).strip().splitlines()[0]
    if not position or not position[0]:
        return Finding(message, Loc(path, None, None))
    line, column = position
    lines = original.count("\n") + 1
    line = min(max(line, 1), lines)
    column = _map_back(line, max(column - 1, 0), history) + 1
    return Finding(message, Loc(path, line, column),
                   hint="urdftool does not recognise this breakage; fix it by hand "
                        "(what follows may be read wrongly)")


_TRAILING_NUL = ("NUL byte(s) at the end of the file; C-based robot tools stop reading there, "
                 "strict XML parsers reject the file")


def _replace_bad_characters(text: str, found: list) -> str:
    """Characters XML forbids (control characters, NUL) become spaces; one finding per run."""
    matches = list(_RE.bad_chars.finditer(text))
    if not matches:
        return text
    starts = _line_starts(text)
    content_end = len(text.rstrip("\x00 \t\r\n"))
    for count, match in enumerate(matches):
        if count == 20:
            line, column0 = _position(starts, match.start())
            more = f"{len(matches) - 20} more runs of characters XML forbids"
            found.append(("xml.bad-character", more, line, column0 + 1, None, None, None))
            break
        line, column0 = _position(starts, match.start())
        characters = ", ".join(f"U+{ord(c):04X}" for c in list(dict.fromkeys(match.group()))[:5])
        trailing = match.start() >= content_end and set(match.group()) == {"\x00"}
        if trailing:
            found.append(("xml.bad-character", _TRAILING_NUL,
                          line, column0 + 1, "remove them", None, "warning"))
        else:
            found.append(("xml.bad-character", f"character(s) XML forbids ({characters})", line,
                          column0 + 1, "remove them", None, None))
    return _RE.bad_chars.sub(lambda m: " " * len(m.group()), text)
