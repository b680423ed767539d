"""Kinematics checked against pinocchio (never against urdftool's own FK): forward kinematics,
the DH product written out by `urdftool dh --format json` (evaluated here with this file's own
DH formulas), and the geometric Jacobian (`getFrameJacobian(..., LOCAL_WORLD_ALIGNED)`, also
through `urdftool jacobian --format json`), at 50 random configurations within the limits, to
1e-9. Subjects: ur5 (example-robot-data), panda arm without fingers, kuka iiwa (pybullet_data),
one arm of the seed dual-arm, and small hand-written chains with the awkward cases (prismatic
and fixed joints in the middle, parallel, collinear, intersecting and nearly parallel axes,
arbitrary rotations and non-unit axes, continuous joints, mimic joints).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from tests.conftest import ROBOTS, example_robot_data_dir, pybullet_data_dir, run_urdftool
from urdftool.cli import load_robot
from urdftool.kinematics.chain import extract_chain
from urdftool.kinematics.dh import extract_dh, self_check
from urdftool.kinematics.fk import forward
from urdftool.kinematics.jacobian import geometric_jacobian

TOL = 1e-9
SAMPLES = 50


def _joint(name, kind, parent, child, xyz="0 0 0", rpy="0 0 0", axis=None, limit=None,
           mimic=""):
    axis_xml = f'<axis xyz="{axis}"/>' if axis else ""
    limit_xml = (f'<limit lower="{limit[0]}" upper="{limit[1]}" effort="10" velocity="1"/>'
                 if limit else "")
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}" rpy="{rpy}"/>{axis_xml}{limit_xml}{mimic}</joint>')


def _robot(name, joints) -> str:
    links = []
    for j in joints:
        for link in ((j[2], j[3]) if isinstance(j, tuple) else (j["parent"], j["child"])):
            if link not in links:
                links.append(link)
    body = "".join(f'<link name="{link}"/>' for link in links)
    body += "".join(_joint(*j) if isinstance(j, tuple) else _joint(**j) for j in joints)
    return f'<?xml version="1.0"?>\n<robot name="{name}">{body}</robot>\n'


R = (-2.0, 2.0)
# A prismatic joint and a fixed joint in the middle of the chain, a fixed tool at the end.
PRISMATIC_FIXED = _robot("prismatic_fixed", [
    ("j1", "revolute", "base", "l1", "0.1 0 0.2", "0 0 0.3", "0 0 1", R),
    ("fix", "fixed", "l1", "l1b", "0 0.15 0.3", "0.4 -0.2 0.1"),
    ("slide", "prismatic", "l1b", "l2", "0.05 0 0.1", "0 0.5 0", "0 0.6 0.8", (-0.2, 0.5)),
    ("j3", "revolute", "l2", "l3", "0.2 0 0", "0 0 0", "1 0 0", (-1.5, 1.5)),
    ("tool_joint", "fixed", "l3", "tool", "0 0.1 0.05", "0.1 0.2 0.3"),
])
# Consecutive parallel axes, offset along the axis too (so the common normal is a choice).
PARALLEL = _robot("parallel", [
    ("j1", "revolute", "base", "l1", "0 0 0.1", "0.3 0.2 0.1", "0 0 1", R),
    ("j2", "revolute", "l1", "l2", "0.4 0 0.05", "0 0 0", "0 0 1", R),
    ("j3", "revolute", "l2", "l3", "0.3 0.1 -0.02", "0 0 0", "0 0 -1", R),
    ("j4", "revolute", "l3", "l4", "0.2 0 0", "0 0 0", "1 0 0", R),
    ("tip", "fixed", "l4", "tip_link", "0.1 0.05 0", "0 0 0"),
])
# A spherical wrist: three intersecting axes, then a tool off the centre.
INTERSECTING = _robot("intersecting", [
    ("j1", "revolute", "base", "l1", "0 0 0.3", "0 0 0", "0 0 1", R),
    ("j2", "revolute", "l1", "l2", "0 0 0", "0 0 0", "0 1 0", R),
    ("j3", "revolute", "l2", "l3", "0 0 0", "0 0 0", "1 0 0", R),
    ("tip", "fixed", "l3", "tool", "0.05 0 0.1", "0 0.3 0"),
])
# Origins with arbitrary rotations, axes not unit and not perpendicular to anything, a
# continuous joint and a prismatic one along a skew direction.
ROTATED = _robot("rotated", [
    ("j1", "revolute", "base", "l1", "0.1 -0.2 0.3", "0.3 -1.1 2.5", "1 2 3", R),
    ("j2", "revolute", "l1", "l2", "0.25 0.1 -0.05", "-0.7 0.4 1.9", "-0.3 0.5 0.8", R),
    ("j3", "continuous", "l2", "l3", "0 0.3 0.1", "2.9 0.1 -0.6", "0.2 -0.9 0.1"),
    ("j4", "prismatic", "l3", "l4", "0.1 0.1 0.1", "0.5 0.5 0.5", "1 1 0", (-0.3, 0.3)),
    ("tip", "fixed", "l4", "tool", "0.05 0 0.2", "1 2 3"),
])
# Collinear revolute axes, then a prismatic joint along the same line.
COLLINEAR = _robot("collinear", [
    ("j1", "revolute", "base", "l1", "0 0 0.1", "0 0 0", "0 0 1", R),
    ("j2", "revolute", "l1", "l2", "0 0 0.3", "0 0 0.7", "0 0 1", R),
    ("j3", "prismatic", "l2", "l3", "0 0 0.2", "0 0 0", "0 0 1", (0.0, 0.4)),
    ("j4", "revolute", "l3", "l4", "0.2 0 0.1", "0 0 0", "1 0 0", R),
    ("tip", "fixed", "l4", "tool", "0 0.1 0", "0 0 0"),
])
# Axes 1e-5 rad from parallel (as rounded rpy values produce): DH stays exact, with a note.
NEARLY_PARALLEL = _robot("nearly_parallel", [
    ("j1", "revolute", "base", "l1", "0 0 0.1", "0 0 0", "0 0 1", R),
    ("j2", "revolute", "l1", "l2", "0.3 0 0", "0 0 0", "0 0.00001 1", R),
    ("j3", "revolute", "l2", "l3", "0.25 0 0", "0 0 0", "0 1 0", R),
    ("tip", "fixed", "l3", "tool", "0.1 0 0", "0 0 0"),
])
# Mimic joints: one follows a leader outside the chain, one a leader inside it.
MIMIC = _robot("mimic", [
    ("j1", "revolute", "base", "l1", "0 0 0.2", "0 0 0", "0 0 1", R),
    ("other", "revolute", "base", "side", "0.3 0 0", "0 0 0", "0 1 0", (-1, 1)),
    {"name": "j2", "kind": "revolute", "parent": "l1", "child": "l2", "xyz": "0.3 0 0",
     "axis": "0 1 0", "limit": (-5, 5),
     "mimic": '<mimic joint="other" multiplier="0.5" offset="0.1"/>'},
    {"name": "j3", "kind": "revolute", "parent": "l2", "child": "l3", "xyz": "0.25 0 0.1",
     "axis": "0 1 0", "limit": (-5, 5), "mimic": '<mimic joint="j1" multiplier="-2"/>'},
    ("j4", "prismatic", "l3", "l4", "0.1 0 0", "0 0 0", "1 0 0", (0, 0.2)),
])


def _erd(relative: str) -> Path:
    return example_robot_data_dir() / "robots" / relative


DUAL_ARM = ROBOTS / "dual_arm" / "corrected" / "test.xacro"

# id -> (path or URDF text, base, tip)
CASES = {
    "ur5": (lambda: _erd("ur_description/urdf/ur5_robot.urdf"), None, "ee_link"),
    "ur5-tool0": (lambda: _erd("ur_description/urdf/ur5_robot.urdf"), "base_link", "tool0"),
    "panda-hand": (lambda: _erd("panda_description/urdf/panda.urdf"), None, "panda_hand"),
    "panda-link8": (lambda: _erd("panda_description/urdf/panda.urdf"), None, "panda_link8"),
    # a base that is rotated in the world: the Jacobian is expressed in its axes
    "panda-from-link2": (lambda: _erd("panda_description/urdf/panda.urdf"), "panda_link2",
                         "panda_hand"),
    "iiwa": (lambda: pybullet_data_dir() / "kuka_iiwa" / "model.urdf", None, None),
    "dual_arm-left": (lambda: DUAL_ARM, None, "link_eeleft"),
    "dual_arm-right": (lambda: DUAL_ARM, None, "link_003"),
    "dual_arm-mid": (lambda: DUAL_ARM, "link_01", "link_03"),
    "prismatic_fixed": (PRISMATIC_FIXED, None, None),
    "parallel": (PARALLEL, None, None),
    "intersecting": (INTERSECTING, None, None),
    "rotated": (ROTATED, None, None),
    "collinear": (COLLINEAR, None, None),
    "nearly_parallel": (NEARLY_PARALLEL, None, None),
    "mimic": (MIMIC, None, "l4"),
}


class Subject:
    """One case: the file, urdftool's chain, and pinocchio's model of the same file."""

    def __init__(self, case: str, tmp_path_factory):
        source, self.base, self.tip = CASES[case]
        if isinstance(source, str):
            self.path = tmp_path_factory.mktemp(case) / f"{case}.urdf"
            self.path.write_text(source, encoding="utf-8")
        else:
            self.path = source()
        self.chain = extract_chain(load_robot(str(self.path)), self.base, self.tip)
        # mimic=False: pinocchio treats followers as independent joints; we drive them.
        self.model = pin.buildModelFromXML(self.path.read_text(encoding="utf-8"))
        self.data = self.model.createData()
        self.tip_frame = self.model.getFrameId(self.chain.tip, pin.BODY)
        self.base_frame = self.model.getFrameId(self.chain.base, pin.BODY)

    def configurations(self, seed: int = 7) -> np.ndarray:
        return self.chain.sample(np.random.default_rng(seed), SAMPLES)

    def pin_q(self, q) -> np.ndarray:
        """pinocchio's configuration vector for chain variables q (mimics applied here)."""
        config = pin.neutral(self.model)
        values = dict(zip(self.chain.variable_names, q))
        for joint, value in zip(self.chain.joints, self.chain.joint_values(q)):
            values[joint.name] = value
        for name, value in values.items():
            joint = self.model.joints[self.model.getJointId(name)]
            if joint.nq == 2:  # continuous: (cos, sin)
                config[joint.idx_q:joint.idx_q + 2] = [math.cos(value), math.sin(value)]
            else:
                config[joint.idx_q] = value
        return config

    def placement(self, q) -> np.ndarray:
        """Tip pose in the base link's frame, by pinocchio."""
        pin.framesForwardKinematics(self.model, self.data, self.pin_q(q))
        base = self.data.oMf[self.base_frame]
        return (base.inverse() * self.data.oMf[self.tip_frame]).homogeneous

    def jacobian(self, q) -> np.ndarray:
        """pinocchio's LOCAL_WORLD_ALIGNED frame Jacobian turned into the base link's axes
        (the chain's joints do not move the base), columns summed per chain variable (a mimic
        follower's column times its multiplier goes to its leader)."""
        config = self.pin_q(q)
        full = pin.computeFrameJacobian(self.model, self.data, config, self.tip_frame,
                                        pin.LOCAL_WORLD_ALIGNED)
        pin.framesForwardKinematics(self.model, self.data, config)
        to_base = self.data.oMf[self.base_frame].rotation.T
        full = np.vstack([to_base @ full[:3], to_base @ full[3:]])
        out = np.zeros((6, self.chain.n))
        for joint in self.chain.joints:
            column = self.model.joints[self.model.getJointId(joint.name)].idx_v
            out[:, joint.variable] += joint.multiplier * full[:, column]
        return out


