"""Rules of the `structure` family: the kinematic tree.

A URDF robot is a tree of links joined by joints: names unique, every joint's parent and child
defined, one root link (the only link that is no joint's child), every link reachable from it,
no link with two parents, no loops. urdfdom rejects the whole robot when any of this fails, so
these are errors. Everything here reads the model (``robot.links``, ``robot.joints``, in document
order, duplicates kept); the joint's ``<parent>``/``<child>`` elements are looked up in
``robot.root`` only to point at the exact line. SDF inputs are the sdf family's business.
"""

from __future__ import annotations

import functools
from collections.abc import Iterator

from urdftool.findings import Finding
from urdftool.rules import Names, did_you_mean, lost, rule, value_edits


def _urdf_only(check):
    """SDF inputs are checked on the SDF itself by the sdf family (duplicate names, loops,
    disconnected links); the URDF converted from them is made a tree on purpose."""

    @functools.wraps(check)
    def run(robot):
        if robot.source.kind == "sdf":
            return iter(())
        return check(robot)

    return run


def _joint_elements(robot) -> list[tuple[object, object]]:
    """(model joint, lxml <joint> element) pairs, in document order."""
    elements = robot.elements("joint")
    if len(elements) != len(robot.joints):
        return [(joint, None) for joint in robot.joints]
    return list(zip(robot.joints, elements))


def _end_loc(robot, joint, element, end: str):
    """Where a joint's <parent> or <child> is written (the joint's place if not found)."""
    if element is not None:
        for child in element:
            if child.tag == end:
                return robot.loc(child)
    return joint.loc


def _line(loc) -> str:
    return f"line {loc.line}" if loc is not None and loc.line else "earlier"


def _link_names(robot) -> list[str]:
    return [link.name for link in robot.links if link.name is not None]


_ROBOT = '<robot name="r">\n{}\n</robot>'
_TWO_LINKS = ('  <link name="base"/>\n  <link name="arm"/>\n'
              '  <joint name="j" type="fixed">\n    <parent link="base"/>\n'
              '    <child link="arm"/>\n  </joint>')


@rule("structure.no-name", "error", "the robot has no name",
      doc="""
`<robot name="...">` is required: urdfdom rejects a robot without a name ("No name given for
the robot"), and ROS tools use it as the model's name. An empty name is accepted by urdfdom
but names nothing; it is a warning.
""",
      bad='<robot>\n  <link name="base"/>\n</robot>',
      good='<robot name="r">\n  <link name="base"/>\n</robot>')
@_urdf_only
def no_name(robot) -> Iterator[Finding]:
    root = robot.root
    if root is None or root.tag != "robot":
        return
    name = root.get("name")
    if name is None:
        yield Finding("<robot> has no name: urdfdom rejects the robot", robot.loc(root),
                      hint='add name="my_robot" to <robot>')
    elif not name.strip():
        yield Finding("<robot> has an empty name", robot.loc(root),
                      hint='give the robot a name: <robot name="my_robot">', severity="warning")


@rule("structure.no-links", "error", "the robot has no links",
      doc="""
A robot is made of links; urdfdom rejects a `<robot>` without any ("No link elements found").
Usually the links sit in a macro that is never called, or in a file that is not included.
""",
      bad='<robot name="r">\n  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>\n'
          '</robot>',
      good='<robot name="r">\n  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>\n'
           '  <link name="base"/>\n</robot>')
@_urdf_only
def no_links(robot) -> Iterator[Finding]:
    root = robot.root
    if root is None or root.tag != "robot" or robot.links:
        return
    yield Finding("the robot has no <link>: urdfdom rejects it", robot.loc(root),
                  hint='add at least one <link name="base_link"/>')


def _duplicates(items, kind: str) -> Iterator[Finding]:
    first: dict[str, object] = {}
    for item in items:
        if item.name is None:
            continue
        if item.name in first:
            earlier = first[item.name].loc
            yield Finding(f"{kind} '{item.name}' is defined twice (first at {_line(earlier)}): "
                          "urdfdom rejects the robot", item.loc,
                          hint=f"rename or remove one of the two {kind}s '{item.name}'")
        else:
            first[item.name] = item


@rule("structure.duplicate-link", "error", "two links with the same name",
      doc="""
Link names identify links: joints, Gazebo references and transmissions point at them by name.
urdfdom rejects a robot with two links of one name ("link 'x' is not unique"). In xacro this
usually comes from calling a macro twice with the same prefix.
""",
      bad=_ROBOT.format('  <link name="base"/>\n  <link name="base"/>'),
      good=_ROBOT.format('  <link name="base"/>'))
