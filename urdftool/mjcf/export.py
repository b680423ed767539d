"""`urdftool convert ROBOT --to mjcf` (issue 32): a URDF model (URDF, xacro, SDF converted) as
MJCF that MuJoCo loads, written at full precision, every link kept as a body.

- Bodies: one per link (a fixed joint is a body without joint: MuJoCo welds it, nothing is
  fused), placed by ``pos``/``quat`` written as ``repr`` floats (MuJoCo's own saved XML keeps 6
  significant digits); a root link named ``world`` is MuJoCo's world body.
- Inertia: ``<inertial pos mass fullinertia>`` in the body frame (the URDF's inertial origin
  rotation folded into the tensor), ``inertiafromgeom="false"``: a link without ``<inertial>``
  has no mass, as in the URDF, never one MuJoCo would derive from its geometry.
- Joints: hinge (revolute ``limited="true"`` with its range, continuous unlimited), slide,
  free (``floating``, at the top level only); ``damping``, ``frictionloss``, and the effort
  limit as ``actuatorfrcrange``; mimics as ``<equality><joint polycoef="offset multiplier 0 0
  0">``. What MJCF cannot state (a planar joint, a joint velocity limit) is listed as lost.
- Geometry: collisions as colliding geoms, visuals as ``contype="0" conaffinity="0"
  group="1"`` with their colour; meshes in a format MuJoCo reads (STL, OBJ, MSH) referenced
  where they are, others (COLLADA, ...) converted with trimesh to STL files beside the output
  (through the one writer, ``urdftool.output``).
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import NamedTuple

from lxml import etree

MUJOCO_MESHES = (".stl", ".obj", ".msh")
STL_FACES = 200000  # MuJoCo's STL reader's bound


def _mujoco_reads(path: Path) -> bool:
    """A mesh file MuJoCo reads as it is: OBJ, MSH, binary STL of at most ``STL_FACES`` faces
    (MuJoCo reads no ASCII STL)."""
    suffix = path.suffix.lower()
    if suffix not in MUJOCO_MESHES:
        return False
    if suffix != ".stl":
        return True
    try:
        with open(path, "rb") as handle:
            head = handle.read(84)
        size = os.path.getsize(path)
    except OSError:
        return True  # MuJoCo says what is wrong with it
    if len(head) < 84:
        return False
    faces = int.from_bytes(head[80:84], "little")
    return 0 < faces <= STL_FACES and size == 84 + 50 * faces


class Export(NamedTuple):
    text: str
    lost: list[str]  # what the MJCF does not carry of what MJCF could state: a failure
    meshes: dict[str, bytes]  # converted mesh files to write: path -> content
    notes: list[str]  # what MJCF cannot state at all (joint velocity limits)


def _num(value: float) -> str:
    value = float(value)
    if value == 0:
        return "0"
    text = repr(value)
    return text.removesuffix(".0")


def _nums(values) -> str:
    return " ".join(_num(v) for v in values)


def _quat(rpy) -> tuple[float, float, float, float]:
    """URDF roll-pitch-yaw (fixed axes: Rz(y) Ry(p) Rx(r)) as MuJoCo's (w, x, y, z)."""
    r, p, y = (float(v) / 2 for v in rpy)
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), \
        math.sin(y)
    return (cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy)


def _place(element, pose) -> None:
    if any(pose.xyz):
        element.set("pos", _nums(pose.xyz))
    if any(pose.rpy):
        element.set("quat", _nums(_quat(pose.rpy)))


def _safe_name(text: str) -> str:
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in text) or "mesh"


