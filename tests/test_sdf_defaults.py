"""issue 29: SDFormat's default inertial (a link without <inertial> is 1 kg with 1 kg·m²), judged
by consequence: nothing on a static model (Gazebo never integrates it), the share of the
simulated mass elsewhere, and the inertia rules say the value is SDFormat's, not the author's."""

from __future__ import annotations

from urdftool.check import CheckOptions, check_file
from urdftool.source import LoadOptions


def findings(path):
    return check_file(path, CheckOptions(select=["inertia", "sdf"], load=LoadOptions())).diagnostics


def sdf(model: str) -> str:
    return f'<?xml version="1.0"?>\n<sdf version="1.9">\n{model}\n</sdf>\n'


BOX = '<visual name="v"><geometry><box><size>0.1 0.1 0.1</size></box></geometry></visual>'


def frame_link(name: str) -> str:
    return (f'<link name="{name}"><pose>0 0 0.05 0 0 0</pose>{BOX}</link>'
            f'<joint name="{name}_joint" type="fixed"><parent>base</parent>'
            f'<child>{name}</child></joint>')


def test_static_model_default_inertials_are_not_judged(write):
    path = write(sdf('<model name="shelf"><static>true</static>'
                     f'<link name="base">{BOX}</link><link name="top">{BOX}</link>'
                     '<joint name="j" type="fixed"><parent>base</parent><child>top</child></joint>'
                     '</model>'), "shelf.sdf")
    got = [(d.rule, d.severity) for d in findings(path)]
    assert not [r for r in got if r[0].startswith("inertia.") or r[0] == "sdf.default-inertial"], got


def test_default_masses_that_dominate_the_model_are_an_error(write):
    # a 1.4 kg robot with three frame links without <inertial>: Gazebo simulates 4.4 kg,
    # 3 / 4.4 = 68% of it nobody wrote
    base = ('<link name="base"><inertial><mass>1.4</mass><inertia><ixx>0.0023</ixx>'
            '<iyy>0.0023</iyy><izz>0.0023</izz></inertia></inertial>' + BOX + '</link>')
    path = write(sdf('<model name="bot">' + base + frame_link("camera") + frame_link("imu")
                     + frame_link("lidar") + '</model>'), "bot.sdf")
    defaults = [d for d in findings(path) if d.rule == "sdf.default-inertial"]
    assert len(defaults) == 3 and {d.severity for d in defaults} == {"error"}
    share = 3 / (1.4 + 3)
    assert f"{share:.0%} of its mass in Gazebo" in defaults[0].message
    assert "add 3 kg to the 1.4 kg" in defaults[0].message


def test_one_default_mass_on_a_heavy_robot_is_advice(write):
    base = ('<link name="base"><inertial><mass>20</mass><inertia><ixx>0.033</ixx>'
            '<iyy>0.033</iyy><izz>0.033</izz></inertia></inertial>' + BOX + '</link>')
    path = write(sdf('<model name="bot">' + base + frame_link("camera") + '</model>'), "heavy.sdf")
    (d,) = [d for d in findings(path) if d.rule == "sdf.default-inertial"]
    assert d.severity == "info" and f"{1 / 21:.0%}" in d.message  # 5%


def test_inertia_findings_on_a_default_say_it_is_sdformats(write):
    path = write(sdf(f'<model name="box"><link name="base">{BOX}</link></model>'), "box.sdf")
    got = {d.rule: d for d in findings(path)}
    assert got["sdf.default-inertial"].severity == "warning"  # no link declares one
    bound = got["inertia.exceeds-geometry"]
    assert "SDFormat's default" in bound.message and "placeholder" not in bound.message
