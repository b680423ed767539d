"""Rules of the `geometry` family: shapes of visuals and collisions.

Sizes must be positive; a link's collision should roughly cover what its visual shows; a moving
link that is seen and has mass should also collide. Pure Python (no numpy): these run on every
``urdftool check``. Meshes are left to the `mesh` family, which loads them; here only primitive
shapes (box, cylinder, sphere, capsule) are compared.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

from urdftool.findings import Finding
from urdftool.physics.inertia import rpy_matrix
from urdftool.rules import child_loc, rule, value_edits

HUGE = 1e9  # metres: bounds beyond this are not a robot

# -- shapes -------------------------------------------------------------------------------------


def _bounds(shape) -> tuple[tuple[float, ...], tuple[float, ...]] | None:
    """Axis-aligned bounds (low, high) of a primitive shape in the link frame, or None."""
    geometry = shape.geometry
    kind = geometry.kind
    rotation = rpy_matrix(shape.origin.rpy)
    if kind == "box" and geometry.size is not None:
        half = [abs(s) / 2 for s in geometry.size]
        extent = [sum(abs(rotation[i][k]) * half[k] for k in range(3)) for i in range(3)]
    elif kind == "sphere" and geometry.radius is not None:
        extent = [abs(geometry.radius)] * 3
    elif kind in ("cylinder", "capsule") and geometry.radius is not None \
            and geometry.length is not None:
        radius, half_length = abs(geometry.radius), abs(geometry.length) / 2
        extent = []
        for i in range(3):
            along = abs(rotation[i][2])  # the shape's z axis, seen along link axis i
            across = math.sqrt(max(0.0, 1.0 - along * along))
            if kind == "cylinder":
                extent.append(radius * across + half_length * along)
            else:
                extent.append(radius + half_length * along)
    else:
        return None
    if not all(math.isfinite(e) for e in extent) or not all(math.isfinite(c)
                                                              for c in shape.origin.xyz):
        return None
    centre = shape.origin.xyz
    return (tuple(centre[i] - extent[i] for i in range(3)),
            tuple(centre[i] + extent[i] for i in range(3)))


def _union(boxes):
    low = tuple(min(b[0][i] for b in boxes) for i in range(3))
    high = tuple(max(b[1][i] for b in boxes) for i in range(3))
    return low, high


def _size(box) -> float:
    """The largest extent of a bounding box."""
    return max(box[1][i] - box[0][i] for i in range(3))


def _centre(box) -> tuple[float, ...]:
    return tuple((box[0][i] + box[1][i]) / 2 for i in range(3))


def _gap(a, b) -> float:
    """Distance between two boxes (0 when they touch or overlap)."""
    return math.sqrt(sum(max(0.0, a[0][i] - b[1][i], b[0][i] - a[1][i]) ** 2 for i in range(3)))


def _describe(geometry) -> str:
    if geometry.kind == "box" and geometry.size is not None:
        return "box " + " x ".join(f"{s:g}" for s in geometry.size)
    if geometry.kind in ("cylinder", "capsule"):
        return f"{geometry.kind} r={geometry.radius:g} l={geometry.length:g}"
    if geometry.kind == "sphere":
        return f"sphere r={geometry.radius:g}"
    return geometry.kind or "shape"


# -- rules --------------------------------------------------------------------------------------

_ROBOT = '<robot name="r">\n  <link name="base"/>\n{}\n</robot>'
_JOINT = ('  <joint name="j" type="continuous">\n    <parent link="base"/>\n'
          '    <child link="wheel"/>\n    <axis xyz="0 1 0"/>\n  </joint>')
_INERTIAL = ('    <inertial>\n      <mass value="1"/>\n'
             '      <inertia ixx="0.003" ixy="0" ixz="0" iyy="0.005" iyz="0" izz="0.003"/>\n'
             '    </inertial>\n')


def _wheel(visual: str, collision: str | None) -> str:
    body = (f'  <link name="wheel">\n{_INERTIAL}    <visual>\n'
            f'      <geometry>{visual}</geometry>\n    </visual>\n')
    if collision is not None:
        body += f'    <collision>\n      <geometry>{collision}</geometry>\n    </collision>\n'
    return _ROBOT.format(body + '  </link>\n' + _JOINT)


def _size_edits(robot, link, shape):
    """(edits, note) making the shape's dimensions positive: a non-positive one taken from the
    link's one shape of the same kind in the other role, a negative one without it made
    positive; ((), "") when a zero has no such twin."""
    from urdftool.edits import number

    geometry = shape.geometry
    twins = [s.geometry for s in link.shapes
             if s.role != shape.role and s.geometry.kind == geometry.kind]
    twin = twins[0] if len(twins) == 1 else None

    def mend(value, other):
        if value > 0:
            return value
        if other is not None and other > 0:
            return other
        return -value if value < 0 else None

    values = {}
    if geometry.kind == "box":
        other = twin.size if twin is not None and twin.size is not None else (None,) * 3
        size = [mend(v, o) for v, o in zip(geometry.size, other)]
        if None in size:
            return (), ""
        values["size"] = " ".join(number(v) for v in size)
    else:
        for name in ("radius",) if geometry.kind == "sphere" else ("radius", "length"):
            value = getattr(geometry, name)
            if value is not None and value <= 0:
                new = mend(value, getattr(twin, name) if twin is not None else None)
                if new is None:
                    return (), ""
                values[name] = number(new)
    return value_edits(robot, geometry.loc, (geometry.kind,), values) if values else ((), "")


@rule("geometry.nonpositive-size", "error", "a shape with a zero or negative size",
      doc="""