@pytest.fixture(scope="module", params=list(CASES))
def subject(request, tmp_path_factory) -> Subject:
    return Subject(request.param, tmp_path_factory)


def _dh_matrix(convention: str, theta: float, d: float, a: float, alpha: float) -> np.ndarray:
    """Written out independently of urdftool.kinematics.dh."""
    ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    if convention == "standard":  # Rz(theta) Tz(d) Tx(a) Rx(alpha)
        return np.array([[ct, -st * ca, st * sa, a * ct],
                         [st, ct * ca, -ct * sa, a * st],
                         [0, sa, ca, d],
                         [0, 0, 0, 1.0]])
    # modified (Craig): Rx(alpha) Tx(a) Rz(theta) Tz(d)
    return np.array([[ct, -st, 0, a],
                     [st * ca, ct * ca, -sa, -sa * d],
                     [st * sa, ct * sa, ca, ca * d],
                     [0, 0, 0, 1.0]])


def _dh_forward(table: dict, values) -> np.ndarray:
    result = np.array(table["base"], dtype=float)
    for row, value in zip(table["rows"], values):
        prismatic = row["type"] == "prismatic"
        theta = row["theta"] + (0.0 if prismatic else value)
        d = row["d"] + (value if prismatic else 0.0)
        result = result @ _dh_matrix(table["convention"], theta, d, row["a"], row["alpha"])
    return result @ np.array(table["tool"], dtype=float)


