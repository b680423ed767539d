"""SDF -> URDF on the shapes of real Gazebo models that used to fail, each model written here for
the test. Oracle: Drake (`tests/sdf_drake.py`): the SDF loaded by Drake's SDFormat parser
(libsdformat), the URDF by Drake's URDF parser, every body compared at the default and at 20
random configurations (pose, mass, COM, inertia) to 1e-9. Where Drake refuses an SDF that
libsdformat (and Gazebo) accept, Drake loads the equivalent SDF the test writes out by hand
(names made unique as libsdformat renames them, a loop's cut joint removed), never urdftool's.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from conftest import run_urdftool
from hypothesis import given, settings
from hypothesis import strategies as st
from lxml import etree
from sdf_drake import Plant, compare, drake_copy

TOL = 1e-9

INERTIAL = ("<inertial><pose>{c} 0.01 -0.02 0.1 0.2 0.3</pose><mass>{m}</mass><inertia>"
            "<ixx>0.03</ixx><ixy>0.001</ixy><ixz>-0.002</ixz><iyy>0.02</iyy><iyz>0.003</iyz>"
            "<izz>0.025</izz></inertia></inertial>")


def link(name: str, pose: str = "0 0 0 0 0 0", mass: float = 1.0, c: float = 0.05) -> str:
    return f'<link name="{name}"><pose>{pose}</pose>{INERTIAL.format(c=c, m=mass)}</link>'


def joint(name: str, parent: str, child: str, kind: str = "revolute", axis: str = "0 0 1",
          pose: str = "0 0 0 0 0 0", extra: str = "") -> str:
    return (f'<joint name="{name}" type="{kind}"><pose>{pose}</pose><parent>{parent}</parent>'
            f"<child>{child}</child><axis><xyz>{axis}</xyz><limit><lower>-2</lower>"
            f"<upper>2</upper><effort>5</effort><velocity>3</velocity></limit></axis>{extra}"
            "</joint>")


def sdf(body: str, version: str = "1.7", name: str = "m") -> str:
    return f'<sdf version="{version}"><model name="{name}">{body}</model></sdf>'


def convert(tmp_path: Path, text: str, *extra: str, name: str = "model.sdf"):
    path = tmp_path / name
    path.write_text(text)
    out = tmp_path / (path.stem + ".urdf")
    result = run_urdftool("convert", path, "-o", out, *extra)
    assert "Traceback" not in result.err
    return path, (out.read_text() if out.exists() else None), result


def assert_matches(report: dict) -> None:
    assert report["configurations"] == 20 and report["moved_joints"] > 0, report
    for key in ("pose", "mass", "com", "inertia"):
        assert report[key] < TOL, report


# -- 2. a link whose only joint makes it the parent: reversed, never floating -----------------


def test_sensor_mounted_backwards_is_reversed_not_floating(tmp_path):
    """turtlebot's kinect: its only joint names it the parent of a link that hangs elsewhere."""
    text = sdf(link("base") + link("plate", "0 0 0.3 0 0 0.2") + link("kinect", "0.1 0 0.5 0.1 0 0")
               + joint("spin", "base", "plate", pose="0.02 0 0 0 0 0")
               + joint("kinect_joint", "kinect", "plate", axis="1 0.5 0",
                       pose="0.05 0.01 -0.1 0.3 -0.2 0.1"))
    path, urdf, result = convert(tmp_path, text)
    assert result.code == 0, result.err
    assert 'type="floating"' not in urdf and "is joined to no other link" not in result.err
    assert " info sdf.reversed-joint: " in result.err and "kinect_joint" in result.err
    assert "reorder" not in result.err
    assert_matches(compare(path, urdf))  # Drake loads the SDF as written (reversed joint)


