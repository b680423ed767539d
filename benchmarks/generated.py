"""Generated robots of any size for the scaling benchmark and the big-input tests: a serial
chain (every link the child of the previous one) and a branching tree (link i hangs from link
(i - 1) // 3), primitive geometry, a revolute joint with limits per link."""

from __future__ import annotations


def robot_text(n_links: int, shape: str = "chain") -> str:
    """The URDF of a ``shape`` ("chain" or "tree") robot with ``n_links`` links."""
    parts = [f"<?xml version=\"1.0\"?>\n<robot name=\"gen_{shape}_{n_links}\">\n"]
    link = ('  <link name="l%d">\n'
            '    <inertial><origin xyz="0 0 0.05"/><mass value="1"/>'
            '<inertia ixx="0.0010833" ixy="0" ixz="0" iyy="0.0010833" iyz="0" izz="0.00041667"/>'
            '</inertial>\n'
            '    <visual><origin xyz="0 0 0.05"/><geometry><box size="0.05 0.05 0.1"/></geometry>'
            '</visual>\n'
            '    <collision><origin xyz="0 0 0.05"/><geometry><box size="0.05 0.05 0.1"/>'
            '</geometry></collision>\n'
            '  </link>\n')
    joint = ('  <joint name="j%d" type="revolute">\n'
             '    <parent link="l%d"/><child link="l%d"/><origin xyz="0 0 0.1" rpy="0 0 %s"/>\n'
             '    <axis xyz="%s"/><limit lower="-1.5" upper="1.5" effort="10" velocity="2"/>\n'
             '  </joint>\n')
    for i in range(n_links):
        parts.append(link % i)
        if i:
            parent = i - 1 if shape == "chain" else (i - 1) // 3
            parts.append(joint % (i, parent, i, "0.3" if i % 2 else "0",
                                  "0 1 0" if i % 2 else "1 0 0"))
    parts.append("</robot>\n")
    return "".join(parts)


def sdf_text(n_links: int, shape: str = "chain") -> str:
    """The SDFormat 1.7 model of the same robot (for ``convert``)."""
    parts = [f'<?xml version="1.0"?>\n<sdf version="1.7">\n<model name="gen_{shape}_{n_links}">\n']
    link = ('  <link name="l%d"><pose relative_to="j%d">0 0 0 0 0 0</pose>\n'
            '    <inertial><pose>0 0 0.05 0 0 0</pose><mass>1</mass><inertia><ixx>0.0010833</ixx>'
            '<iyy>0.0010833</iyy><izz>0.00041667</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz>'
            '</inertia></inertial>\n'
            '    <collision name="c"><pose>0 0 0.05 0 0 0</pose><geometry><box><size>0.05 0.05 0.1'
            '</size></box></geometry></collision>\n'
            '  </link>\n')
    joint = ('  <joint name="j%d" type="revolute"><parent>l%d</parent><child>l%d</child>\n'
             '    <pose relative_to="l%d">0 0 0.1 0 0 %s</pose>\n'
             '    <axis><xyz>%s</xyz><limit><lower>-1.5</lower><upper>1.5</upper>'
             '<effort>10</effort><velocity>2</velocity></limit></axis>\n'
             '  </joint>\n')
    for i in range(n_links):
        if i:
            parent = i - 1 if shape == "chain" else (i - 1) // 3
            parts.append(joint % (i, parent, i, parent, "0.3" if i % 2 else "0",
                                  "0 1 0" if i % 2 else "1 0 0"))
            parts.append(link % (i, i))
        else:
            parts.append((link % (0, 0)).replace('<pose relative_to="j0">', "<pose>"))
    parts.append("</model>\n</sdf>\n")
    return "".join(parts)
