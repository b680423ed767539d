"""Rules of the `mesh` family: `<mesh filename>` references that do not resolve or load, meshes
in the wrong unit, and open meshes whose volume the inertia checks had to approximate.

Meshes are loaded with trimesh, lazily (a robot without meshes never imports it), once per
file per run (``urdftool.physics.meshes``). Without trimesh installed, only resolution and
existence are checked, and `mesh.not-checked` says what was skipped.
"""

from __future__ import annotations

import math

from urdftool.findings import Finding
from urdftool.packages import is_file
from urdftool.physics import links as analysis
from urdftool.rules import rule
from urdftool.uris import parse_uri


def _mesh_shapes(robot):
    """(link, ShapeInfo) for every mesh of the robot."""
    for a in analysis.analyse(robot).values():
        for info in a.shapes:
            if info.shape.geometry.kind == "mesh" and info.shape.geometry.filename:
                yield a, info


def _loc(info):
    return info.shape.geometry.loc or info.shape.loc


def _what(a, info) -> str:
    return f"link '{a.link.name}' {info.shape.role}"


_SKIPPED = "neither the mesh nor the link's inertia against its geometry is checked"


@rule("mesh.unresolved", "warning", "a mesh URI names a package urdftool cannot find",
      doc="""`package://NAME/path` needs package NAME: urdftool looks for it with `-P NAME=DIR`,
the nearest `package.xml` above the file and its siblings, `ROS_PACKAGE_PATH`,
`AMENT_PREFIX_PATH`, and a directory called NAME above the file (`package://urdftool/...` are
the example meshes shipped with urdftool). When none has it, the mesh
cannot be checked, and a robot tool run in the same environment will not find it either.
`package:///path` (an empty package name) is rejected by ROS's resource retriever even when
some tools (pinocchio) accept it. Other URI schemes (`http://`, `model://`) are not
local files. One finding per missing package (or scheme), at its first mesh, says how many
meshes share it: one `-P` fixes them all. In an SDF, `model://` meshes are reported by the SDF
reader (`sdf.mesh-uri`) with the model paths it searched. A package name one slip away from
exactly one package urdftool knows (`ur_descripton`) gets that name as its fix (safe: every
mesh URI of that package name written literally).""",
      bad='<robot name="r"><link name="a"><visual><geometry>'
          '<mesh filename="package://urdftol/physics/examples/open_box.stl"/>'
          '</geometry></visual></link></robot>',
      good='<robot name="r"><link name="a"><visual><geometry>'
           '<mesh filename="package://urdftool/physics/examples/open_box.stl"/>'
           '</geometry></visual></link></robot>',
      fix="safe")
