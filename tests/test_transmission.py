"""The `transmission` rules: ros_control transmissions and ros2_control blocks."""

from __future__ import annotations

from urdftool.check import CheckOptions, check_file

ROBOT = """<robot name="r">
  <link name="a"/><link name="b"/>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
"""


def found(write, text: str):
    report = check_file(write(text), CheckOptions(select=["transmission"]))
    return report.diagnostics


def transmission(joint="j", interface="hardware_interface/EffortJointInterface",
                 reduction="1", actuator=True, kind="transmission_interface/SimpleTransmission"):
    hw = f"<hardwareInterface>{interface}</hardwareInterface>" if interface is not None else ""
    type_xml = f"<type>{kind}</type>" if kind else ""
    act = (f'<actuator name="m"><mechanicalReduction>{reduction}</mechanicalReduction>'
           "</actuator>") if actuator else ""
    return f'  <transmission name="t">{type_xml}\n    <joint name="{joint}">{hw}</joint>\n    ' \
           f"{act}\n  </transmission>\n"


def test_complete_transmission_is_quiet(write):
    assert found(write, ROBOT + transmission() + "</robot>\n") == []
    assert found(write, ROBOT + transmission(interface="effort") + "</robot>\n") == []
    # a vendor's own interface is not ours to judge
    assert found(write, ROBOT + transmission(interface="franka_hw/FrankaStateInterface")
                 + "</robot>\n") == []


def test_unknown_joint(write):
    diagnostics = found(write, ROBOT + transmission(joint="b") + "</robot>\n")
    assert [(d.rule, d.line) for d in diagnostics] == [("transmission.unknown-joint", 6)]
    assert "joint that moves it is 'j'" in diagnostics[0].hint


def test_incomplete(write):
    text = ROBOT + transmission(actuator=False, kind="") + "</robot>\n"
    diagnostics = found(write, text)
    assert [(d.rule, d.line) for d in diagnostics] == [("transmission.incomplete", 5)]
    assert "<type>" in diagnostics[0].message and "<actuator" in diagnostics[0].message


def test_pre_hydro_transmissions_are_not_held_to_the_new_form(write):
    text = ROBOT + ('  <transmission name="w" type="pr2_mechanism_model/PR2WristTransmission">\n'
                    '    <rightActuator name="r"/><leftActuator name="l"/>\n'
                    '    <flexJoint name="j" mechanicalReduction="1"/>\n'
                    "  </transmission>\n</robot>\n")
    assert found(write, text) == []


def test_hardware_interfaces(write):
    text = ROBOT + transmission(interface=None) + \
        transmission(interface="hardware_interface/EffortJointInterfase") + \
        transmission(interface="EffortJointInterface") + "</robot>\n"
    diagnostics = found(write, text)
    assert [(d.rule, d.severity, d.line) for d in diagnostics] == [
        ("transmission.hardware-interface", "error", 6),
        ("transmission.hardware-interface", "warning", 10),
        ("transmission.hardware-interface", "info", 14)]
    assert "EffortJointInterface'" in diagnostics[1].hint
    assert "deprecated" in diagnostics[2].message


def test_reduction(write):
    text = ROBOT + transmission(reduction="0") + transmission(reduction="reduction") + \
        "</robot>\n"
    diagnostics = found(write, text)
    # 'reduction' (a leftover xacro parameter name) is schema.bad-number, not ours
    assert [(d.rule, d.line) for d in diagnostics] == [("transmission.zero-reduction", 7)]


def test_ros2_control_joints(write):
    text = ROBOT + """  <ros2_control name="sys" type="system">
    <hardware><plugin>mock_components/GenericSystem</plugin></hardware>
    <joint name="j"><command_interface name="position"/></joint>
    <joint name="jj"><command_interface name="position"/></joint>
  </ros2_control>
</robot>
"""
    diagnostics = found(write, text)
    assert [(d.rule, d.line) for d in diagnostics] == [("transmission.ros2-control-joint", 8)]
    assert "did you mean 'j'" in diagnostics[0].hint
