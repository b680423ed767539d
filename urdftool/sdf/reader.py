"""Reading SDFormat: files, versions, ``<include>``, and the model tree with scoped names.

The reader turns an SDF file into ``Scope`` objects (one per model, nested models and
included models as child scopes) holding ``Entity`` records (links, joints, frames) with their
raw poses. Everything it finds wrong is reported into the ``Source`` as ``sdf.*`` problems with
the file and line where it was written; it never raises on bad input.
"""

from __future__ import annotations

import difflib
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from urdftool.errors import ToolError
from urdftool.findings import Finding, Loc
from urdftool.sdf.schema import SPEC
from urdftool.sdf.transforms import IDENTITY, Transform
from urdftool.source import tag_position
from urdftool.uris import parse_uri

SUPPORTED = ((1, 4), (1, 5), (1, 6), (1, 7), (1, 8), (1, 9), (1, 10), (1, 11))
OLD = ((1, 0), (1, 2), (1, 3))
NEWEST = (1, 11)
RESOURCE_ENV = ("GZ_SIM_RESOURCE_PATH", "IGN_GAZEBO_RESOURCE_PATH", "GAZEBO_MODEL_PATH",
                "SDF_PATH")
MAX_INCLUDE_DEPTH = 20
# include files read for one input (issue 21: includes that double at each level are 2^20
# reads within the depth limit); a world of a few hundred models is far below it
MAX_INCLUDES = 1000
_VERSION_RE = re.compile(r"^\s*(\d+)\.(\d+)\s*$")


@dataclass
class Doc:
    """One SDF file read (the input or an included model)."""

    path: str  # as shown in diagnostics
    directory: Path
    text: str
    root: etree._Element
    version: tuple[int, int]


@dataclass
class Entity:
    """A link, joint or frame of a model, with its raw pose as written."""

    kind: str  # "link", "joint", "frame"
    name: str
    scope: Scope
    element: etree._Element
    pose: Transform = IDENTITY
    pose_element: etree._Element | None = None
    relative_to: str | None = None  # as written (None: the default for this kind)
    attached_to: str | None = None  # frames
    written: str = ""  # the name as written, when libsdformat renamed it (SDFormat < 1.7)

    @property
    def key(self) -> str:
        return self.scope.prefix + self.name


@dataclass
class Scope:
    """A model: the top one, a nested ``<model>`` or an included one."""

    name: str
    element: etree._Element
    doc: Doc
    parent: Scope | None = None
    merged: bool = False  # <include merge="true">: entities join the parent's namespace
    pose: Transform = IDENTITY
    pose_element: etree._Element | None = None
    relative_to: str | None = None
    placement_frame: str | None = None
    placement_element: etree._Element | None = None
    canonical_link: str | None = None
    static: bool = False
    include_element: etree._Element | None = None  # the <include> that brought it in
    links: list[Entity] = field(default_factory=list)
    joints: list[Entity] = field(default_factory=list)
    frames: list[Entity] = field(default_factory=list)
    models: list[Scope] = field(default_factory=list)
    plugins: list[etree._Element] = field(default_factory=list)

    @property
    def version(self) -> tuple[int, int]:
        return self.doc.version

    @property
    def prefix(self) -> str:
        """Scope prefix of this model's entities ('' for the top model)."""
        if self.parent is None:
            return ""
        if self.merged:
            return self.parent.prefix
        return self.parent.prefix + self.name + "::"

    @property
    def frame_key(self) -> str:
        """The key of this model's own frame in the pose graph."""
        if self.parent is None:
            return "__model__"
        return self.parent.prefix + self.name

    def walk(self):
        yield self
        for model in self.models:
            yield from model.walk()


