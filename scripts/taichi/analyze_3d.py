#!/usr/bin/env python3
"""Summarise results.jsonl from bench_3d.py: medians of particle-steps/s per size and
variant, ratios mpm / Taichi, peak RSS; lattice and motion check against the Taichi
dumps (compare_motion_3d.py).  The 3D variant of ../shared/peers/taichi/analyze.py;
a ratio column is left empty when its Taichi variant was not run."""
import json
import os
import statistics as st
import subprocess
import sys

out = sys.argv[1]
rows = [json.loads(l) for l in open(os.path.join(out, "results.jsonl"))]
here = os.path.dirname(os.path.abspath(__file__))
groups = {}
for r in rows:
    groups.setdefault((r["n"], r["program"], r["variant"]), []).append(r)


def ratio(m, ref):
    return f"{m / ref:.3f}" if ref else "–"


print("| particles (grid) | steps | program | runs | median M p-steps/s (min–max) | / Taichi f64 | / Taichi f32 | peak RSS MiB | load avg |")
print("|---|---:|---|---:|---|---:|---:|---:|---:|")
for n in sorted({k[0] for k in groups}):
    med = {k[1:]: st.median(r["pss"] for r in v) for k, v in groups.items() if k[0] == n}
    for prog, var in [("taichi", "f64"), ("taichi", "f32"), ("mpm", "usl"), ("mpm", "usf"), ("mpm", "musl")]:
        g = groups.get((n, prog, var))
        if not g:
            continue
        p = [r["pss"] / 1e6 for r in g]
        m = st.median(p)
        rss = st.median(r["max_rss_kb"] for r in g) / 1024
        load = st.median(r["load1"] for r in g)
        name = f"Taichi {var}" if prog == "taichi" else f"mpm {var.upper()}"
        print(f"| {g[0]['particles']:,} ({n}³) | {g[0]['steps']} | {name} | {len(g)} | {m:.2f} ({min(p):.2f}–{max(p):.2f}) "
              f"| {ratio(m * 1e6, med.get(('taichi', 'f64')))} | {ratio(m * 1e6, med.get(('taichi', 'f32')))} "
              f"| {rss:.0f} | {load:.1f} |")

# ratio per round (same round, same size: the runs were back to back)
print("\nper-round ratio mpm/Taichi-f64 (median over rounds):")
for n in sorted({k[0] for k in groups}):
    for var in ("usl", "usf", "musl"):
        rs = []
        for rnd in sorted({r["round"] for r in rows}):
            a = [r["pss"] for r in rows if r["n"] == n and r["round"] == rnd and r["program"] == "mpm" and r["variant"] == var]
            b = [r["pss"] for r in rows if r["n"] == n and r["round"] == rnd and r["program"] == "taichi" and r["variant"] == "f64"]
            if a and b:
                rs.append(a[0] / b[0])
        if rs:
            print(f"  n={n} {var}: median {st.median(rs):.3f}  rounds {' '.join(f'{x:.3f}' for x in rs)}")

# CPU per wall second of the whole process (how much of the 2 cores each program got)
print("\nprocess CPU / wall (user + sys over elapsed), median:")
for n in sorted({k[0] for k in groups}):
    for (prog, var), g in sorted((k[1:], v) for k, v in groups.items() if k[0] == n):
        print(f"  n={n} {prog} {var}: {st.median((r['user_s'] + r['sys_s']) / r['process_wall_s'] for r in g):.2f}")

# setup: process wall - loop wall (mpm)
print("\nmpm process wall - stepping loop (setup + final output), median s:")
for n in sorted({k[0] for k in groups}):
    g = groups.get((n, "mpm", "usl"), [])
    if g:
        print(f"  n={n}: {st.median(r['process_wall_s'] - r['loop_s'] for r in g):.2f} s of "
              f"{st.median(r['process_wall_s'] for r in g):.2f} s")

print("\nlattice and motion (final positions after the timed steps):")
for n in sorted({k[0] for k in groups}):
    npy = os.path.join(out, f"taichi_n{n}_f64.npy")
    for var in ("usl", "usf", "musl"):
        csv = os.path.join(out, f"mpm_n{n}_{var}", "particles_final.csv")
        if os.path.exists(npy) and os.path.exists(csv):
            r = subprocess.run([sys.executable, os.path.join(here, "compare_motion_3d.py"), csv, npy, str(n)],
                               capture_output=True, text=True)
            print(f"  n={n} mpm {var} vs Taichi f64:\n    " + (r.stdout + r.stderr[-500:]).strip().replace("\n", "\n    "))
