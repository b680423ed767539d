"""From a robot file to something PyBullet can load, plus the facts the checks need.

A plain URDF whose meshes PyBullet can find by itself is loaded directly. Otherwise (xacro,
SDF, ``package://`` or ``file://`` mesh URIs, ``--free`` on a model anchored to ``world``) a
temporary copy is written with every mesh as an absolute path, and a line map from the copy back
to the user's file lets PyBullet's messages point at the line the user wrote.

What PyBullet cannot load at all is caught here with a clear reason before PyBullet sees it:
XML that is not well-formed (PyBullet's tinyxml2 rejects the file), xacro errors, and several
root links (PyBullet 3.2 crashes on those).
"""

from __future__ import annotations

import copy
import math
import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from urdftool.errors import ToolError
from urdftool.loader import load
from urdftool.model import Loc, Robot, build_robot
from urdftool.rules.inertia import is_kinematics_only
from urdftool.sdf.transforms import Transform
from urdftool.source import LoadOptions
from urdftool.uris import parse_uri

REVOLUTE = ("revolute", "continuous")
CONTROLLED = ("revolute", "continuous", "prismatic")
MAX_LINKS = 128  # PyBullet's b3 multibody limit (base included), found by experiment


@dataclass
class JointFacts:
    name: str
    type: str
    parent: str | None
    child: str | None
    lower: float | None  # None: no (usable) limit
    upper: float | None
    effort: float | None  # None: not given (no limit on the motor)
    home: float = 0.0
    mimic: tuple[str, float, float] | None = None  # leader, multiplier, offset
    limit_loc: Loc | None = None

    @property
    def linear(self) -> bool:
        return self.type == "prismatic"

    @property
    def empty_range(self) -> bool:
        return self.lower is not None and self.upper is not None and self.lower > self.upper


@dataclass
class Prepared:
    path: str
    kind: str = "urdf"
    robot: str | None = None
    problem: str | None = None  # why the model cannot be loaded at all
    urdf_file: str | None = None  # the file PyBullet loads
    urdf_text: str = ""  # the same document (for pinocchio)
    temp_file: str | None = None  # set when urdf_file is our temporary copy
    line_map: dict[int, Loc] = field(default_factory=dict)  # temp line -> user's file and line
    anchored: bool = False
    anchor_reason: str | None = None
    root_link: str | None = None
    kinematics_only: bool = False  # no <inertial> anywhere: nothing to simulate
    masses: dict[str, float | None] = field(default_factory=dict)  # link -> mass, None: none
    joints: dict[str, JointFacts] = field(default_factory=dict)
    group: dict[str, int] = field(default_factory=dict)  # link -> rigid group
    group_parent: dict[int, int] = field(default_factory=dict)  # group -> parent group
    body_joint: dict[int, str] = field(default_factory=dict)  # group -> the joint moving it
    srdf: str | None = None  # the SRDF whose <disable_collisions> pairs are allowed
    srdf_pairs: set[frozenset] = field(default_factory=set)
    unresolved: list[str] = field(default_factory=list)  # mesh URIs that do not resolve
    notes: list[str] = field(default_factory=list)
    xml_problem: str | None = None  # the first XML problem of a URDF (PyBullet may cope)
    mesh_paths: dict[str, str] = field(default_factory=dict)  # mesh URI as written -> file
    not_read: dict[str, str] = field(default_factory=dict)  # ``_not_read`` name -> as written
    _tempdir: tempfile.TemporaryDirectory | None = field(default=None, repr=False)

    def scratch_dir(self) -> str:
        """A temporary folder of this model's own (removed by ``cleanup``)."""
        if self._tempdir is None:
            self._tempdir = tempfile.TemporaryDirectory(prefix="urdftool-sim-")
        return self._tempdir.name

    def cleanup(self) -> None:
        if self._tempdir is not None:
            self._tempdir.cleanup()
            self._tempdir = None

    def loop_cut(self, a: str, b: str) -> bool:
        """Whether two links sit where a closed chain was cut open: the moving joints that
        carry their bodies are one mimic group (a four-bar gripper's knuckle and finger, pinned
        together in the real mechanism), so they overlap by design."""
        ja, jb = (self.body_joint.get(self.group.get(name, -1)) for name in (a, b))
        if ja is None or jb is None or ja == jb:
            return False
        if self.joints.get(ja) is None or self.joints.get(jb) is None or (
                self.joints[ja].mimic is None and self.joints[jb].mimic is None):
            return False
        return self._mimic_leader(ja) == self._mimic_leader(jb)

    def _mimic_leader(self, joint: str) -> str:
        """The joint at the head of ``joint``'s chain of mimics (itself when it mimics none)."""
        seen = {joint}
        fact = self.joints.get(joint)
        while fact is not None and fact.mimic is not None and fact.mimic[0] not in seen:
            joint = fact.mimic[0]
            seen.add(joint)
            fact = self.joints.get(joint)
        return joint

    def relation(self, a: str, b: str) -> str:
        """How two links are related, counting links joined by fixed joints as one body:
        'adjacent' (the same body, or one moving joint apart), 'ancestor' (one is further up
        the other's chain to the root) or 'apart' (different branches)."""
        ga, gb = self.group.get(a), self.group.get(b)
        if ga is None or gb is None:
            return "apart"
        if ga == gb or self.group_parent.get(ga) == gb or self.group_parent.get(gb) == ga:
            return "adjacent"
        for start, other in ((ga, gb), (gb, ga)):
            node, seen = self.group_parent.get(start), set()
            while node is not None and node not in seen:
                if node == other:
                    return "ancestor"
                seen.add(node)
                node = self.group_parent.get(node)
        return "apart"


