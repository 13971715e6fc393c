#!/usr/bin/env python3
"""results.csv from the runs of reproduce.sh (their measure.json), or, with
--svg RUN_DIR, an SVG of that run's plate coloured by damage at its end."""
import csv, json, os, sys

RUNS = ["dx2", "dx1", "dx05", "dx1_g42", "dx1_v32", "dx1_beam"]


def table(out):
    print("run,dx_mm,particles,upper_angle_deg,lower_angle_deg,upper_tip_speed_max_m_s,"
          "crack_length_90us_mm,damaged_between_the_notches")
    for name in RUNS:
        path = os.path.join(out, name, "measure.json")
        if not os.path.exists(path):
            continue
        m = json.load(open(path))
        print(f"{name},{m['dx'] * 1e3:g},{m['particles']},{m['upper_angle_deg']},"
              f"{m['lower_angle_deg']},{m['upper_tip_speed_max_m_s']:.0f},"
              f"{m['tip_history_us_mm'][-1][1]},{m['damaged_between_the_notches']}")


def svg(run):
    rows = [r for r in csv.DictReader(open(os.path.join(run, "particles_final.csv")))
            if r["body"] == "0"]
    scale = 3000.0  # px per m
    print(f'<svg xmlns="http://www.w3.org/2000/svg" width="{0.1 * scale:.0f}" '
          f'height="{0.2 * scale:.0f}">')
    print('<rect width="100%" height="100%" fill="white"/>')
    for r in rows:
        d = float(r["damage"])
        if d < 0.05:
            continue
        x, y = float(r["X0"]) * scale, (0.2 - float(r["Y0"])) * scale
        shade = int(255 * (1.0 - min(d, 0.6) / 0.6))
        print(f'<rect x="{x - 1.5:.1f}" y="{y - 1.5:.1f}" width="3" height="3" '
              f'fill="rgb(255,{shade},{shade})"/>')
    for y0 in (0.07425, 0.12425):
        print(f'<rect x="0" y="{(0.2 - y0 - 0.0015) * scale:.1f}" width="{0.05 * scale:.0f}" '
              f'height="{0.0015 * scale:.1f}" fill="black"/>')
    print("</svg>")


if len(sys.argv) > 3 and sys.argv[2] == "--svg":
    svg(sys.argv[3])
else:
    table(sys.argv[1])
