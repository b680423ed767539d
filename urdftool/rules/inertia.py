"""Rules of the `inertia` family: what a link's `<inertial>` declares, against physics and
against the link's own geometry.

Two kinds of finding, kept apart on purpose:

- impossible (error): a negative mass, a tensor that is not positive definite, principal
  moments that break the triangle inequality, a moment larger than the declared mass can have
  anywhere inside what the link looks like and touches;
- unusual (warning or info): axes swapped against the geometry, a unit slip, a centre of mass
  outside the geometry, a large mismatch, an implausible density.

Geometry-based rules only run on links whose geometry is complete (every visual and collision
readable: primitives, and meshes that load); nothing is guessed about links without geometry.
The analysis is shared with `urdftool inertia` (``urdftool.physics.links``). Pure Python for
primitive robots; numpy and trimesh are imported only when a link has a mesh.
"""

from __future__ import annotations

import math

from urdftool import rules
from urdftool.findings import Finding
from urdftool.physics import links as analysis
from urdftool.physics.links import AXIS_NAMES
from urdftool.rules import child_loc, rule, value_edits

_INERTIA = '<inertia ixx="{0}" ixy="0" ixz="0" iyy="{1}" iyz="0" izz="{2}"/>'


def _robot(body: str) -> str:
    return f'<robot name="r">\n{body}\n</robot>'


def _link(name: str, mass: str, moments: tuple[str, str, str], geometry: str = "",
          origin: str = "") -> str:
    inertial = (f'  <inertial>{origin}<mass value="{mass}"/>'
                f'{_INERTIA.format(*moments)}</inertial>')
    shapes = (f'\n  <visual><geometry>{geometry}</geometry></visual>'
              f'\n  <collision><geometry>{geometry}</geometry></collision>') if geometry else ""
    return f'<link name="{name}">\n{inertial}{shapes}\n</link>'


def _inertia_loc(link):
    inertial = link.inertial
    if inertial is None:
        return link.loc
    return inertial.inertia_loc or inertial.loc or link.loc


def _moment_loc(robot, link, axis: str):
    """Where the moment about ``axis`` ("x", "y", "z" of the inertial frame) is written (its
    attribute, on whichever line of a tag written across lines); the <inertia> for a
    principal axis."""
    loc = _inertia_loc(link)
    if axis not in ("x", "y", "z") or link.inertial is None or loc is not link.inertial.inertia_loc:
        return loc
    from urdftool.edits import attribute_loc

    return attribute_loc(robot.source.texts, loc, ("inertia",), f"i{axis}{axis}")


def _mass_loc(link):
    inertial = link.inertial
    return (inertial.mass_loc or inertial.loc or link.loc) if inertial is not None else link.loc


def _origin_loc(robot, link):
    """Where the <origin> of a link's <inertial> was written, if it has one."""
    return child_loc(robot, link.inertial.loc, "origin") if link.inertial is not None else None


def _analyses(robot, name: str):
    defaults = robot.source.defaults
    for a in analysis.analyse(robot).values():
        if name in a.findings and not (defaults and defaults.get(a.link.name)):
            yield a  # (a static SDF model's default inertial never acts: not judged)


def _defaulted(robot, a) -> str:
    """What to say of a tensor the author did not write: SDFormat's default (an SDF link
    without <inertial>, converted)."""
    if a.link.name not in robot.source.defaults:
        return ""
    return ("; the link has no <inertial>: mass 1 kg and ixx = iyy = izz = 1 kg·m² are "
            "SDFormat's default, which Gazebo simulates (see sdf.default-inertial)")


# issue 22.4: inertias that simulation models set on purpose. A multicopter's motor plugin spins
# a rotor link (its inertia tuned so that software-in-the-loop flies), a fixed-wing's lift-drag
# plugin moves a control surface whose mass is negligible: physically impossible tensors there
# are the model's convention, warnings that say so
_ROTOR_PLUGINS = ("motor_model", "motormodel", "multicopter", "multirotor", "rotor",
                  "propeller")
_SURFACE_PLUGINS = ("lift_drag", "liftdrag", "lift-drag", "control_surface")
NEGLIGIBLE_MASS = 0.01  # a control surface lighter than 1% of the robot


_LAST_CONVENTIONS: tuple = (None, {})  # (robot, its conventions): asked once per bad tensor


def _conventions(robot) -> dict[str, str]:
    """Link name -> why its inertia is a simulation convention (the plugin that names it).
    Computed once per robot (a robot of thousands of bad tensors asked it for each)."""
    global _LAST_CONVENTIONS
    if _LAST_CONVENTIONS[0] is robot:
        return _LAST_CONVENTIONS[1]
    found = _find_conventions(robot)
    _LAST_CONVENTIONS = (robot, found)
    return found


def _find_conventions(robot) -> dict[str, str]:
    from urdftool.rules.gazebo import _local, _named, plugins

    found: dict[str, str] = {}
    total = sum(link.inertial.mass for link in robot.links if link.inertial is not None
                and link.inertial.mass is not None and math.isfinite(link.inertial.mass)
                and link.inertial.mass > 0)
    for plugin in plugins(robot):
        what = f"{plugin.get('filename') or ''} {plugin.get('name') or ''}".lower()
        rotor = any(p in what for p in _ROTOR_PLUGINS)
        surface = any(p in what for p in _SURFACE_PLUGINS)
        if not (rotor or surface):
            continue
        label = plugin.get("filename") or plugin.get("name") or "plugin"
        for node in plugin.iter():
            if _local(node.tag) not in ("linkName", "link_name", "bodyName", "body_name"):
                continue
            name = _named(robot, (node.text or "").strip())
            link = robot.link(name)
            if link is None or link.inertial is None or link.inertial.mass is None:
                continue
            if rotor:
                found[name] = (f"; '{name}' is a rotor of the multicopter plugin '{label}', "
                               "whose simulation models set rotor inertia on purpose (the "
                               "model flies in software-in-the-loop with it): a warning")
            elif total > 0 and link.inertial.mass <= NEGLIGIBLE_MASS * total:
                found[name] = (f"; '{name}' is a control surface of the plugin '{label}' with "
                               f"a negligible mass ({link.inertial.mass:g} of {total:g} kg), "
                               "whose inertia simulation models shrink or inflate on purpose: "
                               "a warning")
    return found


