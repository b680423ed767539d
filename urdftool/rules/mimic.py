"""Rules of the `mimic` family: a mimic joint's leader exists, is not itself, is not part of a
cycle or a chain, and — the one that bites — drives the follower only through positions its own
limits allow (``urdftool.ranges`` has the interval arithmetic).

A follower is driven to ``multiplier * q_leader + offset``. MoveIt, ros2_control's mimic joints
and Gazebo's mimic plugins apply exactly that, so a leader range whose image leaves the
follower's limits pushes the follower into its stops (the simulator fights the constraint,
planners reject the state).
"""

from __future__ import annotations

from urdftool.findings import Finding
from urdftool.model import Robot
from urdftool.ranges import chain_path, composed, mimic_chain, mimic_image, tolerance
from urdftool.rules import Names, rename_edits, rule, value_edits
from urdftool.rules.joint import fmt, label

_ROBOT = '<robot name="r"><link name="a"/><link name="b"/><link name="c"/><link name="d"/>\n'
_LEADER = ('  <joint name="lead" type="revolute"><parent link="a"/><child link="b"/>\n'
           '    <limit lower="0" upper="1" effort="1" velocity="1"/></joint>\n')


MOST_SHOWN = 6  # joints named in a message about a chain or a cycle (the others counted)


def _example(follower: str) -> str:
    return _ROBOT + _LEADER + follower + "</robot>"


def _follower(mimic: str, joint_type: str = "revolute", limits: str = 'lower="0" upper="1"',
              name: str = "follow", parent: str = "a", child: str = "c") -> str:
    return (f'  <joint name="{name}" type="{joint_type}"><parent link="{parent}"/>'
            f'<child link="{child}"/>\n'
            f'    <limit {limits} effort="1" velocity="1"/>\n    {mimic}</joint>\n')


def _interval(interval) -> str:
    return f"[{fmt(interval[0])}, {fmt(interval[1])}]"


@rule("mimic.unknown-joint", "error", "a mimic names a joint that does not exist",
      doc="""`<mimic joint="X">` must name another joint of the robot. urdfdom refuses a mimic
      without `joint`; MoveIt, ros2_control and Gazebo fail to load or ignore the relation when
      X is not a joint (naming a link is a common slip).""",
      bad=_example(_follower('<mimic joint="leed"/>')),
      good=_example(_follower('<mimic joint="lead"/>')),
      fix="safe")
def unknown_joint(robot: Robot):
    names = Names(j.name for j in robot.joints)
    for joint in robot.joints:
        mimic = joint.mimic
        if mimic is None:
            continue
        if not mimic.joint:
            yield Finding(f"{label(joint)}: <mimic> without a joint attribute", mimic.loc,
                          hint='<mimic joint="LEADER" multiplier="1" offset="0"/>')
            continue
        if robot.joint(mimic.joint) is not None:
            continue
        what = "a link, not a joint" if robot.link(mimic.joint) is not None else "not a joint"
        edits, new, note = rename_edits(robot, mimic.loc, "mimic", "joint", mimic.joint,
                                        names, True, exclude=joint.name)
        if new is None:
            hint = "name one of the robot's joints"
        elif robot.link(mimic.joint) is not None:
            hint = f"the joint whose child is link '{mimic.joint}' is '{new}'"
        else:
            hint = f"did you mean '{new}'?"
        yield Finding(f"{label(joint)} mimics '{mimic.joint}', which is {what}", mimic.loc,
                      hint=hint + note, edits=edits)


@rule("mimic.self", "error", "a joint mimics itself",
      doc="""A joint cannot follow itself: `q = m*q + o` has no meaning as a constraint, and
      consumers either loop or ignore it.""",
      bad=_example(_follower('<mimic joint="follow"/>')),
      good=_example(_follower('<mimic joint="lead"/>')))
def mimic_self(robot: Robot):
    for joint in robot.joints:
        if joint.mimic is not None and joint.mimic.joint and joint.mimic.joint == joint.name:
            yield Finding(f"{label(joint)} mimics itself", joint.mimic.loc,
                          hint="name the joint it should follow, or remove the <mimic>")


