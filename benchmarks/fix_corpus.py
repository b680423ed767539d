"""Single-defect corpus for ``check --fix --unsafe-fixes -o OUT`` (issue 17).

Each case injects one defect into a clean robot (the corrected seeds in robots/, and
pybullet_data's KUKA iiwa for meshes), checks that the defect's rule fires near it, runs the
command a user runs (``urdftool check --fix --unsafe-fixes -o OUT FILE``, OUT beside FILE so
relative paths resolve) and measures on OUT:

- fixed: no finding of the defect's rule within 3 lines of it any more;
- added: errors and warnings (rule, line) of ``check OUT`` that neither the clean original nor
  the broken file has (what the fix brought), and for the fixed cases every one the clean
  original does not have;
- distance: how far the farthest changed line is from the defect (must be <= 12), leaving out
  the lines the command changes in the clean original too (its own findings' fixes, listed).

Mutations the rules do not detect are listed and left out of the share. Lines never move (no
mutation or fix adds a line), so findings are compared by rule and line.

Run: ``python benchmarks/fix_corpus.py`` (one row per case, then the totals).
"""

from __future__ import annotations

import re
import shutil
import sys
import tempfile
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from urdftool.check import check_file

BASES = {
    "smartcar": "smartcar/corrected/smartcar.urdf",
    "chip_v2": "chip_v2/corrected/chip_v2.urdf",
    "dd_robot": "dd_robot/corrected/diff_robot.urdf",
    "m2wr": "m2wr/corrected/m2wr.xacro",
    "dual_arm": "dual_arm/corrected/test.xacro",
    "open_manipulator": "open_manipulator/corrected/open_manipulator.urdf.xacro",
}


def _bases() -> dict[str, Path]:
    bases = {key: ROOT / "robots" / relative for key, relative in BASES.items()}
    try:
        import pybullet_data

        bases["kuka_iiwa"] = Path(pybullet_data.getDataPath()) / "kuka_iiwa" / "model.urdf"
    except ImportError:
        print("pybullet_data is not installed: the mesh cases are left out", file=sys.stderr)
    return bases


def _sub(pattern: str, replacement, nth: int = 0, at: int = 0):
    """A mutation replacing the nth match of ``pattern`` (``replacement``: str or function);
    the defect is on the line where group ``at`` starts."""

    def mutate(text: str):
        matches = list(re.finditer(pattern, text))
        if len(matches) <= nth:
            return None
        m = matches[nth]
        new = replacement(m) if callable(replacement) else m.expand(replacement)
        if new == m.group(0):
            return None
        return text[:m.start()] + new + text[m.end():], text.count("\n", 0, m.start(at)) + 1

    return mutate


def _scale_rgba(m):
    values = [float(v) for v in m.group(1).split()]
    return 'rgba="' + " ".join(str(round(v * 255)) for v in values[:3]) + f' {values[3]:g}"'


def _swap_limits(m):
    return f'lower="{m.group(2)}" upper="{m.group(1)}"'


def _permute(m):
    return m.group(0).replace(f'ixx="{m.group(1)}"', "IXX").replace(
        f'izz="{m.group(2)}"', f'ixx="{m.group(2)}"').replace("IXX", f'izz="{m.group(1)}"')


