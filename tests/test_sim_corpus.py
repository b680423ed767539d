"""`urdftool sim` on well-made robots from pybullet_data and example-robot-data.

A handful of representative robots keeps the suite fast; `benchmarks/bench_sim.py` runs the
whole corpus (every pybullet_data URDF and every example-robot-data URDF) and lists the
verdicts.
"""

from __future__ import annotations

import math

import pybullet  # noqa: F401 - the test extra has it: missing, this fails
import pytest

from tests.conftest import example_robot_data_dir, pybullet_data_dir
from urdftool.sim import SimOptions
from urdftool.sim.runner import simulate

GOOD_PYBULLET = [
    "r2d2.urdf",  # wheels, gripper, prismatic joints with limits
    "kuka_iiwa/model.urdf",  # zero-mass root: PyBullet keeps it static (anchored)
    "laikago/laikago_toes_zup.urdf",  # quadruped with meshes, standing on its toes
    "quadruped/minitaur.urdf",  # 26 links, mostly fixed joints
]
GOOD_EXAMPLE_ROBOTS = [
    "ur_description/urdf/ur5_robot.urdf",  # root 'world': anchored
    "go2_description/urdf/go2.urdf",
]


@pytest.fixture(scope="module")
def good():
    paths = [pybullet_data_dir() / name for name in GOOD_PYBULLET]
    robots = example_robot_data_dir() / "robots"
    paths += [robots / name for name in GOOD_EXAMPLE_ROBOTS]
    results = simulate([str(p) for p in paths], SimOptions(jobs=2))
    return {p.name: r for p, r in zip(paths, results)}


def test_known_good_robots_pass(good):
    for name, result in good.items():
        assert result.verdict == "pass", (name, [c.message for c in result.failures()])
        assert result.check("load").values["links"] >= 2
        # every model loads its meshes (package://example-robot-data/... resolved) and steps
        # faster than real time: its whole run (load, steps, checks) takes less CPU than the
        # simulated time (CPU, not real_time_factor's wall clock: the machine's load does not
        # count)
        assert result.timing["cpu"] < SimOptions().duration, (name, result.timing)


def test_anchoring_follows_the_model(good):
    assert good["ur5_robot.urdf"].anchor_reason == "root link 'world'"
    assert "zero mass" in good["model.urdf"].anchor_reason
    assert good["r2d2.urdf"].anchored is False
    assert good["r2d2.urdf"].check("drift").status == "pass"


def test_go2_srdf_allows_the_overlaps_at_the_hips(good):
    # go2's thighs overlap its base by about 1 cm at the zero pose (two joints apart); its
    # SRDF (found in ../srdf/go2.srdf) lists them in <disable_collisions>. Without the SRDF
    # they are reported but not counted; with --strict-collision they fail the check.
    check = good["go2.urdf"].check("self-collision")
    assert check.status == "pass" and check.values["srdf"].endswith("srdf/go2.srdf")
    assert check.values["srdf_pairs"] == 14 and not check.values["ancestor_pairs"]
    path = example_robot_data_dir() / "robots" / "go2_description" / "urdf" / "go2.urdf"
    (plain,) = simulate([str(path)], SimOptions(duration=0.05, srdf=False,
                                                strict_collision=False))
    (strict,) = simulate([str(path)], SimOptions(duration=0.05, srdf=False))
    pairs = {frozenset((p["a"], p["b"])) for p in plain.check("self-collision")
             .values["ancestor_pairs"]}
    assert frozenset(("base", "FR_thigh")) in pairs
    assert plain.check("self-collision").status == "pass"
    assert strict.check("self-collision").failed
    assert "base:FR_thigh" in strict.check("self-collision").message


def test_husky_mass_fails_on_pybullets_default_for_links_without_inertial():
    # husky's frames without <inertial> weigh nothing by the URDF spec and 1 kg each in
    # PyBullet: the model PyBullet simulates is heavier than the URDF (issue 14)
    from lxml import etree

    path = pybullet_data_dir() / "husky" / "husky.urdf"
    (result,) = simulate([str(path)], SimOptions(duration=0.05))
    mass = result.check("mass")
    root = etree.parse(str(path)).getroot()
    joints = root.findall("joint")

    def reads(joint) -> bool:  # an <origin> whose numbers read ($(optenv ...) in husky's do not)
        origin = joint.find("origin")
        try:
            return origin is None or all(len([float(v) for v in (origin.get(a) or "0 0 0").split()])
                                         == 3 for a in ("xyz", "rpy"))
        except ValueError:
            return False

    fixed = {j.find("child").get("link") for j in joints if j.get("type") == "fixed" and reads(j)}
    children = [j.find("child").get("link") for j in joints]
    (top,) = {link.get("name") for link in root.findall("link")} - set(children)
    below_top = [j for j in joints if j.find("parent").get("link") == top]
    # a frame (no inertial, no shape) on a fixed joint is lumped, as is a free root frame
    # with one fixed joint below it (issue 23.7); a joint whose origin does not read is left
    # as written (nothing to compose)
    frames = {link.get("name") for link in root.findall("link")
              if not link.findall("inertial") + link.findall("visual") + link.findall("collision")
              and (link.get("name") in fixed or (link.get("name") == top and len(below_top) == 1
                                                  and below_top[0].get("type") == "fixed"))}
    without = sorted(link.get("name") for link in root.findall("link")
                     if link.find("inertial") is None and link.get("name") not in frames)
    assert "base_footprint" in frames and without  # husky has shaped links without mass too
    assert mass.status == "fail" and sorted(mass.values["default_mass_links"]) == without
    assert mass.values["pybullet_kg"] == pytest.approx(mass.values["urdf_kg"] + len(without))
    assert f"{len(without)} link(s) without <inertial>" in mass.message


def test_baxter_cannot_hold_its_arms_out_with_its_shoulder_effort_limit(tmp_path):
    # Baxter at its zero pose holds both arms straight out; its s1 (shoulder) joints are
    # limited to 50 N·m. The gravity torque they need, computed here independently with
    # pinocchio's RNEA on the same file (base fixed, all joints zero), is above that: the real
    # robot has gravity-compensating springs the URDF does not model.
    import numpy as np
    import pinocchio

    path = example_robot_data_dir() / "robots" / "baxter_description" / "urdf" / "baxter.urdf"
    model = pinocchio.buildModelFromUrdf(str(path))
    data = model.createData()
    q = pinocchio.neutral(model)
    tau = pinocchio.rnea(model, data, q, np.zeros(model.nv), np.zeros(model.nv))
    needed = abs(tau[model.joints[model.getJointId("left_s1")].idx_v])
    effort = model.effortLimit[model.joints[model.getJointId("left_s1")].idx_v]
    assert needed > effort == 50

    (result,) = simulate([str(path)], SimOptions(duration=0.5))
    hold = result.check("hold")
    assert hold.failed
    entry = next(e for e in result.saturation if e["joint"] == "left_s1")
    assert entry["saturated"] and entry["effort"] == 50
    assert math.isclose(abs(entry["gravity_torque"]), needed, rel_tol=1e-9)
    assert "left_s1" in hold.message and "so it saturates" in hold.message
