"""Pictures of a model at rest: PyBullet's CPU renderer (TinyRenderer), a three-quarter view
framing the whole robot, once with the visual geometry and once with the collision geometry
(each collision shape drawn as a visual, in orange), so that a person sees at a glance that a
wheel is sideways or a collision box is somewhere else than the mesh it stands for.

A collision mesh is drawn as the mesh itself; PyBullet collides with its convex hull.
"""

from __future__ import annotations

import math
import struct
import zlib
from pathlib import Path

from lxml import etree

COLLISION_RGBA = "1 0.45 0.05 1"
YAW, PITCH, FOV = 45.0, -25.0, 40.0


def write_png(path: str | Path, rgb, width: int, height: int) -> None:
    """An 8-bit RGB PNG from ``rgb`` (a uint8 array of shape (height, width, 3))."""
    raw = b"".join(b"\x00" + bytes(rgb[row].tobytes()) for row in range(height))

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    data = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) +
            chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))
    from urdftool.output import write_file

    write_file(path, data, make_dirs=True)  # atomic, through no link, over no file read


def collision_as_visual(urdf_text: str, mesh_paths: dict[str, str]) -> str:
    """The same robot with each link's visuals replaced by copies of its collisions."""
    root = etree.fromstring(urdf_text.encode("utf-8"))
    for link in root.iter("link"):
        for visual in link.findall("visual"):
            link.remove(visual)
        for collision in link.findall("collision"):
            visual = etree.SubElement(link, "visual")
            for child in collision:
                if isinstance(child.tag, str) and child.tag in ("origin", "geometry"):
                    visual.append(_copy(child))
            material = etree.SubElement(visual, "material", name="urdftool_collision")
            etree.SubElement(material, "color", rgba=COLLISION_RGBA)
    for mesh in root.iter("mesh"):
        filename = mesh.get("filename")
        if filename in mesh_paths:
            mesh.set("filename", mesh_paths[filename])
    for tag in ("gazebo", "transmission"):
        for element in root.findall(tag):
            root.remove(element)
    return etree.tostring(root, encoding="unicode")


def _copy(element):
    import copy

    return copy.deepcopy(element)


def _bounds(p, body, links):
    lows, highs = [], []
    for index in links:
        low, high = p.getAABB(body, index)
        lows.append(low)
        highs.append(high)
    low = [min(v[k] for v in lows) for k in range(3)]
    high = [max(v[k] for v in highs) for k in range(3)]
    return low, high


def _camera(p, low, high, width: int, height: int):
    center = [(a + b) / 2 for a, b in zip(low, high)]
    radius = max(0.05, 0.5 * math.dist(low, high))
    vertical = math.radians(FOV) / 2
    horizontal = math.atan(math.tan(vertical) * width / height)
    distance = 1.1 * radius / math.sin(min(vertical, horizontal))
    view = p.computeViewMatrixFromYawPitchRoll(center, distance, YAW, PITCH, 0, 2)
    projection = p.computeProjectionMatrixFOV(FOV, width / height, distance / 50, distance * 10)
    return view, projection


def _snapshot(p, view, projection, width: int, height: int):
    import numpy as np
    import pybullet

    image = p.getCameraImage(width, height, view, projection, shadow=1,
                             lightDirection=[1, 1, 2], renderer=pybullet.ER_TINY_RENDERER)
    pixels = np.asarray(image[2], dtype=np.uint8).reshape(height, width, 4)
    return np.ascontiguousarray(pixels[:, :, :3])


def render_model(run, target: str) -> list[str]:
    """Write ``target`` (the visual geometry) and ``<target stem>-collision.png`` for the model
    of ``run`` (an engine ``_Run`` after its simulation); returns the paths written."""
    import pybullet

    p, body, prepared = run.client, run.body, run.prepared
    width, height = run.options.size
    links = list(run.link_names)
    low, high = _bounds(p, body, links)
    view, projection = _camera(p, low, high, width, height)
    target_path = Path(target)
    written = []
    write_png(target_path, _snapshot(p, view, projection, width, height), width, height)
    written.append(str(target_path))

    position, orientation = p.getBasePositionAndOrientation(body)
    joints = {name: p.getJointState(body, index)[0] for name, index in run.joint_index.items()}
    text = collision_as_visual(prepared.urdf_text, prepared.mesh_paths)
    directory = Path(prepared.scratch_dir())
    collision_file = directory / "collision.urdf"
    collision_file.write_text(text, encoding="utf-8")
    p.removeBody(body)
    run.body = None
    # loaded like the model (a fixed and a free base place their frames differently); nothing
    # steps the simulation any more, so a free one stays where it is put
    shown = p.loadURDF(str(collision_file), position, orientation, useFixedBase=prepared.anchored,
                       flags=pybullet.URDF_IGNORE_COLLISION_SHAPES |
                       pybullet.URDF_USE_INERTIA_FROM_FILE)
    p.resetBasePositionAndOrientation(shown, position, orientation)
    for index in range(p.getNumJoints(shown)):
        name = p.getJointInfo(shown, index)[1].decode("utf-8", "replace")
        if name in joints:
            p.resetJointState(shown, index, joints[name])
    collision_path = target_path.with_name(target_path.stem + "-collision.png")
    write_png(collision_path, _snapshot(p, view, projection, width, height), width, height)
    written.append(str(collision_path))
    return written
