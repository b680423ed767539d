"""Rules of the `material` family: `<material>` definitions and references.

urdfdom (what RViz, robot_state_publisher, MoveIt and Gazebo's URDF import use) reads every
top-level `<material>` first — a name may appear only once, or it refuses the file — then the
links in document order. A visual's `<material name="X"/>` names a top-level material or one
defined with a colour inside an *earlier* link; a name defined nowhere (or only later) gets an
empty material, shown in the default colour, and an inline definition of a name that already
exists is ignored in favour of the first one. A colour component outside [0, 1], or a colour
without four components, is discarded (logged as an error) and the default colour used.
"""

from __future__ import annotations

import math

from urdftool.findings import Finding
from urdftool.model import Robot, parse_float
from urdftool.rules import Names, rule, value_edits


def _child(element, tag: str):
    for node in element:
        if isinstance(node.tag, str) and node.tag == tag:
            return node
    return None


def _definition(element):
    """(rgba text or None, texture filename or None) of a <material> element."""
    color = _child(element, "color")
    texture = _child(element, "texture")
    rgba = color.get("rgba") if color is not None else None
    filename = texture.get("filename") if texture is not None else None
    return rgba, filename


def _rgba(text: str | None) -> tuple[float, ...] | None:
    """The colour urdfdom accepts: four numbers in [0, 1], else None."""
    if text is None:
        return None
    values = [parse_float(part) for part in text.split()]
    if len(values) != 4 or any(v is None or not math.isfinite(v) or not 0 <= v <= 1
                               for v in values):
        return None
    return tuple(values)  # type: ignore[arg-type]


def _same_colour(a, b) -> bool:
    """The same colour once drawn: no channel differs by more than one 8-bit step (0.9 and
    230/255 are one colour)."""
    if a is None or b is None:
        return a == b
    return all(abs(x - y) <= 1 / 255 for x, y in zip(a, b))


def _defines(element) -> bool:
    rgba, filename = _definition(element)
    return _rgba(rgba) is not None or bool(filename)


def _visual_materials(robot: Robot, first_only: bool = False):
    """(link element, visual material element) in document order, for materials with a name
    (urdfdom skips ``name=""``, which exporters write: each visual keeps its own colour)."""
    if robot.root is None:
        return
    for link in robot.elements("link"):
        visuals = [v for v in link if isinstance(v.tag, str) and v.tag == "visual"]
        for visual in visuals[:1] if first_only else visuals:
            material = _child(visual, "material")
            if material is not None and material.get("name"):
                yield link, material


def _show(rgba: str | None, filename: str | None) -> str:
    parts = []
    if rgba is not None:
        parts.append(f"rgba '{' '.join(rgba.split())}'")
    if filename:
        parts.append(f"texture '{filename}'")
    return " and ".join(parts) or "nothing"


_LINK = '<link name="a"><visual><geometry><box size="1 1 1"/></geometry>'


@rule("material.undefined", "warning", "a visual uses a material that is never defined",
      doc="""`<material name="grey"/>` in a visual refers to a material defined elsewhere: at the
      top level of `<robot>`, or with a colour in an earlier link's visual. Without a definition
      the reference is invalid: old urdfdom refused the file ("material 'grey' undefined"),
      current urdfdom quietly gives the visual an empty material, so RViz and Gazebo show it in
      the default colour. A definition that only comes in a *later* link is too late: urdfdom
      reads links in order.""",
      bad='<robot name="r">\n  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>\n'
          '  ' + _LINK + '<material name="gray"/></visual></link>\n</robot>',
      good='<robot name="r">\n  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>\n'
           '  ' + _LINK + '<material name="grey"/></visual></link>\n</robot>',
      fix="safe")
def undefined(robot: Robot):
    defined = {m.get("name") for m in robot.elements("material")
               if m.get("name") is not None and _defines(m)}
    later: dict[str, str] = {}
    visuals = list(_visual_materials(robot))
    for link, material in visuals:
        name = material.get("name")
        if name is not None and _defines(material):
            later.setdefault(name, link.get("name") or "?")
    # every name defined anywhere, indexed once (issue 28: a sorted copy per undefined name
    # was quadratic)
    candidates = Names([*defined, *later])
    for link, material in visuals:
        name = material.get("name")
        if name is None:
            continue
        if name in defined:
            continue
        if _defines(material):
            defined.add(name)
            continue
        where = later.get(name)
        if where is not None:
            message = (f"link '{link.get('name')}': material '{name}' is defined (with a colour) "
                       f"only later, in link '{where}'; urdfdom reads links in order, so this "
                       "visual gets no colour")
            hint = f"move the definition of '{name}' to a top-level <material> before the links"
        edits = ()
        if where is None:
            message = (f"link '{link.get('name')}': material '{name}' is never defined; it is "
                       "shown in the default colour")
            hint = (f'add <material name="{name}"><color rgba="R G B A"/></material> under '
                    "<robot>, or a <color> inside this <material>")
            match = candidates.did_you_mean(name)
            if match is not None:  # a typo of one defined material
                message += f"; did you mean '{match}'?"
                edits, note = value_edits(robot, robot.loc(material), ("material",),
                                          {"name": match})
                hint = f'write <material name="{match}"/>' + note
        yield Finding(message, robot.loc(material), hint=hint, edits=edits)


