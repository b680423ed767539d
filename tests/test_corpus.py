"""Good robots stay quiet: every URDF shipped by pybullet_data and example-robot-data gives no
error and no warning from any rule family, except the genuine defects listed in KNOWN_DEFECTS.

A rule that fires on a file and is not listed for it fails the test (a false alarm, or a new
genuine defect: then add it below, saying why it is wrong). A listed defect that no longer fires
fails too (the entry is stale, or the rule lost the case). Infos are advice and not checked.
"""

from __future__ import annotations

import pytest

from tests.conftest import (
    example_robot_data_dir,
    example_robot_urdfs,
    pybullet_data_dir,
    pybullet_urdfs,
)
from tests.test_inertia_corpus import INERTIA_KNOWN_DEFECTS
from urdftool.check import CheckOptions, check_file
from urdftool.source import LoadOptions

# file (as "pybullet_data/..." or "example-robot-data/...") -> {rule id: why it is genuinely
# wrong}. Extend it when a rule finds a real defect in these corpora; never to hide a false alarm.
KNOWN_DEFECTS: dict[str, dict[str, str]] = {
    # -- schema ----------------------------------------------------------------------------------
    "pybullet_data/bicycle/bike.urdf": {
        "schema.bad-vector": "two joint origins are written with commas (xyz=\"0.07, 0, -0.69\"): "
                             "check_urdf rejects the robot",
    },
    "pybullet_data/biped/biped2d_pybullet.urdf": {
        "schema.bad-number": "joint limits lower=\"-1.57.\" (two decimal points): check_urdf "
                             "rejects the robot",
        "joint.lower-above-upper": "prismatic lower=\"1\" upper=\"-1\": Bullet's idiom for 'no "
                                   "limit'; every URDF consumer sees an empty range",
    },
    "pybullet_data/humanoid/humanoid.urdf": {
        "schema.bad-value": "joints of type 'spherical', a PyBullet extension: check_urdf rejects "
                            "the robot",
        "schema.needs-version": "capsule collisions in a robot without version=\"1.1\": urdfdom "
                                "drops them",
    },
    "pybullet_data/spherical_joint_limit.urdf": {
        "schema.bad-value": "a joint of type 'spherical' (PyBullet only): check_urdf rejects it",
        "schema.missing-attribute": "<limit> without velocity: check_urdf rejects the joint",
    },
    "pybullet_data/husky/husky.urdf": {
        "schema.bad-vector": "the IMU joint origin is \"$(optenv HUSKY_IMU_XYZ 0.19 0 0.149)\": "
                             "a xacro substitution left in a .urdf; check_urdf rejects the robot",
    },
    "pybullet_data/quadruped/microtaur/microtaur.urdf": {
        "schema.bad-vector": "origins with four rpy numbers (rpy=\"-3.14159 1.57079 0 0\"): "
                             "check_urdf rejects the robot",
    },
    "pybullet_data/racecar/racecar_differential.urdf": {
        "schema.bad-vector": "mesh scale=\"1 1 1 1\" (four numbers): urdfdom drops the visuals",
        "schema.misplaced-element": "a <material> inside <geometry> instead of <visual>: the "
                                    "colour is ignored",
        "joint.continuous-with-limits": "right_steering_hinge_joint is continuous with limits "
                                        "[-1, 1] (its left twin is revolute): limits ignored",
        # issue 22.3: the differential's visual meshes are not found ('differential/X.stl' from
        # racecar/); its collisions bound it: the 2.637 kg differential's 0.0247 kg·m² kept on
        # 56-64 g gears, 620-1960x m r² (the visuals, measured with trimesh, are no larger)
        "inertia.exceeds-geometry": "diff_ring/spider/side gears of 56-64 g declare 0.0247 "
                                    "kg·m²: 620-1960x what their size allows",
    },
    "pybullet_data/racecar/racecar.urdf": {
        "schema.misplaced-element": "a <material> inside <geometry> instead of <visual>: the "
                                    "colour is ignored",
        "joint.continuous-with-limits": "right_steering_hinge_joint is continuous with limits "
                                        "[-1, 1] (its left twin is revolute): the limits are "
                                        "ignored, the wheel can steer round",
    },
    "pybullet_data/quadruped/spirit40newer.urdf": {
        "schema.duplicate-element": "a joint with two <axis> elements: the second is ignored",
        "material.undefined": "visuals use material 'darkgray', defined nowhere: default colour",
    },
    "pybullet_data/xarm/xarm6_robot.urdf": {
        "schema.bad-number": "<mechanicalReduction>reduction</mechanicalReduction>: a leftover "
                             "xacro parameter name, not a number (ros_control cannot load it)",
    },
    "pybullet_data/xarm/xarm6_robot_white.urdf": {
        "schema.bad-number": "<mechanicalReduction>reduction</mechanicalReduction>: not a number",
    },
    "pybullet_data/xarm/xarm6_with_gripper.urdf": {
        "schema.bad-number": "<mechanicalReduction>reduction</mechanicalReduction>: not a number",
    },
    "example-robot-data/robots/so_arm_description/urdf/so101.urdf": {
        "schema.misplaced-element": "an <origin> directly in a <link> (links have no pose): "
                                    "ignored by every parser",
    },
    "example-robot-data/robots/tiago_description/robots/tiago_dual.urdf": {
        "schema.sdf-element": "SDF <kinematic> and <gravity> inside URDF links: ignored",
        "gazebo.unknown-reference": "<gazebo reference=\"wheel_{side}_joint\"> and "
                                    "\"caster_{side}_1_joint\": an unexpanded {side} placeholder, "
                                    "so Gazebo drops the wheel and caster settings",
    },
    "example-robot-data/robots/tiago_pro_description/robots/tiago_pro.urdf": {
        "schema.sdf-element": "SDF <kinematic>, <gravity> and <surface> inside URDF links: ignored",
        "schema.unknown-element": "ros2_control transmission joints with <mechanicalReduction>; "
                                  "ros2_control reads <mechanical_reduction>",
    },
    # -- structure -------------------------------------------------------------------------------
    "pybullet_data/torus_deform.urdf": {
        "structure.no-links": "a PyBullet <deformable> only, no <link>: not a URDF robot "
                              "(check_urdf: \"No link elements found\")",
    },
    "example-robot-data/robots/ur_description/urdf/ur3.urdf": {
        "structure.no-name": "an empty xacro output: <robot> without name",
        "structure.no-links": "an empty xacro output: no links at all",
    },
    # -- geometry --------------------------------------------------------------------------------
    **{f"pybullet_data/laikago/{name}.urdf": {
        "geometry.nonpositive-size": "toe visuals are spheres of radius 0 (draw nothing; URDF "
                                     "1.2 parsers reject them)",
    } for name in ("laikago_toes", "laikago_toes_limits", "laikago_toes_zup",
                   "laikago_toes_zup_lores")},
    # -- joint, mimic, material, gazebo, transmission ---------------------------------------------
    "pybullet_data/cube_no_rotation.urdf": {
        "joint.lower-above-upper": "prismatic lower=\"1\" upper=\"-1\": Bullet's idiom for 'no "
                                   "limit'; every URDF consumer sees an empty range",
    },
    **{f"pybullet_data/quadruped/{name}.urdf": {
        "joint.frozen-range": "knee joints are revolute with <limit> but no lower/upper: URDF "
                              "reads [0, 0] (Pinocchio, MoveIt: frozen); only PyBullet reads "
                              "'no limit'",
    } for name in ("minitaur", "quadruped")},
    "example-robot-data/robots/quadruped_description/urdf/quadruped.urdf": {
        "joint.frozen-range": "the KFE joints have <limit> without lower/upper: Pinocchio loads "
                              "them with bounds [0, 0]",
    },
    "example-robot-data/robots/centauro_description/urdf/centauro.urdf": {
        "joint.frozen-range": "wheel joints are revolute without lower/upper (commented "
                              "'actually continuous'): URDF reads [0, 0]",
    },
    **{f"example-robot-data/robots/double_pendulum_description/urdf/{name}.urdf": {
        "joint.frozen-range": "revolute joints with lower=upper=0 (exporter defaults): the "
                              "pendulum cannot swing in Pinocchio or MoveIt",
    } for name in ("double_pendulum", "double_pendulum_simple")},
    "pybullet_data/r2d2.urdf": {
        "joint.continuous-with-limits": "head_swivel is continuous with limits [-0.38, 0], which "
                                        "every consumer ignores",
    },
    "example-robot-data/robots/alex_description/urdf/alex_psyonic_hands.urdf": {
        "mimic.unknown-joint": "finger q2 joints mimic 'index_q1', 'middle_q1', ... while the "
                               "joints are named 'Left_index_q1', ...: no such joints",
    },
    "example-robot-data/robots/pr2_description/urdf/pr2.urdf": {
        "mimic.out-of-range": "the r_parallel_root joints mimic the l_finger joints ([0, 0.548]) "
                              "with multiplier -1, so they are driven to [-0.548, 0] while "
                              "their limits are [0, 0.548]",
        "gazebo.unknown-reference": "<gazebo reference> to double_stereo_double_stereo_link and "
                                    "sensor_mount_sensor_link, links this model does not have",
    },
    "example-robot-data/robots/talos_data/robots/talos_left_arm.urdf": {
        "transmission.unknown-joint": "a transmission for arm_left_1_joint, which this reduced "
                                      "model does not have",
        "gazebo.unknown-reference": "<gazebo reference=\"arm_left_1_joint\">: no such joint",
    },
    **{f"pybullet_data/{name}.urdf": {
        "material.undefined": f"visuals use material '{material}', defined nowhere: they get "
                              "the default colour",
    } for name, material in (("differential/diff_ring", "DarkGrey"),
                             ("mini_cheetah/mini_cheetah", "darkgray"), ("pendulum5", "Red"),
                             ("table/table", "framemat0"))},
    "example-robot-data/robots/talos_data/robots/talos_reduced_corrected.urdf": {
        "material.undefined": "the ft tool links use material 'FlatBlack', defined nowhere",
    },
    **{f"example-robot-data/robots/{name}.urdf": {
        "material.redefined": f"an inline '{material}' with another colour than the first "
                              "definition: urdfdom keeps the first, the written colour is ignored",
    } for name, material in (
        ("anymal_b_simple_description/robots/anymal-kinova", "carbon_fiber"),
        ("kinova_description/robots/kinova", "carbon_fiber"),
        ("hyq_description/robots/hyq_no_sensors", "black"),
        ("talos_data/robots/talos_full_v2", "DarkGrey"),
        ("talos_data/robots/talos_full_v2_box", "DarkGrey"))},
}


