"""The cylinder rim bound (physics.inertia._rim_max) evaluates only the sample blocks that can
hold the largest sample: it must give exactly what a scan of every sample gives."""

from __future__ import annotations

import math
import random

from urdftool.physics import inertia as phys


def _every_sample(centre, a, b, radius, origin, axis) -> float:
    """The bound as defined: the largest of the 256 samples, plus the sampling allowance."""
    w = phys._perp(phys.sub(centre, origin), axis)
    ap, bp = phys._perp(a, axis), phys._perp(b, axis)
    r2 = radius * radius
    c0 = phys.dot(w, w) + r2 * (phys.dot(ap, ap) + phys.dot(bp, bp)) / 2.0
    c1, s1 = 2.0 * radius * phys.dot(w, ap), 2.0 * radius * phys.dot(w, bp)
    c2, s2 = r2 * (phys.dot(ap, ap) - phys.dot(bp, bp)) / 2.0, r2 * phys.dot(ap, bp)
    best = max(c0 + c1 * math.cos(t) + s1 * math.sin(t) + c2 * math.cos(2 * t)
               + s2 * math.sin(2 * t)
               for t in (2.0 * math.pi * k / 256 for k in range(256)))
    curvature = abs(c1) + abs(s1) + 4.0 * (abs(c2) + abs(s2))
    return best + curvature * (math.pi / 256) ** 2 / 2.0


def test_rim_bound_equals_the_scan_of_every_sample():
    rnd = random.Random(7)
    for _ in range(5000):
        angles = tuple(rnd.choice([0.0, math.pi / 2, rnd.uniform(-4, 4)]) for _ in range(3))
        rotation = phys.rpy_matrix(angles)
        a = (rotation[0][0], rotation[1][0], rotation[2][0])
        b = (rotation[0][1], rotation[1][1], rotation[2][1])
        scale = 10 ** rnd.uniform(-4, 2)
        centre = tuple(rnd.choice([0.0, rnd.uniform(-1, 1) * scale]) for _ in range(3))
        origin = tuple(rnd.choice([0.0, rnd.uniform(-1, 1) * scale]) for _ in range(3))
        axis = rnd.choice([(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0),
                           phys.unit((rnd.gauss(0, 1), rnd.gauss(0, 1), rnd.gauss(0, 1)))])
        radius = scale * 10 ** rnd.uniform(-2, 1)
        assert phys._rim_max(centre, a, b, radius, origin, axis) == \
            _every_sample(centre, a, b, radius, origin, axis)


def test_rim_bound_with_non_finite_numbers_scans_everything():
    value = phys._rim_max((math.inf, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), 1.0,
                          (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    assert math.isnan(value) or math.isinf(value)
