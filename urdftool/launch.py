"""The xacro arguments a package's launch files pass to its xacro files, read statically: a
package whose entry needs ``model:=...`` is checked the way its launch file expands it, not
reported as broken (issues 13 and 22.2).

Nothing is executed. Python launch files are parsed with ``ast``, XML launch files (ROS 1
``.launch``, ROS 2 ``.launch.xml``) with the secure lxml parser (none from a file that declares
entities). A launch file's xacro invocations are found and resolved as launch resolves them:

- an invocation: a ``Command([...])``-style list or string (``xacro FILE NAME:=VALUE ...``),
  ``xacro.process_file(FILE, mappings={...})``, or an XML attribute naming a ``.xacro``;
- values are literals, launch arguments (``LaunchConfiguration(NAME)``, ``$(arg NAME)``,
  ``$(var NAME)``) bound to their defaults (a quoted empty default, ``'""'``, is empty),
  variables assigned once anywhere in the file, ``+``, f-strings, ``PathJoinSubstitution``,
  ``os.path.join``, ``FindPackageShare``/``$(find)`` of the package itself;
- an XML launch file that other launch files include (``<include file>``, with ``<arg name
  value>`` or ``pass_all_args``) is resolved once per includer, with what each passes; a
  required Python launch argument with ``choices`` once per choice;
- conditions are honoured where they can be known: an XML ``<arg>`` or element (and the
  elements inside it) with ``if``/``unless`` (``true``/``false``/``1``/``0``, an argument,
  ``$(eval ...)`` over the arguments, evaluated by urdftool's expression interpreter), a
  Python action with ``condition=IfCondition(...)``/``UnlessCondition(...)`` (of a launch
  argument or a ``PythonExpression``), also where a variable holding the command is used;
  a condition that cannot be known holds;
- the file name is matched against the package's xacro files: a launch argument left unbound
  in it (``robot_$(arg model).urdf.xacro``) matches any text, and each file it matches is its
  own entry, with the matched text as that argument.

A value that needs anything else (a command's output, an environment variable) is not passed.
Launch files are found under the package's ``launch/`` directory, at most ``MAX_FILES`` of at
most ``MAX_BYTES`` each; what is refused for its size (a file over ``MAX_BYTES``, the files
beyond ``MAX_FILES``) is handed back to the caller (``refused``), never skipped in silence.
"""

from __future__ import annotations

import ast
import errno
import re
from pathlib import Path

from urdftool.files import read_regular_text

MAX_FILES = 64
MAX_BYTES = 256 * 1024
MAX_SETS = 12  # argument sets per xacro file
MAX_XACROS = 4000  # xacro files of a package matched against the launch files' names
_SUBSTITUTION = re.compile(r"\$\((arg|var|find-pkg-share|find-pkg-prefix|find|dirname|env|optenv|"
                           r"eval|anon)(?![\w-])([^)$]*)\)")
_PAIR = re.compile(r"(?<!\w)([A-Za-z_]\w*):=(.*)", re.DOTALL)

# a value: a list of parts, each a literal string, ("arg", NAME), ("pkg", NAME) or ANY
ANY = ("any", "")


