"""`urdftool diff` on real upstream commits (issue 30), side by side with robot-diff and a plain
name-based XML diff, and the time of the UR description's nine-variant diff.

Pairs: commits of UniversalRobots/Universal_Robots_ROS2_Description and
frankaemika/franka_description (the public histories, as `fetch` mirrors them under
/work/.mirror), each with one robot variant and the changes a robot engineer names, written
down by hand from reading the commit (`git show`); plus a regenerated URDF (the UR5e expanded at HEAD, every number written again with
17 digits and its attributes reordered, with two real changes among them).

Each pair is compared three ways:

  urdftool       `urdftool diff BASE..COMMIT NAME:=VALUE...` in a clone (the revisions read from
                 git objects; the xacro expanded at both sides by urdftool itself)
  robot-diff     henrynoyes/robot-diff 1.0.1 (not on PyPI: run from its git snapshot, --robot-diff
                 DIR, with its dependencies lxml, tyro, usd-core installed) on the two URDFs that
                 `urdftool expand` writes at BASE and at COMMIT (robot-diff reads no xacro), its
                 changes mapped to the same (element, name, aspect) names
  name-xml       a plain name-based XML diff written here (baseline, clearly not a tool): links
                 and joints matched by name, every attribute of every child compared as text

Measured per tool: recall (expected changes found / expected), spurious changes (found, not
expected), renames found as renames, origin changes given with their effect, and (urdftool)
changes located in a file of the repository at a line. Time: `urdftool diff` of a commit that
changes all nine UR variants (CPU time of the child, warm mesh cache; and cold, without it).

Usage: python benchmarks/bench_diff.py [--robot-diff DIR] [--mirrors DIR] [--only COMMIT]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
URDFTOOL = [sys.executable, "-m", "urdftool"]
MIRRORS = Path("/work/.mirror")
ROBOT_DIFF = Path("/work/.mirror/henrynoyes+robot-diff/repo")

# the arguments of a UR variant (ur.urdf.xacro of the time, as its launch file passes them;
# the YAML files named relative to the repository: each side reads its own)
OLD_ARGS = ["name:=ur", "prefix:=", "joint_limit_params:=config/{v}/joint_limits.yaml",
            "kinematics_params:=config/{v}/default_kinematics.yaml",
            "physical_params:=config/{v}/physical_parameters.yaml",
            "visual_params:=config/{v}/visual_parameters.yaml"]
NEW_ARGS = ["name:=ur", "tf_prefix:=", "safety_limits:=true", "safety_pos_margin:=0.15",
            "safety_k_position:=20"]
JOINTS6 = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
           "wrist_2_joint", "wrist_3_joint")
LINKS6 = ("shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link",
          "wrist_3_link")

UR, FRANKA = "UniversalRobots+Universal_Robots_ROS2_Description", "frankaemika+franka_description"
ENTRY, MOCKED = "urdf/ur.urdf.xacro", "urdf/ur_mocked.urdf.xacro"
FR3 = "robots/fr3/fr3.urdf.xacro"


def ur(variant: str, args: list[str] = NEW_ARGS) -> list[str]:
    return [a.format(v=variant) for a in args] + [f"ur_type:={variant}"]


# (repository, commit, entry, arguments, kind, expected {(element, name, aspect)}), each read
# from `git show COMMIT` (the YAML and xacro lines it changes, for this variant)
PAIRS = [
    (UR, "352a35c", ENTRY, ur("ur3"), "semantic: ur3 wrist 3 made continuous (YAML + xacro)",
     {("joint", "wrist_3_joint", a) for a in
      ("type", "limit.lower", "limit.upper", "safety_controller")}),
    (UR, "352a35c", ENTRY, ur("ur5e"), "refactor for ur5e (same commit): nothing", set()),
    (UR, "9712b2e", ENTRY, ur("ur20"), "semantic: UR20 effort and velocity limits (YAML)",
     {("joint", j, a) for j in JOINTS6 for a in ("limit.effort", "limit.velocity")}),
    (UR, "aa2db08", ENTRY, ur("ur5e"), "semantic: link masses (YAML; inertias follow them)",
     {("link", l, a) for l in LINKS6 for a in ("mass", "inertia")}),
    (UR, "707b369", ENTRY, ur("ur5"), "semantic: ur5 base meshes re-exported on the ground",
     {("link", "base_link_inertia", "visual"), ("link", "base_link_inertia", "collision")}),
    (UR, "ea0c6b5", MOCKED, ["name:=ur", "tf_prefix:=", "ur_type:=ur5e"],
     "semantic: a TCP pose sensor in <ros2_control> (mock hardware)",
     {("ros2_control", "ur", "changed")}),
    (UR, "ea0c6b5", ENTRY, ur("ur5e"), "the same commit: ur.urdf.xacro reads no changed file",
     set()),
    (UR, "c6f6a7a", ENTRY, ur("ur30"), ("regenerated calibration YAML: numbers re-written, "
     "wrist_2 z 0 -> -3.27e-11 m"), {("joint", "wrist_2_joint", "origin")}),
    (UR, "dcb7db0", ENTRY, ur("ur5e"), "formatting only: whitespace", set()),
    (UR, "6a5b5e5", ENTRY, ur("ur5e"), "refactor: xacro.load_yaml for load_yaml", set()),
    (UR, "00b1a0f", ENTRY, ur("ur5e"), ("refactor prefix -> tf_prefix; the hardware's prefix "
     "parameter dropped"), {("ros2_control", "ur", "changed")}),
    (UR, "6f4ae5d", ENTRY, ur("ur5e", OLD_ARGS),
     "renames: base_link_fixed -> base_link -> base_link_inertia",
     {("link", "base_link", "renamed"), ("link", "base_link_inertia", "renamed"),
      ("joint", "base_link-base_link_inertia", "renamed"),
      ("link", "base_link_inertia", "mass"), ("link", "base_link_inertia", "inertia")}),
    (FRANKA, "14c5d63", FR3, [], ("semantic: inertias (YAML) and the one-link hand dropped "
     "(xacro:if)"), {("link", f"fr3_link{i}", "inertia") for i in range(1, 8)} | {
         ("link", "fr3_franka_hand", "removed"), ("link", "fr3_franka_hand_tcp", "removed"),
         ("joint", "fr3_franka_hand_joint", "removed"),
         ("joint", "fr3_franka_hand_tcp_joint", "removed")}),
    (FRANKA, "de0dc86", FR3, [], "semantic: link0 inertial added (YAML)",
     {("link", "fr3_link0", a) for a in ("mass", "com", "inertia")}),
    (FRANKA, "4bb824f", FR3, [], "formatting: 'rpy: ' -> 'rpy: 0 0 0' (YAML)", set()),
]
REGENERATED = (UR, "regenerated", ENTRY, ur("ur5e"),
               ("regenerated URDF: every number re-written, attributes reordered; wrist_3_link "
                "inertia, elbow_joint damping and origin (+1 mm in z) changed"),
               {("link", "wrist_3_link", "inertia"), ("joint", "elbow_joint", "dynamics"),
                ("joint", "elbow_joint", "origin")})


def run(command: list[str], cwd: Path, env=None) -> subprocess.CompletedProcess:
    return subprocess.run(command, cwd=cwd, capture_output=True, text=True, env=env,
                          check=False)


def git(repo: Path, *args: str) -> str:
    return subprocess.run(["git", "-C", str(repo), *args], capture_output=True, text=True,
                          check=True).stdout


# -- urdftool ---------------------------------------------------------------------------------


def urdftool_diff(repo: Path, base: str, head: str, entry: str, args: list[str],
                  env) -> tuple[list, float]:
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = run([*URDFTOOL, "diff", "--format", "json", "--trusted", "--timeout", "300",
                f"{base}..{head}", *args, "--", entry], repo, env)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise SystemExit(f"urdftool diff {base}..{head}: {done.stderr}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return json.loads(done.stdout)["robots"], cpu


def found_by_urdftool(robots: list) -> tuple[set, list]:
    changes = [c for r in robots for c in r["changes"]]
    return {(c["element"], c["name"], c["aspect"]) for c in changes}, changes


# -- the expanded URDFs for robot-diff and the name baseline ---------------------------------


def expand_at(repo: Path, commit: str, entry: str, args: list[str], out: Path, env) -> None:
    """``urdftool expand`` of ``entry`` at ``commit`` (its files from git objects; a path
    argument names the file of that commit)."""
    sys.path.insert(0, str(ROOT))
    from urdftool.diff.revisions import commit as resolve
    from urdftool.diff.revisions import materialize

    with tempfile.TemporaryDirectory(prefix="bench-diff-") as tree:
        materialize(repo, resolve(repo, commit), Path(tree))
        mapped = []
        for a in args:
            name, _, value = a.partition(":=")
            mapped.append(f"{name}:={tree}/{value}" if value and (Path(tree) / value).is_file()
                          else a)
        done = run([*URDFTOOL, "expand", "--trusted", "--timeout", "300",
                    f"{tree}/{entry}", *mapped, "-o", str(out)], repo, env)
        if not out.exists():
            raise SystemExit(f"urdftool expand at {commit}: {done.stderr}")


_ROBOT_DIFF_ASPECTS = [
    (r"^inertial\.mass", "mass"), (r"^inertial\.inertia", "inertia"),
    (r"^inertial\.origin\.xyz", "com"), (r"^inertial\.origin", "inertia"), (r"^inertial", "mass"),
    (r"^visuals\[\d+\]\.material", "material"), (r"^visuals", "visual"),
    (r"^collisions", "collision"), (r"^type", "type"), (r"^parent", "parent"),
    (r"^child", "child"), (r"^origin", "origin"), (r"^axis", "axis"),
    (r"^limit\.(lower|upper|effort|velocity)", None), (r"^limit", "limit.lower"),
    (r"^dynamics", "dynamics"), (r"^mimic", "mimic"), (r"^safety", "safety_controller"),
    (r"^calibration", "calibration")]


def _aspect(path: str) -> str:
    for pattern, aspect in _ROBOT_DIFF_ASPECTS:
        match = re.match(pattern, path)
        if match:
            return aspect or f"limit.{match.group(1)}"
    return path


def robot_diff(old: Path, new: Path, source: Path) -> set:
    """robot-diff's changes as (element, name, aspect), run from its snapshot ``source``. Its
    schema refuses ``<ros2_control>`` (every UR description has one): the blocks are taken out
    of copies of both files first."""
    from lxml import etree

    copies = []
    for path in (old, new):
        root = etree.parse(str(path)).getroot()
        for element in root.findall("ros2_control"):
            root.remove(element)
        copy = path.with_name(path.stem + "-for-robot-diff.urdf")
        copy.write_bytes(etree.tostring(root))
        copies.append(copy)
    old, new = copies
    code = ("import json, sys\nfrom pathlib import Path\n"
            "from robot_diff.diff import compare_robots\nfrom robot_diff.parsers import URDFParser\n"
            "d = compare_robots(URDFParser(Path(sys.argv[1])).parse(), URDFParser(Path(sys.argv[2])).parse())\n"
            "out = [(k, n, i.status, sorted(i.changes)) for k, items in (('link', d.link_diffs), "
            "('joint', d.joint_diffs)) for n, i in items.items()]\n"
            "print(json.dumps(out))\n")
    done = run([sys.executable, "-c", code, str(old), str(new)], source,
               {**os.environ, "PYTHONPATH": str(source)})
    if done.returncode != 0:  # its schema refuses the file (a misplaced element): no answer
        print(f"    robot-diff refused: {done.stderr.strip().splitlines()[-1]}")
        return set()
    found = set()
    for element, name, status, paths in json.loads(done.stdout):
        if status in ("added", "removed"):
            found.add((element, name, status))
        for path in paths:
            found.add((element, name, _aspect(path)))
    return found


def name_xml(old: Path, new: Path) -> set:
    """The baseline: links and joints by name, attributes of their descendants as text."""
    from lxml import etree

    def flat(element) -> dict[str, str]:
        values = {}
        for node in element.iter():
            if not isinstance(node.tag, str):
                continue
            path = node.getroottree().getpath(node).split("/", 3)[-1] if node is not element else ""
            for key, value in node.attrib.items():
                values[f"{path}@{key}"] = value
        return values

    found = set()
    trees = [etree.parse(str(p)).getroot() for p in (old, new)]
    for tag in ("link", "joint"):
        a = {e.get("name"): e for e in trees[0].findall(tag)}
        b = {e.get("name"): e for e in trees[1].findall(tag)}
        found |= {(tag, n, "removed") for n in set(a) - set(b)}
        found |= {(tag, n, "added") for n in set(b) - set(a)}
        for name in set(a) & set(b):
            fa, fb = flat(a[name]), flat(b[name])
            for key in set(fa) | set(fb):
                if fa.get(key) != fb.get(key) and key != "@name":
                    path = re.sub(r"\[\d+\]", "", key.split("@")[0])
                    attribute = key.split("@")[1]
                    found.add((tag, name, _xml_aspect(path, attribute)))
    return found


def _xml_aspect(path: str, attribute: str) -> str:
    if path.startswith("inertial/mass"):
        return "mass"
    if path.startswith("inertial/origin"):
        return "com" if attribute == "xyz" else "inertia"
    if path.startswith("inertial"):
        return "inertia"
    if path.startswith(("visual", "collision")):
        return "material" if "material" in path else path.split("/")[0]
    if path == "limit":
        return f"limit.{attribute}"
    if path == "safety_controller":
        return "safety_controller"
    return path or attribute


# -- the regenerated URDF ---------------------------------------------------------------------


def regenerated(expanded: Path, out: Path) -> None:
    """``expanded`` written again as a generator would (17 digits, attributes reordered,
    another indentation), with an inertia and a damping changed."""
    from lxml import etree

    root = etree.parse(str(expanded)).getroot()
    for element in root.iter():
        if not isinstance(element.tag, str):
            continue
        items = sorted(element.attrib.items(), reverse=True)
        element.attrib.clear()
        for key, value in items:
            try:
                value = " ".join(f"{float(v):.17g}" for v in value.split())
            except ValueError:
                pass
            element.set(key, value)
    for link in root.findall("link"):
        if link.get("name") == "wrist_3_link":
            link.find("inertial/inertia").set("ixx", "0.01")
    for joint in root.findall("joint"):
        if joint.get("name") == "elbow_joint":
            joint.find("dynamics").set("damping", "1.0")
            origin = joint.find("origin")
            x, y, z = (float(v) for v in origin.get("xyz").split())
            origin.set("xyz", f"{x!r} {y!r} {z + 0.001!r}")
    etree.indent(root, space="\t")
    out.write_text(etree.tostring(root, encoding="unicode"))


# -- scoring ----------------------------------------------------------------------------------


class Score:
    def __init__(self):
        self.expected = self.found = self.spurious = 0
        self.renames_expected = self.renames_found = 0

    def add(self, expected: set, found: set) -> tuple[int, int]:
        hit = len(expected & found)
        extra = len(found - expected)
        self.expected += len(expected)
        self.found += hit
        self.spurious += extra
        renames = {e for e in expected if e[2] == "renamed"}
        self.renames_expected += len(renames)
        self.renames_found += len(renames & found)
        return hit, extra


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--mirrors", type=Path, default=MIRRORS,
                        help="where `fetch` put the repositories (OWNER+NAME/repo)")
    parser.add_argument("--robot-diff", type=Path, default=ROBOT_DIFF,
                        help="a checkout or git mirror of henrynoyes/robot-diff")
    parser.add_argument("--only", default=None, help="one commit (or 'regenerated')")
    options = parser.parse_args()
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    env.pop("CI", None)
    scores = {"urdftool": Score(), "robot-diff": Score(), "name-xml": Score()}
    located = total = effects = origins = 0
    with tempfile.TemporaryDirectory(prefix="bench-diff-") as work:
        work = Path(work)
        clones = {}
        for name in (UR, FRANKA):  # (a mirror may lack its largest blobs: no checkout)
            clones[name] = work / name
            subprocess.run(["git", "clone", "-q", "--no-checkout",
                            str(options.mirrors / name / "repo"), str(clones[name])], check=True)
        repo = clones[UR]
        source = options.robot_diff
        if (source / "HEAD").exists() and not (source / "robot_diff").exists():  # a mirror
            snapshot = work / "robot-diff"
            snapshot.mkdir()
            archive = subprocess.run(["git", "-C", str(source), "archive", "HEAD"],
                                     capture_output=True, check=True).stdout
            subprocess.run(["tar", "-x", "-C", str(snapshot)], input=archive, check=True)
            source = snapshot
        print(f"{'pair':<44} {'kind':<60} {'exp':>3} | urdftool | robot-diff | name-xml "
              "(found/spurious)")
        for name, commit, entry, args, kind, expected in [*PAIRS, REGENERATED]:
            if options.only and options.only != commit:
                continue
            repo = clones[name]
            old, new = work / f"{commit}-old.urdf", work / f"{commit}-new.urdf"
            if commit == "regenerated":
                expand_at(repo, "HEAD", entry, args, old, env)
                regenerated(old, new)
                done = run([*URDFTOOL, "diff", "--format", "json", "--trusted", str(old),
                            str(new)], work, env)
                robots = json.loads(done.stdout)["robots"]
            else:
                robots, _ = urdftool_diff(repo, f"{commit}~1", commit, entry, args, env)
                expand_at(repo, f"{commit}~1", entry, args, old, env)
                expand_at(repo, commit, entry, args, new, env)
            found, changes = found_by_urdftool(robots)
            for change in changes:
                total += 1
                where = change["path"] or change["base_path"]
                line = change["line"] or change["base_line"]
                known = {old.name, new.name} if commit == "regenerated" else set(
                    git(repo, "ls-tree", "-r", "--name-only", commit).split())
                located += bool(where and line and where in known)
                if change["aspect"] == "origin":
                    origins += 1
                    effects += "effect" in change
                    if commit == "regenerated":  # a translation of 1 mm: every link below
                        print(f"    elbow_joint origin effect: {change['effect']} (expected: "
                              "every link below the elbow moved 0.001 m, none turned)")
            results = [scores["urdftool"].add(expected, found),
                       scores["robot-diff"].add(expected, robot_diff(old, new, source)),
                       scores["name-xml"].add(expected, name_xml(old, new))]
            cells = " | ".join(f"{hit:>3}/{extra:<4}" for hit, extra in results)
            label = f"{name.split('+')[1][:10]} {commit} {Path(entry).name}"
            print(f"{label:<44} {kind[:60]:<60} {len(expected):>3} | {cells}", flush=True)
        print()
        for name, score in scores.items():
            recall = score.found / score.expected if score.expected else 1.0
            print(f"{name:<11} recall {score.found}/{score.expected} ({recall:.0%}), "
                  f"spurious {score.spurious}, renames {score.renames_found}/"
                  f"{score.renames_expected}")
        print(f"urdftool    located {located}/{total} changes in a file of the repository at a "
              f"line; origin changes with their effect {effects}/{origins} (robot-diff and "
              "name-xml: no effects, no locations in the xacro)")
        if options.only is None:
            timing(clones[UR], env)


def timing(repo: Path, env) -> None:
    """The nine UR variants, both sides: 60e6974 changes every variant's inertias. The
    working tree checked out at 60e6974, as a CI job has it."""
    git(repo, "checkout", "-q", "60e6974")
    with tempfile.TemporaryDirectory(prefix="bench-diff-cache-") as cache:
        cold = {**env, "URDFTOOL_CACHE_DIR": cache}
        for label in ("cold mesh cache", "warm mesh cache"):
            started = time.perf_counter()
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            done = run([*URDFTOOL, "diff", "--format", "json", "--trusted", "--timeout", "300",
                        "60e6974~1..60e6974"], repo, cold)
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            robots = json.loads(done.stdout)["robots"]
            cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
            print(f"UR description 60e6974~1..60e6974, {len(robots)} variants "
                  f"({sum(r['status'] == 'changed' for r in robots)} changed), {label}: "
                  f"{cpu:.2f} s CPU, {time.perf_counter() - started:.1f} s wall")
            if label == "cold mesh cache":  # the check a CI job runs first warms it
                run([*URDFTOOL, "check", "--trusted", "--timeout", "300", "."], repo, cold)


if __name__ == "__main__":
    main()