@rule("mimic.cycle", "error", "mimic relations that form a cycle",
      doc="""Joints that follow each other round a loop have no leader: no joint is driven, and
      consumers that resolve mimic chains loop or give up.""",
      bad=_ROBOT +
      '  <joint name="j1" type="revolute"><parent link="a"/><child link="b"/>\n'
      '    <limit lower="0" upper="1" effort="1" velocity="1"/><mimic joint="j2"/></joint>\n'
      '  <joint name="j2" type="revolute"><parent link="a"/><child link="c"/>\n'
      '    <limit lower="0" upper="1" effort="1" velocity="1"/><mimic joint="j1"/></joint>\n'
      '</robot>',
      good=_ROBOT +
      '  <joint name="j1" type="revolute"><parent link="a"/><child link="b"/>\n'
      '    <limit lower="0" upper="1" effort="1" velocity="1"/></joint>\n'
      '  <joint name="j2" type="revolute"><parent link="a"/><child link="c"/>\n'
      '    <limit lower="0" upper="1" effort="1" velocity="1"/><mimic joint="j1"/></joint>\n'
      '</robot>')
def mimic_cycle(robot: Robot):
    reported: set[int] = set()
    for joint in robot.joints:
        if joint.mimic is None:
            continue
        chain = mimic_chain(robot, joint)
        if chain.end != "cycle":
            continue
        members = chain.cycle
        key = id(members)  # one tuple per cycle (ranges.mimic_chains)
        if key in reported:
            continue
        reported.add(key)
        shown = [f"'{j.name}'" for j in members[:MOST_SHOWN]]
        if len(members) > MOST_SHOWN:
            shown.append(f"... ({len(members) - MOST_SHOWN} more)")
        loop = " -> ".join(shown) + f" -> '{members[0].name}'"
        first = members[0]
        yield Finding(f"mimic cycle: {loop} (each follows the next); no joint leads",
                      first.mimic.loc if first.mimic else first.loc,
                      hint=f"remove the <mimic> of the joint that is really driven "
                           f"(e.g. '{first.name}')")


@rule("mimic.chained", "warning", "a mimic whose leader is itself a mimic",
      doc="""A follows B follows C. MoveIt, ros2_control and most simulators only support a
      follower of a joint that is not itself a mimic: the chain is rejected or the middle link
      is ignored. The same motion is a direct mimic of the chain's root with the composed
      multiplier and offset: `A = mA*(mB*C + oB) + oA = (mA*mB)*C + (mA*oB + oA)`.""",
      bad=_ROBOT + _LEADER +
      '  <joint name="mid" type="revolute"><parent link="a"/><child link="c"/>\n'
      '    <limit lower="0" upper="2" effort="1" velocity="1"/><mimic joint="lead" '
      'multiplier="2"/></joint>\n'
      '  <joint name="end" type="revolute"><parent link="a"/><child link="d"/>\n'
      '    <limit lower="0" upper="2" effort="1" velocity="1"/><mimic joint="mid"/></joint>\n'
      '</robot>',
      good=_ROBOT + _LEADER +
      '  <joint name="mid" type="revolute"><parent link="a"/><child link="c"/>\n'
      '    <limit lower="0" upper="2" effort="1" velocity="1"/><mimic joint="lead" '
      'multiplier="2"/></joint>\n'
      '  <joint name="end" type="revolute"><parent link="a"/><child link="d"/>\n'
      '    <limit lower="0" upper="2" effort="1" velocity="1"/><mimic joint="lead" '
      'multiplier="2" offset="0"/></joint>\n'
      '</robot>')
def chained(robot: Robot):
    for joint in robot.joints:
        if joint.mimic is None:
            continue
        chain = mimic_chain(robot, joint)
        if chain.length < 3 or chain.end in ("self", "cycle"):
            continue
        path = chain_path(robot, chain, MOST_SHOWN)
        values = composed(chain)
        if chain.end == "root" and values is not None:
            multiplier, offset = values
            hint = (f'<mimic joint="{chain.root.name}" multiplier="{multiplier:.10g}" '
                    f'offset="{offset:.10g}"/>')
        else:
            hint = "follow the joint that is really driven, with the composed multiplier/offset"
        yield Finding(f"{label(joint)} follows a mimic joint: {path}; most consumers do not "
                      "support chained mimics", joint.mimic.loc, hint=hint)


@rule("mimic.zero-multiplier", "warning", "a mimic with multiplier 0",
      doc="""With multiplier 0 the follower sits at `offset` whatever the leader does: it is a
      fixed joint in disguise, or the multiplier was lost.""",
      bad=_example(_follower('<mimic joint="lead" multiplier="0" offset="0.5"/>')),
      good=_example(_follower('<mimic joint="lead" multiplier="1" offset="0"/>')))
def zero_multiplier(robot: Robot):
    for joint in robot.joints:
        mimic = joint.mimic
        if mimic is not None and mimic.multiplier == 0:
            offset = mimic.offset if mimic.offset is not None else 0.0
            yield Finding(f"{label(joint)}: mimic multiplier 0 holds it at {fmt(offset)} "
                          "whatever the leader does", mimic.loc,
                          hint='give the real multiplier, or make the joint type="fixed"')


