"""Rules of the `sdf` family: problems of SDFormat input, and what a URDF cannot express.

An SDF file is converted to URDF while loading (``urdftool.sdf``); every problem found on the
way is recorded there with the SDF line, and the rules here report them. The URDF rules then run
on the converted model, with positions mapped back to the SDF lines.
"""

from __future__ import annotations

from urdftool.rules import source_rule

_LINK = "<link name=\"{0}\"><inertial><mass>1</mass><inertia><ixx>0.1</ixx><iyy>0.1</iyy>" \
        "<izz>0.1</izz></inertia></inertial></link>"


def _model(body: str, version: str = "1.7", name: str = "m") -> str:
    return f'<sdf version="{version}"><model name="{name}">{body}</model></sdf>'


_BASE = _LINK.format("base")
_ARM = _LINK.format("arm")
_HINGE = ('<joint name="j" type="revolute"><parent>base</parent><child>arm</child>'
          "<axis><xyz>0 0 1</xyz><limit><lower>-1</lower><upper>1</upper>"
          "<effort>10</effort><velocity>1</velocity></limit></axis></joint>")

source_rule(
    "sdf.version", "error", "the <sdf> version is missing or unknown",
    doc="""SDFormat's meaning changed between versions: where a joint axis is expressed (1.4:
    the model frame; 1.5/1.6: the joint frame unless use_parent_model_frame; 1.7+:
    expressed_in), whether poses may name a frame (relative_to from 1.7), degrees and quaternions
    (1.9). Without a known version the file cannot be read as its author meant. libsdformat
    (so Gazebo) refuses a file without a version or with one it cannot convert (2.0, 7.3),
    converts 1.0 to 1.3 on loading, and reads up to its own newest version. urdftool reads 1.4
    to 1.11; older files are read as 1.4 (a warning), unknown ones as 1.11 (an error: Gazebo
    will not load them).""",
    bad='<sdf version="7.3"><model name="m">' + _BASE + "</model></sdf>",
    good=_model(_BASE),
)

source_rule(
    "sdf.no-model", "error", "there is no <model> to convert (or the one asked for is missing)",
    doc="""A robot in SDFormat is a `<model>`, at the top of the file or inside a `<world>`.
    A file with only a world (lights, physics, a ground plane) has no robot to check; `--model
    NAME` naming a model that is not there is the same problem.""",
    bad='<sdf version="1.7"><world name="w"><gravity>0 0 -9.8</gravity></world></sdf>',
    good=_model(_BASE),
)

source_rule(
    "sdf.several-models", "info", "the file has several models; the first one is checked",
    doc="""A world may hold several models; a URDF holds one robot. `check` converts the first
    model and runs the URDF rules on it (the SDF rules see every model); `--model NAME` picks
    another. `convert` refuses to guess and asks for `--model`.""",
    bad='<sdf version="1.7"><world name="w"><model name="a">' + _BASE + '</model>'
        '<model name="b">' + _BASE + "</model></world></sdf>",
    good='<sdf version="1.7"><world name="w"><model name="a">' + _BASE + "</model></world></sdf>",
)

source_rule(
    "sdf.unknown-element", "warning", "an element SDFormat does not define here (did you mean...?)",
    doc="""SDF readers ignore elements they do not know (with a console warning nobody reads):
    a misspelt `<inertia>` written as `<inertial>` inside `<inertial>`, or `<limits>` for
    `<limit>`, silently becomes the default value. Custom elements need a namespace prefix
    (`<my:thing>`), which SDFormat allows anywhere.""",
    bad=_model('<link name="base"><inertial><mass>1</mass><inertia><ixx>0.1</ixx>'
               "<iyy>0.1</iyy><izz>0.1</izz></inertia><center>0 0 0</center></inertial></link>"),
    good=_model(_BASE),
)

source_rule(
    "sdf.unknown-attribute", "warning", "an attribute SDFormat does not define here",
    doc="""SDF readers ignore unknown attributes: `<pose relative-to="...">` (a hyphen for an
    underscore) leaves the pose relative to the default frame, silently.""",
    bad=_model('<link name="base"><pose relative-to="__model__">0 0 1 0 0 0</pose></link>'),
    good=_model('<link name="base"><pose relative_to="__model__">0 0 1 0 0 0</pose></link>'),
)

source_rule(
    "sdf.bad-value", "error", "a value that does not parse, or an impossible one",
    doc="""Numbers, vectors and poses that do not parse, unknown joint types, a joint whose
    parent and child are the same link: SDF readers reject the file or fall back to defaults.""",
    bad=_model('<link name="base"><pose>0 0 1 0 0</pose></link>'),
    good=_model('<link name="base"><pose>0 0 1 0 0 0</pose></link>'),
)

source_rule(
    "sdf.missing-element", "error", "a required element or name is missing",
    doc="""Links, joints, frames and models need a name; a joint needs a type, a parent and a
    child; a visual or collision needs a geometry; a mesh needs a uri. SDF readers reject the
    element.""",
    bad=_model(_BASE + _ARM + '<joint name="j" type="fixed"><parent>base</parent></joint>'),
    good=_model(_BASE + _ARM + '<joint name="j" type="fixed"><parent>base</parent>'
                "<child>arm</child></joint>"),
)

