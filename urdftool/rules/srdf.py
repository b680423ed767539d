"""Rule family ``srdf`` (issue 31): a MoveIt SRDF against the URDF it describes. Each rule is
given the ``companion.Srdf`` (the SRDF's records, located in the SRDF or its xacro files, and
the robot's model).

Severity follows what MoveIt does with the defect, read in its sources: srdfdom
(``src/model.cpp``, ``srdf::Model::initXml`` and its ``load*`` functions) logs and skips every
name the URDF lacks; moveit_core (``robot_model/src/robot_model.cpp``: ``buildGroups``,
``addJointModelGroup``, ``buildGroupStates``, ``buildGroupsInfoEndEffectors``, and
``RobotModel::buildModel`` for the virtual joint) builds groups, states and end effectors from
what is left. What MoveIt refuses or drops (a group, a chain, a state, an end effector, the
virtual joint), and a planner allowed to collide, is an error; a likely mistake whose outcome
is harmless is a warning."""

from __future__ import annotations

from urdftool.findings import Finding
from urdftool.rules import rename_edits, rule

# the robot the examples below are checked against (``tests/test_rule_docs.py`` writes it
# beside the SRDF): a two-joint arm with box collisions; for |joint2| above about 2.4 its
# forearm folds back into the base (``tests/test_srdf.py`` computes where)
EXAMPLE_ROBOT = """<robot name="arm">
  <link name="base_link"><collision><origin xyz="0 0 0.05"/><geometry><box size="0.4 0.4 0.1"/></geometry></collision></link>
  <link name="upper_arm"><collision><origin xyz="0 0 0.15"/><geometry><box size="0.06 0.06 0.3"/></geometry></collision></link>
  <link name="forearm"><collision><origin xyz="0 0 0.2"/><geometry><box size="0.06 0.06 0.4"/></geometry></collision></link>
  <link name="tool0"/>
  <joint name="joint1" type="revolute"><parent link="base_link"/><child link="upper_arm"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-3.14" upper="3.14" effort="10" velocity="1"/></joint>
  <joint name="joint2" type="revolute"><parent link="upper_arm"/><child link="forearm"/><origin xyz="0 0 0.3"/><axis xyz="0 1 0"/><limit lower="-2.8" upper="2.8" effort="10" velocity="1"/></joint>
  <joint name="tool_joint" type="fixed"><parent link="forearm"/><child link="tool0"/><origin xyz="0 0 0.4"/></joint>
</robot>"""

_HEAD = '<robot name="arm">\n  <group name="arm"><chain base_link="base_link" tip_link="tool0"/></group>\n'


def _example(body: str) -> str:
    return _HEAD + body + "\n</robot>"


MOVEIT = ("MoveIt's srdfdom (src/model.cpp) logs '{}' and skips it")


def _known_joints(srdf) -> set[str]:
    """Joint names MoveIt knows: the URDF's and the SRDF's virtual joints."""
    names = {j.name for j in srdf.robot.joints if j.name}
    names.update(v.name for v in srdf.virtual_joints if v.name)
    return names


def _links(srdf) -> list[str]:
    return [link.name for link in srdf.robot.links if link.name]


def _rename(srdf, ref, candidates):
    """``rules.rename_edits`` for a name an SRDF element gives, kept only when each edit
    replaces that very name (two elements of one tag on one line are told apart by their line
    only: the edit could land on the other)."""
    edits, new, note = rename_edits(srdf, ref.loc, ref.tag, ref.attribute, ref.name, candidates)
    for edit in edits:
        lines = srdf.source.texts.get(edit.path, "").split("\n")
        if edit.line != edit.end_line or not 0 < edit.line <= len(lines) or \
                lines[edit.line - 1][edit.column - 1:edit.end_column - 1] != ref.name:
            return (), new, note
    return edits, new, note


def _unknown(srdf, ref, candidates, what: str, where: str, severity: str | None, consequence: str):
    edits, new, note = _rename(srdf, ref, candidates)
    hint = f"did you mean '{new}'?{note}" if new else \
        f"name a {what} of {srdf.robot_path} (robot '{srdf.robot.name}')"
    return Finding(f"{where}: {what} '{ref.name}' is not in the URDF ({srdf.robot_path}); "
                   f"{consequence}", ref.loc, hint=hint, severity=severity, edits=edits)