def launch_arguments(root: Path, refused: list[tuple[Path, str]] | None = None,
                     ) -> dict[str, list[tuple[dict[str, str], str]]]:
    """xacro file (posix path relative to ``root``) -> the distinct argument sets the launch
    files under ``root/launch`` pass to it, each with the launch file's path (relative to
    ``root``). ``refused`` gets (path, why) for what was not read for its size (issue 21):
    each launch file over ``MAX_BYTES``, and the ``launch`` directory when it holds more than
    ``MAX_FILES``."""
    found: dict[str, list[tuple[dict[str, str], str]]] = {}
    directory = root / "launch"
    if directory.is_symlink() or not directory.is_dir():
        return found  # nothing outside the package is read
    files = sorted(p for p in directory.rglob("*") if _is_launch(p))
    if len(files) > MAX_FILES and refused is not None:
        first = files[MAX_FILES].relative_to(root).as_posix()
        why = (f"{len(files)} launch files, more than the {MAX_FILES} urdftool reads: "
               f"{len(files) - MAX_FILES} not read, from {first} on")
        refused.append((directory, why))
    texts = {}
    for path in files[:MAX_FILES]:
        try:
            texts[path] = read_regular_text(path, MAX_BYTES)
        except OSError as exc:  # larger than MAX_BYTES, unreadable
            if refused is not None:
                refused.append((path, f"launch file {exc.strerror}" if exc.errno == errno.EFBIG
                                else f"launch file not read: {exc.strerror or exc}"))
            continue
    if not texts:
        return found
    package = _package_name(root)
    xacros = _xacro_files(root)
    xml = {path: _XmlLaunch(text) for path, text in texts.items() if path.suffix != ".py"}
    for path, text in texts.items():
        where = path.relative_to(root).as_posix()
        if path.suffix == ".py":
            commands = _python(text)
        else:
            commands = [(parts, binding) for binding in _xml_bindings(path, xml)
                        for parts, conditions in xml[path].commands
                        if _holds([conditions], binding, package, root)]
        for parts, binding in commands:
            invocation = _invocation(_tokens(parts), binding)
            if invocation is None:
                continue
            for rel, args in _resolve(invocation, binding, xacros, package, root):
                sets = found.setdefault(rel, [])
                if all(args != known for known, _ in sets) and len(sets) < MAX_SETS:
                    sets.append((args, where))
    return {rel: [s for s in sets if s[0]] for rel, sets in found.items() if any(a for a, _ in sets)}


def _is_launch(path: Path) -> bool:
    name = path.name
    return path.is_file() and not path.is_symlink() and (
        name.endswith((".launch.py", ".launch", ".launch.xml"))
        or (name.endswith(".py") and "launch" in name))


def _package_name(root: Path) -> str | None:
    try:
        text = read_regular_text(root / "package.xml", 1 << 20)
    except OSError:
        return None
    match = re.search(r"<name>\s*([^<\s]+)\s*</name>", text)
    return match.group(1) if match else None


def _xacro_files(root: Path) -> list[str]:
    found = []
    for path in sorted(root.rglob("*.xacro")):
        if len(found) >= MAX_XACROS:
            break
        if any(part.startswith(".") for part in path.relative_to(root).parts):
            continue
        found.append(path.relative_to(root).as_posix())
    return found


# -- from a file name and NAME:=VALUE pairs to argument sets -------------------------------------


def _tokens(parts: list) -> list[list]:
    """Parts split at whitespace in their literals (a command line's words)."""
    tokens: list[list] = [[]]
    for part in parts:
        if isinstance(part, str):
            pieces = re.split(r"(\s+)", part)
            for piece in pieces:
                if not piece:
                    continue
                if piece.isspace():
                    if tokens[-1]:
                        tokens.append([])
                else:
                    tokens[-1].append(piece)
        else:
            tokens[-1].append(part)
    return [t for t in tokens if t]


def _invocation(tokens: list[list], binding: dict[str, list],
                ) -> tuple[list, dict[str, list]] | None:
    """(the file name's parts, NAME -> value parts) of one xacro command line, or None when
    no word names a ``.xacro`` (a launch argument's value counts: ``xacro
    $(arg description_file)``)."""
    file = None
    pairs: dict[str, list] = {}
    for token in tokens:
        head = token[0] if isinstance(token[0], str) else ""
        match = _PAIR.fullmatch(head) if head else None
        if match:
            value = ([match.group(2)] if match.group(2) else []) + token[1:]
            pairs[match.group(1)] = value
        elif file is None and _ends_with_xacro(token, binding, 0):
            file = token
    return (file, pairs) if file is not None else None


def _ends_with_xacro(token: list, binding: dict[str, list], depth: int) -> bool:
    last = token[-1] if token else None
    if isinstance(last, str):
        return last.rstrip("'\"").endswith(".xacro")
    if last is not None and last[0] == "arg" and last[1] in binding and depth < 8:
        return _ends_with_xacro(binding[last[1]], binding, depth + 1)
    return False


def _resolve(invocation, binding: dict[str, list], xacros: list[str], package: str | None,
             root: Path):
    """(xacro file, args) for every package xacro file the invocation's file name matches."""
    file, pairs = invocation
    pattern = _file_pattern(file, binding, package)
    if pattern is None:
        return
    pieces, anchored = pattern
    for rel in xacros:
        captured = _match_path(pieces, rel, anchored)
        if captured is None:
            continue
        bound = {**binding, **{name: [value] for name, value in captured.items()}}
        args = {}
        for name, value in pairs.items():
            text = _text(value, bound, package, root, 0)
            if text is not None:
                args[name] = text
        yield rel, args


