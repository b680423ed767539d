"""xacro expansion through the ``xacro`` package, with source positions kept.

xacro keeps global state and reads files itself; ``_patched_xacro`` swaps in, for the duration
of one expansion, a parser that repairs and tags every element with its file and line, a macro
call handler that records call sites, and a package finder that uses our resolver.

It also makes expansion safe on untrusted files: every expression (``${}``, ``$(eval)``, YAML
units) is evaluated by ``urdftool.xacro_eval``'s interpreter, never by Python's ``eval``;
``xacro.load_yaml`` reads with the safe loader through ``_Policy``; ``$(env)``/``$(optenv)``
see only ``--allow-env`` variables, files are read only inside the run's roots (``LoadOptions.roots``:
the repository and the operator's directories), and a deadline bounds the run. With
``LoadOptions.untrusted`` the whole xacro pass runs in a child process (``urdftool.sandbox``)
with a wall-time and memory limit; it hands back the expanded text, tagged with the source
locations, and the problems found.
"""

from __future__ import annotations

import contextlib
import functools
import os
import re
import time
import xml.dom.minicompat
import xml.dom.minidom
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from urdftool.errors import exception_text
from urdftool.findings import Finding, Loc
from urdftool.source import (
    LOC_ATTR,
    VIA_ATTR,
    LoadOptions,
    Source,
    _qualified_tag,
    _utf8_bytes,
    parse_text,
    quiet_stderr,
    read_input,
    shown_path,
    tag_position,
)
from urdftool.xacro_eval import (
    REFUSED_TEXT,
    Deadline,
    DependsOnRefused,
    Interpreter,
    LimitExceeded,
    Refused,
    UnsafeExpression,
)
from urdftool.xmlrepair import secure_parser


class _Files:
    """File table shared by the tags: index <-> path."""

    def __init__(self):
        self.paths: list[str] = []

    def index(self, path: str) -> int:
        if path not in self.paths:
            self.paths.append(path)
        return self.paths.index(path)


class _ChildList(xml.dom.minicompat.NodeList):
    """minidom's child list (``NodeList``) that looks a child up near the last place it found
    one. xacro replaces each macro call by its body with ``insertBefore``/``removeChild``,
    which search the parent's children from the first (``list.index``): expansion was
    quadratic in the number of siblings (a robot of n macro calls, issue 15). Installed for
    one expansion by ``_patched_xacro``; the methods are minidom's own otherwise."""

    __slots__ = ("_near",)

    def index(self, item, *bounds):
        if not bounds:
            near = getattr(self, "_near", 0)
            try:
                found = list.index(self, item, max(near - 32, 0), near + 32)
            except ValueError:
                found = list.index(self, item)
            self._near = found
            return found
        return list.index(self, item, *bounds)

    def remove(self, item):
        del self[self.index(item)]


def _tag_elements(root, file_index: int, text: str) -> None:
    from urdftool.edits import line_starts

    starts = line_starts(text)
    for element in root.iter():
        if not isinstance(element.tag, str):
            continue
        line, column = tag_position(text, starts, element.sourceline or 0,
                                    _qualified_tag(element))
        element.set(LOC_ATTR, f"{file_index}:{line}:{column or 0}")


def _parse_loc(value: str, files: _Files) -> Loc:
    index, line, column = (int(v) for v in value.split(":"))
    return Loc(files.paths[index], line or None, column or None)


MAX_FILE_BYTES = 64 << 20  # a robot description file (or YAML file) larger than this is refused
# the expanded document, in characters of XML (issue 21): every file parsed (each include, each
# time) and every copy of a macro body or block xacro makes, counted as it is made; values of
# expressions are the interpreter's (xacro_eval.MAX_BUDGET). Copies are counted as written,
# before xacro drops what it drops (comments before a macro call, branches not taken): the
# largest of 72 real robots (realworld-dev, real-packages, robots/, example-robot-data) is
# pr2.urdf.xacro, 114 KB expanded and 387 KB counted, 85x below this limit
MAX_DOCUMENT = 32 << 20
MAX_NAME = 1024  # characters of an element or attribute name xacro builds (xacro:element/attribute)


class _Size:
    """What an expansion has built so far, in characters of XML (``MAX_DOCUMENT``)."""

    def __init__(self):
        self.total = 0
        self.known: dict[int, tuple[object, int]] = {}  # id(node) -> (node, its size)

    def add(self, size: int, what: str) -> None:
        self.total += size
        if self.total > MAX_DOCUMENT:
            from urdftool.xacro_eval import LimitExceeded

            raise LimitExceeded(f"the expanded document grew past {MAX_DOCUMENT >> 20} MB "
                                f"(limit of urdftool; {what})")

    def of(self, node) -> int:
        """``node``'s size written out (memoised: a macro body is copied at every call)."""
        known = self.known.get(id(node))
        if known is not None and known[0] is node:
            return known[1]
        size, stack = 0, [node]
        while stack:
            current = stack.pop()
            if current.nodeType == current.ELEMENT_NODE:
                size += 2 * len(current.tagName) + 5
                attrs = current._attrs
                if attrs:
                    size += sum(len(k) + len(a.value) + 4 for k, a in attrs.items())
                stack.extend(current.childNodes)
            else:
                size += len(getattr(current, "data", "") or "")
        self.known[id(node)] = (node, size)
        return size