def _convention(robot, a, severity: str, message: str) -> tuple[str, str]:
    """(severity, message) of an impossible tensor, a warning on a link whose inertia is a
    simulation model's convention."""
    if severity != "error" or a.link.name is None:
        return severity, message
    why = _conventions(robot).get(a.link.name)
    return ("warning", message + why) if why else (severity, message)


def _g(value: float) -> str:
    return f"{value:.4g}"


def _block_hint(a) -> str | None:
    block = analysis.derived_inertial(a)
    if block is None:
        return None
    return ("the geometry gives " + analysis.inertial_xml(block, compact=True)
            + f"; see `urdftool inertia FILE --link {a.link.name}`")


_COMPONENTS = {"ixx": (0, 0), "ixy": (0, 1), "ixz": (0, 2), "iyy": (1, 1), "iyz": (1, 2),
               "izz": (2, 2)}


def _unasked(robot) -> bool:
    """The unsafe fix's edits are not asked for (``rules.UNSAFE_EDITS``: text output, no
    --fix or --diff) and a plain URDF computes no value, so there is no "fix by hand" note to
    give either: nothing to derive."""
    return not rules.UNSAFE_EDITS and robot.source.kind == "urdf"


def _tensor_edits(robot, a, values: dict[str, str]):
    """(edits, note) writing ``values`` into the link's <inertia> where they were written."""
    loc = a.link.inertial.inertia_loc if a.link.inertial is not None else None
    if loc is None:
        return (), ""
    return value_edits(robot, loc, ("inertia",), values)


def _derived_edits(robot, a):
    """The geometry's tensor for the declared mass (about its centroid, in the inertial
    frame) written into <inertia>."""
    if _unasked(robot):
        return (), ""
    if a.derived is not None:
        return _tensor_edits(robot, a, {name: f"{a.derived[i][j]:.6g}"
                                        for name, (i, j) in _COMPONENTS.items()})
    block = analysis.derived_inertial(a)  # in the link frame
    if block is None:
        return (), ""
    tensor = [[0.0] * 3 for _ in range(3)]
    for name, (i, j) in _COMPONENTS.items():
        tensor[i][j] = tensor[j][i] = block[name]
    rpy = a.link.inertial.origin.rpy
    if rpy != (0.0, 0.0, 0.0):  # written in the inertial's rotated frame: R^T I R
        from urdftool.physics.inertia import rpy_matrix

        r = rpy_matrix(rpy)
        tensor = [[sum(r[k][i] * tensor[k][m] * r[m][j] for k in range(3) for m in range(3))
                   for j in range(3)] for i in range(3)]
    scale = max(abs(tensor[i][i]) for i in range(3))  # rounding noise of the rotation: 0
    return _tensor_edits(robot, a, {name: f"{tensor[i][j] if abs(tensor[i][j]) > 1e-12 * scale else 0:.6g}"
                                    for name, (i, j) in _COMPONENTS.items()})


def _permuted_edits(robot, a):
    """The declared tensor with its axes put back: the author's own numbers, moved to the
    axes the geometry says they belong to."""
    if _unasked(robot):
        return (), ""
    import itertools

    d = [a.declared[i][i] for i in range(3)]
    g = [a.derived[i][i] for i in range(3)]
    if min(d) <= 0 or min(g) <= 0:
        return (), ""
    best = min(itertools.permutations(range(3)),
               key=lambda p: sum(abs(math.log(d[p[k]] / g[k])) for k in range(3)))
    names = {v: k for k, v in _COMPONENTS.items()}
    written = dict(zip(_COMPONENTS, _written_values(robot, a.link.inertial.inertia_loc)))
    values = {}
    for name, (i, j) in _COMPONENTS.items():
        source = names.get((min(best[i], best[j]), max(best[i], best[j])))
        values[name] = written.get(source) or "0"
    return _tensor_edits(robot, a, values)


def _written_values(robot, loc) -> list:
    from urdftool.edits import attribute, line_starts, tag_at

    text = robot.source.texts.get(loc.path) if loc is not None else None
    found = tag_at(text, line_starts(text), loc.line, loc.column, ("inertia",)) if text else None
    if found is None:
        return [None] * 6
    spans = [attribute(text, found, name) for name in _COMPONENTS]
    return [text[s[2]:s[3]] if s else None for s in spans]


def _centroid_hint(a) -> str:
    if a.solid is None:
        return "put the inertial <origin xyz> inside the body, in this link's frame"
    x, y, z = a.solid.centroid
    return (f"the {a.derived_from} geometry's centroid is at ({_g(x)}, {_g(y)}, {_g(z)}); "
            "the inertial <origin xyz> is in this link's frame")


# -- validity --------------------------------------------------------------------------------


