"""Reading inputs: detect the kind (URDF, xacro, SDF), repair and parse the XML, expand xacro
with the ``xacro`` package, and remember for every element where the user wrote it.

For xacro, every element of every file read is tagged with its file and line before xacro sees
it; xacro carries the tags through macros and includes, and macro calls add their call site.
After expansion the tags are moved into ``Source.locs`` and removed from the tree.
"""

from __future__ import annotations

import codecs
import contextlib
import errno
import io
import os
import re
from pathlib import Path

from lxml import etree

from urdftool.errors import ToolError
from urdftool.files import read_regular, read_regular_text
from urdftool.findings import Finding, Loc
from urdftool.packages import PackageResolver
from urdftool.roots import has_vcs_component, repository_for, resolved
from urdftool.textscan import declared_encoding, declared_utf8, without_comments
from urdftool.uris import FIND
from urdftool.xmlrepair import repair_and_parse, secure_parser

ROBOT_SUFFIXES = (".urdf", ".xacro", ".sdf")
LOC_ATTR = "urdftool-loc"
VIA_ATTR = "urdftool-via"
# Patterns are compiled on first use (``re`` caches them), not at import: most runs need few.
# xacro is run only when the file uses it: many generated URDFs keep an unused xmlns:xacro.
_XACRO_USE = r"<xacro:|\$\{|\$\((?:find|arg|env|optenv|eval|dirname) "


# seconds for one xacro expansion, and under --untrusted for one file or mesh the sandboxed
# reader reads: what a hostile file may cost (a CI gate's budget per file is a few seconds)
DEFAULT_TIMEOUT = 3.0


class LoadOptions:
    __slots__ = ("allow_env", "in_sandbox", "lenient", "memory_mb", "overlay", "packages",
                 "roots", "sdf_model", "sdf_model_paths", "timeout", "untrusted", "xacro_args")

    def __init__(self, packages: dict[str, str] | None = None,
                 xacro_args: dict[str, str] | None = None, sdf_model: str | None = None,
                 sdf_model_paths: list[str] | None = None, untrusted: bool = False,
                 allow_env: tuple[str, ...] = (), timeout: float | None = DEFAULT_TIMEOUT,
                 memory_mb: int = 1024):
        self.packages = packages if packages is not None else {}  # -P NAME=DIR
        self.xacro_args = xacro_args if xacro_args is not None else {}  # NAME:=VALUE
        self.sdf_model = sdf_model  # SDF input: the model to convert (--model)
        self.sdf_model_paths = sdf_model_paths if sdf_model_paths is not None else []  # model://
        # untrusted input (issue 8; see urdftool.sandbox): xacro runs in a confined child process,
        # $(env)/$(optenv) see only allow_env, files are read only inside the package roots
        self.untrusted = untrusted
        self.allow_env = allow_env
        self.timeout = timeout  # seconds for one xacro expansion (None: no limit)
        self.memory_mb = memory_mb  # memory for the sandboxed expansion, above what is mapped
        # files read from memory instead of the disk (resolved path -> text): a check looking
        # through the safe fixes, or ``check --fix`` re-checking what it fixed
        self.overlay: dict[str, str] = {}
        # xacro: an expression naming something undefined is left as written instead of
        # stopping the expansion (a check looking past the error it already reported)
        self.lenient = False
        # what the run may read (urdftool.roots.Roots): set once by urdftool.loader from the
        # operator's options and the repository; never from what a repository file says
        self.roots = None
        self.in_sandbox = False  # read by the sandboxed reader (its environment is empty)