def _where(loc: Loc | None) -> str:
    if loc is None:
        return ""
    return f"{loc.path}:{loc.line}: " if loc.line else f"{loc.path}: "


def _home_position(joint: JointFacts) -> float:
    if joint.type == "continuous" or joint.lower is None or joint.upper is None or joint.empty_range:
        return 0.0
    return min(max(0.0, joint.lower), joint.upper)


def _joint_facts(robot: Robot) -> dict[str, JointFacts]:
    facts: dict[str, JointFacts] = {}
    for joint in robot.joints:
        if joint.name is None or joint.name in facts:
            continue
        limit = joint.limit
        lower = upper = None
        if limit is not None and joint.type in ("revolute", "prismatic") \
                and limit.lower is not None and limit.upper is not None \
                and math.isfinite(limit.lower) and math.isfinite(limit.upper):
            lower, upper = limit.lower, limit.upper
        effort = limit.effort if limit is not None and limit.effort is not None \
            and math.isfinite(limit.effort) else None
        mimic = None
        if joint.mimic is not None and joint.mimic.joint:
            mimic = (joint.mimic.joint, joint.mimic.multiplier if joint.mimic.multiplier
                     is not None else 1.0, joint.mimic.offset or 0.0)
        facts[joint.name] = JointFacts(joint.name, joint.type or "", joint.parent, joint.child,
                                       lower, upper, effort, mimic=mimic,
                                       limit_loc=limit.loc if limit is not None else None)
    for fact in facts.values():
        fact.home = _home_position(fact)
    for fact in facts.values():  # a follower's home is the image of its leader's (one level)
        if fact.mimic and fact.mimic[0] in facts and fact.type in CONTROLLED:
            leader = facts[fact.mimic[0]]
            fact.home = fact.mimic[1] * leader.home + fact.mimic[2]
    return facts


def _groups(robot: Robot) -> tuple[dict[str, int], dict[int, int]]:
    names = [link.name for link in robot.links if link.name is not None]
    parent = {name: name for name in names}

    def find(name: str) -> str:
        while parent[name] != name:
            parent[name] = parent[parent[name]]
            name = parent[name]
        return name

    for joint in robot.joints:
        if joint.type == "fixed" and joint.parent in parent and joint.child in parent:
            parent[find(joint.child)] = find(joint.parent)
    ids: dict[str, int] = {}
    group = {name: ids.setdefault(find(name), len(ids)) for name in names}
    group_parent = {group[j.child]: group[j.parent] for j in robot.joints
                    if j.type != "fixed" and j.parent in group and j.child in group
                    and group[j.child] != group[j.parent]}
    return group, group_parent


