"""The comparison table of compare.sh: median seconds of each side over the
repetitions and their ratio (mpm / CHOLMOD)."""
import json, statistics, sys

def medians(path):
    runs = {}
    for line in open(path):
        row = json.loads(line)
        runs.setdefault(row["name"], []).append(row)
    return {n: (statistics.median(r["seconds"] for r in rows), rows[-1]) for n, rows in runs.items()}

ours, theirs = medians(sys.argv[1]), medians(sys.argv[2])
print("| tangent | mpm direct (s) | CHOLMOD analyze+factorize+solve (s) | ratio | CHOLMOD nnz(L) | residual |")
print("|---|---:|---:|---:|---:|---:|")
for name in sorted(ours):
    if name not in theirs:
        continue
    t_ours, _ = ours[name]
    t_chol, row = theirs[name]
    print(f"| {name} | {t_ours:.3f} | {t_chol:.3f} | {t_ours / t_chol:.2f} | {row['nnz_l']:,} | {row['residual']:.1e} |")