class Source:
    """One input file, read and (for xacro) expanded."""

    __slots__ = ("_xpaths", "controllers", "defaults", "kind", "lines", "locs", "lost", "missing",
                 "path", "problems", "reads", "resolver", "root", "texts", "unread")

    def __init__(self, path: str, kind: str, root: etree._Element | None = None,
                 problems: list[tuple[str, Finding]] | None = None,
                 texts: dict[str, str] | None = None, resolver: PackageResolver | None = None,
                 locs: dict | None = None):
        self.path = path  # as given by the user
        self.kind = kind  # "urdf", "xacro" or "sdf"
        self.root = root  # the URDF document (expanded / converted)
        self.problems = problems if problems is not None else []
        self.texts = texts if texts is not None else {}  # every file read -> its original text
        self.reads: set[str] = set()  # other files the reading read (YAML): resolved paths
        # files the reading asked for that are not there (an include, a YAML file): resolved
        # path -> the Locs that asked (a deleted file's includers: ``check --changed``)
        self.missing: dict[str, list[Loc]] = {}
        # the controllers YAML its simulator plugins name, as ``controllers.read_controllers``
        # gives them (issue 31: the ``ros2_control`` rules)
        self.controllers: list = []
        # files an <include> names that were not read (unprefixed, hence never processed):
        # shown path -> text (``find_unread``)
        self.unread: dict[str, str] = {}
        # SDF: the names (``a::b`` keys) an include that could not be read would define, and
        # the joints left out with it: findings that name them only repeat the include's
        # (``urdftool.rules.lost``)
        self.lost: tuple[str, ...] = ()
        # SDF: URDF link name -> whether its model is static, for each link without <inertial>
        # (the conversion writes SDFormat's default 1 kg, 1 kg·m²: not the author's values)
        self.defaults: dict[str, bool] = {}
        self.resolver = resolver
        self.locs = locs if locs is not None else {}  # element -> Loc (xacro, SDF)
        self.lines: str | None = None  # plain URDF: its text (positions from the parser)
        self._xpaths: dict = {}  # element -> its XPath, filled a parent's children at a time

    def loc(self, element) -> Loc:
        """Where ``element`` was written; elements made by xacro take their parent's place, and
        comments their element's."""
        xpath = self.xpath(element) if self.root is not None else None
        node = element
        text = self.lines
        if text is not None:  # found when asked: most elements never are
            tag = node.tag
            while not isinstance(tag, str):
                node = node.getparent()
                if node is None:
                    return Loc(self.path, None, None, xpath)
                tag = node.tag
            line = node.sourceline
            column = None
            if line:
                from urdftool.edits import line_starts

                if tag[0] == "{":  # namespaced: written with its prefix
                    tag = _qualified_tag(node)
                line, column = tag_position(text, line_starts(text), line, tag)
            return Loc(self.path, line, column, xpath)
        while node is not None and node not in self.locs:
            node = node.getparent()
        base = self.locs.get(node) if node is not None else None
        if base is None:
            return Loc(self.path, None, None, xpath)
        return Loc(base.path, base.line, base.column, xpath, base.via)

    def xpath(self, element) -> str:
        """``getpath(element)`` in linear time over a document. lxml's ``getpath`` counts the
        preceding siblings of every ancestor, which is quadratic on a wide or deep (hostile)
        file; here the paths of a parent's children are made in one pass over them."""
        paths = self._xpaths
        known = paths.get(element)
        if known is not None:  # the common case: a parent's children are filled at once
            return known
        chain = []  # element and its ancestors up to one whose path is known
        node = element
        while node not in paths:
            parent = node.getparent()
            if parent is None or not isinstance(node.tag, str) or node.tag[0] == "{":
                paths[node] = node.getroottree().getpath(node)  # root, comment, namespaced
                break
            chain.append(parent)
            node = parent
        for parent in reversed(chain):
            base = paths[parent]
            children = [c for c in parent if isinstance(c.tag, str) and c.tag[0] != "{"]
            total: dict[str, int] = {}
            for child in children:
                total[child.tag] = total.get(child.tag, 0) + 1
            seen: dict[str, int] = {}
            for child in children:
                tag = child.tag
                if total[tag] == 1:
                    paths.setdefault(child, f"{base}/{tag}")
                else:
                    seen[tag] = seen.get(tag, 0) + 1
                    paths.setdefault(child, f"{base}/{tag}[{seen[tag]}]")
        return paths[element]

    def forget_xpaths(self) -> None:
        """Drop the XPath memo: it keeps every element it named alive (after an SDF
        conversion, the whole SDF document: issue 15)."""
        self._xpaths = {}

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
    evaluated) unless it has xacro elements, or has no ``<link>`` and uses xacro (a fragment
    named ``.urdf``); other names by whether the text uses xacro."""
    if re.search(r"<sdf[\s>]", text[:4096]) or path.suffix == ".sdf":
        return "sdf"
    if path.suffix == ".xacro":
        return "xacro"
    pattern = "<xacro:" if path.suffix == ".urdf" else _XACRO_USE
    if re.search(pattern, text) and re.search(pattern, without_comments(text)):
        return "xacro"
    if path.suffix == ".urdf" and "<link" not in text and re.search(_XACRO_USE, text) and (
            re.search(_XACRO_USE, without_comments(text))):
        return "xacro"  # no robot a URDF consumer could read: a xacro fragment so named
    return "urdf"


MAX_FILE_BYTES = 64 << 20  # a robot description file larger than this is refused unread


def read_bytes(path: Path) -> bytes:
    """A regular file's bytes, at most MAX_FILE_BYTES (``files.read_regular``). A device, FIFO
    or directory (a committed symlink to /dev/zero, say) or a larger file is a ToolError, found
    before reading."""
    try:
        return read_regular(path, MAX_FILE_BYTES)
    except IsADirectoryError:
        raise ToolError(f"{path}: is a directory") from None
    except OSError as exc:
        if exc.errno in (errno.EINVAL, errno.EFBIG):
            raise ToolError(f"{path}: {exc.strerror}") from None
        raise ToolError(f"{path}: cannot read: {exc.strerror or exc}") from None


def shown_path(file: str | Path, entry: str) -> str:
    """How a file read on behalf of ``entry`` (an include, a macro file) is named in findings:
    the way the user named the entry, relative to the working directory when ``entry`` was
    given relative, absolute when it was given absolute, so one report never mixes the two."""
    if os.path.isabs(entry):
        return os.path.abspath(file)
    return os.path.relpath(os.path.abspath(file))


def read_text(path: Path) -> str:
    """Read a file as text: UTF-8, UTF-16/32 with a BOM, or the encoding its XML declaration
    names (any Python knows). Raises ToolError on anything else. An encoding declaration is
    rewritten to UTF-8 (the text is decoded now), lines unchanged."""
    data = read_bytes(path)
    for bom, encoding in ((codecs.BOM_UTF32_LE, "utf-32"), (codecs.BOM_UTF32_BE, "utf-32"),
                          (codecs.BOM_UTF8, "utf-8-sig"), (codecs.BOM_UTF16_LE, "utf-16"),
                          (codecs.BOM_UTF16_BE, "utf-16")):
        if data.startswith(bom):
            try:
                return declared_utf8(data.decode(encoding))
            except UnicodeDecodeError:
                break
    if b"\x00" in data[:4096]:
        raise ToolError(f"{path}: binary file, not an XML robot description")
    declared = declared_encoding(data)
    if declared is not None:  # ISO-8859-1, Windows-1252, ...: read as the declaration says
        try:
            return declared_utf8(data.decode(declared))
        except UnicodeDecodeError as exc:
            raise ToolError(f"{path}: not {declared} text as its XML declaration says (byte "
                            f"{exc.start})") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ToolError(f"{path}: not UTF-8 text (byte {exc.start}): not a robot description") from None
    return text


def read_input(path: Path, options: LoadOptions | None) -> str:
    """``read_text(path)``, or the text given for it in ``options.overlay``."""
    overlay = getattr(options, "overlay", None)
    if overlay:
        text = overlay.get(str(path.resolve()))
        if text is not None:
            return text
    return read_text(path)


def _utf8_bytes(text: str) -> bytes:
    """The text as UTF-8 bytes with any encoding declaration made to agree."""
    return declared_utf8(text).encode("utf-8")


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


LONG_LINE = 4096  # a minified file's one line: no column (finding it per element is quadratic)
LOOK_BACK = 8192  # characters above its line where a tag written across lines may start


def tag_position(text: str, starts: list[int], line: int, tag: str) -> tuple[int, int | None]:
    """(line, column) of the ``<tag`` of an element the parser places at ``line`` (libxml2
    gives the line where its start tag ends): the first on that line, or else the nearest above
    it (a tag written across lines: its first line, not the ``izz="0.001" />`` of its last);
    (line, None) when there is none near or the line is a minified file's one long line.
    ``starts``: ``edits.line_starts(text)``."""
    if not 0 < line <= len(starts):
        return line, None
    start = starts[line - 1]
    end = starts[line] - 1 if line < len(starts) else len(text)
    if end - start > LONG_LINE:
        return line, None
    needle = "<" + tag
    index = text.find(needle, start, end)
    while index >= 0 and not _ends_name(text, index + len(needle)):
        index = text.find(needle, index + 1, end)
    if index >= 0:
        return line, index - start + 1
    index = text.rfind(needle, max(0, start - LOOK_BACK), start)
    while index >= 0 and not _ends_name(text, index + len(needle)):
        index = text.rfind(needle, max(0, start - LOOK_BACK), index)
    if index < 0:
        return line, None
    from bisect import bisect_right

    found = bisect_right(starts, index)
    return found, index - starts[found - 1] + 1


def _ends_name(text: str, index: int) -> bool:
    return index >= len(text) or text[index] in " \t\r\n/>"


def _qualified_tag(element) -> str:
    try:
        local = etree.QName(element).localname
    except ValueError:  # a name lxml's recovery let through (e.g. "colo:")
        return str(element.tag)
    return f"{element.prefix}:{local}" if element.prefix else local


# elements whose children are not URDF (an <include> in them is no xacro include)
FOREIGN_BLOCKS = frozenset({"gazebo", "ros2_control", "transmission", "plugin", "sensor"})
MAX_UNREAD = 200


def find_unread(source: Source, options: LoadOptions | None = None) -> None:
    """``source.unread``: the files an ``<include>`` names that the reading did not read (an
    include without the xacro: prefix is never processed), and those they include, so that
    the rules see the whole robot and its fixes reach every file. Read like the input: from
    ``options.overlay`` first, regular files of at most MAX_FILE_BYTES, and only inside the
    package roots when the input is untrusted (this runs in the sandboxed reader then)."""
    pending: list[tuple[str, str]] = list(source.texts.items())
    seen = {_real(p) for p in source.texts}

    def add(spec: str, base: Path) -> None:
        target = _include_target(source, spec, base)
        if target is None or str(target) in seen or len(seen) > MAX_UNREAD:
            return
        seen.add(str(target))
        try:
            text = read_input(target, options)
        except ToolError:
            return
        shown = shown_path(target, source.path)
        source.unread[shown] = text
        pending.append((shown, text))

    if source.root is not None:  # unprefixed includes that survived the expansion
        for element in source.root.iter("include"):
            filename = element.get("filename")
            if filename and not any(isinstance(a.tag, str) and a.tag in FOREIGN_BLOCKS
                                    for a in element.iterancestors()):
                add(filename, Path(_real(source.loc(element).path)).parent)
    while pending:  # and the includes (of any kind) of every file, transitively
        path, text = pending.pop()
        for spec in re.findall(_INCLUDE, text):
            add(spec, Path(_real(path)).parent)


def _real(path) -> str:
    """The realpath of ``path`` (memoised for the run); as written when a link on the way
    cannot be read (what is then asked of it fails as for a missing file)."""
    try:
        return resolved(os.path.abspath(path))
    except (OSError, ValueError):
        return os.path.abspath(path)


def _include_target(source: Source, spec: str, base: Path) -> Path | None:
    """The file an include's filename names (``$(find)`` resolved like xacro does), or None:
    computed from an expression, not a file, or not readable for this input."""
    resolver = source.resolver
    if "${" in spec or "$(arg" in spec:
        return None

    def find(match: re.Match) -> str:
        directory = resolver.find(match.group(1)) if resolver is not None else None
        if directory is None:
            raise LookupError(match.group(1))
        return str(directory)

    try:
        path = Path(FIND.sub(find, spec))
    except LookupError:
        return None
    path = Path(_real(path if path.is_absolute() else base / path))
    if resolver is not None and not resolver.allows(path):
        return None
    try:
        return path if path.is_file() else None
    except OSError:
        return None


@contextlib.contextmanager
def quiet_stderr():
    """Keep what libraries print to sys.stderr out of our output."""
    buffer = io.StringIO()
    with contextlib.redirect_stderr(buffer), contextlib.redirect_stdout(io.StringIO()):
        yield buffer


# includes, old unprefixed ones too: the files they name are fragments, not robots
# (the tag's text never crosses a '<': each match looks at the text up to the next one)
_INCLUDE = r"<(?:xacro:)?include\s[^<>]*filename\s*=\s*[\"']([^\"'<]+)[\"']"


def _links_out(path: Path, top: Path) -> bool:
    """Whether ``path`` is a link resolving outside the repository ``top`` (or into its
    version-control metadata): not read here (the loader refuses it as an input)."""
    if not os.path.islink(path):
        return False
    target = Path(os.path.realpath(path))
    return not target.is_relative_to(top) or has_vcs_component(target, top)


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
            top = repository_for(path)
            for candidate in in_directory:
                if candidate.suffix == ".xacro" and not _links_out(candidate, top):
                    try:
                        head = read_regular_text(candidate)
                    except OSError:
                        continue
                    included.update(Path(m).name for m in re.findall(_INCLUDE, head))
            found.extend(p for p in in_directory
                         if not (p.suffix == ".xacro" and p.name in included))
        elif path.exists() or path.is_symlink():  # a dangling link: the loader answers
            found.append(path)
        else:
            raise ToolError(f"{raw}: no such file or directory")
    return found
