"""Rules of the `gazebo` family: `<gazebo>` extension blocks — references to links and joints,
plugin parameters naming joints and links, drive-plugin geometry, and Gazebo material names.

Plugins are recognised by their parameters, not by a list of plugin files: a `<leftJoint>` or a
`<joint_name>` names a joint in every Gazebo classic, gazebo_ros (ROS 1 and 2) and Gazebo Sim
plugin that has one. Unclosed tags and stray text inside the blocks are `xml` findings.
"""

from __future__ import annotations

import math

from urdftool.findings import Finding
from urdftool.model import Robot
from urdftool.rules import Names, lost, rename_edits, rule

# plugin parameters whose text names joints (comma-separated lists allowed, e.g. jointName)
JOINT_PARAMS = frozenset({
    # gazebo_ros diff drive / skid steer / tricycle (ROS 1)
    "leftJoint", "rightJoint", "leftFrontJoint", "rightFrontJoint", "leftRearJoint",
    "rightRearJoint", "steeringJoint", "actuatedWheelJoint", "encoderWheelLeftJoint",
    "encoderWheelRightJoint",
    # gazebo_ros (ROS 2) and Gazebo Sim systems
    "left_joint", "right_joint", "front_left_joint", "front_right_joint", "rear_left_joint",
    "rear_right_joint", "left_steering_joint", "right_steering_joint", "steering_wheel_joint",
    "steering_joint", "actuated_wheel_joint", "encoder_wheel_left_joint",
    "encoder_wheel_right_joint",
    # joint state publishers, joint controllers, mimic plugins
    "jointName", "joint_name", "mimicJoint", "mimic_joint",
})
# plugin parameters whose text names a link the plugin looks up in the model (GetLink). Frame
# parameters (`robotBaseFrame`, `frameName`, `odometryFrame`, `*_frame`, `frame_id`...) are not
# among them: they name TF frames the plugin publishes or stamps (a leading "/" is the old tf
# style), which need not be links at all (`odom`, `world`, `map`)
LINK_PARAMS = frozenset({"bodyName", "body_name", "link_name", "linkName"})


def _text(element) -> str:
    return (element.text or "").strip()


def _local(tag) -> str | None:
    if not isinstance(tag, str):
        return None
    return tag.rsplit("}", 1)[-1]


def plugins(robot: Robot):
    """Every <plugin> element inside the robot's <gazebo> blocks."""
    for block in robot.elements("gazebo"):
        for node in block.iter():
            if _local(node.tag) == "plugin":
                yield node


def plugin_references(robot: Robot) -> list[tuple[str, str, object]]:
    """(kind, name, element) for every plugin parameter naming a joint ("joint") or link."""
    found = []
    for plugin in plugins(robot):
        for node in plugin.iter():
            tag = _local(node.tag)
            if tag in JOINT_PARAMS:
                for name in _text(node).split(","):
                    if name.strip():
                        found.append(("joint", name.strip(), node))
            elif tag in LINK_PARAMS and _text(node):
                found.append(("link", _text(node), node))
    return found


def _named(robot: Robot, name: str) -> str:
    """The URDF name of what a plugin parameter names: in an SDF model, ``a::b`` (a link or
    joint of the nested model ``a``) is the converted robot's ``a__b``."""
    return name.replace("::", "__") if robot.source.kind == "sdf" else name


_BASE = ('<robot name="r">\n  <link name="base"/><link name="wheel"/>\n'
         '  <joint name="wheel_joint" type="continuous"><parent link="base"/>'
         '<child link="wheel"/>\n    <axis xyz="0 1 0"/><limit effort="1" velocity="1"/>'
         '</joint>\n')


