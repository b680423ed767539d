"""Readers layer (issue 31): a ros2_control controllers YAML (the controller_manager's
parameters file) as located, JSON-safe data: the controllers the controller_manager is told to
load (``type``) and, for each, the joints and interfaces its parameters name, each with the
line and column where it is written. PyYAML composes the nodes (never constructs objects from
tags: ``yaml.compose`` with the safe loader); sizes are bounded (``MAX_BYTES``, ``MAX_NODES``).

Which YAML a robot's check reads is decided by the loader (``loader.load``: the ``<parameters>``
of a ``gz_ros2_control``/``gazebo_ros2_control``/``ign_ros2_control`` plugin, when the run's
roots allow it), in the sandboxed reader under ``--untrusted`` like every YAML."""

from __future__ import annotations

MAX_BYTES = 1 << 20
MAX_NODES = 100_000
# parameters of a controller that name joints (ros2_controllers: joint_trajectory_controller,
# forward_command_controller, *gripper*_controller, diff_drive_controller, ...)
JOINT_KEYS = ("joints", "joint", "left_wheel_names", "right_wheel_names")
INTERFACE_KEYS = ("command_interfaces", "state_interfaces", "interface_name")


def _item(node) -> list:
    """[value, line, column] (1-based) of a scalar node."""
    return [str(node.value), node.start_mark.line + 1, node.start_mark.column + 1]


def _scalars(node) -> list[list]:
    import yaml

    if isinstance(node, yaml.ScalarNode):
        return [_item(node)] if node.value not in ("", "~", "null") else []
    if isinstance(node, yaml.SequenceNode):
        return [_item(n) for n in node.value if isinstance(n, yaml.ScalarNode)]
    return []


def _pairs(node) -> list:
    """(key node, value node) of a mapping, every pair in order (duplicate keys kept)."""
    import yaml

    if not isinstance(node, yaml.MappingNode):
        return []
    return [(key, value) for key, value in node.value if isinstance(key, yaml.ScalarNode)]


def _node_name(key: str) -> str:
    """A ROS node's name from a parameters file key (``/ns/controller_manager`` ->
    ``controller_manager``; ``/**`` stays)."""
    return key.rstrip("/").rsplit("/", 1)[-1] if key not in ("/**", "**") else key


def read_controllers(text: str, path: str) -> dict | str:
    """The controllers of a parameters file: {"path", "manager": [line, column] or None,
    "controllers": [{"name", "type", "line", "column", "joints": [[name, line, column]...],
    "interfaces": {key: [[name, line, column]...]}}]}; or why it cannot be read (a str)."""
    import yaml

    if len(text) > MAX_BYTES:
        return f"larger than {MAX_BYTES} bytes"
    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.YAMLError as exc:
        return " ".join(str(exc).split())[:300]
    nodes = [root]
    count = 0
    while nodes:  # bounded: an alias-heavy file is refused before anything is walked
        node = nodes.pop()
        count += 1
        if count > MAX_NODES:
            return f"more than {MAX_NODES} YAML nodes"
        if isinstance(node, yaml.MappingNode):
            nodes.extend(v for pair in node.value for v in pair)
        elif isinstance(node, yaml.SequenceNode):
            nodes.extend(node.value)
    # node name -> [(its key node, its ros__parameters node)...]: a file may give one node's
    # parameters in several sections (``/**:`` twice, as rcl's parser merges them)
    sections: dict[str, list] = {}

    def section(key_node, value) -> bool:
        params = [v for k, v in _pairs(value) if k.value == "ros__parameters"]
        for node in params:
            sections.setdefault(_node_name(key_node.value), []).append((key_node, node))
        return bool(params)

    for key_node, value in _pairs(root):
        if not section(key_node, value) and (key_node.value in ("/**", "**")
                                             or key_node.value.startswith("/")):
            for inner_key, inner_value in _pairs(value):  # a namespace: its nodes
                section(inner_key, inner_value)
    managers = sections.get("controller_manager")
    result = {"path": path, "manager": None, "controllers": []}
    if not managers:
        return result
    result["manager"] = [managers[0][0].start_mark.line + 1, managers[0][0].start_mark.column + 1]
    for _, params in managers:
        for key_node, value in _pairs(params):
            fields = {k.value: v for k, v in _pairs(value)}
            if not isinstance(fields.get("type"), yaml.ScalarNode):
                continue
            name = key_node.value
            entry = {"name": name, "type": str(fields["type"].value),
                     "line": key_node.start_mark.line + 1,
                     "column": key_node.start_mark.column + 1,
                     "joints": [], "interfaces": {}, "configured": False}
            for _, own in sections.get(name, ()):
                entry["configured"] = True
                for joint_key, node in _pairs(own):
                    if joint_key.value in JOINT_KEYS:
                        entry["joints"].extend(_scalars(node))
                    elif joint_key.value in INTERFACE_KEYS:
                        entry["interfaces"].setdefault(joint_key.value, []).extend(
                            _scalars(node))
            result["controllers"].append(entry)
    return result