class _Writer:
    def __init__(self, robot, out_dir: Path | None, out_stem: str):
        self.robot = robot
        self.out_dir = out_dir
        self.out_stem = out_stem
        self.lost: list[str] = []
        self.meshes: dict[str, bytes] = {}
        self.assets: dict[tuple, str] = {}  # (path, scale) -> mesh asset name
        self.asset_element = None
        self.colours = {m.name: m.rgba for m in robot.materials if m.name and m.rgba}
        self.geom_names: set[str] = set()

    def mesh_asset(self, shape) -> str | None:
        from urdftool.physics import meshes

        geometry = shape.geometry
        path = meshes.resolve(self.robot, geometry)
        if path is None or not os.path.isfile(path):
            self.lost.append(f"mesh {geometry.filename!r} of a {shape.role}: not found")
            return None
        key = (str(path), tuple(geometry.scale))
        if key in self.assets:
            return self.assets[key]
        name = f"{_safe_name(Path(path).stem)}_{len(self.assets)}"
        file = Path(path)
        if not _mujoco_reads(file):
            file = self.converted(file)
            if file is None:
                return None
        reference = str(file.resolve()) if self.out_dir is None else os.path.relpath(
            file.resolve() if file.is_absolute() else file, self.out_dir.resolve())
        # inertia="shell": the mesh's own inertia is never used (inertiafromgeom="false"), and
        # an open or flat mesh has no volume, which MuJoCo would refuse to compute
        element = etree.SubElement(self.asset_element, "mesh", name=name, file=reference,
                                   inertia="shell")
        if tuple(geometry.scale) != (1.0, 1.0, 1.0):
            element.set("scale", _nums(geometry.scale))
        self.assets[key] = name
        return name

    def converted(self, path: Path) -> Path | None:
        """A mesh MuJoCo cannot read, as an STL file beside the output (trimesh)."""
        if self.out_dir is None:
            self.lost.append(f"mesh {path.name}: MuJoCo cannot read {path.suffix} and the MJCF "
                             "goes to stdout (give -o OUT.xml to convert it beside it)")
            return None
        try:
            import trimesh

            mesh = trimesh.load(str(path), force="mesh")
            if len(mesh.faces) == 0:
                raise ValueError("no faces")
            # MuJoCo's STL reader takes at most 200000 faces; OBJ has no such bound
            suffix = "stl" if len(mesh.faces) <= STL_FACES else "obj"
            data = mesh.export(file_type=suffix)
        except Exception as exc:  # noqa: BLE001 - any reader's failure: said, the rest exported
            self.lost.append(f"mesh {path.name}: cannot be converted ({type(exc).__name__}: "
                             f"{exc})")
            return None
        if isinstance(data, str):
            data = data.encode("utf-8")
        target = self.out_dir / f"{self.out_stem}_meshes" / f"{_safe_name(path.stem)}_" \
            f"{len(self.meshes)}.{suffix}"
        self.meshes[str(target)] = bytes(data)
        return target

    def geom(self, body, shape) -> None:
        geometry = shape.geometry
        element = etree.Element("geom")
        if shape.name and shape.name not in self.geom_names:  # MuJoCo: unique names only
            self.geom_names.add(shape.name)
            element.set("name", shape.name)
        kind = geometry.kind
        sizes = [v for v in (*(geometry.size or ()), geometry.radius, geometry.length)
                 if v is not None]
        if kind != "mesh" and not all(v > 0 for v in sizes):
            self.lost.append(f"{shape.role} of link {body.get('name')!r}: a {kind} of size "
                             f"{' '.join(f'{v:g}' for v in sizes)}, which MuJoCo refuses")
            return
        if kind == "box" and geometry.size is not None:
            element.set("type", "box")
            element.set("size", _nums(v / 2 for v in geometry.size))
        elif kind in ("cylinder", "capsule") and geometry.radius is not None \
                and geometry.length is not None:
            element.set("type", kind)
            element.set("size", _nums((geometry.radius, geometry.length / 2)))
        elif kind == "sphere" and geometry.radius is not None:
            element.set("type", "sphere")
            element.set("size", _num(geometry.radius))
        elif kind == "mesh":
            name = self.mesh_asset(shape)
            if name is None:
                return
            element.set("type", "mesh")
            element.set("mesh", name)
        else:
            self.lost.append(f"{shape.role} of link {body.get('name')!r}: geometry {kind!r} "
                             "not written")
            return
        _place(element, shape.origin)
        if shape.role == "visual":
            element.set("contype", "0")
            element.set("conaffinity", "0")
            element.set("group", "1")
            rgba = self.colours.get(shape.material)
            if rgba is not None:
                element.set("rgba", _nums(rgba))
        else:
            element.set("group", "3")
        body.append(element)


