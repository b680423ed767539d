"""Good robots stay quiet: every URDF shipped by pybullet_data and example-robot-data gives no
error and no warning from any rule family, except the genuine defects waived below, one waiver
per finding (rule, line, message fragment) under the reason it is wrong (tests/waivers.py).

A finding no waiver names fails the test, even of a rule already waived in that file (a false
alarm, or a new genuine defect: then add it under the reason it is wrong). A waiver that names
no finding fails too (stale: the defect is gone, or the rule lost the case). Infos are advice
and not checked.
"""

from __future__ import annotations

import functools

import pytest

from tests.conftest import (
    example_robot_data_dir,
    example_robot_urdfs,
    pybullet_data_dir,
    pybullet_urdfs,
)
from tests.test_inertia_corpus import INERTIA_KNOWN_DEFECTS
from tests.waivers import Entry, Waiver, by_file, in_each, problems
from urdftool.check import CheckOptions, check_file
from urdftool.source import LoadOptions

# (rule, why it is genuinely wrong, {file (as "pybullet_data/..." or "example-robot-data/..."):
# [(line, message fragment), ...]}). Extend it when a rule finds a real defect in these corpora;
# never to hide a false alarm. The inertia and mesh rules' defects are in
# tests/test_inertia_corpus.py.
KNOWN_DEFECTS: list[Entry] = [
    # -- schema ------------------------------------------------------------------------------------
    ("schema.bad-vector",
     ('two joint origins are written with commas (xyz="0.07, 0, -0.69"): check_urdf rejects the '
      "robot"),
     {"pybullet_data/bicycle/bike.urdf": [
          (103, "xyz='0.07, 0, -0.69'"),
          (136, "xyz='-0.69, 0, -0.42'")]}),
    ("schema.bad-number",
     'joint limits lower="-1.57." (two decimal points): check_urdf rejects the robot',
     {"pybullet_data/biped/biped2d_pybullet.urdf": [
          (115, "lower='-1.57.'"),
          (146, "lower='-1.57.'"),
          (177, "lower='-1.57.'"),
          (208, "lower='-1.57.'")]}),
    ("schema.bad-value",
     "joints of type 'spherical', a PyBullet extension: check_urdf rejects the robot",
     {"pybullet_data/humanoid/humanoid.urdf": [
          (40, "type='spherical'"),
          (58, "type='spherical'"),
          (76, "type='spherical'"),
          (114, "type='spherical'"),
          (132, "type='spherical'"),
          (188, "type='spherical'"),
          (226, "type='spherical'"),
          (244, "type='spherical'")]}),
    ("schema.needs-version",
     'capsule collisions in a robot without version="1.1": urdfdom drops them',
     {"pybullet_data/humanoid/humanoid.urdf": [
          (72, "<capsule>"),
          (90, "<capsule>"),
          (128, "<capsule>"),
          (146, "<capsule>"),
          (184, "<capsule>"),
          (202, "<capsule>"),
          (240, "<capsule>"),
          (258, "<capsule>")]}),
    ("schema.bad-value",
     "a joint of type 'spherical' (PyBullet only): check_urdf rejects it",
     {"pybullet_data/spherical_joint_limit.urdf": [(28, "type='spherical'")]}),
    ("schema.missing-attribute",
     "<limit> without velocity: check_urdf rejects the joint",
     {"pybullet_data/spherical_joint_limit.urdf": [(30, "no 'velocity'")]}),
    ("schema.bad-vector",
     ('the IMU joint origin is xyz="$(optenv HUSKY_IMU_XYZ 0.19 0 0.149)" and rpy="$(optenv '
      'HUSKY_IMU_RPY 0 -1.5708 3.1416)": xacro substitutions left in a .urdf; check_urdf rejects '
      "the robot"),
     {"pybullet_data/husky/husky.urdf": [
          (97, "rpy='$(optenv HUSKY_IMU_RPY 0 -1.5708 3.1416)'"),
          (97, "xyz='$(optenv HUSKY_IMU_XYZ 0.19 0 0.149)'")]}),
    ("schema.bad-vector",
     'origins with four rpy numbers (rpy="-3.14159 1.57079 0 0"): check_urdf rejects the robot',
     {"pybullet_data/quadruped/microtaur/microtaur.urdf": [
          (300, "rpy='-3.14159 1.57079 0 0'"),
          (336, "rpy='0 1.57079 0 0'"),
          (372, "rpy='0 -1.57079 0 0'"),
          (409, "rpy='-3.14159 -1.57079 0 0'"),
          (552, "rpy='-1.57079 0 -1.57079 0'"),
          (717, "rpy='1.57079 0 -1.57079 0'"),
          (885, "rpy='1.57079 0 -1.57079 0'"),
          (1050, "rpy='-1.57079 0 -1.57079 0'")]}),
    ("schema.bad-vector",
     'mesh scale="1 1 1 1" (four numbers): urdfdom drops the visuals',
     {"pybullet_data/racecar/racecar_differential.urdf": [
          (16, "scale='1 1 1 1'"),
          (23, "scale='1 1 1 1'")]}),
    ("schema.misplaced-element",
     "a <material> inside <geometry> instead of <visual>: the colour is ignored",
     {"pybullet_data/racecar/racecar_differential.urdf": [(268, "<material>")],
      "pybullet_data/racecar/racecar.urdf": [(284, "<material>")]}),
    ("schema.duplicate-element",
     "a joint with two <axis> elements: the second is ignored",
     {"pybullet_data/quadruped/spirit40newer.urdf": [(550, "<axis>")]}),
    ("schema.bad-number",
     ("<mechanicalReduction>reduction</mechanicalReduction>: a leftover xacro parameter name, not "
      "a number (ros_control cannot load it)"),
     {"pybullet_data/xarm/xarm6_robot.urdf": [
          (252, "<mechanicalReduction>"),
          (262, "<mechanicalReduction>"),
          (272, "<mechanicalReduction>"),
          (282, "<mechanicalReduction>"),
          (292, "<mechanicalReduction>")]}),
    ("schema.bad-number",
     "<mechanicalReduction>reduction</mechanicalReduction>: not a number",
     {"pybullet_data/xarm/xarm6_robot_white.urdf": [
          (252, "<mechanicalReduction>"),
          (262, "<mechanicalReduction>"),
          (272, "<mechanicalReduction>"),
          (282, "<mechanicalReduction>"),
          (292, "<mechanicalReduction>")],
      "pybullet_data/xarm/xarm6_with_gripper.urdf": [
          (245, "<mechanicalReduction>"),
          (255, "<mechanicalReduction>"),
          (265, "<mechanicalReduction>"),
          (275, "<mechanicalReduction>"),
          (285, "<mechanicalReduction>")]}),
    ("schema.misplaced-element",
     "an <origin> directly in a <link> (links have no pose): ignored by every parser",
     {"example-robot-data/robots/so_arm_description/urdf/so101.urdf": [(294, "<origin>")]}),
    ("schema.sdf-element",
     "SDF <kinematic> and <gravity> inside URDF links: ignored",
     {"example-robot-data/robots/tiago_description/robots/tiago_dual.urdf": [
          (301, "<kinematic>"),
          (302, "<gravity>"),
          (376, "<kinematic>"),
          (377, "<gravity>")]}),
    ("schema.sdf-element",
     "SDF <kinematic>, <gravity> and <surface> inside URDF links: ignored",
     {"example-robot-data/robots/tiago_pro_description/robots/tiago_pro.urdf": [
          (448, "<kinematic>"),
          (449, "<gravity>"),
          (477, "<surface>"),
          (537, "<kinematic>"),
          (538, "<gravity>"),
          (566, "<surface>"),
          (626, "<kinematic>"),
          (627, "<gravity>"),
          (655, "<surface>"),
          (715, "<kinematic>"),
          (716, "<gravity>"),
          (744, "<surface>")]}),
    ("schema.unknown-element",
     ("ros2_control transmission joints with <mechanicalReduction>; ros2_control reads "
      "<mechanical_reduction>"),
     {"example-robot-data/robots/tiago_pro_description/robots/tiago_pro.urdf": [
          (2447, "<mechanicalReduction>"),
          (2461, "<mechanicalReduction>")]}),
    # -- structure ---------------------------------------------------------------------------------
    ("structure.no-links",
     ('a PyBullet <deformable> only, no <link>: not a URDF robot (check_urdf: "No link elements '
      'found")'),
     {"pybullet_data/torus_deform.urdf": [(2, "no <link>")]}),
    ("structure.no-name",
     "an empty xacro output: <robot> without name",
     {"example-robot-data/robots/ur_description/urdf/ur3.urdf": [(6, "no name")]}),
    ("structure.no-links",
     "an empty xacro output: no links at all",
     {"example-robot-data/robots/ur_description/urdf/ur3.urdf": [(6, "no <link>")]}),
    # -- geometry ----------------------------------------------------------------------------------
    ("geometry.nonpositive-size",
     "toe visuals are spheres of radius 0 (draw nothing; URDF 1.2 parsers reject them)",
     {**in_each(("pybullet_data/laikago/laikago_toes.urdf",
                 "pybullet_data/laikago/laikago_toes_limits.urdf"), [
          (475, "'toeRL'"),
          (508, "'toeRR'"),
          (541, "'toeFL'"),
          (574, "'toeFR'")]),
      **in_each(("pybullet_data/laikago/laikago_toes_zup.urdf",
                 "pybullet_data/laikago/laikago_toes_zup_lores.urdf"), [
          (477, "'toeRL'"),
          (510, "'toeRR'"),
          (543, "'toeFL'"),
          (576, "'toeFR'")])}),
    # issue 14: dynamics models without any <collision>; `sim` drops them through the floor
    # (sim.sink), so `check` says so too
    ("geometry.no-collision",
     "no <collision> on any link: in a simulator it falls through the floor",
     {"example-robot-data/robots/alexander_description/urdf/alexander_v1.lowerBodyOnly.urdf": [
          (2, "'Alexander'")],
      "example-robot-data/robots/asr_twodof_description/urdf/TwoDofs.urdf": [(2, "'twodofs'")],
      "example-robot-data/robots/human_description/robots/human.urdf": [
          (1, "'human_36dof_ISB_model'")],
      "example-robot-data/robots/simple_humanoid_description/urdf/simple_humanoid_classical.urdf": [
          (7, "'simple_humanoid_classical'")]}),
    # -- joint -------------------------------------------------------------------------------------
    ("joint.lower-above-upper",
     ("prismatic lower=\"1\" upper=\"-1\": Bullet's idiom for 'no limit'; every URDF consumer "
      "sees an empty range"),
     {"pybullet_data/biped/biped2d_pybullet.urdf": [
          (39, "'y_to_world'"),
          (55, "'z_to_y'")],
      "pybullet_data/cube_no_rotation.urdf": [
          (17, "'x_to_world'"),
          (33, "'y_to_x'"),
          (49, "'z_to_y'")]}),
    ("joint.continuous-with-limits",
     ("right_steering_hinge_joint is continuous with limits [-1, 1] (its left twin is revolute): "
      "limits ignored"),
     {"pybullet_data/racecar/racecar_differential.urdf": [(151, "'right_steering_hinge_joint'")]}),
    ("joint.continuous-with-limits",
     ("right_steering_hinge_joint is continuous with limits [-1, 1] (its left twin is revolute): "
      "the limits are ignored, the wheel can steer round"),
     {"pybullet_data/racecar/racecar.urdf": [(179, "'right_steering_hinge_joint'")]}),
    ("joint.frozen-range",
     ("knee joints are revolute with <limit> but no lower/upper: URDF reads [0, 0] (Pinocchio, "
      "MoveIt: frozen); only PyBullet reads 'no limit'"),
     {"pybullet_data/quadruped/minitaur.urdf": [
          (460, "'knee_front_rightR_link'"),
          (528, "'knee_front_rightL_link'"),
          (594, "'knee_front_leftR_link'"),
          (661, "'knee_front_leftL_link'"),
          (725, "'knee_back_rightR_link'"),
          (793, "'knee_back_rightL_link'"),
          (859, "'knee_back_leftR_link'"),
          (924, "'knee_back_leftL_link'")],
      "pybullet_data/quadruped/quadruped.urdf": [
          (322, "'knee_back_leftR_link'"),
          (352, "'knee_back_leftL_link'"),
          (438, "'knee_front_leftR_link'"),
          (468, "'knee_front_leftL_link'"),
          (557, "'knee_back_rightR_link'"),
          (587, "'knee_back_rightL_link'"),
          (673, "'knee_front_rightR_link'"),
          (703, "'knee_front_rightL_link'")]}),
    ("joint.frozen-range",
     "the KFE joints have <limit> without lower/upper: Pinocchio loads them with bounds [0, 0]",
     {"example-robot-data/robots/quadruped_description/urdf/quadruped.urdf": [
          (65, "'FL_KFE'"),
          (162, "'FR_KFE'"),
          (259, "'BL_KFE'"),
          (356, "'BR_KFE'")]}),
    ("joint.frozen-range",
     ("wheel joints are revolute without lower/upper (commented 'actually continuous'): URDF "
      "reads [0, 0]"),
     {"example-robot-data/robots/centauro_description/urdf/centauro.urdf": [
          (828, "'j_wheel_1'"),
          (1016, "'j_wheel_2'"),
          (1204, "'j_wheel_3'"),
          (1392, "'j_wheel_4'")]}),
    ("joint.frozen-range",
     ("revolute joints with lower=upper=0 (exporter defaults): the pendulum cannot swing in "
      "Pinocchio or MoveIt"),
     {"example-robot-data/robots/double_pendulum_description/urdf/double_pendulum.urdf": [
          (99, "'joint1'"),
          (159, "'joint2'")],
      "example-robot-data/robots/double_pendulum_description/urdf/double_pendulum_simple.urdf": [
          (94, "'joint1'"),
          (152, "'joint2'")]}),
    ("joint.continuous-with-limits",
     "head_swivel is continuous with limits [-0.38, 0], which every consumer ignores",
     {"pybullet_data/r2d2.urdf": [(391, "'head_swivel'")]}),
    # -- mimic -------------------------------------------------------------------------------------
    ("mimic.unknown-joint",
     ("finger q2 joints mimic 'index_q1', 'middle_q1', ... while the joints are named "
      "'Left_index_q1', ...: no such joints"),
     {"example-robot-data/robots/alex_description/urdf/alex_psyonic_hands.urdf": [
          (1037, "'Left_index_q2'"),
          (1103, "'Left_middle_q2'"),
          (1170, "'Left_ring_q2'"),
          (1235, "'Left_pinky_q2'"),
          (1413, "'Right_index_q2'"),
          (1478, "'Right_middle_q2'"),
          (1541, "'Right_ring_q2'"),
          (1606, "'Right_pinky_q2'")]}),
    ("mimic.out-of-range",
     ("the r_parallel_root joints mimic the l_finger joints ([0, 0.548]) with multiplier -1, so "
      "they are driven to [-0.548, 0] while their limits are [0, 0.548]"),
     {"example-robot-data/robots/pr2_description/urdf/pr2.urdf": [
          (1848, "'r_gripper_r_parallel_root_joint'"),
          (2712, "'l_gripper_r_parallel_root_joint'")]}),
    # -- material ----------------------------------------------------------------------------------
    ("material.undefined",
     "visuals use material 'darkgray', defined nowhere: default colour",
     {"pybullet_data/quadruped/spirit40newer.urdf": [
          (408, "'RR_lower'"),
          (560, "'RL_lower'")]}),
    ("material.undefined",
     "visuals use material 'DarkGrey', defined nowhere: they get the default colour",
     {"pybullet_data/differential/diff_ring.urdf": [
          (26, "'diff_ring'"),
          (33, "'diff_ring'"),
          (66, "'diff_spiderA'"),
          (105, "'diff_spiderB'"),
          (145, "'diff_sideA'"),
          (181, "'diff_sideB'")]}),
    ("material.undefined",
     "visuals use material 'darkgray', defined nowhere: they get the default colour",
     {"pybullet_data/mini_cheetah/mini_cheetah.urdf": [
          (116, "'toe_fr'"),
          (230, "'toe_fl'"),
          (344, "'toe_hr'"),
          (458, "'toe_hl'")]}),
    ("material.undefined",
     "visuals use material 'Red', defined nowhere: they get the default colour",
     {"pybullet_data/pendulum5.urdf": [
          (45, "'link1'"),
          (72, "'link2'"),
          (99, "'link3'"),
          (126, "'link4'")]}),
    ("material.undefined",
     "visuals use material 'framemat0', defined nowhere: they get the default colour",
     {"pybullet_data/table/table.urdf": [
          (32, "'baseLink'"),
          (39, "'baseLink'"),
          (46, "'baseLink'")]}),
    ("material.undefined",
     "the ft tool links use material 'FlatBlack', defined nowhere",
     {"example-robot-data/robots/talos_data/robots/talos_reduced_corrected.urdf": [
          (1233, "'wrist_right_ft_tool_link'"),
          (1287, "'wrist_left_ft_tool_link'")]}),
    ("material.redefined",
     ("an inline 'carbon_fiber' with another colour than the first definition: urdfdom keeps the "
      "first, the written colour is ignored"),
     {"example-robot-data/robots/anymal_b_simple_description/robots/anymal-kinova.urdf": [
          (1236, "'carbon_fiber'"),
          (1273, "'carbon_fiber'"),
          (1310, "'carbon_fiber'"),
          (1347, "'carbon_fiber'")],
      "example-robot-data/robots/kinova_description/robots/kinova.urdf": [
          (353, "'carbon_fiber'"),
          (390, "'carbon_fiber'"),
          (427, "'carbon_fiber'"),
          (464, "'carbon_fiber'")]}),
    ("material.redefined",
     ("an inline 'black' with another colour than the first definition: urdfdom keeps the first, "
      "the written colour is ignored"),
     {"example-robot-data/robots/hyq_description/robots/hyq_no_sensors.urdf": [(994, "'black'")]}),
    ("material.redefined",
     ("an inline 'DarkGrey' with another colour than the first definition: urdfdom keeps the "
      "first, the written colour is ignored"),
     {**in_each(("example-robot-data/robots/talos_data/robots/talos_full_v2.urdf",
                 "example-robot-data/robots/talos_data/robots/talos_full_v2_box.urdf"), [
          (278, "'DarkGrey'")])}),
    # -- gazebo ------------------------------------------------------------------------------------
    ("gazebo.unknown-reference",
     ('<gazebo reference="wheel_{side}_joint">, "caster_{side}_1_joint" and '
      '"caster_{side}_2_joint": an unexpanded {side} placeholder, so Gazebo drops the wheel and '
      "caster settings"),
     {"example-robot-data/robots/tiago_description/robots/tiago_dual.urdf": [
          (346, 'reference="wheel_{side}_joint"'),
          (421, 'reference="wheel_{side}_joint"'),
          (492, 'reference="caster_{side}_1_joint"'),
          (495, 'reference="caster_{side}_2_joint"'),
          (572, 'reference="caster_{side}_1_joint"'),
          (575, 'reference="caster_{side}_2_joint"'),
          (646, 'reference="caster_{side}_1_joint"'),
          (649, 'reference="caster_{side}_2_joint"'),
          (720, 'reference="caster_{side}_1_joint"'),
          (723, 'reference="caster_{side}_2_joint"')]}),
    ("gazebo.unknown-reference",
     ("<gazebo reference> to double_stereo_double_stereo_link and sensor_mount_sensor_link, links "
      "this model does not have"),
     {"example-robot-data/robots/pr2_description/urdf/pr2.urdf": [
          (1188, 'reference="double_stereo_double_stereo_link"'),
          (1191, 'reference="sensor_mount_sensor_link"')]}),
    ("gazebo.unknown-reference",
     '<gazebo reference="arm_left_1_joint">: no such joint',
     {"example-robot-data/robots/talos_data/robots/talos_left_arm.urdf": [
          (163, 'reference="arm_left_1_joint"')]}),
    # -- transmission ------------------------------------------------------------------------------
    ("transmission.unknown-joint",
     "a transmission for arm_left_1_joint, which this reduced model does not have",
     {"example-robot-data/robots/talos_data/robots/talos_left_arm.urdf": [
          (353, "'arm_left_1_trans'")]}),
    # -- xml ---------------------------------------------------------------------------------------
    # Not well-formed XML, read by every robot tool anyway: one warning each, the rest is checked.
    ("xml.declaration",
     ('<?xml version="0.0"?>: only XML 1.0 exists, strict parsers (lxml, expat, so xacro) reject '
      "it"),
     {**in_each(("pybullet_data/bicycle/bike.urdf",
                 "pybullet_data/quadruped/minitaur.urdf",
                 "pybullet_data/quadruped/quadruped.urdf",
                 "pybullet_data/table/table.urdf",
                 "pybullet_data/cube_small.urdf",
                 "pybullet_data/duck_vhacd.urdf",
                 "pybullet_data/gripper/wsg50_one_motor_gripper_left_finger.urdf",
                 "pybullet_data/gripper/wsg50_one_motor_gripper_right_finger.urdf",
                 "pybullet_data/jenga/jenga.urdf",
                 "pybullet_data/lego/lego.urdf",
                 "pybullet_data/plane.urdf",
                 "pybullet_data/plane100.urdf",
                 "pybullet_data/quadruped/minitaur_derpy.urdf",
                 "pybullet_data/quadruped/minitaur_fixed_all.urdf",
                 "pybullet_data/quadruped/minitaur_fixed_knees.urdf",
                 "pybullet_data/quadruped/minitaur_single_motor.urdf",
                 "pybullet_data/quadruped/minitaur_v1.urdf",
                 "pybullet_data/samurai.urdf",
                 "pybullet_data/sphere2.urdf",
                 "pybullet_data/sphere2red.urdf",
                 "pybullet_data/sphere2red_nocol.urdf",
                 "pybullet_data/sphere8cube.urdf",
                 "pybullet_data/sphere_small.urdf",
                 "pybullet_data/sphere_with_restitution.urdf",
                 "pybullet_data/table_square/table_square.urdf",
                 "pybullet_data/teddy_vhacd.urdf"), [
          (1, 'version "0.0"')])}),
    ("xml.declaration",
     ("three blank lines before <?xml ...?>: strict parsers reject a declaration that is not "
      "first"),
     {"pybullet_data/biped/biped2d_pybullet.urdf": [(4, "3 blank line")]}),
    ("xml.bad-character",
     "a NUL byte after </robot>: strict parsers reject it, C-based tools stop reading there",
     {"pybullet_data/humanoid/humanoid.urdf": [(288, "NUL byte")]}),
    ("xml.declaration",
     "a blank line before <?xml ...?>: strict parsers reject a declaration that is not first",
     {"pybullet_data/differential/diff_ring.urdf": [(2, "1 blank line")]}),
    # -- inertia -----------------------------------------------------------------------------------
    # issue 22.3: the differential's visual meshes are not found ('differential/X.stl' from
    # racecar/); its collisions bound it: the 2.637 kg differential's 0.0247 kg·m² kept on
    # 56-64 g gears, 620-1960x m r² (the visuals, measured with trimesh, are no larger)
    ("inertia.exceeds-geometry",
     ("diff_ring/spider/side gears (and their diff2_ twins) of 56-64 g declare 0.0247 kg·m²: "
      "620-1960x what their size allows"),
     {"pybullet_data/racecar/racecar_differential.urdf": [
          (347, "'diff_ring'"),
          (387, "'diff_spiderA'"),
          (426, "'diff_spiderB'"),
          (466, "'diff_sideA'"),
          (502, "'diff_sideB'"),
          (538, "'diff2_ring'"),
          (578, "'diff2_spiderA'"),
          (617, "'diff2_spiderB'"),
          (655, "'diff2_sideA'"),
          (691, "'diff2_sideB'")]}),
    # issue 22.3: its visual meshes are named 'differential/X.stl' from inside differential/ (not
    # found), which hid the bound its collisions allow; measured with trimesh, the visuals are the
    # collisions' size (ring r 0.053 m, gears r 0.016 m): 2.637 kg with the same 0.0247/0.0441 kg·m²
    # copied onto every gear is 4.9x (ring) to 41.6x (gears) what those bodies can have
    ("inertia.exceeds-geometry",
     ("the ring and every gear declare the ring's 2.637 kg and 0.0247/0.0441 kg·m²: 4.9x (ring) "
      "to 41.6x (gears) m r² of their collisions, and their visual meshes are no larger"),
     {"pybullet_data/differential/diff_ring.urdf": [
          (19, "'diff_ring'"),
          (59, "'diff_spiderA'"),
          (98, "'diff_spiderB'"),
          (138, "'diff_sideA'"),
          (174, "'diff_sideB'")]}),
]
WAIVERS = by_file(KNOWN_DEFECTS + INERTIA_KNOWN_DEFECTS)


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


