#!/usr/bin/env python3
"""Crack angles, crack-tip history and the damage off the two cracks of one
Kalthoff-Winkler run (problems/kalthoff_winkler.toml), from its output
directory: particles_final.csv and the particles_NNNN.csv of particle_times.csv.

    measure.py OUT_DIR [DX]      prints one JSON line

A crack is the particles of the plate with damage > 0.35 beyond its notch
(upper: y > tip + 3 dx, lower: y < tip - 3 dx; x > tip - dx): the angle to the
notch is atan(1/|b|) of the least-squares line x = a + b y through them (x on
y: the cracks are steep). Damage between the notches (off both cracks) is
counted apart. Its tip at a time is the damaged particle of
the crack farthest from the notch tip; the tip speed is the slope of that
distance between the files. Standard library only.
"""
import csv, json, math, sys

THRESHOLD = 0.35
TIPS = {"upper": (0.05, 0.12575), "lower": (0.05, 0.07425)}


def read(path):
    with open(path) as f:
        return [r for r in csv.DictReader(f) if r["body"] == "0"]


def crack(rows, side, dx):
    xt, yt = TIPS[side]
    out = []
    for r in rows:
        if float(r["damage"]) <= THRESHOLD:
            continue
        x, y = float(r["X0"]), float(r["Y0"])
        beyond = y > yt + 3 * dx if side == "upper" else y < yt - 3 * dx
        if beyond and x > xt - dx:
            out.append((x, y))
    return out


def angle(points):
    n = len(points)
    my = sum(p[1] for p in points) / n
    mx = sum(p[0] for p in points) / n
    syy = sum((p[1] - my) ** 2 for p in points)
    sxy = sum((p[0] - mx) * (p[1] - my) for p in points)
    b = sxy / syy
    return math.degrees(math.atan2(1.0, abs(b)))


def tip_distance(points, side):
    xt, yt = TIPS[side]
    return max((math.hypot(x - xt, y - yt) for x, y in points), default=0.0)


def main():
    out = sys.argv[1]
    dx = float(sys.argv[2]) if len(sys.argv) > 2 else 1e-3
    final = read(f"{out}/particles_final.csv")
    result = {"dx": dx, "particles": len(final)}
    for side in TIPS:
        pts = crack(final, side, dx)
        result[f"{side}_angle_deg"] = round(angle(pts), 2) if len(pts) > 2 else None
        result[f"{side}_points"] = len(pts)
    # Damage between the notches, off both cracks (x > 0.055, between them).
    off = [r for r in final if float(r["damage"]) > THRESHOLD
           and TIPS["lower"][1] + 3 * dx < float(r["Y0"]) < TIPS["upper"][1] - 3 * dx]
    result["damaged_between_the_notches"] = len(off)
    result["damaged_between_min_x"] = round(min((float(r["X0"]) for r in off), default=0.0), 4)
    history = []
    with open(f"{out}/particle_times.csv") as f:
        for row in csv.DictReader(f):
            rows = read(f"{out}/{row['file']}")
            t = float(row["t"])
            d = {s: tip_distance(crack(rows, s, dx), s) for s in TIPS}
            off_t = sum(1 for r in rows if float(r["damage"]) > THRESHOLD
                        and TIPS["lower"][1] + 3 * dx < float(r["Y0"]) < TIPS["upper"][1] - 3 * dx)
            history.append((t, d["upper"], d["lower"], off_t))
    result["tip_history_us_mm"] = [(round(t * 1e6, 1), round(u * 1e3, 1), round(l * 1e3, 1), o)
                                   for t, u, l, o in history]
    speeds = [(history[k][1] - history[k - 1][1]) / (history[k][0] - history[k - 1][0])
              for k in range(1, len(history))]
    result["upper_tip_speed_max_m_s"] = round(max(speeds), 0) if speeds else None
    print(json.dumps(result))


main()
