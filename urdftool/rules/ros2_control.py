"""Rule family ``ros2_control`` (issue 31): the ``<ros2_control>`` blocks of a robot, the
controllers YAML its simulator plugin names, and the launch files that load it.

Severity follows what ros2_control does, read in its sources: hardware_interface's
``component_parser.cpp`` (``parse_control_resources_from_urdf``: only ``<ros2_control>``
elements directly under ``<robot>`` are read, a ``<plugin>``'s text is taken as written, a
joint must be the URDF's and not fixed, mimic joints are checked against the URDF) and
controller_manager (a controller whose joints' interfaces the hardware does not export fails
to configure). An unknown joint inside ``<ros2_control>`` is ``transmission.ros2-control-joint``
(one finding per cause)."""

from __future__ import annotations

from urdftool.findings import Finding, Loc
from urdftool.rules import did_you_mean, rule

_JOINT = """<robot name="r">
  <link name="base"/><link name="arm"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
"""


def _block(plugin: str = "mock_components/GenericSystem", joint: str = "j",
           command: str = "position") -> str:
    return (f'  <ros2_control name="sys" type="system">\n    <hardware><plugin>{plugin}</plugin>'
            f'</hardware>\n    <joint name="{joint}"><command_interface name="{command}"/>'
            '<state_interface name="position"/></joint>\n  </ros2_control>\n')


# the robot the controllers examples are checked against (``tests/test_rule_docs.py``)
EXAMPLE_ROBOT = _JOINT + _block() + "</robot>"

# hardware_interface/types/hardware_interface_type_values.hpp
STANDARD = ("position", "velocity", "acceleration", "effort", "jerk", "torque", "force",
            "current", "temperature")
# what the simulators' systems export for a joint (gz_ros2_control GazeboSimSystem,
# ign_ros2_control IgnitionSystem, gazebo_ros2_control GazeboSystem): any other name is refused
SIMULATED = {"command": ("position", "velocity", "effort"),
             "state": ("position", "velocity", "effort")}
SIM_SYSTEMS = ("gz_ros2_control/", "ign_ros2_control/", "gazebo_ros2_control/")


def _text(element) -> str:
    return element.text or "" if element is not None else ""


def _plugin(block) -> str:
    hardware = next((c for c in block if c.tag == "hardware"), None)
    plugin = next((c for c in hardware if c.tag == "plugin"), None) if hardware is not None \
        else None
    return _text(plugin).strip()


def _blocks(robot) -> list:
    return robot.elements("ros2_control")


@rule("ros2_control.misplaced", "error", "a <ros2_control> block that ros2_control never reads",
      doc="""hardware_interface's parser (`parse_control_resources_from_urdf`) reads only the
`<ros2_control>` elements directly under `<robot>` (`robot->FirstChildElement("ros2_control")`).
One placed inside `<gazebo>` (a common slip when the simulator plugin and the hardware are
written together) or any other element is never read: the controller manager starts without
that hardware ("no ros2_control tag"), and no controller comes up.""",
      bad=_JOINT + '  <gazebo>\n' + _block() + '  </gazebo>\n</robot>',
      good=_JOINT + _block() + '</robot>')
def misplaced(robot):
    if robot.root is None:
        return
    for block in robot.root.iter("ros2_control"):
        parent = block.getparent()
        if parent is None or parent is robot.root:
            continue
        yield Finding(f"<ros2_control name=\"{block.get('name')}\"> is inside <{parent.tag}>: "
                      "ros2_control reads only <ros2_control> elements directly under <robot>, "
                      "so this hardware is never loaded", robot.loc(block),
                      hint=f"move it out of <{parent.tag}>, directly under <robot>")


@rule("ros2_control.plugin-name", "error", "a hardware plugin name with spaces or line breaks",
      doc="""ros2_control takes the text of `<hardware><plugin>` as written (`GetText()`, not
trimmed) and asks pluginlib for that class: a name broken across lines by a formatter, or with
spaces around it, is a class that does not exist ("According to the loaded plugin descriptions
the class ... does not exist"), and the hardware fails to load.""",
      bad=_JOINT + _block().replace("<plugin>mock_components/GenericSystem</plugin>",
                                    "<plugin>\n      mock_components/GenericSystem\n    "
                                    "</plugin>") + "</robot>",
      good=_JOINT + _block() + "</robot>")
