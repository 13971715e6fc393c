#!/usr/bin/env python3
"""Final shape of a Taylor bar run (3D quarter model with the axis along z, or the
axisymmetric r-z model with x = r, y = z; anvil at axial coordinate 0) from
particles_final.csv: length L, impact-face diameter D and the diameter W at
0.2 L0 above the anvil, in mm.

Usage: measure.py OUT_DIR [L0_mm R_mm]

Each particle's final radius r is scaled by R/r0 (r0 its initial radius), i.e.
the body's surface is placed where the outermost particle of a layer maps it
under that layer's radial stretch; L is the highest particle plus its initial
distance to the top face (the rear of the bar stays nearly rigid).
"""
import csv
import math
import sys


def measure(out_dir, l0=25.4, radius=3.8):
    rows = list(csv.DictReader(open(f"{out_dir}/particles_final.csv")))
    mm = 1e3
    if "z" not in rows[0]:
        # Axisymmetric: radius x, axis y.
        for r in rows:
            r["Z0"], r["z"], r["Y0"], r["y"] = r["Y0"], r["y"], "0", "0"
    z0s = sorted({round(float(r["Z0"]) * mm, 9) for r in rows})
    spacing = z0s[1] - z0s[0]
    top = max(rows, key=lambda r: float(r["z"]))
    length = float(top["z"]) * mm + (l0 - float(top["Z0"]) * mm)

    def diameter(select):
        best = 0.0
        for r in rows:
            if not select(r):
                continue
            r0 = math.hypot(float(r["X0"]), float(r["Y0"])) * mm
            rf = math.hypot(float(r["x"]), float(r["y"])) * mm
            if r0 > radius - spacing:  # outermost ring of its layer
                best = max(best, 2.0 * rf * radius / r0)
        return best

    bottom = z0s[0]
    d = diameter(lambda r: abs(float(r["Z0"]) * mm - bottom) < 1e-6)
    h = 0.2 * l0
    w = diameter(lambda r: abs(float(r["z"]) * mm - h) < 0.5 * spacing)
    return length, d, w


if __name__ == "__main__":
    out = sys.argv[1]
    args = [float(a) for a in sys.argv[2:4]]
    length, d, w = measure(out, *args)
    measured = (16.2, 13.5, 10.1)
    errors = [abs(a / b - 1.0) for a, b in zip((length, d, w), measured)]
    print(f"L {length:.2f} mm  D {d:.2f} mm  W {w:.2f} mm  "
          f"(test 16.2 / 13.5 / 10.1; errors {errors[0]:.1%} {errors[1]:.1%} {errors[2]:.1%}, "
          f"mean {sum(errors) / 3:.1%})")