@rule("inertia.mass-not-positive", "error",
      "a link declares a negative mass, inertia without mass, or a massless free base",
      doc="""A mass is positive. Three declarations cannot describe a body:

- a negative mass;
- mass 0 with non-zero moments of inertia: a moment is a sum of m·r² terms, so a body
  without mass has none;
- a base link (the root of the tree) with mass 0 while nothing fixed to it has mass and the
  robot has moving joints: as a free body it has no dynamics. PyBullet silently makes such
  a base static, Gazebo and Drake refuse it.

Moments on a massless root body (nothing fixed to it has mass) are a warning: PyBullet keeps
such a body static (mass 0 is how pybullet_data writes tables and fixed bases), so they never
act.

Mass 0 with zero inertia on a link fixed to a body that has mass (a frame like `tool0` or
`base_footprint`) is a deliberate massless frame and is fine. A robot meant to be bolted to
the ground says so with a `world` link and a fixed joint.""",
      bad=_robot('<link name="base">\n  <inertial><mass value="0"/>'
                 + _INERTIA.format(0, 0, 0) + '</inertial>\n</link>\n'
                 '<joint name="j" type="revolute"><parent link="base"/><child link="arm"/>'
                 '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
                 '</joint>\n' + _link("arm", "1", ("0.01", "0.01", "0.01"))),
      good=_robot('<link name="base">\n  <inertial><mass value="5"/>'
                  + _INERTIA.format(0.05, 0.05, 0.05) + '</inertial>\n</link>\n'
                  '<joint name="j" type="revolute"><parent link="base"/><child link="arm"/>'
                  '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
                  '</joint>\n' + _link("arm", "1", ("0.01", "0.01", "0.01"))))
def mass_not_positive(robot):
    bodies = analysis.RigidBodies.of(robot)
    for link in robot.links:
        inertial = link.inertial
        if inertial is None or inertial.mass is None or not math.isfinite(inertial.mass):
            continue
        mass = inertial.mass
        if mass < 0:
            yield Finding(f"link '{link.name}': mass {mass:g} kg is negative", _mass_loc(link),
                          hint="a mass is positive: write the link's mass in kilograms")
            continue
        if mass > 0:
            continue
        tensor = inertial.tensor
        largest = max((abs(v) for row in tensor for v in row), default=0.0) if tensor else 0.0
        if largest > 0:
            static = link.name is not None and bodies.is_static_root(link.name)
            yield Finding(f"link '{link.name}': mass 0 but moments of inertia up to "
                          f"{largest:g} kg·m²; a body without mass has no inertia "
                          "(a moment is at most m·r²)"
                          + ("; its body is a root without mass, which PyBullet keeps static "
                             "(the usual way to write a fixed object), so the inertia never "
                             "acts" if static else ""), _mass_loc(link),
                          hint="give the mass, or set the inertia to 0 for a massless frame",
                          severity="warning" if static else None)
        elif bodies.is_free_massless_base(link.name):
            yield Finding(f"link '{link.name}' is the base, has mass 0 and nothing fixed to it "
                          "has mass, while joints move below it: a free body without mass has "
                          "no dynamics (PyBullet silently makes it static, Gazebo and Drake "
                          "reject it)", _mass_loc(link),
                          hint="give the base its mass; to bolt the robot down, add a 'world' "
                               "link and a fixed joint to it")


def _targets_gazebo(robot) -> bool:
    """The description carries <gazebo> blocks (plugins, sensors, materials): it is meant to be
    loaded by Gazebo, whose URDF reader (sdformat) drops a moving link without mass."""
    return bool(robot.elements("gazebo"))


def is_kinematics_only(robot) -> bool:
    """No <inertial> anywhere while joints move: a description for rviz, TF and planning."""
    return (all(link.inertial is None for link in robot.links)
            and any(joint.moving for joint in robot.joints))


@rule("inertia.kinematics-only", "warning",
      "no link has an <inertial>: the description is kinematics only and cannot be simulated",
      doc="""A description without any `<inertial>` serves rviz, TF and motion planning (the
ROS-Industrial support packages, MoveIt's test robots are written so on purpose), but no
simulator can use it as is: PyBullet gives every link 1 kg and 1 kg·m², Gazebo's URDF reader
drops every link that a joint moves. Reported once for the robot, instead of once per moving
link as `inertia.massless-moving-link`. Add the inertials before simulating (`urdftool inertia
FILE --density 1000` suggests them from the geometry), or ignore the rule for a package that is
kinematics only on purpose (`ignore = ["inertia.kinematics-only"]`).""",
      bad=_robot('<link name="base"/>\n<joint name="j" type="revolute"><parent link="base"/>'
                 '<child link="arm"/><axis xyz="0 0 1"/>'
                 '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n'
                 '<link name="arm"/>\n<gazebo><static>false</static></gazebo>'),
      good=_robot(_link("base", "1", ("0.01", "0.01", "0.01")) + '\n'
                  '<joint name="j" type="revolute"><parent link="base"/><child link="arm"/>'
                  '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
                  '</joint>\n' + _link("arm", "0.5", ("0.001", "0.001", "0.001"))))
def kinematics_only(robot):
    if not is_kinematics_only(robot):
        return
    moving = sum(joint.moving for joint in robot.joints)
    loc = robot.loc(robot.root) if robot.root is not None else None
    yield Finding(f"robot '{robot.name}': no link has an <inertial> ({len(robot.links)} links, "
                  f"{moving} moving joints): kinematics only, it cannot be simulated as is "
                  "(PyBullet gives every link 1 kg, Gazebo drops every moving link)", loc,
                  hint="add an <inertial> to every link that moves (`urdftool inertia FILE "
                       "--density 1000` suggests them), or ignore inertia.kinematics-only "
                       "for a description meant for planning only")