def unresolved(robot):
    # one finding per missing package (or URI scheme), at its first mesh: one -P or one path
    # variable fixes them all, and a humanoid has a hundred meshes in the same package
    groups: dict[tuple[str, str], list] = {}
    for a, info in _mesh_shapes(robot):
        uri = info.shape.geometry.filename.strip()
        parsed = parse_uri(uri)
        if parsed.scheme == "package" and parsed.empty_name:
            groups.setdefault(("empty", ""), []).append((a, info, uri))
        elif info.path is None:
            if parsed.scheme == "model" and robot.source.kind == "sdf":
                continue  # the SDF reader's sdf.mesh-uri names it with the model paths
            key = ("package", parsed.name) if parsed.scheme == "package" else \
                ("other", parsed.scheme)
            groups.setdefault(key, []).append((a, info, uri))
    for (kind, name), meshes in groups.items():
        a, info, uri = meshes[0]
        more = (f" (and {len(meshes) - 1} more mesh{'es' if len(meshes) > 2 else ''} of this "
                "robot like it)") if len(meshes) > 1 else ""
        if kind == "empty":
            yield Finding(f"{_what(a, info)} mesh {uri!r} has an empty package name{more}: "
                          "ROS's resource retriever rejects it", _loc(info),
                          hint="write package://PACKAGE/" + parse_uri(uri).named)
        elif kind == "package":
            guess = _package_guess(robot, name)
            edits = ()
            if guess is not None:
                from urdftool.edits import head_edit

                # every mesh of the misspelt package, where its URI is written literally (a
                # macro line is one edit however many instances it has)
                made = {head_edit(robot.source.texts, _loc(i), ("mesh",), "filename",
                                  f"package://{name}/", f"package://{guess}/")
                        for _, i, _ in meshes}
                edits = tuple(sorted((e for e in made if e is not None),
                                     key=lambda e: (e.path, e.line, e.column)))
            yield Finding(f"{_what(a, info)} mesh {uri!r}: package '{name}' is not found{more}, "
                          f"so {_SKIPPED}", _loc(info),
                          hint=(f"did you mean package '{guess}'? " if guess else "")
                          + f"pass -P {name}=DIR, or put the directory holding it on "
                            "ROS_PACKAGE_PATH" + _tried(robot), edits=edits)
        elif name == "model":
            yield Finding(f"{_what(a, info)} mesh {uri!r}{more}: model:// is resolved by Gazebo "
                          "alone (from its resource path); other URDF tools cannot read it, "
                          f"and {_SKIPPED}", _loc(info),
                          hint="use package://PACKAGE/... or a path relative to the file")
        else:
            yield Finding(f"{_what(a, info)} mesh {uri!r} is not a local file{more}, so "
                          f"{_SKIPPED}", _loc(info),
                          hint="use package://PACKAGE/... or a relative path")


@rule("mesh.not-found", "error", "a mesh file does not exist",
      doc="""The mesh reference resolves to a path where there is no file. Every robot tool
fails to show or collide the link (rviz shows nothing, Gazebo and PyBullet print an error and
drop the shape). Relative paths are relative to the file where the `<mesh>` is written.
When the directory holds the same name in another case (`base.STL` for `base.stl`: found on a
case-insensitive disk, missing on Linux) or one mesh with a close name, that name is the fix;
a folder name with a slip in it (`mehses/`) is fixed the same way.

One finding per cause: when several meshes of a robot are missing from one folder that holds
no mesh at all (it does not exist, or is empty: a package whose meshes are not shipped with
its sources, or not pulled from Git LFS), that is one finding at the first of them, with how
many there are. When the package says how its meshes are installed (its `.gitignore` leaves
the folder or the mesh files out, `.gitattributes` stores them in Git LFS, its CMakeLists.txt
downloads them, or its README says how to fetch them), the finding is a warning naming what
says so: the meshes are expected to come from that step, and the robot tools will find them
once it has run.""",
      bad='<robot name="r"><link name="a"><visual><geometry>'
          '<mesh filename="package://urdftool/physics/examples/Open_Box.stl"/></geometry>'
          '</visual></link></robot>',
      good='<robot name="r"><link name="a"><visual><geometry>'
           '<mesh filename="package://urdftool/physics/examples/open_box.stl"/></geometry>'
           '</visual></link></robot>',
      fix="safe")
def not_found(robot):
    missing: dict = {}  # folder -> [(link analysis, shape info)] in document order
    for a, info in _mesh_shapes(robot):
        if info.path is not None and not is_file(info.path):
            missing.setdefault(info.path.parent, []).append((a, info))
    roots = getattr(getattr(robot.source, "resolver", None), "roots", None)
    for folder, shapes in missing.items():
        files = list(dict.fromkeys(info.path.name for _, info in shapes))
        # a folder of the repository's packages (not an absolute path of another machine:
        # file:///root/ws/install/..., each its own finding)
        ours = roots is None or roots.readable(folder)
        state = _empty_folder(folder) if len(files) > 1 and ours else None
        if state is not None:
            yield _folder_finding(robot, folder, state, shapes, files)
            continue
        for a, info in shapes:
            yield _missing_file(robot, a, info)


