"""urdftool.physics.inertia against closed-form formulas written here, numpy and scipy
(independent of the code under test)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from urdftool.physics import inertia as phys


def close(a, b, rel=1e-9, abs_=1e-15):
    np.testing.assert_allclose(np.asarray(a, dtype=float), np.asarray(b, dtype=float),
                               rtol=rel, atol=abs_)


# -- closed forms (textbook, for a mass m) ----------------------------------------------------


def box_formula(m, a, b, c):
    return np.diag([m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12])


def cylinder_formula(m, r, h):  # axis z
    side = m * (3 * r * r + h * h) / 12
    return np.diag([side, side, m * r * r / 2])


def sphere_formula(m, r):
    return np.eye(3) * 2 / 5 * m * r * r


def capsule_formula(m, r, h):  # cylinder of length h along z, two hemispherical caps
    v_cyl, v_cap = math.pi * r * r * h, 2 / 3 * math.pi * r ** 3
    rho = m / (v_cyl + 2 * v_cap)
    m_cyl, m_cap = rho * v_cyl, rho * v_cap
    izz = m_cyl * r * r / 2 + 2 * m_cap * 2 * r * r / 5
    # a hemisphere about its own centroid (3r/8 from the flat face): 83/320 m r^2 across
    across_cap = 83 / 320 * m_cap * r * r
    offset = h / 2 + 3 * r / 8
    ixx = m_cyl * (3 * r * r + h * h) / 12 + 2 * (across_cap + m_cap * offset ** 2)
    return np.diag([ixx, ixx, izz])


def test_box_cylinder_sphere_capsule_match_closed_forms():
    close(phys.box_solid((0.5, 0.3, 0.07)).inertia(5.0), box_formula(5.0, 0.5, 0.3, 0.07))
    close(phys.cylinder_solid(0.1, 0.04).inertia(0.2), cylinder_formula(0.2, 0.1, 0.04))
    close(phys.sphere_solid(0.05).inertia(0.3), sphere_formula(0.3, 0.05))
    close(phys.capsule_solid(0.02, 0.1).inertia(0.7), capsule_formula(0.7, 0.02, 0.1))
    assert phys.box_solid((1, 2, 3)).volume == pytest.approx(6)
    assert phys.cylinder_solid(1, 2).volume == pytest.approx(2 * math.pi)
    assert phys.capsule_solid(1, 2).volume == pytest.approx(2 * math.pi + 4 / 3 * math.pi)


def test_m2wr_chassis_box_values_from_the_seed():
    # the seed's corrected chassis: 5 kg, 0.5 x 0.3 x 0.07 box
    tensor = phys.box_solid((0.5, 0.3, 0.07)).inertia(5.0)
    assert tensor[0][0] == pytest.approx(0.03954166666667)
    assert tensor[1][1] == pytest.approx(0.106208333333)
    assert tensor[2][2] == pytest.approx(0.141666666667)


@pytest.mark.parametrize("rpy", [(0.3, -0.7, 1.9), (0, 1.5707, 1.5707), (math.pi / 2, 0, 0),
                                 (0.1, 0.2, 0.3)])
def test_rpy_matrix_is_urdf_fixed_axis_convention(rpy):
    # URDF rpy: rotations about the fixed x, y, z axes = scipy's extrinsic 'xyz'
    close(phys.rpy_matrix(rpy), Rotation.from_euler("xyz", rpy).as_matrix(), abs_=1e-12)
    close(phys.rpy_matrix(phys.matrix_rpy(phys.rpy_matrix(rpy))), phys.rpy_matrix(rpy),
          abs_=1e-12)


def test_rotated_box_tensor_is_r_i_rt():
    rpy = (0.4, -1.1, 2.3)
    r = Rotation.from_euler("xyz", rpy).as_matrix()
    expected = r @ box_formula(2.0, 0.2, 0.1, 0.05) @ r.T
    solid = phys.box_solid((0.2, 0.1, 0.05)).moved(phys.rpy_matrix(rpy), (1.0, 2.0, 3.0))
    close(solid.inertia(2.0), expected, abs_=1e-15)
    close(solid.centroid, (1.0, 2.0, 3.0))


def test_parallel_axis_two_cubes_make_a_box():
    # two unit cubes side by side along x = a 2 x 1 x 1 box
    cube = phys.box_solid((1.0, 1.0, 1.0))
    both = phys.combine([cube.moved(phys.IDENTITY, (-0.5, 0, 0)),
                         cube.moved(phys.IDENTITY, (0.5, 0, 0))])
    close(both.inertia(2.0), box_formula(2.0, 2.0, 1.0, 1.0))
    close(both.centroid, (0, 0, 0), abs_=1e-15)
    # parallel_axis: the inertia of one cube about the pair's centre
    about = phys.parallel_axis(cube.inertia(1.0), 1.0, (0.5, 0.0, 0.0))
    close(np.asarray(about) * 2, box_formula(2.0, 2.0, 1.0, 1.0))


def test_scaled_solid_is_the_stretched_body():
    close(phys.box_solid((1, 1, 1)).scaled((0.2, 0.3, 0.5)).inertia(3.0),
          box_formula(3.0, 0.2, 0.3, 0.5))
    # a mirror (negative scale) is the same body
    close(phys.box_solid((1, 1, 1)).scaled((-0.2, 0.3, 0.5)).inertia(3.0),
          box_formula(3.0, 0.2, 0.3, 0.5))


def test_eigen_symmetric_matches_numpy():
    rng = np.random.default_rng(7)
    for _ in range(300):
        a = rng.normal(size=(3, 3))
        sym = a @ a.T if rng.random() < 0.5 else a + a.T
        values, vectors = phys.eigen_symmetric(tuple(map(tuple, sym)))
        close(values, np.linalg.eigvalsh(sym), rel=1e-8, abs_=1e-10)
        v = np.array(vectors)
        close(v @ v.T, np.eye(3), abs_=1e-9)
        for value, vector in zip(values, vectors):
            close(sym @ np.array(vector), value * np.array(vector), abs_=1e-8)
    # repeated eigenvalues (a cylinder) and a diagonal tensor
    assert phys.principal_moments(((2, 0, 0), (0, 1, 0), (0, 0, 2))) == (1, 2, 2)
    q = Rotation.from_euler("xyz", (0.3, 0.2, 0.1)).as_matrix()
    rotated = q @ np.diag([1.0, 1.0, 3.0]) @ q.T
    close(phys.eigen_symmetric(tuple(map(tuple, rotated)))[0], (1, 1, 3), rel=1e-9)


def test_max_sq_distance_bounds():
    # box 2 x 1 x 1 about the z axis through its centre: corner at (1, 0.5) -> 1.25
    box = phys.BoxExtent((2.0, 1.0, 1.0))
    assert box.max_sq_distance((0, 0, 0), (0, 0, 1)) == pytest.approx(1.25)
    # sphere r=0.5 at (3, 0, 0), axis z through the origin: (3 + 0.5)^2
    assert phys.SphereExtent(0.5, translation=(3, 0, 0)).max_sq_distance(
        (0, 0, 0), (0, 0, 1)) == pytest.approx(12.25)
    # cylinder r=0.1 h=0.04 along z: about its own axis r^2, across r^2 + (h/2)^2; the rim
    # is sampled, with a margin that keeps it an upper bound within 0.02%
    cylinder = phys.CylinderExtent(0.1, 0.04)
    assert cylinder.max_sq_distance((0, 0, 0), (0, 0, 1)) == pytest.approx(0.01)
    across = cylinder.max_sq_distance((0, 0, 0), (1, 0, 0))
    assert 0.01 + 0.0004 <= across <= (0.01 + 0.0004) * 1.0002
    # capsule r=0.1, h=0.2 along z, about x through the centre: (0.1 + 0.1)^2
    assert phys.CylinderExtent(0.1, 0.2, capsule=True).max_sq_distance(
        (0, 0, 0), (1, 0, 0)) == pytest.approx(0.04)


def test_cylinder_bound_is_an_upper_bound_for_tilted_axes():
    rng = np.random.default_rng(3)
    rot = phys.rpy_matrix((0.3, 1.2, -0.4))
    cylinder = phys.CylinderExtent(0.2, 0.5, rot, (0.1, 0.0, -0.2))
    r = np.array(rot)
    t = np.linspace(0, 2 * np.pi, 20000)
    rims = [np.stack([0.2 * np.cos(t), 0.2 * np.sin(t), np.full_like(t, z)], 1) @ r.T
            + (0.1, 0.0, -0.2) for z in (-0.25, 0.25)]
    points = np.vstack(rims)
    for _ in range(20):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        origin = rng.normal(size=3) * 0.3
        rel = points - origin
        exact = np.max(np.sum(rel * rel, 1) - (rel @ axis) ** 2)
        bound = cylinder.max_sq_distance(tuple(origin), tuple(axis))
        assert exact <= bound <= exact * 1.001 + 1e-12


def test_hull_distance_box_and_cylinder():
    rot = phys.rpy_matrix((0.3, 0.2, 0.1))
    box = phys.BoxExtent((1, 2, 3), rot, (1, 1, 1))
    r = np.array(rot)
    rng = np.random.default_rng(11)
    for _ in range(100):
        p = rng.normal(size=3) * 3
        local = r.T @ (p - 1)
        expected = np.linalg.norm(np.maximum(np.abs(local) - (0.5, 1.0, 1.5), 0))
        assert phys.hull_distance(tuple(p), [box]) == pytest.approx(expected, abs=1e-7)
    # m2wr: COM 0.1 above a 0.07 m box -> 0.065 outside; the hull of box + a sphere below
    chassis = phys.BoxExtent((0.5, 0.3, 0.07))
    caster = phys.SphereExtent(0.05, translation=(0.35, 0, -0.05))
    distance, width = phys.hull_escape((0, 0, 0.1), [chassis, caster])
    assert distance == pytest.approx(0.065)
    assert width == pytest.approx(0.035 + 0.1)  # from the box top to the caster's bottom
    assert phys.hull_escape((0.28, 0, -0.03), [chassis, caster]) == (0.0, 0.0)  # in between


def test_mesh_extent_numpy_and_python_paths_give_the_same_floats(monkeypatch):
    """A placed hull is queried with Python loops (small, numpy not loaded) or numpy arrays:
    the same floats either way (support vertex, squared reach per axis, the hull-escape
    distance), on random hulls with repeated extremes, scales, rotations."""
    import random

    from urdftool.physics import inertia as phys
    from urdftool.physics import meshes

    rng = random.Random(7)
    for trial in range(60):
        count = rng.choice([4, 9, 30, 60])
        points = [tuple(rng.choice([-1.0, 1.0, 0.5]) * rng.random() for _ in range(3))
                  for _ in range(count)]
        points += points[: count // 3]  # equal extremes: the first of equals is chosen
        flat = [x for p in points for x in p]
        info = meshes.MeshInfo("m.stl", flat=meshes.array("d", flat))
        scale = tuple(rng.uniform(0.1, 2.0) for _ in range(3))
        rotation = phys.rpy_matrix(tuple(rng.uniform(-3, 3) for _ in range(3)))
        translation = tuple(rng.uniform(-1, 1) for _ in range(3))
        directions = [tuple(rng.uniform(-1, 1) for _ in range(3)) for _ in range(5)]
        origin = tuple(rng.uniform(-0.5, 0.5) for _ in range(3))
        axes = [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), directions[0]]
        answers = []
        for threshold in (10**9, 0):
            monkeypatch.setattr(meshes, "VECTOR_POINTS", threshold)
            monkeypatch.setattr(meshes, "VECTOR_POINTS_LOADED", threshold)
            extent = meshes.MeshExtent(info, scale, rotation, translation)
            assert (extent.columns is None) == (threshold > 0)
            answers.append(([extent.support(d) for d in directions],
                            extent.max_sq_distances(origin, axes),
                            phys.hull_escape(origin, [extent])))
        assert answers[0] == answers[1]


def test_gjk_inside_shortcut_gives_what_the_full_search_gives(monkeypatch):
    """``_hull_offset`` ends as soon as its tetrahedron strictly holds the point: the same
    answer as the full search over the tetrahedron's faces, for points inside, outside and
    near the surface of random hulls of every size (1e-6 m to 100 m)."""
    import random

    from urdftool.physics import inertia as phys

    rng = random.Random(11)
    cases = []
    for _ in range(300):
        size = 10 ** rng.uniform(-6, 2)
        points = [tuple(rng.gauss(0, size) for _ in range(3)) for _ in range(rng.randint(4, 30))]
        extent = phys.PointsExtent(points)
        scale = rng.choice([0.1, 0.9, 1.0, 1.1, 3.0])
        point = tuple(scale * rng.gauss(0, size) for _ in range(3))
        cases.append((point, [extent]))
    shortcuts = []
    inside = phys._strictly_inside
    monkeypatch.setattr(phys, "_strictly_inside",
                        lambda points: shortcuts.append(inside(points)) or shortcuts[-1])
    fast = [phys.hull_escape(point, extents) for point, extents in cases]
    assert sum(shortcuts) > 50  # the shortcut was taken, so the comparison says something
    monkeypatch.setattr(phys, "_strictly_inside", lambda points: False)
    full = [phys.hull_escape(point, extents) for point, extents in cases]
    assert fast == full
    assert sum(1 for d, _ in fast if d == 0) > 50 and sum(1 for d, _ in fast if d > 0) > 50