def export(robot, tree, out: Path | None = None) -> Export:
    """The MJCF of ``robot`` (``tree``: its ``bodies.tree_of_robot``); ``out``: where it will be
    written (relative mesh paths, converted meshes beside it), None for stdout."""
    writer = _Writer(robot, out.parent if out is not None else None,
                     out.stem if out is not None else "robot")
    root = etree.Element("mujoco", model=robot.name or "robot")
    root.append(etree.Comment(f" Converted by urdftool from {Path(robot.source.path).name}: "
                              "every link a body, numbers at full precision "))
    # balanceinertia: a tensor that breaks the triangle inequality (no rigid body has it) is
    # made one MuJoCo loads, and the comparison says by how much it moved
    etree.SubElement(root, "compiler", angle="radian", inertiafromgeom="false",
                     autolimits="false", balanceinertia="true")
    writer.asset_element = etree.SubElement(root, "asset")
    world = etree.SubElement(root, "worldbody")
    equality = etree.Element("equality")
    elements: dict[int, object] = {}
    bounds = _bounds(tree)
    for i, body in enumerate(tree.bodies):
        link = robot.link(body.name)
        if i == 0 and tree.static_root:  # a root link named world: MuJoCo's world body
            element = world
        else:
            parent = elements[body.parent] if body.parent is not None else world
            element = etree.SubElement(parent, "body", name=body.name or f"body{i}")
            joint = robot.parent_joint(body.name) if body.parent is not None else None
            if joint is not None:
                _place(element, joint.origin)
                _joint(element, joint, body.joints[0], parent is world, writer, equality)
        elements[i] = element
        if element is not world:
            inertial = _inertial(body, bounds.get(i), writer)
            if inertial is not None:
                element.insert(0, inertial)
        if link is not None:
            for shape in link.visuals + link.collisions:
                writer.geom(element, shape)
    if len(writer.asset_element) == 0:
        root.remove(writer.asset_element)
    written = {e.get("name") for e in world.iter("joint")}
    for constraint in list(equality):
        if constraint.get("joint2") not in written:
            writer.lost.append(f"mimic of joint {constraint.get('joint1')!r}: its leader "
                               f"{constraint.get('joint2')!r} is no moving joint of the MJCF")
            equality.remove(constraint)
    if len(equality):
        root.append(equality)
    notes = []
    velocities = [j.name for _, j in tree.joints() if j.velocity is not None]
    if velocities:
        notes.append(f"velocity limits of {len(velocities)} joint(s) not carried: MuJoCo has no "
                     "joint velocity limit (a velocity actuator would add a controller)")
    etree.indent(root, space="  ")
    text = etree.tostring(root, encoding="unicode") + "\n"
    return Export(text, writer.lost, writer.meshes, notes)


MIN_MASS = 1e-9  # kg: what a moving body MuJoCo refuses as massless is given
MIN_MOMENT = 1e-12  # kg m^2: likewise, a rotational inertia (MuJoCo's bound is 1e-15)


def _bounds(tree) -> dict[int, tuple[float, float]]:
    """Group root body -> (mass, moment) to add: MuJoCo refuses a moving body whose welded
    group has no mass or no rotational inertia (a URDF may have both: virtual links, point
    masses on a slide)."""
    import numpy as np

    from urdftool.bodies import groups

    found = {}
    for root, group in groups(tree).items():
        if not tree.moving(root):
            continue
        add_mass = MIN_MASS if group.mass <= 0 else 0.0
        moments = np.linalg.eigvalsh(group.inertia) if group.mass > 0 else np.zeros(3)
        add_moment = MIN_MOMENT if float(min(moments)) < MIN_MOMENT else 0.0
        if add_mass or add_moment:
            found[root] = (add_mass, add_moment)
    return found


def _inertial(body, bound, writer):
    """The <inertial> of a body: ``diaginertia`` for a diagonal tensor, ``fullinertia`` for a
    positive definite one, else its principal moments and axes (``quat``); at full precision.
    ``bound``: (mass, moment) added where MuJoCo would refuse the body (said as lost)."""
    import numpy as np

    mass, tensor = body.mass, np.array(body.inertia, dtype=float)
    if bound is not None:
        mass += bound[0]
        tensor = tensor + bound[1] * np.eye(3)
        said = " and ".join(what for what, value in (("no mass", bound[0]),
                                                     ("no rotational inertia", bound[1])) if value)
        writer.lost.append(f"link {body.name!r} moves with {said}, which MuJoCo refuses: given "
                           f"{bound[0] or mass:g} kg, {bound[1]:g} kg m^2 more")
    if mass <= 0:
        return None
    inertial = etree.Element("inertial", pos=_nums(body.com), mass=_num(mass))
    off = (tensor[0][1], tensor[0][2], tensor[1][2])
    if not any(off):
        a, b, c = sorted(np.diag(tensor))
        if a < 0:
            writer.lost.append(f"inertia of link {body.name!r}: a negative moment ({a:g}; no "
                               "rigid body has one)")
        elif a + b < c * (1 - 1e-12):
            writer.lost.append(f"inertia of link {body.name!r}: its moments break the triangle "
                               "inequality (no rigid body has them); MuJoCo's balanceinertia "
                               "changes them")
        inertial.set("diaginertia", _nums(np.diag(tensor)))
        return inertial
    moments, axes = np.linalg.eigh(tensor)
    noise = 1e-12 * float(max(abs(moments)))  # rounding of a tensor with a zero moment
    moments = np.where(abs(moments) <= noise, 0.0, moments)
    if float(min(moments)) < 0:
        writer.lost.append(f"inertia of link {body.name!r}: a negative principal moment "
                           f"({float(min(moments)):g}; no rigid body has one), written as 0")
    elif moments[0] + moments[1] < moments[2] * (1 - 1e-12):  # (eigh: ascending)
        writer.lost.append(f"inertia of link {body.name!r}: its principal moments break the "
                           "triangle inequality (no rigid body has them); MuJoCo's "
                           "balanceinertia changes them")
    if float(min(moments)) > 0:
        inertial.set("fullinertia", _nums((tensor[0][0], tensor[1][1], tensor[2][2], *off)))
        return inertial
    if np.linalg.det(axes) < 0:
        axes[:, 2] = -axes[:, 2]
    inertial.set("quat", _nums(_matrix_quat(axes)))
    inertial.set("diaginertia", _nums(max(0.0, float(v)) for v in moments))
    return inertial