def _missing_file(robot, a, info) -> Finding:
    edits, hint = (), None
    twin = _twin(info.path)
    if twin is not None:
        from urdftool.edits import tail_edit

        name, where = twin
        hint = f"did you mean '{name}' ({where})?"
        written = info.path.name if "/" not in name else f"{info.path.parent.name}/{info.path.name}"
        made = tail_edit(robot.source.texts, _loc(info), ("mesh",), "filename", written, name)
        edits = (made,) if made is not None else ()
    return Finding(f"{_what(a, info)} mesh {info.shape.geometry.filename!r}: no file at "
                   f"{info.path}", _loc(info), hint=hint, edits=edits)


def _folder_finding(robot, folder, state: str, shapes, files: list[str]) -> Finding:
    """One finding for every mesh missing from a folder that holds none."""
    a, info = shapes[0]
    installed = _install_note(robot, folder)
    where = "does not exist" if state == "missing" else "holds no mesh file"
    message = (f"{_what(a, info)} mesh {info.shape.geometry.filename!r}: no file at "
               f"{info.path}; the folder {where}, and the robot names {len(files)} meshes in it "
               f"({_names(files, 3)}): the package's meshes are not there")
    if installed:
        return Finding(message + f"; {installed}, so they come from a separate step",
                       _loc(info), severity="warning",
                       hint="run the package's step that installs its meshes before checking "
                            "them (the mesh and inertia checks of these links are skipped)")
    return Finding(message + " (not shipped, or not pulled from Git LFS)", _loc(info),
                   hint="add the meshes to the package, or say in the package how they are "
                        "installed (the mesh and inertia checks of these links are skipped)")


def _empty_folder(folder) -> str | None:
    """"missing" when ``folder`` does not exist, "empty" when it holds no mesh file (nor a
    folder of them), None when it holds some."""
    from urdftool.physics.meshes import LOADABLE

    try:
        for _, entry in zip(range(2000), folder.iterdir()):
            if entry.suffix.lower() in LOADABLE or entry.is_dir():
                return None
    except FileNotFoundError:
        return "missing"
    except OSError:
        return None
    return "empty"


# what says how a package's meshes are installed (issue 29): read from these files of the
# package (and the repository root), small and bounded, inside the run's roots
_INSTALL_FILES = (".gitignore", ".gitattributes", "CMakeLists.txt", "README.md", "README.rst",
                  "README.txt", "README")
_INSTALL_BYTES = 256 << 10
_DOWNLOAD_WORDS = ("file(download", "externalproject_add", "fetchcontent_declare",
                   "catkin_download", "download_file", "_download(")


def _install_note(robot, folder) -> str | None:
    """What in the package of ``folder`` says its meshes are installed by a separate step
    (a short phrase), or None."""
    from urdftool.files import read_regular

    mesh_words = {".stl", ".dae", ".obj", ".ply", "mesh"}
    roots = getattr(getattr(robot.source, "resolver", None), "roots", None)
    for directory in _package_dirs(folder):
        for name in _INSTALL_FILES:
            path = directory / name
            if not is_file(path) or (roots is not None and not roots.readable(path)):
                continue
            try:
                text = read_regular(path, _INSTALL_BYTES).decode("utf-8", "replace").lower()
            except OSError:
                continue
            lines = [line.strip() for line in text.splitlines()]
            relative = _relative_name(folder, directory)
            if name == ".gitignore" and any(
                    line and not line.startswith(("#", "!")) and (
                        line.strip("/") in relative or any(w in line for w in mesh_words))
                    for line in lines):
                return f"its {path.parent.name}/.gitignore leaves the meshes out"
            if name == ".gitattributes" and any("filter=lfs" in line and any(
                    w in line for w in mesh_words | {relative}) for line in lines):
                return f"its {path.parent.name}/.gitattributes stores the meshes in Git LFS"
            if name == "CMakeLists.txt" and any(w in text for w in _DOWNLOAD_WORDS):
                return f"its {path.parent.name}/CMakeLists.txt downloads files"
            if name.startswith("README") and any(
                    "mesh" in line and any(w in line for w in ("download", "git lfs", "fetch",
                                                               "install"))
                    for line in lines):
                return f"its {path.parent.name}/{name} says how to get the meshes"
    return None


