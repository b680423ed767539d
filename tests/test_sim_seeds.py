"""`urdftool sim` on the seed robots (robots/NAME/{published,corrected}, see robots/README.md).

The corrected copies must pass. The published files show what they really do in PyBullet, and
each expectation says why.
"""

from __future__ import annotations

import re
import shutil

import pybullet  # noqa: F401 - the test extra has it: missing, this fails
import pytest

from tests.conftest import ROBOTS
from urdftool.sim import SimOptions
from urdftool.sim.runner import simulate


@pytest.fixture(scope="module")
def corrected():
    folders = sorted(str(p) for p in ROBOTS.glob("*/corrected"))
    assert folders, "robots/*/corrected is missing"
    return simulate(folders, SimOptions(jobs=2))


@pytest.fixture(scope="module")
def published():
    folders = sorted(str(p) for p in ROBOTS.glob("*/published"))
    assert folders, "robots/*/published is missing"
    results = simulate(folders, SimOptions(jobs=2))
    repaired = simulate(folders, SimOptions(jobs=2, repaired=True))
    return ({r.path.split("robots/", 1)[1]: r for r in results},
            {r.path.split("robots/", 1)[1]: r for r in repaired})


def failed(result) -> set[str]:
    return {c.check.removeprefix("sim.") for c in result.failures()}


def test_corrected_seed_robots_pass(corrected):
    assert len(corrected) >= 6
    for result in corrected:
        assert result.verdict == "pass", (result.path, [c.message for c in result.failures()])
        assert result.timing["cpu"] < 5  # CPU seconds: the machine's other load does not count


def _expect(results, name):
    assert name in results, f"robots/{name} is committed: its result is missing"
    return results[name]


def test_published_files_pybullet_cannot_parse_fail_to_load(published):
    # not well-formed XML: PyBullet's tinyxml2 (or xacro, before it) refuses the file as
    # written, and the load check says where (file:line; the line is the XML reader's call)
    as_written, _ = published
    expectations = [
        "dd_robot/published/diff_robot.urdf",  # line 4: 'k name="base_link">' lost its '<li'
        "m2wr/published/m2wr.xacro",  # <material>Gazebo/Orange/material> never closed
        "dual_arm/published/test.xacro",  # <geometry> missing, </geometry> closes nothing
        "open_manipulator/published/open_manipulator.urdf.xacro",  # 'link name=...' lost '<'
    ]
    for name in expectations:
        result = _expect(as_written, name)
        assert failed(result) == {"load"}, (name, failed(result))
        message = result.check("load").message
        assert re.search(re.escape(name.rsplit("/", 1)[1]) + r":\d+", message), message
    # PyBullet's own refusal is passed on for the plain URDF it tried to read
    dd = as_written["dd_robot/published/diff_robot.urdf"].check("load").message
    assert "Cannot load URDF file" in dd


def test_published_smartcar_urdf_is_not_simulated(published):
    # no <inertial> in any link: kinematics only, as check says (inertia.kinematics-only, a
    # warning); PyBullet would give each link 1 kg and let the car fall through the ground
    # (no <collision> either): one cause, said once, and nothing is simulated
    result = _expect(published[0], "smartcar/published/smartcar.urdf")
    assert result.verdict == "skip" and failed(result) == set()
    assert all("inertia.kinematics-only" in c.message for c in result.checks)


def test_published_smartcar_xacro_expands_to_nothing(published):
    # old unprefixed <include>, <property> and macro calls: current xacro copies them through,
    # the expanded robot has no links
    result = _expect(published[0], "smartcar/published/smartcar.urdf.xacro")
    assert failed(result) == {"load"}
    assert "old unprefixed tags" in result.check("load").message


