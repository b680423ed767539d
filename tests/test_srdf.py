"""The ``srdf`` rules (issue 31): a MoveIt SRDF against its robot. Collisions are decided by an
independent computation: the test's own forward kinematics and box-box separating-axis test
(primitives), pinocchio's kinematics with its coal collision model (real meshes)."""

from __future__ import annotations

import json
import math
import re
import subprocess
from pathlib import Path

import pytest

from tests.conftest import example_robot_data_dir, run_urdftool
from urdftool.rules.srdf import EXAMPLE_ROBOT

# -- the test's own geometry: boxes, rotations, the separating-axis test ---------------------


def _rz(a):
    c, s = math.cos(a), math.sin(a)
    return ((c, -s, 0.0), (s, c, 0.0), (0.0, 0.0, 1.0))


def _ry(a):
    c, s = math.cos(a), math.sin(a)
    return ((c, 0.0, s), (0.0, 1.0, 0.0), (-s, 0.0, c))


def _matmul(a, b):
    return tuple(tuple(sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3))
                 for i in range(3))


def _apply(r, v):
    return tuple(sum(r[i][k] * v[k] for k in range(3)) for i in range(3))


def _boxes_overlap(c1, r1, h1, c2, r2, h2) -> bool:
    """Separating-axis test of two oriented boxes (centre, rotation, half sizes): the 15 axes."""
    a = [tuple(r1[i][k] for i in range(3)) for k in range(3)]
    b = [tuple(r2[i][k] for i in range(3)) for k in range(3)]
    axes = a + b + [(u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                     u[0] * v[1] - u[1] * v[0]) for u in a for v in b]
    d = tuple(y - x for x, y in zip(c1, c2))
    for axis in axes:
        if sum(x * x for x in axis) < 1e-18:
            continue
        spread = sum(h * abs(sum(x * y for x, y in zip(u, axis))) for h, u in zip(h1, a)) + \
            sum(h * abs(sum(x * y for x, y in zip(u, axis))) for h, u in zip(h2, b))
        if abs(sum(x * y for x, y in zip(d, axis))) > spread:
            return False
    return True


def _forearm_hits_base(q1: float, q2: float) -> bool:
    """EXAMPLE_ROBOT: does the forearm box meet the base box at (joint1, joint2)?"""
    rotation = _matmul(_rz(q1), _ry(q2))
    centre = tuple(x + y for x, y in zip((0.0, 0.0, 0.4), _apply(rotation, (0.0, 0.0, 0.2))))
    identity = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    return _boxes_overlap((0.0, 0.0, 0.05), identity, (0.2, 0.2, 0.05),
                          centre, rotation, (0.03, 0.03, 0.2))


NEVER = ('<robot name="arm">\n  <group name="arm"><chain base_link="base_link" '
         'tip_link="tool0"/></group>\n  <disable_collisions link1="base_link" link2="forearm" '
         'reason="Never"/>\n</robot>\n')


def _check(tmp_path, srdf: str, robot: str = EXAMPLE_ROBOT, *extra) -> list[dict]:
    (tmp_path / "robot.urdf").write_text(robot, encoding="utf-8")
    (tmp_path / "arm.srdf").write_text(srdf, encoding="utf-8")
    result = run_urdftool("check", str(tmp_path / "arm.srdf"), "--robot",
                          str(tmp_path / "robot.urdf"), "--format", "json", *extra)
    assert result.code in (0, 1), result.err
    return [d for f in json.loads(result.out)["files"] for d in f["diagnostics"]]


def _configuration(message: str) -> dict[str, float]:
    return {name: float(value) for name, value in re.findall(r"(\w+)=(-?[\d.e+-]+)", message)}