def srdf_candidates(path: Path, robot: str | None) -> list[Path]:
    """Where a robot's SRDF usually sits: next to the file or in a sibling ``srdf/`` folder,
    named like the file or like the robot."""
    stems = [path.name.split(".")[0]] + ([robot] if robot else [])
    folders = [path.parent, path.parent / "srdf", path.parent.parent / "srdf"]
    return [folder / f"{stem}.srdf" for folder in folders for stem in stems]


def read_srdf(path: Path) -> tuple[str | None, set[frozenset]]:
    """(robot name, pairs of links in <disable_collisions>) of an SRDF file."""
    from urdftool.xmlrepair import secure_parser

    try:
        root = etree.fromstring(path.read_bytes(), secure_parser())
    except (OSError, etree.XMLSyntaxError) as exc:
        raise ToolError(f"{path}: cannot read the SRDF: {exc}") from None
    pairs = {frozenset((e.get("link1"), e.get("link2"))) for e in root.iter("disable_collisions")
             if e.get("link1") and e.get("link2")}
    return root.get("name"), pairs


def _find_srdf(prepared: Prepared, options) -> None:
    explicit = getattr(options, "srdf", None)
    if explicit:
        name, pairs = read_srdf(Path(explicit))
        prepared.srdf, prepared.srdf_pairs = str(explicit), pairs
        return
    if getattr(options, "srdf", None) is False:
        return
    for candidate in srdf_candidates(Path(prepared.path), prepared.robot):
        if candidate.is_file():
            try:
                name, pairs = read_srdf(candidate)
            except ToolError:
                continue
            if name == prepared.robot or candidate.name.split(".")[0] == \
                    Path(prepared.path).name.split(".")[0]:
                prepared.srdf, prepared.srdf_pairs = str(candidate), pairs
                return


def _first_problem(source, families: tuple[str, ...]) -> str | None:
    for rule, finding in source.problems:
        if rule.startswith(families) and rule != "xml.declaration":
            return f"{_where(finding.loc)}{finding.message}"
    return None


def _pybullet_search(relative: str, base_dir: Path, allows) -> Path | None:
    """Where PyBullet itself finds a relative mesh path (``package://`` dropped): next to the
    URDF or up to five folders above it, inside the run's roots (``allows``) only."""
    directory = base_dir
    for _ in range(6):
        candidate = directory / relative
        if allows(candidate) and candidate.exists():
            return candidate
        directory = directory.parent
    return None


NOT_FOUND = "not found"


def _lookup(filename: str, source) -> tuple[Path | None, str]:
    """A mesh file as PyBullet gets it (its realpath: a regular file inside the run's roots,
    what urdftool's readers would read), or None and why not (``NOT_FOUND``, outside the
    roots, not a regular file)."""
    import os
    import stat

    allows = source.resolver.allows if source.resolver is not None else (lambda _: True)
    base_dir = source.base_dir
    resolved = source.resolver.resolve_uri(filename, base_dir) if source.resolver else None
    found = Path(resolved) if resolved is not None and Path(resolved).exists() else None
    parsed = parse_uri(filename)
    if found is None and parsed.scheme == "package":
        found = _pybullet_search(parsed.named, base_dir, allows)
    elif found is None and parsed.scheme == "path" and not Path(filename).is_absolute():
        found = _pybullet_search(filename, base_dir, allows)
    if found is None:
        return None, NOT_FOUND
    if not allows(found):
        return None, "outside the repository and the operator's directories: not read"
    try:
        real = Path(os.path.realpath(found))
        regular = stat.S_ISREG(os.stat(real).st_mode)
    except (OSError, ValueError):
        return None, NOT_FOUND
    if not regular:
        return None, "not a regular file (a device, FIFO or socket): not read"
    return real, ""


def _resolve(filename: str, source) -> Path | None:
    """``_lookup``'s file, or None."""
    return _lookup(filename, source)[0]


def _note_unresolved(prepared: Prepared, filename: str, source) -> None:
    why = _lookup(filename, source)[1]
    shown = filename if why == NOT_FOUND else f"{filename} ({why})"
    if shown not in prepared.unresolved:
        prepared.unresolved.append(shown)


