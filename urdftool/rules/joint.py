"""Rules of the `joint` family: limits (presence, ranges, effort, velocity), axes, safety
controllers, dynamics and calibration.

What the consumers do, which decides the severities here:

- urdfdom (ROS, check_urdf, MoveIt, Pinocchio) refuses a revolute or prismatic joint without
  ``<limit>``. Missing ``lower``/``upper`` default to 0, which freezes the joint. (An unknown
  joint type and a ``<limit>`` without ``effort``/``velocity`` are ``schema`` findings.)
- PyBullet reads a missing ``lower``/``upper`` as "no limit" (its defaults are 0 and -1, and
  Bullet treats lower > upper as unlimited), does not enforce ``effort``/``velocity`` from
  the file, and freezes a joint whose lower equals upper.
- Gazebo, ros2_control and MoveIt enforce effort and velocity limits: 0 means the joint cannot
  be driven, or a trajectory through it cannot be timed.

Values that do not parse are None in the model (the ``schema`` rules report them): every rule
here skips them.
"""

from __future__ import annotations

import math

from urdftool.edits import number
from urdftool.findings import Finding
from urdftool.model import Joint, Robot
from urdftool.rules import rule, value_edits

TWO_PI = 2.0 * math.pi
AXIS_TOLERANCE = 1e-4  # |norm - 1| above this is "not unit" (6-digit axes are fine)
DEGREES_MAX = 1080.0  # beyond 3 turns written in degrees, a bound is "effectively unlimited"
HUGE_BOUND = 1e6  # a bound this large means "no limit" (SDF converters write 1e16)
TURN_SLACK = 0.01  # rad: a range of 2π written as ±3.1416 is one turn, not more


def fmt(value: float) -> str:
    """A number in a message: 6 significant digits (hints meant to be pasted use more)."""
    return f"{value:.6g}"


def joint_elements(robot: Robot) -> list[tuple[Joint, object]]:
    """Each joint with its raw lxml element (same document order as ``robot.joints``)."""
    elements = robot.elements("joint")
    if len(elements) != len(robot.joints):  # cannot happen with build_robot; be safe
        return []
    return list(zip(robot.joints, elements))


def child(element, tag: str):
    for node in element:
        if isinstance(node.tag, str) and node.tag == tag:
            return node
    return None


def written(element, tag: str, attribute: str) -> bool:
    """Whether ``<tag attribute=...>`` is written (non-empty) under a joint element."""
    node = child(element, tag)
    return node is not None and (node.get(attribute) or "").strip() != ""


def label(joint: Joint) -> str:
    return f"joint '{joint.name}'" if joint.name else "joint without a name"


def actuated_joint_names(robot: Robot) -> set[str]:
    """Joints something in the file drives: transmissions, ros2_control, Gazebo plugins."""
    names: set[str] = set()
    for block in robot.elements("transmission"):
        for node in block.iter("joint"):
            if node.get("name"):
                names.add(node.get("name"))
    for block in robot.elements("ros2_control"):
        for node in block.iter("joint"):
            if node.get("name") and node.getparent() is block:
                names.add(node.get("name"))
    from urdftool.rules.gazebo import plugin_references

    names.update(name for kind, name, _node in plugin_references(robot) if kind == "joint")
    return names


def mimic_followers(robot: Robot) -> set[str]:
    return {j.name for j in robot.joints if j.mimic is not None and j.name}


# -- types and <limit> presence --------------------------------------------------------------


@rule("joint.missing-limit", "error", "a revolute or prismatic joint has no <limit>",
      doc="""urdfdom requires `<limit effort=".." velocity=".."/>` on revolute and prismatic
      joints and refuses the file without it ("Joint [j] is of type REVOLUTE but it does not
      specify limits"). Give lower and upper too: they default to 0, a joint that cannot move.""",
      bad='<robot name="r"><link name="a"/><link name="b"/>\n'
          '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/></joint>\n'
          '</robot>',
      good='<robot name="r"><link name="a"/><link name="b"/>\n'
           '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
           '    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n</robot>')