def _package_dirs(folder):
    """The directories above ``folder`` up to its package's (the nearest ``package.xml``),
    and that of the repository (``.git``) if it is further up: the nearest first."""
    found = []
    for directory in (folder, *folder.parents):
        if directory.is_dir():
            found.append(directory)
            if is_file(directory / "package.xml"):
                break
    else:
        return []
    for directory in found[-1].parents:
        if (directory / ".git").exists():
            found.append(directory)
            break
    return found[-2:] if len(found) > 1 else found


def _relative_name(folder, directory) -> str:
    try:
        return folder.relative_to(directory).as_posix().lower()
    except ValueError:
        return folder.name.lower()


def _package_guess(robot, name: str) -> str | None:
    """The one known package ``name`` is a slip of (``did_you_mean``), if any."""
    from urdftool.rules import did_you_mean

    known = getattr(getattr(robot.source, "resolver", None), "known", None)
    return did_you_mean(name, known()) if known is not None else None


def _tried(robot) -> str:
    """Where the package was looked for (``PackageResolver.tried``)."""
    resolver = robot.source.resolver if robot.source is not None else None
    tried = getattr(resolver, "tried", None)
    return f" (looked in: {tried()})" if tried is not None else ""


def _twin(path):
    """(name, where) of the one mesh file a missing ``path`` is a slip of: the same name in
    another case (``base.STL`` for ``base.stl``), else the one close name (``did_you_mean``)
    in the same directory; when the directory itself does not exist, the one close directory
    name beside it holding the file (``mehses/base.stl``: ``meshes/base.stl``). None when there
    is no such file or several."""
    from urdftool.rules import did_you_mean

    folder = path.parent
    entries = _mesh_files(folder)
    if entries is None:  # no such folder: a slip in its name?
        others = _folders(folder.parent)
        guess = did_you_mean(folder.name, others) if others else None
        if guess is not None and is_file(folder.parent / guess / path.name):
            return f"{guess}/{path.name}", "a folder of that name beside it"
        return None
    same = [n for n in entries if n.lower() == path.name.lower()]
    if same:
        return (same[0], "in the same directory") if len(same) == 1 else None
    guess = did_you_mean(path.name, entries)
    return (guess, "in the same directory") if guess is not None else None


def _mesh_files(folder) -> list[str] | None:
    """The mesh files of ``folder`` (at most 2000 entries looked at); None when it does not
    exist or cannot be listed."""
    from urdftool.physics.meshes import LOADABLE

    try:
        return [p.name for _, p in zip(range(2000), folder.iterdir())
                if p.suffix.lower() in LOADABLE and is_file(p)]
    except OSError:
        return None


def _folders(directory) -> list[str]:
    try:
        return [p.name for _, p in zip(range(2000), directory.iterdir()) if p.is_dir()]
    except OSError:
        return []



@rule("mesh.unreadable", "error", "a mesh file cannot be read as a mesh",
      doc="""The file exists but cannot be read as a mesh (corrupt, truncated, an HTML error
page saved as .stl, a format with no triangles). Simulators fail on it the same way. Formats
trimesh does not read (Ogre `.mesh`, for instance) are not checked. The message names the
reader that refused the file.

A COLLADA file is read as the ROS tools read it: RViz and MoveIt through assimp, Gazebo
classic with its own loader, both lenient about XML. White space or a byte-order mark before
`<?xml` is skipped, and a document a strict XML parser refuses (an exporter's
`<node id="<STL_BINARY>">`: `<` inside an attribute) is read in lxml's recover mode, as
assimp reads it. When pycollada still refuses such an XML document, RViz and Gazebo may well
display it: a warning (the file's other checks are not run), not an error.""",
      bad='<robot name="r"><link name="a"><visual><geometry>'
          '<mesh filename="package://urdftool/physics/examples/corrupt.stl"/>'
          '</geometry></visual></link></robot>',
      good='<robot name="r"><link name="a"><visual><geometry>'
           '<box size="0.1 0.1 0.1"/></geometry></visual></link></robot>')
