#!/usr/bin/env bash
# Strength-reduction search with its defaults (continuation from the last
# stable trial, a trial given up when Newton's residual rises twice in a row or falls by
# less than 10 % over 10 iterations) against the
# search as it was (every trial from the initial state, Newton to its cap),
# alternated ROUNDS times per scene; prints factor, bracket, trials, Newton
# iterations and wall seconds of each run, and the ratio of the medians.
# Usage: scripts/strength_reduction/compare.sh ROUNDS SCENE [--set K=V ...]
set -euo pipefail
rounds=$1; scene=$2; shift 2
mpm=${MPM:-target/release/mpm}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
summarise() {  # factor bracket trials newton wall
  python3 - "$1" <<'PY'
import json, sys
s = json.load(open(sys.argv[1] + "/summary.json"))
b = s.get("factor_of_safety_bracket")
print(f'F={s.get("factor_of_safety")} bracket={b} trials={len(s["trials"])} '
      f'newton={s["newton_iterations"]} wall={s["wall_seconds"]:.3f}')
PY
}
declare -a new old
for r in $(seq "$rounds"); do
  "$mpm" run "$scene" --out "$out/new" "$@" > /dev/null 2>&1 || true
  echo "round $r new: $(summarise "$out/new")"
  new+=("$(python3 -c "import json;print(json.load(open('$out/new/summary.json'))['wall_seconds'])")")
  "$mpm" run "$scene" --out "$out/old" "$@" --set strength_reduction.continuation=false \
    --set solver.max_rising_iterations=1000 --set solver.stall_iterations=1000 > /dev/null 2>&1 || true
  echo "round $r old: $(summarise "$out/old")"
  old+=("$(python3 -c "import json;print(json.load(open('$out/old/summary.json'))['wall_seconds'])")")
done
python3 - "${new[*]}" "${old[*]}" <<'PY'
import statistics, sys
n = statistics.median(map(float, sys.argv[1].split()))
o = statistics.median(map(float, sys.argv[2].split()))
print(f"median wall: new {n:.3f} s, old {o:.3f} s, old/new {o/n:.2f}")
PY