def missing_limit(robot: Robot):
    for joint in robot.joints:
        if joint.type in ("revolute", "prismatic") and joint.limit is None:
            hint = 'add <limit lower=".." upper=".." effort=".." velocity=".."/>'
            if joint.type == "revolute":
                hint += ' (radians); if it turns without end, make it type="continuous"'
            else:
                hint += " (metres)"
            yield Finding(f"{label(joint)}: {joint.type} joint without <limit>; urdfdom refuses "
                          "the file", joint.loc, hint=hint)


# -- ranges ----------------------------------------------------------------------------------


@rule("joint.lower-above-upper", "error", "a joint's lower limit is above its upper limit",
      doc="""The range is empty: urdfdom-based tools, MoveIt and Pinocchio cannot place the joint
      anywhere. (Bullet reads lower > upper as "no limit"; PyBullet-only files use that idiom,
      but every other consumer sees an empty range. For a joint without limits use type
      continuous, or wide explicit limits for a prismatic joint.)""",
      bad='<robot name="r"><link name="a"/><link name="b"/>\n'
          '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
          '    <limit lower="1" upper="-1" effort="1" velocity="1"/></joint>\n</robot>',
      good='<robot name="r"><link name="a"/><link name="b"/>\n'
           '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
           '    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n</robot>',
      fix="unsafe")
def lower_above_upper(robot: Robot):
    for joint in robot.joints:
        limit = joint.limit
        if joint.type not in ("revolute", "prismatic") or limit is None:
            continue
        if limit.lower is None or limit.upper is None or not limit.lower > limit.upper:
            continue
        edits, note = value_edits(robot, limit.loc, ("limit",),
                                  {"lower": number(limit.upper), "upper": number(limit.lower)})
        yield Finding(f"{label(joint)}: lower {fmt(limit.lower)} > upper {fmt(limit.upper)}: "
                      "the range is empty (only Bullet reads this as 'no limit')", limit.loc,
                      hint=f'swap them: lower="{fmt(limit.upper)}" upper="{fmt(limit.lower)}"'
                           + note, edits=edits)


@rule("joint.frozen-range", "warning", "a moving joint's lower and upper limits are equal",
      doc="""A revolute or prismatic joint whose range is a single value cannot move: MoveIt,
      Pinocchio, joint_state_publisher and PyBullet hold it there. Often lower/upper were simply
      left out — URDF defaults both to 0 (only PyBullet reads missing bounds as "no limit").
      If the joint should not move, make it fixed; if it turns without end, make it continuous.""",
      bad='<robot name="r"><link name="a"/><link name="b"/>\n'
          '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
          '    <limit effort="1" velocity="1"/></joint>\n</robot>',
      good='<robot name="r"><link name="a"/><link name="b"/>\n'
           '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
           '    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n</robot>')
def frozen_range(robot: Robot):
    for joint, element in joint_elements(robot):
        limit = joint.limit
        if joint.type not in ("revolute", "prismatic") or limit is None:
            continue
        if limit.lower is None or limit.upper is None or limit.lower != limit.upper:
            continue
        if not written(element, "limit", "lower") and not written(element, "limit", "upper"):
            hint = ('add lower=".." upper=".."' +
                    ("; if it turns without end, make it type=\"continuous\""
                     if joint.type == "revolute" else ""))
            yield Finding(f"{label(joint)}: <limit> has no lower/upper, so URDF reads the range "
                          "as [0, 0] and the joint cannot move (only PyBullet reads missing "
                          "bounds as 'no limit')", limit.loc, hint=hint)
        else:
            yield Finding(f"{label(joint)}: lower = upper = {fmt(limit.lower)}: the joint cannot "
                          "move", limit.loc,
                          hint='make it type="fixed", or give it a real range')


def _degrees_suspect(lower: float, upper: float) -> bool:
    biggest = max(abs(lower), abs(upper))
    return 2 * TWO_PI + TURN_SLACK < biggest <= DEGREES_MAX


