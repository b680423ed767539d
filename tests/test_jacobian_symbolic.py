"""`urdftool jacobian --symbolic`: the sympy tip position and Jacobian, evaluated at random q,
equal the numeric ones (which test_kinematics_pinocchio.py checks against pinocchio); the text,
LaTeX, JSON and NumPy-code outputs; and the seed dual-arm's hand-derived Jacobian set beside the
one derived from its URDF, with every difference located and explained."""

from __future__ import annotations

import json

import numpy as np
import pytest
import sympy as sp

from tests.conftest import ROBOTS, example_robot_data_dir, run_urdftool
from tests.test_kinematics_pinocchio import MIMIC, PRISMATIC_FIXED, _robot
from urdftool.cli import load_robot
from urdftool.kinematics.chain import extract_chain
from urdftool.kinematics.fk import forward
from urdftool.kinematics.jacobian import geometric_jacobian
from urdftool.kinematics.symbolic import symbolic_kinematics

DUAL_ARM = ROBOTS / "dual_arm" / "corrected" / "test.xacro"
ERD = example_robot_data_dir() / "robots"
# One joint origin with an arbitrary rotation and an axis along no coordinate direction: its
# numbers stay full-precision Floats in the expressions.
TILTED = _robot("tilted", [
    ("j1", "revolute", "base", "l1", "0 0 0.2", "0 0 0", "0 0 1", (-2, 2)),
    ("j2", "revolute", "l1", "l2", "0.1 0 0.3", "0.3 -0.2 0.5", "0.2 1 0.1", (-2, 2)),
    ("j3", "prismatic", "l2", "l3", "0.2 0 0", "0 0 0", "1 0 0", (0, 0.3)),
    ("tip", "fixed", "l3", "tool", "0.05 0.02 0.1", "0 0 0"),
])


def _compare(chain, result, samples=20, tol=1e-9):
    worst = 0.0
    for q in chain.sample(np.random.default_rng(3), samples):
        position, jac = result.evaluate(q)
        worst = max(worst, np.abs(jac - geometric_jacobian(chain, q)).max(),
                    np.abs(position - forward(chain, q)[:3, 3]).max())
    assert worst < tol
    return worst


@pytest.mark.parametrize(("source", "tip", "simplify"), [
    (DUAL_ARM, "link_eeleft", "auto"),
    (DUAL_ARM, "link_003", "full"),
    (MIMIC, "l4", "none"),  # simplified through the CLI in test_numpy_code_runs_and_agrees
    # ~6 s of sympy: CI (slow); make test derives TILTED through the CLI below
    pytest.param(PRISMATIC_FIXED, None, "auto", marks=pytest.mark.slow),
    pytest.param(TILTED, None, "auto", marks=pytest.mark.slow),
])
def test_symbolic_equals_numeric(write, source, tip, simplify):
    path = write(source) if isinstance(source, str) else source
    chain = extract_chain(load_robot(str(path)), None, tip)
    _compare(chain, symbolic_kinematics(chain, simplify))


@pytest.mark.slow  # ~11 s of sympy: CI; make test simplifies the smaller chains above
def test_symbolic_ur5_simplified():
    chain = extract_chain(load_robot(str(ERD / "ur_description/urdf/ur5_robot.urdf")), None,
                          "ee_link")
    result = symbolic_kinematics(chain)
    assert result.simplified == "trig"
    # the URDF's 1.57079632679 is taken as pi/2 (5e-12 off): still equal at 1e-9
    assert result.snapped
    _compare(chain, result)
    # parallel shoulder/elbow/wrist-1 axes: their angles combine into sums
    assert any(arg.is_Add for e in result.position for f in e.atoms(sp.cos, sp.sin)
               for arg in f.args)


@pytest.mark.slow  # ~2 s of sympy: CI
def test_symbolic_7dof_is_left_unsimplified_but_exact():
    chain = extract_chain(load_robot(str(ERD / "panda_description/urdf/panda.urdf")), None,
                          "panda_hand")
    result = symbolic_kinematics(chain)
    assert result.simplified == "none"
    _compare(chain, result, samples=5)


# -- output formats ----------------------------------------------------------------------------

ARM = (str(DUAL_ARM), "--tip", "link_eeleft", "--symbolic")


def test_text():
    result = run_urdftool("jacobian", *ARM)
    assert result.code == 0, result.err
    assert "q1 = q_base_link__link_01 (rad)" in result.out
    assert "l2 = 0.6 m" in result.out and "l3_x = 0.03 m" in result.out
    assert "pz = l0_z + l1 + l2*cos(q2) + l3_z*cos(q2 + q3)" in result.out
    assert "J[vz, q3] = -l3_z*sin(q2 + q3)" in result.out