def unreadable(robot):
    for a, info in _mesh_shapes(robot):
        mesh = info.mesh
        if mesh is not None and mesh.error is not None and not _timed_out(mesh) \
                and info.problem != analysis.NO_LIBRARY and not _lfs(mesh):
            from urdftool.physics.meshes import LENIENT  # loaded already: this mesh was read

            lenient = mesh.error.startswith(LENIENT)
            yield Finding(f"{_what(a, info)} mesh {info.path.name} cannot be read: "
                          f"{mesh.error}", _loc(info), severity="warning" if lenient else None)


def _not_read(shapes, why: str, hint: str) -> Finding:
    """One finding for the meshes of ``shapes`` that were not read for one cause: which files,
    which rules did not check them, on which links."""
    files = list(dict.fromkeys(info.path.name for _, info in shapes))
    links = list(dict.fromkeys(str(a.link.name) for a, _ in shapes))
    return Finding(f"{len(files)} mesh file(s) ({_names(files)}) {why} {_MESH_RULES} did not "
                   f"check them and {_GEOMETRY_RULES} did not run on {_names(links)}",
                   _loc(shapes[0][1]), hint=hint)


def _lfs(mesh) -> bool:
    from urdftool.physics import meshes  # loaded already: this mesh was read

    return meshes.lfs_pointer(mesh)


def _timed_out(mesh) -> bool:
    from urdftool.physics import meshes  # loaded already: this mesh was read

    return meshes.timed_out(mesh)


_MESH_RULES = "mesh.unreadable, mesh.scale and mesh.not-watertight"
# import name -> the distribution pip installs it from (the mesh extra)
_DISTRIBUTIONS = {"collada": "pycollada", "PIL": "Pillow"}
_GEOMETRY_RULES = ("inertia.exceeds-geometry, permuted-axes, unit-scale, com-outside-geometry, "
                   "geometry-mismatch and implausible-density")


def _names(names: list[str], most: int = 6) -> str:
    shown = ", ".join(f"'{n}'" for n in names[:most])
    return shown + (f" and {len(names) - most} more" if len(names) > most else "")


@rule("mesh.not-checked", "warning",
      "meshes were not read (trimesh or a library it needs missing, a format urdftool does not "
      "read): checks skipped",
      doc="""Nothing is skipped in silence. The mesh checks (`mesh.unreadable`, `mesh.scale`,
`mesh.not-watertight`) and the inertia checks against a link's geometry need the meshes read,
with trimesh and the libraries of the `mesh` extra (pycollada for COLLADA, scipy, Pillow).
The hint gives the command that installs the extra into this installation (a source checkout:
`pip install -e 'DIR[mesh]'`; an installation from a folder, archive or repository: from there;
with no record of where it came from, the README's line from a clone: urdftool is on no index). A mesh that cannot be read for want of one of
them is reported here, never as `mesh.unreadable`. Without them, `check` still runs every other rule
and says here, once per robot, which meshes and links were not checked: a warning, so that
`--strict` fails a CI job whose environment lacks it (the other commands that need trimesh stop
with exit code 2). A mesh in a format urdftool does not read (Ogre `.mesh`, VRML...) is advice:
its link's inertia is not compared with its geometry. Meshes that do not resolve are
`mesh.unresolved` and `mesh.not-found`. Meshes that are Git LFS pointers (a clone that did not
`git lfs pull`: actions/checkout's default) are one warning for the robot naming them, never
`mesh.unreadable`: the description is not at fault, the checkout is.""",
      bad='<robot name="r"><link name="a"><visual><geometry>'
          '<mesh filename="package://urdftool/physics/examples/part.mesh"/>'
          '</geometry></visual></link></robot>',
      good='<robot name="r"><link name="a"><visual><geometry>'
           '<box size="0.1 0.1 0.1"/></geometry></visual></link></robot>')