def _not_read(prepared: Prepared, filename: str) -> str:
    """Where a mesh that is not given to PyBullet points in the copy it loads: a name in the
    model's own scratch folder where nothing is (PyBullet answers as for a missing file, and
    opens nothing of the machine), with the written name's suffix (PyBullet picks its reader
    by it)."""
    suffix = Path(filename.split("?", 1)[0]).suffix[:16]
    name = str(Path(prepared.scratch_dir()) / "not-read" / f"{len(prepared.not_read)}{suffix}")
    prepared.not_read[name] = filename
    return name


def _rewrite_tree_uris(root, source, prepared: Prepared) -> None:
    for element in root.iter("mesh", "texture"):
        filename = element.get("filename")
        if not filename:
            continue
        resolved = _resolve(filename, source)
        if resolved is not None:
            element.set("filename", str(resolved))
            continue
        if element.tag == "mesh":
            _note_unresolved(prepared, filename, source)
        element.set("filename", _not_read(prepared, filename))


# every filename attribute, in any tag (a URDF has them on <mesh> and <texture>, and whatever
# tinyxml2 reads as one is written so: a quoted value after `filename=`); linear: a value never
# runs past its closing quote
_FILENAME_RE = re.compile(r"""(\bfilename\s*=\s*)(?:"([^"]*)"|'([^']*)')""")


def _rewrite_text_uris(text: str, source, prepared: Prepared) -> str:
    """Every file name of the file's own text replaced by the file ``_lookup`` found, or by a
    name where nothing is (``_not_read``): PyBullet opens no name as written (a FIFO, a file
    outside the roots). Every line stays where the user wrote it (and a malformed file stays
    malformed: PyBullet judges what the user wrote)."""

    def replace(match: re.Match) -> str:
        quote = '"' if match.group(2) is not None else "'"
        filename = match.group(2) if match.group(2) is not None else match.group(3)
        if not filename:
            return match.group(0)
        resolved = _resolve(filename, source)
        if resolved is None:
            _note_unresolved(prepared, filename, source)
        value = str(resolved) if resolved is not None else _not_read(prepared, filename)
        value = value.replace("&", "&amp;").replace(quote, "&quot;" if quote == '"'
                                                    else "&apos;")
        return f"{match.group(1)}{quote}{value}{quote}"

    return _FILENAME_RE.sub(replace, text)


def _strip_world(root, prepared: Prepared) -> bool:
    """--free on a model whose root is 'world': drop the world link and its one fixed joint."""
    world_joints = [j for j in root.findall("joint")
                    if (j.find("parent") is not None and j.find("parent").get("link") == "world")]
    if len(world_joints) != 1:
        prepared.notes.append(f"--free: 'world' holds {len(world_joints)} joints; kept anchored")
        return False
    joint = world_joints[0]
    child = joint.find("child").get("link") if joint.find("child") is not None else None
    for link in root.findall("link"):
        if link.get("name") == "world":
            root.remove(link)
    root.remove(joint)
    prepared.notes.append(f"--free: removed link 'world' and joint '{joint.get('name')}'; "
                          f"'{child}' is the free base")
    prepared.root_link = child
    prepared.masses.pop("world", None)
    return True


def _is_frame(link) -> bool:
    """A link without <inertial> and without shapes: a named frame (UR's tool0, flange and
    base_link, Franka's link8, a camera's optical frame). PyBullet would give it 1 kg."""
    return (link.find("inertial") is None and link.find("visual") is None
            and link.find("collision") is None)


def _joint_origin(joint) -> Transform | None:
    """The joint's <origin> as a transform; None when a value does not read (left as written)."""
    origin = joint.find("origin")
    values = []
    for attribute in ("xyz", "rpy"):
        text = origin.get(attribute) if origin is not None else None
        try:
            numbers = tuple(float(v) for v in (text or "0 0 0").split())
        except ValueError:
            return None
        if len(numbers) != 3 or not all(math.isfinite(v) for v in numbers):
            return None
        values.append(numbers)
    return Transform.from_rpy(values[0], values[1])


def _set_origin(joint, transform: Transform) -> None:
    origin = joint.find("origin")
    if origin is None:
        origin = etree.SubElement(joint, "origin")
    origin.set("xyz", " ".join(repr(v) for v in transform.xyz))
    origin.set("rpy", " ".join(repr(v) for v in transform.rpy))