@rule("joint.range-in-degrees", "warning", "revolute limits that look like degrees",
      doc="""URDF angles are radians. Bounds such as 90 or -170 on a revolute joint are almost
      certainly degrees: read as radians they allow dozens of turns, so planners and simulators
      never stop the joint where the hardware does.""",
      bad='<robot name="r"><link name="a"/><link name="b"/>\n'
          '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
          '    <limit lower="-170" upper="170" effort="1" velocity="1"/></joint>\n</robot>',
      good='<robot name="r"><link name="a"/><link name="b"/>\n'
           '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
           '    <limit lower="-2.96706" upper="2.96706" effort="1" velocity="1"/></joint>\n'
           '</robot>',
      fix="unsafe")
def range_in_degrees(robot: Robot):
    for joint in robot.joints:
        limit = joint.limit
        if joint.type != "revolute" or limit is None or limit.lower is None or limit.upper is None:
            continue
        if not _degrees_suspect(limit.lower, limit.upper) or limit.lower > limit.upper:
            continue
        lo, hi = math.radians(limit.lower), math.radians(limit.upper)
        turns = (limit.upper - limit.lower) / TWO_PI
        edits, note = value_edits(robot, limit.loc, ("limit",),
                                  {"lower": number(lo), "upper": number(hi)})
        yield Finding(f"{label(joint)}: limits [{fmt(limit.lower)}, {fmt(limit.upper)}] look "
                      f"like degrees; as radians they span {turns:.1f} turns", limit.loc,
                      hint=f'in radians: lower="{lo:.6g}" upper="{hi:.6g}" '
                           f'(or lower="${{radians({fmt(limit.lower)})}}" in xacro)' + note,
                      edits=edits)


@rule("joint.multi-turn-range", "info", "a revolute range wider than one turn",
      doc="""A revolute range wider than 2π is normal for multi-turn joints with hard stops
      (UR and xArm wrists use ±2π). A bound of 1e6 or more means "no limit": say so with type
      continuous, which every consumer understands.""",
      bad='<robot name="r"><link name="a"/><link name="b"/>\n'
          '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
          '    <limit lower="-1e16" upper="1e16" effort="1" velocity="1"/></joint>\n</robot>',
      good='<robot name="r"><link name="a"/><link name="b"/>\n'
           '  <joint name="j" type="continuous"><parent link="a"/><child link="b"/>\n'
           '    <limit effort="1" velocity="1"/></joint>\n</robot>')
def multi_turn_range(robot: Robot):
    for joint in robot.joints:
        limit = joint.limit
        if joint.type != "revolute" or limit is None or limit.lower is None or limit.upper is None:
            continue
        span = limit.upper - limit.lower
        if span <= TWO_PI + TURN_SLACK or _degrees_suspect(limit.lower, limit.upper):
            continue
        if max(abs(limit.lower), abs(limit.upper)) >= HUGE_BOUND:
            yield Finding(f"{label(joint)}: limits [{fmt(limit.lower)}, {fmt(limit.upper)}] mean "
                          "'no limit'", limit.loc,
                          hint='make it type="continuous" and drop lower/upper')
        elif max(abs(limit.lower), abs(limit.upper)) > DEGREES_MAX:
            yield Finding(f"{label(joint)}: limits [{fmt(limit.lower)}, {fmt(limit.upper)}] span "
                          f"{span / TWO_PI:.0f} turns", limit.loc,
                          hint='if the joint has no stop, make it type="continuous"')
        else:
            yield Finding(f"{label(joint)}: range {fmt(span)} rad ({math.degrees(span):.0f}°) "
                          "is more than one turn: fine for a multi-turn joint with stops",
                          limit.loc, hint='if the joint has no stop, make it type="continuous"')


