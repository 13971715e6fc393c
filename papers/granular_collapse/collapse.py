"""Regenerate the granular column collapse numbers and plot.

    python3 papers/granular_collapse/collapse.py [--cell 0.01] [--mpm PATH] [--out DIR]

Runs problems/collapse.toml at aspect ratios a = h0/d0 = 0.5, 1, 2, 4 (d0 = 0.2 m)
with square cells of size --cell, measures runout and height (measure.py), writes
DIR/results.csv and DIR/collapse.svg (ours beside the experimental laws).
"""
import argparse
import math
import os
import subprocess
import time

from measure import lube, measure

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
D0 = 0.2
# aspect ratio -> run time (kinetic energy has fallen below 1 % of its peak)
CASES = {0.5: 0.6, 1.0: 0.8, 2.0: 1.0, 4.0: 1.5}


def run_case(mpm, a, cell, out, extra):
    h0 = a * D0
    law = lube(a)[0] or 3.25 * a**0.96
    length = D0 * (1.0 + 1.35 * law) + 0.2
    height = h0 + 0.1
    nx, ny = math.ceil(length / cell), math.ceil(height / cell)
    d = os.path.join(out, f"a{a}_h{cell}")
    args = [
        mpm, "run", os.path.join(ROOT, "problems", "collapse.toml"), "--out", d,
        "--set", f"body.0.max=[{D0},{h0}]",
        "--set", f"grid.max=[{nx * cell},{ny * cell}]",
        "--set", f"grid.cells=[{nx},{ny}]",
        "--set", f"solver.end_time={CASES[a]}",
        "--set", "output.frames=0",
    ] + [x for e in extra for x in ("--set", e)]
    t0 = time.time()
    subprocess.run(args, check=True)
    m = measure(d, D0, h0)
    m["wall"] = time.time() - t0
    return m


def svg(rows, path):
    """Runout against a, log-log, with the laws (no plotting dependency)."""
    W, H, P = 480, 360, 50
    lx = lambda a: P + (math.log10(a) - math.log10(0.4)) / (math.log10(5) - math.log10(0.4)) * (W - 2 * P)
    ly = lambda r: H - P - (math.log10(r) - math.log10(0.5)) / (math.log10(20) - math.log10(0.5)) * (H - 2 * P)
    s = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="11">',
         f'<rect x="{P}" y="{P}" width="{W - 2 * P}" height="{H - 2 * P}" fill="none" stroke="black"/>']
    for lo, hi, c, e in ((0.65, 1.5, 3.25, 0.96), (1.5, 5.0, 3.80, 0.73)):
        pts = " ".join(f"{lx(a):.1f},{ly(c * a**e):.1f}" for a in [lo + (hi - lo) * i / 20 for i in range(21)])
        s.append(f'<polyline points="{pts}" fill="none" stroke="black"/>')
    for r in rows:
        if r["runout"] > 0:
            s.append(f'<circle cx="{lx(r["a"]):.1f}" cy="{ly(r["runout"]):.1f}" r="4" fill="{"red" if r["cell"] == min(x["cell"] for x in rows) else "blue"}"/>')
    for a in (0.5, 1, 2, 4):
        s.append(f'<text x="{lx(a) - 6:.1f}" y="{H - P + 15}">{a}</text>')
    for r in (1, 2, 5, 10):
        s.append(f'<text x="{P - 20}" y="{ly(r) + 4:.1f}">{r}</text>')
    s.append(f'<text x="{W / 2 - 40}" y="{H - 10}">a = h0/d0</text>')
    s.append(f'<text x="5" y="{P - 10}">(d_inf - d0)/d0: lines Lube et al. laws, dots MPM (red finest)</text>')
    s.append("</svg>")
    open(path, "w").write("\n".join(s))


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--cell", type=float, nargs="+", default=[0.01])
    ap.add_argument("--mpm", default=os.path.join(os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target")), "release", "mpm"))
    ap.add_argument("--out", default="collapse_out")
    ap.add_argument("--aspect", type=float, nargs="+", default=list(CASES))
    ap.add_argument("--set", action="append", default=[], help="extra scene override")
    o = ap.parse_args()
    rows = []
    for cell in o.cell:
        for a in o.aspect:
            m = run_case(o.mpm, a, cell, o.out, o.set)
            run_law, h_law = lube(a)
            rows.append(dict(a=a, cell=cell, **m, runout_law=run_law or float("nan"), height_law=h_law or float("nan")))
            r = rows[-1]
            print(f"a={a} cell={cell}: runout {r['runout']:.3f} (law {r['runout_law']:.3f}), "
                  f"h/h0 {r['height_ratio']:.3f} (law {r['height_law']:.3f}), KE end/peak {r['ke_ratio']:.1e}, wall {r['wall']:.0f} s", flush=True)
    keys = ["a", "cell", "runout", "runout_law", "height_ratio", "height_law", "front", "front_max", "height", "ke_ratio", "t_end", "wall"]
    with open(os.path.join(o.out, "results.csv"), "w") as f:
        f.write(",".join(keys) + "\n")
        for r in rows:
            f.write(",".join(f"{r[k]:.6g}" for k in keys) + "\n")
    svg(rows, os.path.join(o.out, "collapse.svg"))
