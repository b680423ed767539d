"""Issue 28.4: the rules inside the run budget, and the rules that walk chains and references
in linear time. Hostile files of each kind (a mimic chain, fixed-joint chains, unknown
``<gazebo reference>``s, transmission, mimic, material and link names that are not defined:
each one did-you-mean over every name, a walk per joint or per link) are checked through
``urdftool check`` as the hook and the Action run it (``CI=true``: untrusted), each in its own
process, whose CPU time and peak memory are read from ``wait4`` (the process and the sandboxed
reader it waited for).

- Linear: at N and 2N the run's CPU time grows at most ~2x (quadratic: ~4x), every finding is
  there (the rules ran to the end, not stopped by the budget), and it stays under a few seconds
  of CPU (today's code: 7 to 20 s at 3000, killed at CPU_KILL).
- ``--timeout 1``: every run ends within the budget's CPU, under MEMORY_MB, exit 0 or 1, no
  traceback; the rules either all ran or say so in ONE finding.
- A rule that spins is stopped at the budget: one ``xacro.limit-exceeded`` finding naming it
  and the rules not run (``rules.run``, the one function that runs rules).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

URDFTOOL = [sys.executable, "-m", "urdftool"]
INERT = ('<inertial><mass value="{m}"/><inertia ixx="{i}" iyy="{i}" izz="{i}" ixy="0" ixz="0" '
         'iyz="0"/></inertial>')
LIMIT = '<limit lower="0" upper="1" effort="1" velocity="1"/>'
SIZE = 1500  # N; the linear test also checks 2N
CPU_KILL = 25  # seconds of CPU after which a run is killed (today's code on 2N)
LINEAR_CPU = 8.0  # seconds of CPU for a run at 2N (start-up, reading, every rule)
STARTUP = 4.0  # CPU beyond 2 x --timeout for a --timeout 1 run (imports, the reader's start)
MEMORY_MB = 400


def _robot(parts) -> str:
    return '<robot name="r">\n' + "\n".join(parts) + "\n</robot>\n"


def mimic_chain(n):  # each joint mimics the one before: chained mimics, N findings
    parts = ['<link name="l0"/>']
    for i in range(1, n + 1):
        mimic = f'<mimic joint="j{i - 1}"/>' if i > 1 else ""
        parts += [f'<link name="l{i}"/>', (f'<joint name="j{i}" type="revolute"><parent '
                                           f'link="l0"/><child link="l{i}"/>{LIMIT}{mimic}</joint>')]
    return _robot(parts), "mimic.chained", n - 2


def fixed_chain_tensors(n):  # tensors impossible for their geometry, merged along the chain
    parts = [f'<link name="l0">{INERT.format(m=1, i=1)}</link>']
    for i in range(1, n + 1):
        parts += [(f'<link name="l{i}">{INERT.format(m=0.001, i=10)}<collision><geometry><box '
                   'size="0.01 0.01 0.01"/></geometry></collision></link>'),
                  (f'<joint name="j{i}" type="fixed"><parent link="l{i - 1}"/><child '
                   f'link="l{i}"/></joint>')]
    return _robot(parts), "inertia.exceeds-geometry", n


def fixed_chain_massless(n):  # mass 0 with inertia, each asking whether its body is static
    parts = [f'<link name="l0">{INERT.format(m=1, i=1)}</link>']
    for i in range(1, n + 1):
        parts += [f'<link name="l{i}">{INERT.format(m=0, i=1)}</link>',
                  (f'<joint name="j{i}" type="fixed"><parent link="l{i - 1}"/><child '
                   f'link="l{i}"/></joint>')]
    return _robot(parts), "inertia.mass-not-positive", n


def _links(n):
    return [f'<link name="link_{i}"/>' for i in range(n)] + [
        f'<joint name="joint_{i}" type="revolute"><parent link="link_0"/><child '
        f'link="link_{i}"/>{LIMIT}</joint>' for i in range(1, n)]


def gazebo_references(n):
    return (_robot(_links(n) + [f'<gazebo reference="lnk_x{i}"><mu1>1</mu1></gazebo>'
                                for i in range(n)]), "gazebo.unknown-reference", n)


def transmission_joints(n):
    return (_robot(_links(n) + [
        f'<transmission name="t{i}"><type>transmission_interface/SimpleTransmission</type>'
        f'<joint name="jnt_x{i}"><hardwareInterface>EffortJointInterface</hardwareInterface>'
        f'</joint><actuator name="m{i}"><mechanicalReduction>1</mechanicalReduction>'
        '</actuator></transmission>' for i in range(n)]), "transmission.unknown-joint", n)


def mimic_leaders(n):
    parts = ['<link name="l0"/>']
    for i in range(1, n + 1):
        parts += [f'<link name="l{i}"/>', (
            f'<joint name="joint_{i}" type="revolute"><parent link="l0"/><child link="l{i}"/>'
            f'{LIMIT}<mimic joint="jnt_x{i}"/></joint>')]
    return _robot(parts), "mimic.unknown-joint", n


def joint_links(n):
    return (_robot(['<link name="l0"/>'] + [f'<link name="link_{i}"/>' for i in range(n)] + [
        f'<joint name="j{i}" type="fixed"><parent link="l0"/><child link="lnk_x{i}"/></joint>'
        for i in range(n)]), "structure.missing-link", n)


def materials(n):
    return (_robot([f'<material name="mat_{i}"><color rgba="1 0 0 1"/></material>'
                    for i in range(n)] + [
        f'<link name="l{i}"><visual><geometry><box size="1 1 1"/></geometry><material '
        f'name="mt_x{i}"/></visual></link>' for i in range(n)] + [
        f'<joint name="j{i}" type="fixed"><parent link="l0"/><child link="l{i}"/></joint>'
        for i in range(1, n)]), "material.undefined", n)


def two_parents(n):  # a chain whose every link has a second parent joint from no link:
    # the links below each walked per joint, cut-off links walked to the top per link
    parts = ['<link name="l0"/>'] + [f'<link name="l{i}"/>' for i in range(1, n + 1)]
    parts += [f'<joint name="k{i}" type="fixed"><parent link="l{i}"/><child link="l{i + 1}"/>'
              '</joint>' for i in range(1, n)]
    parts += [f'<joint name="j{i}" type="fixed"><parent link="zz_missing_{i}"/><child '
              f'link="l{i}"/></joint>' for i in range(1, n + 1)]
    return _robot(parts), "structure.missing-link", n


def two_parents_masses(n):  # the same chain: the inertia rules' subtree masses
    return two_parents(n)[0], "inertia.massless-moving-link", 0


CASES = [two_parents, two_parents_masses, mimic_chain, fixed_chain_tensors, fixed_chain_massless, gazebo_references,
         transmission_joints, mimic_leaders, joint_links, materials]


# Linux keeps a process's peak RSS across fork and exec (ru_maxrss starts at its parent's
# RSS when forked): a run forked from a pytest worker that grew to 1.4 GB "peaked" at 1.4 GB.
# So a small launcher (its own fresh, small memory after exec) starts the run and reports the
# run's wait4: the peak is the run's own.
LAUNCHER = """
import json, os, resource, subprocess, sys
cpu_kill = int(sys.argv[1])
def limit():
    resource.setrlimit(resource.RLIMIT_CPU, (cpu_kill, cpu_kill + 1))