def test_latex():
    result = run_urdftool("jacobian", *ARM, "--format", "latex")
    assert result.code == 0, result.err
    assert r"J = \begin{bmatrix}" in result.out and r"l_{3z}" in result.out
    assert r"\cos{\left(q_{2} + q_{3} \right)}" in result.out


def test_json():
    result = run_urdftool("jacobian", *ARM, "--format", "json")
    assert result.code == 0, result.err
    data = json.loads(result.out)
    assert data["joints"] == ["base_link__link_01", "link_01__link_02", "link_02__link_03",
                              "link_03__link_eeleft"]
    assert data["lengths"] == {"l0_x": 0.25, "l0_z": 0.25, "l1": 0.15, "l2": 0.6, "l3_x": 0.03,
                               "l3_z": 0.6}
    assert len(data["J"]) == 6 and all(len(row) == 4 for row in data["J"])
    assert data["J"][5][0] == "1"


@pytest.mark.parametrize(("source", "tip"), [(DUAL_ARM, "link_eeleft"), (TILTED, None),
                                             # ~9 s of sympy: CI (slow)
                                             pytest.param(MIMIC, "l4", marks=pytest.mark.slow)])
def test_numpy_code_runs_and_agrees(write, source, tip):
    path = write(source) if isinstance(source, str) else source
    args = [str(path), "--symbolic", "--format", "numpy"] + (["--tip", tip] if tip else [])
    result = run_urdftool("jacobian", *args)
    assert result.code == 0, result.err
    namespace: dict = {}
    exec(compile(result.out, "generated.py", "exec"), namespace)  # noqa: S102 - our own output
    chain = extract_chain(load_robot(str(path)), None, tip)
    for q in chain.sample(np.random.default_rng(9), 10):
        assert np.abs(namespace["jacobian"](q) - geometric_jacobian(chain, q)).max() < 1e-9
        assert np.abs(namespace["tip_position"](q) - forward(chain, q)[:3, 3]).max() < 1e-9


# -- the seed's hand derivation beside the URDF's -------------------------------------------------


@pytest.fixture(scope="module")
def seed_arm(tmp_path_factory):
    """The seed's left arm with its end-effector point: the end of link_03 (0.6 m along it,
    between the two fingers), as a fixed 'tool' link, so that the chain is the seed's 3-DoF
    arm with l1 = 0.15, l2 = 0.6, l3 = 0.6."""
    text = DUAL_ARM.read_text(encoding="utf-8").replace("</robot>", """
  <link name="tool"/>
  <joint name="link_03__tool" type="fixed"><parent link="link_03"/><child link="tool"/>
    <origin xyz="0 0 0.6" rpy="0 0 0"/></joint>
</robot>""")
    path = tmp_path_factory.mktemp("seed") / "arm.urdf"
    path.write_text(text, encoding="utf-8")
    chain = extract_chain(load_robot(str(path)), None, "tool")
    return chain, symbolic_kinematics(chain)


def _seed_expressions(result):
    """The seed's formulas (section 2.3 and appendix 4.1.1), in our symbols."""
    th1, th2, th3 = result.q
    names = {str(s): s for s in result.lengths}
    l1, l2, l3 = names["l1"], names["l2"], names["l3"]
    s1, c1, s2, c2 = sp.sin(th1), sp.cos(th1), sp.sin(th2), sp.cos(th2)
    s3, c3 = sp.sin(th3), sp.cos(th3)
    s23, c23 = sp.sin(th2 + th3), sp.cos(th2 + th3)
    # MATLAB's A_03 (appendix 4.1.1): the last column
    position = sp.Matrix([l3 * c23 + l1 * c1 + l2 * c2,
                          l1 * s1 + l2 * c1 * s2 + l3 * c1 * c2 * s3 + l3 * c1 * c3 * s2,
                          s1 * (l3 * s23 + l2 * s2)])
    # the typeset 0T3 of section 2.3: its z entry
    typeset_pz = l3 * s1 * s23 + l2 * s2
    # the "final Jacobian Matrix" of section 2.3, as printed
    jacobian = sp.Matrix([
        [-l1 * s1, -l2 * s23 - l2 * s2, -l2 * s23],
        [l1 * c1 - l2 * s1 * s2 - l3 * s1 * c2 * c3 - l3 * s1 * s2 * c3,
         l2 * c1 * c2 - l3 * c1 * s2 * s3 + l3 * c1 * c2 * c3,
         l3 * c1 * c2 * c3 - l3 * c1 * s2 * s3],
        [l3 * c1 * s23 + l2 * c1 * s2, l3 * s1 * c23 + l2 * s1 * c2, l3 * s1 * c23],
    ])
    return position, typeset_pz, jacobian, (l1, l2, l3)


