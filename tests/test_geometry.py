"""The `geometry` family: nonpositive sizes, gross visual/collision mismatch, missing collision."""

from __future__ import annotations

import math

import pytest

from urdftool.check import CheckOptions, check_file
from urdftool.model import Geometry, Pose, Shape
from urdftool.rules import geometry


def fired(path, rule_id):
    return [d for d in check_file(path, CheckOptions(select=[rule_id])).diagnostics
            if d.rule == rule_id]


def robot(link_body: str, joint_type: str = "continuous") -> str:
    """The link under test is 'wheel', on a joint of ``joint_type``; its body starts on line 4."""
    return ('<?xml version="1.0"?>\n<robot name="r">\n  <link name="wheel">\n'
            f"{link_body}\n  </link>\n  <link name=\"base\"/>\n"
            f'  <joint name="axle" type="{joint_type}">\n    <parent link="base"/>\n'
            '    <child link="wheel"/>\n    <axis xyz="0 1 0"/>\n  </joint>\n</robot>\n')


def shape(role, geometry_xml, origin=""):
    return f"    <{role}>{origin}<geometry>{geometry_xml}</geometry></{role}>"


INERTIAL = ('    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" '
            'iyz="0" izz="0.01"/></inertial>')


# -- nonpositive-size ---------------------------------------------------------------------------


@pytest.mark.parametrize("xml", [
    '<box size="0.1 0 0.1"/>', '<box size="0.1 -0.1 0.1"/>', '<cylinder radius="0" length="1"/>',
    '<cylinder radius="0.1" length="-1"/>', '<sphere radius="-0.1"/>',
    '<mesh filename="m.stl" scale="1 0 1"/>'])
def test_nonpositive_collision_sizes_are_errors(write, xml):
    [d] = fired(write(robot(shape("collision", xml))), "geometry.nonpositive-size")
    assert (d.severity, d.line) == ("error", 4)


def test_zero_visual_is_a_warning_and_mirroring_mesh_is_fine(write):
    [d] = fired(write(robot(shape("visual", '<sphere radius="0"/>'))), "geometry.nonpositive-size")
    assert d.severity == "warning" and "draws nothing" in d.message
    assert fired(write(robot(shape("visual", '<mesh filename="m.stl" scale="-1 1 1"/>')),
                       "mirror.urdf"), "geometry.nonpositive-size") == []


# -- bounds (checked against a direct computation) ----------------------------------------------


def _corners_bounds(size, rpy, xyz):
    """Bounding box of a box's eight corners, rotated by an independent rotation matrix
    (Rx, Ry, Rz multiplied here, not the rule's closed form)."""
    r, p, y = rpy

    def matmul(a, b):
        return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]

    rx = [[1, 0, 0], [0, math.cos(r), -math.sin(r)], [0, math.sin(r), math.cos(r)]]
    ry = [[math.cos(p), 0, math.sin(p)], [0, 1, 0], [-math.sin(p), 0, math.cos(p)]]
    rz = [[math.cos(y), -math.sin(y), 0], [math.sin(y), math.cos(y), 0], [0, 0, 1]]
    rot = matmul(rz, matmul(ry, rx))
    points = []
    for sx in (-1, 1):
        for sy in (-1, 1):
            for sz in (-1, 1):
                c = (sx * size[0] / 2, sy * size[1] / 2, sz * size[2] / 2)
                points.append([xyz[i] + sum(rot[i][k] * c[k] for k in range(3))
                               for i in range(3)])
    return ([min(p[i] for p in points) for i in range(3)],
            [max(p[i] for p in points) for i in range(3)])


@pytest.mark.parametrize("rpy", [(0, 0, 0), (0.3, -0.7, 1.1), (math.pi / 2, 0, 0), (1, 2, 3)])
def test_box_bounds_match_rotated_corners(rpy):
    size, xyz = (0.4, 0.1, 0.2), (0.5, -0.2, 1.0)
    box = Shape("collision", None, Pose(xyz, rpy), Geometry("box", size=size))
    low, high = geometry._bounds(box)
    want_low, want_high = _corners_bounds(size, rpy, xyz)
    assert low == pytest.approx(want_low) and high == pytest.approx(want_high)


def test_cylinder_bounds_lying_down():
    lying = Shape("visual", None, Pose((0, 0, 0), (math.pi / 2, 0, 0)),
                  Geometry("cylinder", radius=0.1, length=1.0))
    low, high = geometry._bounds(lying)
    assert low == pytest.approx((-0.1, -0.5, -0.1)) and high == pytest.approx((0.1, 0.5, 0.1))


# -- visual-collision-mismatch ------------------------------------------------------------------


def test_collision_ten_times_the_visual(write):
    path = write(robot(shape("visual", '<cylinder radius="0.05" length="0.02"/>') + "\n"
                       + shape("collision", '<cylinder radius="0.5" length="0.02"/>')))
    [d] = fired(path, "geometry.visual-collision-mismatch")
    assert d.severity == "warning" and d.line == 5 and "10x larger" in d.message