@rule("mimic.fixed-joint", "warning", "a mimic on or of a fixed joint",
      doc="""A follower of a fixed joint never moves (warning: the relation is pointless, the
      leader is probably the wrong joint). A `<mimic>` on a fixed joint is ignored by every
      consumer (info: a leftover, e.g. in a reduced model that locked the joint).""",
      bad=_ROBOT +
      '  <joint name="lead" type="fixed"><parent link="a"/><child link="b"/></joint>\n' +
      _follower('<mimic joint="lead"/>') + '</robot>',
      good=_example(_follower('<mimic joint="lead"/>')))
def fixed_joint(robot: Robot):
    for joint in robot.joints:
        mimic = joint.mimic
        if mimic is None:
            continue
        leader = robot.joint(mimic.joint)
        if joint.type == "fixed":
            yield Finding(f"{label(joint)} is fixed; its <mimic> is ignored", mimic.loc,
                          hint="remove the <mimic>", severity="info")
        elif leader is not None and leader.type == "fixed":
            yield Finding(f"{label(joint)} mimics '{leader.name}', a fixed joint: it never "
                          "moves", mimic.loc,
                          hint="follow the joint that is really driven")


@rule("mimic.mixed-kinds", "info", "a revolute joint mimics a prismatic one, or vice versa",
      doc="""The multiplier then converts units (m per rad or rad per m). That is legitimate for
      a rack or a linkage, but worth a look: a multiplier written for the same kind of joint is
      off by the unit.""",
      bad=_example(_follower('<mimic joint="lead" multiplier="0.01"/>', "prismatic",
                             'lower="0" upper="0.01"')),
      good=_example(_follower('<mimic joint="lead" multiplier="1"/>')))
def mixed_kinds(robot: Robot):
    kinds = {"revolute": "rad", "continuous": "rad", "prismatic": "m"}
    for joint in robot.joints:
        mimic = joint.mimic
        if mimic is None:
            continue
        leader = robot.joint(mimic.joint)
        if leader is None or joint.type not in kinds or leader.type not in kinds:
            continue
        if kinds[joint.type] != kinds[leader.type]:
            yield Finding(f"{label(joint)} ({joint.type}) mimics '{leader.name}' "
                          f"({leader.type}): the multiplier {fmt(mimic.multiplier or 0)} is in "
                          f"{kinds[joint.type]} per {kinds[leader.type]}", mimic.loc)


@rule("mimic.out-of-range", "error", "a leader's range drives the follower outside its limits",
      doc="""A follower is driven to `multiplier*q + offset` as the leader `q` sweeps its range.
      When that image leaves the follower's own limits, the follower is pushed into its stops:
      simulators fight the constraint (jitter, explosions), planners reject the states, and the
      real mechanism cannot do what the model says. Usually the offset or the multiplier's sign
      is wrong, or the follower's limits are mirrored.""",
      bad=_example(_follower('<mimic joint="lead" multiplier="-1" offset="0"/>')),
      good=_example(_follower('<mimic joint="lead" multiplier="-1" offset="1"/>')),
      fix="unsafe")
def out_of_range(robot: Robot):
    for joint in robot.joints:
        info = mimic_image(robot, joint)
        if info is None or not info.violates:
            continue
        follower = info.follower_range
        how = "entirely outside" if info.disjoint else "beyond"
        width = info.image[1] - info.image[0]
        edits = ()
        if width <= follower[1] - follower[0] + tolerance(follower):
            # the smallest change of offset that brings the image inside the limits
            shift = follower[1] - info.image[1] if info.image[1] > follower[1] else \
                follower[0] - info.image[0]
            hint = (f'offset="{info.offset + shift:.10g}" keeps multiplier {fmt(info.multiplier)} '
                    f"and drives it through {_interval((info.image[0] + shift, info.image[1] + shift))}"
                    "; or fix the multiplier's sign or the limits")
            edits, note = value_edits(robot, joint.mimic.loc, ("mimic",),
                                      {"offset": f"{info.offset + shift:.10g}"})
            hint += note
        else:
            hint = (f"the image is {fmt(width)} wide but the limits only "
                    f"{fmt(follower[1] - follower[0])}: fix the multiplier or the limits")
        yield Finding(f"{label(joint)} mimics '{info.leader.name}' (range "
                      f"{_interval(info.leader_range)}) with multiplier {fmt(info.multiplier)}, "
                      f"offset {fmt(info.offset)}: it is driven to {_interval(info.image)}, "
                      f"{how} its limits {_interval(follower)}", joint.mimic.loc, hint=hint,
                      edits=edits)
