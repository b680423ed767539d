"""`urdftool compare` and `convert --to mjcf` (issue 32) side by side with what a user would use
instead, on the same pairs, and timed.

Pairs (made in a temporary folder, each with its known truth):
  seeded      the MJCF MuJoCo makes of tests/test_compare.py's arm, with one seeded difference
              of each kind (MJCF_SEEDS: kind and name known)
  import      real URDFs (pybullet_data, example-robot-data) against the MJCF MuJoCo's own
              import makes of them: the truth is computed here from the URDF text (a root link
              with mass is dropped by MuJoCo: "mass"; a joint whose <limit> lacks a bound is
              made unlimited: "range"; nothing else)
  export      the same URDFs against urdftool's own export (truth: equivalent, the tests check
              each export independently)
  urdf2mjcf   the same URDFs against the MJCF urdf2mjcf (PyPI) makes of them: no known truth;
              what urdftool finds there is listed beside what urdf2mjcf itself reported

Tools: urdftool compare (exit 0/1, differences as JSON), robot-diff (GitHub henrynoyes/robot-diff,
`robot-diff A B`; "different" when it prints a change; a crash is counted), urdf2mjcf's own log
(converter's report). robot-diff and urdf2mjcf are looked for in --tools-venv (default
/tmp/bvenv: `python -m venv /tmp/bvenv && /tmp/bvenv/bin/pip install urdf2mjcf ./robot-diff`);
a missing tool is said, not faked.

Timing: compare and export of a generated 30-link chain (primitives, a fixed link every third),
CPU time of the child process (user + system) and wall time, median of --runs.

Usage: python benchmarks/bench_compare.py [--runs 3] [--tools-venv /tmp/bvenv]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tests.conftest import example_robot_data_dir, pybullet_data_dir
from tests.test_compare import ARM, MJCF_SEEDS, _edit_mjcf

URDFTOOL = [sys.executable, "-m", "urdftool"]
REAL = [("pybullet", "kuka_iiwa/model.urdf"), ("pybullet", "r2d2.urdf"),
        ("pybullet", "franka_panda/panda.urdf"), ("pybullet", "quadruped/minitaur.urdf"),
        ("example-robot-data", "solo_description/robots/solo12.urdf"),
        ("example-robot-data", "ur_description/urdf/ur5_robot.urdf"),
        ("example-robot-data", "panda_description/urdf/panda.urdf")]


def run(command, cwd=None, timeout=600):
    """(exit code, stdout, stderr, cpu seconds, wall seconds) of a child process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    try:
        done = subprocess.run(command, capture_output=True, text=True, cwd=cwd, timeout=timeout,
                              check=False)
        code, out, err = done.returncode, done.stdout, done.stderr
    except subprocess.TimeoutExpired:
        code, out, err = "timeout", "", ""
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return code, out, err, cpu, wall


def packages(where):
    """-P for the meshes: the MJCF files live in a temporary folder and name meshes of the
    installed data, outside that folder's roots (refused unless the operator names them)."""
    if where == "pybullet":
        return ["-P", f"pybullet_data={pybullet_data_dir()}"]
    return ["-P", f"example-robot-data={example_robot_data_dir()}"]


def source_of(where, name):
    return (pybullet_data_dir() if where == "pybullet" else example_robot_data_dir() / "robots") / name


def import_truth(urdf: Path) -> set[tuple[str, str]]:
    """What MuJoCo's URDF import loses, read here from the URDF text: the root link's group
    mass (the root and the links fixed to it: fused into the world) and limits missing a
    bound (URDF: that bound is 0; MuJoCo: unlimited)."""
    root = ET.parse(urdf).getroot()
    children = {j.find("child").get("link") for j in root.findall("joint")}
    links = [link.get("name") for link in root.findall("link")]
    top = next(name for name in links if name not in children)
    fixed = {top}
    changed = True
    while changed:
        changed = False
        for j in root.findall("joint"):
            if j.get("type") == "fixed" and j.find("parent").get("link") in fixed \
                    and j.find("child").get("link") not in fixed:
                fixed.add(j.find("child").get("link"))
                changed = True
    truth = set()
    mass = 0.0
    for link in root.findall("link"):
        element = link.find("inertial/mass")
        if link.get("name") in fixed and element is not None:
            mass += float(element.get("value", "0"))
    if mass > 0 and top != "world":
        truth.add(("mass", top))
    for j in root.findall("joint"):
        limit = j.find("limit")
        if j.get("type") in ("revolute", "prismatic") and limit is not None and \
                (limit.get("lower") is None or limit.get("upper") is None):
            truth.add(("range", j.get("name")))  # [0, upper], [lower, 0], [0, 0] by the spec
    return truth


