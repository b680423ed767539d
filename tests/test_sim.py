"""`urdftool sim` on small models built to fail one way each, and the command line around it.

Every broken model runs in one `simulate()` call (two worker processes); the numbers checked are
closed-form values computed here (gravity torque m·g·d, box overlap depth), not urdftool's own.
"""

from __future__ import annotations

import json
import math
import os

import pybullet  # noqa: F401 - the test extra has it: missing, this fails
import pytest

from tests.conftest import run_urdftool
from urdftool.sim import CHECKS, SimOptions
from urdftool.sim.runner import simulate

RED = '<material name="red"><color rgba="1 0 0 1"/></material>'


def box_inertial(mass, x, y, z, xyz="0 0 0", scale=1.0):
    ixx, iyy, izz = (mass / 12 * (y * y + z * z) * scale, mass / 12 * (x * x + z * z) * scale,
                     mass / 12 * (x * x + y * y) * scale)
    return (f'<inertial><origin xyz="{xyz}"/><mass value="{mass}"/>'
            f'<inertia ixx="{ixx}" iyy="{iyy}" izz="{izz}" ixy="0" ixz="0" iyz="0"/></inertial>')


def box_link(name, mass, size, xyz="0 0 0", collision=True, inertia=None):
    x, y, z = size
    inertial = box_inertial(mass, x, y, z, xyz)
    if inertia is not None:
        inertial = (f'<inertial><origin xyz="{xyz}"/><mass value="{mass}"/><inertia ixx="{inertia}"'
                    f' iyy="{inertia}" izz="{inertia}" ixy="0" ixz="0" iyz="0"/></inertial>')
    geometry = f'<origin xyz="{xyz}"/><geometry><box size="{x} {y} {z}"/></geometry>'
    return (f'<link name="{name}">{inertial}<visual>{geometry}{RED}</visual>'
            + (f"<collision>{geometry}</collision>" if collision else "") + "</link>")


def arm(effort="100", limits='lower="-1.5" upper="1.5"', lamp=False, world=True) -> str:
    """A 10 kg block anchored to the world, with a 5 kg, 0.5 m bar on a horizontal shoulder
    axis (y), held horizontal at the home pose: the shoulder must give m·g·d = 5·9.81·0.25."""
    parts = ['<robot name="arm">']
    if world:
        parts.append('<link name="world"/><joint name="fix" type="fixed"><parent link="world"/>'
                     '<child link="base"/></joint>')
    parts.append(box_link("base", 10, (0.2, 0.2, 0.2)))
    parts.append(box_link("upper", 5, (0.5, 0.06, 0.06), "0.25 0 0"))
    parts.append(f'<joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>'
                 f'<origin xyz="0 0 0.2"/><axis xyz="0 1 0"/><limit {limits} effort="{effort}" '
                 'velocity="2"/></joint>')
    if lamp:  # a sibling of the bar on its own joint, placed right inside it (copy-paste origin)
        parts.append(box_link("lamp", 1, (0.3, 0.06, 0.06), "0.25 0 0"))
        parts.append('<joint name="lamp_joint" type="revolute"><parent link="base"/>'
                     '<child link="lamp"/><origin xyz="0 0 0.2"/><axis xyz="0 0 1"/>'
                     '<limit lower="-1" upper="1" effort="100" velocity="1"/></joint>')
    parts.append("</robot>")
    return "\n".join(parts)


def walker(foot_inertia=None) -> str:
    """A 20 kg body on four legs ending in 1 kg feet on ankle joints (COM on the ankle axis)."""
    parts = ['<robot name="walker">', box_link("body", 20, (0.6, 0.4, 0.2))]
    for k, (x, y) in enumerate([(0.25, 0.15), (0.25, -0.15), (-0.25, 0.15), (-0.25, -0.15)]):
        parts.append(box_link(f"leg{k}", 1, (0.04, 0.04, 0.3), "0 0 -0.15"))
        parts.append(f'<joint name="hip{k}" type="revolute"><parent link="body"/>'
                     f'<child link="leg{k}"/><origin xyz="{x} {y} -0.1"/><axis xyz="0 1 0"/>'
                     '<limit lower="-1" upper="1" effort="40" velocity="2"/></joint>')
        parts.append(box_link(f"foot{k}", 1, (0.12, 0.08, 0.03), inertia=foot_inertia))
        parts.append(f'<joint name="ankle{k}" type="revolute"><parent link="leg{k}"/>'
                     f'<child link="foot{k}"/><origin xyz="0 0 -0.315"/><axis xyz="0 1 0"/>'
                     '<limit lower="-1" upper="1" effort="20" velocity="2"/></joint>')
    parts.append("</robot>")
    return "\n".join(parts)