Box sizes, radii and lengths must be positive, and a mesh scale must not have a zero
component: a zero-size shape has no volume, so collision detection ignores it or divides by
zero, and newer urdfdom versions reject it ("Box size must be positive finite values"). A
negative mesh scale is allowed (it mirrors the mesh); a negative box size or radius is not.
A zero-size *visual* only draws nothing (a stand-in for "no visual"): a warning, remove it.

The fix (unsafe: it chooses a size) takes the missing dimension from the link's one shape of
the same kind in the other role (the visual of a collision, the collision of a visual), and
makes a negative dimension positive; a zero with no such twin is left to you.
""",
      bad=_ROBOT.format('  <link name="plate">\n    <visual>\n'
                        '      <geometry><box size="0.2 0.2 0.005"/></geometry>\n'
                        '    </visual>\n    <collision>\n'
                        '      <geometry><box size="0.2 0.2 0"/></geometry>\n'
                        '    </collision>\n  </link>\n  <joint name="j" type="fixed">'
                        '<parent link="base"/><child link="plate"/></joint>'),
      good=_ROBOT.format('  <link name="plate">\n    <visual>\n'
                         '      <geometry><box size="0.2 0.2 0.005"/></geometry>\n'
                         '    </visual>\n    <collision>\n'
                         '      <geometry><box size="0.2 0.2 0.005"/></geometry>\n'
                         '    </collision>\n  </link>\n  <joint name="j" type="fixed">'
                         '<parent link="base"/><child link="plate"/></joint>'),
      fix="unsafe")
def nonpositive_size(robot) -> Iterator[Finding]:
    for link in robot.links:
        for shape in link.shapes:
            geometry = shape.geometry
            where = f"link '{link.name}' {shape.role}"
            loc = geometry.loc or shape.loc
            values: list[tuple[str, float]] = []
            if geometry.kind == "box" and geometry.size is not None:
                values = [("size", s) for s in geometry.size]
            elif geometry.kind in ("cylinder", "capsule", "sphere"):
                names = ("radius",) if geometry.kind == "sphere" else ("radius", "length")
                values = [(n, getattr(geometry, n)) for n in names
                          if getattr(geometry, n) is not None]
            bad = [(n, v) for n, v in values if v <= 0]
            if bad:
                if geometry.kind == "box":
                    what = (f"box size {' '.join(f'{v:g}' for _, v in values)} has a side that"
                            " is")
                else:
                    what = ", ".join(f"{geometry.kind} {n} {v:g}" for n, v in bad) + " is"
                # A zero-size visual only draws nothing; anything else is wrong physics.
                harmless = shape.role == "visual" and all(v == 0 for _, v in bad)
                edits, note = _size_edits(robot, link, shape)
                yield Finding(f"{where}: {what} not positive"
                              + (" (it draws nothing: remove the visual instead)"
                                 if harmless else ""), loc,
                              hint="every size must be positive" + note, severity="warning"
                              if harmless else None, edits=edits)
            elif geometry.kind == "mesh" and any(s == 0 for s in geometry.scale):
                scale = " ".join(f"{s:g}" for s in geometry.scale)
                yield Finding(f"{where}: mesh scale {scale} has a zero component: the mesh is "
                              "flattened to nothing", loc,
                              hint='use scale="1 1 1" (or the unit factor, e.g. 0.001 for mm)')


# The thresholds are deliberately coarse: collision shapes are often simplified, padded or
# shrunk on purpose. Only a mismatch no design intends is reported.
SIZE_RATIO = 5.0  # collision's largest extent vs the visual's, either way
GAP_RATIO = 1.0  # gap between the two bounding boxes vs the larger shape
PLACEHOLDER = 0.005  # m: shapes this small are stand-ins ("no visual", "no collision")


@rule("geometry.visual-collision-mismatch", "warning",
      "a link's collision shape grossly differs from its visual (size or place)",
      doc="""
