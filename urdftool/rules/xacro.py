"""Rules of the `xacro` family: what xacro reports while expanding, located in the .xacro
source, and old-style xacro usage that modern xacro silently ignores."""

from __future__ import annotations

from urdftool.rules import source_rule

source_rule(
    "xacro.error", "error", "xacro cannot expand the file",
    doc="""xacro stopped: an undefined property or macro, a bad expression, a missing include,
    wrong macro parameters. Nothing after this point was expanded, so the robot is checked
    incompletely until this is fixed.""",
    bad='<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">\n'
        '  <link name="${base}"/>\n</robot>',
    good='<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">\n'
         '  <xacro:property name="base" value="base_link"/>\n  <link name="${base}"/>\n</robot>',
)
