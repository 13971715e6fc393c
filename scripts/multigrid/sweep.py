#!/usr/bin/env python3
"""Krylov iterations of the multigrid preconditioner per Newton iteration over three
refinements, per shape function (issue 18's targets; docs/multigrid.md).

usage: scripts/multigrid/sweep.py MPM OUT [--threads N] [CASE_SUBSTRING ...]

Runs problems/bench/block.toml (self-weight block, Hencky, fixed base, 4 load steps)
at 40², 80², 160² cells for each shape function, the same block at ν = 0.49, and
problems/bench/two_layer_block.toml (a 10³ stiffness contrast), all with CG +
multigrid to a relative tolerance of 1e-8, and prints the smallest and largest
Krylov count over the Newton iterations that solved a system (iteration 0 of a step
included) beside the wall time of the stepping loop."""
import csv
import json
import os
import subprocess
import sys

mpm, out = sys.argv[1], sys.argv[2]
threads = sys.argv[sys.argv.index("--threads") + 1] if "--threads" in sys.argv else "2"
root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
block = os.path.join(root, "problems/bench/block.toml")
layers = os.path.join(root, "problems/bench/two_layer_block.toml")
mg = ["solver.linear_solver=cg", "solver.preconditioner=multigrid", "solver.krylov_tolerance=1e-8"]


def run(scene, name, sets):
    d = os.path.join(out, name)
    cmd = [mpm, "run", scene, "--out", d, "--threads", threads]
    for s in mg + sets:
        cmd += ["--set", s]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        return None, r.stderr.strip().splitlines()[-1] if r.stderr.strip() else "failed"
    rows = list(csv.DictReader(open(os.path.join(d, "newton.csv"))))
    its = [int(x["krylov_iterations"]) for x in rows if int(x["krylov_iterations"]) > 0]
    summary = json.load(open(os.path.join(d, "summary.json")))
    wall = sum(s["wall_seconds"] for s in summary["stages"])
    return (min(its), max(its), len(rows), wall), None


cases = []
for shape in ["linear", "ugimp", "cpgimp", "cpdi", "bspline2"]:
    for n in (40, 80, 160):
        cases.append((f"block {shape}", n, block, [f"grid.cells=[{n},{n}]", f"grid.shape_function=\"{shape}\""]))
for n in (40, 80, 160):
    # A grid 1 m wider on each side and above: the nearly incompressible block bulges.
    cases.append(("block ugimp ν=0.49", n, block,
                  [f"grid.cells=[{n * 12 // 10},{n * 11 // 10}]", "grid.min=[-1.0,0.0]",
                   "grid.max=[11.0,11.0]", "material.0.poisson_ratio=0.49"]))
for n in (40, 80, 160):
    cases.append(("two layers, E ratio 10³, ugimp", n, layers, [f"grid.cells=[{n},{n}]"]))
only = [a for a in sys.argv[3:] if not a.startswith("--") and a != threads]
if only:
    cases = [c for c in cases if any(o in c[0] for o in only)]
print("| case | cells | Krylov its per Newton it (min–max) | Newton its | loop s |")
print("|---|---:|---|---:|---:|")
for label, n, scene, sets in cases:
    res, err = run(scene, f"{label.replace(' ', '_').replace('=', '')}_{n}", sets)
    if res is None:
        print(f"| {label} | {n}² | failed: {err} | | |", flush=True)
    else:
        print(f"| {label} | {n}² | {res[0]}–{res[1]} | {res[2]} | {res[3]:.2f} |", flush=True)
