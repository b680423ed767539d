"""Fuzzing in the default suite: hypothesis mutates real robots (the seeds in robots/, the xacro
corpus, small pybullet_data URDFs) with urdftool.fuzz's mutations and runs ``check`` plus one of
``limits``/``inertia``/``tree``; each must answer with a report or one clean exit-2 line, never a
traceback or an internal error, within a time bound. ``make fuzz`` runs 10 000 cases."""

from __future__ import annotations

import json
import random
import tempfile
import warnings
from pathlib import Path

import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from urdftool import fuzz

SEEDS = fuzz.seeds(include_pybullet=True, limit_pybullet=12)
TEXTS = {path: path.read_text(encoding="utf-8") for path in SEEDS}
# The in-suite run keeps nesting shallow: thousands-deep files are make fuzz's business (slow).
SHALLOW = [m for m in fuzz.MUTATIONS if m is not fuzz.deep_nesting]


@pytest.fixture(scope="module")
def workspace():
    space = fuzz.Workspace()
    yield space
    space.cleanup()


def _assert_fine(outcomes, path: Path):
    for outcome in outcomes:
        if outcome.problem is None:
            continue
        keep = Path(tempfile.mkdtemp(prefix="urdftool-fuzz-crash-")) / path.name
        keep.write_bytes(path.read_bytes())
        pytest.fail(f"urdftool {' '.join(outcome.command[:-1])} {keep}: {outcome.problem} "
                    f"(reproducer saved; it may include files next to {path})\n"
                    f"{outcome.err[-2000:]}")