MODELS = {
    "good_arm": arm(),
    "zero_effort": arm(effort="0"),
    "swapped_limits": arm(limits='lower="1" upper="-1"'),
    "overlap": arm(lamp=True),
    "walker": walker(),
    "tiny_inertia_feet": walker(foot_inertia="1e-9"),
    "no_collision": '<robot name="ghost">' + box_link("body", 2, (0.3, 0.3, 0.3), collision=False)
                    + "</robot>",
    "no_inertial": '<robot name="light"><link name="body"><collision><geometry><box size="0.2 0.2'
                   ' 0.2"/></geometry></collision></link></robot>',
    "two_roots": '<robot name="split">' + box_link("a", 1, (0.1, 0.1, 0.1)) +
                 box_link("b", 1, (0.1, 0.1, 0.1)) + "</robot>",
    "pybullet_refuses": '<robot name="bad"><link name="a"><inertial><mass value="1"/></link>'
                        "</robot>",
}


@pytest.fixture(scope="module")
def models(tmp_path_factory):
    folder = tmp_path_factory.mktemp("sim_models")
    paths = {}
    for name, text in MODELS.items():
        paths[name] = folder / f"{name}.urdf"
        paths[name].write_text(text, encoding="utf-8")
    return paths


@pytest.fixture(scope="module")
def results(models):
    ordered = list(models)
    found = simulate([str(models[name]) for name in ordered], SimOptions(jobs=2))
    return dict(zip(ordered, found))


def failed(result) -> set[str]:
    return {c.check for c in result.failures()}


def test_every_model_gets_every_check_in_order(results):
    for result in results.values():
        assert [c.check for c in result.checks] == [f"sim.{name}" for name in CHECKS]
        assert all(c.status in ("pass", "fail", "skip") for c in result.checks)


def test_good_arm_passes_anchored_to_world(results):
    good = results["good_arm"]
    assert good.verdict == "pass", [c.message for c in good.failures()]
    assert good.anchored and good.anchor_reason == "root link 'world'"
    assert good.check("sink").status == "skip" and good.check("drift").status == "skip"
    assert good.check("mass").values["pybullet_kg"] == pytest.approx(15.0)  # world: no mass
    assert good.real_time_factor > 1


def test_zero_effort_joint_cannot_hold_its_load(results):
    # the bar hangs on a motor with effort 0: it falls, and the report names the joint with
    # the torque it would need, m·g·d with d = 0.25 m to the bar's COM
    result = results["zero_effort"]
    assert "sim.hold" in failed(result)
    entry = result.saturation[0]
    assert entry["joint"] == "shoulder" and entry["effort"] == 0 and entry["saturated"]
    assert abs(entry["gravity_torque"]) == pytest.approx(5 * 9.81 * 0.25, rel=1e-3)
    assert abs(entry["error"]) > 0.3
    assert "gravity needs 12.3 N·m" in result.check("hold").message
    assert entry["saturated_by"] == "gravity"


def test_swapped_limits_are_an_empty_range_pybullet_ignores(results):
    result = results["swapped_limits"]
    check = result.check("joint-limits")
    assert check.failed and "empty range" in check.message
    assert check.values["joints"][0]["empty_range"] is True


def test_two_overlapping_links_fail_self_collision_with_the_overlap_depth(results):
    # the lamp (0.3 x 0.06 x 0.06) sits inside the bar (0.5 x 0.06 x 0.06), both centred on
    # x = 0.25 at the same height: the boxes overlap by their full 0.06 m thickness
    result = results["overlap"]
    check = result.check("self-collision")
    assert check.failed
    (pair,) = check.values["pairs"]
    assert {pair["a"], pair["b"]} == {"upper", "lamp"}
    assert pair["depth_m"] == pytest.approx(0.06, abs=1e-4)
    assert "upper:lamp" in check.message or "lamp:upper" in check.message