class Reader:
    """Reads the input file and its includes, reporting into ``source``."""

    def __init__(self, source, model_paths: list[str] | None = None):
        self.source = source
        self.model_paths = [Path(p) for p in (model_paths or [])]
        for variable in RESOURCE_ENV:
            for entry in os.environ.get(variable, "").split(os.pathsep):
                if entry:
                    self.model_paths.append(Path(entry))
        self._element_doc: dict[int, Doc] = {}  # id(root) -> doc
        self._locs: dict = {}  # SDF element -> its Loc, shared by the URDF elements made from it
        self._include_stack: list[Path] = []
        self._includes = 0  # include files read (MAX_INCLUDES)
        self._too_deep = False  # an include past MAX_INCLUDE_DEPTH was reported
        # issue 22.3, one finding per cause: the models whose include could not be read (their
        # keys: what joints, frames and plugins name them by) and each unresolved URI's one
        # finding (problem index, how many more includes of it)
        self.lost: list[str] = []
        self._unresolved: dict[str, list] = {}

    # -- reporting -------------------------------------------------------------------------

    def doc_of(self, element) -> Doc | None:
        root = element.getroottree().getroot()
        return self._element_doc.get(id(root))

    def loc(self, element) -> Loc:
        known = self._locs.get(element)
        if known is None:
            known = self._locs[element] = self._loc(element)
        return known

    def _loc(self, element) -> Loc:
        doc = self.doc_of(element)
        if doc is None:
            return Loc(self.source.path)
        line = element.sourceline
        column = None
        if line and isinstance(element.tag, str):
            from urdftool.edits import line_starts

            line, column = tag_position(doc.text, line_starts(doc.text), line, element.tag)
        # Source.xpath is getpath in linear time (lxml's counts every ancestor's preceding
        # siblings: quadratic on a model of thousands of links, issue 15)
        return Loc(doc.path, line, column, self.source.xpath(element))

    def report(self, rule: str, message: str, element, hint: str | None = None,
               severity: str | None = None) -> None:
        loc = self.loc(element) if element is not None else Loc(self.source.path, 1, 1)
        self.source.add(rule, Finding(message, loc, hint, severity))

    # -- files ------------------------------------------------------------------------------

    def read_root(self, path: Path, text: str) -> Doc | None:
        from urdftool.source import parse_text

        root = parse_text(text, str(self.source.path), self.source)
        if root is None:
            return None
        return self._make_doc(str(self.source.path), path.resolve().parent, text, root)

    def _make_doc(self, shown: str, directory: Path, text: str, root) -> Doc | None:
        doc = Doc(shown, directory, text, root, NEWEST)
        self._element_doc[id(root)] = doc
        if not isinstance(root.tag, str) or etree.QName(root).localname != "sdf":
            self.report("sdf.no-model", f"the root element is <{root.tag}>, not <sdf>", root,
                        hint='an SDFormat file starts with <sdf version="1.11">')
            return doc
        doc.version = self._version(root)
        return doc

    def _version(self, root) -> tuple[int, int]:
        raw = root.get("version")
        if raw is None:
            self.report("sdf.version", "<sdf> has no version attribute: libsdformat cannot "
                        "read the file (Gazebo does not load it); urdftool reads it with 1.11 rules",
                        root, hint='write <sdf version="1.11"> (or the version the file was '
                                   "written for)")
            return NEWEST
        match = _VERSION_RE.match(raw)
        if not match:
            self.report("sdf.version", f"<sdf version=\"{raw}\"> is not an SDFormat version: "
                        "libsdformat cannot convert it (Gazebo does not load the file); urdftool "
                        "reads it with 1.11 rules", root,
                        hint="SDFormat versions are 1.0 to 1.12 (1.4 or newer for new files)")
            return NEWEST
        version = (int(match.group(1)), int(match.group(2)))
        if version in SUPPORTED:
            return version
        if version in OLD:
            self.report("sdf.version", f"SDFormat {raw} predates 1.4: libsdformat converts it "
                        "on loading (Gazebo loads it); urdftool reads it with 1.4 rules, which "
                        "may differ", root,
                        hint='convert the file (gz sdf -p) and write version="1.4" or newer',
                        severity="warning")
            return (1, 4)
        if version[0] == 1 and version > NEWEST:
            self.report("sdf.version", f"SDFormat {raw} is newer than urdftool knows (1.11): "
                        "read with 1.11 rules (a libsdformat older than the file refuses it)",
                        root, severity="warning")
            return NEWEST
        self.report("sdf.version", f"unknown SDFormat version \"{raw}\": libsdformat cannot "
                    "convert it (Gazebo does not load the file); urdftool reads it with 1.11 "
                    "rules", root, hint="SDFormat versions are 1.0 to 1.12 (1.4 or newer for new "
                                        "files)")
        return NEWEST

    # -- schema -----------------------------------------------------------------------------

    def check_schema(self, element, kind: str = "sdf") -> None:
        spec = SPEC.get(kind)
        if spec is None:
            return
        for name in element.attrib:
            if ":" in name or name.startswith("{"):
                continue
            if name not in spec.attributes:
                guess = difflib.get_close_matches(name, sorted(spec.attributes), n=1)
                self.report("sdf.unknown-attribute",
                            f"<{element.tag}> has no attribute '{name}' in SDFormat", element,
                            hint=f"did you mean '{guess[0]}'?" if guess else
                            f"<{element.tag}> takes: {', '.join(sorted(spec.attributes)) or 'none'}")
        for child in element:
            if not isinstance(child.tag, str):
                continue
            tag = child.tag
            if tag.startswith("{") or ":" in tag:
                continue  # custom element with a namespace: allowed anywhere
            if tag in spec.children:
                sub = spec.children[tag]
                if sub is not None:
                    self.check_schema(child, sub)
            elif not spec.open:
                guess = difflib.get_close_matches(tag, sorted(spec.children), n=1)
                hint = f"did you mean <{guess[0]}>?" if guess else (
                    f"<{element.tag}> takes: " + ", ".join(f"<{c}>" for c in sorted(spec.children)))
                self.report("sdf.unknown-element",
                            f"<{tag}> is not an SDFormat element inside <{element.tag}>; "
                            "SDF readers ignore it", child, hint=hint)

    # -- values -----------------------------------------------------------------------------

    def text_of(self, element, tag: str) -> str | None:
        child = element.find(tag)
        if child is None or child.text is None:
            return None if child is None else ""
        return child.text.strip()

    def number(self, element, tag: str, default: float | None) -> float | None:
        child = element.find(tag)
        if child is None:
            return default
        raw = (child.text or "").strip()
        try:
            value = float(raw)
        except ValueError:
            self.report("sdf.bad-value", f"<{tag}> value '{raw}' is not a number", child,
                        hint="write a decimal number")
            return default
        if math.isnan(value):
            self.report("sdf.bad-value", f"<{tag}> is NaN", child)
            return default
        return value

    def vector(self, element, tag: str, size: int, default):
        child = element.find(tag)
        if child is None:
            return default
        return self.parse_vector(child, size, default)

    def parse_vector(self, child, size: int, default, sizes: tuple[int, ...] = ()):
        raw = (child.text or "").split()
        try:
            values = tuple(float(v) for v in raw)
        except ValueError:
            values = ()
        if len(values) not in ((size,) + sizes) or not all(math.isfinite(v) for v in values):
            self.report("sdf.bad-value",
                        f"<{child.tag}> '{' '.join(raw)}' is not {size} numbers", child,
                        hint=f"write {size} finite numbers separated by spaces")
            return default
        return values

    def boolean(self, element, tag: str, default: bool) -> bool:
        child = element.find(tag)
        if child is None:
            return default
        raw = (child.text or "").strip().lower()
        if raw in ("true", "1"):
            return True
        if raw in ("false", "0"):
            return False
        self.report("sdf.bad-value", f"<{tag}> value '{raw}' is not a boolean", child,
                    hint="write true or false")
        return default

    def pose(self, element, version) -> tuple[Transform, etree._Element | None, str | None]:
        """The ``<pose>`` child of ``element``: transform, element and relative_to."""
        pose = element.find("pose")
        if pose is None:
            return IDENTITY, None, None
        return self.parse_pose(pose, version)

    def parse_pose(self, pose, version) -> tuple[Transform, etree._Element, str | None]:
        relative_to = pose.get("relative_to")
        frame_attr = pose.get("frame")
        if relative_to is not None and version < (1, 7):
            self.report("sdf.version-feature",
                        f"pose/@relative_to needs SDFormat 1.7; a {_v(version)} reader ignores it, "
                        "and so does urdftool", pose,
                        hint='write <sdf version="1.7"> or newer to use relative_to')
            relative_to = None
        if frame_attr is not None:
            if version >= (1, 7):
                self.report("sdf.version-feature",
                            "pose/@frame was replaced by @relative_to in SDFormat 1.7; ignored",
                            pose, hint="write relative_to=\"...\"")
            elif frame_attr.strip() and (1, 5) <= version:
                relative_to = frame_attr  # 1.5/1.6: converted to relative_to by SDF readers
        if relative_to is not None and not relative_to.strip():
            relative_to = None
        rotation_format = pose.get("rotation_format", "euler_rpy")
        degrees = (pose.get("degrees") or "false").strip().lower() in ("true", "1")
        if (pose.get("rotation_format") is not None or pose.get("degrees") is not None) \
                and version < (1, 9):
            self.report("sdf.version-feature",
                        f"pose/@rotation_format and @degrees need SDFormat 1.9; a {_v(version)} "
                        "reader ignores them", pose, hint='write <sdf version="1.9"> or newer')
            rotation_format, degrees = "euler_rpy", False
        if rotation_format == "quat_xyzw":
            values = self.parse_vector(pose, 7, None)
            if values is None:
                return IDENTITY, pose, relative_to
            return Transform.from_quat(values[:3], values[3:]), pose, relative_to
        if rotation_format != "euler_rpy":
            self.report("sdf.bad-value", f"rotation_format '{rotation_format}' is not "
                        "euler_rpy or quat_xyzw", pose)
        raw = (pose.text or "").split()
        if not raw:
            return IDENTITY, pose, relative_to  # <pose/> or <pose relative_to="x"/>
        values = self.parse_vector(pose, 6, None)
        if values is None:
            return IDENTITY, pose, relative_to
        rpy = values[3:]
        if degrees:
            rpy = tuple(math.radians(v) for v in rpy)
        return Transform.from_rpy(values[:3], rpy), pose, relative_to

    # -- models -----------------------------------------------------------------------------

    def models_in(self, doc: Doc) -> list[tuple[etree._Element, str]]:
        """Candidate models of a document: (element or <include>, name), in document order."""
        found = []
        root = doc.root
        containers = [root] + [w for w in root if w.tag == "world"]
        for container in containers:
            for child in container:
                if child.tag == "model":
                    found.append((child, child.get("name") or ""))
                elif child.tag == "include" and container is not root:
                    name = self.text_of(child, "name") or _uri_model_name(self.text_of(child, "uri"))
                    found.append((child, name or ""))
        return found

    def read_model(self, element, doc: Doc, parent: Scope | None = None,
                   include=None, merged: bool = False, name: str | None = None) -> Scope:
        version = doc.version
        scope = Scope(name if name is not None else (element.get("name") or ""), element, doc,
                      parent, merged)
        scope.include_element = include
        if not scope.name:
            self.report("sdf.missing-element", "<model> has no name", element,
                        hint='write <model name="...">')
        scope.pose, scope.pose_element, scope.relative_to = self.pose(element, version)
        scope.canonical_link = element.get("canonical_link") or None
        scope.placement_frame = element.get("placement_frame") or None
        if scope.placement_frame:
            scope.placement_element = element
        scope.static = self.boolean(element, "static", False)
        if include is not None:  # the include's settings override the model's
            if include.find("pose") is not None:
                scope.pose, scope.pose_element, scope.relative_to = self.pose(
                    include, self.doc_of(include).version)
            if include.find("placement_frame") is not None:
                scope.placement_frame = self.text_of(include, "placement_frame") or None
                scope.placement_element = include.find("placement_frame")
            if include.find("static") is not None:
                scope.static = self.boolean(include, "static", False)
        taken: dict[str, str] = {}  # name -> kind, in document order (libsdformat's order)
        for child in element:
            if not isinstance(child.tag, str):
                continue
            tag = child.tag
            if tag in ("link", "joint", "frame"):
                entity = Entity(tag, child.get("name") or "", scope, child)
                if not entity.name:
                    self.report("sdf.missing-element", f"<{tag}> has no name", child,
                                hint=f'write <{tag} name="...">')
                    continue
                if taken.get(entity.name, tag) != tag and version < (1, 7):
                    self._rename(entity, taken)
                taken.setdefault(entity.name, tag)
                entity.pose, entity.pose_element, entity.relative_to = self.pose(child, version)
                if tag == "frame":
                    entity.attached_to = child.get("attached_to") or None
                getattr(scope, tag + "s").append(entity)
            elif tag == "model":
                scope.models.append(self.read_model(child, doc, scope))
                taken.setdefault(scope.models[-1].name, tag)
            elif tag == "include":
                included = self.read_include(child, scope)
                if included is not None:
                    scope.models.append(included)
                    if not included.merged:
                        taken.setdefault(included.name, "model")
            elif tag == "plugin":
                scope.plugins.append(child)
        return scope

    def _rename(self, entity: Entity, taken: dict[str, str]) -> None:
        """SDFormat < 1.7 allowed a link, joint and frame of one model to share a name;
        libsdformat (so Gazebo) loads such a file and renames the later element NAME_joint
        (NAME_link, NAME_frame; then NAME_joint0, NAME_joint1...). So does urdftool."""
        written, kind = entity.name, entity.kind
        name, index = f"{written}_{kind}", 0
        while name in taken:
            name, index = f"{written}_{kind}{index}", index + 1
        entity.written, entity.name = written, name
        other = taken[written]
        self.report("sdf.duplicate-name",
                    f"{kind} '{written}' has the name of a {other} of model "
                    f"'{entity.scope.name}': SDFormat {_v(entity.scope.version)} allows it, and "
                    f"libsdformat (so Gazebo) loads the file with a warning, renaming this "
                    f"{kind} '{name}'; the URDF does the same (from SDFormat 1.7 on, libsdformat "
                    "refuses the file)", entity.element, severity="warning",
                    hint=f'rename it <{kind} name="{name}"> (names must be unique before the '
                         "file can say version 1.7 or newer)")

    # -- includes ---------------------------------------------------------------------------

    def is_lost(self, key: str) -> str | None:
        """The model whose include could not be read that ``key`` (a pose-graph key: model
        frame, link, joint or frame) would be in, if any."""
        for model in self.lost:
            if key == model or key.startswith(model + "::"):
                return model
        return None

    def finish(self) -> None:
        """Say on each unresolved URI's one finding how many more includes of it there are;
        hand the names left out to the rules (``Source.lost``)."""
        self.source.lost = tuple(dict.fromkeys(self.lost))
        for index, more in self._unresolved.values():
            if more:
                rule, finding = self.source.problems[index]
                self.source.problems[index] = (rule, finding._replace(
                    message=f"{finding.message}; {len(more)} more include(s) of it (model(s) "
                            f"{', '.join(repr(k) for k in more)}) are left out the same way"))

    def read_include(self, include, parent: Scope | None) -> Scope | None:
        uri = self.text_of(include, "uri")
        name = self.text_of(include, "name") or _uri_model_name(uri) or ""
        key = (parent.prefix if parent is not None else "") + name
        problems = len(self.source.problems)
        included = self._read_include(include, parent, uri, key)
        if included is None and name and parent is not None:
            self.lost.append(key)
            rule, finding = (self.source.problems[problems]
                             if len(self.source.problems) > problems else (None, None))
            if rule == "sdf.include":  # say what is not checked because of it
                self.source.problems[problems] = (rule, finding._replace(message=(
                    f"{finding.message}: model '{key}' is left out, and what names it (joints, "
                    "frames, plugins) is not checked until it is read")))
        return included

    def _read_include(self, include, parent: Scope | None, uri: str | None,
                      key: str) -> Scope | None:
        doc = self.doc_of(include)
        if not uri:
            self.report("sdf.include", "<include> has no <uri>", include,
                        hint="write <uri>model://NAME</uri> or a path")
            return None
        target = self.resolve_uri(uri, doc.directory if doc else Path.cwd())
        if target is None:
            where = ", ".join(str(p) for p in self.model_paths) or "none given"
            hint = ("give the models' folder with --model-path DIR or GZ_SIM_RESOURCE_PATH"
                    if uri.startswith("model://") or "/" not in uri.strip("/")
                    else "check the path, or give its folder with --model-path DIR")
            if uri.startswith(("http://", "https://")):
                hint = "urdftool does not download models; download it and use --model-path"
            if uri in self._unresolved:  # one cause: one finding, counting the others
                self._unresolved[uri][1].append(key)
                return None
            self._unresolved[uri] = [len(self.source.problems), []]
            self.report("sdf.include", f"cannot resolve include '{uri}' (model paths: {where})",
                        include, hint=hint)
            return None
        if not self._allowed(target):  # the URI as written, never where it resolves
            self.report("sdf.include", f"include '{uri}' is outside the repository; urdftool "
                        "reads only inside it and the operator's directories", include,
                        hint="give the models' folder with --model-path DIR")
            return None
        file = self._model_file(target)
        if file is None:
            self.report("sdf.include", f"include '{uri}': no SDF file in {target}", include,
                        hint="a model folder holds model.config and model.sdf")
            return None
        if not self._allowed(file):  # model.config may name a file anywhere
            self.report("sdf.include", f"include '{uri}': its model.config names a file "
                        "outside the repository; urdftool does not read it", include)
            return None
        if file.resolve() in self._include_stack:
            self.report("sdf.include", f"include '{uri}' includes itself (through {file})", include)
            return None
        if len(self._include_stack) >= MAX_INCLUDE_DEPTH:
            if not self._too_deep:  # one finding: the others as deep are left out too
                self._too_deep = True
                self.report("sdf.include", f"include '{uri}' not read: includes nested more "
                            f"than {MAX_INCLUDE_DEPTH} deep (urdftool's limit); this one and the "
                            "others as deep are left out", include)
            return None
        from urdftool.source import parse_text, read_text, shown_path

        self._includes += 1
        if self._includes > MAX_INCLUDES:
            if self._includes == MAX_INCLUDES + 1:  # one finding: the later ones are left out
                self.report("sdf.include", f"include '{uri}' not read: the file's includes "
                            f"passed urdftool's limit of {MAX_INCLUDES} files (includes that "
                            "include each other several times?); this one and the later ones "
                            "are left out", include)
            return None
        try:
            text = read_text(file)
        except ToolError as exc:  # unreadable
            self.report("sdf.include", f"include '{uri}': {exc}", include)
            return None
        shown = shown_path(file, self.source.path)
        self.source.texts[shown] = text
        root = parse_text(text, shown, self.source)
        if root is None:
            return None
        included_doc = self._make_doc(shown, file.resolve().parent, text, root)
        if included_doc is None:
            return None
        models = [m for m, _ in self.models_in(included_doc) if m.tag == "model"]
        if not models:
            self.report("sdf.no-model", f"included file {shown} has no <model>", include)
            return None
        self.check_schema(root)
        name = self.text_of(include, "name") or models[0].get("name") or ""
        merge = (include.get("merge") or "false").strip().lower() in ("true", "1")
        if merge and (doc.version if doc else NEWEST) < (1, 9):
            self.report("sdf.version-feature", "include/@merge needs SDFormat 1.9; ignored",
                        include)
            merge = False
        self._include_stack.append(file.resolve())
        try:
            return self.read_model(models[0], included_doc, parent, include, merge, name)
        finally:
            self._include_stack.pop()

    def _allowed(self, path: Path) -> bool:
        """Includes are read only inside the run's roots (the repository, the model paths
        the operator gave: --model-path, GZ_SIM_RESOURCE_PATH...), never where the input
        points (an absolute path, ``../..``, a symlink)."""
        resolver = self.source.resolver
        return resolver is None or resolver.allows(path)

    def search_dirs(self, base: Path) -> list[Path]:
        return [*self.model_paths, base, base.parent]

    def resolve_uri(self, uri: str, base: Path) -> Path | None:
        """A model:// URI, file:// URI or path, to a file or directory on disk."""
        parsed = parse_uri(uri)
        if parsed.scheme == "model":
            rest = uri[len("model://"):]
            for directory in self.search_dirs(base):
                candidate = directory / rest
                # outside the roots (model://../../X): not looked at, so the answer is the
                # same whether X exists or not
                if self._allowed(candidate) and candidate.exists():
                    return candidate
            return None
        if parsed.scheme in ("http", "https"):
            return None
        if parsed.scheme == "file":
            uri, parsed = parsed.rest, parse_uri(parsed.rest)
        if parsed.scheme == "package":
            package, inner = parsed.name, parsed.rest
            resolver = self.source.resolver
            found = resolver.find(package) if resolver is not None else None
            if found is not None and not self._allowed(found / inner):
                return found / inner  # refused by the caller, unlooked at
            return (found / inner) if found is not None and (found / inner).exists() else None
        if os.path.isabs(uri):  # outside the roots: refused by the caller, never looked at
            return Path(uri) if not self._allowed(Path(uri)) or Path(uri).exists() else None
        # a relative path or a bare model name: beside the file, then on the model paths
        # (libsdformat's findFile: the local path, SDF_PATH, then the simulator's resource paths)
        for directory in (base, *self.model_paths):
            candidate = directory / uri
            if not self._allowed(candidate):
                if directory is base:
                    return candidate  # refused by the caller, never looked at
                continue
            if candidate.exists():
                return candidate
        return None

    def _model_file(self, target: Path) -> Path | None:
        if target.is_file():
            return target
        config = target / "model.config"
        if config.is_file():
            from urdftool.xmlrepair import secure_parser

            try:
                tree = etree.parse(str(config), secure_parser())
                best = None
                for sdf in tree.getroot().iter("sdf"):
                    match = _VERSION_RE.match(sdf.get("version") or "")
                    version = (int(match.group(1)), int(match.group(2))) if match else (0, 0)
                    if version <= NEWEST and (best is None or version > best[0]) and sdf.text:
                        best = (version, sdf.text.strip())
                if best and (target / best[1]).is_file():
                    return target / best[1]
            except (etree.XMLSyntaxError, OSError):
                pass
        for name in ("model.sdf",):
            if (target / name).is_file():
                return target / name
        files = sorted(target.glob("*.sdf"))
        return files[0] if files else None


def _uri_model_name(uri: str | None) -> str | None:
    if not uri:
        return None
    return uri.rstrip("/").split("/")[-1] or None


def _v(version: tuple[int, int]) -> str:
    return f"{version[0]}.{version[1]}"