def _cli_args(subject: Subject) -> list[str]:
    args = [str(subject.path)]
    if subject.base:
        args += ["--base", subject.base]
    if subject.tip:
        args += ["--tip", subject.tip]
    return args


def test_forward_kinematics_matches_pinocchio(subject):
    worst = max(np.abs(forward(subject.chain, q) - subject.placement(q)).max()
                for q in subject.configurations())
    assert worst < TOL


def test_jacobian_matches_pinocchio(subject):
    worst = max(np.abs(geometric_jacobian(subject.chain, q) - subject.jacobian(q)).max()
                for q in subject.configurations())
    assert worst < TOL


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_dh_json_matches_pinocchio(subject, convention):
    result = run_urdftool("dh", *_cli_args(subject), "--convention", convention,
                          "--format", "json")
    assert result.code == 0, result.err
    assert result.err == ""  # no self-check warning
    table = json.loads(result.out)
    assert list(table) == ["convention", "base", "tool", "rows"]
    assert table["convention"] == convention
    assert [list(row) for row in table["rows"]] == [
        ["joint", "type", "theta", "d", "a", "alpha"]] * len(subject.chain.joints)
    assert [row["joint"] for row in table["rows"]] == [j.name for j in subject.chain.joints]
    worst = 0.0
    for q in subject.configurations(seed=11):
        values = subject.chain.joint_values(q)  # each row's variable is its joint's position
        worst = max(worst, np.abs(_dh_forward(table, values) - subject.placement(q)).max())
    assert worst < TOL


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_dh_rows_are_dh_transforms_along_the_urdf_axes(subject, convention):
    """+q in the URDF is +theta (or +d): the DH z axis of each joint points along its URDF
    axis. Check with pinocchio: moving joint i alone moves the tip as rotating (translating)
    about (along) the world z axis of DH frame i-1 (standard) or i (modified)."""
    result = extract_dh(subject.chain, convention)
    q = subject.configurations(seed=3)[0]
    values = subject.chain.joint_values(q)
    step = 1e-6
    shared = [j.variable for j in subject.chain.joints]
    for i, joint in enumerate(subject.chain.joints):
        if joint.mimic or shared.count(joint.variable) > 1:
            continue
        frames = result.transforms(values)
        pose = result.base
        for a in frames[: i if convention == "standard" else i + 1]:
            pose = pose @ a
        z_dh, origin = pose[:3, 2], pose[:3, 3]
        moved = q.copy()
        moved[joint.variable] += step
        delta = subject.placement(moved) - subject.placement(q)
        if joint.revolute:
            # angular velocity of the tip: skew part of dR R^T
            rotation = subject.placement(q)[:3, :3]
            omega = delta[:3, :3] @ rotation.T / step
            w = np.array([omega[2, 1], omega[0, 2], omega[1, 0]])
            assert np.allclose(w, z_dh, atol=1e-5), (joint.name, w, z_dh)
            # and the axis passes through the DH frame's origin
            tip = subject.placement(q)[:3, 3]
            assert np.allclose(delta[:3, 3] / step, np.cross(z_dh, tip - origin), atol=1e-5)
        else:
            assert np.allclose(delta[:3, 3] / step, z_dh, atol=1e-5), joint.name


def test_dh_self_check_is_tiny(subject):
    for convention in ("standard", "modified"):
        assert self_check(subject.chain, extract_dh(subject.chain, convention)) < 1e-12


def test_jacobian_json_matches_pinocchio(subject):
    for q in subject.configurations(seed=5)[:4]:
        args = [str(subject.path)] + (["--tip", subject.tip] if subject.tip else [])
        args += ["--base", subject.base] if subject.base else []
        result = run_urdftool("jacobian", *args, "--q=" + ",".join(repr(float(v)) for v in q),
                              "--format", "json")
        assert result.code == 0, result.err
        data = json.loads(result.out)
        assert list(data) == ["tip", "q", "joints", "frame", "reference_point", "J"]
        frame = "world" if subject.chain.base_is_root else subject.chain.base
        assert data["frame"] == frame and data["reference_point"] == "tip_origin"
        assert data["tip"] == subject.chain.tip
        assert data["joints"] == subject.chain.variable_names
        assert data["q"] == [float(v) for v in q]  # repr round trip: full precision
        assert np.abs(np.array(data["J"]) - subject.jacobian(q)).max() < TOL