@rule("inertia.massless-moving-link", "warning",
      "a link that moves has no <inertial>, or nothing on it or beyond it has mass",
      doc="""A link attached by a moving joint needs mass and inertia: it is a body the
joint accelerates. Without `<inertial>` PyBullet substitutes 1 kg and 1 kg·m² (adding mass the
robot does not have) and Gazebo drops the link and everything attached to it. With mass 0 and
nothing beyond it carrying mass, the joint moves nothing and its equation of motion is
singular.

A massless link between two joints (a hip or wrist built from several revolute joints) is fine
for PyBullet, pinocchio and Drake when the links beyond it carry mass, and is not reported,
unless the description carries `<gazebo>` blocks: Gazebo's URDF reader (sdformat) drops a
link of zero mass attached by a moving joint, together with its joints and everything beyond
it. It judges the lumped body: the links fixed to a link are merged into it first (their mass
becomes its mass, unless the fixed joint's `<gazebo>` block sets `preserveFixedJoint` or
`disableFixedJointLumping`), so a massless link whose fixed children carry mass is kept (not
reported for an SDF: Gazebo reads it as SDF, and the massless links its conversion to
URDF adds are named by `sdf.unsupported-joint`). A description with no `<inertial>` at all is
reported once, as `inertia.kinematics-only`.""",
      bad=_robot(_link("base", "1", ("0.01", "0.01", "0.01")) + '\n'
                 '<joint name="j" type="revolute"><parent link="base"/><child link="arm"/>'
                 '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
                 '</joint>\n<link name="arm"/>'),
      good=_robot(_link("base", "1", ("0.01", "0.01", "0.01")) + '\n'
                  '<joint name="j" type="revolute"><parent link="base"/><child link="arm"/>'
                  '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
                  '</joint>\n' + _link("arm", "0.5", ("0.001", "0.001", "0.001"))))
def massless_moving_link(robot):
    if is_kinematics_only(robot):
        return  # one finding for the robot: inertia.kinematics-only
    bodies = analysis.RigidBodies.of(robot)
    # an SDF is read by Gazebo as SDF, not through its URDF reader; the massless links its
    # conversion adds (ball, universal, screw joints) are sdf.unsupported-joint's to report
    gazebo = _targets_gazebo(robot) and robot.source.kind != "sdf"
    massless_tops = _massless_tops(robot, bodies)
    for link in robot.links:
        joint = robot.parent_joint(link.name) if link.name is not None else None
        if joint is None or not joint.moving:
            continue
        moves = f"link '{link.name}' moves (joint '{joint.name}', {joint.type})"
        if link.inertial is None:
            lumped = _gazebo_lumped_mass(robot, bodies, link.name)
            gazebo_says = ("Gazebo drops it and what hangs from it" if lumped == 0 else
                           f"Gazebo lumps what is fixed to it ({lumped:g} kg) into it")
            yield Finding(f"{moves} but has no <inertial>: PyBullet gives it 1 kg and "
                          f"1 kg·m², {gazebo_says}", link.loc,
                          hint="add an <inertial> with the link's mass and inertia "
                               "(`urdftool inertia FILE --density 1000` suggests one)")
        elif link.inertial.mass == 0 and bodies.subtree_mass(link.name) == 0:
            if massless_tops[link.name] != link.name:
                continue  # within the massless subtree of a link reported above it
            beyond = sum(top == link.name for top in massless_tops.values()) - 1
            what = f"the {beyond} moving link{'s' if beyond > 1 else ''} beyond it have" \
                if beyond else "anything beyond it has"
            yield Finding(f"{moves} but neither it nor {what} mass: the joint moves nothing "
                          "and its equation of motion is singular",
                          _mass_loc(link), hint="give the link its mass and inertia")
        elif link.inertial.mass == 0 and gazebo \
                and _gazebo_lumped_mass(robot, bodies, link.name) == 0:
            yield Finding(f"{moves} with mass 0 in a description for Gazebo: Gazebo's URDF "
                          f"reader drops it, joint '{joint.name}' and everything beyond it "
                          f"({bodies.subtree_mass(link.name):g} kg)", _mass_loc(link),
                          hint="give the link a small mass and inertia (a few grams and "
                               "1e-6 kg·m² keep the chain)")


_LUMPING_OFF = ("preserveFixedJoint", "disableFixedJointLumping")


def _gazebo_lumped_mass(robot, bodies, name: str) -> float:
    """The mass Gazebo's URDF reader (sdformat) gives link ``name``: its own and that of every
    link fixed to it, lumped into it before it judges a link massless (``ReduceFixedJoints``
    runs first), except through a fixed joint whose <gazebo> block keeps it
    (``preserveFixedJoint``, ``disableFixedJointLumping``)."""
    kept = set()
    for block in robot.elements("gazebo"):
        reference = block.get("reference")
        if reference and any((block.findtext(tag) or "").strip().lower() in ("true", "1")
                             for tag in _LUMPING_OFF):
            kept.add(reference)
    total, stack, seen = bodies.mass.get(name, 0.0), [name], {name}
    while stack:
        for joint in bodies.children.get(stack.pop(), []):
            if joint.moving or joint.child is None or joint.child in seen or joint.name in kept:
                continue
            seen.add(joint.child)
            stack.append(joint.child)
            total += bodies.mass.get(joint.child, 0.0)
    return total