def _lump_massless_frames(root, prepared: Prepared) -> bool:
    """Lump the frame links (``_is_frame``) on fixed joints into their neighbours, as Gazebo,
    Drake and MuJoCo lump fixed links into one body (issue 23.7): a frame adds nothing to that
    body, while PyBullet would give it 1 kg. A frame with a fixed parent joint is removed and its
    child joints hang from its parent (origins composed: nothing moves); an unanchored root frame
    with one fixed child joint is removed and the child is the root. Repeated until none is left
    (a chain of frames); their names are said in a note."""
    merged: list[str] = []
    changed = True
    while changed:
        changed = False
        joints = [j for j in root.findall("joint")
                  if j.find("parent") is not None and j.find("child") is not None]
        by_child = {j.find("child").get("link"): j for j in joints}
        children: dict[str | None, list] = {}
        for joint in joints:
            children.setdefault(joint.find("parent").get("link"), []).append(joint)
        for link in root.findall("link"):
            name = link.get("name")
            if not _is_frame(link):
                continue
            below = children.get(name, [])
            above = by_child.get(name)
            if above is not None and above.get("type") == "fixed" and name != prepared.root_link:
                lift = _joint_origin(above)
                if lift is None or any(_joint_origin(j) is None for j in below):
                    continue
                parent = above.find("parent").get("link")
                for joint in below:
                    joint.find("parent").set("link", parent)
                    _set_origin(joint, lift * _joint_origin(joint))
                root.remove(above)
                prepared.joints.pop(above.get("name"), None)
            elif (above is None and name == prepared.root_link and not prepared.anchored
                  and len(below) == 1 and below[0].get("type") == "fixed"):
                root.remove(below[0])
                prepared.joints.pop(below[0].get("name"), None)
                prepared.root_link = below[0].find("child").get("link")
            else:
                continue
            root.remove(link)
            prepared.masses.pop(name, None)
            merged.append(name)
            changed = True
            break  # the maps above are stale now
    if merged:
        shown = ", ".join(f"'{n}'" for n in merged[:6]) + (
            f" and {len(merged) - 6} more" if len(merged) > 6 else "")
        prepared.notes.append(f"massless frame link(s) on fixed joints lumped into their "
                              f"neighbours, as Gazebo, Drake and MuJoCo lump them: {shown}")
    return bool(merged)


def _temp_path(prepared: Prepared) -> Path:
    name = Path(prepared.path).name.split(".")[0] or "model"
    path = Path(prepared.scratch_dir()) / f"{name}.urdf"
    prepared.temp_file = str(path)
    return path


def _write_text_copy(text: str, source, prepared: Prepared) -> None:
    path = _temp_path(prepared)
    text = _rewrite_text_uris(text, source, prepared)
    path.write_bytes(text.encode("utf-8"))
    prepared.urdf_file, prepared.urdf_text = str(path), text
    prepared.line_map = {line: Loc(prepared.path, line) for line in
                         range(1, text.count("\n") + 2)}


def _write_tree_copy(root, origin: dict, source, prepared: Prepared) -> None:
    """Serialise a copy of the document (``origin``: copied element -> where the user wrote
    it); remember which user line each line of the written file came from."""
    _rewrite_tree_uris(root, source, prepared)
    text = etree.tostring(root, encoding="unicode", pretty_print=True)
    path = _temp_path(prepared)
    path.write_text(text, encoding="utf-8")
    prepared.urdf_file, prepared.urdf_text = str(path), text
    reparsed = etree.fromstring(text.encode("utf-8"))
    for copied, written in zip(root.iter(), reparsed.iter()):
        if isinstance(written.tag, str) and written.sourceline and copied in origin:
            prepared.line_map.setdefault(written.sourceline, origin[copied])