def not_checked(robot):
    skipped: dict[str, list] = {}
    slow, pointers = [], []
    for a, info in _mesh_shapes(robot):
        if info.problem in (analysis.NO_TRIMESH, analysis.NO_LIBRARY, analysis.UNREAD_FORMAT):
            skipped.setdefault(info.problem, []).append((a, info))
        elif info.mesh is not None and _timed_out(info.mesh):
            slow.append((a, info))
        elif info.mesh is not None and info.mesh.error is not None and _lfs(info.mesh):
            pointers.append((a, info))
    if pointers:  # one cause: the checkout (its meshes are fine where they were pulled)
        yield _not_read(pointers, "are Git LFS pointers: this checkout did not pull them, so",
                        "git lfs pull (in GitHub Actions: actions/checkout with lfs: true)")
    if slow:  # not known to be broken: stopped at the time limit (hostile, or a loaded machine)
        yield _not_read(slow, "were not read within the time limit:",
                        "--timeout SECONDS (each mesh is given that long)")
    for problem, shapes in skipped.items():
        links = list(dict.fromkeys(str(a.link.name) for a, _ in shapes))
        files = list(dict.fromkeys(info.path.name for _, info in shapes))
        first = _loc(shapes[0][1])
        if problem in (analysis.NO_TRIMESH, analysis.NO_LIBRARY):
            from urdftool.errors import install_line
            from urdftool.physics.meshes import missing_library

            missing = ["trimesh"] if problem == analysis.NO_TRIMESH else list(dict.fromkeys(
                _DISTRIBUTIONS.get(name, name) for name in
                (missing_library(info.mesh) for _, info in shapes)))
            yield Finding(f"{' and '.join(missing)} {'is' if len(missing) == 1 else 'are'} not "
                          f"installed: {len(files)} mesh file(s) of {len(links)} link(s) were "
                          f"not read (the files are not known to be broken), so {_MESH_RULES} "
                          f"did not check them and {_GEOMETRY_RULES} did not run on "
                          f"{_names(links)}", first,
                          hint=f"install urdftool's mesh extra: {install_line('mesh')}")
        else:
            suffixes = sorted({info.path.suffix or info.path.name for _, info in shapes})
            yield Finding(f"{len(files)} mesh file(s) in a format urdftool does not read "
                          f"({', '.join(suffixes)}): {_GEOMETRY_RULES} did not run on "
                          f"{_names(links)}", first, severity="info",
                          hint="a collision mesh in STL, OBJ or DAE is read by every tool")


def _reference_size(robot, skip) -> float | None:
    """The robot's typical dimension: joint offsets and primitive sizes (median), or the
    other meshes' sizes when there is nothing else."""
    sizes = []
    for joint in robot.joints:
        length = math.sqrt(sum(c * c for c in joint.origin.xyz))
        if length > 0 and math.isfinite(length):
            sizes.append(length)
    meshes_sizes = []
    for a in analysis.analyse(robot).values():
        for info in a.shapes:
            g = info.shape.geometry
            if g.kind == "box" and g.size:
                sizes.append(max(abs(v) for v in g.size))
            elif g.kind in ("cylinder", "capsule") and g.radius and g.length:
                sizes.append(max(2 * abs(g.radius), abs(g.length)))
            elif g.kind == "sphere" and g.radius:
                sizes.append(2 * abs(g.radius))
            elif info is not skip and info.mesh is not None and info.mesh.ok:
                meshes_sizes.append(_mesh_size(info))
    sizes = [s for s in sizes if s > 0 and math.isfinite(s)]
    if sizes:
        return _median(sizes)
    return _median(meshes_sizes) if meshes_sizes else None