def _zero(expr) -> bool:
    return sp.simplify(sp.expand_trig(expr)) == 0


def test_urdf_derivation_of_the_seed_arm(seed_arm):
    """What the URDF says, symbolically: joint 1 turns about the vertical z, joints 2 and 3
    about x; l1 (0.15) lies along joint 1's axis; the arm stands at (-0.25, 0, 0.25)."""
    chain, result = seed_arm
    th1, th2, th3 = result.q
    names = {str(s): s for s in result.lengths}
    assert {k: v for k, v in zip(names, result.lengths.values())} == {
        "l0_x": 0.25, "l0_z": 0.25, "l1": 0.15, "l2": 0.6, "l3": 0.6}
    l0x, l0z, l1, l2, l3 = (names[k] for k in ("l0_x", "l0_z", "l1", "l2", "l3"))
    reach = l2 * sp.sin(th2) + l3 * sp.sin(th2 + th3)
    expected = sp.Matrix([-l0x + sp.sin(th1) * reach, -sp.cos(th1) * reach,
                          l0z + l1 + l2 * sp.cos(th2) + l3 * sp.cos(th2 + th3)])
    assert all(_zero(e) for e in result.position - expected)
    assert all(_zero(e) for e in result.jacobian[:3, :] - expected.jacobian(result.q))
    _compare(chain, result)


def test_seed_jacobian_beside_the_urdf_jacobian(seed_arm):
    """Where and why the seed's hand-derived Jacobian differs.

    1. Slips in the differentiation of its own position (3 of the 9 entries):
       - dPx/dθ2 is written -l2 s23 - l2 s2; it is -l3 s23 - l2 s2 (l2 where l3 belongs);
       - dPx/dθ3 is written -l2 s23; it is -l3 s23 (the same slip);
       - dPy/dθ1 has -l3 s1 c2 c3; it is -l3 s1 c2 s3 (c3 where s3 belongs).
       The other six entries are the right derivatives of its position.
    2. The typeset 0T3 drops s1 from the l2 term of Pz (l2 s2 instead of s1 l2 s2); MATLAB's
       output in the appendix has it, and the Jacobian's third row follows MATLAB.
    3. Its model is not its URDF's. The DH table puts θ1 in the α column (a twist is not a
       joint variable), and A_01 is not a DH transform: it rotates about x by θ1 but translates
       by l1 (c1, s1, 0), so link 1's length swings with θ1. In the URDF, link 1 (0.15 m) lies
       along joint 1's vertical axis and contributes no velocity at all. Seen from a base frame
       with x up (seed x = URDF z, seed y = -URDF y, seed z = URDF x: a proper rotation), with
       l1 taken out of A_01 and the URDF's mounting offset dropped, the seed's position and its
       corrected Jacobian are exactly the URDF's.
    """
    _, result = seed_arm
    position, typeset_pz, seed_jac, (l1, l2, l3) = _seed_expressions(result)
    q = result.q
    own = position.jacobian(q)  # the correct derivative of the seed's own position

    wrong = {(r, c) for r in range(3) for c in range(3) if not _zero(seed_jac[r, c] - own[r, c])}
    assert wrong == {(0, 1), (0, 2), (1, 0)}
    th1, th2, th3 = q
    s23 = sp.sin(th2 + th3)
    assert _zero(seed_jac[0, 1] - own[0, 1] - (l3 - l2) * s23)  # l2 where l3 belongs
    assert _zero(seed_jac[0, 2] - own[0, 2] - (l3 - l2) * s23)
    assert _zero(seed_jac[1, 0] - own[1, 0]
                 + l3 * sp.sin(th1) * sp.cos(th2) * (sp.cos(th3) - sp.sin(th3)))  # c3 for s3

    # 2. the typeset Pz lost the s1 of its l2 term
    assert _zero(position[2] - typeset_pz - l2 * sp.sin(th2) * (sp.sin(th1) - 1))

    # 3. the model: rotate the URDF's frame so x points up, drop the mounting offset ...
    rotation = sp.Matrix([[0, 0, 1], [0, -1, 0], [1, 0, 0]])
    assert rotation.det() == 1
    names = {str(s): s for s in result.lengths}
    mount = sp.Matrix([-names["l0_x"], 0, names["l0_z"] + names["l1"]])
    urdf_in_seed_frame = rotation * (result.position - mount)
    # ... and the seed's position without its l1 terms is the URDF's
    assert all(_zero(e) for e in position.subs(l1, 0) - urdf_in_seed_frame)
    urdf_jac = rotation * result.jacobian[:3, :]
    assert all(_zero(e) for e in own.subs(l1, 0) - urdf_jac)
    # the seed's l1 terms: a velocity l1 (-s1, c1, 0) of joint 1 that the URDF does not have
    assert all(_zero(e) for e in (own - urdf_jac)[:, 0]
               - sp.Matrix([-l1 * sp.sin(th1), l1 * sp.cos(th1), 0]))
    assert all(_zero(e) for e in (own - urdf_jac)[:, 1:])

    # In numbers, at one pose with the URDF's lengths: the l1 terms and the c3-for-s3 slip show
    # in column 1; the l2-for-l3 slip is invisible because this robot has l2 == l3 == 0.6 ...
    values = {th1: 0.3, th2: 0.5, th3: -0.4, l1: 0.15, l2: 0.6, l3: 0.6}

    def numbers(matrix, at):
        return np.array(matrix.subs(at).evalf(), dtype=float)

    difference = np.abs(numbers(seed_jac, values) - numbers(urdf_jac, values))
    assert difference[:, 0].max() > 0.05
    assert difference[:, 1:].max() < 1e-12
    # ... and shows as soon as the two lengths differ
    values[l3] = 0.45
    difference = np.abs(numbers(seed_jac, values) - numbers(urdf_jac, values))
    assert difference[0, 1] > 0.01 and difference[0, 2] > 0.01