@dataclass
class Expansion:
    """What the xacro pass hands back (pickle-able: it may come from the sandbox process)."""

    text: str | None  # the expanded XML, every element tagged with LOC_ATTR / VIA_ATTR
    files: list[str] = field(default_factory=list)  # the index used in the tags
    problems: list = field(default_factory=list)  # (rule, Finding)
    texts: dict[str, str] = field(default_factory=dict)  # every file read -> its text
    reads: list[str] = field(default_factory=list)  # other files read (YAML), resolved
    # files asked for that are not there (an include, a YAML file): resolved -> where asked
    missing: dict = field(default_factory=dict)


class OutsidePackage(Exception):
    """A file outside the run's roots (the repository, the operator's directories), named by
    the file being expanded."""

    def __init__(self, path: str):
        super().__init__(f"{path} is outside the repository; urdftool reads only inside it and "
                         "the operator's directories (-P NAME=DIR, ROS_PACKAGE_PATH)")
        self.path = path


BLANK_ATTR = "urdftool-blank"
# seconds past the deadline after which the watchdog interrupts a trusted expansion (the
# interpreter's own deadline stops it first when it is the one working)
WATCHDOG_GRACE = 0.2
@functools.lru_cache(maxsize=1)
def watched_code() -> tuple[str, ...]:
    """Where the watchdog may interrupt: xacro's, PyYAML's and minidom's own code (their
    package directories, as installed) and the interpreter's file; never urdftool's patching
    of xacro (its restoring must run whole), whatever directory names the checkout's path holds
    (a clone under a folder called `xacro` is not xacro's code)."""
    import xacro
    import yaml

    from urdftool import xacro_eval

    def directory(module) -> str:
        return os.path.dirname(os.path.abspath(module.__file__)).replace("\\", "/") + "/"

    return (directory(xacro), directory(yaml), directory(xml.dom),
            os.path.abspath(xacro_eval.__file__).replace("\\", "/"))


def _mark_blank_only(doc) -> None:
    """Mark the elements whose only children are blank text (a macro-only file's root, a
    ``<link>`` with a newline inside): xacro's writer drops blank text but still writes them
    ``<x>`` ``</x>``, while its serialisation read back has no child left to tell. An element
    or attribute name longer than ``MAX_NAME`` (built by xacro:element/xacro:attribute) is
    refused (LimitExceeded, at the element)."""
    from urdftool.xacro_eval import LimitExceeded

    stack = [doc.documentElement]
    while stack:
        node = stack.pop()
        if len(node.tagName) > MAX_NAME or (node._attrs and max(map(len, node._attrs)) > MAX_NAME):
            longest = max([node.tagName, *(node._attrs or ())], key=len)
            refused = LimitExceeded(f"an element or attribute name of {len(longest)} characters, "
                                    f"past urdftool's limit of {MAX_NAME}")
            if node.getAttribute(LOC_ATTR):
                refused.urdftool_loc = node.getAttribute(LOC_ATTR)
            raise refused
        children = node.childNodes
        if children and all(c.nodeType == c.TEXT_NODE and not c.data.strip() for c in children):
            node.setAttribute(BLANK_ATTR, "")
        stack.extend(c for c in children if c.nodeType == c.ELEMENT_NODE)


class _Reported(Exception):
    """Expansion stopped on problems already recorded (a condition on a refused value)."""


@dataclass
class _Policy:
    deadline: float | None = None  # time.monotonic() after which expansion stops
    roots: object = None  # urdftool.roots.Roots: files only inside them (None: anywhere)
    allow_env: frozenset | None = None  # $(env)/$(optenv) see only these (None: all: tests)
    hidden: list = field(default_factory=list)  # $(optenv NAME) that took its default for it
    refused: set = field(default_factory=set)  # (expression, reason) already reported

    def check_path(self, filename: str) -> None:
        if self.roots is not None and not self.roots.readable(filename):
            raise OutsidePackage(str(filename))


def _cause(exc: BaseException, kinds) -> BaseException | None:
    """The first exception of ``kinds`` among ``exc``, what xacro wrapped in it, and its
    causes."""
    seen = set()
    stack = [exc]
    while stack:
        current = stack.pop()
        if current is None or id(current) in seen:
            continue
        seen.add(id(current))
        if isinstance(current, kinds):
            return current
        stack.extend([getattr(current, "exc", None), current.__cause__, current.__context__])
    return None


UNSAFE_HINT = ("xacro expressions may use numbers, strings, properties, operators, math "
               "functions and YAML data; nothing that reaches Python internals")


def _unsafe_expressions(root) -> list[tuple[str, str, int | None]]:
    """(expression, reason, line) of every literal expression of the file that the validator
    rejects, where it is written (also those in macros never called and branches never taken).
    Expansion goes on: each is refused again, silently, if it is evaluated (its value is the
    placeholder)."""
    from urdftool.xacro_eval import scan

    found = []
    for element in root.iter():
        if not isinstance(element.tag, str):
            continue
        values = [*element.attrib.values(), element.text or "", element.tail or ""]
        for value in values:
            for unsafe in scan(value):
                found.append((unsafe.expression, unsafe.reason, element.sourceline))
    return found