def test_never_pair_colliding_in_part_of_the_range_is_found(tmp_path):
    # the forearm reaches the base only for |joint2| above ~2.4 of its +-2.8: a seventh of the
    # range (the test's own grid says how much)
    grid = [-2.8 + 5.6 * i / 400 for i in range(401)]
    share = sum(_forearm_hits_base(0.0, q2) for q2 in grid) / len(grid)
    assert 0.05 < share < 0.3
    found = [d for d in _check(tmp_path, NEVER) if d["rule"] == "srdf.never-pair-collides"]
    assert len(found) == 1 and found[0]["line"] == 3 and found[0]["severity"] == "error"
    assert "never proves" in found[0]["message"]
    q = _configuration(found[0]["message"].split(" at ", 1)[1])
    assert set(q) == {"joint1", "joint2"} and abs(q["joint2"]) <= 2.8
    assert _forearm_hits_base(q["joint1"], q["joint2"])  # the test's geometry agrees


def test_never_pair_that_cannot_collide_within_the_limits_is_not_reported(tmp_path):
    robot = EXAMPLE_ROBOT.replace('lower="-2.8" upper="2.8"', 'lower="-2.2" upper="2.2"')
    assert not any(_forearm_hits_base(q1, -2.2 + 4.4 * j / 200)
                   for q1 in (0.0, 0.7, 1.9) for j in range(201))
    assert not [d for d in _check(tmp_path, NEVER, robot) if d["rule"] == "srdf.never-pair-collides"]


def test_a_never_pair_checked_through_an_enabled_pair_of_rigidly_fixed_links(tmp_path):
    """Franka's panda_moveit_config disables the normal links' pairs on purpose and enables
    the pairs of capsule links fixed to them (`_sc`): MoveIt checks those bodies through the
    enabled pair, so the disabled one is no risk (a judged false alarm on real packages). A
    capsule pair that is not enabled covers nothing."""
    capsules = ('  <link name="base_link_sc"><collision><geometry><sphere radius="0.2"/>'
                '</geometry></collision></link>\n'
                '  <joint name="base_sc" type="fixed"><parent link="base_link"/>'
                '<child link="base_link_sc"/></joint>\n'
                '  <link name="forearm_sc"><collision><origin xyz="0 0 0.2"/><geometry>'
                '<cylinder radius="0.04" length="0.4"/></geometry></collision></link>\n'
                '  <joint name="forearm_sc_joint" type="fixed"><parent link="forearm"/>'
                '<child link="forearm_sc"/></joint>\n</robot>')
    robot = EXAMPLE_ROBOT.replace("</robot>", capsules)
    enabled = NEVER.replace("</robot>", '  <enable_collisions link1="base_link_sc" '
                                        'link2="forearm_sc" reason="Default"/>\n</robot>')
    assert not [d for d in _check(tmp_path, enabled, robot)
                if d["rule"] == "srdf.never-pair-collides"]
    found = [d for d in _check(tmp_path, NEVER, robot) if d["rule"] == "srdf.never-pair-collides"]
    assert [d["line"] for d in found] == [3]


def test_mimic_joints_follow_their_leader(tmp_path):
    # joint2 mimics 'drive' (x2): its range is +-2.8 only through the leader's +-1.4
    robot = EXAMPLE_ROBOT.replace(
        '<limit lower="-2.8" upper="2.8" effort="10" velocity="1"/></joint>',
        '<limit lower="-2.8" upper="2.8" effort="10" velocity="1"/>'
        '<mimic joint="drive" multiplier="2"/></joint>'
        '<link name="motor"/><joint name="drive" type="revolute"><parent link="base_link"/>'
        '<child link="motor"/><axis xyz="1 0 0"/>'
        '<limit lower="-1.4" upper="1.4" effort="1" velocity="1"/></joint>')
    found = [d for d in _check(tmp_path, NEVER, robot) if d["rule"] == "srdf.never-pair-collides"]
    assert len(found) == 1
    q = _configuration(found[0]["message"].split(" at ", 1)[1])
    assert set(q) == {"joint1", "drive"}
    assert _forearm_hits_base(q["joint1"], 2 * q["drive"])
    # a smaller leader range keeps the forearm away: nothing
    narrow = robot.replace('lower="-1.4" upper="1.4" effort="1"', 'lower="-1.1" upper="1.1" effort="1"')
    assert not [d for d in _check(tmp_path, NEVER, narrow) if d["rule"] == "srdf.never-pair-collides"]