# -- xml -----------------------------------------------------------------------------------------
# Not well-formed XML, read by every robot tool anyway: one warning each, the rest is checked.
_XML_VERSION_ZERO = (
    "pybullet_data/bicycle/bike.urdf",
    "pybullet_data/cube_small.urdf",
    "pybullet_data/duck_vhacd.urdf",
    "pybullet_data/gripper/wsg50_one_motor_gripper_left_finger.urdf",
    "pybullet_data/gripper/wsg50_one_motor_gripper_right_finger.urdf",
    "pybullet_data/jenga/jenga.urdf",
    "pybullet_data/lego/lego.urdf",
    "pybullet_data/plane.urdf",
    "pybullet_data/plane100.urdf",
    "pybullet_data/quadruped/minitaur.urdf",
    "pybullet_data/quadruped/minitaur_derpy.urdf",
    "pybullet_data/quadruped/minitaur_fixed_all.urdf",
    "pybullet_data/quadruped/minitaur_fixed_knees.urdf",
    "pybullet_data/quadruped/minitaur_single_motor.urdf",
    "pybullet_data/quadruped/minitaur_v1.urdf",
    "pybullet_data/quadruped/quadruped.urdf",
    "pybullet_data/samurai.urdf",
    "pybullet_data/sphere2.urdf",
    "pybullet_data/sphere2red.urdf",
    "pybullet_data/sphere2red_nocol.urdf",
    "pybullet_data/sphere8cube.urdf",
    "pybullet_data/sphere_small.urdf",
    "pybullet_data/sphere_with_restitution.urdf",
    "pybullet_data/table/table.urdf",
    "pybullet_data/table_square/table_square.urdf",
    "pybullet_data/teddy_vhacd.urdf",
)
for _name in _XML_VERSION_ZERO:
    KNOWN_DEFECTS.setdefault(_name, {})["xml.declaration"] = (
        '<?xml version="0.0"?>: only XML 1.0 exists, strict parsers (lxml, expat, so xacro) reject it')