source_rule(
    "sdf.missing-frame", "error", "a joint, pose or axis names a frame that does not exist",
    doc="""Joint `<parent>`/`<child>`, `relative_to`, `expressed_in`, `attached_to`,
    `canonical_link` and `placement_frame` must name a link, joint, frame or nested model of the
    same model (or `__model__`). A joint naming a missing link cannot be built; a pose relative to
    a missing frame falls back to its default frame, which is not what was meant.""",
    bad=_model(_BASE + _ARM + _HINGE.replace("<child>arm</child>", "<child>amr</child>")),
    good=_model(_BASE + _ARM + _HINGE),
)

source_rule(
    "sdf.pose-cycle", "error", "poses are relative to each other in a cycle",
    doc="""With `relative_to` (SDFormat 1.7+), each pose is placed in another frame. If frame A
    is relative to B and B relative to A, neither has a place: SDF readers reject the model.""",
    bad=_model('<link name="a"><pose relative_to="b">1 0 0 0 0 0</pose></link>'
               '<link name="b"><pose relative_to="a">0 1 0 0 0 0</pose></link>'),
    good=_model('<link name="a"><pose>1 0 0 0 0 0</pose></link>'
                '<link name="b"><pose relative_to="a">0 1 0 0 0 0</pose></link>'),
)

source_rule(
    "sdf.duplicate-name", "error", "two links, joints, frames or models share a name",
    doc="""Names are how joints, poses and plugins find things; two with one name make every
    reference ambiguous. SDFormat requires distinct names among the frames of a model, and
    libsdformat follows the version: two links (two joints, two frames) with one name are
    refused in every version; below 1.7 a link, a joint and a frame may share a name, and
    libsdformat (so Gazebo) loads the file with a warning, renaming the later one in document
    order `NAME_joint`, `NAME_link` or `NAME_frame` (then `NAME_joint0`...): urdftool does the
    same and says so (a warning). From 1.7 on the clash is refused (an error). A model
    included twice without `<name>` (both take the included model's own name) is one finding
    at the includer's second `<include>`, with a `<name>` to write, never inside the included
    file; in a world, a second model of one name is a warning (Gazebo refuses to add it).""",
    bad=_model(_BASE + _LINK.format("base")),
    good=_model(_BASE + _ARM),
)

source_rule(
    "sdf.version-feature", "warning", "a feature the file's SDFormat version does not have",
    doc="""`relative_to` and `expressed_in` need 1.7, `use_parent_model_frame` was removed in
    1.7, `degrees` and quaternions need 1.9, `<mimic>` needs 1.11. A reader of the declared
    version ignores the feature (and so does urdftool): either the version or the feature is
    wrong.""",
    bad=_model(_BASE + '<link name="arm"><pose relative_to="base">0 0 1 0 0 0</pose></link>',
               version="1.6"),
    good=_model(_BASE + '<link name="arm"><pose relative_to="base">0 0 1 0 0 0</pose></link>',
                version="1.7"),
)

source_rule(
    "sdf.include", "error", "an <include> cannot be resolved or read",
    doc="""`<include><uri>model://NAME</uri>` is found through `--model-path`,
    `GZ_SIM_RESOURCE_PATH`, `IGN_GAZEBO_RESOURCE_PATH`, `GAZEBO_MODEL_PATH` and the folders
    beside the file. urdftool never downloads (Fuel URLs are reported). A missing include leaves
    its links and joints out of the robot.""",
    bad=_model(_BASE + "<include><uri>model://no_such_model_anywhere</uri></include>"),
    good=_model(_BASE),
)

source_rule(
    "sdf.unsupported-joint", "warning", "a joint type URDF has not got, converted to its nearest form",
    doc="""URDF knows revolute, continuous, prismatic, fixed, floating and planar. A `ball` is
    written as three continuous joints (x, y, z) through two massless links, `universal` and
    `revolute2` as two revolute joints, `screw` as a revolute joint with a prismatic one mimicking
    it, and a `gearbox` as a `<mimic>` between the two hinges it couples. Kinematics are kept;
    simulators see extra links, and the ball's chain has a singularity.""",
    bad=_model(_BASE + _ARM + '<joint name="j" type="ball"><parent>base</parent>'
               "<child>arm</child></joint>"),
    good=_model(_BASE + _ARM + _HINGE),
)

source_rule(
    "sdf.unsupported-geometry", "warning", "a shape URDF has not got: approximated or dropped",
    doc="""URDF has box, cylinder, sphere and mesh. A capsule is written exactly as a cylinder and
    two spheres (an info); an ellipsoid or a cone is replaced by the sphere or cylinder that
    encloses it; planes, heightmaps, polylines and images are dropped (they belong to the world,
    or need a mesh).""",
    bad=_model('<link name="base"><collision name="c"><geometry><plane><normal>0 0 1</normal>'
               "</plane></geometry></collision></link>"),
    good=_model('<link name="base"><collision name="c"><geometry><box><size>1 1 0.1</size>'
                "</box></geometry></collision></link>"),
)