The collision is what the simulator and planners use; the visual is what people see. Collision
shapes are often simplified, but a collision box ten times the visual, or a collision sphere
placed far from the visual, is almost always a typo (a missing decimal point, radius and
diameter swapped, an origin copied from another link). Compared are the bounding boxes of the
primitive visuals and collisions of each link (meshes are the `mesh` family's business): the
largest extents may differ by up to 5x, and the boxes may not be apart by more than the larger
shape's size. Shapes under 5 mm are taken as placeholders and not compared.

The fix (unsafe: it trusts the visual) gives a link's one collision the dimensions of its one
visual of the same kind, or, the shapes being the same, the visual's `<origin>`.
""",
      bad=_wheel('<cylinder radius="0.05" length="0.02"/>',
                 '<cylinder radius="0.5" length="0.02"/>'),
      good=_wheel('<cylinder radius="0.05" length="0.02"/>',
                  '<cylinder radius="0.05" length="0.02"/>'),
      fix="unsafe")
def visual_collision_mismatch(robot) -> Iterator[Finding]:
    for link in robot.links:
        if not link.visuals or not link.collisions:
            continue
        visual_boxes = [_bounds(s) for s in link.visuals]
        collision_boxes = [_bounds(s) for s in link.collisions]
        if None in visual_boxes or None in collision_boxes:
            continue  # a mesh, or a size that does not parse
        if any(abs(v) > HUGE for box in visual_boxes + collision_boxes for corner in box
               for v in corner):
            continue  # not a physical size (e.g. an origin at -1e308): nothing to compare
        visual, collision = _union(visual_boxes), _union(collision_boxes)
        seen, solid = _size(visual), _size(collision)
        if min(seen, solid) < PLACEHOLDER:
            continue  # a millimetre sphere standing in for "no visual" / "no collision"
        first = link.collisions[0]
        label = (_describe(first.geometry) if len(link.collisions) == 1 else
                 f"{len(link.collisions)} collision shapes")
        shown = (_describe(link.visuals[0].geometry) if len(link.visuals) == 1 else
                 f"{len(link.visuals)} visual shapes")
        ratio = solid / seen
        if ratio > SIZE_RATIO or ratio < 1 / SIZE_RATIO:
            bigger = "larger" if ratio > 1 else "smaller"
            factor = ratio if ratio > 1 else 1 / ratio
            edits, note = _follow_visual(robot, link, "size")
            yield Finding(f"link '{link.name}': the collision ({label}, {solid:g} across) is "
                          f"{factor:.3g}x {bigger} than the visual ({shown}, {seen:g} across)",
                          first.geometry.loc or first.loc,
                          hint="make the collision match what the visual shows" + note,
                          edits=edits)
            continue
        gap = _gap(visual, collision)
        if gap > GAP_RATIO * max(seen, solid):
            a, b = _centre(visual), _centre(collision)
            offset = " ".join(f"{b[i] - a[i]:g}" for i in range(3))
            edits, note = _follow_visual(robot, link, "place")
            yield Finding(f"link '{link.name}': the collision ({label}) is {gap:g} away from the "
                          f"visual ({shown}); centres differ by ({offset})", first.loc,
                          hint="check the collision's <origin>: it should overlap the visual"
                               + note, edits=edits)


def _follow_visual(robot, link, what: str):
    """(edits, note) of the unsafe fix: a link's one collision made like its one visual of the
    same kind, in ``what`` it differs ("size": the dimensions; "place": the <origin>, when the
    shapes are the same and the collision has one). ((), "") otherwise."""
    from urdftool.edits import number

    if len(link.visuals) != 1 or len(link.collisions) != 1:
        return (), ""
    visual, collision = link.visuals[0], link.collisions[0]
    kind = visual.geometry.kind
    if kind != collision.geometry.kind or kind not in ("box", "cylinder", "sphere", "capsule"):
        return (), ""
    dimensions = ("size",) if kind == "box" else ("radius",) if kind == "sphere" \
        else ("radius", "length")
    if what == "size":
        values = {}
        for name in dimensions:
            value = getattr(visual.geometry, name)
            if value is None:
                return (), ""
            values[name] = " ".join(map(number, value)) if name == "size" else number(value)
        return value_edits(robot, collision.geometry.loc, (kind,), values)
    if any(getattr(visual.geometry, n) != getattr(collision.geometry, n) for n in dimensions):
        return (), ""
    origin = child_loc(robot, collision.loc, "origin")
    if origin is None:
        return (), ""
    return value_edits(robot, origin, ("origin",),
                       {"xyz": " ".join(map(number, visual.origin.xyz)),
                        "rpy": " ".join(map(number, visual.origin.rpy))})


def _no_collision_anywhere(robot) -> bool:
    """Not one <collision> in a robot that is a body (something drawn or with mass, not a tree
    of bare frames) and would fall (a link with mass, or without <inertial>: PyBullet gives it
    1 kg); a massless visual marker stays where it is."""
    if not robot.links or any(link.collisions for link in robot.links):
        return False

    def massive(link):
        return link.inertial is not None and link.inertial.mass is not None \
            and link.inertial.mass > 0

    physical = any(link.visuals or massive(link) for link in robot.links)
    return physical and any(massive(link) or link.inertial is None for link in robot.links)


@rule("geometry.no-collision", "warning", "no link of the robot has a <collision>",
      doc="""
Without any `<collision>` the robot touches nothing in simulation: dropped into PyBullet or
Gazebo it falls through the floor (`urdftool sim` reports it sinking), and motion planners
(MoveIt) see no obstacle and no self-collision. Reported once for the robot when something in
it has mass (or no `<inertial>`, which PyBullet makes 1 kg); a massless visual marker stays
where it is put and is not reported. A description meant only for display (rviz, TF) can
ignore the rule; anything simulated needs collisions, often the visual's geometry or simpler
shapes around it.
""",
      bad='<robot name="r">\n  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" '
          'ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>\n    <visual><geometry>'
          '<box size="0.3 0.3 0.3"/></geometry></visual></link>\n</robot>',
      good='<robot name="r">\n  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" '
           'ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>\n    <visual><geometry>'
           '<box size="0.3 0.3 0.3"/></geometry></visual>\n    <collision><geometry>'
           '<box size="0.3 0.3 0.3"/></geometry></collision></link>\n</robot>')
def no_collision(robot) -> Iterator[Finding]:
    if not _no_collision_anywhere(robot):
        return
    drawn = sum(bool(link.visuals) for link in robot.links)
    loc = robot.loc(robot.root) if robot.root is not None else None
    yield Finding(f"robot '{robot.name}' has no <collision> on any of its {len(robot.links)} "
                  f"links ({drawn} drawn): in simulation it falls through the floor and touches "
                  "nothing, and planners see no obstacle", loc,
                  hint="add a <collision> to each link (the visual's geometry, or a simpler "
                       "shape around it)")


@rule("geometry.missing-collision", "info",
      "a moving link that has a visual and mass but no collision",
      doc="""
A link that moves, is drawn and has mass, but has no `<collision>`, passes through the floor
and through other links in simulation and is invisible to motion planners. Often intended
(decorative covers, a link whose collision sits on a rigidly attached sibling), hence only
advice. A collision on any link fixed to it counts.
""",
      bad=_wheel('<cylinder radius="0.05" length="0.02"/>', None),
      good=_wheel('<cylinder radius="0.05" length="0.02"/>',
                  '<cylinder radius="0.05" length="0.02"/>'))
def missing_collision(robot) -> Iterator[Finding]:
    fixed_children: dict[str, list[str]] = {}
    fixed_parent: dict[str, str] = {}
    for joint in robot.joints:
        if joint.type == "fixed" and joint.parent is not None and joint.child is not None:
            fixed_children.setdefault(joint.parent, []).append(joint.child)
            fixed_parent.setdefault(joint.child, joint.parent)

    def rigid_group(name: str) -> set[str]:
        """The link and every link welded to it through fixed joints (up and down)."""
        top, seen = name, {name}
        while top in fixed_parent and fixed_parent[top] not in seen:
            top = fixed_parent[top]
            seen.add(top)
        group, todo = {top}, [top]
        while todo:
            for child in fixed_children.get(todo.pop(), []):
                if child not in group:
                    group.add(child)
                    todo.append(child)
        return group

    for joint in robot.joints:
        if not joint.moving:
            continue
        link = robot.link(joint.child)
        if link is None or not link.visuals or link.collisions:
            continue
        mass = link.inertial.mass if link.inertial is not None else None
        if mass is None or not mass > 0:
            continue
        group = rigid_group(link.name)
        if any(robot.link(n) is not None and robot.link(n).collisions for n in group):
            continue
        yield Finding(f"link '{link.name}' moves (joint '{joint.name}', {joint.type}), has a "
                      f"visual and {mass:g} kg but no <collision>: it passes through everything "
                      "in simulation", link.loc,
                      hint="add a <collision> (the visual's geometry, or a simpler shape)")