@rule("joint.continuous-with-limits", "warning", "a continuous joint with lower/upper limits",
      doc="""Continuous joints have no position limits: urdfdom, MoveIt, Gazebo and PyBullet
      ignore lower and upper on them. A range narrower than a turn on a continuous joint usually
      means the joint was meant to be revolute (a steering hinge, a head pan).""",
      bad='<robot name="r"><link name="a"/><link name="b"/>\n'
          '  <joint name="j" type="continuous"><parent link="a"/><child link="b"/>\n'
          '    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n</robot>',
      good='<robot name="r"><link name="a"/><link name="b"/>\n'
           '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
           '    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n</robot>')
def continuous_with_limits(robot: Robot):
    for joint in robot.joints:
        limit = joint.limit
        if joint.type != "continuous" or limit is None or limit.lower is None \
                or limit.upper is None:
            continue
        # a full turn or more (e.g. ±2π) is harmless; lower >= upper is the "unlimited" idiom
        if not limit.lower < limit.upper or limit.upper - limit.lower >= TWO_PI - TURN_SLACK:
            continue
        yield Finding(f"{label(joint)}: continuous joint with limits [{fmt(limit.lower)}, "
                      f"{fmt(limit.upper)}], which every consumer ignores", limit.loc,
                      hint='if the joint must stop there, make it type="revolute"; '
                           "otherwise drop lower/upper")


# -- effort and velocity ---------------------------------------------------------------------


def _zero_limit(robot: Robot, attribute: str, quantity: str, consumers: str):
    actuated = None
    followers = mimic_followers(robot)
    for joint in robot.joints:
        limit = joint.limit
        if limit is None or joint.type not in ("revolute", "prismatic", "continuous"):
            continue
        value = getattr(limit, attribute)
        if value is None or value > 0 or not math.isfinite(value) or joint.name in followers:
            continue
        if actuated is None:
            actuated = actuated_joint_names(robot)
        if value < 0:
            yield Finding(f"{label(joint)}: {attribute} {fmt(value)} is negative; a {quantity} "
                          "limit is a magnitude (SDF reads -1 as 'no limit', ros2_control as a "
                          "negative bound)", limit.loc, hint=f"give the positive {quantity} limit")
        elif joint.name in actuated:
            yield Finding(f"{label(joint)}: {attribute}=0 on a driven joint: {consumers}",
                          limit.loc, hint=f"give the actuator's {quantity} limit")
        else:
            yield Finding(f"{label(joint)}: {attribute}=0: {consumers}; fine if the joint is "
                          "passive", limit.loc, hint=f"give the actuator's {quantity} limit",
                          severity="info")


@rule("joint.zero-effort", "warning", "a joint's effort limit is zero or negative",
      doc="""Gazebo and ros2_control clamp commanded forces to the effort limit: 0 means the
      joint cannot be driven (PyBullet ignores the value). On a joint that a transmission,
      ros2_control or a Gazebo plugin drives this is a warning; on a joint nothing drives (a
      passive joint, a mimic follower) it is harmless and reported as info at most.""",
      bad='<robot name="r"><link name="a"/><link name="b"/>\n'
          '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
          '    <limit lower="-1" upper="1" effort="0" velocity="1"/></joint>\n'
          '  <transmission name="t"><type>transmission_interface/SimpleTransmission</type>\n'
          '    <joint name="j"><hardwareInterface>hardware_interface/EffortJointInterface'
          '</hardwareInterface></joint>\n'
          '    <actuator name="m"><mechanicalReduction>1</mechanicalReduction></actuator>\n'
          '  </transmission>\n</robot>',
      good='<robot name="r"><link name="a"/><link name="b"/>\n'
           '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
           '    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>\n'
           '  <transmission name="t"><type>transmission_interface/SimpleTransmission</type>\n'
           '    <joint name="j"><hardwareInterface>hardware_interface/EffortJointInterface'
           '</hardwareInterface></joint>\n'
           '    <actuator name="m"><mechanicalReduction>1</mechanicalReduction></actuator>\n'
           '  </transmission>\n</robot>')