# -- a real package: example-robot-data's Panda and its SRDF, seeded with one defect each ----


def _panda() -> tuple[Path, Path]:
    root = example_robot_data_dir() / "robots" / "panda_description"
    return root / "urdf" / "panda.urdf", root / "srdf" / "panda.srdf"


def _robot_args(urdf) -> tuple[str, ...]:
    """--robot URDF and its package (its meshes are package://example-robot-data/...)."""
    return ("--robot", str(urdf), "-P", f"example-robot-data={example_robot_data_dir()}")


SEEDS = [  # (what is replaced, by what, the rule, its severity)
    ('<joint name="panda_joint7"/>\n    </group>', '<joint name="panda_joint77"/>\n    </group>',
     "srdf.unknown-joint", "error"),
    ('<group name="arm"/>', '<group name="arms"/>', "srdf.unknown-group", "error"),
    ('<joint name="panda_joint3" value="0"/>', '<joint name="panda_jiont3" value="0"/>',
     "srdf.unknown-joint", "error"),  # (the state then lacks joint3: the same cause)
    ('parent_link="panda_hand_tcp"', 'parent_link="panda_hand_tpc"', "srdf.unknown-link", "error"),
    ('<joint name="panda_joint4" value="-2.35619"/>', '<joint name="panda_joint4" value="0.5"/>',
     "srdf.state-out-of-limits", "error"),
    ('        <joint name="panda_joint5" value="0"/>\n', '', "srdf.state-incomplete", "warning"),
    ('<disable_collisions link1="panda_link0" link2="panda_link1" reason="Adjacent"/>',
     ('<disable_collisions link1="panda_link0" link2="panda_link1" reason="Adjacent"/>'
     '<disable_collisions link1="panda_link1" link2="panda_link0" reason="Adjacent"/>'),
     "srdf.duplicate-pair", "warning"),
    ('link1="panda_link0" link2="panda_link2" reason="Never"',
     'link1="panda_link0" link2="panda_link2" reason="Adjacent"', "srdf.adjacent-mislabelled",
     "warning"),
    ('<end_effector name="end_effector" parent_link="panda_hand_tcp" group="arm"/>',
     ('<end_effector name="end_effector" parent_link="panda_hand_tcp" group="arm"/>'
     '<virtual_joint name="world" type="fixed" parent_frame="world" child_link="panda_link1"/>'),
     "srdf.virtual-joint-child", "error"),
    ('<group name="arm">\n', ('<group name="arm">\n        <chain base_link="panda_hand" '
     'tip_link="panda_link0"/>\n'), "srdf.chain-not-below", "warning"),
]


def test_the_real_panda_srdf_is_clean(tmp_path):
    urdf, srdf = _panda()
    result = run_urdftool("check", str(srdf), *_robot_args(urdf), "--format", "json")
    assert result.code == 0, result.out
    assert json.loads(result.out)["summary"]["errors"] == 0
    assert json.loads(result.out)["summary"]["warnings"] == 0


@pytest.mark.parametrize("old,new,rule,severity", SEEDS, ids=[s[2] for s in SEEDS])
def test_every_seeded_defect_is_found_at_its_line(tmp_path, old, new, rule, severity):
    urdf, srdf = _panda()
    text = srdf.read_text(encoding="utf-8")
    assert text.count(old) == 1
    seeded = text.replace(old, new)
    line = next(i for i, (a, b) in enumerate(zip(text.splitlines(), seeded.splitlines()),
                                             start=1) if a != b)  # the first line changed
    path = tmp_path / "panda.srdf"
    path.write_text(seeded, encoding="utf-8")
    result = run_urdftool("check", str(path), *_robot_args(urdf), "--format", "json")
    found = [d for f in json.loads(result.out)["files"] for d in f["diagnostics"]]
    assert [(d["rule"], d["severity"]) for d in found] == [(rule, severity)], found
    if rule != "srdf.state-incomplete":  # (a deleted line: found at its group state)
        assert found[0]["line"] == line, (found[0], line)


