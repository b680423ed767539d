"""xacro expansion through the ``xacro`` package, with source positions kept.

xacro keeps global state and reads files itself; ``_patched_xacro`` swaps in, for the duration
of one expansion, a parser that repairs and tags every element with its file and line, a macro
call handler that records call sites, and a package finder that uses our resolver.
"""

from __future__ import annotations

import contextlib
import xml.dom.minidom
from pathlib import Path

from lxml import etree

from urdftool.model import Loc
from urdftool.report import Finding
from urdftool.source import (
    LOC_ATTR,
    VIA_ATTR,
    LoadOptions,
    Source,
    _column,
    _qualified_tag,
    _utf8_bytes,
    parse_text,
    quiet_stderr,
    read_text,
)


class _Files:
    """File table shared by the tags: index <-> path."""

    def __init__(self):
        self.paths: list[str] = []

    def index(self, path: str) -> int:
        if path not in self.paths:
            self.paths.append(path)
        return self.paths.index(path)


def _tag_elements(root, file_index: int, text: str) -> None:
    lines = text.splitlines()
    for element in root.iter():
        if not isinstance(element.tag, str):
            continue
        line = element.sourceline or 0
        column = _column(lines[line - 1], _qualified_tag(element)) if 0 < line <= len(lines) else None
        element.set(LOC_ATTR, f"{file_index}:{line}:{column or 0}")


def _parse_loc(value: str, files: _Files) -> Loc:
    index, line, column = (int(v) for v in value.split(":"))
    return Loc(files.paths[index], line or None, column or None)


@contextlib.contextmanager
def _patched_xacro(source: Source, files: _Files, options: LoadOptions, top: Path):
    import xacro
    import xacro.substitution_args as substitution_args

    saved = (xacro.parse, xacro.handle_macro_call, xacro.eval_all, substitution_args._eval_find,
             xacro.process_include)

    def display_path(filename: str) -> str:
        candidate = Path(filename)
        if candidate.resolve() == top.resolve():
            return source.path
        try:
            return str(candidate.resolve().relative_to(Path.cwd()))
        except ValueError:
            return str(candidate)

    def parse(inp, filename=None):
        if isinstance(inp, xml.dom.minidom.Document):
            return inp
        if inp is None:
            full = Path(xacro.root_dir if hasattr(xacro, "root_dir") else ".") / filename
            try:
                text = read_text(full)
            except Exception as exc:  # noqa: BLE001 - reported as a xacro problem
                xacro.filestack.pop()
                raise xacro.XacroException("cannot include", exc=OSError(str(exc))) from None
            shown = display_path(str(full))
        else:
            text = inp if isinstance(inp, str) else inp.read()
            shown = source.path
        source.texts.setdefault(shown, text)
        root = parse_text(text, shown, source)
        if root is None:
            raise xacro.XacroException(f"{shown}: not well-formed XML")
        _tag_elements(root, files.index(shown), text)
        return xml.dom.minidom.parseString(_utf8_bytes(etree.tostring(root, encoding="unicode")))

    def handle_macro_call(node, macros, symbols):
        if not node.tagName.startswith("xacro:") or node.tagName == "xacro:call":
            return saved[1](node, macros, symbols)
        call = node.getAttribute(LOC_ATTR)
        if call:
            node.removeAttribute(LOC_ATTR)
        parent, after = node.parentNode, node.nextSibling
        before = node.previousSibling
        while before is not None and before.nodeType != before.ELEMENT_NODE:
            before = before.previousSibling
        try:
            expanded = saved[1](node, macros, symbols)
        except xacro.XacroException as exc:
            if call and not hasattr(exc, "urdftool_loc"):
                exc.urdftool_loc = call
            raise
        if expanded and call and parent is not None:
            index, line, _ = call.split(":")
            site = f"{files.paths[int(index)]}:{line}"
            current = before.nextSibling if before is not None else parent.firstChild
            while current is not None and current is not after:
                if current.nodeType == current.ELEMENT_NODE:
                    for element in [current, *current.getElementsByTagName("*")]:
                        via = element.getAttribute(VIA_ATTR)
                        element.setAttribute(VIA_ATTR, f"{via};{site}" if via else site)
                current = current.nextSibling
        return expanded

    def eval_all(node, macros, symbols):
        try:
            return saved[2](node, macros, symbols)
        except xacro.XacroException as exc:
            if not hasattr(exc, "urdftool_loc") and node.nodeType == node.ELEMENT_NODE \
                    and node.getAttribute(LOC_ATTR):
                exc.urdftool_loc = node.getAttribute(LOC_ATTR)
            raise

    def process_include(elt, macros, symbols, func):
        """A missing include is reported and skipped, so the rest is still expanded."""
        try:
            return saved[4](elt, macros, symbols, func)
        except xacro.XacroException as exc:
            if not hasattr(exc, "urdftool_loc") and elt.getAttribute(LOC_ATTR):
                exc.urdftool_loc = elt.getAttribute(LOC_ATTR)
            if not isinstance(exc.exc, OSError) or not elt.getAttribute(LOC_ATTR):
                raise
            source.add("xacro.error", Finding(f"xacro: {str(exc).strip()}; skipped, the rest is "
                                              "expanded without it",
                                              _parse_loc(exc.urdftool_loc, files)))
            xacro.replace_node(elt, by=None)

    def find(package: str) -> str:
        directory = source.resolver.find(package) if source.resolver else None
        if directory is None:
            raise xacro.XacroException(
                f"package '{package}' not found (give it with -P {package}=DIR)")
        return str(directory)

    xacro.parse, xacro.handle_macro_call, xacro.eval_all = parse, handle_macro_call, eval_all
    substitution_args._eval_find, xacro.process_include = find, process_include
    try:
        yield xacro
    finally:
        (xacro.parse, xacro.handle_macro_call, xacro.eval_all, substitution_args._eval_find,
         xacro.process_include) = saved