def plugin_name(robot):
    if robot.root is None:
        return
    for block in robot.root.iter("ros2_control"):
        for hardware in (c for c in block if c.tag == "hardware"):
            for plugin in (c for c in hardware if c.tag == "plugin"):
                text = _text(plugin)
                name = text.strip()
                if not name or text == name:
                    continue
                inner = len(name.split()) > 1
                shown = " ".join(text.split())
                yield Finding(f"ros2_control '{block.get('name')}': the hardware plugin name "
                              f"{shown!r} is written with "
                              f"{'spaces inside it' if inner else 'spaces or line breaks around it'}"
                              "; pluginlib finds no class of that name", robot.loc(plugin),
                              hint=f"<plugin>{name if not inner else shown}</plugin> on one "
                                   "line, nothing around the name")


@rule("ros2_control.fixed-joint", "error", "a fixed joint inside <ros2_control>",
      doc="""ros2_control refuses a `<ros2_control>` joint that is fixed in the URDF ("Joint 'x' is
of type 'fixed'. Fixed joints do not make sense in ros2_control."): the hardware component, and
every controller of the robot, fails to start.""",
      bad=_JOINT.replace('type="revolute"', 'type="fixed"') + _block() + "</robot>",
      good=_JOINT + _block() + "</robot>")
def fixed_joint(robot):
    for block in _blocks(robot):
        for node in (c for c in block if c.tag == "joint"):
            joint = robot.joint(node.get("name"))
            if joint is not None and joint.type == "fixed":
                yield Finding(f"ros2_control '{block.get('name')}': joint '{joint.name}' is fixed in "
                              "the URDF; ros2_control refuses it", robot.loc(node),
                              hint="remove it from <ros2_control>, or make the joint move")


@rule("ros2_control.mimic", "error", "a <ros2_control> joint whose mimic setting contradicts the URDF",
      doc="""Since ros2_control 4 (Jazzy) the parser checks mimic joints against the URDF:
`mimic="true"` on a joint the URDF does not make a mimic ("has no mimic information in the
URDF") and a URDF mimic joint given a command interface while its `mimic` attribute is not
"false" ("Activated mimic joints cannot have command interfaces") are refused, and so is a mimic
joint whose leader is not in the same `<ros2_control>` block. Refused: errors. (Humble reads
them without the check; the commands to a mimic joint are then fought by the simulator.)""",
      bad=_JOINT + '  <link name="tip"/><joint name="m" type="revolute"><parent link="arm"/>'
                   '<child link="tip"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
                   '<mimic joint="j"/></joint>\n' + _block() +
          _block(joint="m").replace('name="sys"', 'name="sys2"') + "</robot>",
      good=_JOINT + '  <link name="tip"/><joint name="m" type="revolute"><parent link="arm"/>'
                    '<child link="tip"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
                    '<mimic joint="j"/></joint>\n' + _block() + "</robot>")
def mimic(robot):
    for block in _blocks(robot):
        names = {c.get("name") for c in block if c.tag == "joint"}
        for node in (c for c in block if c.tag == "joint"):
            joint = robot.joint(node.get("name"))
            if joint is None:
                continue
            flag = (node.get("mimic") or "").strip().lower()
            commands = [c for c in node if c.tag == "command_interface"]
            where = f"ros2_control '{block.get('name')}': joint '{joint.name}'"
            if joint.mimic is None:
                if flag == "true":
                    yield Finding(f"{where} is marked mimic=\"true\" but the URDF gives it no "
                                  "<mimic>; ros2_control refuses it", robot.loc(node),
                                  hint="remove mimic=\"true\", or add the <mimic> to the URDF joint")
                continue
            if flag in ("false", "0"):
                continue
            if commands:
                yield Finding(f"{where} mimics '{joint.mimic.joint}' in the URDF but has a "
                              "command interface; ros2_control (Jazzy and later) refuses an "
                              "active mimic joint with command interfaces", robot.loc(commands[0]),
                              hint="remove its <command_interface> (its leader is commanded), "
                                   "or set mimic=\"false\"")
            elif joint.mimic.joint and joint.mimic.joint not in names:
                yield Finding(f"{where} mimics '{joint.mimic.joint}', which is not in this "
                              "<ros2_control> block; ros2_control (Jazzy and later) refuses it",
                              robot.loc(node),
                              hint=f"add '{joint.mimic.joint}' to the block, or set "
                                   "mimic=\"false\"")


