#!/usr/bin/env python3
"""Imports every example of Pyslvs's collection and checks the result.

    python3 tools/check/pyslvs_examples.py PATH/TO/pyslvs/example.py target/debug/dofplan [-v]

Pyslvs (AGPL) is not imported and nothing of it is kept: `example.py` is
read as text and its example dictionary taken out with `ast` (a literal);
should a version build it with code, the file is run with a stub for every
module it imports that is not installed. Get the file with

    pip download --no-deps --no-binary :all: pyslvs==22.7.0 -d /tmp/pyslvs-dl
    tar xzf /tmp/pyslvs-dl/pyslvs-22.7.0.tar.gz -C /tmp/pyslvs-dl
    # then /tmp/pyslvs-dl/pyslvs-22.7.0/pyslvs/example.py

For every example (an expression and its input pairs) it writes the two
to a temporary file, runs `dofplan import` on it, then `dofplan check
--json` and `dofplan simulate --json` on the mechanism written, and checks
from the JSON alone, with its own reading of the expression, that every
point's joint closes in every solved frame:

- an R point's markers (one on each link it lists) coincide;
- a P or RP point's markers off the slot's link (the pinned links', the
  slider block's) coincide and lie on the slot's line (through the slot
  link's marker, at the point's angle A turned with the slot's link);
- a P point's pinned links keep their angle to the slot's link;

and, from `simulate --from 0 --to 0`, that the pose at input 0 is the
drawn one: every marker Pk at the expression's P[x, y] of point k.
Residuals are relative to the mechanism's size (the diagonal of its points'
bounding box), the tolerance 1e-9. An example dofplan cannot express must
fail to import with an error naming why (those expected are listed in
`CANNOT_EXPRESS`, with the reason); one that fails otherwise, or a residual
over the tolerance, makes the exit status 1. Standard library only,
Python 3.9 or later.
"""

import argparse
import ast
import importlib.util
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import types

TOLERANCE = 1e-9

# Examples dofplan cannot express, by name, and why. Every example of
# Pyslvs 22.7.0 imports: R, P and RP points all have a dofplan form.
CANNOT_EXPRESS = {}


# --- reading example.py -------------------------------------------------------


NAME = "_example_list"


def is_collection(value):
    """Whether `value` looks like the collection: names to (expression, pairs)."""
    return (
        isinstance(value, dict)
        and value
        and all(isinstance(v, tuple) and len(v) == 2 and isinstance(v[0], str) for v in value.values())
    )


def examples_from(path):
    """{name: (expression, input pairs)} of Pyslvs's example.py: the literal
    assigned to `_example_list`, else what running the file puts there."""
    with open(path, encoding="utf-8") as f:
        source = f.read()
    tree = ast.parse(source, path)
    literals = []
    for node in ast.walk(tree):
        target = None
        if isinstance(node, ast.AnnAssign):
            target = node.target
        elif isinstance(node, ast.Assign) and len(node.targets) == 1:
            target = node.targets[0]
        if not isinstance(target, ast.Name) or node.value is None:
            continue
        try:
            value = ast.literal_eval(node.value)
        except ValueError:
            value = None
        if target.id == NAME:
            if is_collection(value):
                return value
            return examples_by_running(source, path)
        if is_collection(value):
            literals.append(value)
    if literals:
        return literals[0]
    return examples_by_running(source, path)


def examples_by_running(source, path):
    """The collection of a file that builds it with code: the file is run
    with every module it imports and cannot find replaced by a stub."""
    for node in ast.walk(ast.parse(source, path)):
        names = []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module]
        for name in names:
            top = name.split(".")[0]
            if top not in sys.modules and importlib.util.find_spec(top) is None:
                stub = types.ModuleType(name)
                stub.__getattr__ = lambda attr: (lambda *a, **k: None)
                sys.modules[name] = stub
    namespace = {"__name__": "pyslvs_example"}
    exec(compile(source, path, "exec"), namespace)
    if is_collection(namespace.get(NAME)):
        return namespace[NAME]
    for value in namespace.values():
        if is_collection(value):
            return value
    sys.exit(f"{path}: no example collection found")


# --- reading an expression (independently of dofplan) -----------------------

POINT = re.compile(
    r"J\[\s*(RP|R|P)\s*"
    r"(?:,\s*A\[\s*([^\]]+?)\s*\])?\s*"
    r"(?:,\s*color\[(?:[^\[\]]|\[[^\]]*\])*\])?\s*"
    r",\s*P\[\s*([^,\]]+?)\s*,\s*([^\]]+?)\s*\]\s*"
    r",\s*L\[\s*([^\]]*?)\s*\]\s*\]"
)


def points_of(expression):
    """[(type, angle in degrees or None, (x, y), [links])] in order."""
    found = []
    for m in POINT.finditer(expression):
        kind, angle, x, y, links = m.groups()
        names = [n.strip() for n in links.split(",") if n.strip()]
        found.append((kind, float(angle) if angle else None, (float(x), float(y)), names))
    return found


# --- residuals ----------------------------------------------------------------


def size_of(points):
    xs = [p[2][0] for p in points]
    ys = [p[2][1] for p in points]
    size = math.hypot(max(xs) - min(xs), max(ys) - min(ys))
    return size if size > 0 else 1.0