def _median(values: list[float]) -> float:
    """(statistics.median costs 10 ms of imports on every check)"""
    ordered = sorted(values)
    middle = len(ordered) // 2
    return ordered[middle] if len(ordered) % 2 else (ordered[middle - 1] + ordered[middle]) / 2


def _mesh_size(info) -> float:
    extents = info.mesh.extents
    scale = info.shape.geometry.scale
    return max(abs(e * s) for e, s in zip(extents, scale))


@rule("mesh.scale", "warning", "a mesh is about 1000x too large: millimetres read as metres",
      doc="""URDF lengths are metres, and so are the coordinates of a mesh file. CAD tools
often export STL in millimetres; without `scale="0.001 0.001 0.001"` the part is then a
thousand times too large (a 10 cm bracket becomes 100 m). Reported when a mesh is at least
2 m across and 200 times the robot's typical dimension (the median of its joint offsets and
primitive shapes, or of its other meshes).""",
      bad='<robot name="r">\n<link name="a"><visual><geometry><box size="0.1 0.1 0.1"/>'
          '</geometry></visual></link>\n<joint name="j" type="fixed"><parent link="a"/>'
          '<child link="b"/><origin xyz="0.1 0 0"/></joint>\n<link name="b"><visual>'
          '<geometry><mesh filename="package://urdftool/physics/examples/bracket_mm.stl"/></geometry></visual></link>\n'
          '</robot>',
      good='<robot name="r">\n<link name="a"><visual><geometry><box size="0.1 0.1 0.1"/>'
           '</geometry></visual></link>\n<joint name="j" type="fixed"><parent link="a"/>'
           '<child link="b"/><origin xyz="0.1 0 0"/></joint>\n<link name="b"><visual>'
           '<geometry><mesh filename="package://urdftool/physics/examples/bracket_mm.stl" scale="0.001 0.001 0.001"/>'
           '</geometry></visual></link>\n</robot>')
def scale(robot):
    for a, info in _mesh_shapes(robot):
        if info.mesh is None or not info.mesh.ok:
            continue
        size = _mesh_size(info)
        if size < 2.0:
            continue
        reference = _reference_size(robot, info)
        if reference is None or size < 200 * reference:
            continue
        yield Finding(f"{_what(a, info)} mesh {info.path.name} is {size:.4g} m across, "
                      f"{size / reference:.3g}x the robot's typical dimension "
                      f"({reference:.3g} m): a mesh in millimetres?", _loc(info),
                      hint='add scale="0.001 0.001 0.001" to the <mesh>')


@rule("mesh.not-watertight", "info",
      "a mesh used for the inertia checks is not closed: its convex hull was used instead",
      doc="""To compare a link's declared inertia with its geometry, urdftool needs the
volume the mesh encloses, which only a closed (watertight, consistently wound) mesh has. For
an open mesh it uses the convex hull, which overestimates the volume of concave parts, so the
geometry-based inertia checks on that link are less precise. Visual meshes are often open;
this is reported only for the meshes the inertia is derived from (the collision geometry,
or the visual when there is no usable collision).""",
      bad='<robot name="r"><link name="a"><inertial><mass value="1"/>'
          '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'
          '<collision><geometry><mesh filename="package://urdftool/physics/examples/open_box.stl"/></geometry></collision>'
          '</link></robot>',
      good='<robot name="r"><link name="a"><inertial><mass value="1"/>'
           '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'
           '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>'
           '</link></robot>')
def not_watertight(robot):
    for a, info in _mesh_shapes(robot):
        if a.derived_from != info.shape.role or a.link.inertial is None:
            continue
        if info.mesh is not None and info.mesh.ok and info.mesh.used_hull:
            yield Finding(f"{_what(a, info)} mesh {info.path.name} is not a closed surface; "
                          "its convex hull stands in for it in the inertia checks",
                          _loc(info))
