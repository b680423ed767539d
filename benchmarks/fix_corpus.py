"""Single-defect corpus for ``check --fix --unsafe-fixes`` (issue 17).

Each case injects one defect into a clean robot (the corrected seeds in robots/), checks that the
defect's rule fires, fixes the file in memory (safe and unsafe fixes) and measures:

- fixed: the defect's finding is gone;
- no new error or warning that the clean original does not have;
- every changed line within 12 lines of the defect.

Run: ``python benchmarks/fix_corpus.py`` (prints one row per case and the totals).
"""

from __future__ import annotations

import re
import shutil
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from urdftool.check import CheckOptions, check_file
from urdftool.fix import fix_file

BASES = {
    "smartcar": "smartcar/corrected/smartcar.urdf",
    "chip_v2": "chip_v2/corrected/chip_v2.urdf",
    "dd_robot": "dd_robot/corrected/diff_robot.urdf",
    "m2wr": "m2wr/corrected/m2wr.xacro",
    "dual_arm": "dual_arm/corrected/test.xacro",
    "open_manipulator": "open_manipulator/corrected/open_manipulator.urdf.xacro",
}


def _sub(pattern: str, replacement, nth: int = 0):
    """A mutation replacing the nth match of ``pattern`` (``replacement``: str or function)."""

    def mutate(text: str):
        matches = list(re.finditer(pattern, text))
        if len(matches) <= nth:
            return None
        m = matches[nth]
        new = replacement(m) if callable(replacement) else m.expand(replacement)
        return text[:m.start()] + new + text[m.end():], text.count("\n", 0, m.start()) + 1

    return mutate


def _scale_rgba(m):
    values = [float(v) for v in m.group(1).split()]
    return 'rgba="' + " ".join(str(round(v * 255)) for v in values[:3]) + f' {values[3]:g}"'


def _swap_limits(m):
    return f'lower="{m.group(2)}" upper="{m.group(1)}"'


def _permute(m):
    return m.group(0).replace(f'ixx="{m.group(1)}"', "IXX").replace(
        f'izz="{m.group(2)}"', f'ixx="{m.group(2)}"').replace("IXX", f'izz="{m.group(1)}"')


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
    ("pre-1.0 <joint_properties>", "schema", ("schema.unknown-element",),
     _sub(r'(<joint name="[^"]*" type="(?:revolute|continuous)">)',
          r'\1<joint_properties damping="0.1" friction="0"/>', 0)),
    ("axis not unit", "joint", ("joint.axis-not-unit",),
     _sub(r'<axis xyz="0 0 1"', '<axis xyz="0 0 2"', 0)),
    ("axis not unit (y)", "joint", ("joint.axis-not-unit",),
     _sub(r'<axis xyz="0 1 0"', '<axis xyz="0 3 0"', 0)),
    ("limits swapped", "joint", ("joint.lower-above-upper",),
     _sub(r'lower="(-?[\d.]+)" upper="([\d.]+)"', _swap_limits, 0)),
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
     _sub(r'(<link name=")([^"]+)(">[\s\S]*?<link name=")([^"]+)"', r'\1\2\3\2"', 0)),
    ("mesh not found", "mesh", ("mesh.not-found", "mesh.unresolved"),
     _sub(r"<cylinder [^>]*/>", '<mesh filename="missing.stl"/>', 0)),
    ("undefined material", "material", ("material.undefined",),
     _sub(r'<material name="([^"]+)"\s*/>', r'<material name="\1_x"/>', 0)),
    ("zero-size box", "geometry", ("geometry.nonpositive-size",),
     _sub(r'<box size="([\d.]+) ', r'<box size="0 ', 0)),
]


def _problems(report) -> set:
    return {(d.rule, d.severity) for d in report.diagnostics if d.severity in ("error", "warning")}


def run_case(base: Path, name: str, family: str, rules: tuple, mutate, work: Path) -> dict | None:
    text = base.read_text(encoding="utf-8")
    mutated = mutate(text)
    if mutated is None:
        return None
    new_text, line = mutated
    shutil.rmtree(work, ignore_errors=True)
    shutil.copytree(base.parent.parent if base.parent.name == "corrected" else base.parent, work)
    relative = base.relative_to(base.parent.parent if base.parent.name == "corrected"
                                else base.parent)
    clean = check_file(work / relative)
    path = work / relative
    path.write_text(new_text, encoding="utf-8")
    broken = check_file(path)
    fired = [d for d in broken.diagnostics if d.rule in rules and abs((d.line or 0) - line) <= 3]
    if not fired:
        return {"case": name, "family": family, "base": base.parent.parent.name,
                "status": "not detected"}
    result = fix_file(path, CheckOptions(), unsafe=True)
    fixed_text = result.texts.get(str(path), new_text)
    changed = [i for i, (a, b) in enumerate(zip(new_text.split("\n"), fixed_text.split("\n")), 1)
               if a != b]
    others = [n for n in result.changed() if Path(n).resolve() != path.resolve()]
    path.write_text(fixed_text, encoding="utf-8")
    after = check_file(path, CheckOptions(look_through=False))
    still = [d for d in after.diagnostics if d.rule in rules and abs((d.line or 0) - line) <= 3]
    # added by the fix: neither in the clean original nor in the broken file
    new = _problems(after) - _problems(clean) - _problems(broken)
    worse = _problems(after) - _problems(clean) if not still else new
    far = [i for i in changed if abs(i - line) > 12]
    return {"case": name, "family": family, "base": base.parent.parent.name,
            "status": "fixed" if not still else "not fixed", "new": sorted(worse), "far": far,
            "others": others, "changed": changed}


def main() -> int:
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for key, relative in BASES.items():
            base = ROOT / "robots" / relative
            for name, family, rules, mutate in CASES:
                row = run_case(base, name, family, rules, mutate, Path(tmp) / key)
                if row is not None:
                    rows.append(row)
    detected = [r for r in rows if r["status"] != "not detected"]
    fixed = [r for r in detected if r["status"] == "fixed"]
    new = [r for r in detected if r.get("new")]
    far = [r for r in detected if r.get("far")]
    for r in rows:
        print(f"{r['base']:<17} {r['family']:<10} {r['case']:<28} {r['status']:<12} "
              f"new={r.get('new', [])} far={r.get('far', [])}")
    print(f"\n{len(detected)} detected single-defect cases ({len(rows) - len(detected)} "
          f"mutations not detected, left out): {len(fixed)} fixed "
          f"({100 * len(fixed) / max(len(detected), 1):.0f}%), {len(new)} with a new error or "
          f"warning, {len(far)} with a changed line more than 12 lines from the defect")
    by_family: dict[str, list] = {}
    for r in detected:
        by_family.setdefault(r["family"], []).append(r["status"] == "fixed")
    print("per family: " + ", ".join(f"{f} {sum(v)}/{len(v)}" for f, v in sorted(by_family.items())))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