def test_tiny_inertia_on_the_feet_makes_the_robot_sink(results):
    # 1 kg feet with an inertia of 1e-9 kg·m²: the contact solver cannot hold them, they turn
    # under the body and dig into the ground (the ChipV2 symptom); the same walker with the
    # box inertia of its feet stands
    good, bad = results["walker"], results["tiny_inertia_feet"]
    assert good.verdict == "pass", [c.message for c in good.failures()]
    assert good.check("sink").values["penetration_m"] < 0.002
    assert "sim.sink" in failed(bad)
    assert bad.check("sink").values["penetration_m"] > 0.02
    assert "sim.hold" in failed(bad)  # the ankles turn although gravity needs no torque there
    ankles = [e for e in bad.saturation if e["joint"].startswith("ankle")]
    assert ankles and all(abs(e["gravity_torque"]) < 1e-9 for e in ankles)
    assert all(e["saturated_by"] is None for e in ankles)  # the motors are far from 20 N·m
    assert "cannot hold the joint (tiny inertia or mass?)" in bad.check("hold").message


def test_no_collision_geometry_falls_through_the_ground(results):
    result = results["no_collision"]
    assert "sim.sink" in failed(result)
    assert "falls through" in result.check("sink").message
    # a free model that does not settle is pointed at --fixed-base (issue 14: an arm written
    # without a 'world' link is dropped and falls over)
    assert "sim.settle" in failed(result)
    assert "run with --fixed-base" in result.check("settle").message


def test_link_without_inertial_gets_pybullets_default_mass(results):
    result = results["no_inertial"]
    mass = result.check("mass")
    # the URDF says no mass, PyBullet simulates 1 kg: a mismatch, a failure (issue 14)
    assert mass.status == "fail" and mass.values["default_mass_links"] == ["body"]
    assert mass.values["pybullet_kg"] == pytest.approx(1.0) and mass.values["urdf_kg"] == 0
    assert "1 link(s) without <inertial> get PyBullet's default 1 kg ('body')" in mass.message


def test_two_root_links_fail_to_load_without_crashing(results):
    result = results["two_roots"]
    load = result.check("load")
    assert load.failed and "2 root links" in load.message
    assert all(c.status == "skip" for c in result.checks[1:])


def test_pybullets_own_error_message_is_passed_on(results):
    load = results["pybullet_refuses"].check("load")
    assert load.failed
    assert "Cannot load URDF file" in load.message
    assert "XML_ERROR_MISMATCHED_ELEMENT" in load.message
    assert "pybullet_refuses.urdf:1" in load.message  # our own reading of the XML problem


# -- the command line ----------------------------------------------------------------------


def test_cli_exit_codes_and_clean_stdout(models):
    good = run_urdftool("sim", models["good_arm"])
    assert good.code == 0, good.out + good.err
    assert "pybullet build time" not in good.out and "b3Warning" not in good.out
    assert "1 model(s): 1 passed" in good.out
    bad = run_urdftool("sim", models["zero_effort"], "--format", "json")
    assert bad.code == 1
    report = json.loads(bad.out)  # nothing but the report on stdout
    (model,) = report["models"]
    assert model["verdict"] == "fail" and report["summary"]["failed"] == 1
    hold = next(c for c in model["checks"] if c["check"] == "sim.hold")
    assert hold["status"] == "fail" and hold["values"]["joints"][0]["joint"] == "shoulder"
    assert set(model["timing"]) >= {"prepare", "load", "simulate", "total"}


def test_cli_tool_errors_exit_2(models, tmp_path):
    missing = run_urdftool("sim", tmp_path / "nope.urdf")
    assert missing.code == 2 and "no such file" in missing.err
    assert "Traceback" not in missing.err
    size = run_urdftool("sim", models["good_arm"], "--size", "huge")
    assert size.code == 2 and "--size" in size.err
    pair = run_urdftool("sim", models["good_arm"], "--allow-collision", "upper")
    assert pair.code == 2 and "LINK_A:LINK_B" in pair.err


def test_cli_allow_collision_and_base_options(models):
    allowed = run_urdftool("sim", models["overlap"], "--allow-collision", "lamp:upper",
                           "--format", "json")
    assert allowed.code == 0, allowed.out
    fixed = run_urdftool("sim", models["walker"], "--fixed-base", "--duration", "0.25",
                         "--format", "json")
    model = json.loads(fixed.out)["models"][0]
    assert model["anchored"] and model["anchor_reason"] == "--fixed-base"
    free = run_urdftool("sim", models["good_arm"], "--free", "--duration", "0.25",
                        "--format", "json")
    model = json.loads(free.out)["models"][0]
    assert model["anchored"] is False
    assert any("removed link 'world'" in note for note in model["notes"])