KNOWN_DEFECTS["pybullet_data/biped/biped2d_pybullet.urdf"]["xml.declaration"] = (
    "three blank lines before <?xml ...?>: strict parsers reject a declaration that is not first")
KNOWN_DEFECTS.setdefault("pybullet_data/differential/diff_ring.urdf", {})["xml.declaration"] = (
    "a blank line before <?xml ...?>: strict parsers reject a declaration that is not first")
# issue 22.3: its visual meshes are named 'differential/X.stl' from inside differential/ (not
# found), which hid the bound its collisions allow; measured with trimesh, the visuals are the
# collisions' size (ring r 0.053 m, gears r 0.016 m): 2.637 kg with the same 0.0247/0.0441 kg·m²
# copied onto every gear is 4.9x (ring) to 41.6x (gears) what those bodies can have
KNOWN_DEFECTS["pybullet_data/differential/diff_ring.urdf"]["inertia.exceeds-geometry"] = (
    "every gear declares the ring's 2.637 kg and 0.0247/0.0441 kg·m²: 4.9-41.6x m r² of its "
    "collision, and its visual meshes are no larger")
KNOWN_DEFECTS["pybullet_data/humanoid/humanoid.urdf"]["xml.bad-character"] = (
    "a NUL byte after </robot>: strict parsers reject it, C-based tools stop reading there")