def urdftool_compare(a, b, extra=()):
    code, out, err, cpu, _wall = run([*URDFTOOL, "compare", str(a), str(b), "--format", "json",
                                     *extra])
    if code not in (0, 1):
        return {"code": code, "error": (err.strip().splitlines() or ["?"])[-1]}
    data = json.loads(out)
    return {"code": code, "found": {(d["kind"], d["name"] if d["kind"] != "extra-body"
                                     else d["other"]) for d in data["differences"]},
            "cpu": cpu}


def robot_diff(tools, a, b):
    binary = Path(tools) / "bin" / "robot-diff"
    if not binary.exists():
        return None
    code, out, err, _, _ = run([str(binary), str(a), str(b)], cwd=Path(a).parent)
    if code != 0 and not out.strip():
        return {"crashed": True, "lines": 0, "error": (err.strip().splitlines() or ["?"])[-1]}
    lines = [line for line in out.splitlines() if line.strip()]
    return {"crashed": False, "lines": len(lines),
            "different": any(line.lstrip()[:1] in "+-~M" or "modified" in line.lower()
                             or "added" in line.lower() or "removed" in line.lower()
                             for line in lines), "text": out}


def seeded_pairs(folder: Path):
    import mujoco

    urdf = folder / "arm.urdf"
    urdf.write_text(ARM)
    mjcf = folder / "arm.xml"
    mujoco.mj_saveLastXML(str(mjcf), mujoco.MjModel.from_xml_path(str(urdf)))
    pairs = [("seeded", "equivalent", urdf, mjcf, set(), [])]
    for kind, (change, name) in sorted(MJCF_SEEDS.items()):
        seeded = folder / f"seeded_{kind}.xml"
        seeded.write_text(_edit_mjcf(mjcf.read_text(), change))
        pairs.append(("seeded", kind, urdf, seeded, {(kind, name)}, []))
    return pairs


def real_pairs(folder: Path, tools: str):
    import mujoco

    pairs, converters = [], []
    for where, name in REAL:
        source = source_of(where, name)
        if not source.exists():
            print(f"  (not installed: {source})")
            continue
        label = f"{Path(name).stem}-{where[:3]}"
        imported = folder / f"{label}_mujoco.xml"
        try:
            mujoco.mj_saveLastXML(str(imported), mujoco.MjModel.from_xml_path(str(source)))
            # MuJoCo's saved XML names its meshes relative to the URDF's folder: said here
            saved = ET.parse(imported)
            compiler = saved.getroot().find("compiler")
            if compiler is not None and compiler.get("meshdir") is None:
                compiler.set("meshdir", str(source.parent))
                saved.write(imported)
            pairs.append(("import", label, source, imported, import_truth(source),
                          packages(where)))
        except ValueError as exc:
            print(f"  MuJoCo cannot import {name}: {' '.join(str(exc).split())[:120]}")
        exported = folder / f"{label}_urdftool.xml"
        code, _, _err, _, _ = run([*URDFTOOL, "convert", str(source), "--to", "mjcf", "-o",
                                  str(exported), *packages(where)])
        if exported.exists():
            pairs.append(("export", label, source, exported, set() if code == 0 else None,
                          packages(where)))
        converter = Path(tools) / "bin" / "urdf2mjcf"
        if converter.exists():
            out = folder / f"{label}_urdf2mjcf.xml"
            code, stdout, stderr, _, _ = run([str(converter), str(source), "--output", str(out),
                                              "--copy-meshes"])
            report = [line for line in (stdout + stderr).splitlines()
                      if any(word in line.lower() for word in ("warn", "error", "lost", "drop",
                                                               "skip", "ignor"))]
            converters.append((label, source, out if out.exists() else None, code, report,
                               packages(where)))
    return pairs, converters


def score(pairs, tools):
    print(f"\n{'pair':<28} {'truth':<24} {'urdftool':<30} {'robot-diff':<22}")
    totals = {"urdftool": 0, "robot-diff": 0, "crashes": 0, "n": 0, "seeded": 0,
              "seeded_named": 0, "robot-diff_seen": 0}
    have_robot_diff = (Path(tools) / "bin" / "robot-diff").exists()
    for group, label, a, b, truth, extra in pairs:
        ours = urdftool_compare(a, b, extra)
        theirs = robot_diff(tools, a, b) if have_robot_diff else None
        totals["n"] += truth is not None
        if truth is None:
            truth_text, right = "(export not verified)", None
        else:
            truth_text = "equivalent" if not truth else ", ".join(f"{k} {n}" for k, n in sorted(truth))
            found = ours.get("found")
            right = found is not None and (found == truth if group != "seeded" or not truth
                                           else truth <= found and len(found) == 1)
            if right:
                totals["urdftool"] += 1
            if group == "seeded" and truth:
                totals["seeded"] += 1
                totals["seeded_named"] += int(bool(found) and truth <= found)
        if "error" in ours:
            ours_text = f"exit {ours['code']}"
            print(f"  ({label}: {ours['error']})")
        else:
            ours_text = ("equivalent" if not ours["found"] else
                         ", ".join(f"{k} {n}" for k, n in sorted(ours["found"]))[:26]) + \
                (" ok" if right else " WRONG" if right is False else "")
        theirs_text = "(not installed)"
        if theirs is not None:
            if theirs["crashed"]:
                totals["crashes"] += 1
                theirs_text = "crashed"
            else:
                says_different = theirs["different"]
                theirs_text = f"{'different' if says_different else 'same'} ({theirs['lines']} lines)"
                if truth is not None and says_different == bool(truth):
                    totals["robot-diff"] += 1
        print(f"{group + ' ' + label:<28.28} {truth_text:<24.24} {ours_text:<30.30} "
              f"{theirs_text:<22}")
    print(f"\nright verdict and differences: urdftool {totals['urdftool']}/{totals['n']}; "
          f"seeded differences reported with kind and name: {totals['seeded_named']}/"
          f"{totals['seeded']}")
    if have_robot_diff:
        print(f"robot-diff: right verdict {totals['robot-diff']}/{totals['n']} (a pair in two "
              f"formats counts as 'same' only if it prints nothing), crashed {totals['crashes']}")
    else:
        print("robot-diff: not installed in the tools venv (see the module docstring)")


