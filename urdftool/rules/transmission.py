"""Rules of the `transmission` family: `<transmission>` blocks (ros_control, gazebo_ros_control,
gazebo_ros2_control) and `<ros2_control>` blocks.

ros_control's transmission parser needs a `<type>`, at least one `<joint>` with a
`<hardwareInterface>`, and an `<actuator>`; a reduction of 0 divides by zero. The pre-Hydro form
(`<transmission type="..."><joint name/><actuator name/>...`, used by the PR2) has no hardware
interfaces and is checked only for the names it uses.
"""

from __future__ import annotations

import math

from urdftool.findings import Finding
from urdftool.model import Robot
from urdftool.rules import Names, lost, rename_edits, rule

ROS1_INTERFACES = (
    "EffortJointInterface", "PositionJointInterface", "VelocityJointInterface",
    "JointStateInterface", "PosVelJointInterface", "PosVelAccJointInterface",
    "JointCommandInterface", "ActuatorStateInterface", "EffortActuatorInterface",
    "PositionActuatorInterface", "VelocityActuatorInterface", "ImuSensorInterface",
    "ForceTorqueSensorInterface",
)
ROS2_INTERFACES = ("position", "velocity", "effort", "acceleration")
KNOWN_INTERFACES = tuple(f"hardware_interface/{name}" for name in ROS1_INTERFACES) + \
    ROS2_INTERFACES


def _text(element) -> str:
    return (element.text or "").strip() if element is not None else ""


def _children(element, tag: str) -> list:
    return [n for n in element if isinstance(n.tag, str) and n.tag == tag]


def _child(element, tag: str):
    found = _children(element, tag)
    return found[0] if found else None


def _new_style(transmission) -> bool:
    """ros_control (Hydro and later) form: <type> element, hardware interfaces per joint."""
    return transmission.get("type") is None


def _joint_hint(robot: Robot, name: str, new: str | None) -> str:
    if robot.link(name) is not None:
        if new is not None:
            return f"'{name}' is a link; the joint that moves it is '{new}'"
        return f"'{name}' is a link, not a joint"
    return f"did you mean '{new}'?" if new else "name a joint of the robot"


_JOINT = ('<robot name="r"><link name="a"/><link name="b"/>\n'
          '  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>\n'
          '    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n')


def _transmission(joint: str = "j", interface: str = "hardware_interface/EffortJointInterface",
                  reduction: str = "1", actuator: bool = True) -> str:
    hw = f"<hardwareInterface>{interface}</hardwareInterface>" if interface else ""
    act = (f'    <actuator name="m"><mechanicalReduction>{reduction}</mechanicalReduction>'
           '</actuator>\n') if actuator else ""
    return ('  <transmission name="t"><type>transmission_interface/SimpleTransmission</type>\n'
            f'    <joint name="{joint}">{hw}</joint>\n{act}  </transmission>\n</robot>')


@rule("transmission.unknown-joint", "error", "a transmission names a joint that does not exist",
      doc="""ros_control and gazebo_ros_control look the transmission's joint up by name; a name
      that is not a joint makes the controller manager fail to load the robot hardware.""",
      bad=_JOINT + _transmission(joint="b"),
      good=_JOINT + _transmission(),
      fix="safe")
def unknown_joint(robot: Robot):
    joints = Names(j.name for j in robot.joints)
    for transmission in robot.elements("transmission"):
        for tag in ("joint", "passive_joint"):
            for node in _children(transmission, tag):
                name = node.get("name")
                if name is None or robot.joint(name) is not None or lost(robot, name):
                    continue
                edits, new, note = rename_edits(robot, robot.loc(node), tag, "name", name,
                                                joints, True)
                yield Finding(f"transmission '{transmission.get('name')}': <{tag}> '{name}' is "
                              "not a joint of the robot", robot.loc(node),
                              hint=_joint_hint(robot, name, new) + note, edits=edits)


@rule("transmission.incomplete", "error", "a transmission without a type, joint or actuator",
      doc="""A transmission maps an actuator onto a joint: ros_control's parser rejects one
      without a `<type>`, without a `<joint name>` or without an `<actuator name>`, and the
      controllers for that joint never come up. (Pre-Hydro transmissions with a `type`
      attribute, like the PR2's, name their joints and actuators in their own elements and are
      not checked here.)""",
      bad=_JOINT + _transmission(actuator=False),
      good=_JOINT + _transmission())
def incomplete(robot: Robot):
    for transmission in robot.elements("transmission"):
        if not _new_style(transmission):
            continue  # pre-Hydro types (PR2 wrist, gripper) have their own children
        name = transmission.get("name")
        missing = []
        if not _text(_child(transmission, "type")):
            missing.append("<type>")
        if not any(n.get("name") for n in _children(transmission, "joint")):
            missing.append('<joint name="...">')
        if not any(n.get("name") for n in _children(transmission, "actuator")):
            missing.append('<actuator name="...">')
        if missing:
            yield Finding(f"transmission '{name}' lacks " + " and ".join(missing),
                          robot.loc(transmission),
                          hint="<type>transmission_interface/SimpleTransmission</type>, "
                               '<joint name="J"><hardwareInterface>...</hardwareInterface></joint>'
                               ', <actuator name="M"><mechanicalReduction>1'
                               "</mechanicalReduction></actuator>")