def test_no_compact_closed_form_is_a_clear_error(write):
    """Seven joints whose origins and axes are rotated by arbitrary angles: the expressions
    would swell without bound; the command says so instead of running for hours."""
    dense = _robot("dense", [(f"j{i}", "revolute", f"l{i}", f"l{i + 1}", "0.1 0.2 0.3",
                              f"0.{i + 1} -0.{i + 2} 0.7", "0.3 0.5 0.8", (-2, 2))
                             for i in range(7)])
    result = run_urdftool("jacobian", str(write(dense)), "--symbolic")
    assert result.code == 2
    assert "no compact closed form; use the numeric Jacobian (--q)" in result.err
    assert len(result.err.strip().splitlines()) == 1


# A vendor's rounded pi/2 (UR's kinematics YAML writes 1.570796327): cos is -2.05e-10
ROUNDED = _robot("rounded", [
    ("j1", "revolute", "base", "l1", "0 0 0.16", "0 0 0", "0 0 1", (-3, 3)),
    ("j2", "revolute", "l1", "l2", "0 0 0", "1.570796327 0 0", "0 0 1", (-3, 3)),
    ("j3", "revolute", "l2", "l3", "-0.425 0 0", "0 0 0", "0 0 1", (-3, 3)),
    ("tip", "fixed", "l3", "tool", "-0.39 0 0", "0 0 0"),
])


def test_angles_near_multiples_of_half_pi_are_recognised_and_said(write):
    import math

    path = write(ROUNDED)
    assert abs(math.cos(1.570796327)) > 1e-10  # what the old 1e-10 tolerance let through
    result = run_urdftool("jacobian", "--symbolic", path)
    assert result.code == 0, result.err
    expressions = [line for line in result.out.splitlines() if line.startswith(("p", "J["))]
    assert len(expressions) == 3 + 6 * 3
    assert not any("e-1" in line for line in expressions), result.out  # no 2.05e-10*sin(q2)
    note = next(line for line in result.out.splitlines() if "taken as exact" in line)
    assert "origin of 'j2'" in note and f"off by up to {abs(math.cos(1.570796327)):.3g}" in note
    assert "within 1e-06" in note
    chain = extract_chain(load_robot(str(path)), None, None)
    _compare(chain, symbolic_kinematics(chain), tol=1e-8)  # the snap moves the tip < 1e-9 m
    # the numeric table keeps the angle as written: its Jacobian is pinocchio's/ours exactly
    numeric = json.loads(run_urdftool("jacobian", "--format", "json", "--q", "0.3,0.2,0.1",
                                      path).out)
    expected = geometric_jacobian(chain, np.array([0.3, 0.2, 0.1]))
    assert np.array(numeric["J"]).shape == expected.shape
    assert np.array_equal(np.array(numeric["J"]), expected)