def _refuse(source: Source, policy: _Policy, rule: str, expression: str, reason: str,
            loc: Loc, stops: bool = False) -> None:
    """One located finding per refused expression (and reason), however often it is met."""
    key = (expression.strip(), reason)
    if key in policy.refused:
        return
    policy.refused.add(key)
    then = ("expansion stops here (which branch the file meant is unknown)" if stops else
            f"its value is '{REFUSED_TEXT}' and expansion goes on")
    if rule == "xacro.unsafe-expression":
        source.add(rule, Finding(f"unsafe expression '{expression.strip()}': {reason}; "
                                 f"urdftool does not evaluate it: {then}", loc,
                                 hint=UNSAFE_HINT))
    else:
        source.add(rule, Finding(f"xacro: expression '{expression.strip()}': {reason}; {then}",
                                 loc))


def _copy_node(node, document):
    """A deep copy of a minidom element, text or comment owned by ``document``: what
    ``cloneNode(deep=True)`` makes (the same nodes, attributes and slots), without minidom's
    per-attribute DOM calls, about three times faster. xacro copies every macro body it
    expands, and each parsed file is copied from ``_PARSED`` instead of parsed again."""
    minidom = xml.dom.minidom
    kind = node.nodeType
    if kind == node.ELEMENT_NODE:
        new = minidom.Element.__new__(minidom.Element)
        new.ownerDocument = document
        new.parentNode = new.nextSibling = new.previousSibling = None
        new.tagName = new.nodeName = node.tagName
        new.prefix, new.namespaceURI = node.prefix, node.namespaceURI
        if hasattr(node, "_localName"):
            new._localName = node._localName
        if node._attrs:
            copies = {}
            for attr in node._attrs.values():
                copied = minidom.Attr.__new__(minidom.Attr)
                copied._name, copied._value = attr._name, attr._value
                copied.namespaceURI, copied._prefix = attr.namespaceURI, attr._prefix
                if hasattr(attr, "_localName"):
                    copied._localName = attr._localName
                copied.ownerDocument, copied.ownerElement = document, new
                text = minidom.Text()  # the attribute's value as its one child
                text._data = attr._value
                copied.childNodes = minidom.NodeList((text,))
                copies[id(attr)] = copied
            new._attrs = {key: copies[id(attr)] for key, attr in node._attrs.items()}
            new._attrsNS = {key: copies[id(attr)] for key, attr in node._attrsNS.items()}
        else:
            new._attrs = new._attrsNS = None
        children = new.childNodes = minidom.NodeList()
        previous = None
        for child in node.childNodes:
            copied = _copy_node(child, document)
            copied.parentNode, copied.previousSibling = new, previous
            if previous is not None:
                previous.nextSibling = copied
            children.append(copied)
            previous = copied
        return new
    if kind in (node.TEXT_NODE, node.COMMENT_NODE, node.CDATA_SECTION_NODE):
        new = type(node).__new__(type(node))
        new._data, new.ownerDocument = node._data, document
        new.parentNode = new.previousSibling = new.nextSibling = None
        return new
    return _CLONE_NODE(node, True, document)


_CLONE_NODE = xml.dom.minidom._clone_node


def _clone_node(node, deep, document):
    """minidom's ``_clone_node`` (behind ``cloneNode``) while xacro runs: ``_copy_node`` for
    the deep copies of elements."""
    if deep and node.nodeType == node.ELEMENT_NODE:
        return _copy_node(node, document)
    return _CLONE_NODE(node, deep, document)


def _copy_document(template):
    """A new minidom document holding a copy of ``template``'s nodes."""
    document = xml.dom.minidom.Document()
    document.__dict__.update(template.__dict__)  # the XML declaration's version, encoding
    for child in template.childNodes:
        document.appendChild(_copy_node(child, document))
    return document


# (text, shown path, file index) -> (minidom document, unsafe expressions) of a file read
# without a problem a second time: kept across expansions (the language server expands on every
# edit; a package's entries include the same files), never handed out, copied for each one
_PARSED: dict[tuple[str, str, int], tuple[object, list]] = {}
_SEEN: set[tuple[str, str, int]] = set()  # read once without a problem
MAX_PARSED = 64


@contextlib.contextmanager
def _patched(target, **values):
    """``target``'s attributes (a module's functions, a class's method) set to ``values`` for the
    duration of the block, the originals put back whatever happens. Process-wide: every
    thread sees them (one expansion runs at a time: check's workers are processes, the
    language server expands in one worker thread)."""
    saved = {name: getattr(target, name) for name in values}
    for name, value in values.items():
        setattr(target, name, value)
    try:
        yield saved
    finally:
        for name, value in saved.items():
            setattr(target, name, value)