@pytest.mark.slow  # 120 mutated robots (~16 s CPU): CI; make test keeps the xacro mutants below
@settings(max_examples=120, deadline=None, derandomize=True, database=None,
          phases=[Phase.explicit, Phase.generate],  # no shrinking: the reproducer is saved
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(seed=st.sampled_from(SEEDS), rng=st.randoms(use_true_random=False),
       count=st.integers(1, 4), command=st.sampled_from(fuzz.COMMANDS))
def test_mutated_robots_never_crash(workspace, seed, rng, count, command):
    text = TEXTS[seed]
    for _ in range(count):
        text = rng.choice(SHALLOW)(text, rng)
    path = workspace.write(seed, text)
    _assert_fine(fuzz.run_case(path, command, bound=30.0), path)


@pytest.mark.parametrize("mutation", fuzz.MUTATIONS, ids=lambda m: m.__name__)
def test_every_mutation_changes_text_and_stays_text(mutation):
    rng = random.Random(4)
    text = TEXTS[SEEDS[0]]
    changed = [mutation(text, rng) for _ in range(20)]
    assert any(c != text for c in changed)
    assert all(isinstance(c, str) for c in changed)


def test_untrusted_xacro_mutants_never_crash(workspace):
    xacros = [p for p in SEEDS if p.name.endswith(".xacro")]
    rng = random.Random(8)
    for number in range(6):  # each command twice, sandboxed (~1 s a case); CI runs 120 above
        seed = xacros[number % len(xacros)]
        text, _ = fuzz.mutate(TEXTS[seed], rng)
        path = workspace.write(seed, text)
        _assert_fine(fuzz.run_case(path, fuzz.COMMANDS[number % 3], untrusted=True, bound=30.0),
                     path)


def test_judge_catches_what_counts_as_a_crash():
    assert fuzz.judge(["tree", "x"], 2, "", "urdftool: x: no such file\n") is None
    assert fuzz.judge(["tree", "x"], 2, "", "Traceback (most recent call last):\n...") \
        == "a Python traceback"
    assert fuzz.judge(["tree", "x"], 2, "", "urdftool: internal error: KeyError: 'a'\n")
    assert fuzz.judge(["tree", "x"], 2, "", "urdftool: a\nb\n")  # not one line
    report = ('{"files": [{"diagnostics": [{"rule": "joint.x", "message": '
              '"internal error in rule joint.x: ZeroDivisionError"}]}]}')
    assert "joint.x" in fuzz.judge(["check", "--format", "json", "x"], 1, report, "")
    assert fuzz.judge(["check", "--format", "json", "x"], 1, "not json", "")
    assert fuzz.judge(["tree", "x"], -1, "", "")


# -- regressions: sizes, scales and places at the ends of the float range --------------------

_CUBE_STL = "solid cube\n" + "".join(
    " facet normal 0 0 0\n  outer loop\n" + "".join(
        f"   vertex {(v >> 2) & 1} {(v >> 1) & 1} {v & 1}\n" for v in face)
    + "  endloop\n endfacet\n"
    for face in ((0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7),
                 (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3))) + "endsolid cube\n"
EXTREME_SHAPES = {
    "box-1e309": '<box size="1e309 1 1"/>', "box-1e308": '<box size="1e308 1e308 1e308"/>',
    "box-inf": '<box size="inf 1 1"/>', "box-underflow": '<box size="1e-320 1e-320 1e-320"/>',
    "cylinder-1e308": '<cylinder radius="1e308" length="1e308"/>',
    "cylinder-inf": '<cylinder radius="inf" length="1"/>',
    "cylinder-underflow": '<cylinder radius="4.9e-324" length="4.9e-324"/>',
    "sphere-inf": '<sphere radius="inf"/>', "sphere-1e308": '<sphere radius="1e308"/>',
    "sphere-nan": '<sphere radius="nan"/>', "sphere-underflow": '<sphere radius="1e-310"/>',
    "capsule-1e308": '<capsule radius="1e308" length="1e308"/>',
    "mesh-scale-1e308": '<mesh filename="cube.stl" scale="1e308 1e308 1e308"/>',
    "mesh-scale-inf": '<mesh filename="cube.stl" scale="inf 1 1"/>',
    "mesh-scale-underflow": '<mesh filename="cube.stl" scale="1e-320 1e-320 1e-320"/>',
}
_INERTIA = '<inertia ixx="{0}" iyy="{0}" izz="{0}" ixy="0" ixz="0" iyz="0"/>'
# (origin of the inertial, visual and collision; mass and moments; collision the same shape)
EXTREME_PLACES = [
    ('<origin xyz="0 0 0"/>', "1e308", False),
    ('<origin xyz="1e308 1e308 1e308" rpy="1e308 0 0"/>', "1e308", True),
    ('<origin xyz="-1e308 0 0" rpy="inf 0 0"/>', "1", False),
    ('<origin xyz="1e-320 0 0"/>', "1e-320", True),
]


def _extreme_robot(shape: str, origin: str, mass: str, same_collision: bool) -> str:
    collision = shape if same_collision else '<box size="1 1 1"/>'
    return f"""<robot name="r">
  <link name="base"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="l"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="l">
    <inertial>{origin}<mass value="{mass}"/>{_INERTIA.format(mass)}</inertial>
    <visual>{origin}<geometry>{shape}</geometry></visual>
    <collision>{origin}<geometry>{collision}</geometry></collision>
  </link>
</robot>
"""


def _outcomes(write, shape: str, place: int):
    """``check`` and ``inertia`` on the robot with ``shape`` at ``EXTREME_PLACES[place]``."""
    write(_CUBE_STL, "cube.stl")
    origin, mass, same = EXTREME_PLACES[place]
    path = write(_extreme_robot(EXTREME_SHAPES[shape], origin, mass, same), f"r{place}.urdf")
    with warnings.catch_warnings():  # numpy's overflow warnings would reach the user's stderr
        warnings.simplefilter("error", RuntimeWarning)
        return [fuzz.run_command(args, bound=30.0)
                for args in (["check", "--format", "json", "--trusted", str(path)],
                             ["inertia", "--format=json", str(path)])]


@pytest.mark.parametrize("shape", EXTREME_SHAPES)
def test_extreme_sizes_give_findings_not_internal_errors(write, shape):
    """A ZeroDivisionError for a size that underflows to a zero volume (inertia.implausible-
    density) was found this way: every rule, and the commands that analyse a link, must give
    findings for sizes, scales, origins and masses at the ends of the float range."""
    for place in range(len(EXTREME_PLACES)):
        check, inertia = _outcomes(write, shape, place)
        for outcome in (check, inertia):
            assert outcome.problem is None, (place, outcome.command[0], outcome.problem)
            assert outcome.code in (0, 1)
        assert json.loads(check.out)["files"][0]["robot"] == "r"
        assert json.loads(inertia.out)["links"]


def test_a_mesh_file_name_longer_than_the_system_allows(write):
    """Found by the fuzzer (a number mutated into 400 nines inside a mesh filename): the name is
    a missing mesh, not an internal error of inertia.* or of the inertia command."""
    mesh = f'<mesh filename="{"9" * 400}.stl"/>'
    path = write(_extreme_robot(mesh, '<origin xyz="5 5 5"/>', "1", True))
    outcomes = [fuzz.run_command(args, bound=30.0)
                for args in (["check", "--format", "json", "--trusted", str(path)],
                             ["inertia", "--format=json", str(path)])]
    assert [o.problem for o in outcomes] == [None, None]