@_urdf_only
def duplicate_link(robot) -> Iterator[Finding]:
    return _duplicates(robot.links, "link")


@rule("structure.duplicate-joint", "error", "two joints with the same name",
      doc="""
Joint names identify joints for controllers, transmissions, mimics and joint states. urdfdom
rejects a robot with two joints of one name ("joint 'x' is not unique").
""",
      bad=_ROBOT.format('  <link name="base"/>\n  <link name="a"/>\n  <link name="b"/>\n'
                        '  <joint name="j" type="fixed"><parent link="base"/>'
                        '<child link="a"/></joint>\n'
                        '  <joint name="j" type="fixed"><parent link="base"/>'
                        '<child link="b"/></joint>'),
      good=_ROBOT.format('  <link name="base"/>\n  <link name="a"/>\n  <link name="b"/>\n'
                         '  <joint name="ja" type="fixed"><parent link="base"/>'
                         '<child link="a"/></joint>\n'
                         '  <joint name="jb" type="fixed"><parent link="base"/>'
                         '<child link="b"/></joint>'))
@_urdf_only
def duplicate_joint(robot) -> Iterator[Finding]:
    return _duplicates(robot.joints, "joint")


@rule("structure.missing-link", "error", "a joint names a parent or child link that is not defined",
      doc="""
Every link a joint refers to must be defined with `<link name="...">`. urdfdom rejects the
robot otherwise ("child link [x] of joint [j] not found"). The usual causes are a typo, a
prefix that differs between the link and the joint, or a link in a macro that is not called.
The message suggests the closest defined link name.
""",
      bad=_ROBOT.format('  <link name="base_link"/>\n  <link name="arm"/>\n'
                        '  <joint name="j" type="fixed">\n    <parent link="base_lnk"/>\n'
                        '    <child link="arm"/>\n  </joint>'),
      good=_ROBOT.format('  <link name="base_link"/>\n  <link name="arm"/>\n'
                         '  <joint name="j" type="fixed">\n    <parent link="base_link"/>\n'
                         '    <child link="arm"/>\n  </joint>'),
      fix="safe")
@_urdf_only
def missing_link(robot) -> Iterator[Finding]:
    names = _link_names(robot)
    known = set(names)
    candidates = Names(names)
    children = {j.child for j in robot.joints}
    for joint, element in _joint_elements(robot):
        for end, name in (("parent", joint.parent), ("child", joint.child)):
            if name is None or name in known or lost(robot, name):
                continue
            close = candidates.close(name)
            match = [close] if close is not None else []
            message = f"joint '{joint.name}': {end} link '{name}' is not defined"
            loc = _end_loc(robot, joint, element, end)
            edits, note = (), ""
            if match:
                message += f"; did you mean '{match[0]}'?"
                # the typo mended when it is one (did_you_mean), unless the link named then
                # gets a second parent or closes a loop
                new = did_you_mean(name, candidates)
                under = _below(robot, joint.child) if end == "parent" else set()
                if new == match[0] and (
                        under is not None and new not in under if end == "parent"
                        else new != joint.parent and new not in children):
                    edits, note = value_edits(robot, loc, (end,), {"link": new})
            if end == "parent" and joint.child in known:
                under = _below(robot, joint.child)
                if under is None:
                    message += ("; the links below it are cut off from the root by this (not "
                                "counted: too many such joints in one file)")
                else:
                    below = sorted(under & known)
                    message += (f"; the {len(below)} link(s) below it ({_names(below)}) are "
                                "cut off from the root by this")
            yield Finding(message, loc,
                          hint=(f'write <{end} link="{match[0]}"/>' + note) if match
                          else f'define <link name="{name}"/> or name an existing link',
                          edits=edits)


def _names(names: list[str], most: int = 3) -> str:
    shown = ", ".join(f"'{n}'" for n in names[:most])
    return shown + (f" and {len(names) - most} more" if len(names) > most else "")


# links ``_below`` may visit in all for one robot (issue 28: a walk per joint whose parent is
# undefined is quadratic in a chain of them); past it, None: not counted, said so
BELOW_VISITS = 200_000