@contextlib.contextmanager
def _patched_xacro(source: Source, files: _Files, options: LoadOptions, top: Path,
                   policy: _Policy | None = None):
    """xacro (and minidom) as one expansion of ``top`` needs them, in four patch groups
    (``_Reader`` holds what they share): minidom's child lists and copies (fast, counted),
    the reading of files (repaired, tagged, inside the roots), the evaluation of expressions
    (urdftool's interpreter, the hidden environment) and the locations (macro call sites, the
    element being evaluated). Each group is undone on leaving, in reverse order."""
    import xacro
    from xacro import substitution_args

    reader = _Reader(source, files, options, top, policy)

    def clone_node(node, deep):  # a function: a method of the node it is called on
        return reader.counted_clone(node, deep)

    with contextlib.ExitStack() as stack:
        stack.enter_context(_patched(xml.dom.minidom, NodeList=_ChildList,
                                     _clone_node=_clone_node))
        stack.enter_context(_patched(xml.dom.minidom.Node, cloneNode=clone_node))
        stack.enter_context(_patched(xacro, parse=reader.parse,
                                     process_include=reader.process_include,
                                     get_include_files=reader.get_include_files))
        stack.enter_context(_patched(substitution_args, _eval_find=reader.find))
        # a name is a valid identifier or not whatever the file (xacro parses it with ast each
        # time); verbosity is restored (process_file sets it)
        stack.enter_context(_patched(
            xacro, safe_eval=reader.safe_eval, eval_text=reader.eval_text,
            get_boolean_value=reader.get_boolean_value, verbosity=xacro.verbosity,
            is_valid_name=functools.lru_cache(maxsize=4096)(xacro.is_valid_name)))
        stack.enter_context(_patched(substitution_args, _eval=reader.eval_substitution,
                                     _eval_env=reader.eval_env,
                                     _eval_optenv=reader.eval_optenv))
        stack.enter_context(_patched(xacro, handle_macro_call=reader.handle_macro_call,
                                     eval_all=reader.eval_all))
        yield xacro


