#!/bin/sh
# Residual velocity of the Hanchak perforation (749 m/s, C48 slab 178 mm) with
# RHT + P-alpha and with HJC, a free rigid rod, axisymmetric, at h = 4 mm (2 mm
# particle spacing, the thesis' spacing; 15 s each on 2 cores). H2=1 adds
# h = 2 mm (2-3 min each), H1=1 adds h = 1 mm (about an hour each); ELASTIC=1
# adds the elastic rod (HJC) at h = 4 mm.
set -e
cd "$(dirname "$0")/../.."
cargo build --release --quiet
out=${OUT:-out/penetration_hanchak}
cells="[83,215]"
[ -n "$H2" ] && cells="$cells [166,430]"
[ -n "$H1" ] && cells="$cells [332,860]"
scenes="hanchak_rht hanchak"
[ -n "$ELASTIC" ] && scenes="$scenes hanchak_elastic_rod"
for scene in $scenes; do
  for c in $cells; do
    [ "$scene" = hanchak_elastic_rod ] && [ "$c" != "[83,215]" ] && continue
    dir="$out/$scene-$(echo "$c" | tr -d '[],')"
    ./target/release/mpm run "papers/penetration_hanchak/$scene.toml" --out "$dir" --set "grid.cells=$c" > /dev/null || true
    # The rod is body 1: its mean axial velocity at the last history row.
    awk -F, -v s="$scene" -v c="$c" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "body1_vy") k = i }
      END { printf "%s %s: residual velocity %.1f m/s (test 615)\n", s, c, -$k }' "$dir/history.csv"
  done
done