@rule("srdf.no-robot", "warning", "the SRDF's robot could not be found or read",
      doc="""An SRDF is checked against the URDF its MoveIt configuration names: the
`.setup_assistant` file of its package (`URDF: package`, `relative_path`, `xacro_args`), an
entry `srdf = [{ file = "...", robot = "...", args = {...} }]` in `urdftool.toml`, or
`urdftool check ROBOT.srdf --robot ROBOT.urdf.xacro`. When none names one, or the one named
cannot be read, nothing else of the SRDF is checked: this finding says which robot was looked
for and how to name it. (The robot's own errors are reported where the robot is checked.)
The examples: the same SRDF checked without, then with `--robot robot.urdf`.""",
      bad=_example(""), good=_example("  <!-- checked with --robot robot.urdf -->"), on="srdf")
def no_robot(srdf):
    if srdf.missing:
        yield Finding(srdf.missing, srdf.loc, hint=srdf.missing_hint)


@rule("srdf.robot-name", "warning", "the SRDF names another robot than the URDF",
      doc="""srdfdom compares `<robot name>` of the SRDF with the URDF's and logs "Semantic
description is not specified for the same robot as the URDF", then goes on: harmless for
MoveIt, but the SRDF was probably written for another robot (or the robot was renamed), and
its names should be checked.""",
      bad='<robot name="other">\n  <group name="arm"><chain base_link="base_link" tip_link="tool0"/></group>\n</robot>',
      good=_example(""), on="srdf")
def robot_name(srdf):
    if srdf.name and srdf.robot.name and srdf.name.strip() != srdf.robot.name.strip() \
            and "$" not in srdf.name:
        yield Finding(f"the SRDF is for robot '{srdf.name}', the URDF ({srdf.robot_path}) is "
                      f"'{srdf.robot.name}'", srdf.loc,
                      hint=f"name the robot '{srdf.robot.name}' (or pair the SRDF with the URDF "
                           "it was written for)")


@rule("srdf.unknown-link", "error", "an SRDF names a link the URDF does not have",
      doc="""srdfdom checks every link name against the URDF and skips what it lacks, with a log
line and no file or line: "Link 'x' declared as part of group 'g' is not known to the URDF",
"Link 'x' declared as part of a chain in group 'g' is not known to the URDF" (the chain is
dropped), "Link 'x' specified as parent for end effector 'e' is not known to the URDF" (the end
effector is dropped), "Virtual joint does not attach to a link on the robot" (the virtual joint
is dropped). Those are errors: the group, chain, end effector or virtual joint MoveIt plans
with is not the one written. In `<disable_collisions>`, `<enable_collisions>`,
`<disable_default_collisions>` and `<link_sphere_approximation>` srdfdom logs "Link 'x' is not
known to URDF. Cannot disable collisions" and skips the entry: harmless for the planner
(there is no such link to collide), a warning. The fix renames the link when one name of the
URDF is clearly meant.""",
      bad=_example('  <disable_collisions link1="base_link" link2="uper_arm" reason="Adjacent"/>'),
      good=_example('  <disable_collisions link1="base_link" link2="upper_arm" reason="Adjacent"/>'),
      fix="safe", on="srdf")
def unknown_link(srdf):
    places = []
    for group in srdf.groups:
        places += [(ref, f"group '{group.name}'", None, "MoveIt leaves it out of the group")
                   for ref in group.links]
        places += [(ref, f"chain of group '{group.name}'", None, "MoveIt drops the chain")
                   for chain in group.chains for ref in (chain.base, chain.tip)]
    places += [(eef.parent_link, f"end effector '{eef.name}'", None,
                "MoveIt drops the end effector") for eef in srdf.end_effectors]
    places += [(virtual.child, f"virtual joint '{virtual.name}'", None,
                "MoveIt drops the virtual joint") for virtual in srdf.virtual_joints]
    places += [(ref, f"<{ref.tag}>", "warning",
                "MoveIt skips the entry ('Cannot disable collisions')")
               for pair in srdf.pairs for ref in (pair.link1, pair.link2)]
    places += [(ref, f"<{ref.tag}>", "warning", "MoveIt skips the entry")
               for ref in (*srdf.default_disabled, *srdf.spheres)]
    return _unknown_names(srdf, "link", _links(srdf), places)


def _unknown_names(srdf, what: str, known, places):
    """The findings of the names among ``places`` ((ref, where, severity, consequence)) that
    ``known`` lacks (names written for substitution, with ``$``, are not judged)."""
    candidates = list(dict.fromkeys(known))
    known = set(candidates)
    for ref, where, severity, consequence in places:
        if ref.name is not None and ref.name not in known and "$" not in ref.name:
            yield _unknown(srdf, ref, candidates, what, where, severity, consequence)