class _Reader:
    """What one expansion puts in place of xacro's functions (``_patched_xacro``), and what
    they share: the ``Source`` being filled, the files read (``_Files``), the policy, the
    interpreter, the document's size, the elements being evaluated (``where``). xacro's own
    functions, taken when it is made, are called through ``original``."""

    def __init__(self, source: Source, files: _Files, options: LoadOptions, top: Path,
                 policy: _Policy | None):
        import xacro
        from xacro import substitution_args

        self.xacro, self.substitution_args = xacro, substitution_args
        self.source, self.files, self.options, self.top = source, files, options, top
        self.policy = policy or _Policy()
        self.where: list[str] = []  # the LOC_ATTR of the elements being evaluated, innermost last
        self.globs: list[bool] = []  # per pattern of the current <xacro:include>: matched nothing
        self.size = _Size()
        self.interpreter = Interpreter(self.policy.deadline, self.read_yaml)
        self.original = {name: getattr(xacro, name) for name in (
            "handle_macro_call", "eval_all", "process_include", "eval_text",
            "get_boolean_value", "get_include_files")}
        self.original.update({name: getattr(substitution_args, name)
                              for name in ("_eval_env", "_eval_optenv")})
        self.clone_node = xml.dom.minidom.Node.cloneNode
        self.text_of = self.lenient_eval_text if getattr(options, "lenient", False) \
            else self.original["eval_text"]

    # -- locations --

    def current_loc(self) -> Loc:
        return _parse_loc(self.where[-1], self.files) if self.where \
            else Loc(self.source.path, None, None)

    def refused(self, rule: str, expression: str, reason: str) -> Refused:
        _refuse(self.source, self.policy, rule, expression, reason, self.current_loc())
        return Refused()

    def condition_loc(self, condition: str) -> Loc:
        """The line of a condition (xacro gives get_boolean_value its text, not its node)."""
        where, source = self.where, self.source
        shown = self.files.paths[int(where[-1].split(":")[0])] if where else source.path
        text = source.texts.get(shown, "")
        found = re.search(r"<(?:xacro:)?(?:if|unless)\s[^<>]*?value\s*=\s*[\"']"
                          + re.escape(condition) + "[\"']", text)
        if found is None:
            return self.current_loc()
        return Loc(shown, text.count("\n", 0, found.start()) + 1, None)

    def display_path(self, filename: str) -> str:
        if Path(filename).resolve() == self.top.resolve():
            return self.source.path
        return shown_path(filename, self.source.path)

    # -- reading --

    def read_yaml(self, filename: str) -> str:
        """xacro.load_yaml's file: inside the package roots, a regular file, bounded."""
        self.policy.check_path(filename)
        if not os.path.lexists(filename):  # asked for and absent: in the reads graph
            self.source.missing.setdefault(os.path.realpath(filename), []).append(
                self.current_loc())
        if os.path.exists(filename) and not os.path.isfile(filename):
            raise OSError(f"{filename}: not a regular file (a device or a pipe)")
        if os.path.isfile(filename) and os.path.getsize(filename) > MAX_FILE_BYTES:
            raise LimitExceeded(f"{filename}: larger than {MAX_FILE_BYTES >> 20} MB")
        text = read_input(Path(filename), self.options)  # an open editor buffer: its text
        self.source.reads.add(os.path.realpath(filename))  # a trigger of the entry (issue 23)
        return text

    def counted_clone(self, node, deep):
        """A macro body or block copied into the document: counted before it is made."""
        if deep:
            self.size.add(self.size.of(node), "copying a macro body or block again")
        return self.clone_node(node, deep)

    def parse(self, inp, filename=None):
        if isinstance(inp, xml.dom.minidom.Document):
            return inp
        if inp is None:
            full = Path(self.xacro.root_dir if hasattr(self.xacro, "root_dir") else ".") / filename
            try:
                self.policy.check_path(str(full))
                if full.exists() and not full.is_file() and not full.is_dir():
                    raise OSError(f"{full}: not a regular file (a device or a pipe)")
                if full.is_file() and full.stat().st_size > MAX_FILE_BYTES:
                    raise LimitExceeded(f"{full}: larger than {MAX_FILE_BYTES >> 20} MB")
                text = read_input(full, self.options)
            except (OutsidePackage, LimitExceeded) as exc:
                self.xacro.filestack.pop()
                raise self.xacro.XacroException(str(exc), exc=exc) from None
            except Exception as exc:  # noqa: BLE001 - reported as a xacro problem
                self.xacro.filestack.pop()
                failed = self.xacro.XacroException("cannot include", exc=OSError(str(exc)))
                if not os.path.lexists(full):  # asked for and absent: in the reads graph
                    failed.urdftool_missing = os.path.realpath(full)
                raise failed from None
            shown = self.display_path(str(full))
        else:
            text = inp if isinstance(inp, str) else inp.read()
            shown = self.source.path
        self.source.texts.setdefault(shown, text)
        self.size.add(len(text), f"reading {shown}")
        key = (text, shown, self.files.index(shown))
        known = _PARSED.get(key)
        if known is not None:
            for expression, reason, line in known[1]:
                _refuse(self.source, self.policy, "xacro.unsafe-expression", expression, reason,
                        Loc(shown, line, None))
            return _copy_document(known[0])
        problems = len(self.source.problems)
        root = parse_text(text, shown, self.source)
        clean = len(self.source.problems) == problems
        if root is None:
            raise self.xacro.XacroException(f"{shown}: not well-formed XML")
        info = root.getroottree().docinfo
        dtd = info.internalDTD
        if info.system_url or info.public_id or (dtd is not None and any(dtd.iterentities())):
            refused = self.xacro.XacroException(
                "a DOCTYPE that declares entities or names an external DTD: urdftool neither "
                "loads DTDs nor expands entities, so the file is not expanded")
            line = text.count("\n", 0, max(text.find("<!DOCTYPE"), 0)) + 1
            refused.urdftool_loc = f"{self.files.index(shown)}:{line}:0"
            raise refused
        unsafe = _unsafe_expressions(root)
        for expression, reason, line in unsafe:
            _refuse(self.source, self.policy, "xacro.unsafe-expression", expression, reason,
                    Loc(shown, line, None))
        _tag_elements(root, self.files.index(shown), text)
        # Only the element tree goes to minidom: no DOCTYPE, so no entity declarations; an
        # entity reference left unexpanded by the secure parser is refused here.
        for node in root.iter(etree.Entity):
            raise self.xacro.XacroException(
                f"{shown}:{node.sourceline}: entity reference {node.text} "
                "is not expanded (DTD entities are disabled)")
        # the comments beside the root element too: xacro writes them (issue 14)
        around = [etree.tostring(node, encoding="unicode", with_tail=False)
                  for node in root.itersiblings(preceding=True)][::-1]
        after = [etree.tostring(node, encoding="unicode", with_tail=False)
                 for node in root.itersiblings()]
        document = xml.dom.minidom.parseString(_utf8_bytes(
            "".join(around) + etree.tostring(root, encoding="unicode") + "".join(after)))
        if clean and key in _SEEN:  # read again without a problem: kept, a copy given
            if len(_PARSED) >= MAX_PARSED:
                del _PARSED[next(iter(_PARSED))]
            _PARSED[key] = (document, unsafe)
            return _copy_document(document)
        if clean:  # the first time: no copy (most files of a run are read once)
            if len(_SEEN) >= 4 * MAX_PARSED:
                _SEEN.clear()
            _SEEN.add(key)
        return document

    def get_include_files(self, filename_spec, symbols):
        matched = list(self.original["get_include_files"](filename_spec, symbols))
        if self.policy.roots is not None and (len(matched) != 1 or re.search(
                "[*[?]+", self.xacro.eval_text(filename_spec, symbols))):
            # a pattern: only the files that may be read, so that the answer is the same
            # whether or not files outside the roots match it
            matched = [m for m in matched if self.policy.roots.readable(m)]
        self.globs.append(not matched)  # only a pattern matches nothing (a name is tried as is)
        return matched

    def process_include(self, elt, macros, symbols, func):
        """A missing include is reported and skipped, so the rest is still expanded; a
        pattern that matches nothing is said (plain xacro only warns on stderr), the same way
        whether or not something outside the package roots would have matched."""
        try:
            self.globs.clear()
            result = self.original["process_include"](elt, macros, symbols, func)
            if any(self.globs) and elt.getAttribute(LOC_ATTR):
                self.source.add("xacro.error", Finding(
                    f"xacro: include '{elt.getAttribute('filename')}' matched no file"
                    + (" inside the repository" if self.policy.roots is not None else "")
                    + "; nothing included", _parse_loc(elt.getAttribute(LOC_ATTR), self.files),
                    severity="warning"))
            return result
        except LimitExceeded as exc:  # (the document's size: at the include that grew it)
            if not hasattr(exc, "urdftool_loc") and elt.getAttribute(LOC_ATTR):
                exc.urdftool_loc = elt.getAttribute(LOC_ATTR)
            raise
        except self.xacro.XacroException as exc:
            if not hasattr(exc, "urdftool_loc") and elt.getAttribute(LOC_ATTR):
                exc.urdftool_loc = elt.getAttribute(LOC_ATTR)
            outside = isinstance(exc.exc, OutsidePackage)
            # $(find PKG) of a package not found: the include cannot be read, as a missing file
            package = getattr(exc.exc, "urdftool_package", None) \
                or getattr(exc, "urdftool_package", None)
            if not (isinstance(exc.exc, OSError) or outside or package) \
                    or not elt.getAttribute(LOC_ATTR):
                raise
            # outside the roots: the include as written, never the file found (a glob would
            # tell which files exist on the machine)
            message = (f"include '{elt.getAttribute('filename')}' is outside the repository; "
                       "urdftool reads only inside it and the operator's directories (give the "
                       "package with -P NAME=DIR or ROS_PACKAGE_PATH)") if outside \
                else f"$(find {package}): package '{package}' not found" if package \
                else str(exc).strip()
            loc = _parse_loc(exc.urdftool_loc, self.files)
            template = None
            if hasattr(exc, "urdftool_missing"):  # the include of a file that is not there
                self.source.missing.setdefault(exc.urdftool_missing, []).append(loc)
                template = _template_of(exc.urdftool_missing, self.policy)
            if template is not None:  # made by the build: not a defect of the sources
                message = (f"cannot include '{elt.getAttribute('filename')}': it is generated "
                           f"at build time from {Path(template).name} (not in the source tree)")
            self.source.add("xacro.error", Finding(
                f"xacro: {message}; skipped, the rest is expanded without it", loc,
                hint=None if template is None else
                "check the built package (its share directory), or give the directory of the "
                "generated file with -P NAME=DIR",
                severity=None if template is None else "warning"))
            self.xacro.replace_node(elt, by=None)

    def find(self, package: str) -> str:
        directory = self.source.resolver.find(package) if self.source.resolver else None
        if directory is None:
            missing = self.xacro.XacroException(
                f"package '{package}' not found (looked in: "
                f"{self.source.resolver.tried() if self.source.resolver else '-P'}; give it with "
                f"-P {package}=DIR, or put the directory holding it on ROS_PACKAGE_PATH)")
            missing.urdftool_package = package
            raise missing
        return str(directory)

    # -- evaluation --

    def safe_eval(self, expr, globals, locals=None):
        """An expression by the interpreter; a refused one is a finding and the placeholder
        (the rest of the file is still expanded), except past the deadline."""
        try:
            return self.interpreter.evaluate(expr, globals)
        except DependsOnRefused:
            return Refused()
        except UnsafeExpression as exc:
            return self.refused("xacro.unsafe-expression", exc.expression, exc.reason)
        except Deadline:
            raise
        except LimitExceeded as exc:
            return self.refused("xacro.limit-exceeded", expr, str(exc))

    def eval_substitution(self, s, context):
        """xacro's ``$(eval ...)``, by the interpreter."""
        if "arg" not in context:
            context["arg"] = {}

        def arg(name):
            return self.substitution_args.convert_value(
                self.substitution_args._eval_arg(name, args=context["arg"]), "auto")

        def dirname():
            return self.substitution_args._eval_dirname(context["filename"])

        if s.find("__") >= 0:
            return self.refused("xacro.unsafe-expression", s,
                                "$(eval ...) may not contain double underscore expressions")
        functions = {"arg": arg, "dirname": dirname, "env": self.eval_env,
                     "optenv": self.eval_optenv, "find": self.find}
        try:
            value = self.interpreter.evaluate_substitution(s, context["arg"], functions)
        except DependsOnRefused:
            return Refused()
        except UnsafeExpression as exc:
            return self.refused("xacro.unsafe-expression", s, exc.reason)
        except Deadline:
            raise
        except LimitExceeded as exc:
            return self.refused("xacro.limit-exceeded", s, str(exc))
        return self.interpreter.to_str(value)

    def eval_env(self, name):
        if self.policy.allow_env is not None and name not in self.policy.allow_env:
            raise self.substitution_args.SubstitutionException(
                f"environment variable {name} is not visible: a checked file reads only the "
                "variables named with --allow-env")
        return self.original["_eval_env"](name)

    def eval_optenv(self, name, default=""):
        if self.policy.allow_env is not None and name not in self.policy.allow_env:
            self.policy.hidden.append(name)
            return default
        return self.original["_eval_optenv"](name, default)

    def lenient_eval_text(self, text, symbols):
        """An expression naming something undefined (or computed from one) stays as written."""
        try:
            return self.original["eval_text"](text, symbols)
        except self.xacro.XacroException as exc:
            if _cause(exc, (NameError, TypeError)) is None:
                raise
            return text

    def eval_text(self, text, symbols):
        """A text without ``$`` is its own value (xacro lexes every attribute and text node,
        whitespace included, to find that out)."""
        if type(text) is str and "$" not in text:
            return text
        return self.text_of(text, symbols)

    def get_boolean_value(self, value, condition):
        if isinstance(value, Refused) or (isinstance(value, str) and REFUSED_TEXT in value):
            # which branch the file meant is unknown: expanding either could raise false alarms
            _refuse(self.source, self.policy, "xacro.unsafe-expression", condition,
                    "a condition on a refused expression", self.condition_loc(condition),
                    stops=True)
            raise _Reported()
        return self.original["get_boolean_value"](value, condition)

    # -- macro calls and the element being evaluated --

    def handle_macro_call(self, node, macros, symbols):
        if self.policy.deadline is not None and time.monotonic() > self.policy.deadline:
            raise Deadline("xacro expansion took longer than the time limit")
        if not node.tagName.startswith("xacro:") or node.tagName == "xacro:call":
            return self.original["handle_macro_call"](node, macros, symbols)
        call = node.getAttribute(LOC_ATTR)
        if call:
            node.removeAttribute(LOC_ATTR)
        parent, after = node.parentNode, node.nextSibling
        before = node.previousSibling
        while before is not None and before.nodeType != before.ELEMENT_NODE:
            before = before.previousSibling
        try:
            expanded = self.original["handle_macro_call"](node, macros, symbols)
        except (self.xacro.XacroException, LimitExceeded) as exc:
            if call and not hasattr(exc, "urdftool_loc"):
                exc.urdftool_loc = call
            raise
        if expanded and call and parent is not None:
            index, line, _ = call.split(":")
            site = f"{self.files.paths[int(index)]}:{line}"
            current = before.nextSibling if before is not None else parent.firstChild
            while current is not None and current is not after:
                if current.nodeType == current.ELEMENT_NODE:  # what it holds inherits it
                    via = current.getAttribute(VIA_ATTR)
                    current.setAttribute(VIA_ATTR, f"{via};{site}" if via else site)
                current = current.nextSibling
        return expanded

    def eval_all(self, node, macros, symbols):
        tagged = node.nodeType == node.ELEMENT_NODE and node.getAttribute(LOC_ATTR)
        if tagged:
            self.where.append(tagged)
        try:
            return self.original["eval_all"](node, macros, symbols)
        except (self.xacro.XacroException, UnsafeExpression, LimitExceeded) as exc:
            if not hasattr(exc, "urdftool_loc") and tagged:
                exc.urdftool_loc = tagged
            raise
        finally:
            if tagged:
                self.where.pop()