def test_parallel_links_of_a_gripper_stay_attached(tmp_path):
    """PR2 gripper: each parallel link is the parent of both its joints (to the palm and to the
    finger tip), closing a four-bar; one joint per loop is cut, no link floats."""
    links = link("arm") + link("palm", "0.3 0 0 0 0 0")
    joints = joint("wrist", "arm", "palm", axis="1 0 0", pose="0 0 0 0 0 0")
    cut = []
    for side, y in (("l", 0.02), ("r", -0.02)):
        links += (link(f"{side}_finger", f"0.35 {y} 0 0 0 0", 0.1)
                  + link(f"{side}_tip", f"0.4 {y} 0 0 0 0", 0.05)
                  + link(f"{side}_parallel", f"0.36 {y} 0.01 0 0 0", 0.08))
        joints += (joint(f"{side}_finger_joint", "palm", f"{side}_finger")
                   + joint(f"{side}_tip_joint", f"{side}_finger", f"{side}_tip")
                   + joint(f"{side}_parallel_root", f"{side}_parallel", "palm")
                   + joint(f"{side}_parallel_tip", f"{side}_parallel", f"{side}_tip"))
        cut.append(f"{side}_parallel_tip")
    _path, urdf, result = convert(tmp_path, sdf(links + joints))
    assert result.code == 0, result.err
    assert 'type="floating"' not in urdf
    for name in cut:
        assert f"joint '{name}' closes the kinematic loop" in result.err
        assert f'<joint name="{name}"' not in urdf
    # Drake has no loops: it loads the same SDF without the two cut joints
    opened = tmp_path / "opened.sdf"
    opened.write_text(sdf(links + "".join(
        part + "</joint>" for part in joints.split("</joint>")[:-1]
        if not any(f'name="{name}"' in part for name in cut))))
    assert_matches(compare(opened, urdf))


def test_screw_link_parent_of_its_only_joint(tmp_path):
    """pr2_gripper's screw: the screw link is the parent of its only (screw) joint."""
    links = link("frame") + link("nut", "0.1 0 0 0 0 0") + link("screw", "0.1 0 0.05 0 0 0.3")
    slide = joint("slide", "frame", "nut", "prismatic", axis="1 0 0")
    pitch = "<screw_thread_pitch>0.02</screw_thread_pitch>"
    _path, urdf, result = convert(tmp_path, sdf(links + slide + joint(
        "screw_joint", "screw", "nut", "screw", axis="0.2 0 1", pose="0 0.01 0 0.1 0 0",
        extra=pitch), version="1.10"))
    assert result.code == 0, result.err
    assert 'type="floating"' not in urdf and " info sdf.reversed-joint: " in result.err
    # Drake cannot reverse a screw joint: it loads the joint written the other way round by
    # hand (the same joint frame, still relative to 'nut'; the opposite axis: the inverse screw
    # motion at the same q)
    by_hand = tmp_path / "by_hand.sdf"
    by_hand.write_text(sdf(links + slide + joint(
        "screw_joint", "nut", "screw", "screw", axis="-0.2 0 -1",
        pose="0 0.01 0 0.1 0 0", extra=pitch).replace("<pose>0 0.01", '<pose relative_to='
                                                      '"nut">0 0.01'), version="1.10"))
    assert_matches(compare(by_hand, urdf))


def test_truly_free_body_is_the_only_floating_one(tmp_path):
    text = sdf(link("base") + link("arm", "0 0 1 0 0 0") + link("ball", "2 0 0 0 0 0")
               + joint("j", "arm", "base"))
    _, urdf, result = convert(tmp_path, text)
    assert urdf.count('type="floating"') == 1 and 'name="ball__floating"' in urdf
    assert "link 'ball' is joined by no joint" in result.err


# -- 3. no snapping: rpy near gimbal lock -------------------------------------------------------


def rpy_matrix(r, p, y):  # closed form, written here
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), \
        math.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def test_pitch_just_below_gimbal_lock_round_trips(tmp_path):
    """The shape of the failing model: a link placed relative to a rotated one with a relative
    pitch of pi/2 - 7.7e-7 (urdftool composes the rotations and writes their rpy)."""
    pitch = math.pi / 2 - 7.7e-7
    text = sdf('<link name="base"><pose>0 0 0 0.2 0 0.3</pose>' + INERTIAL.format(c=0.1, m=1)
               + '</link><link name="arm"><pose relative_to="base">0.1 0.2 0.3 0.4 '
               f"{pitch!r} -0.7</pose>{INERTIAL.format(c=0.3, m=2)}</link>"
               '<link name="hand"><pose relative_to="arm">0.5 0 0 0.2 '
               f"{-pitch!r} 1.1</pose>{INERTIAL.format(c=0.2, m=1)}</link>"
               + joint("j", "base", "arm", "fixed") + joint("k", "arm", "hand", axis="0 1 0"))
    path, urdf, result = convert(tmp_path, text)
    assert result.code == 0, result.err
    report = compare(path, urdf)
    assert_matches(report)
    assert report["pose"] < 1e-12 and report["com"] < 1e-12, report