def test_published_chip_v2_stands_still_at_its_home_pose(published):
    # well-formed, loads. Its defects are in the inertia tensors (axis-swapped upper and lower
    # legs, COMs at the joints instead of the box centres) and a copy-pasted BR_lower collision
    # box: with every joint held at zero by its 10 N·m motor for 1 s none of them moves the
    # robot (it rests on its feet, drift below a millimetre). The drifting and sinking of the
    # seed came from its own setup (default inertia from the collision shapes, friction);
    # `urdftool check` is what finds these defects.
    result = _expect(published[0], "chip_v2/published/chip_v2.urdf")
    assert result.verdict == "pass", [c.message for c in result.failures()]
    assert result.check("drift").values["travel_m"] < 1e-3


def test_published_files_repaired_show_their_physics(published):
    _, repaired = published
    # dd_robot: the left wheel has no collision and the caster sits 2.5 cm above the wheels'
    # contact plane: the robot leans onto its wheel-less side by about 8 degrees and is still
    # rocking after 1 s
    dd = _expect(repaired, "dd_robot/published/diff_robot.urdf")
    assert dd.check("load").status == "pass"
    assert dd.check("drift").values["tilt_deg"] > 5
    assert set(dd.check("mass").values["default_mass_links"]) == {"left_wheel", "right_wheel"}
    # m2wr: once its tags are closed it is a sound robot
    assert _expect(repaired, "m2wr/published/m2wr.xacro").verdict == "pass"
    # dual_arm: the 47 mg fingers with 1 kg·m² inertias and off-axis COMs are wrong, but held
    # at the home pose on a 12.5 kg base nothing makes them move: the physics test passes and
    # `urdftool check` is what catches them
    assert _expect(repaired, "dual_arm/published/test.xacro").verdict == "pass"
    # open_manipulator: its gazebo include is not part of the published material
    om = _expect(repaired, "open_manipulator/published/open_manipulator.urdf.xacro")
    assert failed(om) == {"load"} and "cannot include" in om.check("load").message


def test_published_smartcar_xacro_with_prefixes_added_does_not_settle(tmp_path):
    # the published smartcar xacro with only the xacro: prefixes added (nothing else fixed):
    # the wheels' collision cylinders and COMs repeat the joint offset (0.116 m off the wheel,
    # tilted), so the car rests on misplaced wheels and slowly tips; the 1 kg·m² inertias on
    # 0.1 kg wheels make that motion so slow that it is still going after 1 s (in 3 s it
    # tilts by some 37 degrees). With the origins fixed and the inertias kept, it stands.
    copy = tmp_path / "smartcar"
    shutil.copytree(ROBOTS / "smartcar" / "published", copy)
    for path in [copy / "smartcar.urdf.xacro", *(copy / "urdf").glob("*.xacro")]:
        text = path.read_text(encoding="utf-8")
        text = re.sub(r"<(/?)(include|property|macro)\b", r"<\1xacro:\2", text)
        text = re.sub(r"<(smartcar_body|smartcar_sim)/>", r"<xacro:\1/>", text)
        path.write_text(text, encoding="utf-8")
    origins_fixed = tmp_path / "origins_fixed"
    shutil.copytree(copy, origins_fixed)
    body = origins_fixed / "urdf" / "smartcar_body.urdf.xacro"
    text = body.read_text(encoding="utf-8")
    text = re.sub(r'(<collision>\s*)<origin rpy="0 1.57075 1.57075" xyz="[^"]*"/>',
                  r'\1<origin rpy="0 0 0" xyz="0 0 0"/>', text)
    text = re.sub(r'(<inertial>\s*)<origin xyz="[-0-9. ]*0.025"/>', r'\1<origin xyz="0 0 0"/>',
                  text)
    body.write_text(text, encoding="utf-8")
    prefixed, fixed = simulate([str(copy / "smartcar.urdf.xacro"),
                                str(origins_fixed / "smartcar.urdf.xacro")], SimOptions(jobs=2))
    assert prefixed.check("load").status == "pass", prefixed.check("load").message
    assert "settle" in failed(prefixed)
    assert fixed.verdict == "pass", [c.message for c in fixed.failures()]