source_rule(
    "sdf.kinematic-loop", "warning", "a kinematic loop: one joint is cut to make a URDF tree",
    doc="""SDF models may close loops (a four-bar linkage, a parallel gripper). URDF is a tree,
    so urdftool keeps a spanning tree that attaches every link (grown from the world or the root
    link, joints taken in document order, the SDF way round first) and cuts the joint of each
    loop whose two links are already attached, naming the loop; the loop then has to be closed
    in the simulator. `urdftool convert --no-cut` refuses instead. Gazebo simulates the SDF loop
    as written; a URDF simulator sees the open chain.""",
    bad=_model(_BASE + _ARM + _HINGE + _HINGE.replace('name="j"', 'name="k"')),
    good=_model(_BASE + _ARM + _HINGE),
)

source_rule(
    "sdf.reversed-joint", "info", "a joint written the other way round to keep its link attached",
    doc="""A link whose only joint makes it the *parent* of a link that already hangs on another
    joint (a sensor bolted on with the joint written backwards, a parallel link of a gripper)
    is not a loop: SDF and Gazebo accept it. URDF gives each link one parent, so urdftool writes
    that joint reversed: parent and child swapped, the origin inverted and the axis flipped, so
    that +q is the same relative motion and limits, mimics and controllers keep their meaning.
    The converted robot moves exactly as the SDF does; only the joint's direction changed.""",
    bad=_model(_BASE + _ARM + _LINK.format("sensor") + _HINGE
               + '<joint name="mount" type="fixed"><parent>sensor</parent><child>arm</child>'
               "</joint>"),
    good=_model(_BASE + _ARM + _LINK.format("sensor") + _HINGE
                + '<joint name="mount" type="fixed"><parent>arm</parent><child>sensor</child>'
                "</joint>"),
)

source_rule(
    "sdf.disconnected-link", "warning", "a link joined to nothing: hung on the root by a floating joint",
    doc="""An SDF model may hold free bodies that no joint connects (directly or through other
    links) to the rest of the model; Gazebo simulates them as free bodies. A URDF has exactly
    one root, so each free body is joined to the root by a `floating` joint (a `fixed` one in a
    static model), which keeps it free but is read differently by different tools (many ignore
    floating joints). A link that has a joint, whichever way round, is never floating: see
    `sdf.reversed-joint` and `sdf.kinematic-loop`.""",
    bad=_model(_BASE + _ARM),
    good=_model(_BASE + _ARM + _HINGE),
)

source_rule(
    "sdf.not-in-urdf", "info", "something URDF has no place for: kept in a <gazebo> block or dropped",
    doc="""Sensors, plugins, `<static>`, `<gravity>false`, `<kinematic>` and self-collision are
    kept in `<gazebo>` blocks (Gazebo reads them; other URDF tools do not); joint springs,
    one-sided limits, submeshes, lights and velocity decay are dropped; unlimited effort and
    velocity become 1e16 because URDF requires a number. Each is said once, where it was
    written.""",
    bad=_model('<link name="base"><inertial><mass>1</mass><inertia><ixx>0.1</ixx><iyy>0.1</iyy>'
               "<izz>0.1</izz></inertia></inertial><gravity>false</gravity></link>"),
    good=_model(_BASE),
)

source_rule(
    "sdf.default-inertial", "warning", "a link without <inertial>: SDF's default mass 1 kg is written out",
    doc="""In SDFormat a link with no `<inertial>` has mass 1 and inertia diag(1, 1, 1), not
    zero, and Gazebo simulates it so. The converted URDF writes those values out so that it
    means what the SDF meant; if the link is really a massless frame, make it a `<frame>`.

    Graded by consequence, the share of the model's mass in Gazebo that nobody wrote (the
    default kilograms over those plus the masses the model declares): an error from 50% (the
    default masses dominate the dynamics: three frame links on a 1.4 kg robot triple its mass),
    a warning from 10%, advice below; a warning when no link declares an `<inertial>` (each is
    simulated as 1 kg). Not reported on a static model (`<static>true</static>`, or nested in
    one): Gazebo never integrates it, and the `inertia` rules do not judge its default values
    either. Elsewhere they say that the value they judge is SDFormat's default, not the
    author's.""",
    bad=_model('<link name="base"/>'),
    good=_model(_BASE),
)

source_rule(
    "sdf.mesh-uri", "warning", "a mesh URI URDF tools cannot read",
    doc="""URDF tools read local paths and `package://` URIs. `model://NAME/...` is rewritten to
    a path when the model is found (`--model-path`, resource path variables) or to
    `package://...` with `--package-uri`; otherwise, and for network URLs, it is kept as written
    and will not load. One finding per missing model (and one for network meshes), at its first
    mesh, counting the rest.""",
    bad=_model('<link name="base"><visual name="v"><geometry><mesh><uri>model://no_such_model'
               "_anywhere/meshes/a.dae</uri></mesh></geometry></visual></link>"),
    good=_model('<link name="base"><visual name="v"><geometry><box><size>1 1 1</size></box>'
                "</geometry></visual></link>"),
)