@settings(max_examples=25, deadline=None)
@given(st.lists(st.tuples(
    st.tuples(*[st.floats(-2, 2)] * 3),
    st.floats(-math.pi, math.pi),
    st.one_of(st.floats(-math.pi / 2, math.pi / 2),
              st.floats(-16, -3).map(lambda e: math.pi / 2 - 10 ** e),
              st.floats(-16, -3).map(lambda e: -math.pi / 2 + 10 ** e),
              st.sampled_from([math.pi / 2, -math.pi / 2])),
    st.floats(-math.pi, math.pi)), min_size=2, max_size=4))
def test_pose_composition_round_trips(tmp_path_factory, poses):
    """A chain of links, each placed relative_to the previous one (so urdftool composes the
    poses and writes rpy for the products): every link frame read back from the URDF by Drake
    equals the product of the poses computed here, to 1e-12."""
    tmp_path = tmp_path_factory.mktemp("poses")
    body, expected, total = "", {}, np.eye(4)
    for index, (xyz, roll, pitch, yaw) in enumerate(poses):
        relative = f' relative_to="l{index - 1}"' if index else ""
        body += (f'<link name="l{index}"><pose{relative}>{" ".join(map(repr, xyz))} {roll!r} '
                 f"{pitch!r} {yaw!r}</pose></link>")
        if index:
            body += (f'<joint name="j{index}" type="fixed"><parent>l{index - 1}</parent>'
                     f"<child>l{index}</child></joint>")
        step = np.eye(4)
        step[:3, :3], step[:3, 3] = rpy_matrix(roll, pitch, yaw), xyz
        total = total @ step
        expected[f"l{index}"] = total
    _, urdf, result = convert(tmp_path, sdf(body))
    assert result.code == 0, result.err
    plant = Plant(text=urdf, kind="urdf")
    root = plant.pose(plant.bodies["l0"])
    for name, pose in expected.items():
        got = np.linalg.inv(root) @ plant.pose(plant.bodies[name])
        want = np.linalg.inv(expected["l0"]) @ pose
        assert np.abs(got - want).max() < 1e-12, (name, got - want)


def test_matrix_rpy_against_drake_near_gimbal_lock():
    """urdftool's rotation -> rpy against Drake's RollPitchYaw on the same matrices: both give
    rpy that rebuild the matrix to 1e-14, down to pitch = pi/2 - 1e-16."""
    from pydrake.math import RollPitchYaw, RotationMatrix

    from urdftool.sdf.transforms import matrix_rpy

    rng = np.random.default_rng(5)
    for exponent in range(3, 17):
        for sign in (1, -1):
            rpy = (rng.uniform(-3, 3), sign * (math.pi / 2 - 10.0 ** -exponent), rng.uniform(-3, 3))
            matrix = rpy_matrix(*rpy)
            ours = rpy_matrix(*matrix_rpy(tuple(map(tuple, matrix))))
            drake = rpy_matrix(*RollPitchYaw(RotationMatrix(matrix)).vector())
            assert np.abs(ours - matrix).max() < 1e-14
            assert np.abs(drake - matrix).max() < 1e-14


# -- 6. universal joint without axes -------------------------------------------------------------


def test_universal_without_axes_warns_with_what_readers_do(tmp_path):
    text = sdf(link("base") + link("arm", "0 0 0.5 0 0 0")
               + '<joint name="u" type="universal"><parent>base</parent><child>arm</child></joint>')
    path, _urdf, result = convert(tmp_path, text)
    assert result.code == 0
    warning = [line for line in result.err.splitlines() if "joint 'u' has no <axis>" in line]
    assert warning and "warning" in warning[0] and "about the same line" in warning[0]
    with pytest.raises(RuntimeError, match="Both axis and axis2 must be specified"):
        Plant(path=path)  # the oracle refuses the file, as the warning says


# -- 1. SDFormat < 1.7: a joint (frame) with a link's name ---------------------------------------