def _crash_on_walker(path, options, from_directory, picture):
    """Stands in for the worker function: dies like PyBullet on a segmentation fault."""
    from urdftool.sim.engine import run_model

    if path.endswith("walker.urdf"):
        import faulthandler

        faulthandler.disable()  # pytest's, inherited by the fork: keep the test output clean
        os.abort()
    return run_model(path, options, from_directory, picture)


def test_a_crashing_model_fails_its_load_check_and_the_others_still_run(models, monkeypatch):
    # PyBullet segfaults on some inputs: only the worker dies, the model is re-run alone and
    # reported; forked workers see the patched worker function
    from urdftool.sim import runner

    if runner._context().get_start_method() != "fork":
        pytest.skip("needs fork to patch the workers")
    monkeypatch.setattr(runner, "_work", _crash_on_walker)
    found = simulate([str(models["good_arm"]), str(models["walker"])],
                     SimOptions(duration=0.1, jobs=2))
    assert found[0].verdict == "pass"
    assert found[1].check("load").failed and "crashed" in found[1].check("load").message


def test_home_pose_is_zero_clamped_into_the_limits(tmp_path):
    from urdftool.sim.prepare import prepare

    path = tmp_path / "r.urdf"
    path.write_text(arm(limits='lower="0.2" upper="1.2"'), encoding="utf-8")
    prepared = prepare(str(path), SimOptions())
    try:
        assert prepared.joints["shoulder"].home == 0.2
        assert math.isclose(prepared.joints["shoulder"].lower, 0.2)
    finally:
        prepared.cleanup()


def test_sdf_input_is_converted_and_simulated():
    # the SDF converter's URDF: a chassis on two included wheels (model://wheel, found with
    # --model-path) rests on its wheels; without the model path the wheels are missing and the
    # chassis, which has no collision geometry, falls through the ground
    from tests.conftest import ROOT

    sdf = ROOT / "tests" / "data" / "sdf" / "with_include.sdf"  # committed: never skipped
    found = run_urdftool("sim", sdf, "--model-path", sdf.parent / "models", "--format", "json")
    assert found.code == 0, found.out
    (model,) = json.loads(found.out)["models"]
    assert model["robot"] == "cart" and model["anchored"] is False
    missing = run_urdftool("sim", sdf, "--format", "json")
    assert missing.code == 1
    (model,) = json.loads(missing.out)["models"]
    assert any("cannot resolve include 'model://wheel'" in note for note in model["notes"])
    sink = next(c for c in model["checks"] if c["check"] == "sim.sink")
    assert sink["status"] == "fail"


def test_a_package_directory_simulates_its_entries_with_their_arguments(tmp_path):
    """``sim DIR`` drops into the simulator what ``check DIR`` calls entries, expanded with
    the arguments check uses (here a launch file's ``model:=``): a macro file and an included
    part are fragments, no robots (they failed 'the robot has no links' before)."""
    package = tmp_path / "cam_description"
    (package / "urdf").mkdir(parents=True)
    (package / "launch").mkdir()
    (package / "package.xml").write_text("<package><name>cam_description</name></package>")
    (package / "urdf" / "cam.urdf.xacro").write_text(
        '<?xml version="1.0"?>\n<robot name="cam" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:include filename="$(find cam_description)/urdf/$(arg model).xacro"/>\n'
        '  <xacro:body/>\n</robot>\n')
    (package / "urdf" / "box.xacro").write_text(
        '<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:macro name="body"><link name="base"><inertial><mass value="1"/>\n'
        '    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>\n'
        '    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>\n'
        '    <visual><geometry><box size="0.2 0.2 0.2"/></geometry></visual></link>\n'
        '  </xacro:macro>\n</robot>\n')
    (package / "launch" / "view.launch").write_text(
        '<launch><arg name="model" default="box"/><param name="robot_description" '
        'command="$(find xacro)/xacro $(find cam_description)/urdf/cam.urdf.xacro '
        'model:=$(arg model)"/></launch>\n')
    result = run_urdftool("sim", "--trusted", "--format", "json", str(package))
    models = json.loads(result.out)["models"]
    assert [os.path.basename(m["path"]) for m in models] == ["cam.urdf.xacro"], models
    assert models[0]["verdict"] == "pass" and result.code == 0, models