def zero_effort(robot: Robot):
    return _zero_limit(robot, "effort", "force/torque",
                       "Gazebo and ros2_control cannot drive it")


@rule("joint.zero-velocity", "warning", "a joint's velocity limit is zero or negative",
      doc="""MoveIt cannot time a trajectory through a joint whose velocity limit is 0, and
      Gazebo and ros2_control hold it still (PyBullet ignores the value). On a joint that a
      transmission, ros2_control or a Gazebo plugin drives this is a warning; on a joint nothing
      drives it is reported as info at most.""",
      bad='<robot name="r"><link name="a"/><link name="b"/>\n'
          '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
          '    <limit lower="-1" upper="1" effort="1" velocity="-1"/></joint>\n</robot>',
      good='<robot name="r"><link name="a"/><link name="b"/>\n'
           '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
           '    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n</robot>')
def zero_velocity(robot: Robot):
    return _zero_limit(robot, "velocity", "velocity",
                       "MoveIt cannot time trajectories through it, Gazebo and ros2_control "
                       "hold it still")


# -- axis ------------------------------------------------------------------------------------


def _norm(axis) -> float:
    return math.sqrt(sum(a * a for a in axis))


@rule("joint.zero-axis", "error", "a moving joint's axis is the zero vector",
      doc="""A joint turns or slides along its axis; `0 0 0` is no direction at all. KDL and
      Pinocchio normalise it into NaN, simulators reject or freeze the joint.""",
      bad='<robot name="r"><link name="a"/><link name="b"/>\n'
          '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
          '    <axis xyz="0 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n'
          '</robot>',
      good='<robot name="r"><link name="a"/><link name="b"/>\n'
           '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
           '    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n'
           '</robot>')
def zero_axis(robot: Robot):
    for joint, element in joint_elements(robot):
        if joint.axis is None or joint.type not in ("revolute", "continuous", "prismatic",
                                                    "planar"):
            continue
        if not all(math.isfinite(a) for a in joint.axis) or _norm(joint.axis) != 0.0:
            continue
        yield Finding(f"{label(joint)}: axis is 0 0 0", robot.loc(child(element, "axis")),
                      hint='give the direction, e.g. <axis xyz="0 0 1"/>')


@rule("joint.axis-not-unit", "warning", "a joint axis that is not unit length",
      doc="""URDF axes must be unit vectors. Consumers normalise silently, so the direction is
      kept — but a non-unit axis usually hides a typo (`0 1 1` for `0 0 1`) or a lost sign.""",
      bad='<robot name="r"><link name="a"/><link name="b"/>\n'
          '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
          '    <axis xyz="0 1 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n'
          '</robot>',
      good='<robot name="r"><link name="a"/><link name="b"/>\n'
           '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
           '    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n'
           '</robot>',
      fix="safe")
def axis_not_unit(robot: Robot):
    for joint, element in joint_elements(robot):
        if joint.axis is None or joint.type not in ("revolute", "continuous", "prismatic",
                                                    "planar"):
            continue
        if not all(math.isfinite(a) for a in joint.axis):
            continue
        norm = _norm(joint.axis)
        if norm == 0.0 or abs(norm - 1.0) <= AXIS_TOLERANCE:
            continue
        unit = " ".join(f"{a / norm:.6g}" for a in joint.axis)
        loc = robot.loc(child(element, "axis"))
        edits, note = value_edits(robot, loc, ("axis",),
                                  {"xyz": " ".join(number(a / norm) for a in joint.axis)})
        yield Finding(f"{label(joint)}: axis {' '.join(fmt(a) for a in joint.axis)} has length "
                      f"{norm:.6g}; consumers normalise it silently",
                      loc, hint=f'<axis xyz="{unit}"/>' + note, edits=edits)