def names_clash(version: str) -> str:
    """create/turtlebot shape: joints named after their child links, a frame named after a
    link, and a joint written before the link whose name it takes."""
    return sdf(link("base") + link("wheel", "0 0.1 0 -1.5707963267948966 0 0")
               + joint("wheel", "base", "wheel", axis="0 0 1", pose="0 0 0.01 0 0 0")
               + '<frame name="base"><pose>0 0 0.2 0 0 0</pose></frame>'
               + joint("caster", "base", "caster", axis="0 1 0")
               + link("caster", "0.2 0 -0.05 0 0 0", 0.2), version=version)


def test_below_1_7_clashing_names_are_renamed_as_libsdformat_does(tmp_path):
    _path, urdf, result = convert(tmp_path, names_clash("1.6"))
    assert result.code == 0, result.err
    for kind, written, renamed in (("joint", "wheel", "wheel_joint"),
                                   ("frame", "base", "base_frame"),
                                   ("link", "caster", "caster_link")):
        line = next(l for l in result.err.splitlines() if f"{kind} '{written}' has" in l)
        assert " warning sdf.duplicate-name: " in line
        assert f"'{renamed}'" in line and "Gazebo" in line
    assert 'type="floating"' not in urdf
    # Drake refuses the clash even below 1.7: it loads the file with the names libsdformat
    # gives them (written out here; below 1.7 a joint's <child> names a link)
    renamed = tmp_path / "renamed.sdf"
    renamed.write_text(names_clash("1.6").replace('<joint name="wheel"', '<joint name="wheel_joint"')
                       .replace('<frame name="base"', '<frame name="base_frame"')
                       .replace('<link name="caster"', '<link name="caster_link"')
                       .replace("<child>caster<", "<child>caster_link<"))
    assert_matches(compare(renamed, urdf))


def test_from_1_7_clashing_names_are_refused(tmp_path):
    path, _urdf, result = convert(tmp_path, names_clash("1.7"))
    assert result.code == 1
    errors = [l for l in result.err.splitlines() if "sdf.duplicate-name: " in l]
    assert errors and all(" error sdf.duplicate-name: " in l and "libsdformat refuses" in l
                          for l in errors)
    with pytest.raises(RuntimeError, match="(?i)name"):
        Plant(path=path)


# -- 4. libsdformat's flattened nested models: 'X::__model__' frames ------------------------------


FLATTENED = sdf(
    link("base", "0 0 0.1 0 0 0")
    + '<frame name="arm::__model__" attached_to="arm::upper"><pose relative_to="__model__">'
      "1.2 0.4 0.3 0 0 0.5</pose></frame>"
    + '<link name="arm::upper"><pose relative_to="arm::__model__">0 0 0.5 0.2 0 0</pose>'
    + INERTIAL.format(c=0.1, m=1) + "</link>"
    + '<link name="arm::lower"><pose relative_to="arm::__model__">0 0 1.2 0 0.3 0</pose>'
    + INERTIAL.format(c=0.2, m=1) + "</link>"
    + '<joint name="arm::elbow" type="revolute"><pose relative_to="arm::__model__">0 0 0.9 0 0 0'
      "</pose><parent>arm::upper</parent><child>arm::lower</child><axis><xyz "
      'expressed_in="arm::__model__">0 1 0</xyz></axis></joint>'
    + joint("mount", "base", "arm::upper", axis="1 0 0"))


NESTED = sdf(  # the same model before flattening: what Drake loads ('::' names it has not)
    link("base", "0 0 0.1 0 0 0")
    + '<model name="arm"><pose>1.2 0.4 0.3 0 0 0.5</pose>'
    + '<link name="upper"><pose>0 0 0.5 0.2 0 0</pose>' + INERTIAL.format(c=0.1, m=1) + "</link>"
    + '<link name="lower"><pose>0 0 1.2 0 0.3 0</pose>' + INERTIAL.format(c=0.2, m=1) + "</link>"
    + '<joint name="elbow" type="revolute"><pose relative_to="__model__">0 0 0.9 0 0 0</pose>'
      "<parent>upper</parent><child>lower</child><axis><xyz expressed_in="
      '"__model__">0 1 0</xyz></axis></joint></model>'
    + joint("mount", "base", "arm::upper", axis="1 0 0"))


def test_flattened_model_frames_resolve(tmp_path):
    _path, urdf, result = convert(tmp_path, FLATTENED)
    assert result.code == 0, result.err
    assert "sdf.missing-frame" not in result.err
    nested = tmp_path / "nested.sdf"
    nested.write_text(NESTED)
    assert_matches(compare(nested, urdf))


