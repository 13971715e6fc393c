#!/usr/bin/env bash
# The speed/accuracy trade on the Griffiths & Lane slope (issue 57 item 4):
# implicit quasi-static solves (direct, GMRES + multigrid) against explicit
# dynamic relaxation, at F = 1 and F = 1.3 (strengths divided by F), each on the
# grids of problems/bench/slope_bench.toml, the error in the displacement field
# against the same slope solved implicitly on a finer grid (REF_CELLS, default
# 480x144, REF_LOAD_STEPS load steps, default 8). Writes OUT/F*/reference/ and OUT/F*/bench/ (bench.csv, plots).
# Usage: scripts/slope_trade/run.sh OUT [FACTORS...]   (default factors: 1.0 1.3)
set -euo pipefail
out=$(realpath -m "$1"); shift
factors=("${@:-1.0}")
[ $# -eq 0 ] && factors=(1.0 1.3)
mpm=${MPM:-target/release/mpm}
scene=problems/slope_griffiths_lane.toml
ref_cells=${REF_CELLS:-480x144}
ref_steps=${REF_LOAD_STEPS:-8}
for f in "${factors[@]}"; do
  # c' / F and atan(tan φ' / F), φ' = 20°, c' = 10 kPa (the scene's).
  strengths=$(python3 -c "import math;f=$f;print(f'material.0.cohesion={10/f!r} material.0.friction_angle={math.degrees(math.atan(math.tan(math.radians(20))/f))!r}')")
  set_args=()
  for s in $strengths; do set_args+=(--set "$s"); done
  dir="$out/F$f"
  "$mpm" bench "$scene" --config problems/bench/slope_bench.toml --out "$dir/reference" \
    --configurations direct --cells "$ref_cells" --load-steps "$ref_steps" "${set_args[@]}"
  ref="$dir/reference/runs/direct_${ref_cells}_ls${ref_steps}/particles_final.csv"
  [ -f "$ref" ] || { echo "no reference run at $ref" >&2; exit 1; }
  "$mpm" bench "$scene" --config problems/bench/slope_bench.toml --out "$dir/bench" \
    "${set_args[@]}" --set reference.kind=displacement_field --set "reference.file=\"$ref\""
done
