"""``urdftool diff --render DIR`` (issue 30): before/after pictures of each changed robot at its
zero configuration, with PyBullet's CPU renderer (TinyRenderer, offscreen, as ``sim --render``:
``sim.render``'s camera, snapshot and PNG writer): one fixed camera framing both sides, the
links a change touched in red and the others grey, so that the two pictures differ only where
the robot did.
"""

from __future__ import annotations

import re
import tempfile
from pathlib import Path

from lxml import etree

from urdftool.errors import require

HIGHLIGHT = [0.9, 0.15, 0.1, 1.0]
OTHER = [0.72, 0.74, 0.78, 1.0]
SIZE = (640, 480)


def changed_links(robot_diff, side: str) -> set[str]:
    """The links a robot's changes touch at one side ("base" or "head"): changed links, the
    child links of changed joints and the links below a changed origin."""
    entry = robot_diff.base if side == "base" else robot_diff.head
    robot = entry.robot
    names: set[str] = set()
    for change in robot_diff.changes:
        name = change.before if side == "base" and change.aspect == "renamed" else change.name
        if change.element == "link" and name:
            names.add(name)
        elif change.element == "joint" and name and robot.joint(name) is not None:
            joint = robot.joint(name)
            if joint.child:
                names.add(joint.child)
                if change.aspect == "origin":
                    names.update(_below(robot, joint.child))
    return names


def _below(robot, link: str) -> list[str]:
    found, todo = [], [link]
    while todo:
        for joint in robot.child_joints(todo.pop()):
            if joint.child and joint.child not in found:
                found.append(joint.child)
                todo.append(joint.child)
    return found


def urdf_for_render(robot) -> str:
    """The robot's expanded XML with every mesh as an absolute path and what PyBullet does not
    draw (gazebo, transmission, ros2_control) left out."""
    from urdftool.physics.meshes import resolve

    root = etree.fromstring(etree.tostring(robot.root))
    by_element = {}
    for link, element in zip(robot.links, (e for e in robot.root if e.tag == "link")):
        by_element[element.get("name")] = link
    for element in list(root):
        if element.tag in ("gazebo", "transmission", "ros2_control") or not isinstance(
                element.tag, str):
            root.remove(element)
    for link_element in root.iter("link"):
        link = by_element.get(link_element.get("name"))
        meshes = [e for e in link_element.iter("mesh")]
        shapes = [s for s in (link.visuals + link.collisions) if s.geometry.kind == "mesh"] \
            if link is not None else []
        for mesh, shape in zip(meshes, shapes):
            try:
                path = resolve(robot, shape.geometry)
            except Exception:  # noqa: BLE001 - unresolvable: drawn without it
                path = None
            if path is not None and Path(path).is_file():
                mesh.set("filename", str(Path(path).resolve()))
            else:
                mesh.getparent().getparent().getparent().remove(mesh.getparent().getparent())
    return etree.tostring(root, encoding="unicode")


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_")[:120] or "robot"


def render_robots(robots, directory: Path, size=SIZE) -> dict[str, tuple[str, str]]:
    """Write ``<robot>-before.png`` and ``<robot>-after.png`` for each changed robot; returns
    robot title -> (before, after) paths as written."""
    from urdftool.diff.formats import robot_title
    from urdftool.sim.capture import captured_fds

    with captured_fds():  # (its build banner)
        require("pybullet", "sim")
        import pybullet
        from pybullet_utils import bullet_client
    from urdftool.sim.render import _bounds, _camera, _snapshot, write_png

    written: dict[str, tuple[str, str]] = {}
    width, height = size
    for robot_diff in robots:
        if robot_diff.status != "changed":
            continue
        title = robot_title(robot_diff)
        sides = [("base", robot_diff.base.robot), ("head", robot_diff.head.robot)]
        with tempfile.TemporaryDirectory(prefix="urdftool-render-") as scratch, captured_fds():
            client = bullet_client.BulletClient(connection_mode=pybullet.DIRECT)
            try:
                files = []
                for index, (_, robot) in enumerate(sides):
                    file = Path(scratch) / f"{index}.urdf"
                    file.write_text(urdf_for_render(robot), encoding="utf-8")
                    files.append(file)

                def load(file, client=client):
                    return client.loadURDF(str(file), useFixedBase=True,
                                           flags=pybullet.URDF_USE_INERTIA_FROM_FILE)

                lows, highs = [], []
                for file in files:  # one camera for both: framing the two robots
                    body = load(file)
                    low, high = _bounds(client, body, [-1, *range(client.getNumJoints(body))])
                    lows.append(low)
                    highs.append(high)
                    client.removeBody(body)
                low = [min(v[k] for v in lows) for k in range(3)]
                high = [max(v[k] for v in highs) for k in range(3)]
                view, projection = _camera(client, low, high, width, height)
                paths = []
                for (side, _), file in zip(sides, files):
                    body = load(file)
                    highlighted = changed_links(robot_diff, side)
                    names = {-1: client.getBodyInfo(body)[0].decode("utf-8", "replace")}
                    for i in range(client.getNumJoints(body)):
                        names[i] = client.getJointInfo(body, i)[12].decode("utf-8", "replace")
                    for i, name in names.items():
                        client.changeVisualShape(body, i, rgbaColor=HIGHLIGHT if name in
                                                 highlighted else OTHER)
                    target = directory / f"{_slug(title)}-{'before' if side == 'base' else 'after'}.png"
                    write_png(target, _snapshot(client, view, projection, width, height), width,
                              height)
                    paths.append(str(target))
                    client.removeBody(body)
                written[title] = (paths[0], paths[1])
            finally:
                client.disconnect()
    return written