def test_missing_frame_hint_does_not_repeat_the_name(tmp_path):
    text = FLATTENED.replace('relative_to="arm::__model__">0 0 1.2', 'relative_to="arm::__modle__">0 0 1.2')
    _, _, result = convert(tmp_path, text)
    assert " error sdf.missing-frame: relative_to 'arm::__modle__'" in result.err
    assert "did you mean 'arm::__model__'?" in result.err
    assert "did you mean 'arm::__modle__'" not in result.err


# -- 5. include URIs given as a bare model name ---------------------------------------------------


@pytest.mark.parametrize("how", ["--model-path", "GZ_SIM_RESOURCE_PATH", "SDF_PATH"])
def test_bare_model_name_include_is_found_on_the_model_paths(tmp_path, how, monkeypatch):
    models = tmp_path / "models"
    (models / "my_wheel").mkdir(parents=True)
    (models / "my_wheel" / "model.config").write_text(
        "<model><name>my_wheel</name><sdf version='1.7'>wheel.sdf</sdf></model>")
    (models / "my_wheel" / "wheel.sdf").write_text(sdf(link("tyre", "0 0 0 1.5707963267948966 0 0"),
                                                       name="my_wheel"))
    text = sdf(link("chassis") + "<include><uri>my_wheel</uri><name>left</name>"
               "<pose>0 0.3 0 0 0 0</pose></include>"
               + joint("axle", "chassis", "left::tyre", axis="0 1 0"), version="1.8")
    work = tmp_path / "work"
    work.mkdir()
    extra = []
    if how == "--model-path":
        extra = ["--model-path", str(models)]
    else:
        monkeypatch.setenv(how, str(models))
    _path, urdf, result = convert(work, text, *extra)
    assert result.code == 0, result.err
    assert "sdf.include" not in result.err and 'link name="left__tyre"' in urdf
    # Drake resolves model://NAME through its package map: it loads the same model that way
    by_uri = work / "by_uri.sdf"
    by_uri.write_text(text.replace("<uri>my_wheel</uri>", "<uri>model://my_wheel/wheel.sdf</uri>"))
    assert_matches(compare(by_uri, urdf, model_paths=(models,)))


# -- every SDF model of the corpus -----------------------------------------------------------------


def corpus() -> list[tuple[Path, str | None]]:
    from test_sdf_convert import all_models

    return [(path, model) for path, model, _ in all_models()]


# Drake cannot load these, for reasons that are not the conversion's (asserted, not skipped):
DRAKE_REFUSES = {
    "link name [world] is reserved",  # pybullet_data's wsg50 grippers name a link 'world'
    "Joint type (gearbox) not supported",
    "form one or more loops",  # Drake has no loops; the loop tests above open them by hand
    "Non-unique name[lbr_iiwa]",  # kuka_iiwa/model2.sdf: two models of one name in a world
    "collision with name[pod_collision] already exists",  # kiva_shelf: libsdformat refuses it
}


@pytest.mark.parametrize("path,model", corpus(),
                         ids=lambda v: v.name if isinstance(v, Path) else (v or ""))
def test_corpus_matches_drake(path, model, tmp_path):
    models = (Path(__file__).parent / "data" / "sdf" / "models",)
    args = ["--model-path", str(models[0])] + (["--model", model] if model else [])
    out = tmp_path / "robot.urdf"
    result = run_urdftool("convert", path, "-o", out, *args)
    assert result.code == 0, result.err
    urdf = out.read_text()
    copy, sdf_plant = drake_copy(path, tmp_path, models, model)
    if isinstance(sdf_plant, RuntimeError):
        assert any(reason in str(sdf_plant) for reason in DRAKE_REFUSES), sdf_plant
        return
    report = compare(copy, urdf, model=model, plant=sdf_plant)
    for key in ("pose", "mass", "com", "inertia"):
        assert report[key] < TOL, report
    # no floating joint where the SDF attached the link: each link urdftool hangs by a
    # floating joint is one Drake made a free body from the SDF
    for joint in etree.fromstring(urdf.encode()).iter("joint"):
        if joint.get("type") == "floating":
            child = joint.find("child").get("link")
            key = next(k for k in sdf_plant.bodies if k.replace("::", "__") == child)
            assert sdf_plant.bodies[key].is_floating(), child


