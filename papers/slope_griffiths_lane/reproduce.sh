#!/usr/bin/env bash
# Regenerate the factor-of-safety tables of README.md: strength reduction of
# problems/slope_griffiths_lane.toml on refined grids (h = H/10 … H/50).
# Usage: papers/slope_griffiths_lane/reproduce.sh [OUT_DIR]   (from the repository root)
# Needs a release build: cargo build --release (mpm on the PATH or in $MPM).
set -euo pipefail
MPM=${MPM:-mpm}
OUT=${1:-out/slope_griffiths_lane}
SCENE=problems/slope_griffiths_lane.toml
mkdir -p "$OUT"
# FBAR=false reproduces the table without F-bar (the scene ships fbar = true);
# cells (40 m × 12 m grid) → h = 1, 1/2, 1/3, 1/4, 1/5 m.
FBAR=${FBAR:-true}
for cells in 40,12 80,24 120,36 160,48 200,60; do
  dir="$OUT/cells_${cells/,/x}"
  "$MPM" run "$SCENE" --out "$dir" --set "grid.cells=[$cells]" --set "solver.fbar=$FBAR" > "$dir.log" 2>&1 || true
done
python3 - "$OUT" <<'PY'
import json, sys, pathlib
out = pathlib.Path(sys.argv[1])
print("| h (m) | particles | F (bracket) | F / 1.40 | F at crest displacement > 0.1 m | trials | wall s | Newton it. per converged trial |")
print("|---|---|---|---|---|---|---|---|")
rows = []
for d in sorted(out.glob("cells_*[0-9]"), key=lambda p: int(p.name.split("_")[1].split("x")[0])):
    s = json.loads((d / "summary.json").read_text())
    nx = int(d.name.split("_")[1].split("x")[0])
    lo, hi = s.get("factor_of_safety_bracket", [float("nan")] * 2)
    f = s.get("factor_of_safety", float("nan"))
    stable = sorted((t["factor"], t["monitor_displacement"]) for t in s["trials"] if t["status"] == "stable")
    failed = sorted(t["factor"] for t in s["trials"] if t["status"] != "stable")
    # Runaway criterion from the same trials: first stable F whose crest moved > 0.1 m.
    over = [fa for fa, u in stable if u is not None and u > 0.1]
    below = [fa for fa, u in stable if u is not None and u <= 0.1]
    disp = f"{max(below):.4f}–{min(over + failed):.4f}" if below else "n/a"
    conv = [t["newton_iterations"] for t in s["trials"] if t["status"] == "stable"]
    print(f"| {40/nx:.3f} | {s['particles']} | {f:.4f} [{lo:.4f}, {hi:.4f}] | {f/1.40:.3f} | {disp} | {len(s['trials'])} | {s['wall_seconds']:.0f} | {min(conv)}–{max(conv)} |")
    rows.append((40 / nx, f))
# F = F0 + a h^p through the three finest grids (p by bisection on the ratio of differences).
if len(rows) >= 3:
    (h1, f1), (h2, f2), (h3, f3) = sorted(rows, reverse=True)[-3:]
    ratio = (f1 - f2) / (f2 - f3)
    g = lambda p: (h1**p - h2**p) / (h2**p - h3**p) - ratio
    lo_p, hi_p = 0.1, 6.0
    if g(lo_p) * g(hi_p) < 0:
        for _ in range(100):
            mid = 0.5 * (lo_p + hi_p)
            lo_p, hi_p = (mid, hi_p) if g(lo_p) * g(mid) > 0 else (lo_p, mid)
        p = 0.5 * (lo_p + hi_p)
        a = (f2 - f3) / (h2**p - h3**p)
        print(f"\nextrapolated from h = {h1:.3f}, {h2:.3f}, {h3:.3f}: F0 = {f3 - a * h3**p:.4f} (F = F0 + {a:.3f} h^{p:.2f})")
    else:
        print("\nno monotone refinement trend to extrapolate")
PY
# The mechanism of the finest grid (last stable trial).
svg=mechanism_fbar.svg; [ "$FBAR" = true ] || svg=mechanism.svg
python3 "$(dirname "$0")/mechanism.py" "$OUT/cells_160x48" "$(dirname "$0")/$svg"