# gazebo plugins that start a controller_manager with a parameters file (Gazebo Classic's
# gazebo_ros2_control, gz/ign_ros2_control): their <parameters> name the controllers YAML
SIM_PLUGINS = ("gazebo_ros2_control", "gz_ros2_control", "ign_ros2_control")


def parameter_files(root) -> list:
    """(the <parameters> element, its text stripped) of every simulator ros2_control plugin of
    an expanded robot."""
    found = []
    if root is None:
        return found
    for plugin in root.iter("plugin"):
        filename = (plugin.get("filename") or "") + " " + (plugin.get("name") or "")
        if not any(name in filename for name in SIM_PLUGINS):
            continue
        for parameters in plugin.iter("parameters"):
            text = (parameters.text or "").strip()
            if text:
                found.append((parameters, text))
    return found


def read_companions(source, options) -> None:
    """``source.controllers``: the controllers YAML the robot's simulator plugins name, read
    when the run may read them (``options.roots``), each one also in ``source.reads`` (a change
    re-checks the robot). A file that is not there is the ``ros2_control`` rules' finding."""
    from pathlib import Path

    from urdftool.errors import ToolError
    from urdftool.source import read_input, shown_path

    found = []
    for _, text in parameter_files(source.root):
        if "$(" in text or "${" in text or not text.endswith((".yaml", ".yml")):
            continue
        path = Path(text)
        if not path.is_absolute():
            continue  # (relative to wherever the simulator is started: not known here)
        roots = getattr(options, "roots", None)
        if roots is not None and not roots.readable(path):
            continue
        if not path.is_file():
            continue
        try:
            yaml_text = read_input(path, options)
        except (ToolError, OSError):
            continue
        data = read_controllers(yaml_text, shown_path(path, source.path))
        if isinstance(data, dict):
            found.append(data)
            source.reads.add(str(path.resolve()))
    source.controllers = found


def checked(data) -> list:
    """The ``controllers`` of a Source as the sandboxed reader sent them, checked field by
    field (data from a process that read an untrusted file); ValueError when malformed."""

    def item(value) -> list:
        name, line, column = value
        if not (isinstance(name, str) and type(line) is int and type(column) is int):
            raise ValueError("item")
        return [name, line, column]

    result = []
    for entry in data or ():
        if not isinstance(entry.get("path"), str):
            raise ValueError("path")  # noqa: TRY004 - the caller's one error for a bad answer
        manager = entry.get("manager")
        controllers = []
        for c in entry.get("controllers", ()):
            if not all(isinstance(c.get(k), str) for k in ("name", "type")) or not (
                    type(c.get("line")) is int and type(c.get("column")) is int):
                raise ValueError("controller")
            controllers.append({
                "name": c["name"], "type": c["type"], "line": c["line"], "column": c["column"],
                "configured": c.get("configured") is True,
                "joints": [item(j) for j in c.get("joints", ())],
                "interfaces": {str(k): [item(i) for i in v]
                               for k, v in (c.get("interfaces") or {}).items()}})
        result.append({"path": entry["path"],
                       "manager": [int(manager[0]), int(manager[1])] if manager else None,
                       "controllers": controllers})
    return result