@rule("srdf.unknown-joint", "error", "an SRDF names a joint the URDF does not have",
      doc="""srdfdom skips a joint name that is neither the URDF's nor a virtual joint's: "Joint
'x' declared as part of group 'g' is not known to the URDF" (the group lacks it: an error),
"Joint 'x' declared as part of group state 's' is not known to the URDF" (the state lacks its
value: MoveIt then sets that group joint to 0, an error), "Joint 'x' marked as passive is not
known to the URDF. Ignoring." and "Property defined for a joint 'x' that is not known to the
URDF. Ignoring." (warnings: nothing is planned differently, but the entry does nothing).""",
      bad=_example('  <group_state name="home" group="arm">\n    <joint name="joint1" value="0"/>\n'
                   '    <joint name="jont2" value="0"/>\n  </group_state>'),
      good=_example('  <group_state name="home" group="arm">\n    <joint name="joint1" value="0"/>\n'
                    '    <joint name="joint2" value="0"/>\n  </group_state>'),
      fix="safe", on="srdf")
def unknown_joint(srdf):
    places = [(ref, f"group '{group.name}'", None, "MoveIt leaves it out of the group")
              for group in srdf.groups for ref in group.joints]
    places += [(joint.ref, f"group state '{state.name}'", None, "MoveIt ignores its value")
               for state in srdf.group_states for joint in state.joints]
    places += [(ref, f"<{ref.tag}>", "warning", "MoveIt ignores it")
               for ref in (*srdf.passive_joints, *srdf.joint_properties)]
    return _unknown_names(srdf, "joint", sorted(_known_joints(srdf)), places)


@rule("srdf.unknown-group", "error", "an SRDF names a group it does not define",
      doc="""A subgroup, a group state's group, an end effector's group or parent group must be
a `<group>` of the SRDF. srdfdom drops a group whose subgroups are not all defined ("Group 'g'
has unsatisfied subgroups"), a state of an unknown group ("Group state 's' specified for group
'g', but that group is not known") and an end effector of an unknown group ("End effector 'e'
specified for group 'g', but that group is not known"); moveit_core finds no parent group for
an end effector whose `parent_group` is not defined. Each drops what the configuration meant to
give the planner: errors.""",
      bad=_example('  <group_state name="home" group="arms"><joint name="joint1" value="0"/>'
                   '<joint name="joint2" value="0"/></group_state>'),
      good=_example('  <group_state name="home" group="arm"><joint name="joint1" value="0"/>'
                    '<joint name="joint2" value="0"/></group_state>'),
      fix="safe", on="srdf")
def unknown_group(srdf):
    names = [g.name for g in srdf.groups if g.name]
    known = set(names)

    def check(ref, where, consequence):
        if ref is not None and ref.name is not None and ref.name not in known \
                and "$" not in ref.name:
            edits, new, note = _rename(srdf, ref, names)
            yield Finding(f"{where}: group '{ref.name}' is not defined in the SRDF; "
                          f"{consequence}", ref.loc,
                          hint=f"did you mean '{new}'?{note}" if new else
                          "define the group, or name one of: " + (", ".join(names) or "(none)"),
                          edits=edits)

    for group in srdf.groups:
        for ref in group.subgroups:
            yield from check(ref, f"group '{group.name}'",
                             "MoveIt drops the group ('unsatisfied subgroups')")
    for state in srdf.group_states:
        yield from check(state.group, f"group state '{state.name}'", "MoveIt drops the state")
    for eef in srdf.end_effectors:
        yield from check(eef.group, f"end effector '{eef.name}'",
                         "MoveIt drops the end effector")
        yield from check(eef.parent_group, f"end effector '{eef.name}'",
                         "MoveIt finds no parent group for it")


def _ancestors(robot, link: str) -> list[str]:
    """``link`` and the links above it, up to the root."""
    found, seen = [link], {link}
    joint = robot.parent_joint(link)
    while joint is not None and joint.parent and joint.parent not in seen:
        found.append(joint.parent)
        seen.add(joint.parent)
        joint = robot.parent_joint(joint.parent)
    return found