def _file_pattern(parts: list, binding: dict[str, list], package: str | None,
                  ) -> tuple[list, bool] | None:
    """(pieces over paths relative to the package root: literal strings, ("cap", NAME) for
    a launch argument left unbound, ANY for a part that cannot be known; whether it is
    anchored at the package root), or None (another package's file)."""
    pieces: list = []
    anchored = False

    def add(part, level: int) -> bool:
        nonlocal anchored
        if isinstance(part, str):
            pieces.append(part.strip("'\""))
        elif part[0] == "pkg":
            if package is not None and part[1] != package:
                return False  # another package's file
            pieces.clear()
            anchored = True
        elif part[0] == "arg" and part[1] in binding and level < 8:
            return all(add(p, level + 1) for p in binding[part[1]])
        elif part[0] == "arg":
            pieces.append(("cap", part[1]))
        else:
            pieces.append(ANY)
        return True

    if not all(add(part, 0) for part in parts):
        return None
    merged: list = []
    for piece in pieces:  # literals joined, "//" and a leading "/" dropped
        if isinstance(piece, str) and merged and isinstance(merged[-1], str):
            merged[-1] += piece
        elif piece != "":
            merged.append(piece)
    merged = [re.sub("/+", "/", p) if isinstance(p, str) else p for p in merged]
    if merged and isinstance(merged[0], str):
        merged[0] = merged[0].lstrip("/")
    return merged, anchored


MAX_TRIES = 10000  # split points tried when matching one path (a few captures at most)


def _match_path(pieces: list, rel: str, anchored: bool) -> dict[str, str] | None:
    """The launch arguments captured when ``pieces`` match all of ``rel`` (not anchored: any
    tail of it that starts a path part), or None."""
    starts = [0] if anchored else [0] + [i + 1 for i, c in enumerate(rel) if c == "/"]
    budget = [MAX_TRIES]
    for start in starts:
        found = _match(pieces, 0, rel[start:], {}, budget)
        if found is not None:
            return found
    return None


def _match(pieces: list, index: int, text: str, captured: dict[str, str],
           budget: list[int]) -> dict[str, str] | None:
    budget[0] -= 1
    if budget[0] < 0:
        return None
    if index == len(pieces):
        return captured if text == "" else None
    piece = pieces[index]
    if isinstance(piece, str):
        if not text.startswith(piece):
            return None
        return _match(pieces, index + 1, text[len(piece):], captured, budget)
    name = piece[1] if piece[0] == "cap" else None
    if name is not None and name in captured:  # the same argument again: the same text
        known = captured[name]
        return _match(pieces, index + 1, text[len(known):], captured, budget) \
            if text.startswith(known) else None
    end = text.find("/")
    limit = len(text) if end < 0 else end  # a substitution stays inside one path part
    for cut in range(0 if name is None else 1, limit + 1):
        found = _match(pieces, index + 1, text[cut:],
                       {**captured, name: text[:cut]} if name else captured, budget)
        if found is not None:
            return found
    return None


def _text(value: list, binding: dict[str, list], package: str | None, root: Path,
          depth: int, unquote: bool = True) -> str | None:
    """A value's text under ``binding``, or None when a part cannot be known (``unquote``:
    as a command line's word, see ``_unquote``)."""
    out = []
    for part in value:
        if isinstance(part, str):
            out.append(part)
        elif part[0] == "arg" and part[1] in binding and depth < 8:
            text = _text(binding[part[1]], binding, package, root, depth + 1)
            if text is None:
                return None
            out.append(text)
        elif part[0] == "pkg" and package is not None and part[1] == package:
            out.append(str(root))
        else:
            return None
    return _unquote("".join(out).strip()) if unquote else "".join(out)


def _unquote(text: str) -> str:
    """A launch value as the shell-like command line reads it: ``'""'`` and ``"''"`` are
    empty, surrounding quotes dropped."""
    while len(text) >= 2 and text[0] == text[-1] and text[0] in "'\"":
        text = text[1:-1]
    return text


