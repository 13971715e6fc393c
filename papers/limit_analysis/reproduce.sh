#!/usr/bin/env bash
# Regenerate the limit-analysis numbers of README.md: the three scenes at two
# refinement levels, and the slope with a foundation layer of depth H.
# Usage: papers/limit_analysis/reproduce.sh [OUT_DIR]   (about 10 minutes on 2 cores)
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-out/limit_analysis}
cargo build --release --quiet
mpm=${CARGO_TARGET_DIR:-target}/release/mpm
for scene in limit_footing_tresca limit_footing_mc limit_slope; do
  "$mpm" limit "problems/$scene.toml" --out "$out/$scene"
done
"$mpm" limit problems/limit_slope.toml --out "$out/limit_slope_foundation" \
  --set slope.foundation_depth=10.0 --set "mesh.refinements=[0]"
for d in "$out"/*/; do
  echo "== $d"
  cat "$d/refinement.csv"
done