@rule("gazebo.unknown-reference", "warning", "<gazebo reference> names no link or joint",
      doc="""`<gazebo reference="X">` applies its settings (material, friction, sensors) to the
      link or joint X. When X is neither, Gazebo drops the block silently: the wheel keeps the
      default friction, the sensor is never created.""",
      bad=_BASE + '  <gazebo reference="whel"><mu1>1.0</mu1></gazebo>\n</robot>',
      good=_BASE + '  <gazebo reference="wheel"><mu1>1.0</mu1></gazebo>\n</robot>',
      fix="safe")
def unknown_reference(robot: Robot):
    names = Names([*(link.name for link in robot.links), *(joint.name for joint in robot.joints)])
    for block in robot.elements("gazebo"):
        reference = block.get("reference")
        if reference is None:
            continue
        if robot.link(reference) is not None or robot.joint(reference) is not None \
                or lost(robot, reference):
            continue
        edits, close, note = rename_edits(robot, robot.loc(block), "gazebo", "reference",
                                          reference, names)
        close = close or names.close(reference)
        yield Finding(f"<gazebo reference=\"{reference}\"> names no link or joint; Gazebo ignores "
                      "the block", robot.loc(block),
                      hint=(f"did you mean '{close}'?" if close else
                            "name a link (or a joint) of the robot") + note, edits=edits)


@rule("gazebo.plugin-unknown-joint", "error", "a Gazebo plugin parameter names a missing joint",
      doc="""Drive, joint-state and controller plugins look their joints up by name when they
      load (`<leftJoint>`, `<rightJoint>`, `<jointName>`, `<joint_name>`, ...). A name that is not
      a joint makes the plugin fail to load: the robot does not drive, joint states are missing.""",
      bad=_BASE + '  <gazebo><plugin name="jsp" filename="libgazebo_ros_joint_state_publisher.so">'
                  '\n    <jointName>wheel</jointName></plugin></gazebo>\n</robot>',
      good=_BASE + '  <gazebo><plugin name="jsp" filename="libgazebo_ros_joint_state_publisher.so">'
                   '\n    <jointName>wheel_joint</jointName></plugin></gazebo>\n</robot>')
def plugin_unknown_joint(robot: Robot):
    joints = Names(joint.name for joint in robot.joints)
    for kind, name, node in plugin_references(robot):
        if kind != "joint" or robot.joint(_named(robot, name)) is not None or lost(robot, name):
            continue
        tag = _local(node.tag)
        if robot.link(name) is not None:
            parent = robot.parent_joint(name)
            yield Finding(f"<{tag}> names '{name}', a link, not a joint", robot.loc(node),
                          hint=f"the joint that moves link '{name}' is '{parent.name}'"
                          if parent is not None and parent.name else "name a joint")
        else:
            close = joints.close(name)
            yield Finding(f"<{tag}> names '{name}', which is not a joint of the robot",
                          robot.loc(node),
                          hint=f"did you mean '{close}'?" if close else "name a joint")


@rule("gazebo.plugin-unknown-link", "error", "a Gazebo plugin parameter names a missing link",
      doc="""Plugins attach to links by name (`<bodyName>`, `<body_name>`, `<link_name>`,
      `<linkName>`): the plugin looks the link up in the model when it loads, and a name that
      is no link makes it fail to load. Frame parameters (`<robotBaseFrame>`, `<frameName>`,
      `<odometryFrame>`, `<frame_id>`, `*_frame`...) are not checked: they name TF frames the
      plugin publishes or stamps messages with (`odom`, `world`, `/base_link` in the old tf
      style), not links it looks up.""",
      bad=_BASE + '  <gazebo><plugin name="p3d" filename="libgazebo_ros_p3d.so">\n'
                  '    <bodyName>base_link</bodyName></plugin></gazebo>\n</robot>',
      good=_BASE + '  <gazebo><plugin name="p3d" filename="libgazebo_ros_p3d.so">\n'
                   '    <bodyName>base</bodyName></plugin></gazebo>\n</robot>')
