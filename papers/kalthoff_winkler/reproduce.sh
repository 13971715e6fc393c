#!/bin/sh
# The Kalthoff-Winkler plate (problems/kalthoff_winkler.toml) at dx = 2, 1 and
# 0.5 mm (1, 6 and 47 s on 2 cores), then at dx = 1 mm the variants of the
# literature: G0 = 42.4 kJ/m2 (CabanaPD), the striker at 32 m/s (Peridynamics.jl's
# prescribed edge velocity) and seed 003's beam-based bond at the steel's
# nu = 0.3. Each run's crack angles, tip history and off-crack damage come from
# measure.py; results.csv collects them and damage.svg draws the dx = 1 mm
# plate's damage at 90 us. Python 3 standard library only.
set -e
cd "$(dirname "$0")/../.."
cargo build --release --quiet
out=${OUT:-out/kalthoff_winkler}
mkdir -p "$out"
scene=problems/kalthoff_winkler.toml
run() { # name dx ppc extra-args...
  name=$1 dx=$2 ppc=$3; shift 3
  half=$(python3 -c "print($dx / 2)")
  ./target/release/mpm run $scene --out "$out/$name" --set "body.0.particles_per_cell=$ppc" \
    --set "body.1.max=[$half,0.12425]" "$@" > /dev/null
  python3 papers/kalthoff_winkler/measure.py "$out/$name" "$dx" > "$out/$name/measure.json"
  echo "$name: $(cat "$out/$name/measure.json" | cut -c1-160)"
}
run dx2 0.002 1
run dx1 0.001 2
run dx05 0.0005 4
run dx1_g42 0.001 2 --set body.0.fracture_energy=42.4e3
run dx1_v32 0.001 2 --set "body.1.velocity=[32.0,0.0]"
run dx1_beam 0.001 2 --set body.0.bond_model=\"beam\" --set material.0.poisson_ratio=0.3
python3 papers/kalthoff_winkler/tabulate.py "$out" > papers/kalthoff_winkler/results.csv
python3 papers/kalthoff_winkler/tabulate.py "$out" --svg "$out/dx1" > papers/kalthoff_winkler/damage.svg
cat papers/kalthoff_winkler/results.csv