@rule("ros2_control.interface", "error",
      "an interface name the hardware does not have for the joint",
      doc="""A `<command_interface>`/`<state_interface>` of a joint names what the hardware
exports. The simulators' systems (gz_ros2_control's GazeboSimSystem, ign_ros2_control,
gazebo_ros2_control) export only `position`, `velocity` and `effort`: another name is refused
and controllers claiming it fail to configure (error). Custom hardware may export any name, so
a name is judged there only when it is a slip of a standard one (`postion`: a warning, with the
fix).""",
      bad=_JOINT + _block(plugin="gz_ros2_control/GazeboSimSystem", command="postion") + "</robot>",
      good=_JOINT + _block(plugin="gz_ros2_control/GazeboSimSystem") + "</robot>", fix="safe")
def interface(robot):
    from urdftool.rules import value_edits

    for block in _blocks(robot):
        plugin = _plugin(block)
        simulated = plugin.startswith(SIM_SYSTEMS)
        for node in (c for c in block if c.tag == "joint"):
            for kind in ("command", "state"):
                for item in (c for c in node if c.tag == f"{kind}_interface"):
                    name = (item.get("name") or "").strip()
                    if not name or "$" in name:
                        continue
                    allowed = SIMULATED[kind] if simulated else STANDARD
                    if name in allowed:
                        continue
                    near = did_you_mean(name, allowed)
                    if not simulated and near is None:
                        continue  # custom hardware's own interface
                    edits, note = value_edits(robot, robot.loc(item), (f"{kind}_interface",),
                                              {"name": near}) if near else ((), "")
                    what = f"{plugin} exports only {', '.join(allowed)}" if simulated else \
                        f"'{near}' is the standard name"
                    yield Finding(f"ros2_control '{block.get('name')}': joint "
                                  f"'{node.get('name')}' has a {kind} interface '{name}'; {what}",
                                  robot.loc(item), severity=None if simulated else "warning",
                                  hint=(f"did you mean '{near}'?" if near else
                                        f"one of {', '.join(allowed)}") + note, edits=edits)


_GZ = ('  <gazebo><plugin filename="gz_ros2_control-system" '
       'name="gz_ros2_control::GazeboSimROS2ControlPlugin">\n'
       '    <parameters>{}</parameters></plugin></gazebo>\n')


@rule("ros2_control.parameters-missing", "error",
      "the simulator plugin's controllers file is not there",
      doc="""gz_ros2_control, ign_ros2_control and gazebo_ros2_control start the controller
manager with the `<parameters>` file they are given. When it is not there the controller
manager starts without controllers (or the plugin fails to load), and nothing moves. Only an
absolute path (as `$(find pkg)/config/...` expands to) is checked; a relative one depends on
where the simulator is started. (`{dir}` in the example: the directory of the robot file.)""",
      bad=_JOINT + _block(plugin="gz_ros2_control/GazeboSimSystem") +
          _GZ.format("{dir}/config/controllers.yaml") + "</robot>",
      good=_JOINT + _block(plugin="gz_ros2_control/GazeboSimSystem") + "</robot>")
def parameters_missing(robot):
    from pathlib import Path

    from urdftool.controllers import parameter_files
    from urdftool.roots import is_file

    roots = getattr(robot.source.resolver, "roots", None) if robot.source.resolver else None
    for element, text in parameter_files(robot.root):
        if "$(" in text or "${" in text or not text.startswith("/"):
            continue
        path = Path(text)
        if roots is not None and not roots.readable(path):
            continue  # outside what the run may read: not known here (no existence oracle)
        if not is_file(path):
            yield Finding(f"the controllers file {text} given to the simulator plugin is not "
                          "there", robot.loc(element),
                          hint="point <parameters> at the package's controllers YAML "
                               "($(find pkg)/config/controllers.yaml)")


def _controllers(subject):
    for controller in subject.data["controllers"]:
        yield subject.data["path"], controller


def _declared(robot) -> dict[str, dict]:
    """joint -> {"command": names, "state": names, "plugin": its hardware's} over every
    <ros2_control> block."""
    found: dict[str, dict] = {}
    for block in _blocks(robot):
        plugin = _plugin(block)
        for node in (c for c in block if c.tag == "joint"):
            entry = found.setdefault(node.get("name") or "", {"command": set(), "state": set(),
                                                                 "plugin": plugin})
            for kind in ("command", "state"):
                entry[kind].update((c.get("name") or "").strip() for c in node
                                   if c.tag == f"{kind}_interface")
    return found