def _massless_tops(robot, bodies) -> dict[str, str | None]:
    """For each link moved by a joint, with mass 0 and nothing of mass beyond it: the highest
    such link above it through links without mass (itself when there is none), so that a
    massless finger is one finding, not one per phalanx. Iterative, each link walked once."""
    def candidate(name) -> bool:
        link, joint = robot.link(name), robot.parent_joint(name)
        return (joint is not None and joint.moving and link is not None
                and link.inertial is not None and link.inertial.mass == 0
                and bodies.subtree_mass(name) == 0)

    tops: dict[str, str | None] = {}
    for link in robot.links:
        if link.name is None or link.name in tops:
            continue
        path, name, top = [], link.name, None
        while name is not None and name not in tops and name not in path:
            path.append(name)
            joint = robot.parent_joint(name)
            name = joint.parent if joint is not None else None
            if name is not None and bodies.subtree_mass(name) != 0:
                name = None  # the massless subtree ends here
        top = tops.get(name) if name is not None else None
        for name in reversed(path):  # from the highest down
            if top is None and candidate(name):
                top = name
            tops[name] = top if candidate(name) or top is not None else None
    return {name: top for name, top in tops.items() if candidate(name)}


@rule("inertia.not-positive-definite", "error",
      "the inertia tensor has a negative principal moment (or is zero on a moving link)",
      doc="""An inertia tensor is symmetric positive definite: every principal moment (its
eigenvalue) is the sum of two positive second moments of the mass. A negative principal
moment is impossible; simulators reject the link or integrate garbage. The usual cause is a
sign convention: CAD tools export products of inertia as ∫xy dm, URDF wants the tensor
element -∫xy dm, so `ixy`, `ixz`, `iyz` have the wrong sign.

A zero tensor with a positive mass (a point mass) on a link that moves is a warning: a body of
that mass has a size, ODE rejects it and Bullet or MuJoCo clamp it to an arbitrary minimum. On
a link fixed to another body it is harmless (the masses are lumped) and not reported, and
neither is a single zero moment (a thin rod along its axis, a common simplification). Moments
below 1e-15 kg·m² count as zero.""",
      bad=_robot('<link name="a">\n  <inertial><mass value="1"/>'
                 '<inertia ixx="0.01" ixy="0.02" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>'
                 '</inertial>\n</link>'),
      good=_robot('<link name="a">\n  <inertial><mass value="1"/>'
                  '<inertia ixx="0.01" ixy="-0.002" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>'
                  '</inertial>\n</link>'))
def not_positive_definite(robot):
    for a in analysis.analyse(robot).values():
        severity = a.findings.get("not-positive-definite")
        if severity is None:
            continue
        low, mid, high = a.principal
        moments = f"principal moments {_g(low)}, {_g(mid)}, {_g(high)} kg·m²"
        if severity == "error":
            severity, message = _convention(
                robot, a, severity, f"link '{a.link.name}': {moments}: {_g(low)} is negative, "
                "which no mass distribution gives")
            yield Finding(message, _inertia_loc(a.link), severity=severity,
                          hint="check the signs of ixy, ixz, iyz (URDF wants -∫xy dm; CAD "
                               "tools often export +∫xy dm)")
        else:
            yield Finding(f"link '{a.link.name}' moves but its inertia is zero ({moments}) "
                          f"with a mass of {a.mass:g} kg: a point mass; ODE rejects it, Bullet "
                          "and MuJoCo clamp it",
                          _inertia_loc(a.link), hint=_block_hint(a), severity="warning")


@rule("inertia.triangle-inequality", "error",
      "the principal moments break the triangle inequality (one exceeds the sum of the others)",
      doc="""For any body, each principal moment is at most the sum of the other two:
I1 = B + C, I2 = A + C, I3 = A + B with A, B, C ≥ 0 the second moments of the mass along the
principal axes, so I1 + I2 - I3 = 2C ≥ 0. A tensor that breaks this is not the inertia of any
mass distribution; physics engines that check it (Drake, MuJoCo) refuse it, others integrate
unphysical motion. Equality is a flat plate; a relative tolerance of 1% of the largest moment
lets rounded CAD exports and thin rods through.""",
      bad=_robot(_link("a", "1", ("0.01", "0.01", "0.05"), '<box size="0.3 0.3 0.1"/>')),
      good=_robot(_link("a", "1", ("0.01", "0.01", "0.02"), '<box size="0.3 0.3 0.1"/>')),
      fix="unsafe")
def triangle_inequality(robot):
    for a in _analyses(robot, "triangle-inequality"):
        low, mid, high = a.principal
        excess = high - (low + mid)
        edits, note = _derived_edits(robot, a)
        severity, message = _convention(
            robot, a, "error", f"link '{a.link.name}': principal moments {_g(low)} + {_g(mid)} "
            f"< {_g(high)} kg·m² (short by {excess / high:.0%} of the largest): no mass "
            "distribution has these moments")
        yield Finding(message, _inertia_loc(a.link), severity=severity,
                      hint=(_block_hint(a) or "recompute the inertia from the link's shape")
                      + note, edits=edits)


# -- against the geometry --------------------------------------------------------------------


def _impossible(robot) -> set:
    """The links whose tensor is impossible for their geometry (an error of exceeds-geometry,
    or of unit-scale, which takes its place)."""
    return {a.link.name for a in analysis.analyse(robot).values()
            if a.findings.get("exceeds-geometry") == "error"
            or a.findings.get("unit-scale") == "error"}


def _lumped_verdict(robot, a, severity: str, impossible: set) -> tuple[str, str]:
    """(severity, sentence) of an impossible tensor, judged through the body its link is
    lumped into (``_merged_verdict``)."""
    if severity != "error" or a.link.name is None:
        return severity, ""
    effect = analysis.RigidBodies.of(robot).tensor_effect(a.link.name, impossible)
    return _merged_verdict(a.link.name, effect) if effect is not None else (severity, "")


