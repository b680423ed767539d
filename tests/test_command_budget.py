"""Issue 21: a one-file command (limits, tree, inertia, dh, jacobian, sim) reads its file as
check does, through its safe fixes: the first reading, the fix rounds and the last reading
share one run budget (--timeout for the file and one for the start), never a full --timeout
each."""

from __future__ import annotations

from tests.conftest import WallLessWaiting, run_urdftool

# an expansion that only the deadline stops (2**40 macro calls): no robot comes of the first
# reading, so the command reads it again through the safe-fix rounds, then once more
FLOOD = """<?xml version="1.0"?>
<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="t" params="n"><xacro:if value="${n > 0}"><xacro:t n="${n-1}"/>
    <xacro:t n="${n-1}"/></xacro:if></xacro:macro>
  <xacro:t n="40"/>
  <link name="base"/>
</robot>
"""


def test_the_readings_of_one_command_share_one_budget(tmp_path):
    path = tmp_path / "flood.urdf.xacro"
    path.write_text(FLOOD)
    timeout = 1.0
    with WallLessWaiting() as clock:  # the deadlines are wall time: less the machine's load
        result = run_urdftool("limits", "--trusted", "--timeout", str(timeout), str(path))
    spent = clock.seconds
    assert result.code == 1 and "xacro.limit-exceeded" in result.err
    # the first reading, the fix rounds and the last took a full --timeout each before (3 s)
    assert spent < 2 * timeout + 0.6, spent
