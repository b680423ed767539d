"""Reading inputs: detect the kind (URDF, xacro, SDF), repair and parse the XML, expand xacro
with the ``xacro`` package, and remember for every element where the user wrote it.

For xacro, every element of every file read is tagged with its file and line before xacro sees
it; xacro carries the tags through macros and includes, and macro calls add their call site.
After expansion the tags are moved into ``Source.locs`` and removed from the tree.
"""

from __future__ import annotations

import codecs
import contextlib
import io
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from urdftool.errors import ToolError
from urdftool.model import Loc
from urdftool.packages import PackageResolver
from urdftool.report import Finding
from urdftool.xmlrepair import repair_and_parse, secure_parser

ROBOT_SUFFIXES = (".urdf", ".xacro", ".sdf")
LOC_ATTR = "urdftool-loc"
VIA_ATTR = "urdftool-via"
# xacro is run only when the file uses it: many generated URDFs keep an unused xmlns:xacro.
_XACRO_USE_RE = re.compile(r"<xacro:|\$\{|\$\((?:find|arg|env|optenv|eval|dirname) ")
_XACRO_ELEMENT_RE = re.compile(r"<xacro:")
_COMMENT_RE = re.compile(r"<!--.*?-->", re.DOTALL)
_ENCODING_DECL_RE = re.compile(r"(<\?xml[^>]*?encoding\s*=\s*)([\"'])[^\"']*\2")


@dataclass
class LoadOptions:
    packages: dict[str, str] = field(default_factory=dict)  # -P NAME=DIR
    xacro_args: dict[str, str] = field(default_factory=dict)  # NAME:=VALUE
    sdf_model: str | None = None  # SDF input: the model to convert (--model)
    sdf_model_paths: list[str] = field(default_factory=list)  # SDF: model:// search (--model-path)
    # untrusted input (issue 8; see urdftool.sandbox): xacro runs in a confined child process,
    # $(env)/$(optenv) see only allow_env, files are read only inside the package roots
    untrusted: bool = False
    allow_env: tuple[str, ...] = ()
    timeout: float | None = 5.0  # seconds for one xacro expansion (None: no limit)
    memory_mb: int = 1024  # memory for the sandboxed expansion, above what is already mapped


@dataclass
class Source:
    """One input file, read and (for xacro) expanded."""

    path: str  # as given by the user
    kind: str  # "urdf", "xacro" or "sdf"
    root: etree._Element | None = None  # the URDF document (expanded / converted)
    problems: list[tuple[str, Finding]] = field(default_factory=list)
    texts: dict[str, str] = field(default_factory=dict)  # every file read -> its (original) text
    resolver: PackageResolver | None = None
    locs: dict = field(default_factory=dict, repr=False)  # element -> Loc

    def loc(self, element) -> Loc:
        """Where ``element`` was written; elements made by xacro take their parent's place."""
        node = element
        while node is not None and node not in self.locs:
            node = node.getparent()
        base = self.locs.get(node) if node is not None else None
        xpath = element.getroottree().getpath(element) if self.root is not None else None
        if base is None:
            return Loc(self.path, None, None, xpath)
        return Loc(base.path, base.line, base.column, xpath, base.via)

    def problems_for(self, rule: str) -> list[Finding]:
        return [finding for rule_id, finding in self.problems if rule_id == rule]

    def add(self, rule: str, finding: Finding) -> None:
        self.problems.append((rule, finding))

    @property
    def base_dir(self) -> Path:
        return Path(self.path).resolve().parent


def detect_kind(path: Path, text: str) -> str:
    """'sdf', 'xacro' or 'urdf'. SDF by content; a ``.xacro`` file is xacro; a ``.urdf`` file is
    read as URDF consumers read it (leftover ``${...}`` or ``$(...)`` are reported, not
    evaluated) unless it has xacro elements; other names by whether the text uses xacro."""
    if re.search(r"<sdf[\s>]", text[:4096]) or path.suffix == ".sdf":
        return "sdf"
    if path.suffix == ".xacro":
        return "xacro"
    pattern = _XACRO_ELEMENT_RE if path.suffix == ".urdf" else _XACRO_USE_RE
    if pattern.search(text) and pattern.search(_COMMENT_RE.sub("", text)):
        return "xacro"
    return "urdf"


def read_text(path: Path) -> str:
    """Read a file as text: UTF-8, or UTF-16/32 with a BOM. Raises ToolError on anything else.
    An encoding declaration is rewritten to UTF-8 (the text is decoded now), lines unchanged."""
    try:
        data = path.read_bytes()
    except IsADirectoryError:
        raise ToolError(f"{path}: is a directory") from None
    except OSError as exc:
        raise ToolError(f"{path}: cannot read: {exc.strerror or exc}") from None
    for bom, encoding in ((codecs.BOM_UTF32_LE, "utf-32"), (codecs.BOM_UTF32_BE, "utf-32"),
                          (codecs.BOM_UTF8, "utf-8-sig"), (codecs.BOM_UTF16_LE, "utf-16"),
                          (codecs.BOM_UTF16_BE, "utf-16")):
        if data.startswith(bom):
            try:
                return _ENCODING_DECL_RE.sub(r"\1\2UTF-8\2", data.decode(encoding), count=1)
            except UnicodeDecodeError:
                break
    if b"\x00" in data[:4096]:
        raise ToolError(f"{path}: binary file, not an XML robot description")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ToolError(f"{path}: not UTF-8 text (byte {exc.start}): not a robot description") from None
    return text