# -- conditions -------------------------------------------------------------------------------
# a condition: ("if" | "unless", value parts) for an XML attribute or IfCondition(value), or
# ("if" | "unless", ("python", parts)) for IfCondition(PythonExpression(parts)); a command holds
# under a binding when one of its alternatives (a list of conditions) all hold


def _holds(alternatives: list[list], binding: dict[str, list], package: str | None,
           root: Path) -> bool:
    """Whether a command (or an argument declaration) is reached under ``binding``: some
    alternative whose conditions are all true or unknown."""
    return any(all(_truth(condition, binding, package, root) is not False
                   for condition in conditions) for conditions in alternatives)


def _truth(condition, binding: dict[str, list], package: str | None, root: Path) -> bool | None:
    """The value of one ``if``/``unless`` condition, or None when it cannot be known."""
    kind, value = condition
    if isinstance(value, tuple) and value[0] == "python":  # PythonExpression([...])
        text = _text(value[1], binding, package, root, 0, unquote=False)
        result = _evaluate(text, {}) if text is not None else None
    else:
        result = _condition_value(value, binding, package, root)
    if result is None:
        return None
    return result if kind == "if" else not result


def _condition_value(value, binding, package, root) -> bool | None:
    if len(value) == 1 and isinstance(value[0], tuple) and value[0][0] == "eval":
        arguments = {}
        for name in binding:
            text = _text(binding[name], binding, package, root, 0)
            if text is not None:
                arguments[name] = text
        return _evaluate(value[0][1], arguments)
    text = _text(value, binding, package, root, 0)
    if text is None:
        return None
    return _boolean(text)


def _boolean(text) -> bool | None:
    """A launch condition's text as launch reads it (true/false/1/0, any case)."""
    if isinstance(text, bool):
        return text
    lowered = str(text).strip().lower()
    if lowered in ("true", "1"):
        return True
    if lowered in ("false", "0"):
        return False
    return None


def _evaluate(expression: str, arguments: dict[str, str]) -> bool | None:
    """``$(eval EXPR)``/``PythonExpression`` by urdftool's interpreter (never ``eval``): the
    launch arguments by name and through ``arg('NAME')``; None when it cannot be evaluated."""
    import time

    from urdftool.xacro_eval import Interpreter

    def arg(name):
        return arguments[name]

    for name in re.findall(r"\$\((?:arg|var)\s+([^)\s]+)\s*\)", expression):
        if name not in arguments:
            return None
        expression = expression.replace(f"$(arg {name})", arguments[name]).replace(
            f"$(var {name})", arguments[name])
    try:
        value = Interpreter(time.monotonic() + 0.5).evaluate_substitution(
            expression, arguments, {"arg": arg})
    except Exception:  # noqa: BLE001 - an unknown name, a syntax error: not known
        return None
    if isinstance(value, str):
        return _boolean(value)
    return bool(value)


# -- Python launch files ------------------------------------------------------------------------


def _python(text: str) -> list[tuple[list, dict[str, list]]]:
    """(command line parts, launch argument binding) of every xacro invocation."""
    try:
        tree = ast.parse(text)
    except (SyntaxError, ValueError, RecursionError, MemoryError):
        return []
    reader = _PythonLaunch(tree)
    commands: list[tuple[list, list]] = []
    seen = set()
    for node in ast.walk(tree):
        parts = None
        if isinstance(node, ast.Call) and _called(node) == "process_file" and node.args:
            parts = reader.value(node.args[0])
            mappings = _keyword_node(node, "mappings")
            if parts is not None and isinstance(mappings, ast.Dict):
                for key, value in zip(mappings.keys, mappings.values):
                    name = reader.value(key) if key is not None else None
                    resolved = reader.value(value)
                    if name and all(isinstance(p, str) for p in name) and resolved is not None:
                        parts = [*parts, " ", "".join(name) + ":=", *resolved]
        elif isinstance(node, (ast.List, ast.Tuple)) or (
                isinstance(node, ast.Constant) and isinstance(node.value, str)
                and ".xacro" in node.value):
            parts = reader.value(node)
        if parts is not None and repr(parts) not in seen:
            seen.add(repr(parts))
            commands.append((parts, reader.conditions(node)))
    bindings = reader.bindings()
    return [(parts, binding) for parts, alternatives in commands for binding in bindings
            if _holds(alternatives, binding, None, Path())]


