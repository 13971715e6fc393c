#!/usr/bin/env python3
"""Speed ratio at equal error from an `mpm bench` bench.csv: for every completed
explicit run, the cheapest completed implicit run whose displacement error is at
most the explicit run's, and the ratio of their wall times (explicit / implicit).
Prints one line per explicit run and the smallest ratio (the one most favourable
to the explicit solver). Usage: ratio.py BENCH_CSV [BENCH_CSV ...]"""
import csv
import sys


def rows(path):
    with open(path) as f:
        return [r for r in csv.DictReader(f) if r["status"] == "ok" and r["error"]]


for path in sys.argv[1:]:
    runs = rows(path)
    implicit = [r for r in runs if r["solver"] != "explicit"]
    explicit = [r for r in runs if r["solver"] == "explicit"]
    print(path)
    ratios = []
    for e in explicit:
        err, wall = float(e["error"]), float(e["wall_seconds"])
        good = [i for i in implicit if float(i["error"]) <= err]
        if not good:
            print(f"  {e['configuration']:>10} {e['cells']:>7}: error {err:.3e} in {wall:.2f} s; no implicit run this accurate")
            continue
        best = min(good, key=lambda i: float(i["wall_seconds"]))
        ratio = wall / float(best["wall_seconds"])
        ratios.append(ratio)
        print(f"  {e['configuration']:>10} {e['cells']:>7}: error {err:.3e} in {wall:.2f} s; "
              f"{best['configuration']} {best['cells']} ls {best['load_steps']}: "
              f"{float(best['error']):.3e} in {float(best['wall_seconds']):.2f} s; ratio {ratio:.0f}")
    if ratios:
        print(f"  smallest ratio at equal error: {min(ratios):.0f}, median {sorted(ratios)[len(ratios) // 2]:.0f}")