@rule("inertia.exceeds-geometry", "error",
      "a declared moment is larger than the mass can have inside the link's geometry",
      doc="""A mass m lying inside a region has, about any axis through its centre of mass,
a moment of at most m·r², where r is the largest distance from that axis to a point of the
region. urdftool takes the region to be the union of the link's visual and collision
geometry (a body is not larger than what it looks like and what it touches; collision shapes
alone are often deliberately shrunk) and checks the axes of the inertial frame and the
principal axes. More than 2x over the bound is an error: the declared inertia is physically
impossible for that mass (typically a placeholder like `ixx="1"` on a 50 g finger, or a unit
slip). Between 1.1x and 2x it is a warning: possible only if the geometry leaves out part of
the body (a motor that is not drawn). Up to 10% over is let through: rounded numbers and
decimated meshes (whose hull is slightly smaller than the part) get that close to the bound.
Links without geometry are not checked; when only a visual cannot be read (a mesh not found),
the bound is taken over the collisions alone and only more than 2x over it is reported, as a
warning that names the visual (it might have widened the bound).

A link fixed to another is lumped into that body by Gazebo, Drake and MuJoCo, whose own tensor
stays possible (a sum of possible tensors): such a tensor is an error only when it changes the
merged body's principal moments by more than 10% against a point mass in its place (the
body's dynamics change by that much); otherwise a warning that gives the change.

Simulation models set some inertias on purpose: the rotors a multicopter motor plugin spins
(`<linkName>` of a motor-model/multicopter/rotor plugin) and control surfaces of negligible
mass (under 1% of the robot) that a lift-drag plugin moves. There an impossible tensor is a
warning that names the plugin (also for `inertia.triangle-inequality` and
`inertia.not-positive-definite`).""",
      bad=_robot(_link("wheel", "0.1", ("1.0", "1.0", "1.0"),
                       '<cylinder radius="0.025" length="0.02"/>')),
      good=_robot(_link("wheel", "0.1", ("1.9e-05", "1.9e-05", "3.1e-05"),
                        '<cylinder radius="0.025" length="0.02"/>')),
      fix="unsafe")
def exceeds_geometry(robot):
    found = list(_analyses(robot, "exceeds-geometry"))
    impossible = _impossible(robot) if found else set()
    for a in found:
        # permuted axes: that rule's fix keeps the author's numbers
        edits, note = _derived_edits(robot, a) if "permuted-axes" not in a.findings else ((), "")
        b = a.bound
        m = a.mass
        severity, merged = _lumped_verdict(robot, a, a.findings["exceeds-geometry"], impossible)
        axis = b.axis_name.replace("principal", "principal axis") \
            if b.axis_name.startswith("principal") else f"{b.axis_name} axis"
        severity, convention = _convention(robot, a, severity, "")
        yield Finding(f"link '{a.link.name}': moment {_g(b.moment)} kg·m² about the "
                      f"{axis} through the COM is {b.ratio:.3g}x the most {m:g} kg can have "
                      f"within its {a.bound_over} geometry ({m:g} kg × "
                      f"({_g(b.reach)} m)² = {_g(b.bound)} kg·m²)" + _unread_visuals(a)
                      + (_defaulted(robot, a) or
                         (f"; ixx = iyy = izz = {a.declared[0][0]:g} looks like a placeholder"
                          if analysis.is_placeholder(a.declared) else "")) + merged + convention,
                      _moment_loc(robot, a.link, b.axis_name),
                      hint=(_block_hint(a) or "") + note or None, severity=severity, edits=edits)


def _unread_visuals(a) -> str:
    """What a bound over the collisions alone says of the visuals it left out."""
    if a.bound_over != "collision":
        return ""
    unread = [s for s in a.shapes if s.shape.role == "visual" and not s.usable]
    names = ", ".join(f"'{s.path.name if s.path is not None else s.shape.geometry.filename}'"
                      for s in unread[:2]) + (" ..." if len(unread) > 2 else "")
    return (f" (its visual {names} was not read: a warning, since a visual larger than the "
            "collision could allow more)")


def _merged_verdict(name: str, effect) -> tuple[str, str]:
    """(severity, sentence) of an impossible tensor judged through the body it is lumped
    into: negligible there (or on a body welded to the world) is a warning."""
    body = effect.body
    if effect.static:
        return "warning", (f"; but '{name}' is fixed to 'world': that body never moves, so its "
                           "inertia does not act in a simulation")
    change = "∞" if math.isinf(effect.change) else f"{100 * effect.change:.3g}%"
    lumped = (f"; Gazebo, Drake and MuJoCo lump fixed links into one body: '{name}' joins "
              f"'{body.root}' ({body.mass:.4g} kg, {body.links} links with mass), whose "
              f"principal moments this tensor changes by {change} against a point mass")
    limit = f"{100 * analysis.MERGED_ERROR_FRACTION:g}%"
    if effect.change < analysis.NEGLIGIBLE_EFFECT:
        return "warning", lumped + ": negligible there"
    if effect.change <= analysis.MERGED_ERROR_FRACTION:
        return "warning", (lumped + f": the body it joins is possible, and changed by no more "
                           f"than the {limit} urdftool calls an error")
    return "error", lumped + f", more than the {limit} urdftool calls an error"


def _permutation_text(perm: tuple[int, int, int]) -> str:
    names = [f"i{a}{a}" for a in AXIS_NAMES]
    moved = [i for i in range(3) if perm[i] != i]
    if len(moved) == 2:
        return f"{names[moved[0]]} and {names[moved[1]]} swapped"
    # declared axis perm[i] carries the geometry's axis i
    inverse = [perm.index(k) for k in range(3)]
    return ("declared " + ", ".join(names) + " are the geometry's "
            + ", ".join(names[inverse[k]] for k in range(3)))