def plugin_unknown_link(robot: Robot):
    links = Names(link.name for link in robot.links)
    for kind, name, node in plugin_references(robot):
        if kind != "link" or robot.link(_named(robot, name)) is not None or lost(robot, name):
            continue
        tag = _local(node.tag)
        joint = robot.joint(name)
        if joint is not None:
            yield Finding(f"<{tag}> names '{name}', a joint, not a link", robot.loc(node),
                          hint=f"its child link is '{joint.child}'" if joint.child else
                          "name a link")
        else:
            close = links.close(name)
            yield Finding(f"<{tag}> names '{name}', which is not a link of the robot",
                          robot.loc(node),
                          hint=f"did you mean '{close}'?" if close else "name a link")


_MATERIALS: frozenset[str] | None = None


def gazebo_materials() -> frozenset[str]:
    """The standard Gazebo classic material names (urdftool/data/gazebo_materials.txt)."""
    global _MATERIALS
    if _MATERIALS is None:
        from pathlib import Path  # not importlib.resources: it costs ~4 ms of start-up

        text = (Path(__file__).parent.parent / "data" / "gazebo_materials.txt").read_text(
            encoding="utf-8")
        _MATERIALS = frozenset(line.strip() for line in text.splitlines()
                               if line.strip() and not line.startswith("#"))
    return _MATERIALS


@rule("gazebo.unknown-material", "warning", "a Gazebo/... material name that does not exist",
      doc="""`<material>Gazebo/Orange</material>` in a `<gazebo>` block picks a material from
      Gazebo's standard script. Names are case-sensitive; a misspelled one (`Gazebo/Grey` is
      right, `Gazebo/Gray` is not) leaves the link untextured in Gazebo, silently. Materials from
      your own scripts (not starting with `Gazebo/`) are not checked.""",
      bad=_BASE + '  <gazebo reference="base"><material>Gazebo/Gray</material></gazebo>\n'
                  '</robot>',
      good=_BASE + '  <gazebo reference="base"><material>Gazebo/Grey</material></gazebo>\n'
                   '</robot>')
def unknown_material(robot: Robot):
    known = gazebo_materials()
    lowered = {name.lower(): name for name in known}
    suffixes = {known_name[len("Gazebo/"):]: known_name for known_name in known}
    names = Names(sorted(suffixes))
    for block in robot.elements("gazebo"):
        for node in block.iter():
            if _local(node.tag) != "material" or not _text(node):
                continue
            name = _text(node)
            if not name.startswith("Gazebo/") or name in known:
                continue
            close = lowered.get(name.lower())
            if close is None:
                match = names.close(name[len("Gazebo/"):])
                close = suffixes[match] if match else None
            if close:
                yield Finding(f"Gazebo material '{name}' does not exist; did you mean '{close}'?",
                              robot.loc(node), hint=f"<material>{close}</material>")
            else:
                yield Finding(f"'{name}' is not a standard Gazebo material", robot.loc(node),
                              hint="use a standard one (Gazebo/Grey, Gazebo/Blue, ...) or define "
                                   "it in your own material script", severity="info")


# -- drive plugins: wheel separation, wheel size, left/right ---------------------------------

Matrix = tuple[tuple[float, float, float], ...]
Vector = tuple[float, float, float]