process = subprocess.Popen(sys.argv[2:], preexec_fn=limit, stderr=subprocess.STDOUT)
_, status, usage = os.wait4(process.pid, 0)
process.returncode = 0  # reaped by wait4: Popen must not wait again
print(json.dumps([os.waitstatus_to_exitcode(status), usage.ru_utime + usage.ru_stime,
                  usage.ru_maxrss]), file=sys.stderr)
"""


def measured(args: list[str], cwd) -> dict:
    """``urdftool ARGS`` as the Action runs it (CI=true), in its own process: exit code,
    output, CPU seconds and peak MB of it and the children it waited for (``wait4``, through
    ``LAUNCHER``), killed at CPU_KILL seconds of CPU."""
    env = {**os.environ, "CI": "true", "NO_COLOR": "1"}
    env.pop("URDFTOOL_CACHE_DIR", None)

    with tempfile.TemporaryFile() as out:
        process = subprocess.Popen([sys.executable, "-c", LAUNCHER, str(CPU_KILL), *URDFTOOL,
                                    *args], stdout=out, stderr=subprocess.PIPE, cwd=cwd, env=env,
                                   start_new_session=True)
        try:
            _, report = process.communicate(timeout=CPU_KILL * 8)  # wall: a loaded machine;
        except subprocess.TimeoutExpired:  # RLIMIT_CPU ends a spinning run
            os.killpg(process.pid, 9)
            _, report = process.communicate()
        out.seek(0)
        text = out.read().decode("utf-8", "replace")
    code, cpu, peak = json.loads(report.decode().strip().splitlines()[-1])
    return {"code": code, "out": text, "cpu": cpu, "peak_mb": peak / 1024}


def _write(tmp_path: Path, case, n: int) -> tuple[Path, str, int]:
    text, rule, count = case(n)
    path = tmp_path / f"{case.__name__}_{n}.urdf"
    path.write_text(text, encoding="utf-8")
    return path, rule, count


def _counted(out: str, rule: str) -> tuple[int, list[str]]:
    data = json.loads(out)
    diagnostics = [d for f in data["files"] for d in f["diagnostics"]]
    late = [d["message"] for d in diagnostics if "ran out of time" in d["message"]]
    omitted = sum(f.get("omitted", {}).get(rule, 0) for f in data["files"])  # past 200 listed
    return sum(d["rule"] == rule for d in diagnostics) + omitted, late


# make test runs three kinds (chains, references); every kind in CI (`slow`): the
# --timeout 1 test below runs each kind once in make test
FAST = (mimic_chain, fixed_chain_tensors, gazebo_references)


@pytest.mark.parametrize("case", [c if c in FAST else pytest.param(c, marks=pytest.mark.slow)
                                  for c in CASES], ids=[c.__name__ for c in CASES])
def test_rules_walking_chains_and_names_are_linear(case, tmp_path):
    runs = {}
    for n in (SIZE, 2 * SIZE):
        path, rule, count = _write(tmp_path, case, n)
        # --timeout 60: the budget does not stop the rules; they end on their own
        run = measured(["check", "--no-cache", "--timeout", "60", "--format", "json",
                        "--select", rule.split(".")[0], path.name], tmp_path)
        assert run["code"] in (0, 1) and run["cpu"] < CPU_KILL, (n, run["cpu"], run["out"][-500:])
        found, late = _counted(run["out"], rule)
        assert not late and found == count, (n, found, count, late)
        runs[n] = run
    small, large = runs[SIZE]["cpu"], runs[2 * SIZE]["cpu"]
    assert large < LINEAR_CPU, (small, large)
    assert large / small < 3.0, (small, large)  # linear ~2x (less: start-up), quadratic ~4x
    assert runs[2 * SIZE]["peak_mb"] < MEMORY_MB, runs[2 * SIZE]["peak_mb"]


@pytest.mark.slow  # every hostile file through every command (~10 s of CPU): CI
def test_every_hostile_file_holds_with_timeout_1(tmp_path):
    """Every kind at 2N, ``--timeout 1`` (every rule, not only the family): within the
    budget's CPU and MEMORY_MB; the rules all ran, or ONE finding says which rule ran out and
    that the rest were not run."""
    failures = []
    for case in CASES:
        path, rule, count = _write(tmp_path, case, 2 * SIZE)
        run = measured(["check", "--no-cache", "--timeout", "1", "--format", "json",
                        path.name], tmp_path)
        problems = []
        if run["code"] not in (0, 1) or "Traceback" in run["out"]:
            problems.append(f"exit {run['code']}")
        if run["cpu"] > 2 * 1 + STARTUP:
            problems.append(f"{run['cpu']:.1f} s of CPU")
        if run["peak_mb"] > MEMORY_MB:
            problems.append(f"{run['peak_mb']:.0f} MB")
        if not problems:
            found, late = _counted(run["out"], rule)
            if len(late) > 1 or (not late and found != count):
                problems.append(f"{found} of {count} findings, {len(late)} out-of-time")
            if late and not ("rule(s) after it were not run" in late[0]
                             or "every other rule was run" in late[0]):
                problems.append(late[0])
        if problems:
            failures.append(f"{case.__name__}: {', '.join(problems)}")
    assert not failures, failures


def test_a_spinning_rule_is_one_finding_within_the_budget(write):
    """The one rules runner stops a rule that does not end: its findings so far, then one
    error naming it and the rules after it, within the time it was given (CPU)."""
    from urdftool.loader import load
    from urdftool.model import build_robot
    from urdftool.rules import REGISTRY, Rule, load_all, run
    from urdftool.source import LoadOptions

    load_all()
    robot = build_robot(load(write('<robot name="r"><link name="a"/></robot>', "r.urdf"),
                             LoadOptions()))
    ran_after = []

    def spin(robot):
        from urdftool.findings import Finding

        yield Finding("before spinning", None)
        while True:
            pass

    def after(robot):
        ran_after.append(True)
        return []

    spinning = Rule("joint.spin", "warning", "", "", "", "", spin)
    later = Rule("joint.after", "warning", "", "", "", "", after)
    started = time.process_time()
    ran = run(robot, [(spinning, "warning"), (later, "warning"),
                      (REGISTRY["structure.loop"], "error")], seconds=0.5)
    assert time.process_time() - started < 2.0
    assert not ran_after
    assert ran[0].finding.message == "before spinning"
    last = ran[-1]
    assert len(ran) == 2 and last.rule.id == "xacro.limit-exceeded" and last.severity == "error"
    assert "rule joint.spin ran out of time" in last.finding.message
    assert "the 2 rule(s) after it were not run (joint.after, structure.loop)" \
        in last.finding.message