@rule("joint.fixed-with-axis", "info", "an <axis> on a fixed joint",
      doc="""A fixed joint does not move, so its axis is ignored by every consumer. Exporters
      write one anyway; removing it makes the file say what it means.""",
      bad='<robot name="r"><link name="a"/><link name="b"/>\n'
          '  <joint name="j" type="fixed"><parent link="a"/><child link="b"/>\n'
          '    <axis xyz="0 0 1"/></joint>\n</robot>',
      good='<robot name="r"><link name="a"/><link name="b"/>\n'
           '  <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>\n'
           '</robot>')
def fixed_with_axis(robot: Robot):
    for joint, element in joint_elements(robot):
        if joint.type == "fixed" and joint.axis is not None:
            yield Finding(f"{label(joint)}: fixed joint with an <axis>, which is ignored",
                          robot.loc(child(element, "axis")), hint="remove the <axis>")


# -- safety controller, dynamics, calibration ------------------------------------------------


@rule("joint.safety-gains", "warning", "a <safety_controller> without k_velocity or k_position",
      doc="""urdfdom refuses a `<safety_controller>` without `k_velocity` (error). Without
      `k_position` (default 0) the ROS soft-limit safety controller bounds the joint's velocity
      to 0 everywhere: the joint is held still (warning; info when `k_position="0"` is written
      explicitly, which some robots use for joints meant to stay put).""",
      bad='<robot name="r"><link name="a"/><link name="b"/>\n'
          '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
          '    <limit lower="-1" upper="1" effort="1" velocity="1"/>\n'
          '    <safety_controller soft_lower_limit="-0.9" soft_upper_limit="0.9" '
          'k_velocity="10"/></joint>\n</robot>',
      good='<robot name="r"><link name="a"/><link name="b"/>\n'
           '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
           '    <limit lower="-1" upper="1" effort="1" velocity="1"/>\n'
           '    <safety_controller soft_lower_limit="-0.9" soft_upper_limit="0.9" '
           'k_position="100" k_velocity="10"/></joint>\n</robot>')
def safety_gains(robot: Robot):
    for joint, element in joint_elements(robot):
        safety = joint.safety
        if safety is None:
            continue
        node = child(element, "safety_controller")
        if node.get("k_velocity") is None:
            yield Finding(f"{label(joint)}: <safety_controller> without k_velocity; urdfdom "
                          "refuses the file", safety.loc, hint='add k_velocity=".."',
                          severity="error")
        if joint.type not in ("revolute", "prismatic"):
            continue
        if node.get("k_position") is None:
            yield Finding(f"{label(joint)}: <safety_controller> without k_position (default 0): "
                          "the soft limits bound the velocity to 0 and hold the joint still",
                          safety.loc, hint='add k_position=".." (e.g. 100)')
        elif safety.k_position == 0:
            yield Finding(f"{label(joint)}: <safety_controller> with k_position=\"0\" holds the "
                          "joint still; fine for a joint meant to stay put", safety.loc,
                          hint='a positive k_position (e.g. 100) lets it move within the soft '
                               "limits", severity="info")


@rule("joint.safety-limits", "warning", "soft limits outside the hard limits, or empty",
      doc="""The safety controller's soft limits must lie inside the joint's hard limits,
      lower below upper, to keep the joint off its stops. Soft limits outside the hard range do
      not protect anything; an empty soft range (missing soft limits default to 0) holds the
      joint at one position.""",
      bad='<robot name="r"><link name="a"/><link name="b"/>\n'
          '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
          '    <limit lower="-1" upper="1" effort="1" velocity="1"/>\n'
          '    <safety_controller soft_lower_limit="-1.5" soft_upper_limit="1.5" '
          'k_position="100" k_velocity="10"/></joint>\n</robot>',
      good='<robot name="r"><link name="a"/><link name="b"/>\n'
           '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
           '    <limit lower="-1" upper="1" effort="1" velocity="1"/>\n'
           '    <safety_controller soft_lower_limit="-0.9" soft_upper_limit="0.9" '
           'k_position="100" k_velocity="10"/></joint>\n</robot>')
