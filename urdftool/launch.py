"""The xacro arguments a package's launch files pass to its xacro files, read statically: a
package whose entry needs ``model:=...`` is checked the way its launch file expands it, not
reported as broken (issue 13).

Nothing is executed: Python launch files are parsed with ``ast`` and only literals are read
(``DeclareLaunchArgument(NAME, default_value=...)``, a ``'NAME:='`` followed by a string or a
``LaunchConfiguration(NAME)`` in the same list, ``mappings={...}`` of ``xacro.process_file``);
XML launch files (ROS 1 ``.launch``, ROS 2 ``.launch.xml``) with the secure lxml parser
(``<arg name default>``; none from a file that declares entities; ``NAME:=VALUE`` in the attribute that names the ``.xacro``, with
``$(arg X)``/``$(var X)`` replaced by X's default). A value that needs anything else (a path
join, a command) is not passed. The arguments apply to a file when the launch file names its
``.xacro`` by file name. Launch files are found under the package's ``launch/`` directory, at
most ``MAX_FILES`` of at most ``MAX_BYTES`` each.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

from urdftool.files import read_regular_text

MAX_FILES = 64
MAX_BYTES = 256 * 1024
MAX_SETS = 8  # argument sets per xacro file
_MAPPING = re.compile(r"(?<![\w$])([A-Za-z_]\w*):=(\S*)")
_SUBSTITUTION = re.compile(r"\$\((?:arg|var) ([A-Za-z_]\w*)\)")
# a name starts where a run of name characters starts (one try per run: linear)
_XACRO_NAME = re.compile(r"(?<![\w.-])[\w.-]+\.xacro\b")


def launch_arguments(root: Path) -> dict[str, list[tuple[dict[str, str], str]]]:
    """xacro file name -> the distinct argument sets the launch files under ``root/launch``
    pass to it, each with the launch file's path (relative to ``root``)."""
    found: dict[str, list[tuple[dict[str, str], str]]] = {}
    directory = root / "launch"
    if directory.is_symlink() or not directory.is_dir():
        return found  # nothing outside the package is read
    files = sorted(p for p in directory.rglob("*") if _is_launch(p))[:MAX_FILES]
    for path in files:
        try:
            text = read_regular_text(path, MAX_BYTES)
        except OSError:  # larger than MAX_BYTES, not a regular file, unreadable
            continue
        read = _python if path.suffix == ".py" else _xml
        for name, args in read(text):
            sets = found.setdefault(name, [])
            if args and all(args != known for known, _ in sets) and len(sets) < MAX_SETS:
                sets.append((args, path.relative_to(root).as_posix()))
    return found


def _is_launch(path: Path) -> bool:
    name = path.name
    return path.is_file() and not path.is_symlink() and (
        name.endswith((".launch.py", ".launch", ".launch.xml"))
        or (name.endswith(".py") and "launch" in name))


# -- Python launch files ------------------------------------------------------------------------


def _python(text: str) -> list[tuple[str, dict[str, str]]]:
    try:
        tree = ast.parse(text)
    except (SyntaxError, ValueError, RecursionError, MemoryError):
        return []
    defaults: dict[str, object] = {}
    names: set[str] = set()
    pairs: list[tuple[str, object]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            called = _called(node)
            if called == "DeclareLaunchArgument":
                name = _string(node.args[0]) if node.args else _keyword(node, "name")
                default = _keyword_node(node, "default_value")
                if isinstance(name, str) and default is not None:
                    defaults[name] = default
            mappings = _keyword_node(node, "mappings")
            if isinstance(mappings, ast.Dict):
                pairs.extend(_dict_pairs(mappings))
            elif "urdf" in called.lower() or "xacro" in called.lower():
                for arg in node.args:
                    if isinstance(arg, ast.Dict):
                        pairs.extend(_dict_pairs(arg))
        elif isinstance(node, ast.Constant) and isinstance(node.value, str):
            names.update(_XACRO_NAME.findall(node.value))
        if isinstance(node, (ast.List, ast.Tuple)):
            pairs.extend(_list_pairs(node.elts))
    args = {}
    for name, value in pairs:
        resolved = _value(value, defaults, 0)
        if resolved is not None:
            args[name] = resolved
    return [(name, args) for name in sorted(names)]


def _called(node: ast.Call) -> str:
    func = node.func
    return func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")


def _string(node) -> str | None:
    return node.value if isinstance(node, ast.Constant) and isinstance(node.value, str) else None


def _keyword_node(node: ast.Call, name: str):
    return next((k.value for k in node.keywords if k.arg == name), None)


def _keyword(node: ast.Call, name: str) -> str | None:
    return _string(_keyword_node(node, name))


def _dict_pairs(node: ast.Dict) -> list[tuple[str, object]]:
    return [(key.value, value) for key, value in zip(node.keys, node.values)
            if isinstance(key, ast.Constant) and isinstance(key.value, str)]


def _list_pairs(elements: list) -> list[tuple[str, object]]:
    """'NAME:=VALUE' in one string, or 'NAME:=' (or ' NAME:=') followed by its value."""
    pairs: list[tuple[str, object]] = []
    for index, element in enumerate(elements):
        text = _string(element)
        if text is None:
            continue
        for name, value in _MAPPING.findall(text):
            if value:
                pairs.append((name, ast.Constant(value)))
            elif text.rstrip().endswith(":=") and index + 1 < len(elements):
                pairs.append((name, elements[index + 1]))
    return pairs


def _value(node, defaults: dict[str, object], depth: int) -> str | None:
    """A literal string, or a LaunchConfiguration(NAME) whose default is one."""
    text = _string(node)
    if text is not None:
        return text.strip() if _SUBSTITUTION.search(text) is None else None
    if isinstance(node, ast.Call) and _called(node) == "LaunchConfiguration" and node.args:
        name = _string(node.args[0])
        if name in defaults and depth < 8:
            return _value(defaults[name], defaults, depth + 1)
    return None


# -- XML launch files ---------------------------------------------------------------------------


def _xml(text: str) -> list[tuple[str, dict[str, str]]]:
    from lxml import etree

    from urdftool.xmlrepair import secure_parser

    try:
        root = etree.fromstring(text.encode("utf-8"), secure_parser())
    except (etree.XMLSyntaxError, ValueError):
        return []
    if root is None:
        return []
    info = root.getroottree().docinfo
    if info.system_url or info.public_id or (
            info.internalDTD is not None and any(info.internalDTD.iterentities())):
        return []  # entities are never expanded: the file is not read (as xacro does)
    defaults = {a.get("name"): a.get("default", a.get("value")) for a in root.iter("arg")
                if a.get("name") and a.get("default", a.get("value")) is not None}
    found = []
    for element in root.iter():
        if not isinstance(element.tag, str):
            continue
        for value in element.attrib.values():
            names = _XACRO_NAME.findall(value)
            if not names:
                continue
            args = {}
            for name, raw in _MAPPING.findall(_SUBSTITUTION.sub(
                    lambda m: defaults.get(m.group(1)) or m.group(0), value)):
                if raw and "$(" not in raw:
                    args[name] = raw.strip("'\"")
            found.extend((name, args) for name in names)
    return found
