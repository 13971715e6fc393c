"""Hertz line contact from an `mpm run problems/contact_hertz.toml` output.

A rigid cylinder of radius R pressed into an elastic half-space (plane strain):
contact half-width b = sqrt(4 P R / (pi E*)), peak pressure p0 = 2 P / (pi b),
E* = E / (1 - nu^2), P the force per unit length; below the centre of the contact
sigma_z(z) = -p0 / sqrt(1 + z^2 / b^2) (Johnson 1985, Contact Mechanics, §4.2 and
eq. 5.33 with x = 0).

Reads contact.csv (P) and particles_final.csv, and prints Hertz's b and p0 for the
measured P beside two measurements:
- the axis fit: 1/sigma_yy^2 = 1/p0^2 + z^2 / (p0^2 b^2), linear in z^2, fitted by
  least squares to the particles of the column nearest x = 0 at depths from one
  cell to 1.6 b (the block is 8 b deep, so deeper points feel its base);
- the top layer's sigma_yy(x), a quarter cell below the surface: the width b of
  p^2 = p0^2 (1 - x^2/b^2) fitted to its points with p > p_max/4, and its peak.
  The contact acts at the top particles' contact points, on the block's surface,
  so that layer carries the pressure (its peak within 2 % of p0 from 3 cells
  across 2b).

usage: python3 hertz.py OUTDIR [R E NU H]
"""
import csv
import math
import sys


def fit_line(pts):
    """Least-squares (intercept, slope) of y = a + s x over (x, y) points."""
    n = len(pts)
    mx = sum(x for x, _ in pts) / n
    my = sum(y for _, y in pts) / n
    s = sum((x - mx) * (y - my) for x, y in pts) / sum((x - mx) ** 2 for x, _ in pts)
    return my - s * mx, s


def main():
    out = sys.argv[1]
    R, E, NU, H = (float(a) for a in sys.argv[2:6]) if len(sys.argv) > 5 else (0.5, 1.0e6, 0.3, 0.5)
    P = max(-float(r["fy"]) for r in csv.DictReader(open(out + "/contact.csv")))
    block = [r for r in csv.DictReader(open(out + "/particles_final.csv")) if r["body"] == "0"]
    e_star = E / (1.0 - NU * NU)
    b = math.sqrt(4.0 * P * R / (math.pi * e_star))
    p0 = 2.0 * P / (math.pi * b)
    # The axis: the column of particles nearest x = 0.
    x_axis = min((abs(float(r["X0"])) for r in block))
    column = [(H - float(r["Y0"]), -float(r["syy"])) for r in block if abs(float(r["X0"])) == x_axis]
    top_gap = min(z for z, _ in column)
    h = 4.0 * top_gap  # the top particle sits a quarter cell down (2 x 2 per cell)
    a, s = fit_line([(z * z, 1.0 / (p * p)) for z, p in column if h <= z <= 1.6 * b])
    p0_axis, b_axis = 1.0 / math.sqrt(a), math.sqrt(a / s)
    # The top layer.
    top0 = max(float(r["Y0"]) for r in block)
    layer = sorted((float(r["x"]), -float(r["syy"])) for r in block if float(r["Y0"]) == top0)
    p_max = max(p for _, p in layer)
    a, s = fit_line([(x * x, p * p) for x, p in layer if p > 0.25 * p_max])
    b_layer = math.sqrt(-a / s)
    print(f"P = {P:.1f} N/m, h = {h:.4f} m, 2b/h = {2 * b / h:.1f}")
    print(f"Hertz:            b = {b:.5f} m, p0 = {p0:.1f} Pa")
    print(f"axis fit:         b = {b_axis:.5f} m ({100 * (b_axis / b - 1):+.2f} %), "
          f"p0 = {p0_axis:.1f} Pa ({100 * (p0_axis / p0 - 1):+.2f} %)")
    print(f"top layer:        b = {b_layer:.5f} m ({100 * (b_layer / b - 1):+.2f} %), "
          f"peak {p_max:.1f} Pa ({100 * (p_max / p0 - 1):+.2f} %)")


main()