def safety_limits(robot: Robot):
    for joint in robot.joints:
        safety, limit = joint.safety, joint.limit
        if safety is None or joint.type not in ("revolute", "prismatic") or limit is None:
            continue
        soft_lo, soft_hi = safety.soft_lower_limit, safety.soft_upper_limit
        if soft_lo is None or soft_hi is None:
            continue
        if soft_lo >= soft_hi:
            yield Finding(f"{label(joint)}: soft limits [{fmt(soft_lo)}, {fmt(soft_hi)}] are "
                          "empty: the safety controller holds the joint still", safety.loc,
                          hint="set soft_lower_limit < soft_upper_limit inside the hard limits")
            continue
        lo, hi = limit.lower, limit.upper
        if lo is None or hi is None or lo > hi:
            continue
        tolerance = 1e-9 * max(1.0, abs(lo), abs(hi))
        if soft_lo < lo - tolerance or soft_hi > hi + tolerance:
            yield Finding(f"{label(joint)}: soft limits [{fmt(soft_lo)}, {fmt(soft_hi)}] reach "
                          f"outside the hard limits [{fmt(lo)}, {fmt(hi)}]", safety.loc,
                          hint=f'soft_lower_limit="{fmt(max(soft_lo, lo))}" '
                               f'soft_upper_limit="{fmt(min(soft_hi, hi))}" or narrower')


@rule("joint.negative-dynamics", "error", "negative joint damping or friction",
      doc="""Damping and friction dissipate energy. Negative values feed energy in: simulated
      joints accelerate by themselves and the simulation blows up.""",
      bad='<robot name="r"><link name="a"/><link name="b"/>\n'
          '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
          '    <limit lower="-1" upper="1" effort="1" velocity="1"/>\n'
          '    <dynamics damping="-0.1" friction="0"/></joint>\n</robot>',
      good='<robot name="r"><link name="a"/><link name="b"/>\n'
           '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
           '    <limit lower="-1" upper="1" effort="1" velocity="1"/>\n'
           '    <dynamics damping="0.1" friction="0"/></joint>\n</robot>')
def negative_dynamics(robot: Robot):
    for joint in robot.joints:
        dynamics = joint.dynamics
        if dynamics is None:
            continue
        for name in ("damping", "friction"):
            value = getattr(dynamics, name)
            if value is not None and value < 0:
                yield Finding(f"{label(joint)}: {name} {fmt(value)} is negative", dynamics.loc,
                              hint=f'{name}="{fmt(-value)}"')


@rule("joint.calibration-outside-limits", "warning",
      "a calibration reference position outside the joint limits",
      doc="""`<calibration rising/falling>` is where the joint's reference switch triggers.
      Outside the joint's range the switch can never be reached, so calibration never ends.""",
      bad='<robot name="r"><link name="a"/><link name="b"/>\n'
          '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
          '    <limit lower="-1" upper="1" effort="1" velocity="1"/>\n'
          '    <calibration rising="2"/></joint>\n</robot>',
      good='<robot name="r"><link name="a"/><link name="b"/>\n'
           '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
           '    <limit lower="-1" upper="1" effort="1" velocity="1"/>\n'
           '    <calibration rising="0.5"/></joint>\n</robot>')
def calibration_outside_limits(robot: Robot):
    for joint in robot.joints:
        calibration, limit = joint.calibration, joint.limit
        if calibration is None or limit is None or joint.type not in ("revolute", "prismatic"):
            continue
        lo, hi = limit.lower, limit.upper
        if lo is None or hi is None or lo > hi:
            continue
        tolerance = 1e-9 * max(1.0, abs(lo), abs(hi))
        for name in ("rising", "falling"):
            value = getattr(calibration, name)
            if value is not None and not (lo - tolerance <= value <= hi + tolerance):
                yield Finding(f"{label(joint)}: calibration {name} {fmt(value)} is outside the "
                              f"limits [{fmt(lo)}, {fmt(hi)}]; the reference can never be "
                              "reached", calibration.loc,
                              hint=f"a {name} position inside [{fmt(lo)}, {fmt(hi)}]")