def _rotation(rpy: Vector) -> Matrix:
    """URDF fixed-axis roll-pitch-yaw: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    cr, sr = math.cos(rpy[0]), math.sin(rpy[0])
    cp, sp = math.cos(rpy[1]), math.sin(rpy[1])
    cy, sy = math.cos(rpy[2]), math.sin(rpy[2])
    return ((cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr),
            (sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr),
            (-sp, cp * sr, cp * cr))


def _mul(a: Matrix, b: Matrix) -> Matrix:
    return tuple(tuple(sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3))
                 for i in range(3))  # type: ignore[return-value]


def _apply(a: Matrix, v: Vector) -> Vector:
    return tuple(sum(a[i][k] * v[k] for k in range(3)) for i in range(3))  # type: ignore


def _transpose(a: Matrix) -> Matrix:
    return tuple(tuple(a[j][i] for j in range(3)) for i in range(3))  # type: ignore


_IDENTITY: Matrix = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def link_pose(robot: Robot, link: str) -> tuple[Matrix, Vector] | None:
    """The pose of a link's frame in its tree's root frame at the zero configuration."""
    rotation, position = _IDENTITY, (0.0, 0.0, 0.0)
    seen = set()
    current = link
    while True:
        joint = robot.parent_joint(current)
        if joint is None:
            return rotation, position
        if current in seen or joint.parent is None:
            return None
        seen.add(current)
        r = _rotation(joint.origin.rpy)
        # T_parent_current * T_current_link
        position = tuple(p + q for p, q in zip(_apply(r, position), joint.origin.xyz))
        rotation = _mul(r, rotation)
        current = joint.parent


def _in_frame(robot: Robot, base: str, link: str) -> tuple[Matrix, Vector] | None:
    """The pose of ``link`` in ``base``'s frame (both in one tree)."""
    base_pose, link_pose_ = link_pose(robot, base), link_pose(robot, link)
    if base_pose is None or link_pose_ is None:
        return None
    rb_t = _transpose(base_pose[0])
    delta = tuple(a - b for a, b in zip(link_pose_[1], base_pose[1]))
    return _mul(rb_t, link_pose_[0]), _apply(rb_t, delta)  # type: ignore[arg-type]


def _wheel_radius(robot: Robot, joint_name: str) -> float | None:
    joint = robot.joint(joint_name)
    link = robot.link(joint.child) if joint is not None else None
    if link is None:
        return None
    for shape in link.collisions + link.visuals:
        if shape.geometry.kind in ("cylinder", "sphere") and shape.geometry.radius:
            return shape.geometry.radius
    return None


def _values(plugin, *tags: str) -> list[tuple[str, object]]:
    return [(_text(n), n) for n in plugin.iter() if _local(n.tag) in tags and _text(n)]


def _float(text: str) -> float | None:
    try:
        value = float(text)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def _drive_pairs(plugin):
    """(left joint, right joint, separation (text, element) or None, size (kind, value, element)
    or None) for each wheel pair of a diff-drive or skid-steer plugin."""
    lefts = _values(plugin, "leftJoint", "left_joint", "leftFrontJoint", "leftRearJoint")
    rights = _values(plugin, "rightJoint", "right_joint", "rightFrontJoint", "rightRearJoint")
    separations = _values(plugin, "wheelSeparation", "wheel_separation")
    diameters = _values(plugin, "wheelDiameter", "wheel_diameter")
    radii = _values(plugin, "wheel_radius")
    for index, (left, right) in enumerate(zip(lefts, rights)):
        separation = separations[min(index, len(separations) - 1)] if separations else None
        size = None
        if diameters:
            text, node = diameters[min(index, len(diameters) - 1)]
            size = ("diameter", _float(text), node)
        elif radii:
            text, node = radii[min(index, len(radii) - 1)]
            size = ("radius", _float(text), node)
        yield left, right, separation, size