def _below(robot, link: str | None) -> set | None:
    """``link`` and every link below it (through the joints' parent -> child); None once
    the robot's walks have visited BELOW_VISITS links."""
    children = robot.memo.get("child_links")
    if children is None:  # made once per robot (issue 28: once per finding was quadratic)
        children = robot.memo["child_links"] = {}
        for joint in robot.joints:
            children.setdefault(joint.parent, []).append(joint.child)
        robot.memo["below_left"] = BELOW_VISITS
    known = robot.memo.setdefault("below", {})
    if link in known:
        return known[link]
    left = robot.memo["below_left"]
    found, pending = set(), [link]
    while pending and left > 0:
        current = pending.pop()
        if current not in found:
            found.add(current)
            left -= 1
            pending.extend(children.get(current, ()))
    robot.memo["below_left"] = left
    known[link] = None if pending else found
    return known[link]


@rule("structure.self-joint", "error", "a joint whose parent and child are the same link",
      doc="""
A joint connects two different links. With `<parent link="a"/>` and `<child link="a"/>` the
link is its own parent: there is no root any more and urdfdom rejects the robot.
""",
      bad=_ROBOT.format('  <link name="base"/>\n  <link name="arm"/>\n'
                        '  <joint name="j" type="fixed">\n    <parent link="arm"/>\n'
                        '    <child link="arm"/>\n  </joint>'),
      good=_ROBOT.format(_TWO_LINKS))
@_urdf_only
def self_joint(robot) -> Iterator[Finding]:
    for joint, element in _joint_elements(robot):
        if joint.parent is not None and joint.parent == joint.child:
            yield Finding(f"joint '{joint.name}' connects link '{joint.parent}' to itself",
                          _end_loc(robot, joint, element, "child"),
                          hint="the child must be another link")


@rule("structure.two-parents", "error", "a link that is the child of two joints",
      doc="""
In a tree every link but the root has exactly one parent joint. A link that is the child of two
joints closes a kinematic loop, which URDF cannot express; urdfdom rejects the robot. Model the
closed chain with one joint cut open (and a constraint in the simulator), or give the second
joint its own child link.
""",
      bad=_ROBOT.format('  <link name="base"/>\n  <link name="a"/>\n  <link name="b"/>\n'
                        '  <joint name="j1" type="fixed"><parent link="base"/>'
                        '<child link="a"/></joint>\n'
                        '  <joint name="j2" type="fixed"><parent link="base"/>'
                        '<child link="b"/></joint>\n'
                        '  <joint name="j3" type="fixed"><parent link="a"/>'
                        '<child link="b"/></joint>'),
      good=_ROBOT.format('  <link name="base"/>\n  <link name="a"/>\n  <link name="b"/>\n'
                         '  <joint name="j1" type="fixed"><parent link="base"/>'
                         '<child link="a"/></joint>\n'
                         '  <joint name="j3" type="fixed"><parent link="a"/>'
                         '<child link="b"/></joint>'))
@_urdf_only
def two_parents(robot) -> Iterator[Finding]:
    first: dict[str, object] = {}
    for joint, element in _joint_elements(robot):
        if joint.child is None:
            continue
        if joint.child in first:
            earlier = first[joint.child]
            yield Finding(f"link '{joint.child}' is the child of joint '{earlier.name}' "
                          f"({_line(earlier.loc)}) and again of joint '{joint.name}'",
                          _end_loc(robot, joint, element, "child"),
                          hint="a link has one parent joint: remove one joint or give it "
                          "another child link")
        else:
            first[joint.child] = joint


_last_cycles: tuple[object, list[list[object]]] | None = None


def _cycles(robot) -> list[list[object]]:
    """Kinematic loops as lists of joints (parent -> child order), one per loop (two rules ask:
    found once for the last robot)."""
    global _last_cycles
    if _last_cycles is None or _last_cycles[0] is not robot:
        _last_cycles = (robot, _find_cycles(robot))
    return [list(cycle) for cycle in _last_cycles[1]]