# what a build makes a file from: ``robot.urdf.xacro`` from ``robot.urdf.xacro.in`` (CMake's
# configure_file), ``.em`` (empy), Jinja and other templates; ``robot.urdf`` from its xacro
TEMPLATE_SUFFIXES = (".in", ".em", ".j2", ".jinja", ".jinja2", ".template", ".tmpl", ".tpl")


def _template_of(missing: str, policy: _Policy) -> str | None:
    """The template a missing include is generated from at build time (a sibling named as
    the file plus a template suffix, or a ``.urdf``'s ``.urdf.xacro``) that may be read, or
    None."""
    names = [missing + suffix for suffix in TEMPLATE_SUFFIXES]
    if missing.endswith(".urdf"):
        names.append(missing + ".xacro")
    for name in names:
        if (policy.roots is None or policy.roots.readable(name)) and os.path.isfile(name):
            return name
    return None


def _xacro_pass(source: Source, path: Path, options: LoadOptions, policy: _Policy) -> Expansion:
    """Run xacro on ``path``; everything it reports is in the returned Expansion."""
    from urdftool.xacro_eval import LimitExceeded, UnsafeExpression

    work = Source(source.path, source.kind, texts=dict(source.texts), resolver=source.resolver)
    files = _Files()
    files.index(source.path)

    def where(exc) -> Loc:
        return _parse_loc(exc.urdftool_loc, files) if hasattr(exc, "urdftool_loc") else \
            Loc(source.path, None, None)

    expanded = None
    with quiet_stderr(), _patched_xacro(work, files, options, path, policy) as xacro:
        try:
            xacro.init_stacks(str(path))
            doc = xacro.process_file(str(path), mappings=dict(options.xacro_args), verbosity=0)
            _mark_blank_only(doc)
            expanded = doc.toxml()
            if len(expanded) > MAX_DOCUMENT:  # (what expressions made: theirs is a budget too)
                raise LimitExceeded(f"the expanded document is {len(expanded) >> 20} MB, past "
                                    f"urdftool's limit of {MAX_DOCUMENT >> 20} MB")
        except _Reported:
            pass
        except Exception as exc:  # noqa: BLE001 - xacro raises plain Python errors too
            located = _cause(exc, (xacro.XacroException, UnsafeExpression, LimitExceeded))
            loc = where(located) if located is not None else Loc(source.path, None, None)
            unsafe = _cause(exc, (UnsafeExpression,))
            limit = _cause(exc, (LimitExceeded, RecursionError, MemoryError))
            outside = _cause(exc, (OutsidePackage,))
            if unsafe is not None:
                work.add("xacro.unsafe-expression", Finding(
                    f"{unsafe}; urdftool does not evaluate it", loc,
                    hint="xacro expressions may use numbers, strings, properties, operators, "
                         "math functions and YAML data; nothing that reaches Python internals"))
            elif limit is not None:
                what = {RecursionError: "macros or properties nested too deeply (recursion?)",
                        MemoryError: "out of memory"}.get(type(limit), str(limit))
                work.add("xacro.limit-exceeded", Finding(f"xacro: {what}; expansion stopped",
                                                         loc))
            elif outside is not None:
                work.add("xacro.error", Finding(f"xacro: {outside}", loc))
            elif isinstance(exc, xacro.XacroException):
                message = _xacro_message(exc) or type(exc).__name__
                work.add("xacro.error", Finding(f"xacro: {message}", loc))
            elif not work.problems:
                work.add("xacro.error", Finding(f"xacro: {exception_text(exc)}", loc))
    _report_hidden(work, policy.hidden, getattr(options, "in_sandbox", False))
    return Expansion(expanded, list(files.paths), [_one_line(rule, f) for rule, f in work.problems],
                     work.texts, sorted(work.reads), work.missing)


