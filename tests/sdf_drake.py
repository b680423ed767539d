"""Drake as the independent oracle for `urdftool convert`: the SDF is loaded by Drake's own
SDFormat parser (libsdformat inside), the converted URDF by Drake's URDF parser, and every SDF
body is compared in the two plants: its mass, COM and inertia about the COM (in the frame of the
reference body, the URDF root) at the default configuration and at random joint
configurations, and its pose relative to the reference body at those configurations (a URDF link
frame may sit at its joint: that constant offset is taken at the default configuration).
Nothing here calls urdftool's maths.

Joint values are set by joint name: a 1-DOF SDF joint and the URDF joint of the same name take the
same value (a joint urdftool reverses keeps the sense of +q, so the same value). Multi-DOF SDF
joints (universal, ball, revolute2) are held at zero in the random configurations; the screw
joint is a 1-DOF joint in Drake, its revolute part in the URDF (a URDF <mimic> follower is set
from its leader here: Drake does not couple mimics kinematically). Names: a body of a nested
model ``a::b`` is ``a__b`` in the URDF (urdftool's documented naming).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from lxml import etree
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import BodyIndex

ONE_DOF = ("revolute", "prismatic", "screw")


class Plant:
    """A finalized Drake plant of one file (no SceneGraph: geometry is not loaded)."""

    def __init__(self, path: Path | None = None, text: str | None = None, kind: str = "sdf",
                 model: str | None = None, model_paths: tuple[Path, ...] = ()):
        self.plant = MultibodyPlant(0.0)
        parser = Parser(self.plant)
        for directory in model_paths:  # Drake resolves model://NAME as the package NAME
            for config in Path(directory).glob("*/model.config"):
                if not parser.package_map().Contains(config.parent.name):
                    parser.package_map().Add(config.parent.name, str(config.parent))
        if text is not None:
            instances = parser.AddModelsFromString(text, kind)
        else:
            instances = parser.AddModels(str(path))
        self.plant.Finalize()
        self.context = self.plant.CreateDefaultContext()
        names = [self.plant.GetModelInstanceName(i) for i in instances]
        top = model if model is not None else names[0]
        assert top in names, f"Drake has no model {top!r} in {path} ({names})"

        def key(element) -> str | None:
            instance = self.plant.GetModelInstanceName(element.model_instance())
            if instance == top:
                return element.name()
            if instance.startswith(top + "::"):
                return instance[len(top) + 2:] + "::" + element.name()
            return None

        self.bodies = {}
        for index in range(self.plant.num_bodies()):
            body = self.plant.get_body(BodyIndex(index))
            if key(body) is not None:
                self.bodies[key(body)] = body
        self.joints = {}
        for index in self.plant.GetJointIndices():
            joint = self.plant.get_joint(index)
            if key(joint) is not None:
                self.joints[key(joint)] = joint

    def set(self, values: dict[str, float]) -> None:
        self.context = self.plant.CreateDefaultContext()
        q = self.plant.GetPositions(self.context)
        for name, value in values.items():
            q[self.joints[name].position_start()] = value
        self.plant.SetPositions(self.context, q)

    def pose(self, body) -> np.ndarray:
        return self.plant.EvalBodyPoseInWorld(self.context, body).GetAsMatrix4()

    def mass_properties(self, body) -> tuple[float, np.ndarray, np.ndarray]:
        """(mass, world COM, world inertia about the COM)."""
        pose = self.pose(body)
        inertia = body.CalcSpatialInertiaInBodyFrame(self.context)
        mass = inertia.get_mass()
        com = inertia.get_com()
        about_com = inertia.Shift(com).CalcRotationalInertia().CopyToFullMatrix3()
        rotation = pose[:3, :3]
        return mass, pose[:3, :3] @ com + pose[:3, 3], rotation @ about_com @ rotation.T


def drake_copy(path: Path, directory: Path, model_paths: tuple[Path, ...] = (),
               model: str | None = None) -> tuple[Path, Plant | RuntimeError]:
    """The file as Drake will read it: Drake's libsdformat refuses elements and attributes
    SDFormat does not define (pybullet_data's <contact>, concave="yes") where Gazebo ignores
    them, and resolves model://NAME only to a file: those are removed or completed here.
    Nothing that places a body, a joint or a mass is touched. Returns the copy and its plant
    (or Drake's refusal)."""
    import re

    text = path.read_text()
    for directory_ in model_paths:
        for config in Path(directory_).glob("*/model.config"):
            name = config.parent.name
            for candidate in ("model.sdf", *sorted(p.name for p in config.parent.glob("*.sdf"))):
                if (config.parent / candidate).exists():
                    text = text.replace(f"<uri>model://{name}</uri>",
                                        f"<uri>model://{name}/{candidate}</uri>")
                    break
    out = directory / path.name
    refusal = RuntimeError("Drake kept refusing the file")
    for _ in range(20):
        out.write_text(text)
        try:
            return out, Plant(path=out, model=model, model_paths=model_paths)
        except RuntimeError as exc:
            refusal, message = exc, str(exc)
            attribute = re.search(r"XML Attribute\[(\w+)\] in element\[(\w+)\]", message)
            element = re.search(r"XML Element\[(\w+)\], child of element\[(\w+)\]", message)
            if attribute:
                root = etree.fromstring(text.encode())
                for node in root.iter(attribute.group(2)):
                    node.attrib.pop(attribute.group(1), None)
                text = etree.tostring(root, encoding="unicode")
            elif element:
                root = etree.fromstring(text.encode())
                for node in list(root.iter(element.group(1))):
                    if node.getparent().tag == element.group(2):
                        node.getparent().remove(node)
                text = etree.tostring(root, encoding="unicode")
            else:
                return out, exc  # refused for another reason
    return out, refusal


def urdf_name(key: str) -> str:
    return key.replace("::", "__")


def compare(sdf: Path, urdf_text: str, configurations: int = 20, seed: int = 0,
            renamed: dict[str, str] | None = None, model: str | None = None,
            model_paths: tuple[Path, ...] = (), plant: Plant | None = None) -> dict[str, float]:
    """Largest differences between the SDF (Drake's parser) and the URDF, over every SDF body:
    ``pose`` (largest entry of the difference of the 4x4 poses relative to the reference body),
    ``mass``, ``com``, ``inertia``; with ``configurations``, ``bodies`` and ``moved_joints``.
    ``renamed``: SDF body/joint key -> URDF name where the test expects a renaming."""
    renamed = renamed or {}
    a = plant or Plant(path=sdf, model=model, model_paths=model_paths)
    sdf_mimics = {}  # SDF 1.11 follower -> (leader, multiplier, offset, reference)
    for joint in etree.parse(str(sdf)).getroot().iter("joint"):
        mimic = joint.find("axis/mimic")
        if mimic is not None and joint.get("name") in a.joints:
            sdf_mimics[joint.get("name")] = (mimic.get("joint"), *(
                float(mimic.findtext(tag, default)) for tag, default in
                (("multiplier", "1"), ("offset", "0"), ("reference", "0"))))
    mimics = {}  # URDF follower -> (leader, multiplier, offset): Drake does not couple them
    for joint in etree.fromstring(urdf_text.encode()).iter("joint"):
        mimic = joint.find("mimic")
        if mimic is not None:
            mimics[joint.get("name")] = (mimic.get("joint"), float(mimic.get("multiplier", "1")),
                                         float(mimic.get("offset", "0")))
    b = Plant(text=urdf_text, kind="urdf")
    missing = [k for k in a.bodies if renamed.get(k, urdf_name(k)) not in b.bodies]
    assert not missing, f"SDF bodies missing from the URDF: {missing}"
    pairs = [(a.bodies[k], b.bodies[renamed.get(k, urdf_name(k))]) for k in a.bodies]

    def urdf_joint(key: str) -> str | None:
        """Drake files a joint under its child's model instance: a joint of the top model
        whose child is nested is 'nested::joint' there, 'joint' in the URDF."""
        candidates = (renamed.get(key), urdf_name(key), key.rsplit("::", 1)[-1])
        return next((c for c in candidates if c in b.joints), None)

    movable = {k: urdf_joint(k) for k, j in a.joints.items()
               if j.type_name() in ONE_DOF and urdf_joint(k)}
    rng = np.random.default_rng(seed)
    worst = {"pose": 0.0, "mass": 0.0, "com": 0.0, "inertia": 0.0, "configurations": 0}
    # A URDF link's frame may differ from the SDF link's (a moving child's frame is its joint's);
    # the URDF root keeps its SDF frame, so it is the reference body. The constant offset of
    # each link frame is read at the default configuration, then every body's pose relative
    # to the reference must agree at every configuration. Mass, COM and inertia are compared
    # in the reference body's frame, where the link frames do not matter.
    world = b.plant.world_body().index()
    inboard = {j.child_body().index() for j in map(b.plant.get_joint, b.plant.GetJointIndices())
               if "floating" not in j.type_name() and j.parent_body().index() != world}
    pairs.sort(key=lambda pair: pair[1].index() in inboard)
    a.set({})
    b.set({})
    ref_a, ref_b = a.pose(pairs[0][0]), b.pose(pairs[0][1])
    offsets = [np.linalg.inv(np.linalg.inv(ref_b) @ b.pose(body_b))
               @ np.linalg.inv(ref_a) @ a.pose(body_a) for body_a, body_b in pairs]
    for index in range(configurations + 1):
        values = {} if index == 0 else {k: float(rng.uniform(-np.pi, np.pi)) for k in movable}
        for follower, (leader, multiplier, offset, reference) in sdf_mimics.items():
            if leader in values and follower in values:  # SDF: m (leader - reference) + offset
                values[follower] = multiplier * (values[leader] - reference) + offset
        a.set(values)
        urdf_values = {movable[k]: v for k, v in values.items()}
        for follower, (leader, multiplier, offset) in mimics.items():
            if leader in urdf_values and follower in b.joints:
                urdf_values[follower] = multiplier * urdf_values[leader] + offset
        b.set(urdf_values)
        ref_a, ref_b = a.pose(pairs[0][0]), b.pose(pairs[0][1])
        for (body_a, body_b), offset in zip(pairs, offsets):
            relative_a = np.linalg.inv(ref_a) @ a.pose(body_a)
            relative_b = np.linalg.inv(ref_b) @ b.pose(body_b) @ offset
            worst["pose"] = max(worst["pose"], float(np.abs(relative_a - relative_b).max()))
            mass_a, com_a, inertia_a = a.mass_properties(body_a)
            mass_b, com_b, inertia_b = b.mass_properties(body_b)
            com_a = (np.linalg.inv(ref_a) @ np.append(com_a, 1.0))[:3]
            com_b = (np.linalg.inv(ref_b) @ np.append(com_b, 1.0))[:3]
            ra, rb = ref_a[:3, :3], ref_b[:3, :3]
            worst["mass"] = max(worst["mass"], abs(mass_a - mass_b))
            worst["com"] = max(worst["com"], float(np.abs(com_a - com_b).max()))
            worst["inertia"] = max(worst["inertia"], float(np.abs(
                ra.T @ inertia_a @ ra - rb.T @ inertia_b @ rb).max()))
        worst["configurations"] = index
    worst["bodies"] = len(pairs)
    worst["moved_joints"] = len(movable)
    return worst