def prepare(path: str, options, from_directory: bool = False) -> Prepared:
    """Read, expand and check loadability of one model. Raises ToolError only when the file
    cannot be read at all (exit 2); everything else is a ``problem`` (the load check fails)."""
    prepared = Prepared(str(path))
    try:
        source = load(path, LoadOptions(dict(options.packages), dict(options.xacro_args),
                                        sdf_model=options.sdf_model,
                                        sdf_model_paths=list(options.sdf_model_paths),
                                        untrusted=options.untrusted,
                                        allow_env=options.allow_env, timeout=options.timeout,
                                        memory_mb=options.memory_mb))
    except ModuleNotFoundError as exc:  # SDF before the converter exists
        raise ToolError(f"{path}: cannot convert this input for PyBullet ({exc})") from None
    prepared.kind = source.kind
    root = source.root
    repaired = getattr(options, "repaired", False)
    if repaired:
        xml_problem = _first_problem(source, ("xml.",))
        if xml_problem:
            prepared.notes.append(f"simulating the XML as urdftool repaired it; first problem: "
                                  f"{xml_problem}")
    if source.kind == "urdf" and not repaired:
        # PyBullet parses the file itself (tinyxml2 is more lenient than we are): say what is
        # wrong with the XML only if PyBullet refuses it
        prepared.xml_problem = _first_problem(source, ("xml.",))
    else:
        problem = _first_problem(source, ("xacro.",) if repaired else ("xacro.", "xml."))
        if problem or root is None:
            prepared.problem = problem or _first_problem(source, ("sdf.",)) or \
                "nothing to convert"
            return prepared
        # what the SDF converter says (a dropped gearbox, a cut loop, the first of several
        # models...) comes with the simulation of what it converted
        sdf = [f"{_where(f.loc)}{f.message}" for rule, f in source.problems
               if rule.startswith("sdf.")]
        prepared.notes.extend(f"SDF: {text}" for text in sdf[:3])
        if len(sdf) > 3:
            prepared.notes.append(f"SDF: {len(sdf) - 3} more ('urdftool check' lists them)")
    if root is None or root.tag != "robot":
        prepared.problem = ("no <robot> element" if root is not None else "no XML element found")
        if prepared.xml_problem:
            prepared.problem = f"not well-formed XML: {prepared.xml_problem}"
        return prepared
    robot = build_robot(source)
    prepared.robot = robot.name
    if not robot.links:
        prepared.problem = "the robot has no links"
        old = sorted({e.tag for e in root if e.tag in ("include", "macro", "property", "arg")})
        if source.kind == "xacro" and old:
            prepared.problem = ("xacro expansion gives no links: current xacro does not expand "
                                "the old unprefixed tags " + ", ".join(f"<{t}>" for t in old) +
                                " (write xacro:" + old[0] + ")")
        return prepared
    roots = robot.roots()
    if len(roots) != 1:
        prepared.problem = (f"{len(roots)} root links ({', '.join(roots[:6])}): a URDF is one tree "
                            "with one root (PyBullet 3.2 crashes on this)" if roots else
                            "no root link: the joints form a loop")
        return prepared
    prepared.root_link = roots[0]
    prepared.kinematics_only = is_kinematics_only(robot)
    prepared.joints = _joint_facts(robot)
    if len(robot.links) > MAX_LINKS:
        prepared.problem = (f"{len(robot.links)} links: PyBullet 3.2 builds a body of at most "
                            f"{MAX_LINKS} links (it returns a broken body for more)")
        return prepared
    prepared.group, prepared.group_parent = _groups(robot)
    prepared.body_joint = {prepared.group[j.child]: j.name for j in robot.joints
                           if j.type != "fixed" and j.name and j.child in prepared.group}
    _find_srdf(prepared, options)
    for link in robot.links:
        if link.name is not None and link.name not in prepared.masses:
            prepared.masses[link.name] = (link.inertial.mass if link.inertial is not None
                                          and link.inertial.mass is not None else None)
    for joint in prepared.joints.values():
        if joint.type == "floating":
            prepared.notes.append(f"joint '{joint.name}' is floating: PyBullet makes it fixed")

    tree = copy.deepcopy(root)
    origin = {c: source.loc(o) for o, c in zip(root.iter(), tree.iter()) if isinstance(o.tag, str)}
    modified = False
    if options.fixed_base is True:
        prepared.anchored, prepared.anchor_reason = True, "--fixed-base"
    elif prepared.root_link == "world":
        if options.fixed_base is False and _strip_world(tree, prepared):
            modified = True
        else:
            prepared.anchored, prepared.anchor_reason = True, "root link 'world'"
    if _lump_massless_frames(tree, prepared):
        modified = True
    root_mass = prepared.masses.get(prepared.root_link)
    if not prepared.anchored and root_mass is not None and root_mass == 0:
        prepared.anchored = True
        prepared.anchor_reason = (f"root link '{prepared.root_link}' has zero mass: "
                                  "PyBullet keeps it static")
    problem = _visual_meshes(robot, source, prepared)
    if problem:
        prepared.problem = problem
        return prepared
    # PyBullet always loads a copy whose every mesh is the file urdftool found (or none): never
    # the user's file, whose names PyBullet would open as written (issue 28.6)
    if modified or source.kind != "urdf" or repaired:
        _write_tree_copy(tree, origin, source, prepared)
    else:
        _write_text_copy(source.texts[source.path], source, prepared)
    return prepared