def _report_hidden(work: Source, names: list[str], in_sandbox: bool = False) -> None:
    """``xacro.env-not-allowed`` for each ``$(optenv NAME default)`` that took its default
    because urdftool hides NAME (in every mode, unless --allow-env names it), at its first use, when NAME is set (in the sandboxed
    reader, where nothing is set, the parent keeps those whose variable it has)."""
    for name in dict.fromkeys(names):
        if not in_sandbox and name not in os.environ:
            continue  # not set: the default is what xacro itself would take
        loc = Loc(work.path, None, None)
        for shown, text in work.texts.items():
            index = text.find(f"optenv {name}")
            if index >= 0:
                line_start = text.rfind("\n", 0, index) + 1
                loc = Loc(shown, text.count("\n", 0, index) + 1, index - line_start + 1)
                break
        work.add("xacro.env-not-allowed", Finding(
            f"$(optenv {name}) took its default: urdftool hides the environment variable "
            f"{name}, which is set, unless --allow-env names it", loc, hint=f"--allow-env {name}", severity="warning"))


def _xacro_message(exc) -> str:
    """A XacroException's text, without the repeat xacro makes of a cause it wraps
    (``eval_extension``: ``"<class 'X'>: MESSAGE MESSAGE"``)."""
    text = str(exc).strip()
    inner = getattr(exc, "exc", None)
    if inner is not None and text.startswith(f"{type(inner)}: "):
        text = text[len(f"{type(inner)}: "):]
        cause = str(inner).strip()
        if cause and text.startswith(f"{cause} {cause}"):
            text = text[len(cause) + 1:]
    return text


