#!/usr/bin/env bash
# Regenerate the footing numbers of README.md: both footing scenes under grid
# refinement (cells of B/8, B/16 and, for Tresca, B/32), a larger domain for
# Mohr-Coulomb, and the limit-analysis bounds. Prints one line per run:
#   scene, cell size h, domain, N_c, error against Prandtl, plateau change,
#   Newton iterations, steps, wall seconds.
# Usage: papers/footing_prandtl/reproduce.sh [OUT_DIR]   (about 10 minutes on 2 cores)
#   FINE=1 adds Tresca at h = B/32 (15 360 particles; not run for README.md).
# A run whose summary.json is already in OUT_DIR is not repeated.
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-out/footing_prandtl}
cargo build --release --quiet
mpm=${CARGO_TARGET_DIR:-target}/release/mpm
mkdir -p "$out"

# run NAME SCENE EXACT_NC [--set ...]
run() {
  local name=$1 scene=$2 exact=$3
  shift 3
  if [ ! -f "$out/$name/summary.json" ]; then
    "$mpm" run "problems/$scene.toml" --out "$out/$name" "$@" > /dev/null
  fi
  python3 - "$out/$name/summary.json" "$name" "$exact" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
nc, exact = s["bearing_capacity_factor"], float(sys.argv[3])
print(f"{sys.argv[2]:28s} N_c = {nc:8.4f}  error {100 * (nc / exact - 1):+6.2f} %  "
      f"plateau {s['plateau_change']:+.1e}  {s['newton_iterations']:4d} Newton it. "
      f"in {s['steps']} steps  {s['wall_seconds']:6.1f} s")
PY
}

nc_t=5.141593   # 2 + pi
nc_m=14.834710  # (N_q - 1) cot 20 deg, N_q = exp(pi tan 20) tan^2 55

# Tresca: 5 m x 3 m half domain (the mechanism reaches 1.5 B = 3 m).
run tresca_h0.25   footing_tresca $nc_t
run tresca_h0.125  footing_tresca $nc_t --set "grid.cells=[40,24]"
if [ "${FINE:-0}" = 1 ]; then
  run tresca_h0.0625 footing_tresca $nc_t --set "grid.cells=[80,48]"
fi

# Mohr-Coulomb phi = 20: the shipped 4 m x 2.5 m domain at h = 0.25 and 0.125,
# then 7 m x 3.5 m (the passive wedge ends at x = 6.1 m).
run mc_h0.25       footing_mc $nc_m --set "grid.cells=[16,10]"
run mc_h0.125      footing_mc $nc_m
big=(--set "grid.max=[7.0,3.5]" --set "body.0.max=[7.0,3.5]"
     --set "boundary.3.region_min=[0.0,3.5]" --set "boundary.3.region_max=[1.0,3.5]")
run mc_7x3.5_h0.25  footing_mc $nc_m "${big[@]}" --set "grid.cells=[28,14]"
run mc_7x3.5_h0.125 footing_mc $nc_m "${big[@]}" --set "grid.cells=[56,28]"

# Linear shape functions, for comparison (volumetric locking of the isochoric
# plastic flow, and the edge node's cell carries part of the load).
run tresca_linear_h0.25  footing_tresca $nc_t --set grid.shape_function=linear
run tresca_linear_h0.125 footing_tresca $nc_t --set grid.shape_function=linear --set "grid.cells=[40,24]"

# MC=1: Mohr-Coulomb at phi = 10, 20, 30 deg, associated and psi = 0, at
# h = B/8, B/16, B/32 (the tables "Mohr-Coulomb at 10, 20, 30 deg" of README.md;
# about 15 minutes on 2 cores, most of it phi = 30 deg at B/32).
if [ "${MC:-0}" = 1 ]; then
  nc_10=8.344926  # (N_q - 1) cot 10 deg
  nc_30=30.139628 # (N_q - 1) cot 30 deg
  phi10=(--set material.0.friction_angle=10 --set material.0.dilation_angle=10)
  run mc10_h0.25    footing_mc $nc_10 "${phi10[@]}" --set "grid.cells=[16,10]"
  run mc10_h0.125   footing_mc $nc_10 "${phi10[@]}"
  run mc10_h0.0625  footing_mc $nc_10 "${phi10[@]}" --set "grid.cells=[64,40]"
  run mc20_h0.0625  footing_mc $nc_m --set "grid.cells=[64,40]" --set "boundary.3.velocity=[0.0,-0.006]"
  run mc30_h0.25    footing_mc_30 $nc_30 --set "grid.cells=[40,18]"
  run mc30_h0.125   footing_mc_30 $nc_30
  run mc30_h0.0625  footing_mc_30 $nc_30 --set "grid.cells=[160,72]"
  for phi in 10 20 30; do
    case $phi in 10) scene=footing_mc; exact=$nc_10; coarse="[16,10]";;
                 20) scene=footing_mc; exact=$nc_m;  coarse="[16,10]";;
                 30) scene=footing_mc_30; exact=$nc_30; coarse="[40,18]";; esac
    psi0=(--set material.0.friction_angle=$phi --set material.0.dilation_angle=0)
    run mc${phi}_psi0_h0.25  $scene $exact "${psi0[@]}" --set "grid.cells=$coarse"
    run mc${phi}_psi0_h0.125 $scene $exact "${psi0[@]}" || true
  done
fi

# Limit-analysis bounds on the same geometry (docs/limit_analysis.md).
for scene in limit_footing_tresca limit_footing_mc; do
  "$mpm" limit "problems/$scene.toml" --out "$out/$scene" | tail -1
done