PYBULLET_MESH_SUFFIXES = (".obj", ".stl", ".dae")
SIM_MESH_BYTES = 1 << 20  # a larger mesh is read by urdftool (bounded) before PyBullet sees it
SIM_MAX_TRIANGLES = 200_000  # PyBullet takes seconds and gigabytes past this (1.2M: 20 s, 2 GB)


def _heavy_mesh(path) -> str | None:
    """Why PyBullet is not given this mesh file: one urdftool's bounded reader refuses (too
    large, an archive bomb, past --timeout or the memory limit) or of more triangles than
    PyBullet loads in a few seconds. PyBullet's own parser is bounded by nothing."""
    from urdftool.physics import meshes

    try:
        if Path(path).stat().st_size <= SIM_MESH_BYTES:
            return None
    except OSError:
        return None
    info = meshes.load_mesh(path)
    if info.error:
        return f"cannot be read: {info.error}"
    if info.faces > SIM_MAX_TRIANGLES:
        return (f"{info.faces} triangles, more than the {SIM_MAX_TRIANGLES} urdftool lets "
                "PyBullet load (simplify the mesh: a collision mesh needs far fewer)")
    return None


def _visual_meshes(robot: Robot, source, prepared: Prepared) -> str | None:
    """PyBullet refuses a model whose visual mesh it cannot find or read. The simulation loads
    without visual shapes (ten times faster), so that refusal is checked here, the same way
    with and without --render."""
    for link in robot.links:
        for shape in link.shapes:
            filename = shape.geometry.filename if shape.geometry.kind == "mesh" else None
            resolved = _resolve(filename, source) if filename else None
            if resolved is not None:
                prepared.mesh_paths[filename] = str(resolved)
                refused = _heavy_mesh(resolved)
                if refused:
                    return (f"{_where(shape.geometry.loc)}mesh '{filename}' of link "
                            f"'{link.name}': {refused} (not given to PyBullet)")
    for link in robot.links:
        for shape in link.visuals:
            filename = shape.geometry.filename if shape.geometry.kind == "mesh" else None
            if not filename:
                continue
            where = _where(shape.geometry.loc)
            resolved, why = _lookup(filename, source)
            if resolved is None and why != NOT_FOUND:
                return (f"{where}visual mesh '{filename}' of link '{link.name}': {why} (not "
                        "given to PyBullet, which refuses a model without it)")
            if resolved is None:
                return (f"{where}visual mesh '{filename}' of link '{link.name}' not found "
                        "(PyBullet refuses the model; give packages with -P NAME=DIR)")
            suffix = Path(filename).suffix.lower()
            if suffix not in PYBULLET_MESH_SUFFIXES:
                return (f"{where}visual mesh '{filename}' of link '{link.name}': PyBullet reads "
                        f"only {', '.join(PYBULLET_MESH_SUFFIXES)} meshes, not '{suffix}' "
                        "(it refuses the model)")
    return None


def describe_location(prepared: Prepared, message: str) -> str:
    """PyBullet's messages name our temporary copy; point them at the user's file and line."""
    if not prepared.temp_file:
        return message

    def replace(match: re.Match) -> str:
        loc = prepared.line_map.get(int(match.group(1))) if match.group(1) else None
        if loc is not None and loc.line:
            return f"{loc.path}:{loc.line}"
        return loc.path if loc is not None else prepared.path

    for name, written in prepared.not_read.items():  # a mesh not given: its name as written
        message = message.replace(name, written)
    return re.sub(re.escape(prepared.temp_file) + r"(?::(\d+))?", replace, message)