def frame_residual(points, frame):
    """The largest gap of any point's joint in one frame (length units)."""
    markers = frame["markers"]
    bodies = frame["bodies"]
    worst = 0.0
    for k, (kind, angle, _, links) in enumerate(points):
        at = {key.rsplit(".", 1)[0]: xy for key, xy in markers.items() if key.rsplit(".", 1)[1] == f"P{k}"}
        if kind == "R" or len(links) < 2:
            group = list(at.values())
        else:
            slot = links[0]
            group = [xy for body, xy in at.items() if body != slot]
            turn = math.radians(bodies[slot]["angle"])
            a = math.radians(angle) + turn
            sx, sy = at[slot]
            for px, py in group:
                worst = max(worst, abs(math.cos(a) * (py - sy) - math.sin(a) * (px - sx)))
            if kind == "P":
                for pin in links[1:]:
                    d = (bodies[pin]["angle"] - bodies[slot]["angle"] + 180.0) % 360.0 - 180.0
                    worst = max(worst, abs(math.radians(d)) * size_of(points))
        for x, y in group[1:]:
            worst = max(worst, math.hypot(x - group[0][0], y - group[0][1]))
    return worst


def drawn_residual(points, frame):
    """How far the markers of the pose at input 0 are from the drawing."""
    worst = 0.0
    for key, (x, y) in frame["markers"].items():
        k = int(key.rsplit(".", 1)[1][1:])
        px, py = points[k][2]
        worst = max(worst, math.hypot(x - px, y - py))
    return worst


# --- running dofplan ----------------------------------------------------------


def run(binary, *args):
    return subprocess.run([binary, *args], capture_output=True, text=True)


def first_error(text):
    lines = [l.strip() for l in text.splitlines() if l.strip()]
    return lines[0] if lines else "(no message)"


def check_example(binary, name, expression, inputs, folder, verbose):
    """One row of the table: (example, bodies, joints, frames, result,
    worst residual, ok)."""
    slug = re.sub(r"[^A-Za-z0-9_]+", "_", name).strip("_").lower() or "example"
    source = os.path.join(folder, slug + ".pmks")
    toml = os.path.join(folder, slug + ".toml")
    with open(source, "w", encoding="utf-8") as f:
        f.write(expression + "\n" + repr(tuple(tuple(p) for p in inputs)) + "\n")
    imported = run(binary, "import", source, "--name", slug, "--out", toml)
    if imported.returncode != 0:
        why = first_error(imported.stderr)
        if name in CANNOT_EXPRESS:
            return (name, "-", "-", "-", f"cannot express (expected): {why}", "-", True)
        return (name, "-", "-", "-", f"IMPORT FAILED: {why}", "-", False)
    if name in CANNOT_EXPRESS:
        return (name, "-", "-", "-", "imported, but listed as inexpressible", "-", False)
    check = run(binary, "check", "--json", toml)
    if check.returncode != 0:
        return (name, "-", "-", "-", f"CHECK FAILED: {first_error(check.stderr or check.stdout)}", "-", False)
    report = json.loads(check.stdout)
    bodies, joints = report["bodies"], report["joints"]
    simulated = run(binary, "simulate", "--json", toml)
    drawn = run(binary, "simulate", "--json", toml, "--from", "0", "--to", "0", "--steps", "1")
    if simulated.returncode != 0 or drawn.returncode != 0:
        why = first_error(simulated.stderr or drawn.stderr)
        return (name, bodies, joints, "-", f"SIMULATE FAILED: {why}", "-", False)
    points = points_of(expression)
    size = size_of(points)
    frames = json.loads(simulated.stdout)["frames"]
    solved = [f for f in frames if f["status"] == "solved"]
    worst = max((frame_residual(points, f) for f in solved), default=0.0) / size
    zero = json.loads(drawn.stdout)["frames"][0]
    worst_drawn = drawn_residual(points, zero) / size if zero["status"] == "solved" else math.inf
    if verbose:
        print(f"{name}: {len(solved)}/{len(frames)} frames solved, joints {worst:.1e}, drawn {worst_drawn:.1e}")
    ok = solved and worst <= TOLERANCE and worst_drawn <= TOLERANCE
    result = "ok" if ok else ("NO SOLVED FRAME" if not solved else "RESIDUAL TOO LARGE")
    return (name, bodies, joints, f"{len(solved)}/{len(frames)}", result, f"{max(worst, worst_drawn):.1e}", bool(ok))


def table(rows):
    head = ("example", "bodies", "joints", "solved", "result", "worst residual")
    cells = [head] + [tuple(str(c) for c in r[:6]) for r in rows]
    widths = [max(len(r[i]) for r in cells) for i in range(len(head))]
    lines = []
    for i, r in enumerate(cells):
        lines.append("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())
        if i == 0:
            lines.append("  ".join("-" * w for w in widths))
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("example_py", help="Pyslvs's pyslvs/example.py")
    parser.add_argument("dofplan", help="the dofplan binary (e.g. target/debug/dofplan)")
    parser.add_argument("-v", "--verbose", action="store_true")
    args = parser.parse_args()
    examples = examples_from(args.example_py)
    with tempfile.TemporaryDirectory(prefix="pyslvs-examples-") as folder:
        rows = [
            check_example(args.dofplan, name, expression, inputs, folder, args.verbose)
            for name, (expression, inputs) in sorted(examples.items())
        ]
    print(table(rows))
    failed = [r[0] for r in rows if not r[6]]
    print(f"\n{len(rows) - len(failed)} of {len(rows)} examples pass (tolerance {TOLERANCE:g} of the mechanism's size)")
    if failed:
        print("failed: " + ", ".join(failed))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
