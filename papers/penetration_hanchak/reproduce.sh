#!/bin/sh
# Residual velocity of the Hanchak perforation (749 m/s, C48 slab 178 mm) with
# HJC and with RHT + P-alpha, axisymmetric, at h = 4 mm (2 mm particle spacing,
# the thesis' spacing; about 3 and 6 min on 2 cores). H2=1 adds h = 2 mm
# (about 8x longer).
set -e
cd "$(dirname "$0")/../.."
cargo build --release --quiet
out=${OUT:-out/penetration_hanchak}
cells="[83,215]"
[ -n "$H2" ] && cells="$cells [166,430]"
for scene in hanchak hanchak_rht; do
  for c in $cells; do
    dir="$out/$scene-$(echo "$c" | tr -d '[],')"
    ./target/release/mpm run "papers/penetration_hanchak/$scene.toml" --out "$dir" --set "grid.cells=$c" > /dev/null || true
    # The rod is body 1: its mean axial velocity at the last history row.
    awk -F, -v s="$scene" -v c="$c" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "body1_vy") k = i }
      END { printf "%s %s: residual velocity %.1f m/s (test 615)\n", s, c, -$k }' "$dir/history.csv"
  done
done