class _PythonLaunch:
    """What a Python launch file says, statically: its launch arguments' defaults and
    choices, and its variables assigned once."""

    def __init__(self, tree):
        self.tree = tree
        self.assigned: dict[str, list] = {}
        self.parents: dict[int, ast.AST] = {}
        self.uses: dict[str, list] = {}  # variable -> the nodes that read it
        for node in ast.walk(tree):
            for child in ast.iter_child_nodes(node):
                self.parents[id(child)] = node
            if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Load):
                self.uses.setdefault(node.id, []).append(node)
        for node in ast.walk(tree):
            if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(
                    node.targets[0], ast.Name):
                self.assigned.setdefault(node.targets[0].id, []).append(node.value)
            elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name) \
                    and node.value is not None:
                self.assigned.setdefault(node.target.id, []).append(node.value)
        self.defaults: dict[str, list] = {}
        self.choices: dict[str, list[str]] = {}
        for node in ast.walk(tree):
            if isinstance(node, ast.Call) and _called(node) == "DeclareLaunchArgument":
                name_node = node.args[0] if node.args else _keyword_node(node, "name")
                name = self.value(name_node) if name_node is not None else None
                if not name or not all(isinstance(p, str) for p in name):
                    continue
                name = "".join(name)
                default = _keyword_node(node, "default_value")
                if default is not None:
                    resolved = self.value(default, stop=name)
                    if resolved is not None:
                        self.defaults[name] = resolved
                choices = _keyword_node(node, "choices")
                if isinstance(choices, (ast.List, ast.Tuple)):
                    values = [_string(c) for c in choices.elts]
                    if values and all(v is not None for v in values):
                        self.choices[name] = values

    def value(self, node, depth: int = 0, stop: str | None = None) -> list | None:
        """A node's value as parts, or None when it cannot be known statically."""
        if depth > 16 or node is None:
            return None
        if isinstance(node, ast.Constant):
            if isinstance(node.value, str):
                return [node.value]
            if isinstance(node.value, (int, float)) and not isinstance(node.value, bool):
                return [str(node.value)]
            return None
        if isinstance(node, ast.Name):
            values = self.assigned.get(node.id, [])
            if len(values) != 1:  # a parameter, or assigned several times: not known
                return None
            return self.value(values[0], depth + 1)
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
            left, right = self.value(node.left, depth + 1), self.value(node.right, depth + 1)
            return left + right if left is not None and right is not None else None
        if isinstance(node, ast.JoinedStr):
            parts: list = []
            for piece in node.values:
                value = self.value(piece.value if isinstance(piece, ast.FormattedValue)
                                   else piece, depth + 1)
                if value is None:
                    return None
                parts.extend(value)
            return parts
        if isinstance(node, (ast.List, ast.Tuple)):
            parts = []
            for element in node.elts:
                value = self.value(element, depth + 1)
                parts.extend(value if value is not None else [ANY])
            return parts
        if isinstance(node, ast.Call):
            return self._call(node, depth, stop)
        return None

    def _call(self, node: ast.Call, depth: int, stop: str | None) -> list | None:
        called = _called(node)
        first = node.args[0] if node.args else next(
            (k.value for k in node.keywords if k.arg in ("package", "name", "text",
                                                          "variable_name")), None)
        if called == "LaunchConfiguration" and first is not None:
            name = self.value(first, depth + 1)
            if name and all(isinstance(p, str) for p in name):
                return [("arg", "".join(name))]
            return None
        if called in ("PathJoinSubstitution", "join") and node.args:
            items = first.elts if called == "PathJoinSubstitution" and isinstance(
                first, (ast.List, ast.Tuple)) else node.args
            parts = []
            for index, item in enumerate(items):
                value = self.value(item, depth + 1)
                if value is None:
                    return None
                parts.extend(([] if index == 0 else ["/"]) + value)
            return parts
        if called in ("FindPackageShare", "get_package_share_directory",
                      "get_package_share_path", "FindPackagePrefix", "find") \
                and first is not None:  # (the last: FindPackageShare(...).find(NAME))
            name = self.value(first, depth + 1)
            if name and all(isinstance(p, str) for p in name):
                return [("pkg", "".join(name))]
            return None
        if called in ("TextSubstitution",):
            return self.value(_keyword_node(node, "text") or first, depth + 1)
        if called in ("Command", "str", "ParameterValue") and first is not None:
            return self.value(first, depth + 1)
        if called == "FindExecutable":
            return [ANY]
        return None

    def conditions(self, node, depth: int = 0) -> list[list]:
        """The alternatives (lists of conditions, all of which must hold) under which ``node``
        is reached: the ``condition=IfCondition(...)``/``UnlessCondition(...)`` of the calls
        around it; where it is assigned to a variable, those around each use of it."""
        found: list = []
        while node is not None:
            parent = self.parents.get(id(node))
            if isinstance(node, ast.Call):
                condition = _keyword_node(node, "condition")
                if isinstance(condition, ast.Call) and _called(condition) in (
                        "IfCondition", "UnlessCondition") and condition.args:
                    kind = "if" if _called(condition) == "IfCondition" else "unless"
                    found.append((kind, self._condition_value(condition.args[0])))
            if (isinstance(parent, ast.Assign) and len(parent.targets) == 1
                    and isinstance(parent.targets[0], ast.Name) and depth < 4
                    and len(self.assigned.get(parent.targets[0].id, [])) == 1):
                uses = self.uses.get(parent.targets[0].id, [])
                if uses:
                    return [found + alternative for use in uses
                            for alternative in self.conditions(use, depth + 1)]
            node = parent
        return [found]

    def _condition_value(self, node):
        """IfCondition's argument: a PythonExpression's parts, or a value's parts (None
        parts: unknown, a condition that holds)."""
        if isinstance(node, ast.Call) and _called(node) == "PythonExpression" and node.args:
            parts = self.value(node.args[0])
            return ("python", parts) if parts is not None else [ANY]
        parts = self.value(node)
        return parts if parts is not None else [ANY]

    def bindings(self) -> list[dict[str, list]]:
        """The launch arguments' values: their defaults; a required one with choices, once
        per choice (at most MAX_SETS bindings)."""
        bindings = [dict(self.defaults)]
        for name, values in self.choices.items():
            if name in self.defaults:
                continue
            bindings = [{**b, name: [v]} for b in bindings for v in values][:MAX_SETS]
        return bindings