@rule("gazebo.drive-geometry", "warning",
      "a drive plugin's wheel separation, wheel size or sides disagree with the model",
      doc="""A diff-drive or skid-steer plugin turns `cmd_vel` into wheel speeds using its own
      `wheelSeparation` and `wheelDiameter` (or `wheel_separation`, `wheel_radius`), and
      computes odometry from them. When they disagree with the distance between the wheel
      joints and the wheels' radius, the robot turns at the wrong rate and odometry drifts. A
      left joint on the robot's right side (negative y in the base frame, x forward) makes the
      robot turn the wrong way. The separation is measured along the wheels' common axis, so
      the axes are compared first: wheels whose axes are more than 5 degrees apart (omni
      wheels 120 degrees apart, steered wheels) are no axle, and the one finding says that the
      plugin assumes coaxial wheels instead of comparing a separation that has no meaning. The
      fix (unsafe: it trusts the joints) writes the measured separation and wheel size into
      the plugin, and swaps its left and right joints.""",
      bad='<robot name="r">\n  <link name="base"/><link name="l"/><link name="rw"/>\n'
          '  <joint name="left" type="continuous"><parent link="base"/><child link="l"/>\n'
          '    <origin xyz="0 0.15 0"/><axis xyz="0 1 0"/></joint>\n'
          '  <joint name="right" type="continuous"><parent link="base"/><child link="rw"/>\n'
          '    <origin xyz="0 -0.15 0"/><axis xyz="0 1 0"/></joint>\n'
          '  <gazebo><plugin name="dd" filename="libgazebo_ros_diff_drive.so">\n'
          '    <leftJoint>left</leftJoint><rightJoint>right</rightJoint>\n'
          '    <wheelSeparation>0.2</wheelSeparation><robotBaseFrame>base</robotBaseFrame>\n'
          '  </plugin></gazebo>\n</robot>',
      good='<robot name="r">\n  <link name="base"/><link name="l"/><link name="rw"/>\n'
           '  <joint name="left" type="continuous"><parent link="base"/><child link="l"/>\n'
           '    <origin xyz="0 0.15 0"/><axis xyz="0 1 0"/></joint>\n'
           '  <joint name="right" type="continuous"><parent link="base"/><child link="rw"/>\n'
           '    <origin xyz="0 -0.15 0"/><axis xyz="0 1 0"/></joint>\n'
           '  <gazebo><plugin name="dd" filename="libgazebo_ros_diff_drive.so">\n'
           '    <leftJoint>left</leftJoint><rightJoint>right</rightJoint>\n'
           '    <wheelSeparation>0.3</wheelSeparation><robotBaseFrame>base</robotBaseFrame>\n'
           '  </plugin></gazebo>\n</robot>',
      fix="unsafe")
def drive_geometry(robot: Robot):
    for plugin in plugins(robot):
        base_names = [t.lstrip("/") for t, _ in _values(plugin, "robotBaseFrame",
                                                         "robot_base_frame")]
        for (left, left_node), (right, right_node), separation, size in _drive_pairs(plugin):
            left_joint, right_joint = robot.joint(left), robot.joint(right)
            if left_joint is None or right_joint is None or not left_joint.child \
                    or not right_joint.child:
                continue  # gazebo.plugin-unknown-joint reports these
            base = base_names[0] if base_names and robot.link(base_names[0]) else \
                left_joint.parent
            if base is None:
                continue
            left_pose = _in_frame(robot, base, left_joint.child)
            right_pose = _in_frame(robot, base, right_joint.child)
            if left_pose is None or right_pose is None:
                continue
            yield from _check_pair(robot, base, left_joint, right_joint, left_node,
                                   right_node, left_pose, right_pose, separation, size)


# wheel axes further apart than this (either sense) are not one axle: a diff drive turns them
# as if they were, and its separation has no meaning
AXLE_TOLERANCE = math.radians(5.0)


def _angle_between_axes(a: Vector, b: Vector) -> float | None:
    """The angle between two lines (axes of either sense), radians in [0, pi/2]; None for a
    zero axis."""
    na, nb = math.sqrt(sum(x * x for x in a)), math.sqrt(sum(x * x for x in b))
    if na == 0 or nb == 0:
        return None
    cosine = abs(sum(x * y for x, y in zip(a, b))) / (na * nb)
    return math.acos(min(1.0, cosine))