@rule("inertia.permuted-axes", "warning",
      "the declared moments are the geometry's with two axes swapped",
      doc="""The declared principal moments match what the link's geometry gives for its
mass, but on the wrong axes: the moment that belongs about x is written as izz, for instance.
This happens when a formula for a shape along z (a cylinder's izz = m r²/2) is pasted onto a
shape lying along x, or when the box formula gets its sides in the wrong order. The link then
turns too easily about one axis and too hard about another. Compared in the inertial frame,
after rotating the geometry's tensor into it; reported only when the declared tensor is off
by 30% or more as written and within 10% once permuted.""",
      bad=_robot(_link("leg", "1", ("0.0034", "0.0034", "0.00017"),
                       '<box size="0.2 0.04 0.04"/>')),
      good=_robot(_link("leg", "1", ("0.00027", "0.0035", "0.0035"),
                        '<box size="0.2 0.04 0.04"/>')),
      fix="unsafe")
def permuted_axes(robot):
    for a in _analyses(robot, "permuted-axes"):
        edits, note = _permuted_edits(robot, a)
        d = [a.declared[i][i] for i in range(3)]
        g = [a.derived[i][i] for i in range(3)]
        yield Finding(f"link '{a.link.name}': declared ixx, iyy, izz = {_g(d[0])}, {_g(d[1])}, "
                      f"{_g(d[2])} kg·m² match its {a.derived_from} geometry's "
                      f"{_g(g[0])}, {_g(g[1])}, {_g(g[2])} with "
                      f"{_permutation_text(a.permutation)}", _inertia_loc(a.link),
                      hint=f"write ixx=\"{_g(g[0])}\" iyy=\"{_g(g[1])}\" izz=\"{_g(g[2])}\""
                           + note, edits=edits)


_SLIPS = {
    1e3: "inertia in g·m² rather than kg·m²",
    1e6: "inertia in kg·mm² rather than kg·m²",
    1e-3: "mass in grams rather than kilograms",
    1e-6: "geometry in millimetres (a mesh without scale=\"0.001 0.001 0.001\")",
}


@rule("inertia.unit-scale", "warning",
      "the declared inertia is the geometry's times 1000 or a million (or divided by it)",
      doc="""All three declared moments differ from what the geometry gives for the
declared mass by the same power of a thousand: grams for kilograms, millimetres for metres
(kg·mm² is a million times kg·m²). CAD tools export in their document units and the numbers
get pasted as they are. Reported only on that evidence: the three ratios (declared over
geometry, per axis) agree within a factor 2 and their geometric mean is within a factor √10
of 10³ or 10⁶ (or their inverses); a ratio above 1 must also break the geometry bound
(`inertia.exceeds-geometry`), so a large but possible inertia is not called a slip. A round
placeholder typed in (ixx = iyy = izz = 1, 0.01, 0.05...: a CAD export has the part's own
unequal moments) is not called a slip: `inertia.exceeds-geometry` reports it.

One finding per tensor: a slip found is reported here instead of `inertia.exceeds-geometry`,
with that rule's severity (an error when the tensor is impossible for the geometry, judged
through the body a fixed link is lumped into), a warning when the moments are too small.""",
      bad=_robot(_link("box", "1", ("1.04167", "1.04167", "0.416667"),
                       '<box size="0.05 0.05 0.1"/>')),
      good=_robot(_link("box", "1", ("0.00104167", "0.00104167", "0.000416667"),
                        '<box size="0.05 0.05 0.1"/>')))
def unit_scale(robot):
    found = list(_analyses(robot, "unit-scale"))
    impossible = _impossible(robot) if found else set()
    for a in found:
        ratio = [r for r in a.ratios]
        severity, merged = _lumped_verdict(robot, a, a.findings["unit-scale"], impossible)
        severity, convention = _convention(robot, a, severity, "")
        bound = ""
        if a.bound is not None and a.unit_slip > 1:
            bound = (f"; {_g(a.bound.moment)} kg·m² is {a.bound.ratio:.3g}x the most "
                     f"{a.mass:g} kg can have within its {a.bound_over} geometry")
        yield Finding(f"link '{a.link.name}': declared moments are {_g(ratio[0])}x, "
                      f"{_g(ratio[1])}x, {_g(ratio[2])}x (ixx, iyy, izz) what its "
                      f"{a.derived_from} geometry gives for {a.mass:g} kg: "
                      f"{_SLIPS[a.unit_slip]}?" + bound + merged + convention,
                      _inertia_loc(a.link), hint=_block_hint(a), severity=severity)