def _called(node: ast.Call) -> str:
    func = node.func
    return func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")


def _string(node) -> str | None:
    return node.value if isinstance(node, ast.Constant) and isinstance(node.value, str) else None


def _keyword_node(node: ast.Call, name: str):
    return next((k.value for k in node.keywords if k.arg == name), None)


# -- XML launch files ---------------------------------------------------------------------------


class _XmlLaunch:
    """An XML launch file: its arguments (defaults, fixed values), the launch files it
    includes with what it passes them, and the attributes that name a xacro file."""

    def __init__(self, text: str):
        self.defaults: dict[str, list] = {}
        self.fixed: set[str] = set()
        self.includes: list[tuple[str, dict[str, list], bool, list]] = []
        # the parts of every attribute naming a .xacro, with the conditions it is under
        self.commands: list[tuple[list, list]] = []
        # every <arg> with a value: (name, parts, fixed, conditions), in the file's order
        self.declared: list[tuple[str, list, bool, list]] = []
        root = _parse_xml(text)
        if root is None:
            return
        for arg in root.iter("arg"):
            parent = arg.getparent()
            if parent is not None and parent.tag == "include":
                continue
            name = arg.get("name")
            value = arg.get("value", arg.get("default"))
            if name and value is not None:
                fixed = arg.get("value") is not None
                self.declared.append((name, _xml_parts(value), fixed, _xml_conditions(arg)))
                if fixed:
                    self.fixed.add(name)
        self.defaults = self.values({})
        for include in root.iter("include"):
            file = include.get("file", "")
            passed = {a.get("name"): _xml_parts(a.get("value", a.get("default", "")))
                      for a in include.iter("arg") if a.get("name")}
            all_args = include.get("pass_all_args", "").strip().lower() in ("true", "1")
            name = re.split(r"[/)]", file)[-1].strip()
            if name:
                self.includes.append((name, passed, all_args, _xml_conditions(include)))
        for element in root.iter():
            if not isinstance(element.tag, str) or element.tag in ("arg", "include"):
                continue
            for value in element.attrib.values():
                if ".xacro" in value:
                    self.commands.append((_xml_parts(value), _xml_conditions(element)))

    def values(self, passed: dict[str, list], package: str | None = None,
               root: Path | None = None) -> dict[str, list]:
        """The arguments' values when an includer passes ``passed``: in the file's order,
        a declaration whose ``if``/``unless`` is false is not made; a passed value replaces
        a default, never a fixed ``value``."""
        binding: dict[str, list] = {}
        for name, parts, fixed, conditions in self.declared:
            if conditions and not _holds([conditions], {**binding, **passed}, package,
                                         root or Path()):
                continue
            binding[name] = parts if fixed or name not in passed else passed[name]
        return binding