def converters_table(converters):
    if not converters:
        print("\nurdf2mjcf: not installed in the tools venv (see the module docstring)")
        return
    print(f"\n{'urdf2mjcf on':<16} {'exit':<5} {'its own report':<34} urdftool compare URDF with "
          "its output")
    for label, source, out, code, report, extra in converters:
        said = f"{len(report)} warning/error line(s)" if report else "nothing"
        if out is None:
            print(f"{label:<16} {code!s:<5} {said:<34} (no output)")
            continue
        ours = urdftool_compare(source, out, extra)
        found = ("cannot load: " + ours["error"][-160:]) if "error" in ours else \
            ("equivalent" if not ours["found"] else
             f"{len(ours['found'])}: " + ", ".join(f"{k} {n}" for k, n in sorted(ours["found"]))[:90])
        print(f"{label:<16} {code!s:<5} {said:<34} {found}")


def chain(links: int) -> str:
    parts = ['<robot name="chain">']
    for i in range(links):
        parts.append(f'<link name="l{i}"><inertial><origin xyz="0 0 0.05" rpy="0.1 0 0"/>'
                     f'<mass value="{1 + i * 0.01}"/><inertia ixx="0.002" ixy="0.0001" ixz="0" '
                     'iyy="0.002" iyz="0" izz="0.001"/></inertial><collision><geometry>'
                     '<cylinder radius="0.02" length="0.1"/></geometry></collision></link>')
        if i:
            kind = "fixed" if i % 3 == 0 else "revolute"
            limit = '<limit lower="-1" upper="1" effort="10" velocity="2"/>' if kind != "fixed" else ""
            parts.append(f'<joint name="j{i}" type="{kind}"><parent link="l{i - 1}"/>'
                         f'<child link="l{i}"/><origin xyz="0 0.01 0.1" rpy="0 0.2 0"/>'
                         f'<axis xyz="0 {i % 2} {1 - i % 2}"/>{limit}<dynamics damping="0.1"/>'
                         '</joint>')
    parts.append("</robot>")
    return "\n".join(parts)


def timing(folder: Path, runs: int) -> None:
    urdf = folder / "chain30.urdf"
    urdf.write_text(chain(30))
    out = folder / "chain30.xml"
    results = {"convert --to mjcf": [], "compare URDF MJCF": [], "python -c 'import mujoco'": []}
    for _ in range(runs):
        code, _, err, cpu, wall = run([*URDFTOOL, "convert", str(urdf), "--to", "mjcf", "-o",
                                       str(out)])
        assert code == 0, err
        results["convert --to mjcf"].append((cpu, wall))
        code, _, err, cpu, wall = run([*URDFTOOL, "compare", str(urdf), str(out)])
        assert code == 0, err
        results["compare URDF MJCF"].append((cpu, wall))
        _, _, _, cpu, wall = run([sys.executable, "-c", "import mujoco, numpy"])
        results["python -c 'import mujoco'"].append((cpu, wall))
    print(f"\n30-link chain (20 of them moving), median of {runs}: CPU s (user+system), wall s")
    for name, values in results.items():
        print(f"  {name:<28} cpu {statistics.median(v[0] for v in values):6.3f}   "
              f"wall {statistics.median(v[1] for v in values):6.3f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--tools-venv", default="/tmp/bvenv")
    args = parser.parse_args()
    os.environ.setdefault("MUJOCO_GL", "disable")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        pairs = seeded_pairs(folder)
        real, converters = real_pairs(folder, args.tools_venv)
        score(pairs + real, args.tools_venv)
        converters_table(converters)
        timing(folder, args.runs)


if __name__ == "__main__":
    main()