# -- geometry.no-collision (issue 14): dynamics models without any <collision>; `sim` drops them
# through the floor (sim.sink), so `check` says so too ----------------------------------------
for _name in ("alexander_description/urdf/alexander_v1.lowerBodyOnly.urdf",
              "asr_twodof_description/urdf/TwoDofs.urdf", "human_description/robots/human.urdf",
              "simple_humanoid_description/urdf/simple_humanoid_classical.urdf"):
    KNOWN_DEFECTS.setdefault(f"example-robot-data/robots/{_name}", {})["geometry.no-collision"] = (
        "no <collision> on any link: in a simulator it falls through the floor")

# -- inertia, mesh: listed with their reasons in tests/test_inertia_corpus.py --------------------
for _name, _rules in INERTIA_KNOWN_DEFECTS.items():
    KNOWN_DEFECTS.setdefault(_name, {}).update(_rules)


def _corpus() -> list[tuple[str, object]]:
    files = []
    pybullet = pybullet_data_dir()
    for path in pybullet_urdfs():
        files.append(("pybullet_data/" + path.relative_to(pybullet).as_posix(), path))
    robots = example_robot_data_dir()
    for path in example_robot_urdfs():
        files.append(("example-robot-data/" + path.relative_to(robots).as_posix(), path))
    return files


CORPUS = _corpus()
# The URDFs write package://example-robot-data/robots/...: the package is the share folder.
OPTIONS = CheckOptions(load=LoadOptions(packages={"example-robot-data":
                                                  str(example_robot_data_dir())}))


def test_corpus_is_there():
    names = {name for name, _ in CORPUS}
    assert len(names) > 150
    assert "pybullet_data/r2d2.urdf" in names
    assert "example-robot-data/robots/panda_description/urdf/panda.urdf" in names
    assert set(KNOWN_DEFECTS) <= names, set(KNOWN_DEFECTS) - names


@pytest.mark.parametrize("name, path", CORPUS, ids=[name for name, _ in CORPUS])
def test_no_errors_or_warnings_beyond_known_defects(name, path):
    report = check_file(path, OPTIONS)
    known = KNOWN_DEFECTS.get(name, {})
    unexpected = [d for d in report.diagnostics
                  if d.severity in ("error", "warning") and d.rule not in known]
    assert not unexpected, "\n".join(
        f"{d.path}:{d.line}: {d.severity} {d.rule} {d.message}" for d in unexpected[:20])
    fired = {d.rule for d in report.diagnostics if d.severity in ("error", "warning")}
    stale = set(known) - fired
    assert not stale, f"KNOWN_DEFECTS lists {sorted(stale)} for {name}, which no longer fire"