@rule("srdf.chain-not-below", "warning", "a chain's tip link is not below its base link",
      doc="""A `<chain base_link tip_link>` is meant to run down the tree from base to tip. When
the tip is not below the base, MoveIt still builds the group through their common ancestor,
but the kinematics solvers made for chains (KDL, TRAC-IK, pick_ik's chain mode) refuse it at
start-up ("Group 'g' is not a chain"): usually base and tip are swapped, or the tip belongs to
another branch (the other arm).""",
      bad='<robot name="arm">\n  <group name="arm"><chain base_link="tool0" tip_link="base_link"/></group>\n</robot>',
      good=_example(""), on="srdf")
def chain_not_below(srdf):
    robot = srdf.robot
    for group in srdf.groups:
        for chain in group.chains:
            base, tip = chain.base.name, chain.tip.name
            if not base or not tip or robot.link(base) is None or robot.link(tip) is None:
                continue
            if base in _ancestors(robot, tip):
                continue
            swapped = tip in _ancestors(robot, base)
            yield Finding(f"group '{group.name}': chain tip '{tip}' is not below its base "
                          f"'{base}'" + (" (the base is below the tip: swapped?)" if swapped
                                         else " (they are on different branches)"),
                          chain.loc, hint="swap base_link and tip_link" if swapped else
                          "name a base link above the tip")


@rule("srdf.empty-group", "error", "a group has no joint MoveIt can use",
      doc="""srdfdom warns "Group 'g' is empty" and moveit_core refuses a group without a valid
joint ("Group 'g' must have at least one valid joint"): the group is not created, and its group
states and end effectors are dropped with it. (A group whose only members are names the URDF
lacks is the same: `srdf.unknown-link`/`srdf.unknown-joint` report those names.)""",
      bad=_example('  <group name="hand"/>'),
      good=_example('  <group name="hand"><link name="tool0"/></group>'),
      on="srdf")
def empty_group(srdf):
    for group in srdf.groups:
        if not (group.links or group.joints or group.chains or group.subgroups):
            yield Finding(f"group '{group.name}' is empty; MoveIt does not create it (its group "
                          "states and end effectors are dropped)", group.loc,
                          hint="list its links, joints, chain or subgroups, or remove it")


def _group_links(srdf, group, seen=None) -> set[str]:
    """The links of a group as MoveIt collects them: its links, the child links of its joints,
    the links along its chains, and its subgroups' links."""
    robot = srdf.robot
    seen = seen if seen is not None else set()
    if group is None or group.name in seen:
        return set()
    seen.add(group.name)
    links = {r.name for r in group.links if r.name}
    for ref in group.joints:
        joint = robot.joint(ref.name)
        if joint is not None and joint.child:
            links.add(joint.child)
    for chain in group.chains:
        if chain.base.name and chain.tip.name:
            up = _ancestors(robot, chain.tip.name)
            if chain.base.name in up:
                links.update(up[:up.index(chain.base.name) + 1])
    for ref in group.subgroups:
        links |= _group_links(srdf, srdf.group(ref.name), seen)
    return links


def group_joints(srdf, group, seen=None) -> list[str]:
    """The joints of a group as MoveIt collects them (in tree order of discovery): its joints,
    the parent joints of its links, the joints along its chains (and the base's parent joint),
    its subgroups' joints."""
    robot = srdf.robot
    seen = seen if seen is not None else set()
    if group is None or group.name in seen:
        return []
    seen.add(group.name)
    found: dict[str, None] = {}
    for ref in group.joints:
        if ref.name:
            found[ref.name] = None
    for ref in group.links:
        joint = robot.parent_joint(ref.name) if ref.name else None
        if joint is not None and joint.name:
            found[joint.name] = None
    for chain in group.chains:
        if chain.base.name and chain.tip.name:
            up = _ancestors(robot, chain.tip.name)
            if chain.base.name in up:
                for link in reversed(up[:up.index(chain.base.name)]):
                    joint = robot.parent_joint(link)
                    if joint is not None and joint.name:
                        found[joint.name] = None
    for ref in group.subgroups:
        for name in group_joints(srdf, srdf.group(ref.name), seen):
            found[name] = None
    return list(found)


