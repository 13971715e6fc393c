#!/bin/sh
# Regenerates the table of README.md: the Taylor bar with MPM3D's copper and with
# Johnson & Cook's 1983 OFHC constants, at h = 0.76 mm and 0.38 mm (about
# 10 s and 2-3 min each on 2 cores).
set -e
cd "$(dirname "$0")/../.."
cargo build --release --quiet
out=${OUT:-out/taylor_bar}
for scene in problems/taylor_bar.toml papers/taylor_bar/ofhc_jc1983.toml; do
  name=$(basename "$scene" .toml)
  for cells in "[11,11,35]" "[22,22,70]"; do
    dir="$out/$name-$(echo "$cells" | tr -d '[],')"
    ./target/release/mpm run "$scene" --out "$dir" --set "grid.cells=$cells" > /dev/null
    printf '%s %s: ' "$name" "$cells"
    python3 papers/taylor_bar/measure.py "$dir"
  done
done
