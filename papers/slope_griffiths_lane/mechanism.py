"""Draw the failure mechanism of a strength-reduction search as an SVG.

Usage: python3 mechanism.py OUT_DIR mechanism.svg
Reads OUT_DIR/summary.json, takes the last stable trial (`mechanism_stable`) and
shades the equivalent plastic strain `eps_p` of its particles_final.csv, averaged
over 0.5 m bins of the current positions (standard library only).
"""
import csv
import json
import pathlib
import sys

out, svg = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
summary = json.loads((out / "summary.json").read_text())
trial = out / summary["mechanism_stable"]
rows = list(csv.DictReader(open(trial / "particles_final.csv")))
BIN, SCALE = 0.5, 20.0  # m, pixels per m
bins = {}
for r in rows:
    key = (int(float(r["x"]) // BIN), int(float(r["y"]) // BIN))
    s, n = bins.get(key, (0.0, 0))
    bins[key] = (s + float(r["eps_p"]), n + 1)
mean = {k: s / n for k, (s, n) in bins.items()}
peak = max(mean.values())
width, height = 40 * SCALE, 12 * SCALE
parts = [
    f'<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0f}" height="{height + 40:.0f}">',
    f'<rect width="100%" height="100%" fill="white"/>',
]
for (i, j), e in sorted(mean.items()):
    level = min(1.0, e / peak) ** 0.5  # square root: the band and its fringe
    red, blue = int(255 * level), int(255 * (1 - level))
    x, y = i * BIN * SCALE, height - (j + 1) * BIN * SCALE
    parts.append(
        f'<rect x="{x:.1f}" y="{y:.1f}" width="{BIN * SCALE:.1f}" height="{BIN * SCALE:.1f}" '
        f'fill="rgb({red},{int(80 * (1 - level))},{blue})"/>'
    )
parts.append(
    f'<polygon points="0,{height - 10 * SCALE} {15 * SCALE},{height - 10 * SCALE} {35 * SCALE},{height} 0,{height}" '
    'fill="none" stroke="black" stroke-width="1"/>'
)
parts.append(
    f'<text x="5" y="{height + 25:.0f}" font-family="sans-serif" font-size="13">'
    f'eps_p (bin means, sqrt scale, red = {peak:.3g}) at F = {trial.name.split("_F")[1]}; '
    f'outline: initial slope</text>'
)
parts.append("</svg>")
svg.write_text("\n".join(parts) + "\n")
print(f"{svg}: {len(mean)} bins, peak bin eps_p {peak:.3g}, trial {trial.name}")