@pytest.mark.parametrize("version", ["1.6", "1.7"])
def test_two_links_of_one_name_are_refused_and_one_is_written(tmp_path, version):
    """Two links (or two joints) of one name: libsdformat refuses the model in every version
    and keeps the first; the URDF must not hold two links of one name either."""
    text = sdf(link("base") + link("arm", "1 0 0 0 0 0") + link("arm", "2 0 0 0 0 0")
               + joint("j", "base", "arm") + joint("j", "base", "arm", "prismatic"),
               version=version)
    path, urdf, result = convert(tmp_path, text)
    assert result.code == 1
    assert result.err.count(" error sdf.duplicate-name: ") == 2
    with pytest.raises(RuntimeError, match=r"Non-unique name\[arm\]"):
        Plant(path=path)
    root = etree.fromstring(urdf.encode())
    assert [l.get("name") for l in root.iter("link")] == ["base", "arm"]
    assert [(j.get("name"), j.get("type")) for j in root.iter("joint")] == [("j", "revolute")]


# -- 7. an included model placed by its <include><pose>, joined by a joint written reversed -----


def _model(models: Path, name: str, body: str, version: str = "1.5") -> None:
    (models / name).mkdir(parents=True)
    (models / name / "model.config").write_text(
        f'<model><name>{name}</name><sdf version="{version}">model.sdf</sdf></model>')
    (models / name / "model.sdf").write_text(sdf(body, version, name))


@pytest.mark.parametrize("nested", [False, True])
def test_include_pose_overrides_the_model_pose_through_a_reversed_joint(tmp_path, nested):
    """issue 22.7, the shape of a real Gazebo model (SDFormat 1.5): an arm model whose own
    <pose> puts it 0.3 m up is included with an <include><pose> that replaces that pose, and is
    joined to the parent by a joint whose parent is the included link while the child already
    hangs on another joint, so URDF writes it reversed (its origin inverted through the
    included link's frame, which the include's pose placed). Nested: the arm is included by a
    rig model that is itself included with a pose. Drake's libsdformat is the oracle."""
    models = tmp_path / "models"
    arm = ("<pose>0 0 0.3 0 0 0.4</pose>" + link("upper", "0.1 0.02 0.05 0.1 0.2 0")
           + link("lower", "0.3 0 0.05 0 0 0")
           + joint("elbow", "upper", "lower", axis="1 0 0", pose="0.03 0.01 -0.02 0.2 0 0.1"))
    _model(models, "arm", arm)
    include = "<include><uri>model://arm</uri><pose>0.5 0.1 0.2 0 0.3 0</pose></include>"
    prefix = "arm::"
    if nested:
        _model(models, "rig", "<pose>0.3 0 0 0 0.2 0</pose>" + link("frame", "0 0.1 0 0 0 0")
               + include + joint("rig_joint", "frame", "arm::upper", axis="0 1 0"))
        include = "<include><uri>model://rig</uri><pose>0 0.4 0.1 0.3 0 0</pose></include>"
        prefix = "rig::arm::"
    text = sdf(link("base", "0 0 0.1 0 0 0") + link("plate", "0.2 0 0.2 0 0 0")
               + joint("spin", "base", "plate")
               + include
               + joint("mount", f"{prefix}lower", "plate", axis="1 0 0",
                       pose="0.03 0.01 -0.02 0.2 0 0.1"), version="1.5", name="robot")
    _path, urdf, result = convert(tmp_path, text, "--model-path", str(models))
    assert result.code == 0, result.err
    assert "joint 'mount' is written reversed" in result.err
    # Drake resolves model://NAME/FILE through its package map
    by_file = tmp_path / "by_file.sdf"
    by_file.write_text(text.replace("<uri>model://arm</uri>", "<uri>model://arm/model.sdf</uri>")
                       .replace("<uri>model://rig</uri>", "<uri>model://rig/model.sdf</uri>"))
    if nested:
        rig = models / "rig" / "model.sdf"
        rig.write_text(rig.read_text().replace("<uri>model://arm</uri>",
                                               "<uri>model://arm/model.sdf</uri>"))
    assert_matches(compare(by_file, urdf, model_paths=(models,)))