@rule("transmission.hardware-interface", "error",
      "a transmission joint without a hardware interface, or with an unknown one",
      doc="""Each `<joint>` of a transmission declares how controllers talk to it:
      `hardware_interface/EffortJointInterface`, `.../PositionJointInterface`,
      `.../VelocityJointInterface` (ROS 1), or `effort`, `position`, `velocity` (ROS 2). Without
      one, gazebo_ros_control and ros_control refuse the transmission (error). An unknown name
      is usually misspelled (warning); the bare ROS 1 name without `hardware_interface/` is
      deprecated (info).""",
      bad=_JOINT + _transmission(interface=""),
      good=_JOINT + _transmission())
def hardware_interface(robot: Robot):
    for transmission in robot.elements("transmission"):
        if not _new_style(transmission):
            continue
        for joint in _children(transmission, "joint"):
            interfaces = _children(joint, "hardwareInterface")
            if not interfaces or not any(_text(i) for i in interfaces):
                yield Finding(f"transmission '{transmission.get('name')}': joint "
                              f"'{joint.get('name')}' has no <hardwareInterface>",
                              robot.loc(joint),
                              hint="<hardwareInterface>hardware_interface/EffortJointInterface"
                                   "</hardwareInterface> (or Position/Velocity)")
                continue
            for node in interfaces:
                yield from _check_interface(robot, node)


def _check_interface(robot: Robot, node):
    value = _text(node)
    if not value or value in KNOWN_INTERFACES:
        return
    if value in ROS1_INTERFACES:
        yield Finding(f"hardware interface '{value}' without the 'hardware_interface/' prefix is "
                      "deprecated", robot.loc(node),
                      hint=f"<hardwareInterface>hardware_interface/{value}</hardwareInterface>",
                      severity="info")
        return
    if "/" in value and not value.startswith("hardware_interface/"):
        return  # a vendor's own interface (e.g. franka_hw/...): not ours to judge
    import difflib  # only on this error path: keeps start-up lean

    close = difflib.get_close_matches(value, KNOWN_INTERFACES, n=1, cutoff=0.6) or \
        difflib.get_close_matches(value.lower(), ROS2_INTERFACES, n=1, cutoff=0.6)
    yield Finding(f"unknown hardware interface '{value}'", robot.loc(node),
                  hint=f"did you mean '{close[0]}'?" if close else
                  "hardware_interface/EffortJointInterface, .../PositionJointInterface, "
                  ".../VelocityJointInterface, or position/velocity/effort (ROS 2)",
                  severity="warning")


@rule("transmission.zero-reduction", "error", "a mechanical reduction of zero",
      doc="""The reduction scales actuator effort and position into joint effort and position:
      0 divides by zero, and joint positions and efforts become infinite or NaN. (A reduction
      that is not a number at all is a `schema` finding.)""",
      bad=_JOINT + _transmission(reduction="0"),
      good=_JOINT + _transmission())
def zero_reduction(robot: Robot):
    for transmission in robot.elements("transmission"):
        for node in transmission.iter("mechanicalReduction", "mechanical_reduction"):
            text = _text(node)
            try:
                value = float(text)
            except ValueError:
                continue  # not a number: schema.bad-number
            if value == 0 or not math.isfinite(value):
                yield Finding(f"transmission '{transmission.get('name')}': mechanical reduction "
                              f"{text}: joint positions and efforts become infinite",
                              robot.loc(node), hint="the gear ratio, e.g. 1 or 100")


@rule("transmission.ros2-control-joint", "error", "a <ros2_control> joint that does not exist",
      doc="""Each `<joint name>` inside `<ros2_control>` must be a joint of the robot:
      ros2_control's resource manager refuses to start a hardware component whose joints it
      cannot find, and no controller for the robot comes up.""",
      bad=_JOINT + '  <ros2_control name="sys" type="system">\n'
                   '    <hardware><plugin>mock_components/GenericSystem</plugin></hardware>\n'
                   '    <joint name="jj"><command_interface name="position"/>'
                   '<state_interface name="position"/></joint>\n  </ros2_control>\n</robot>',
      good=_JOINT + '  <ros2_control name="sys" type="system">\n'
                    '    <hardware><plugin>mock_components/GenericSystem</plugin></hardware>\n'
                    '    <joint name="j"><command_interface name="position"/>'
                    '<state_interface name="position"/></joint>\n  </ros2_control>\n</robot>',
      fix="safe")
def ros2_control_joint(robot: Robot):
    joints = Names(j.name for j in robot.joints)
    for block in robot.elements("ros2_control"):
        for node in block.iter("joint"):
            name = node.get("name")
            if name is None or robot.joint(name) is not None or lost(robot, name):
                continue
            edits, new, note = rename_edits(robot, robot.loc(node), "joint", "name", name,
                                            joints, True)
            yield Finding(f"ros2_control '{block.get('name')}': joint '{name}' is not a joint of "
                          "the robot", robot.loc(node), hint=_joint_hint(robot, name, new) + note,
                          edits=edits)