@functools.cache
def _findings(name: str) -> tuple:
    """The errors and warnings of one corpus file, checked once per test process."""
    report = check_file(dict(CORPUS)[name], OPTIONS)
    return tuple(d for d in report.diagnostics if d.severity in ("error", "warning"))


def test_corpus_is_there():
    names = {name for name, _ in CORPUS}
    assert len(names) > 150
    assert "pybullet_data/r2d2.urdf" in names
    assert "example-robot-data/robots/panda_description/urdf/panda.urdf" in names
    assert set(WAIVERS) <= names, set(WAIVERS) - names


def test_waivers_are_well_formed():
    for rule_id, reason, files in KNOWN_DEFECTS + INERTIA_KNOWN_DEFECTS:
        assert "." in rule_id and len(reason) > 20 and files, (rule_id, reason)
    for name, waivers in WAIVERS.items():
        for waiver in waivers:
            assert waiver.line is None or (isinstance(waiver.line, int) and waiver.line > 0), \
                (name, waiver)
            assert waiver.fragment.strip() and waiver.count >= 1, (name, waiver)
        keys = [(w.rule, w.line, w.fragment) for w in waivers]
        assert len(keys) == len(set(keys)), f"{name}: a waiver written twice"


@pytest.mark.parametrize("name, path", CORPUS, ids=[name for name, _ in CORPUS])
def test_no_errors_or_warnings_beyond_known_defects(name, path):
    found = problems(_findings(name), WAIVERS.get(name, []))
    assert not found, f"{name}:\n" + "\n".join(found[:20])


