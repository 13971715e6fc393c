#!/usr/bin/env python3
"""Per-round ratios mpm / Taichi f64 of a comparison campaign (compare.sh).

    python3 scripts/taichi/ratios.py RESULTS.jsonl [RESULTS.jsonl ...]

Reads the runs that bench.py (2D, ../shared/peers/taichi) or bench_3d.py (3D)
wrote, one JSON line per run, and prints a table: for every size and mpm scheme,
its rate in every round, the rate of Taichi f64 in the same round, their ratio
per round and the median of those ratios, and the peak resident memory. The
runs of one round alternate between the programs, so a ratio within a round
compares the two under the same load; its median over the rounds is the number
the issue's targets (docs/performance_explicit.md) are read against. Needs only
Taichi f64 runs (the peer's analyze.py also wants f32).
"""
import collections
import json
import statistics
import sys


def main(paths):
    # (file, size, round) -> {(program, variant): run}
    rounds = collections.defaultdict(dict)
    for p in paths:
        for line in open(p):
            if line.strip():
                r = json.loads(line)
                rounds[(p, r["n"], r["round"])][(r["program"], r["variant"])] = r
    table = collections.defaultdict(list)
    for (_, n, _), by_job in sorted(rounds.items(), key=lambda kv: (kv[0][1], kv[0][0], kv[0][2])):
        taichi = by_job.get(("taichi", "f64"))
        if taichi is None:
            continue
        for (program, variant), r in by_job.items():
            if program == "mpm":
                table[(n, r["particles"], variant)].append((r, taichi))
    if not table:
        sys.exit("no round has both an mpm run and a Taichi f64 run")
    print("| particles (n) | mpm scheme | rounds | mpm M p-steps/s | Taichi f64 M p-steps/s "
          "| mpm / Taichi per round | median | peak RSS mpm / Taichi MiB |")
    print("|---|---|---:|---|---|---|---:|---|")
    for (n, particles, variant), pairs in sorted(table.items()):
        ratios = [m["pss"] / t["pss"] for m, t in pairs]
        mpm = " ".join("%.2f" % (m["pss"] / 1e6) for m, _ in pairs)
        peer = " ".join("%.2f" % (t["pss"] / 1e6) for _, t in pairs)
        per_round = " ".join("%.2f" % x for x in ratios)
        rss_mpm = max(m.get("max_rss_kb", 0) for m, _ in pairs) / 1024
        rss_peer = max(t.get("max_rss_kb", 0) for _, t in pairs) / 1024
        print(f"| {particles:,} ({n}) | {variant} | {len(pairs)} | {mpm} | {peer} "
              f"| {per_round} | {statistics.median(ratios):.2f} | {rss_mpm:.0f} / {rss_peer:.0f} |")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