def _one_line(rule: str, finding: Finding) -> tuple[str, Finding]:
    """xacro's messages carry newlines ("...\nwhen evaluating expression '...'"): one line."""
    if not rule.startswith("xacro.") or "\n" not in finding.message:
        return rule, finding
    message = "; ".join(part.strip() for part in finding.message.splitlines() if part.strip())
    return rule, Finding(message, finding.loc, finding.hint, finding.severity)


def expand(source: Source, path: Path, options: LoadOptions) -> None:
    """Expand ``path`` into ``source.root`` with locations in ``source.locs``; xacro errors
    become ``xacro.*`` problems at the line where they happened (in this process: the loader
    decides where, ``urdftool.loader``)."""
    from urdftool import budget
    from urdftool.xacro_eval import Deadline

    timeout = budget.clamp(getattr(options, "timeout", None))  # at most what the run has left
    deadline = time.monotonic() + timeout if timeout else None

    def late() -> Deadline:
        return Deadline("xacro expansion took longer than the time limit")

    # a watchdog stops what the interpreter does not count (xacro's and PyYAML's own Python)
    # shortly after the deadline: in this process (--trusted), and in the sandboxed reader
    # (which its parent kills a second later otherwise)
    watched = timeout + WATCHDOG_GRACE if timeout else None
    try:
        with budget.watchdog(watched, late, watched_code()):
            # files only inside the run's roots (urdftool.loader), in every mode; variables
            # only the --allow-env ones
            result = _xacro_pass(source, path, options,
                                 _Policy(deadline, getattr(options, "roots", None),
                                         frozenset(options.allow_env)))
    except Deadline as exc:  # raised outside xacro's own run (setting up, reporting)
        result = Expansion(None, [], [("xacro.limit-exceeded", Finding(
            f"xacro: {exc}; expansion stopped", Loc(source.path, None, None)))], {})
    source.problems.extend(result.problems)
    source.reads.update(result.reads)
    for missing, where in result.missing.items():
        source.missing.setdefault(missing, []).extend(where)
    for shown, text in result.texts.items():
        source.texts.setdefault(shown, text)
    if result.text is None:
        return
    files = _Files()
    files.paths = list(result.files)
    try:
        root = etree.fromstring(_utf8_bytes(result.text), secure_parser())
    except etree.XMLSyntaxError as exc:
        source.add("xacro.limit-exceeded", Finding(
            f"xacro: the expanded document cannot be read back ({exc.msg}); nested too deeply "
            "or too large", Loc(source.path, None, None)))
        return
    for element in root.iter():  # written <x>...</x> by xacro, not <x/>: keep a blank text
        if isinstance(element.tag, str) and element.attrib.pop(BLANK_ATTR, None) is not None \
                and element.text is None and not len(element):
            element.text = "\n"
    # the call sites an element was expanded at, innermost first: its own (a macro body's
    # top-level elements are tagged) then its parent's (issue 15: tagging every element of
    # every expansion was a tenth of a big expansion)
    inherited: dict = {}
    for element in root.iter():
        if not isinstance(element.tag, str):
            continue
        value = element.attrib.pop(LOC_ATTR, None)
        own = element.attrib.pop(VIA_ATTR, None)
        via = inherited.get(element.getparent(), ())
        if own:
            via = (*own.split(";"), *via)
        if via:
            inherited[element] = via
        if value:
            loc = _parse_loc(value, files)
            if via:
                loc = Loc(loc.path, loc.line, loc.column, None, via)
            source.locs[element] = loc
    source.root = root


def expanded_xml(source: Source) -> str:
    """The expanded document as URDF text (what ``urdftool expand`` writes)."""
    if source.root is None:
        return ""
    return etree.tostring(source.root, encoding="unicode", pretty_print=False,
                          xml_declaration=False)