@rule("srdf.end-effector-overlap", "warning",
      "an end effector's group holds its parent link or the parent group's links",
      doc="""An end effector is a group attached at `parent_link` to `parent_group`. When its own
group contains the parent link, or links of the parent group, the two groups overlap: moving
the end effector moves the arm, and MoveIt's end-effector markers and IK attach to the wrong
place. MoveIt loads it (no refusal), so this is a warning.""",
      bad=_example('  <group name="hand"><link name="forearm"/><link name="tool0"/></group>\n'
                   '  <end_effector name="hand" group="hand" parent_link="forearm" '
                   'parent_group="arm"/>'),
      good=_example('  <group name="hand"><link name="tool0"/></group>\n'
                    '  <end_effector name="hand" group="hand" parent_link="forearm" '
                    'parent_group="arm"/>').replace('tip_link="tool0"', 'tip_link="forearm"'),
      on="srdf")
def end_effector_overlap(srdf):
    for eef in srdf.end_effectors:
        own = _group_links(srdf, srdf.group(eef.group.name))
        if not own:
            continue
        if eef.parent_link.name in own:
            yield Finding(f"end effector '{eef.name}': its group '{eef.group.name}' contains its "
                          f"parent link '{eef.parent_link.name}'", eef.loc,
                          hint="leave the parent link out of the end effector's group")
            continue
        parent = srdf.group(eef.parent_group.name) if eef.parent_group is not None else None
        shared = sorted(own & _group_links(srdf, parent)) if parent is not None else []
        if shared:
            yield Finding(f"end effector '{eef.name}': its group '{eef.group.name}' shares "
                          f"link(s) {', '.join(shared[:5])} with its parent group "
                          f"'{parent.name}'", eef.loc,
                          hint="the arm group and the end effector's group should not overlap")


@rule("srdf.virtual-joint-child", "error", "a virtual joint's child is not the URDF's root link",
      doc="""A virtual joint attaches the robot's root link to a frame of the world. moveit_core
(RobotModel::buildModel) uses a virtual joint only when its `child_link` is the URDF's root
link; any other child is skipped with a log line ("Skipping virtual joint 'x' because its child
frame 'y' does not match the URDF root link 'z'"): the robot is then fixed where it was meant
to float (or the other way round), an error.""",
      bad=_example('  <virtual_joint name="world_joint" type="fixed" parent_frame="world" '
                   'child_link="upper_arm"/>'),
      good=_example('  <virtual_joint name="world_joint" type="fixed" parent_frame="world" '
                    'child_link="base_link"/>'),
      fix="safe", on="srdf")
def virtual_joint_child(srdf):
    roots = srdf.robot.roots()
    if len(roots) != 1:
        return
    root = roots[0]
    for virtual in srdf.virtual_joints:
        child = virtual.child.name
        if not child or child == root or srdf.robot.link(child) is None:
            continue  # (a link the URDF lacks: srdf.unknown-link)
        from urdftool.rules import value_edits

        edits, note = value_edits(srdf, virtual.child.loc, ("virtual_joint",),
                                  {"child_link": root})
        yield Finding(f"virtual joint '{virtual.name}': child link '{child}' is not the URDF's "
                      f"root link '{root}'; MoveIt skips the virtual joint", virtual.loc,
                      hint=f"attach the virtual joint to '{root}'{note}", edits=edits)


def _bounds(joint) -> tuple[float, float] | None:
    if joint.type in ("revolute", "prismatic") and joint.limit is not None \
            and joint.limit.lower is not None and joint.limit.upper is not None:
        return joint.limit.lower, joint.limit.upper
    return None


@rule("srdf.state-out-of-limits", "error", "a group state sets a joint outside its limits",
      doc="""A group state (a named pose: "home", "ready") is a goal the planner is asked to
reach. A value outside the joint's URDF limits is a goal MoveIt rejects ("goal state is not
within bounds"): the named target cannot be planned to.""",
      bad=_example('  <group_state name="home" group="arm"><joint name="joint1" value="0"/>'
                   '<joint name="joint2" value="3"/></group_state>'),
      good=_example('  <group_state name="home" group="arm"><joint name="joint1" value="0"/>'
                    '<joint name="joint2" value="2.5"/></group_state>'),
      on="srdf")
def state_out_of_limits(srdf):
    robot = srdf.robot
    for state in srdf.group_states:
        for joint in state.joints:
            urdf_joint = robot.joint(joint.ref.name)
            bounds = _bounds(urdf_joint) if urdf_joint is not None else None
            if bounds is None or joint.values is None or len(joint.values) != 1:
                continue
            value = joint.values[0]
            lower, upper = bounds
            margin = 1e-9 * max(1.0, abs(lower), abs(upper))
            if lower - margin <= value <= upper + margin:
                continue
            yield Finding(f"group state '{state.name}': joint '{joint.ref.name}' = {value!r} is "
                          f"outside its limits [{lower!r}, {upper!r}]", joint.ref.loc,
                          hint="set a value within the joint's limits")