def _find_cycles(robot) -> list[list[object]]:
    edges: dict[str, list[object]] = {}
    for joint in robot.joints:
        if joint.parent is None or joint.child is None or joint.parent == joint.child:
            continue
        edges.setdefault(joint.parent, []).append(joint)
    # Tarjan's strongly connected components, iteratively.
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    components: list[set[str]] = []
    nodes = list(dict.fromkeys([j.parent for j in robot.joints if j.parent] +
                               [j.child for j in robot.joints if j.child]))
    counter = 0
    for start in nodes:
        if start in index:
            continue
        work = [(start, 0)]
        while work:
            node, position = work.pop()
            if position == 0:
                index[node] = low[node] = counter
                counter += 1
                stack.append(node)
                on_stack.add(node)
            children = edges.get(node, [])
            if position < len(children):
                work.append((node, position + 1))
                child = children[position].child
                if child not in index:
                    work.append((child, 0))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            if low[node] == index[node]:
                component = set()
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.add(member)
                    if member == node:
                        break
                if len(component) > 1:
                    components.append(component)
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
    loops = []
    for component in components:
        # Walk parent -> child inside the component until a link repeats.
        start = min(component, key=nodes.index)
        path: list[object] = []
        seen = {start: 0}
        node = start
        while True:
            joint = next(j for j in edges[node] if j.child in component)
            path.append(joint)
            node = joint.child
            if node in seen:
                loops.append(path[seen[node]:])
                break
            seen[node] = len(path)
    return loops


def _loop_text(loop: list[object]) -> str:
    links = " -> ".join([loop[0].parent] + [j.child for j in loop])
    joints = ", ".join(f"'{j.name}'" for j in loop)
    return f"{links} (joints {joints})"


@rule("structure.loop", "error", "joints that form a closed loop",
      doc="""
Following joints from parent to child must never come back to a link already visited: URDF is
a tree. A loop leaves no root link, and urdfdom rejects the robot ("No root link found"; some
versions never return). The message names the links and joints of the loop.
""",
      bad=_ROBOT.format('  <link name="base"/>\n  <link name="a"/>\n  <link name="b"/>\n'
                        '  <joint name="j1" type="fixed"><parent link="base"/>'
                        '<child link="a"/></joint>\n'
                        '  <joint name="j2" type="fixed"><parent link="a"/>'
                        '<child link="b"/></joint>\n'
                        '  <joint name="j3" type="fixed"><parent link="b"/>'
                        '<child link="a"/></joint>'),
      good=_ROBOT.format('  <link name="base"/>\n  <link name="a"/>\n  <link name="b"/>\n'
                         '  <joint name="j1" type="fixed"><parent link="base"/>'
                         '<child link="a"/></joint>\n'
                         '  <joint name="j2" type="fixed"><parent link="a"/>'
                         '<child link="b"/></joint>'))
@_urdf_only
def loop(robot) -> Iterator[Finding]:
    order = {id(j): i for i, j in enumerate(robot.joints)}
    for cycle in _cycles(robot):
        closing = max(cycle, key=lambda j: order[id(j)])
        yield Finding(f"kinematic loop: {_loop_text(cycle)}", closing.loc,
                      hint=f"URDF is a tree: remove joint '{closing.name}' or give it a new "
                      "child link")


def _trees(robot) -> tuple[list[str], list[str], dict[str, int]]:
    """(roots that have child joints, links in no joint at all, size of each root's tree)."""
    roots = list(dict.fromkeys(robot.roots()))  # a duplicated link is one root
    in_joint = {j.parent for j in robot.joints} | {j.child for j in robot.joints}
    connected = [r for r in roots if r in in_joint]
    isolated = [r for r in roots if r not in in_joint]
    sizes = {root: len(_reachable(robot, [root])) for root in connected}
    return connected, isolated, sizes


def _reachable(robot, roots: list[str]) -> set[str]:
    children: dict[str, list[str]] = {}
    for joint in robot.joints:
        if joint.parent is not None and joint.child is not None:
            children.setdefault(joint.parent, []).append(joint.child)
    seen = set(roots)
    todo = list(roots)
    while todo:
        for child in children.get(todo.pop(), []):
            if child not in seen:
                seen.add(child)
                todo.append(child)
    return seen


@rule("structure.multiple-roots", "error", "more than one root link (several separate trees)",
      doc="""
The root is the one link that is no joint's child. With two or more, the robot falls apart
into separate trees and urdfdom rejects it ("Two root links found"). Usually a joint is missing,
or a joint's parent/child names a link of the other tree wrongly. Links that take part in no
joint at all are reported by `structure.orphan-link`.
""",
      bad=_ROBOT.format('  <link name="base"/>\n  <link name="arm"/>\n'
                        '  <link name="cart"/>\n  <link name="wheel"/>\n'
                        '  <joint name="j1" type="fixed"><parent link="base"/>'
                        '<child link="arm"/></joint>\n'
                        '  <joint name="j2" type="continuous"><parent link="cart"/>'
                        '<child link="wheel"/></joint>'),
      good=_ROBOT.format('  <link name="base"/>\n  <link name="arm"/>\n'
                         '  <link name="cart"/>\n  <link name="wheel"/>\n'
                         '  <joint name="j1" type="fixed"><parent link="base"/>'
                         '<child link="arm"/></joint>\n'
                         '  <joint name="j0" type="fixed"><parent link="base"/>'
                         '<child link="cart"/></joint>\n'
                         '  <joint name="j2" type="continuous"><parent link="cart"/>'
                         '<child link="wheel"/></joint>'))