def _typo(m):
    """A slip in the name of group 2 (a letter dropped: ``wheel_joint`` -> ``wheel_jint``)."""
    name = m.group(2)
    letters = [i for i, c in enumerate(name) if c.isalpha()]
    if len(letters) < 3:
        return m.group(0)
    drop = letters[len(letters) // 2]
    return m.group(1) + name[:drop] + name[drop + 1:] + m.group(3)


def _upper_suffix(m):
    return m.group(1) + m.group(2).upper() + m.group(3)


def _degrees(m):
    import math

    return (f'lower="{math.degrees(float(m.group(1))):.4g}" '
            f'upper="{math.degrees(float(m.group(2))):.4g}"')


def _joint_properties(text: str):
    """A pre-1.0 ``<joint_properties>`` where the joint's ``<dynamics>`` is (or in the first
    moving joint when none has one)."""
    if "<dynamics " in text:
        return _sub(r"<dynamics ", "<joint_properties ")(text)
    return _sub(r'(<joint name="[^"]*" type="(?:revolute|continuous)">)',
                r'\1<joint_properties damping="0.1" friction="0"/>')(text)


def _inflate(m):
    return f'ixx="{float(m.group(1)) * 1000:g}"'


# (name, family, expected rule, mutation)
CASES = [
    ("lost '<' of a <link>", "xml", ("xml.missing-open-bracket", "xml.stray-text"),
     _sub(r"\n(\s*)<link ", r"\n\1link ", 2)),
    ("end tag lost its '<'", "xml", ("xml.missing-open-bracket", "xml.unclosed-tag"),
     _sub(r"</collision>", "/collision>", 1)),
    ("end tag lost its '>'", "xml", ("xml.missing-close-bracket", "xml.unclosed-tag"),
     _sub(r"</visual>", "</visual", 1)),
    ("unclosed <origin>", "xml", ("xml.unclosed-tag",), _sub(r"(<origin [^>]*?)\s*/>", r"\1>", 3)),
    ("bare '&' in a comment-free text", "xml", ("xml.bad-entity",),
     _sub(r'(<robot[^>]*?name="[^"]*)"', r'\1 & co"', 0)),
    ("attribute typo ryp", "schema", ("schema.unknown-attribute",), _sub(r"\brpy=", "ryp=", 2)),
    ("attribute typo xzy", "schema", ("schema.unknown-attribute",),
     _sub(r"(<origin[^>]*?)\bxyz=", r"\1xzy=", 1)),
    ("element typo cylnder", "schema", ("schema.unknown-element",),
     _sub(r"<cylinder\b", "<cylnder", 0)),
    ("element typo <orign>", "schema", ("schema.unknown-element",),
     _sub(r"<origin\b", "<orign", 2)),
    ("rgba on 0-255", "schema", ("schema.bad-rgba",),
     _sub(r'rgba="([^"]+)"', _scale_rgba, 0)),
    ("pre-1.0 <joint_properties>", "schema", ("schema.unknown-element",), _joint_properties),
    ("axis not unit", "joint", ("joint.axis-not-unit",),
     _sub(r'<axis xyz="0 0 1"', '<axis xyz="0 0 2"', 0)),
    ("axis not unit (y)", "joint", ("joint.axis-not-unit",),
     _sub(r'<axis xyz="0 1 0"', '<axis xyz="0 3 0"', 0)),
    ("limits swapped", "joint", ("joint.lower-above-upper",),
     _sub(r'lower="(-?[\d.]+)" upper="([\d.]+)"', _swap_limits, 0)),
    ("limits in degrees", "joint", ("joint.range-in-degrees",),
     _sub(r'lower="(-[\d.]+)" upper="([\d.]+)"', _degrees, 0)),
    ("parent link typo", "structure", ("structure.missing-link",),
     _sub(r'(<parent link=")([^"]+)(")', _typo, 1)),
    ("mimic joint typo", "mimic", ("mimic.unknown-joint",),
     _sub(r'(<mimic joint=")([^"]+)(")', _typo, 0)),
    ("gazebo reference typo", "gazebo", ("gazebo.unknown-reference",),
     _sub(r'(<gazebo reference=")([^"]+)(")', _typo, 0)),
    ("transmission joint typo", "transmission", ("transmission.unknown-joint",),
     _sub(r'(<transmission[^>]*>[\s\S]*?<joint name=")([^"]+)(")', _typo, 0)),
    ("mesh file name case", "mesh", ("mesh.not-found",),
     _sub(r'(<mesh filename="[^"]*?)(\.stl|\.obj)(")', _upper_suffix, 1)),
    ("mesh file name typo", "mesh", ("mesh.not-found",),
     _sub(r'(<mesh filename="[^"]*/)([^/"]+)(")', _typo, 2)),
    ("inertia axes permuted", "inertia", ("inertia.permuted-axes",),
     _sub(r'<inertia ixx="([\d.e-]+)"[^>]*?izz="([\d.e-]+)"', _permute, 1)),
    ("inertia 1000x", "inertia", ("inertia.exceeds-geometry", "inertia.unit-scale",
                                  "inertia.triangle-inequality"),
     _sub(r'ixx="([\d.e-]+)"', _inflate, 1)),
    ("mass zero", "inertia", ("inertia.mass-not-positive",),
     _sub(r'<mass value="[\d.]+"', '<mass value="0"', 1)),
    ("unprefixed xacro:property", "xacro", ("xacro.unprefixed-tag",),
     _sub(r"<xacro:property ", "<property ", 0)),
    ("child link missing", "structure", ("structure.missing-link",),
     _sub(r'<child link="([^"]+)"', r'<child link="\1_x"', 1)),
    ("duplicate link name", "structure", ("structure.duplicate-link",),
     _sub(r'(<link name=")([^"]+)(">[\s\S]*?<link name=")([^"]+)"', r'\1\2\3\2"', 0, 4)),
    ("mesh not found", "mesh", ("mesh.not-found", "mesh.unresolved"),
     _sub(r"<cylinder [^>]*/>", '<mesh filename="missing.stl"/>', 0)),
    ("undefined material", "material", ("material.undefined",),
     _sub(r'<material name="([^"]+)"\s*/>', r'<material name="\1_x"/>', 0)),
    ("zero-size box", "geometry", ("geometry.nonpositive-size",),
     _sub(r'<box size="([\d.]+) ', r'<box size="0 ', 0)),
]


def _problems(report) -> Counter:
    """Errors and warnings by (rule, file name, line)."""
    return Counter((d.rule, Path(d.path).name.removeprefix(FIXED), d.line)
                   for d in report.diagnostics if d.severity in ("error", "warning"))


FIXED = "fixed-"


def _fix(path: Path, out: Path) -> tuple[int, str]:
    """``urdftool check --fix --unsafe-fixes -o OUT PATH``, in this process: (exit code,
    stderr)."""
    import contextlib
    import io

    from urdftool.cli import main

    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        try:
            main(["check", "--fix", "--unsafe-fixes", "-o", str(out), str(path)])
            code = 0
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else 2
    return code, err.getvalue()


_OWN: dict[str, set[int]] = {}


def _own_fixes(path: Path, text: str) -> set[int]:
    """The lines ``--fix --unsafe-fixes`` changes in the clean original itself (its own
    findings' fixes: pybullet's KUKA has a placeholder inertia): not the defect's."""
    if text not in _OWN:
        out = path.with_name(FIXED + path.name)
        _fix(path, out)
        fixed = out.read_text(encoding="utf-8") if out.exists() else text
        _OWN[text] = {i for i, (a, b) in enumerate(zip(text.split("\n"), fixed.split("\n")), 1)
                      if a != b}
        out.unlink(missing_ok=True)
    return _OWN[text]


def run_case(base: Path, name: str, family: str, rules: tuple, mutate, work: Path) -> dict | None:
    text = base.read_text(encoding="utf-8")
    mutated = mutate(text)
    if mutated is None:
        return None
    new_text, line = mutated
    package = base.parent.parent if base.parent.name == "corrected" else base.parent
    shutil.rmtree(work, ignore_errors=True)
    shutil.copytree(package, work)
    path = work / base.relative_to(package)
    clean = check_file(path)
    own = _own_fixes(path, text)
    path.write_text(new_text, encoding="utf-8")
    broken = check_file(path)
    row = {"case": name, "family": family, "base": package.name if package.name != "corrected"
           else base.parent.parent.name}

    def near(report):
        return [d for d in report.diagnostics
                if d.rule in rules and abs((d.line or 0) - line) <= 3]

    if not near(broken):
        return {**row, "status": "not detected"}
    out = path.with_name(FIXED + path.name)
    _, err = _fix(path, out)
    if not out.exists():  # refused (a fix in another file with -o), or nothing written
        return {**row, "status": "not fixed", "why": err.strip().splitlines()[-1:],
                "added": [], "far": [], "distance": 0}
    fixed_text = out.read_text(encoding="utf-8")
    assert fixed_text.count("\n") == new_text.count("\n"), f"{name}: a fix moved lines"
    changed = [i for i, (a, b) in enumerate(zip(new_text.split("\n"), fixed_text.split("\n")), 1)
               if a != b]
    after = check_file(out)
    still = near(after)
    added = _problems(after) - (_problems(clean) | _problems(broken))
    if not still:  # fixed: as clean as the original
        added |= _problems(after) - _problems(clean)
    changed = [i for i in changed if i not in own]  # not the original's own fixes
    distance = max((abs(i - line) for i in changed), default=0)
    return {**row, "status": "fixed" if not still else "not fixed", "added": sorted(added),
            "far": [i for i in changed if abs(i - line) > 12], "distance": distance}


def main() -> int:
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for key, base in _bases().items():
            for name, family, rules, mutate in CASES:
                row = run_case(base, name, family, rules, mutate, Path(tmp) / key)
                if row is not None:
                    rows.append(row)
    detected = [r for r in rows if r["status"] != "not detected"]
    fixed = [r for r in detected if r["status"] == "fixed"]
    added = [r for r in detected if r["added"]]
    far = [r for r in detected if r["far"]]
    for r in rows:
        extra = f" added={r['added']}" if r.get("added") else ""
        extra += f" far={r['far']}" if r.get("far") else ""
        extra += f" ({r['why'][0]})" if r.get("why") else ""
        print(f"{r['base']:<17} {r['family']:<12} {r['case']:<28} {r['status']:<12} "
              f"d={r.get('distance', '-')}{extra}")
    print(f"\n{len(detected)} detected single-defect cases ({len(rows) - len(detected)} "
          f"mutations not detected, left out): {len(fixed)} fixed "
          f"({100 * len(fixed) / max(len(detected), 1):.1f}%); "
          f"{sum(len(r['added']) for r in detected)} "
          f"errors/warnings added in {len(added)} case(s); largest distance of a changed line "
          f"from its defect {max((r['distance'] for r in detected), default=0)} "
          f"({len(far)} case(s) over 12)")
    by_family: dict[str, list] = {}
    for r in detected:
        by_family.setdefault(r["family"], []).append(r["status"] == "fixed")
    own = {k: sorted(v) for k, v in _OWN.items() if v}
    if own:
        print(f"lines the fixes change in the clean originals themselves: {list(own.values())}")
    print("per family: " + ", ".join(f"{f} {sum(v)}/{len(v)}" for f, v in sorted(by_family.items())))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
