"""Fuzzing in the default suite: hypothesis mutates real robots (the seeds in robots/, the xacro
corpus, small pybullet_data URDFs) with urdftool.fuzz's mutations and runs ``check`` plus one of
``limits``/``inertia``/``tree``; each must answer with a report or one clean exit-2 line, never a
traceback or an internal error, within a time bound. ``make fuzz`` runs 10 000 cases."""

from __future__ import annotations

import random
import tempfile
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
    for number in range(12):
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