def _substituted(name: str) -> bool:
    """A name written for launch-time substitution (``$(var prefix)joint1``, ``${prefix}``,
    ``<robot_prefix>``): not a defect, not checked."""
    return any(mark in name for mark in ("$(", "${", "<", "@"))


@rule("ros2_control.controller-joint", "error",
      "a controller names a joint or interface the robot's <ros2_control> lacks",
      doc="""The controller manager configures a controller by claiming the interfaces
`JOINT/INTERFACE` its parameters name (`joints`, `joint`, the wheel names, with its
`command_interfaces`/`state_interfaces` or `interface_name`). A joint that no `<ros2_control>`
block of the robot declares, or an interface the block does not give it, fails the controller
at configuration ("Command interface with 'x/position' does not exist"): the robot does not
move (an error with a simulator's or mock_components' hardware, which export only what is
listed; a warning with custom hardware, which may export more). Names written for launch-time
substitution (`$(var prefix)joint1`) are not judged, nor
entries that are not the robot's joints by design (joint_state_broadcaster's `extra_joints`).
The YAML checked is the one the robot's simulator plugin names (`<parameters>`), or one given
with its robot: `urdftool check config/controllers.yaml --robot urdf/robot.urdf.xacro`.""",
      bad="controller_manager:\n  ros__parameters:\n    arm_controller:\n"
          "      type: forward_command_controller/ForwardCommandController\n"
          "arm_controller:\n  ros__parameters:\n    joints: [jj]\n    interface_name: position",
      good="controller_manager:\n  ros__parameters:\n    arm_controller:\n"
           "      type: forward_command_controller/ForwardCommandController\n"
           "arm_controller:\n  ros__parameters:\n    joints: [j]\n    interface_name: position",
      on="controllers")
def controller_joint(subject):
    robot = subject.robot
    declared = _declared(robot)
    if not declared:
        return
    urdf = [j.name for j in robot.joints if j.name]
    for path, controller in _controllers(subject):
        interfaces = controller["interfaces"]
        wanted = [(kind, item) for key, kind in (("command_interfaces", "command"),
                                                   ("interface_name", "command"),
                                                   ("state_interfaces", "state"))
                  for item in interfaces.get(key, ())]
        where = f"controller '{controller['name']}'"
        lacking: dict[tuple, list[str]] = {}  # (kind, interface item) -> joints without it
        for name, line, column in controller["joints"]:
            if _substituted(name):
                continue
            if name not in declared:
                near = did_you_mean(name, list(declared)) or did_you_mean(name, urdf)
                in_urdf = robot.joint(name) is not None
                yield Finding(f"{where}: joint '{name}' is not in any <ros2_control> block of the "
                              "robot" + (" (it is a joint of the URDF)" if in_urdf else
                                         " (nor a joint of the URDF)"), Loc(path, line, column),
                              hint=f"did you mean '{near}'?" if near else
                              "declare its interfaces in <ros2_control>, or name a joint that has "
                              "them")
                continue
            for kind, item in wanted:
                if not _substituted(item[0]) and item[0] not in declared[name][kind]:
                    lacking.setdefault((kind, tuple(item)), []).append(name)
        for (kind, (interface_name, line, column)), joints in lacking.items():
            plugins = sorted({declared[j]["plugin"] for j in joints})
            # custom hardware may export interfaces its <ros2_control> does not list
            custom = [p for p in plugins if not p.startswith(
                SIM_SYSTEMS + ("mock_components/", "fake_components/"))]
            shown = ", ".join(f"'{j}'" for j in joints)
            yield Finding(f"{where}: joint(s) {shown} have no {kind} interface "
                          f"'{interface_name}' in <ros2_control>"
                          + (f" (unless {', '.join(custom)} exports it itself)" if custom else
                             f" ({', '.join(plugins)} exports only those listed)"),
                          Loc(path, line, column), severity="warning" if custom else None,
                          hint=f"add <{kind}_interface name=\"{interface_name}\"/> to the "
                               "joint(s), or claim an interface they have")


DESCRIPTION_KEYS = ("robot_description", "robot_description_semantic")