def test_collision_far_from_the_visual(write):
    path = write(robot(shape("visual", '<box size="0.1 0.1 0.1"/>') + "\n"
                       + shape("collision", '<box size="0.1 0.1 0.1"/>', '<origin xyz="1 0 0"/>')))
    [d] = fired(path, "geometry.visual-collision-mismatch")
    assert d.line == 5 and "away from the visual" in d.message


@pytest.mark.parametrize("visual, collision", [
    ('<box size="0.1 0.1 0.1"/>', '<box size="0.12 0.12 0.12"/>'),  # padded
    ('<cylinder radius="0.05" length="0.3"/>', '<box size="0.1 0.1 0.3"/>'),  # simplified
    ('<box size="0.3 0.1 0.1"/>', '<sphere radius="0.16"/>'),
    ('<sphere radius="0.001"/>', '<sphere radius="0.2"/>'),  # a placeholder visual
    ('<mesh filename="m.stl"/>', '<box size="5 5 5"/>'),  # meshes are not compared here
])
def test_reasonable_collisions_are_quiet(write, visual, collision):
    path = write(robot(shape("visual", visual) + "\n" + shape("collision", collision)))
    assert fired(path, "geometry.visual-collision-mismatch") == []


def test_rotated_collision_matches_rotated_visual(write):
    origin = '<origin rpy="1.5708 0 0"/>'
    path = write(robot(shape("visual", '<cylinder radius="0.1" length="0.04"/>', origin) + "\n"
                       + shape("collision", '<box size="0.2 0.2 0.04"/>', origin)))
    assert fired(path, "geometry.visual-collision-mismatch") == []


# -- missing-collision --------------------------------------------------------------------------


def test_moving_link_with_mass_and_visual_but_no_collision(write):
    path = write(robot(INERTIAL + "\n" + shape("visual", '<sphere radius="0.1"/>')))
    [d] = fired(path, "geometry.missing-collision")
    assert (d.severity, d.line) == ("info", 3) and "'axle'" in d.message


@pytest.mark.parametrize("body, joint_type", [
    (INERTIAL + "\n" + shape("visual", '<sphere radius="0.1"/>'), "fixed"),  # does not move
    (shape("visual", '<sphere radius="0.1"/>'), "continuous"),  # no mass
    (INERTIAL, "continuous"),  # nothing to see
    (INERTIAL + "\n" + shape("visual", '<sphere radius="0.1"/>') + "\n"
     + shape("collision", '<sphere radius="0.1"/>'), "continuous"),
])
def test_no_missing_collision(write, body, joint_type):
    assert fired(write(robot(body, joint_type)), "geometry.missing-collision") == []


def test_collision_on_a_welded_child_counts(write):
    text = robot(INERTIAL + "\n" + shape("visual", '<sphere radius="0.1"/>')).replace(
        "</robot>", '  <link name="tyre">' + shape("collision", '<sphere radius="0.1"/>').strip()
        + '</link>\n  <joint name="weld" type="fixed"><parent link="wheel"/>'
        '<child link="tyre"/></joint>\n</robot>')
    assert fired(write(text), "geometry.missing-collision") == []


@pytest.mark.parametrize("origin, size", [("-1e308 0 0", "1 1 1"), ("0 0 0", "1e308 1e308 1")])
def test_visual_collision_mismatch_survives_absurd_numbers(write, origin, size):
    """Found by the fuzzer: huge origins or sizes overflowed the comparison."""
    from urdftool.check import CheckOptions, check_file

    path = write(f'<robot name="r"><link name="a"><visual><origin xyz="{origin}"/><geometry>'
                 f'<box size="{size}"/></geometry></visual><collision><geometry>'
                 '<box size="1 1 1"/></geometry></collision></link></robot>')
    report = check_file(path, CheckOptions(select=["geometry"]))
    assert not [d for d in report.diagnostics if "internal error" in d.message]


def test_robot_without_any_collision_is_one_warning(write):
    # issue 14: check and sim agree: such a robot falls through the floor in `sim`
    path = write(robot(INERTIAL + "\n" + shape("visual", '<sphere radius="0.1"/>')))
    [d] = fired(path, "geometry.no-collision")
    assert d.severity == "warning" and "2 links" in d.message and d.line == 2
    # one collision anywhere, or nothing with mass (a static marker): not reported
    with_one = robot(INERTIAL + "\n" + shape("collision", '<sphere radius="0.1"/>'))
    assert fired(write(with_one, "one.urdf"), "geometry.no-collision") == []
    marker = ('<robot name="m"><link name="m"><inertial><mass value="0"/><inertia ixx="0" '
              'ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial><visual><geometry>'
              '<sphere radius="0.1"/></geometry></visual></link></robot>')
    assert fired(write(marker, "marker.urdf"), "geometry.no-collision") == []