def test_a_seeded_never_pair_of_the_real_panda_collides_by_pinocchio_and_coal(tmp_path):
    import coal
    import pinocchio as pin

    urdf, srdf = _panda()
    text = srdf.read_text(encoding="utf-8")
    pair = '<disable_collisions link1="panda_link0" link2="panda_link5" reason="Never"/>'
    assert "panda_link5\" link2=\"panda_link0" not in text and pair not in text
    path = tmp_path / "panda.srdf"
    path.write_text(text.replace("</robot>", f"    {pair}\n</robot>"), encoding="utf-8")
    result = run_urdftool("check", str(path), *_robot_args(urdf), "--format", "json")
    found = [d for f in json.loads(result.out)["files"] for d in f["diagnostics"]]
    assert [d["rule"] for d in found] == ["srdf.never-pair-collides"]
    q = _configuration(found[0]["message"].split(" at ", 1)[1].split(" their ")[0])
    # pinocchio places the meshes, coal tests them: the independent truth
    model = pin.buildModelFromUrdf(str(urdf))
    package_dirs = [str(example_robot_data_dir().parent)]
    geometry = pin.buildGeomFromUrdf(model, str(urdf), pin.GeometryType.COLLISION,
                                     package_dirs=package_dirs)
    data, gdata = model.createData(), pin.GeometryData(geometry)
    config = pin.neutral(model)
    for name, value in q.items():
        joint = model.joints[model.getJointId(name)]
        lower = model.lowerPositionLimit[joint.idx_q]
        upper = model.upperPositionLimit[joint.idx_q]
        assert lower - 1e-9 <= value <= upper + 1e-9
        config[joint.idx_q] = value
    pin.updateGeometryPlacements(model, data, geometry, gdata, config)
    objects = geometry.geometryObjects

    def of(link):
        return [i for i, g in enumerate(objects) if model.frames[g.parentFrame].name == link]

    collide = False
    for i in of("panda_link0"):
        for j in of("panda_link5"):
            result_ = coal.CollisionResult()
            coal.collide(objects[i].geometry, gdata.oMg[i], objects[j].geometry, gdata.oMg[j],
                         coal.CollisionRequest(), result_)
            collide = collide or result_.isCollision()
    assert collide


# -- pairing: .setup_assistant, the configuration, none -----------------------------------


def _repository(tmp_path) -> Path:
    repo = tmp_path / "repo"
    description = repo / "arm_description"
    (description / "urdf").mkdir(parents=True)
    (description / "package.xml").write_text("<package><name>arm_description</name></package>")
    (description / "urdf" / "arm.urdf").write_text(EXAMPLE_ROBOT, encoding="utf-8")
    config = repo / "arm_moveit_config"
    (config / "config").mkdir(parents=True)
    (config / "package.xml").write_text("<package><name>arm_moveit_config</name></package>")
    (config / "config" / "arm.srdf").write_text(NEVER.replace("forearm", "forarm"),
                                                encoding="utf-8")
    subprocess.run(["git", "init", "-q", str(repo)], check=True)
    return repo


def _findings(result) -> list[tuple[str, str, int]]:
    return [(Path(d["path"]).name, d["rule"], d["line"])
            for f in json.loads(result.out)["files"] for d in f["diagnostics"]
            if d["rule"].startswith("srdf.")]


@pytest.mark.parametrize("urdf, srdf", [("URDF", "SRDF"), ("urdf", "srdf")],
                         ids=["moveit1", "moveit2"])