def _utf8_bytes(text: str) -> bytes:
    """The text as UTF-8 bytes with any encoding declaration made to agree."""
    return _ENCODING_DECL_RE.sub(r"\1\2UTF-8\2", text, count=1).encode("utf-8")


def parse_text(text: str, path: str, source: Source) -> etree._Element | None:
    """Repair and parse one file's text; report problems into ``source``. None if hopeless."""
    fixed, problems, root = repair_and_parse(text, path)
    for rule, finding in problems:
        source.add(rule, finding)
    if root is not None:
        return root
    data = _utf8_bytes(fixed)
    try:
        root = etree.fromstring(data, secure_parser(recover=True))
    except etree.XMLSyntaxError:
        root = None
    if root is None and not any(r.startswith("xml.") for r, _ in problems):
        source.add("xml.syntax", Finding("no XML element found", Loc(path, 1, 1)))
    return root


def _column(line_text: str, tag: str) -> int | None:
    index = line_text.find("<" + tag)
    return index + 1 if index >= 0 else None


def _qualified_tag(element) -> str:
    try:
        local = etree.QName(element).localname
    except ValueError:  # a name lxml's recovery let through (e.g. "colo:")
        return str(element.tag)
    return f"{element.prefix}:{local}" if element.prefix else local


def index_locations(root, path: str, text: str) -> dict:
    """Element -> Loc for a parsed file (plain URDF)."""
    lines = text.splitlines()
    locs = {}
    for element in root.iter():
        if not isinstance(element.tag, str):
            continue
        line = element.sourceline
        column = None
        if line and line <= len(lines):
            column = _column(lines[line - 1], _qualified_tag(element))
        locs[element] = Loc(path, line, column)
    return locs


def load(path: str | Path, options: LoadOptions | None = None) -> Source:
    """Read one robot file into a Source. Raises ToolError when the file cannot be read."""
    options = options or LoadOptions()
    file_path = Path(path)
    if not file_path.exists():
        raise ToolError(f"{path}: no such file")
    resolver = PackageResolver(options.packages, file_path)
    if options.untrusted:  # issue 8: regular files inside the package roots only
        from urdftool.sandbox import check_input, confine

        check_input(file_path, resolver)
        confine(resolver, file_path)
    text = read_text(file_path)
    kind = detect_kind(file_path, text)
    source = Source(str(path), kind, texts={str(path): text}, resolver=resolver)
    if not text.strip():
        parse_text(text, str(path), source)  # reports xml.no-root
        return source
    if kind == "urdf":
        root = parse_text(text, str(path), source)
        if root is not None:
            source.root = root
            source.locs = index_locations(root, str(path), text)
    elif kind == "xacro":
        from urdftool.xacro_expand import expand

        expand(source, file_path, options)
    else:
        from urdftool.sdf import load_sdf

        load_sdf(source, file_path, text, options)
    return source


@contextlib.contextmanager
def quiet_stderr():
    """Keep what libraries print to sys.stderr out of our output."""
    buffer = io.StringIO()
    with contextlib.redirect_stderr(buffer), contextlib.redirect_stdout(io.StringIO()):
        yield buffer


# includes, old unprefixed ones too: the files they name are fragments, not robots
_INCLUDE_RE = re.compile(r"<(?:xacro:)?include\s[^>]*filename\s*=\s*[\"']([^\"']+)[\"']")


def discover(paths: list[str]) -> list[Path]:
    """Robot files among paths: files as given, directories searched recursively. In a
    directory, xacro files that another file found there includes are fragments (macros,
    materials, gazebo blocks), checked through the file that includes them, not alone."""
    found: list[Path] = []
    for raw in paths:
        path = Path(raw)
        if path.is_dir():
            in_directory: list[Path] = []
            for dirpath, dirnames, filenames in os.walk(path):
                dirnames[:] = sorted(d for d in dirnames if not d.startswith("."))
                for name in sorted(filenames):
                    if name.endswith(ROBOT_SUFFIXES):
                        in_directory.append(Path(dirpath) / name)
            included: set[str] = set()
            for candidate in in_directory:
                if candidate.suffix == ".xacro":
                    try:
                        head = candidate.read_text(encoding="utf-8", errors="replace")
                    except OSError:
                        continue
                    included.update(Path(m).name for m in _INCLUDE_RE.findall(head))
            found.extend(p for p in in_directory
                         if not (p.suffix == ".xacro" and p.name in included))
        elif path.exists():
            found.append(path)
        else:
            raise ToolError(f"{raw}: no such file or directory")
    return found
