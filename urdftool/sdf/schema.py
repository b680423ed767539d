"""The SDFormat elements urdftool checks, as data: for each element kind, its attributes and
its children (child name -> kind, or ``None`` for an element whose content is not checked).

This is the union of SDFormat 1.4 to 1.11 for the elements that describe a model's structure
(model, link, joint, frame, inertial, visual, collision, geometry, material, include). Inside
sensors, plugins, surfaces, physics and the like, content is passed on unchecked: those are
copied into ``<gazebo>`` blocks, not interpreted. Elements and attributes with a namespace
prefix (``gz:...``, ``xmlns:...``) are custom elements, allowed anywhere by the spec.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class Kind:
    attributes: frozenset[str] = frozenset()
    children: dict[str, str | None] = field(default_factory=dict)
    open: bool = False  # unknown children allowed (content not checked)


def _k(attributes: str = "", children: dict | None = None, open: bool = False) -> Kind:
    return Kind(frozenset(attributes.split()), children or {}, open)


_LEAF = None
_POSE = "pose"
_PLUGIN = None

_AXIS_CHILDREN = {
    "xyz": "xyz", "use_parent_model_frame": _LEAF, "initial_position": _LEAF,
    "dynamics": "dynamics", "limit": "limit", "mimic": "mimic",
}

SPEC: dict[str, Kind] = {
    "sdf": _k("version", {"world": "world", "model": "model", "actor": None, "light": None}),
    # a world: only its models, includes and frames are read; the rest is the simulator's
    "world": _k("name", {"model": "model", "include": "include", "frame": "frame",
                         "joint": "joint"}, open=True),
    "model": _k("name canonical_link placement_frame namespace", {
        "static": _LEAF, "self_collide": _LEAF, "allow_auto_disable": _LEAF,
        "enable_wind": _LEAF, "pose": _POSE, "frame": "frame", "link": "link",
        "joint": "joint", "plugin": _PLUGIN, "gripper": None, "include": "include",
        "model": "model"}),
    "include": _k("merge", {"uri": _LEAF, "pose": _POSE, "plugin": _PLUGIN, "name": _LEAF,
                            "namespace": _LEAF, "static": _LEAF, "placement_frame": _LEAF}),
    "frame": _k("name attached_to", {"pose": _POSE}),
    "pose": _k("relative_to frame degrees rotation_format"),
    "link": _k("name", {
        "gravity": _LEAF, "enable_wind": _LEAF, "self_collide": _LEAF, "kinematic": _LEAF,
        "must_be_base_link": _LEAF, "velocity_decay": None, "pose": _POSE,
        "inertial": "inertial", "collision": "collision", "visual": "visual",
        "sensor": None, "projector": None, "audio_sink": None, "audio_source": None,
        "battery": None, "light": None, "particle_emitter": None, "frame": "frame",
        "contact": None}),  # <contact>: PyBullet's extension (friction, restitution)
    "inertial": _k("auto", {"mass": _LEAF, "pose": _POSE, "inertia": "inertia",
                            "density": _LEAF, "auto_inertia_params": None,
                            "fluid_added_mass": None, "frame": "frame"}),
    "inertia": _k("", {name: _LEAF for name in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}),
    "visual": _k("name", {
        "cast_shadows": _LEAF, "laser_retro": _LEAF, "transparency": _LEAF,
        "visibility_flags": _LEAF, "meta": None, "pose": _POSE, "material": "material",
        "geometry": "geometry", "plugin": _PLUGIN, "frame": "frame"}),
    "collision": _k("name concave", {  # concave: PyBullet's extension
        "laser_retro": _LEAF, "max_contacts": _LEAF, "pose": _POSE, "geometry": "geometry",
        "surface": None, "density": _LEAF, "material_density": _LEAF,
        "auto_inertia_params": None, "frame": "frame"}),
    "geometry": _k("", {
        "empty": _LEAF, "box": "box", "capsule": "capsule", "cone": "cone",
        "cylinder": "cylinder", "ellipsoid": "ellipsoid", "heightmap": None, "image": None,
        "mesh": "mesh", "plane": "plane", "polyline": None, "sphere": "sphere"}),
    "box": _k("", {"size": _LEAF}),
    "capsule": _k("", {"radius": _LEAF, "length": _LEAF}),
    "cone": _k("", {"radius": _LEAF, "length": _LEAF}),
    "cylinder": _k("", {"radius": _LEAF, "length": _LEAF}),
    "ellipsoid": _k("", {"radii": _LEAF}),
    "sphere": _k("", {"radius": _LEAF}),
    "plane": _k("", {"normal": _LEAF, "size": _LEAF}),
    "mesh": _k("optimization", {"uri": _LEAF, "submesh": None, "scale": _LEAF,
                                "convex_decomposition": None}),
    "material": _k("", {
        "script": None, "shader": None, "render_order": _LEAF, "lighting": _LEAF,
        "ambient": _LEAF, "diffuse": _LEAF, "specular": _LEAF, "emissive": _LEAF,
        "double_sided": _LEAF, "pbr": None, "shininess": _LEAF}),
    "joint": _k("name type", {
        "parent": _LEAF, "child": _LEAF, "gearbox_ratio": _LEAF,
        "gearbox_reference_body": _LEAF, "thread_pitch": _LEAF, "screw_thread_pitch": _LEAF,
        "axis": "axis", "axis2": "axis", "physics": None, "pose": _POSE, "sensor": None,
        "frame": "frame"}),
    "axis": _k("", _AXIS_CHILDREN),
    "xyz": _k("expressed_in"),
    "dynamics": _k("", {"damping": _LEAF, "friction": _LEAF, "spring_reference": _LEAF,
                        "spring_stiffness": _LEAF}),
    "limit": _k("", {"lower": _LEAF, "upper": _LEAF, "effort": _LEAF, "velocity": _LEAF,
                     "stiffness": _LEAF, "dissipation": _LEAF}),
    "mimic": _k("joint axis", {"multiplier": _LEAF, "offset": _LEAF, "reference": _LEAF}),
}

JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "ball", "universal",
               "revolute2", "screw", "gearbox")
GEOMETRY_KINDS = tuple(SPEC["geometry"].children)
