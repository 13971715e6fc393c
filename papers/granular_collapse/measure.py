"""Runout and final height of a collapse run (output directory of `mpm run`).

front  d_inf: the 99.5 % mass percentile of particle x (robust against a few
       particles that detach from the toe); the largest x is reported beside it.
height h_inf: the largest particle y.
Both are shifted by half a particle spacing (the gap between the outermost
particle centres and the body's edges at the start), so that the initial column
measures exactly d0 x h0.
final: the run is final when the kinetic energy at the end is below 1 % of its
       peak (checked here and reported).
"""
import csv
import sys


def read(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def measure(out, d0, h0):
    p = read(f"{out}/particles_final.csv")
    h = read(f"{out}/history.csv")
    xs = sorted((float(r["x"]), float(r["mass"])) for r in p)
    total = sum(m for _, m in xs)
    acc, front = 0.0, xs[-1][0]
    for x, m in xs:
        acc += m
        if acc >= 0.995 * total:
            front = x
            break
    # particle centres: the initial extents, measured the same way
    x0 = max(float(r["X0"]) for r in p)
    y0 = max(float(r["Y0"]) for r in p)
    spacing_x, spacing_y = d0 - x0, h0 - y0  # half spacing each
    height = max(float(r["y"]) for r in p) + spacing_y
    front_edge = front + spacing_x
    ke = [float(r["kinetic"]) for r in h]
    return {
        "front": front_edge,
        "front_max": xs[-1][0] + spacing_x,
        "height": height,
        "runout": (front_edge - d0) / d0,
        "height_ratio": height / h0,
        "ke_ratio": ke[-1] / max(ke),
        "t_end": float(h[-1]["t"]),
    }


def lube(a):
    """(d_inf - d0)/d0 and h_inf/h0 from the reference README item 6 (height law
    only given there for a < 0.65)."""
    if a < 0.65:
        run = None
    elif a < 1.5:
        run = 3.25 * a**0.96
    else:
        run = 3.80 * a**0.73
    return run, (1.0 if a < 0.65 else None)


if __name__ == "__main__":
    out, d0, h0 = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
    m = measure(out, d0, h0)
    print(m, "law:", lube(h0 / d0))