@_urdf_only
def multiple_roots(robot) -> Iterator[Finding]:
    connected, isolated, sizes = _trees(robot)
    if not connected:
        roots = isolated  # no joints at all: every link is a root
        if len(roots) > 1:
            second = robot.link(roots[1])
            yield Finding(f"{len(roots)} root links and no joint: "
                          + ", ".join(f"'{r}'" for r in roots),
                          second.loc if second else None,
                          hint="connect the links with joints, one link being the root")
        return
    if len(connected) > 1:
        described = ", ".join(f"'{r}' ({sizes[r]} links)" for r in connected)
        second = robot.link(connected[1])
        yield Finding(f"{len(connected)} root links, the robot is {len(connected)} separate "
                      f"trees: {described}", second.loc if second else None,
                      hint=f"add a joint that attaches '{connected[1]}' to a link of the "
                      f"'{connected[0]}' tree")


@rule("structure.orphan-link", "error", "a link that is not connected to the root",
      doc="""
Every link must be reachable from the root link through joints. A link that no joint mentions
floats on its own (urdfdom sees it as a second root and rejects the robot); a link whose parent
joint hangs from an undefined link, or below a loop, is cut off too. Attach it with a joint or
delete it.
""",
      bad=_ROBOT.format(_TWO_LINKS + '\n  <link name="camera"/>'),
      good=_ROBOT.format(_TWO_LINKS + '\n  <link name="camera"/>\n'
                         '  <joint name="camera_joint" type="fixed"><parent link="arm"/>'
                         '<child link="camera"/></joint>'))
@_urdf_only
def orphan_link(robot) -> Iterator[Finding]:
    connected, isolated, _ = _trees(robot)
    if not robot.joints:
        return  # no joints at all: multiple-roots says it
    roots = connected or isolated
    if not roots:
        return  # every link is a child: the loop rule says why
    main = roots[0]
    isolated = [name for name in isolated if name != main]
    for name in isolated:
        link = robot.link(name)
        yield Finding(f"link '{name}' is connected to no joint: it is not part of the tree "
                      f"rooted at '{main}'", link.loc if link else None,
                      hint=f'attach it: <joint name="{name}_joint" type="fixed"><parent '
                      f'link="..."/><child link="{name}"/></joint>, or remove it')
    reachable = _reachable(robot, [main] + connected)
    on_loop = {j.child for cycle in _cycles(robot) for j in cycle}
    known = set(_link_names(robot))
    seen: set[str] = set()
    for link in robot.links:
        name = link.name
        if name is None or name in reachable or name in isolated or name in on_loop \
                or name in seen:
            continue
        seen.add(name)
        reason = _cut_off_reason(robot, name, known, on_loop)
        if reason is None:
            continue  # one finding per cause: missing-link or loop names it and counts this
        yield Finding(f"link '{name}' is not reachable from the root '{main}': {reason}",
                      link.loc, hint="fix the joint chain above it")


def _cut_off_reason(robot, name: str, known: set[str], on_loop: set[str]) -> str | None:
    """Why a link with a parent joint is still cut off from the root; None when it hangs below
    an undefined link or a loop (``structure.missing-link`` or ``structure.loop`` reports that
    cause, with the links it cuts off)."""
    memo = robot.memo.setdefault("cut_off_reasons", {})  # each link's walk is its parent's
    node, visited, path = name, {name}, []
    while True:  # (issue 28: a walk to the top per link was quadratic in a long chain)
        if node in memo:
            reason = memo[node]
            break
        path.append(node)
        joint = robot.parent_joint(node)
        if joint is None or joint.parent is None:
            reason = "its chain of parent joints does not reach the root"
            break
        if joint.parent not in known or joint.parent in on_loop:
            reason = None
            break
        if joint.parent in visited:
            reason = "its chain of parent joints runs in a circle"
            break
        visited.add(joint.parent)
        node = joint.parent
    for walked in path:
        memo[walked] = reason
    return reason