def _names_unknown(srdf, group, seen=None) -> bool:
    """Whether a group (or a subgroup) names a link, joint or group the SRDF's robot lacks:
    what MoveIt makes of it is then that finding's consequence, not another defect."""
    seen = seen if seen is not None else set()
    if group is None or group.name in seen:
        return group is None
    seen.add(group.name)
    robot, joints = srdf.robot, _known_joints(srdf)
    if any(r.name and robot.link(r.name) is None for r in group.links) or any(
            r.name and r.name not in joints for r in group.joints) or any(
            robot.link(c.base.name) is None or robot.link(c.tip.name) is None
            for c in group.chains):
        return True
    return any(_names_unknown(srdf, srdf.group(r.name), seen) for r in group.subgroups)


@rule("srdf.state-incomplete", "warning",
      "a group state leaves out a joint of its group, or sets one outside it",
      doc="""moveit_core's buildGroupStates warns "Group state 's' doesn't specify all group
joints in group 'g'" and sets the joints left out to 0 (which may not be what was meant, or
within their limits); a value for a joint outside the group is an error line ("specifies value
for joint 'x', but that joint is not part of group 'g'") and is ignored. MoveIt still loads
the state: warnings. Mimic and fixed joints are not the group's variables and are never
required.""",
      bad=_example('  <group_state name="home" group="arm"><joint name="joint1" value="0"/>'
                   '</group_state>'),
      good=_example('  <group_state name="home" group="arm"><joint name="joint1" value="0"/>'
                    '<joint name="joint2" value="0"/></group_state>'),
      on="srdf")
def state_incomplete(srdf):
    robot = srdf.robot
    virtual = {v.name for v in srdf.virtual_joints if v.name}
    for state in srdf.group_states:
        group = srdf.group(state.group.name)
        if group is None:
            continue
        members = group_joints(srdf, group)
        if not members or _names_unknown(srdf, group):
            continue  # (an empty group, or one of unknown names: reported as such)
        written = [j.ref.name for j in state.joints]
        outside = [n for n in written if n and n not in members and n not in virtual
                   and robot.joint(n) is not None]
        active = [n for n in members if (j := robot.joint(n)) is not None and j.moving
                  and j.mimic is None]
        missing = [n for n in active if n not in written]
        # a name the URDF lacks is one of them misspelt (srdf.unknown-joint: one finding)
        unknown = [n for n in written if n and robot.joint(n) is None and n not in virtual]
        if missing and not unknown:
            yield Finding(f"group state '{state.name}' leaves out joint(s) {', '.join(missing)} "
                          f"of group '{group.name}'; MoveIt sets them to 0", state.loc,
                          hint="give every joint of the group a value")
        for joint in state.joints:
            if joint.ref.name in outside:
                yield Finding(f"group state '{state.name}': joint '{joint.ref.name}' is not in "
                              f"group '{group.name}'; MoveIt ignores its value", joint.ref.loc,
                              hint="remove it, or use a group that contains it")


def _pair_key(pair) -> tuple[str, str] | None:
    a, b = pair.link1.name, pair.link2.name
    if not a or not b:
        return None
    return (a, b) if a <= b else (b, a)


@rule("srdf.duplicate-pair", "warning", "a collision pair is listed twice (or reversed)",
      doc="""MoveIt keeps one entry per pair of links in the allowed collision matrix: a second
`<disable_collisions>` of the same two links (in either order) changes nothing, or, with
another reason, says two things of one pair. Usually an edit by hand duplicated a line the
Setup Assistant wrote.""",
      bad=_example('  <disable_collisions link1="base_link" link2="upper_arm" reason="Adjacent"/>\n'
                   '  <disable_collisions link1="upper_arm" link2="base_link" reason="Adjacent"/>'),
      good=_example('  <disable_collisions link1="base_link" link2="upper_arm" reason="Adjacent"/>'),
      on="srdf")