def _parse_xml(text: str):
    from lxml import etree

    from urdftool.xmlrepair import secure_parser

    try:
        root = etree.fromstring(text.encode("utf-8"), secure_parser())
    except (etree.XMLSyntaxError, ValueError):
        return None
    if root is None:
        return None
    info = root.getroottree().docinfo
    if info.system_url or info.public_id or (
            info.internalDTD is not None and any(info.internalDTD.iterentities())):
        return None  # entities are never expanded: the file is not read (as xacro does)
    return root


def _inside_command(value: str) -> str:
    """The command line of ``$(command 'LINE')`` (else ``value``), found without a regex."""
    stripped = value.strip()
    if not stripped.startswith("$(command") or not stripped.endswith(")"):
        return value
    body = stripped[len("$(command"):-1].strip()
    if len(body) >= 2 and body[0] in "'\"" and body[-1] == body[0]:
        return body[1:-1]
    return body


def _xml_conditions(element) -> list:
    """The ``if``/``unless`` conditions of ``element`` and of the elements around it."""
    conditions = []
    while element is not None and isinstance(element.tag, str):
        for kind in ("if", "unless"):
            value = element.get(kind)
            if value is not None:
                stripped = value.strip()
                if stripped.startswith("$(eval") and stripped.endswith(")"):
                    conditions.append((kind, [("eval", stripped[len("$(eval"):-1].strip())]))
                else:
                    conditions.append((kind, _xml_parts(value)))
        element = element.getparent()
    return conditions


def _xml_parts(value: str) -> list:
    """``$(arg X)``/``$(var X)`` as launch arguments, ``$(find P)`` as a package, any other
    substitution unknown."""
    # ROS 2: value="$(command 'xacro FILE NAME:=VALUE')": the command line inside
    value = _inside_command(value)
    parts: list = []
    last = 0
    for match in _SUBSTITUTION.finditer(value):
        if match.start() > last:
            parts.append(value[last:match.start()])
        kind, name = match.group(1), match.group(2).strip()
        if kind in ("arg", "var"):
            parts.append(("arg", name))
        elif kind in ("find", "find-pkg-share"):
            parts.append(("pkg", name))
        else:
            parts.append(ANY)
        last = match.end()
    if last < len(value):
        parts.append(value[last:])
    return parts


def _xml_bindings(path: Path, launches: dict[Path, _XmlLaunch]) -> list[dict[str, list]]:
    """The argument values a launch file runs with: its defaults; when other launch files
    include it, once per includer, with what that one passes (resolved in the includer's
    own defaults)."""
    own = launches[path]
    bindings = []
    for other_path, other in launches.items():
        if other_path == path:
            continue
        for name, passed, all_args, conditions in other.includes:
            if name != path.name:
                continue
            outer = dict(other.defaults)
            if conditions and not _holds([conditions], outer, None, Path()):
                continue  # an <include if="..."> that is not made
            given = {k: v for k, v in outer.items() if k not in own.fixed} if all_args else {}
            given.update({key: _bind(value, outer) for key, value in passed.items()
                          if key not in own.fixed})
            binding = own.values(given)
            binding.update({k: v for k, v in given.items() if k not in binding})
            bindings.append(binding)
    return bindings[:MAX_SETS] if bindings else [dict(own.defaults)]


def _bind(value: list, outer: dict[str, list], depth: int = 0) -> list:
    """``value`` with the includer's arguments replaced by their values."""
    parts: list = []
    for part in value:
        if isinstance(part, tuple) and part[0] == "arg" and part[1] in outer and depth < 8:
            parts.extend(_bind(outer[part[1]], outer, depth + 1))
        else:
            parts.append(part)
    return parts