@rule("inertia.com-outside-geometry", "warning",
      "the centre of mass lies outside the link's visual and collision geometry",
      doc="""A body's centre of mass lies inside the convex hull of the body. urdftool takes
the hull of the link's visual and collision geometry together and reports a centre of mass
outside it by more than a quarter of the body's width in that direction (decimated meshes and
rounded numbers stay well within that). Common causes: the inertial `<origin>` copied from the
joint or written in the parent's frame, a sign error, a `<pose>` that URDF ignores, or
geometry that leaves out a heavy part. The fix (unsafe: it trusts the geometry) puts the
inertial `<origin xyz>` at the geometry's centroid.

Meshes are placed as the ROS tools place them (for every rule of this family): a COLLADA
file's `<unit meter>` is applied and its `<up_axis>` is not. RViz drops the rotation assimp puts
in the scene's root node for a non-Y-up file (rviz `src/rviz/mesh_loader.cpp`, `buildMesh`),
MoveIt's geometric_shapes resets that transform (`src/mesh_operations.cpp`), and Gazebo
classic's own COLLADA loader (`gazebo/common/ColladaLoader.cc`) reads `<unit>` only: a
`Y_UP` mesh is drawn and collided in its own coordinates, so it is checked in them.""",
      bad=_robot('<link name="chassis">\n  <inertial><origin xyz="0 0 0.1"/>'
                 '<mass value="5"/>' + _INERTIA.format(0.0395, 0.106, 0.142) + '</inertial>\n'
                 '  <visual><geometry><box size="0.5 0.3 0.07"/></geometry></visual>\n'
                 '</link>'),
      good=_robot('<link name="chassis">\n  <inertial><origin xyz="0 0 0"/>'
                  '<mass value="5"/>' + _INERTIA.format(0.0395, 0.106, 0.142) + '</inertial>\n'
                  '  <visual><geometry><box size="0.5 0.3 0.07"/></geometry></visual>\n'
                  '</link>'),
      fix="unsafe")
def com_outside_geometry(robot):
    for a in _analyses(robot, "com-outside-geometry"):
        x, y, z = a.com
        loc = _origin_loc(robot, a.link) or a.link.inertial.loc or a.link.loc
        width = (f"{a.com_distance / a.com_thickness:.0%} of the body's "
                 f"{_g(a.com_thickness)} m width in that direction" if a.com_thickness > 0
                 else "the body is flat in that direction")
        edits, note = (), ""
        origin = _origin_loc(robot, a.link)
        if a.solid is not None and origin is not None and not _unasked(robot):  # COM to centroid
            from urdftool.edits import number

            edits, note = value_edits(robot, origin, ("origin",),
                                      {"xyz": " ".join(map(number, a.solid.centroid))})
        yield Finding(f"link '{a.link.name}': centre of mass ({x:g}, {y:g}, {z:g}) lies "
                      f"{_g(a.com_distance)} m outside the convex hull of its visual and "
                      f"collision geometry ({width})" + _defaulted(robot, a), loc,
                      hint=_centroid_hint(a) + note,
                      edits=edits)


@rule("inertia.geometry-mismatch", "info",
      "the declared inertia differs from the geometry's by more than 10x",
      doc="""The declared moments are possible (within the bound of
`inertia.exceeds-geometry`) but more than ten times larger or smaller than a uniform body of
the link's shape and mass would have. Real links are not uniform (motors, hollow shells), so
this is advice only: worth a look, not necessarily wrong. Nothing is said below 10x.""",
      bad=_robot(_link("a", "1", ("0.0001", "0.0001", "0.0001"), '<sphere radius="0.1"/>')),
      good=_robot(_link("a", "1", ("0.004", "0.004", "0.004"), '<sphere radius="0.1"/>')))
def geometry_mismatch(robot):
    for a in _analyses(robot, "geometry-mismatch"):
        worst = max(a.ratios, key=lambda r: max(r, 1 / r) if r > 0 else math.inf)
        worst = max(worst, 0.0)
        d = [a.declared[i][i] for i in range(3)]
        g = [a.derived[i][i] for i in range(3)]
        if worst <= 0:
            how = "declares a zero moment that"
        else:
            factor = worst if worst >= 1 else 1 / worst
            how = (f"declared moments are up to {factor:.3g}x "
                   + ("larger" if worst >= 1 else "smaller") + " than")
        yield Finding(f"link '{a.link.name}': {how} a uniform body of its {a.derived_from} "
                      f"geometry and {a.mass:g} kg (ixx, iyy, izz declared {_g(d[0])}, {_g(d[1])}, "
                      f"{_g(d[2])}; geometry {_g(g[0])}, {_g(g[1])}, {_g(g[2])} kg·m²)"
                      + _defaulted(robot, a),
                      _inertia_loc(a.link), hint=_block_hint(a))


@rule("inertia.implausible-density", "info",
      "mass and geometry volume give a density lighter than foam or denser than osmium",
      doc="""The declared mass divided by the volume of the link's geometry is below
10 kg/m³ (lighter than expanded polystyrene) or above 25000 kg/m³ (denser than any element).
Either the mass or the geometry is off, often by a unit (grams, millimetres). Advice only:
geometry can be a shell or leave parts out. When both the collision and the visual volume are
known (primitives; meshes are measured where the inertia is derived from), both must agree
before anything is said.""",
      bad=_robot(_link("a", "100", ("0.06", "0.06", "0.06"), '<box size="0.06 0.06 0.06"/>')),
      good=_robot(_link("a", "1", ("0.0006", "0.0006", "0.0006"), '<box size="0.06 0.06 0.06"/>')))
def implausible_density(robot):
    for a in _analyses(robot, "implausible-density"):
        volumes = a.volumes
        smallest = min(volumes.values())  # 0 when a tiny size underflows (found by the fuzzer)
        if smallest > 0 and a.mass / smallest < analysis.DENSITY_LOW:
            role = min(volumes, key=volumes.__getitem__)
            density = a.mass / volumes[role]
            what = f"lighter than foam (< {analysis.DENSITY_LOW:g} kg/m³)"
        else:
            role = max(volumes, key=volumes.__getitem__)
            density = a.mass / volumes[role]
            what = f"denser than osmium (> {analysis.DENSITY_HIGH:g} kg/m³)"
        yield Finding(f"link '{a.link.name}': {a.mass:g} kg in {_g(volumes[role])} m³ of "
                      f"{role} geometry is {_g(density)} kg/m³, {what}" + _defaulted(robot, a),
                      _mass_loc(a.link))