def expand(source: Source, path: Path, options: LoadOptions) -> None:
    """Expand ``path`` into ``source.root`` with locations in ``source.locs``; xacro errors
    become ``xacro.error`` problems at the line where they happened."""
    files = _Files()
    files.index(source.path)
    with quiet_stderr(), _patched_xacro(source, files, options, path) as xacro:
        try:
            xacro.init_stacks(str(path))
            doc = xacro.process_file(str(path), mappings=dict(options.xacro_args))
            expanded = doc.toxml()
        except xacro.XacroException as exc:
            loc = _parse_loc(exc.urdftool_loc, files) if hasattr(exc, "urdftool_loc") else \
                Loc(source.path, None, None)
            message = str(exc).strip() or type(exc).__name__
            source.add("xacro.error", Finding(f"xacro: {message}", loc))
            return
        except Exception as exc:  # noqa: BLE001 - xacro raises plain Python errors too
            if not source.problems:
                source.add("xacro.error", Finding(f"xacro: {type(exc).__name__}: {exc}",
                                                  Loc(source.path, None, None)))
            return
    root = etree.fromstring(_utf8_bytes(expanded), etree.XMLParser(
        resolve_entities=False, no_network=True, huge_tree=False))
    for element in root.iter():
        if not isinstance(element.tag, str):
            continue
        value = element.attrib.pop(LOC_ATTR, None)
        via = element.attrib.pop(VIA_ATTR, None)
        if value:
            loc = _parse_loc(value, files)
            if via:
                loc = Loc(loc.path, loc.line, loc.column, None, tuple(via.split(";")))
            source.locs[element] = loc
    source.root = root


def expanded_xml(source: Source) -> str:
    """The expanded document as URDF text (what ``urdftool expand`` writes)."""
    if source.root is None:
        return ""
    return etree.tostring(source.root, encoding="unicode", pretty_print=False,
                          xml_declaration=False)