@rule("material.no-color", "warning", "a top-level material without a colour or texture",
      doc="""A top-level `<material>` exists to say what a surface looks like: a `<color rgba>`
      or a `<texture filename>`. Without either, urdfdom logs "Material [grey] color has no
      rgba" and every visual that uses it is drawn in the default colour.""",
      bad='<robot name="r">\n  <material name="grey"/>\n</robot>',
      good='<robot name="r">\n  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>\n'
           '</robot>')
def no_color(robot: Robot):
    for material in robot.elements("material"):
        rgba, filename = _definition(material)
        if rgba is None and not filename:
            yield Finding(f"material '{material.get('name')}' has neither a <color rgba> nor a "
                          "<texture>; its visuals get the default colour", robot.loc(material),
                          hint='add <color rgba="R G B A"/> (each in [0, 1])')


@rule("material.not-unique", "error", "a top-level material name defined twice",
      doc="""urdfdom refuses a file in which two top-level `<material>` elements share a name
      ("material 'grey' is not unique"), even when the colours agree. With xacro, this usually
      comes from including a materials file twice.""",
      bad='<robot name="r">\n  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>\n'
          '  <material name="grey"><color rgba="0.6 0.6 0.6 1"/></material>\n</robot>',
      good='<robot name="r">\n  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>\n'
           '  <material name="light_grey"><color rgba="0.6 0.6 0.6 1"/></material>\n</robot>')
def not_unique(robot: Robot):
    first: dict[str, object] = {}
    for material in robot.elements("material"):
        name = material.get("name")
        if name is None:
            continue
        if name not in first:
            first[name] = material
            continue
        earlier = robot.loc(first[name])
        where = f" (first at line {earlier.line})" if earlier.line else ""
        yield Finding(f"material '{name}' is defined again{where}; urdfdom refuses the file",
                      robot.loc(material),
                      hint="remove the second definition (with xacro: include the materials "
                           "file once)")


@rule("material.redefined", "warning", "an inline material redefines a name with another colour",
      doc="""A visual's `<material name="X"><color .../></material>` defines X only if X does not
      exist yet. When X is already defined (at the top level, or in an earlier link) with a
      different colour, urdfdom resolves a link's (first) visual to the first definition and
      silently ignores this one. (`name=""`, as exporters write it, is not a reference: each
      such visual keeps its own colour.)""",
      bad='<robot name="r">\n  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>\n'
          '  ' + _LINK + '<material name="grey"><color rgba="1 0 0 1"/></material></visual>'
          '</link>\n</robot>',
      good='<robot name="r">\n  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>\n'
           '  ' + _LINK + '<material name="red"><color rgba="1 0 0 1"/></material></visual>'
           '</link>\n</robot>')
def redefined(robot: Robot):
    definitions: dict[str, tuple[str | None, str | None, object]] = {}
    for material in robot.elements("material"):
        name = material.get("name")
        if name is not None and name not in definitions and _defines(material):
            definitions[name] = (*_definition(material), material)
    for _link, material in _visual_materials(robot, first_only=True):
        name = material.get("name")
        if not _defines(material):
            continue
        rgba, filename = _definition(material)
        if name not in definitions:
            definitions[name] = (rgba, filename, material)
            continue
        first_rgba, first_file, first = definitions[name]
        if _same_colour(_rgba(first_rgba), _rgba(rgba)) and \
                (first_file or None) == (filename or None):
            continue
        earlier = robot.loc(first)
        where = f" at line {earlier.line}" if earlier.line else ""
        yield Finding(f"material '{name}' is redefined as {_show(rgba, filename)}, but the "
                      f"definition{where} ({_show(first_rgba, first_file)}) wins; this one is "
                      "ignored", robot.loc(material),
                      hint="give this material its own name, or drop its <color>/<texture>")
