"""`urdftool jacobian` (numeric): --q forms (a leading minus, name=value, mid, pi), limits,
singular values / manipulability / condition number against closed forms, singularity
warnings, formats and bad input. The Jacobian itself is checked against pinocchio in
test_kinematics_pinocchio.py."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from tests.conftest import ROBOTS, example_robot_data_dir, pybullet_data_dir, run_urdftool
from tests.test_kinematics_pinocchio import MIMIC, _robot
from urdftool.cli import load_robot
from urdftool.kinematics.chain import extract_chain
from urdftool.kinematics.jacobian import analyse, geometric_jacobian

DUAL_ARM = str(ROBOTS / "dual_arm" / "corrected" / "test.xacro")
ARM = (DUAL_ARM, "--tip", "link_03")
UR5 = str(example_robot_data_dir() / "robots" / "ur_description" / "urdf" / "ur5_robot.urdf")
PANDA = str(example_robot_data_dir() / "robots" / "panda_description" / "urdf" / "panda.urdf")
L1, L2 = 0.5, 0.3
PLANAR_2R = _robot("planar", [
    ("j1", "revolute", "base", "l1", "0 0 0", "0 0 0", "0 0 1", (-3, 3)),
    ("j2", "revolute", "l1", "l2", f"{L1} 0 0", "0 0 0", "0 0 1", (-3, 3)),
    ("tip", "fixed", "l2", "hand", f"{L2} 0 0", "0 0 0"),
])


def _json(*args) -> dict:
    result = run_urdftool("jacobian", *args, "--format", "json")
    assert result.code == 0, result.err
    return json.loads(result.out)


# -- --q -------------------------------------------------------------------------------------


def test_leading_minus_both_ways():
    a = _json(*ARM, "--q=-0.5,1.2,-0.3")
    b = _json(*ARM, "--q", "-0.5,1.2,-0.3")
    assert a == b and a["q"] == [-0.5, 1.2, -0.3]


def test_named_values_and_pi():
    data = _json(*ARM, "--q", "link_01__link_02=-pi/4, link_02__link_03=0.25")
    assert data["q"] == [0.0, -math.pi / 4, 0.25]
    assert _json(*ARM, "--q=pi/2,-pi/3,2*pi/5")["q"] == [math.pi / 2, -math.pi / 3,
                                                         2 * math.pi / 5]


def test_mid_is_the_middle_of_the_limits():
    data = _json(PANDA, "--tip", "panda_link8", "--q", "mid")
    assert data["q"][3] == (-3.0718 + -0.0698) / 2  # panda_joint4
    assert data["q"][5] == (-0.0175 + 3.7525) / 2  # panda_joint6
    assert data["q"][0] == 0.0
    data = _json(PANDA, "--tip", "panda_link8", "--q", "mid,panda_joint1=0.5")
    assert data["q"][0] == 0.5 and data["q"][3] == (-3.0718 + -0.0698) / 2


def test_zero_outside_the_limits_is_a_warning():
    result = run_urdftool("jacobian", PANDA, "--tip", "panda_link8", "--format", "json")
    assert result.code == 0
    assert "q = 0 lies outside the limits of panda_joint4 [-3.0718, -0.0698]" in result.err


def test_mimic_leader_outside_the_chain(write):
    data = _json(str(write(MIMIC)), "--tip", "l4", "--q", "other=0.5")
    assert data["joints"] == ["j1", "other", "j4"] and data["q"] == [0.0, 0.5, 0.0]


@pytest.mark.parametrize(("q", "message"), [
    ("1,2", ("--q: 2 values for 3 joint variables (base_link__link_01, link_01__link_02, "
            "link_02__link_03)")),
    ("1,2,3,4", "--q: 4 values for 3 joint variables"),
    ("elbow=1", ("--q: 'elbow' is not a joint variable of the chain (variables: "
                "base_link__link_01, link_01__link_02, link_02__link_03)")),
    ("1,link_01__link_02=1", "give either all values in order or name=value pairs"),
    ("1,x,2", "--q: 'x' is not a number"),
    ("1,__import__('os'),2", "is not a number"),
    ("1,1e999,2", "--q: '1e999' is not a finite number"),
    ("1,nan,2", "--q: 'nan' is not a finite number"),
])
def test_bad_q(q, message):
    result = run_urdftool("jacobian", *ARM, "--q", q)
    assert result.code == 2
    assert message in result.err
    assert len(result.err.strip().splitlines()) == 1 and "Traceback" not in result.err


def test_mimic_follower_is_not_a_variable(write):
    result = run_urdftool("jacobian", str(write(MIMIC)), "--tip", "l4", "--q", "j2=0.1")
    assert result.code == 2 and "joint 'j2' mimics 'other': give 'other' instead" in result.err


# -- conditioning --------------------------------------------------------------------------------


@pytest.mark.parametrize("q2", [0.7, -1.9, 2.5])
def test_planar_2r_closed_forms(write, q2):
    chain = extract_chain(load_robot(str(write(PLANAR_2R))))
    q = [0.4, q2]
    s1, c1 = math.sin(q[0]), math.cos(q[0])
    s12, c12 = math.sin(q[0] + q2), math.cos(q[0] + q2)
    expected = np.array([[-L1 * s1 - L2 * s12, -L2 * s12], [L1 * c1 + L2 * c12, L2 * c12],
                         [0, 0], [0, 0], [0, 0], [1, 1]])
    jac = geometric_jacobian(chain, q)
    assert np.abs(jac - expected).max() < 1e-12
    full, position = analyse(chain, jac)
    assert position.manipulability == pytest.approx(L1 * L2 * abs(math.sin(q2)), rel=1e-12)
    assert full.manipulability == pytest.approx(math.sqrt(np.linalg.det(expected.T @ expected)),
                                                rel=1e-12)
    sv = np.linalg.svd(expected[:2], compute_uv=False)
    assert position.condition == pytest.approx(sv[0] / sv[1], rel=1e-12)
    assert not position.near_singular and not full.near_singular


def test_planar_2r_stretched_is_singular(write):
    chain = extract_chain(load_robot(str(write(PLANAR_2R))))
    for q2 in (0.0, 1e-5):
        _full, position = analyse(chain, geometric_jacobian(chain, [0.3, q2]))
        assert position.near_singular
    result = run_urdftool("jacobian", str(write(PLANAR_2R)), "--q", "0.3,0")
    assert result.code == 0
    assert "warning: near a singularity: its position rows (vx vy vz) lose rank" in result.out
    assert "condition number inf" in result.out


def test_ur5_zero_is_singular_and_a_random_pose_is_not():
    result = run_urdftool("jacobian", UR5, "--tip", "ee_link", "--format", "json")
    assert result.code == 0 and "near a singularity: the Jacobian lose" in result.err
    result = run_urdftool("jacobian", UR5, "--tip", "ee_link", "--q=0.3,-1.1,1.4,-0.6,1.2,0.4")
    assert result.code == 0
    assert "not near a singularity" in result.out and "warning" not in result.out
    for word in ("singular values", "manipulability", "condition number", "tip origin"):
        assert word in result.out


def test_structural_rank_is_not_a_singularity():
    """The tip origin of link_03 lies on joint 3's axis: the position rows never exceed rank 2;
    that is said once, and no singularity warning follows at a generic pose."""
    result = run_urdftool("jacobian", *ARM, "--q=0.1,0.5,0.5")
    assert result.code == 0
    assert "rank 2 at most for this chain" in result.out
    assert "warning" not in result.out


def test_text_output_lists_the_configuration():
    result = run_urdftool("jacobian", PANDA, "--tip", "panda_hand", "--q", "mid")
    assert result.code == 0
    for name in [f"panda_joint{i}" for i in range(1, 8)]:
        assert name in result.out
    assert "[-3.0718, -0.0698]" in result.out
    for row in ("vx", "vy", "vz", "wx", "wy", "wz"):
        assert f"│ {row} " in result.out


def test_latex_numeric():
    result = run_urdftool("jacobian", *ARM, "--q=0.1,0.2,0.3", "--format", "latex")
    assert result.code == 0 and r"J = \begin{bmatrix}" in result.out


# -- inputs ----------------------------------------------------------------------------------------


def test_sdf_input_matches_the_urdf():
    q = "--q=0.3,-0.4,0.5,-1.2,0.7,0.9,-0.2"
    sdf = _json(str(pybullet_data_dir() / "kuka_iiwa" / "model.sdf"), q)
    urdf = _json(str(pybullet_data_dir() / "kuka_iiwa" / "model.urdf"), q)
    assert sdf["joints"] == urdf["joints"]
    assert np.abs(np.array(sdf["J"]) - np.array(urdf["J"])).max() < 1e-4  # SDF: 1.5708


def test_bad_combinations():
    result = run_urdftool("jacobian", *ARM, "--format", "numpy")
    assert result.code == 2 and "add --symbolic" in result.err
    result = run_urdftool("jacobian", *ARM, "--symbolic", "--q", "0,0,0")
    assert result.code == 2 and "leave out --q" in result.err
    result = run_urdftool("jacobian", DUAL_ARM)
    assert result.code == 2 and "3 leaves (link_003, link_eeleft, link_eeright)" in result.err
    result = run_urdftool("jacobian", *ARM, "--tolerance", "nan")
    assert result.code == 2 and "--tolerance" in result.err


def test_q_outside_the_limits_is_computed_with_a_warning():
    # issue 14: q = 0 of a Panda (joint4 beyond its upper limit -0.0698) is a configuration
    # people ask for; the Jacobian is defined there: computed, checked against pinocchio, warned
    import numpy as np
    import pinocchio as pin

    result = run_urdftool("jacobian", PANDA, "--tip", "panda_link8", "--q", "0,0,0,0.5,0,0,0",
                          "--format", "json")
    assert result.code == 0, result.err
    assert ("joint 'panda_joint4' = 0.5 is outside its limits [-3.0718, -0.0698] rad; the "
            "Jacobian is computed there all the same") in result.err
    data = json.loads(result.out)
    model = pin.buildModelFromUrdf(PANDA)
    q = pin.neutral(model)
    q[model.joints[model.getJointId("panda_joint4")].idx_q] = 0.5
    frame = model.getFrameId("panda_link8")
    expected = pin.computeFrameJacobian(model, model.createData(), q, frame,
                                        pin.LOCAL_WORLD_ALIGNED)
    columns = [model.joints[model.getJointId(name)].idx_v for name in data["joints"]]
    assert np.allclose(np.array(data["J"]), expected[:, columns], atol=1e-9)