def duplicate_pair(srdf):
    first: dict[tuple, object] = {}
    for pair in srdf.pairs:
        if pair.enable:
            continue
        key = _pair_key(pair)
        if key is None:
            continue
        if key in first:
            earlier = first[key]
            reversed_ = earlier.link1.name != pair.link1.name  # type: ignore[attr-defined]
            line = earlier.loc.line if earlier.loc is not None else None  # type: ignore[attr-defined]
            yield Finding(f"the pair '{pair.link1.name}' / '{pair.link2.name}' is already "
                          f"disabled{' (reversed)' if reversed_ else ''}"
                          + (f" at line {line}" if line else ""), pair.loc,
                          hint="remove the repeated line")
        else:
            first[key] = pair


def _collision_links(robot) -> set[str]:
    return {link.name for link in robot.links if link.name and link.collisions}


def adjacent_pairs(robot) -> set[tuple[str, str]]:
    """The pairs MoveIt Setup Assistant labels ``Adjacent`` (compute_default_collisions.cpp,
    ``computeConnectionGraph``): links joined by a joint, where a link without collision
    geometry is passed through (its neighbours become adjacent to each other)."""
    neighbours: dict[str, set[str]] = {}
    for joint in robot.joints:
        if joint.parent and joint.child:
            neighbours.setdefault(joint.parent, set()).add(joint.child)
            neighbours.setdefault(joint.child, set()).add(joint.parent)
    with_geometry = _collision_links(robot)
    for link in [name for name in list(neighbours) if name not in with_geometry]:
        around = neighbours.pop(link, set())
        for a in around:
            neighbours[a].discard(link)
            neighbours[a] |= around - {a}
    return {(a, b) if a <= b else (b, a) for a, near in neighbours.items() for b in near}


@rule("srdf.adjacent-mislabelled", "warning", "a pair marked Adjacent is not adjacent",
      doc="""The Setup Assistant marks a pair `Adjacent` when the links are joined by a joint
(links without collision geometry passed through). A pair so marked that is not adjacent was
labelled by hand: if the links can touch, the planner was told to ignore it. MoveIt does not
read the reason, so the label alone changes nothing: a warning.""",
      bad=_example('  <disable_collisions link1="base_link" link2="forearm" reason="Adjacent"/>'),
      good=_example('  <disable_collisions link1="base_link" link2="upper_arm" reason="Adjacent"/>'),
      on="srdf")
def adjacent_mislabelled(srdf):
    robot = srdf.robot
    adjacent = None
    for pair in srdf.pairs:
        if pair.enable or pair.reason != "Adjacent":
            continue
        key = _pair_key(pair)
        if key is None or robot.link(key[0]) is None or robot.link(key[1]) is None:
            continue
        if adjacent is None:
            adjacent = adjacent_pairs(robot)
        with_geometry = _collision_links(robot)
        if key in adjacent or not (set(key) <= with_geometry):
            continue
        yield Finding(f"the pair '{pair.link1.name}' / '{pair.link2.name}' is marked Adjacent, "
                      "but no joint joins them", pair.loc,
                      hint="label it with the reason it is disabled (Never, User), or remove it")


MAX_PAIRS = 2000  # pairs sampled per SRDF


def collision_shapes(robot, link_name: str) -> list:
    """The ``physics.links.ShapeInfo`` of a link's collision shapes that can be placed."""
    from urdftool.physics.links import _shape_info

    link = robot.link(link_name)
    if link is None:
        return []
    shapes = []
    for shape in link.collisions:
        try:
            info = _shape_info(robot, shape, need_volume=False)
        except Exception:  # noqa: BLE001 - an unreadable shape is the mesh rules' business
            info = None
        if info is not None and info.extent is not None and info.problem is None:
            shapes.append(info)
    return shapes


def _pairs_to_sample(srdf):
    """The disabled pairs marked Never whose links are both known and not adjacent: first
    occurrence of each."""
    robot = srdf.robot
    adjacent = adjacent_pairs(robot)
    body = _rigid_bodies(robot)
    # pairs an <enable_collisions> checks on their behalf: links rigidly fixed to the two
    # links (Franka's capsule "_sc" links: the normal links' pairs are disabled on purpose)
    covered = set()
    for pair in srdf.pairs:
        key = _pair_key(pair) if pair.enable else None
        if key is not None and robot.link(key[0]) is not None \
                and robot.link(key[1]) is not None:
            covered.add(frozenset((body(key[0]), body(key[1]))))
    seen = set()
    for pair in srdf.pairs:
        if pair.enable or pair.reason != "Never":
            continue
        key = _pair_key(pair)
        if key is None or key in seen or key in adjacent or key[0] == key[1]:
            continue
        seen.add(key)
        if robot.link(key[0]) is None or robot.link(key[1]) is None:
            continue
        if frozenset((body(key[0]), body(key[1]))) in covered:
            continue  # MoveIt checks these two bodies through the enabled pair
        yield pair