def _check_pair(robot, base, left_joint, right_joint, left_node, right_node, left_pose,
                right_pose, separation, size):
    axis = _apply(left_pose[0], left_joint.axis_or_default)
    other = _apply(right_pose[0], right_joint.axis_or_default)
    angle = _angle_between_axes(axis, other)
    if angle is not None and angle > AXLE_TOLERANCE:
        # omni or steered wheels: nothing below is meaningful (no axle, no sides)
        between = math.degrees(math.acos(sum(x * y for x, y in zip(axis, other)) / (
            math.sqrt(sum(x * x for x in axis)) * math.sqrt(sum(x * x for x in other)))))
        yield Finding(f"the drive plugin turns wheel joints '{left_joint.name}' and "
                      f"'{right_joint.name}' as one axle, but their axes are {between:.3g} "
                      "degrees apart: a diff-drive plugin assumes coaxial wheels, so its "
                      "commanded turn rate and odometry do not match how these wheels move",
                      robot.loc(left_node),
                      hint="drive these wheels with a plugin for their layout (an omni or "
                           "planar-move plugin), or name the two coaxial wheel joints")
        return
    norm = math.sqrt(sum(a * a for a in axis))
    delta = tuple(a - b for a, b in zip(left_pose[1], right_pose[1]))
    if norm > 0:
        distance = abs(sum(d * a for d, a in zip(delta, axis))) / norm
    else:
        distance = math.sqrt(sum(d * d for d in delta))
    if separation is not None:
        text, node = separation
        value = _float(text)
        if value is not None and distance > 0 and abs(value - distance) > 0.05 * distance:
            tag = _local(node.tag)
            yield Finding(f"<{tag}> is {text} but the wheel joints '{left_joint.name}' and "
                          f"'{right_joint.name}' are {distance:.6g} m apart along the wheel "
                          "axis: the robot turns at the wrong rate and odometry drifts",
                          robot.loc(node), hint=f"<{tag}>{distance:.6g}</{tag}>",
                          edits=_text_edits(robot, (node, f"{distance:.9g}")))
    if size is not None and size[1] is not None:
        kind, value, node = size
        radius = _wheel_radius(robot, left_joint.name)
        expected = radius * 2 if kind == "diameter" and radius else radius
        if expected and abs(value - expected) > 0.05 * expected:
            tag = _local(node.tag)
            yield Finding(f"<{tag}> is {value:g} but wheel '{left_joint.child}' has radius "
                          f"{radius:g} ({kind} {expected:g}): speeds and odometry are scaled "
                          "wrong", robot.loc(node), hint=f"<{tag}>{expected:g}</{tag}>",
                          edits=_text_edits(robot, (node, f"{expected:.9g}")))
    lateral = left_pose[1][1] - right_pose[1][1]
    if lateral < -1e-6:
        plugin_line = robot.loc(left_node).line
        where = f" (line {plugin_line})" if plugin_line else ""
        yield Finding(f"the diff-drive's left wheel joint '{left_joint.name}'{where} is on the "
                      f"robot's right side (y = {left_pose[1][1]:.6g} m in '{base}', x forward) "
                      f"and its right wheel joint '{right_joint.name}' on the left "
                      f"(y = {right_pose[1][1]:.6g} m): the robot turns the wrong way",
                      _origin_loc(robot, left_joint),
                      hint="swap the two joints' <origin>s (or the plugin's left/right joints)",
                      edits=_text_edits(robot, (left_node, right_joint.name),
                                        (right_node, left_joint.name)))


def _text_edits(robot: Robot, *changes) -> tuple:
    """Edits writing each (plugin parameter element, new text): all, or none when one of them
    is computed in the file as written."""
    from urdftool.edits import text_edit

    edits = tuple(text_edit(robot.source.texts, robot.loc(node), (_local(node.tag),), new)
                  for node, new in changes)
    return () if None in edits else edits


def _origin_loc(robot: Robot, joint):
    """Where a joint's <origin> was written (the joint itself when it has none)."""
    elements = robot.elements("joint")
    if len(elements) != len(robot.joints):  # cannot happen with build_robot
        return joint.loc
    for candidate, element in zip(robot.joints, elements):
        if candidate is joint:
            origin = next((node for node in element if node.tag == "origin"), None)
            return robot.loc(origin) if origin is not None else joint.loc
    return joint.loc
