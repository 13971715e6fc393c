#!/usr/bin/env bash
# Krylov iterations of mpm's multigrid beside PETSc's GAMG (smoothed aggregation
# with rigid-body near-null space) and hypre's BoomerAMG on the same linear
# systems: the first Newton iteration of every load step of each case below.
#
#   papers/amg_comparison/run.sh [OUT]      (default: target/amg_comparison)
#
# Installs python3-petsc4py and python3-scipy from Debian if they are missing.
# Per case: a run with the direct solver that exports its systems
# ([output] linear_systems = "first"), a run with CG + multigrid to the same
# relative tolerance (its Krylov iterations from newton.csv), and
# petsc_solve.py on the exported systems; then a table (OUT/table.md).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
out="${1:-$root/target/amg_comparison}"
rtol=1e-8

# Debian's Python and PETSc (not a pyenv or venv python that lacks them).
py=/usr/bin/python3
if ! "$py" -c "import scipy" 2>/dev/null || [ -z "$(ls -d /usr/lib/petscdir/*/*-real 2>/dev/null)" ]; then
  echo "installing python3-petsc4py and python3-scipy"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-petsc4py python3-scipy >/dev/null
fi
# petsc4py finds PETSc through /usr/lib/petsc, which Debian's alternatives may not set.
[ -e /usr/lib/petsc ] || export PETSC_DIR="$(ls -d /usr/lib/petscdir/*/*-real | sort | tail -1)"
cargo build --release --quiet --manifest-path "$root/Cargo.toml"
mpm="$root/target/release/mpm"

# name | scene | overrides
cases=(
  "block2d_32|problems/bench/block.toml|grid.cells=[32,32]"
  "block2d_64|problems/bench/block.toml|grid.cells=[64,64]"
  "block2d_128|problems/bench/block.toml|grid.cells=[128,128]"
  "block2d_256|problems/bench/block.toml|grid.cells=[256,256]"
  "cantilever|problems/cantilever.toml|solver.load_steps=5"
  "two_layer_column|problems/two_layer_column.toml|"
)

mkdir -p "$out"
for case in "${cases[@]}"; do
  IFS='|' read -r name scene sets <<<"$case"
  args=(--set output.frames=0)
  [ -n "$sets" ] && for s in $sets; do args+=(--set "$s"); done
  rm -rf "${out:?}/$name"
  mkdir -p "$out/$name"
  echo "== $name"
  "$mpm" run "$root/$scene" --out "$out/$name/direct" "${args[@]}" \
    --set 'output.linear_systems="first"' >"$out/$name/direct.log" 2>&1 ||
    echo "   direct run failed (see $out/$name/direct.log)"
  "$mpm" run "$root/$scene" --out "$out/$name/multigrid" "${args[@]}" \
    --set 'solver.linear_solver="cg"' --set 'solver.preconditioner="multigrid"' \
    --set "solver.krylov_tolerance=$rtol" >"$out/$name/multigrid.log" 2>&1 ||
    echo "   multigrid run failed (see $out/$name/multigrid.log)"
  "$py" "$here/petsc_solve.py" "$out/$name/direct/linear_systems" --rtol "$rtol" \
    >"$out/$name/petsc.jsonl" 2>"$out/$name/petsc.log" || echo "   PETSc failed (see $out/$name/petsc.log)"
done

"$py" - "$out" <<'PY' | tee "$out/table.md"
import csv, json, sys
from pathlib import Path
out = Path(sys.argv[1])
print("| case | system | unknowns | mpm multigrid | PETSc GAMG | hypre BoomerAMG |")
print("|---|---|---|---|---|---|")
for case in sorted(p for p in out.iterdir() if p.is_dir()):
    ours = {}
    newton = case / "multigrid" / "newton.csv"
    if newton.exists():
        for r in csv.DictReader(open(newton)):
            if int(r["iteration"]) == 0:
                ours[(int(r["step"]), int(r["cutback"]))] = r["krylov_iterations"]
    rows = {}
    jsonl = case / "petsc.jsonl"
    for line in open(jsonl) if jsonl.exists() else []:
        d = json.loads(line)
        its = str(d["iterations"]) if d["reason"] > 0 else f'{d["iterations"]} (reason {d["reason"]})'
        rows.setdefault(d["system"], {"unknowns": d["unknowns"]})[d["pc"]] = its
    for system, r in sorted(rows.items()):
        step, cut = int(system[4:10]), int(system.split("_cut")[1].split("_")[0])
        print(f'| {case.name} | {system} | {r["unknowns"]} | {ours.get((step, cut), "–")} '
              f'| {r.get("gamg", "–")} | {r.get("hypre", "–")} |')
PY
