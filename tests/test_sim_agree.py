"""`check` and `sim` agree (issue 14): overlaps where a closed chain is cut (links moved by one
mimic group) are allowed, a link overlapping an ancestor two joints up fails unless an SRDF
disables the pair (MoveIt's own SRDF for the Panda lists exactly the pairs found here, as
"Default": in collision at the zero pose), and `-j` defaults to the CPUs, as `check`."""

from __future__ import annotations

import pybullet  # noqa: F401 - the test extra has it: missing, this fails
import pytest

from tests.conftest import example_robot_data_dir, pybullet_data_dir, pybullet_urdfs
from tests.test_sim import arm
from urdftool.sim import SimOptions
from urdftool.sim.runner import simulate


def mimic_lamp() -> str:
    """The arm's bar with a lamp inside it on a second joint that mimics the shoulder: the two
    move as one, like a four-bar gripper's knuckle and finger cut open at their pin."""
    text = arm(lamp=True)
    return text.replace('<origin xyz="0 0 0.2"/><axis xyz="0 0 1"/>',
                        '<origin xyz="0 0 0.2"/><axis xyz="0 1 0"/>').replace(
        'velocity="1"/></joint>', 'velocity="1"/><mimic joint="shoulder"/></joint>')


def test_mimic_pair_overlap_is_allowed_and_listed(write):
    plain, mimic = simulate([str(write(arm(lamp=True), "lamp.urdf")),
                             str(write(mimic_lamp(), "mimic.urdf"))],
                            SimOptions(duration=0.05, jobs=2))
    assert plain.check("self-collision").failed  # an overlap between independent joints
    check = mimic.check("self-collision")
    assert check.status == "pass", check.message
    (pair,) = check.values["loop_cut_pairs"]
    assert {pair["a"], pair["b"]} == {"upper", "lamp"}
    # the boxes share their axis and centre: the overlap is the lamp's 6 cm thickness
    assert pair["depth_m"] == pytest.approx(0.06, abs=1e-3)
    assert "closed chain is cut" in check.message


def test_ancestor_overlap_fails_unless_the_srdf_disables_it():
    panda = pybullet_data_dir() / "franka_panda" / "panda.urdf"
    srdf = example_robot_data_dir() / "robots" / "panda_description" / "srdf" / "panda.srdf"
    bare, moveit = (simulate([str(panda)], SimOptions(duration=0.05, srdf=s))[0]
                    for s in (False, str(srdf)))
    check = bare.check("self-collision")
    assert check.failed
    pairs = {frozenset((p["a"], p["b"])) for p in check.values["pairs"]}
    assert pairs == {frozenset(("panda_link5", "panda_hand")),
                     frozenset(("panda_link5", "panda_link7"))}
    # MoveIt's SRDF disables both pairs ('Default': colliding at the zero pose)
    assert moveit.check("self-collision").status == "pass"


def test_sim_jobs_default_grows_with_the_work(monkeypatch):
    """Like ``check``: a handful of small models is one worker; many, one per CPU."""
    import urdftool.check
    from urdftool.sim import runner

    seen = []

    class Sized(Exception):
        pass

    class Pool:
        def __init__(self, jobs, **kwargs):
            seen.append(jobs)
            raise Sized  # stop here: only the size is wanted

    monkeypatch.setattr(runner, "ProcessPoolExecutor", Pool)
    monkeypatch.setattr(urdftool.check, "available_cpus", lambda: 3)
    robots = sorted((pybullet_data_dir() / "quadruped").glob("*.urdf"))[:4]
    assert len(robots) == 4 and all(p.stat().st_size < 100_000 for p in robots)
    many = pybullet_urdfs()[:60]  # 60 x 50 ms at least: 3 s of work
    assert len(many) == 60
    for paths in (robots, many):
        with pytest.raises(Sized):
            runner.run_all([str(p) for p in paths], SimOptions())
    assert seen == [1, 3]
    assert SimOptions().jobs is None
