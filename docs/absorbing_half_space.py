#!/usr/bin/env python3
"""Half-space under a surface line-load pulse: absorbing 10 m grid against a 25 m
grid from which no reflection reaches the probes in time (docs/absorbing.md).

Regenerate (python3, standard library only):

    MPM_HALF_SPACE_CSV=docs/absorbing_half_space.csv \\
        cargo test --release --test verification -- --nocapture absorbing::half_space
    python3 docs/absorbing_half_space.py

prints the markdown tables of docs/absorbing.md and writes
docs/absorbing_half_space.svg (velocity histories at the two probes).
"""

import csv
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
SERIES = [
    ("surface_vx", "surface, 3 m from the load: v_x"),
    ("surface_vy", "surface, 3 m from the load: v_y"),
    ("axis_vy", "axis, depth 4 m: v_y"),
]
RUNS = [("ref", "25 m grid (reference)", "#000000"),
        ("dashpots", "10 m grid, dashpots", "#1f77b4"),
        ("fixed", "10 m grid, fixed faces", "#d62728")]


def read(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def errors(data, key, run):
    ref, other = data[key + "_ref"], data[key + "_" + run]
    l2 = math.sqrt(sum((a - b) ** 2 for a, b in zip(other, ref)) / sum(b * b for b in ref))
    peak = max(abs(b) for b in ref)
    worst = max(abs(a - b) for a, b in zip(other, ref)) / peak
    return l2, worst, peak


def tables(data):
    print("| probe | peak (mm/s) | relative L2, dashpots | relative L2, fixed | max/peak, dashpots | max/peak, fixed |")
    print("|---|---|---|---|---|---|")
    for key, name in SERIES:
        l2a, mxa, peak = errors(data, key, "dashpots")
        l2f, mxf, _ = errors(data, key, "fixed")
        print(f"| {name} | {peak * 1e3:.3f} | {l2a:.3f} | {l2f:.3f} | {mxa:.3f} | {mxf:.3f} |")
    print()
    print("| t (s) | " + " | ".join(f"{name} ({run}, mm/s)" for key, name in SERIES[1:] for run in ("ref", "dashpots", "fixed")) + " |")
    print("|---" * 7 + "|")
    t = data["t"]
    for target in [0.03, 0.045, 0.06, 0.075, 0.09, 0.105, 0.12, 0.15, 0.18, 0.21, 0.24]:
        i = min(range(len(t)), key=lambda i: abs(t[i] - target))
        cells = [f"{data[key + '_' + run][i] * 1e3:+.3f}" for key, _ in SERIES[1:] for run in ("ref", "dashpots", "fixed")]
        print(f"| {t[i]:.3f} | " + " | ".join(cells) + " |")


def svg(data, path):
    width, height, margin = 760, 230, 55
    t = data["t"]
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height * 3 + 40}" font-family="sans-serif" font-size="12">',
             '<rect width="100%" height="100%" fill="white"/>']
    for k, (key, name) in enumerate(SERIES):
        y0 = 20 + k * height
        values = [v for run, _, _ in RUNS for v in data[key + "_" + run]]
        vmax = max(abs(v) for v in values)
        sx = lambda x: margin + (width - margin - 10) * x / t[-1]
        sy = lambda v: y0 + (height - 40) * (0.5 - 0.5 * v / vmax)
        parts.append(f'<text x="{margin}" y="{y0 - 4}">{name} (±{vmax * 1e3:.2f} mm/s full scale)</text>')
        parts.append(f'<rect x="{margin}" y="{y0}" width="{width - margin - 10}" height="{height - 40}" fill="none" stroke="#888"/>')
        parts.append(f'<line x1="{margin}" x2="{width - 10}" y1="{sy(0)}" y2="{sy(0)}" stroke="#ccc"/>')
        for tick in [0.0, 0.05, 0.1, 0.15, 0.2, 0.25]:
            parts.append(f'<text x="{sx(tick) - 10}" y="{y0 + height - 24}">{tick:.2f}</text>')
        for run, label, colour in RUNS:
            pts = " ".join(f"{sx(x):.1f},{sy(v):.1f}" for x, v in zip(t, data[key + "_" + run]))
            parts.append(f'<polyline points="{pts}" fill="none" stroke="{colour}" stroke-width="1.2"/>')
    for i, (run, label, colour) in enumerate(RUNS):
        parts.append(f'<text x="{margin + 220 * i}" y="{3 * height + 30}" fill="{colour}">— {label}</text>')
    parts.append(f'<text x="{width - 60}" y="{3 * height + 30}">t (s)</text>')
    parts.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(parts) + "\n")


if __name__ == "__main__":
    data = read(os.path.join(HERE, "absorbing_half_space.csv"))
    tables(data)
    svg(data, os.path.join(HERE, "absorbing_half_space.svg"))