def _matrix_quat(r) -> tuple[float, float, float, float]:
    """A rotation matrix as (w, x, y, z) (Shepperd's method)."""
    trace = r[0][0] + r[1][1] + r[2][2]
    if trace > 0:
        s = math.sqrt(trace + 1.0) * 2
        return (s / 4, (r[2][1] - r[1][2]) / s, (r[0][2] - r[2][0]) / s, (r[1][0] - r[0][1]) / s)
    if r[0][0] > r[1][1] and r[0][0] > r[2][2]:
        s = math.sqrt(1.0 + r[0][0] - r[1][1] - r[2][2]) * 2
        return ((r[2][1] - r[1][2]) / s, s / 4, (r[0][1] + r[1][0]) / s, (r[0][2] + r[2][0]) / s)
    if r[1][1] > r[2][2]:
        s = math.sqrt(1.0 + r[1][1] - r[0][0] - r[2][2]) * 2
        return ((r[0][2] - r[2][0]) / s, (r[0][1] + r[1][0]) / s, s / 4, (r[1][2] + r[2][1]) / s)
    s = math.sqrt(1.0 + r[2][2] - r[0][0] - r[1][1]) * 2
    return ((r[1][0] - r[0][1]) / s, (r[0][2] + r[2][0]) / s, (r[1][2] + r[2][1]) / s, s / 4)


def _joint(body, joint, neutral, top_level: bool, writer, equality) -> None:
    kind = neutral.kind
    if kind == "fixed":
        return
    if kind == "free":
        if top_level:
            free = etree.SubElement(body, "freejoint")
            if joint.name:
                free.set("name", joint.name)
        else:
            writer.lost.append(f"floating joint {joint.name!r}: MuJoCo allows a free joint only "
                               "on a body of the world; welded")
        return
    if kind not in ("hinge", "slide"):
        writer.lost.append(f"{joint.type} joint {joint.name!r}: no MuJoCo joint of its kind; "
                           "welded")
        return
    element = etree.SubElement(body, "joint", name=joint.name or "", type=kind,
                               axis=_nums(neutral.axis))
    if neutral.range is not None and neutral.range[0] < neutral.range[1]:
        element.set("limited", "true")
        element.set("range", _nums(neutral.range))
    elif neutral.range is not None:
        writer.lost.append(f"range of joint {joint.name!r}: [{neutral.range[0]:g}, "
                           f"{neutral.range[1]:g}] is empty, which MuJoCo refuses; unlimited")
        element.set("limited", "false")
    else:
        element.set("limited", "false")
    if neutral.damping:
        element.set("damping", _num(neutral.damping))
    if neutral.friction:
        element.set("frictionloss", _num(neutral.friction))
    if neutral.effort is not None and neutral.effort > 0:
        element.set("actuatorfrclimited", "true")
        element.set("actuatorfrcrange", _nums((-neutral.effort, neutral.effort)))
    elif neutral.effort is not None:
        writer.lost.append(f"effort limit of joint {joint.name!r}: {neutral.effort:g} is an "
                           "empty force range, which MuJoCo refuses; not carried")
    if neutral.mimic is not None:
        leader, multiplier, offset = neutral.mimic
        etree.SubElement(equality, "joint", joint1=joint.name or "", joint2=leader,
                         polycoef=_nums((offset, multiplier, 0, 0, 0)))