def test_check_dir_pairs_an_srdf_through_setup_assistant(tmp_path, urdf, srdf):
    """MoveIt 1's Setup Assistant writes `URDF:`, MoveIt 2's `urdf:` (every MoveIt 2
    configuration got srdf.no-robot: ros2_kortex's, judged on real packages)."""
    repo = _repository(tmp_path)
    (repo / "arm_moveit_config" / ".setup_assistant").write_text(
        f"moveit_setup_assistant_config:\n  {urdf}:\n    package: arm_description\n"
        f"    relative_path: urdf/arm.urdf\n  {srdf}:\n    relative_path: config/arm.srdf\n")
    result = run_urdftool("check", str(repo), "--format", "json")
    assert _findings(result) == [("arm.srdf", "srdf.unknown-link", 3)], result.out


def test_check_dir_pairs_an_srdf_through_the_configuration(tmp_path):
    repo = _repository(tmp_path)
    (repo / "urdftool.toml").write_text(
        'srdf = [{ file = "arm_moveit_config/config/arm.srdf", '
        'robot = "arm_description/urdf/arm.urdf" }]\n')
    result = run_urdftool("check", str(repo), "--format", "json")
    assert _findings(result) == [("arm.srdf", "srdf.unknown-link", 3)], result.out


def test_an_srdf_without_robot_says_what_was_looked_for_once(tmp_path):
    repo = _repository(tmp_path)
    result = run_urdftool("check", str(repo), "--format", "json")
    assert _findings(result) == [("arm.srdf", "srdf.no-robot", 1)]
    message = json.loads(result.out)["files"]
    text = json.dumps(message)
    assert ".setup_assistant" in text and "--robot" in text
    # a robot named by .setup_assistant that is not there: which one, and where it was looked for
    (repo / "arm_moveit_config" / ".setup_assistant").write_text(
        "moveit_setup_assistant_config:\n  URDF:\n    package: other_description\n"
        "    relative_path: urdf/arm.urdf\n")
    result = run_urdftool("check", str(repo), "--format", "json")
    found = [d for f in json.loads(result.out)["files"] for d in f["diagnostics"]
             if d["rule"] == "srdf.no-robot"]
    assert len(found) == 1 and "package://other_description/urdf/arm.urdf" in found[0]["message"]


def test_changed_urdf_rechecks_the_srdf_that_names_it(tmp_path, monkeypatch):
    repo = _repository(tmp_path)
    (repo / "arm_moveit_config" / "config" / "arm.srdf").write_text(NEVER, encoding="utf-8")
    (repo / "arm_moveit_config" / ".setup_assistant").write_text(
        "moveit_setup_assistant_config:\n  URDF:\n    package: arm_description\n"
        "    relative_path: urdf/arm.urdf\n")
    monkeypatch.setenv("URDFTOOL_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.chdir(repo)
    urdf = "arm_description/urdf/arm.urdf"
    # the joint limits narrowed: the pair cannot meet, nothing to say
    Path(urdf).write_text(EXAMPLE_ROBOT.replace('lower="-2.8" upper="2.8"',
                                                'lower="-2.2" upper="2.2"'), encoding="utf-8")
    first = run_urdftool("check", ".", "--format", "json")
    assert not _findings(first)
    # widened again: the edit of the URDF alone re-checks the SRDF, whose pair now collides
    Path(urdf).write_text(EXAMPLE_ROBOT, encoding="utf-8")
    result = run_urdftool("check", "--format", "json", "--changed", urdf)
    assert _findings(result) == [("arm.srdf", "srdf.never-pair-collides", 3)], result.out
    # and the edit of the SRDF re-checks it
    result = run_urdftool("check", "--format", "json", "--changed",
                          "arm_moveit_config/config/arm.srdf")
    assert _findings(result) == [("arm.srdf", "srdf.never-pair-collides", 3)], result.out
