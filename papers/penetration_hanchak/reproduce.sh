#!/bin/sh
# Residual velocity of the Hanchak perforation (749 m/s, C48 slab 178 mm) with
# RHT + P-alpha (without and with erosion at plastic strain 2) and with HJC, a
# free rigid rod, axisymmetric, at h = 4 mm (2 mm particle spacing, the thesis'
# spacing; 15 s each on 2 cores). H3=1 adds h = 2.84 mm, H2=1 h = 2 mm (about
# 4 min each), H141=1 h = 1.41 mm (7-8 min each), H1=1 h = 1 mm (20-25 min
# each); ELASTIC=1 adds the elastic rod (HJC).
set -e
cd "$(dirname "$0")/../.."
cargo build --release --quiet
out=${OUT:-out/penetration_hanchak}
cells="[83,215]"
[ -n "$H3" ] && cells="$cells [117,304]"
[ -n "$H2" ] && cells="$cells [166,430]"
[ -n "$H141" ] && cells="$cells [235,609]"
[ -n "$H1" ] && cells="$cells [332,860]"
runs="hanchak_rht hanchak_rht:eroded hanchak"
[ -n "$ELASTIC" ] && runs="$runs hanchak_elastic_rod"
for run in $runs; do
  scene=${run%%:*}
  extra=""
  [ "$run" = "hanchak_rht:eroded" ] && extra="--set material.0.erosion_plastic_strain=2.0"
  for c in $cells; do
    dir="$out/$(echo "$run" | tr ':' '-')-$(echo "$c" | tr -d '[],')"
    ./target/release/mpm run "papers/penetration_hanchak/$scene.toml" --out "$dir" --set "grid.cells=$c" $extra > /dev/null || true
    # The rod is body 1: its axial velocity at the last history row.
    awk -F, -v s="$run" -v c="$c" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "body1_vy") k = i }
      END { printf "%s %s: residual velocity %.1f m/s (test 615)\n", s, c, -$k }' "$dir/history.csv"
  done
done