def _call_name(node) -> str:
    import ast

    func = node.func if isinstance(node, ast.Call) else None
    if isinstance(func, ast.Name):
        return func.id
    if isinstance(func, ast.Attribute):
        return func.attr
    return ""


def _runs_xacro(node) -> bool:
    """Whether a ``Command([...])`` call runs xacro (``FindExecutable(name="xacro")``, or a
    literal "xacro" word)."""
    import ast

    for inner in ast.walk(node):
        if isinstance(inner, ast.Constant) and isinstance(inner.value, str) and \
                "xacro" in inner.value.split():
            return True
        if isinstance(inner, ast.Call) and _call_name(inner) == "FindExecutable" and any(
                isinstance(k.value, ast.Constant) and k.value.value == "xacro"
                for k in inner.keywords):
            return True
    return False


def _string_typed(node) -> bool:
    """``ParameterValue(..., value_type=str)``."""
    import ast

    return _call_name(node) == "ParameterValue" and any(
        k.arg == "value_type" and isinstance(k.value, ast.Name) and k.value.id == "str"
        for k in node.keywords)


@rule("ros2_control.description-not-string", "warning",
      "a launch file passes xacro output as robot_description without saying it is a string",
      doc="""launch_ros reads every parameter value given as a substitution as YAML first
(`evaluate_parameters`: `yaml.safe_load`). The output of `Command([FindExecutable(name="xacro"),
...])` is XML: the launch works until the robot's text holds something YAML reads otherwise (a
comment with `: ` in it, a `#`), and then stops with "Unable to parse the value of parameter
robot_description as yaml. If the parameter is meant to be a string, try wrapping it in
launch_ros.parameter_descriptions.ParameterValue(value, value_type=str)". Found at the
`robot_description` (or `robot_description_semantic`) key of the launch file; a warning: it
works by chance today.""",
      bad='from launch.substitutions import Command, FindExecutable\n'
          'content = Command([FindExecutable(name="xacro"), " ", "robot.urdf.xacro"])\n'
          'description = {"robot_description": content}',
      good='from launch.substitutions import Command, FindExecutable\n'
           'from launch_ros.parameter_descriptions import ParameterValue\n'
           'content = Command([FindExecutable(name="xacro"), " ", "robot.urdf.xacro"])\n'
           'description = {"robot_description": ParameterValue(content, value_type=str)}',
      on="launch")
def description_not_string(launch):
    import ast

    tree = launch.tree
    if tree is None:
        return
    assigned: dict[str, list] = {}  # name -> the values assigned to it (anywhere)
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign):
            for target in node.targets:
                if isinstance(target, ast.Name):
                    assigned.setdefault(target.id, []).append(node.value)

    def xacro_output(value, depth: int = 0) -> bool:
        if depth > 4:
            return False
        if isinstance(value, ast.Name):
            return any(xacro_output(v, depth + 1) for v in assigned.get(value.id, ()))
        if _call_name(value) == "ParameterValue":
            return not _string_typed(value) and bool(value.args) and xacro_output(
                value.args[0], depth + 1)
        return _call_name(value) == "Command" and _runs_xacro(value)

    # one finding per parameter name and launch file (one variable passed to three nodes is
    # one cause), at its first use, with the other uses' lines
    uses: dict[str, list] = {}
    for node in ast.walk(tree):
        if not isinstance(node, ast.Dict):
            continue
        for key, value in zip(node.keys, node.values):
            if isinstance(key, ast.Constant) and key.value in DESCRIPTION_KEYS and \
                    value is not None and xacro_output(value):
                uses.setdefault(key.value, []).append(key)
    for name, keys in uses.items():
        keys.sort(key=lambda k: (k.lineno, k.col_offset))
        first, more = keys[0], sorted({k.lineno for k in keys[1:]} - {keys[0].lineno})
        also = f" (also given so at line{'s' if len(more) > 1 else ''} " \
               f"{', '.join(map(str, more))})" if more else ""
        yield Finding(f"'{name}' is the output of xacro given without "
                      "ParameterValue(..., value_type=str): launch_ros reads it as YAML "
                      "first, and stops when the robot's text is not a YAML string" + also,
                      Loc(launch.path, first.lineno, first.col_offset + 1),
                      hint="wrap it: ParameterValue(robot_description_content, "
                           "value_type=str) (from launch_ros.parameter_descriptions)")