def test_a_new_finding_of_a_waived_rule_fails_and_a_gone_one_is_stale():
    # a real file with three waived joint.lower-above-upper findings (and an inertia one)
    name = "pybullet_data/cube_no_rotation.urdf"
    findings = list(_findings(name))
    waivers = WAIVERS[name]
    assert not problems(findings, waivers)
    [joint] = [d for d in findings if "'y_to_x'" in d.message]
    assert joint.rule == "joint.lower-above-upper"
    # (a) one more finding of that rule in that file, for another joint: waiving per (file,
    # rule) let it pass; named per finding, it fails
    new = joint._replace(line=joint.line + 5, message=joint.message.replace("'y_to_x'", "'w_to_x'"))
    assert {w.rule for w in waivers} >= {new.rule}
    [problem] = problems(findings + [new], waivers)
    assert "no waiver names this finding" in problem and "'w_to_x'" in problem
    # ... on the very line of a waived finding too (the fragment tells them apart)
    same_line = new._replace(line=joint.line)
    [problem] = problems(findings + [same_line], waivers)
    assert "no waiver names this finding" in problem
    # (b) a finding gone: its waiver is stale
    [problem] = problems([d for d in findings if d is not joint], waivers)
    assert "'y_to_x'" in problem and "(stale)" in problem
    # (c) a waiver names one finding; two identical ones need a count
    [problem] = problems(findings + [joint], waivers)
    assert "names 1 finding(s) but matches 2" in problem
    counted = [w._replace(count=2) if w.fragment == "'y_to_x'" else w for w in waivers]
    assert not problems(findings + [joint], counted)
    # a fragment two waivers share picks no single finding
    loose = waivers + [Waiver(joint.rule, joint.line, "_to_", 1, "too loose a fragment")]
    assert any("named by 2 waivers" in p for p in problems(findings, loose))
