#!/bin/sh
# Residual velocity of the Unosson & Nilsson 400 mm slab (617 m/s, 153 MPa
# concrete), RHT + P-alpha, axisymmetric, h = 4 mm (about 6 min on 2 cores);
# EROSION=1 erodes at plastic strain 2 (README.md).
set -e
cd "$(dirname "$0")/../.."
cargo build --release --quiet
out=${OUT:-out/penetration_unosson}
set_erosion=""
[ -n "$EROSION" ] && set_erosion="--set material.0.erosion_plastic_strain=2.0"
./target/release/mpm run papers/penetration_unosson/unosson_400.toml --out "$out" $set_erosion > /dev/null || true
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "body1_vy") k = i }
  END { printf "unosson 400 mm: residual velocity %.1f m/s (test 290.7)\n", -$k }' "$out/history.csv"