def _rigid_bodies(robot):
    """link name -> the name of the top link of the rigid body it belongs to (links joined by
    fixed joints are one body)."""
    memo: dict[str, str] = {}

    def top(name: str) -> str:
        found = memo.get(name)
        if found is not None:
            return found
        walked, current = [], name
        while current not in memo:
            walked.append(current)
            joint = robot.parent_joint(current)
            if joint is None or joint.type != "fixed" or joint.parent is None \
                    or joint.parent in walked:
                memo[current] = current
                break
            current = joint.parent
        for link in walked:
            memo[link] = memo[current]
        return memo[name]

    return top


@rule("srdf.never-pair-collides", "error",
      "links whose collisions are disabled collide in a sampled configuration",
      doc="""The Setup Assistant disables collision checking between links that never touched
in its random sample of the robot's states (`reason="Never"`), once, when the configuration was
made. Once the meshes, the joint limits or the kinematics change, such a pair may collide, and
the planner, told to ignore it, drives the arm into itself. urdftool samples the joints between
the two links deterministically (a Halton sequence within the joint limits, mimic joints
following their leaders), places their collision shapes by forward kinematics and tests them
as MoveIt does (moveit_core's FCL collision world; here coal, FCL's successor, from
`urdftool[kinematics]`: primitives as such, meshes as their triangles; without coal, GJK on
primitives, and mesh pairs whose convex hulls overlap are one info finding, not judged). A
finding gives the sampled configuration where they collide deepest and the penetration
(coal's; for primitives without coal, the shortest separating translation found). Sampling shows a collision; it never proves that there is none: a pair
without a finding was not proven safe. Links joined rigidly (no moving joint between them)
touch always or never: not sampled.""",
      bad=_example('  <disable_collisions link1="base_link" link2="forearm" reason="Never"/>'),
      good=_example('  <disable_collisions link1="base_link" link2="upper_arm" reason="Adjacent"/>'),
      on="srdf")
def never_pair_collides(srdf):
    from urdftool import budget
    from urdftool.kinematics.pairs import coal_available, contacts, exact_overlap, path

    robot = srdf.robot
    shapes: dict[str, list] = {}
    untested = []
    exact = coal_available()
    for count, pair in enumerate(_pairs_to_sample(srdf)):
        if count >= MAX_PAIRS or budget.spent():
            break
        a, b = pair.link1.name, pair.link2.name
        for name in (a, b):
            if name not in shapes:
                shapes[name] = collision_shapes(robot, name)
        if not shapes[a] or not shapes[b]:
            continue
        meshes = any(info.shape.geometry.kind == "mesh" for info in (*shapes[a], *shapes[b]))
        # the shapes themselves, as MoveIt tests them (a mesh's hull is more than the mesh;
        # one that cannot be read is the mesh rules' business)
        overlap = exact_overlap(shapes[a], shapes[b]) if exact else None
        route = path(robot, a, b)
        if not route.variables:
            continue  # rigidly joined: they touch always or never (the label, not a risk)
        found, tested = contacts(route, [i.extent for i in shapes[a]],
                                 [i.extent for i in shapes[b]], overlap, budget.spent)
        if not found:
            continue
        if meshes and not exact:
            untested.append(f"{a}/{b}")
            continue
        contact = found[0]
        what = "their collision meshes intersect" if meshes else "their collision shapes overlap"
        where = ", ".join(f"{name}={value!r}" for name, value in
                          contact.configuration.items()) or "every configuration"
        yield Finding(f"links '{a}' and '{b}' are marked {pair.reason} in collision, but sampling "
                      f"{tested} configuration(s) within the joint limits shows them colliding: "
                      f"at {where} {what} (penetration {contact.depth:.6g} m); sampling shows a "
                      "collision, it never proves there is none", pair.loc,
                      hint="remove this <disable_collisions> (or regenerate the collision matrix "
                           "with the MoveIt Setup Assistant)")
    if untested:
        yield Finding(f"{len(untested)} disabled pair(s) whose mesh hulls overlap in sampled "
                      f"configurations were not tested with the meshes themselves "
                      f"({', '.join(untested[:5])}{', ...' if len(untested) > 5 else ''})",
                      srdf.loc, severity="info",
                      hint="install urdftool[kinematics] (coal tests the meshes)")
