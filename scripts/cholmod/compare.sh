#!/usr/bin/env bash
# The project's sparse direct path against SuiteSparse CHOLMOD on the project's own
# tangents, one thread each, on this machine (docs/performance.md, "Against CHOLMOD").
#
#   scripts/cholmod/compare.sh [REPETITIONS]     (default 3; about 3 minutes each)
#
# 1. Installs what it needs (not needed by the default build or tests): Debian's
#    libsuitesparse-dev (CHOLMOD 3, SuiteSparse 5) with OpenBLAS and, in target/cholmod/venv,
#    numpy, scipy and scikit-sparse 0.4.16 built against it.
# 2. Exports the tangents of the implicit bench (2D block 160², 3D block 20³, first
#    Newton iteration of load step 2) as Matrix Market files with their right-hand
#    sides (MPM_EXPORT_TANGENTS), and times the project's direct path on them
#    (criterion's `direct`: fill-reducing ordering of the node graph, symbolic and
#    numeric Cholesky, solve; RAYON_NUM_THREADS=1).
# 3. Times CHOLMOD's analyze (its default ordering choice) + factorize + solve on the
#    same matrices (OMP_THREAD_LIMIT=1: Debian's CHOLMOD opens OpenMP regions that
#    OMP_NUM_THREADS does not cap).
# Steps 2 and 3 alternate REPETITIONS times (the machine is noisy); the table gives
# the median of each side and their ratio.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
reps="${1:-3}"
work="$root/target/cholmod"
mkdir -p "$work"

# CHOLMOD's supernodal factorization runs in the BLAS: OpenBLAS, not the reference
# BLAS that libsuitesparse-dev pulls in alone (which is 5-10 times slower here).
if [ ! -f /usr/include/suitesparse/cholmod.h ] || ! dpkg -s libopenblas0-pthread >/dev/null 2>&1; then
  echo "installing libsuitesparse-dev and OpenBLAS"
  apt-get install -y libsuitesparse-dev libopenblas-dev >"$work/apt.log" 2>&1
fi
if [ ! -x "$work/venv/bin/python" ] || ! "$work/venv/bin/python" -c "import sksparse.cholmod" 2>/dev/null; then
  echo "installing scikit-sparse into $work/venv"
  python3 -m venv "$work/venv"
  "$work/venv/bin/pip" install --quiet numpy scipy "Cython<3" setuptools wheel
  "$work/venv/bin/pip" install --quiet --no-build-isolation scikit-sparse==0.4.16
fi

export RAYON_NUM_THREADS=1 OMP_THREAD_LIMIT=1 OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
rm -f "$work/ours.jsonl" "$work/cholmod.jsonl"
for rep in $(seq "$reps"); do
  echo "repetition $rep/$reps: mpm"
  MPM_BENCH_LARGE=1 MPM_EXPORT_TANGENTS="$work/mtx" \
    cargo bench --quiet --manifest-path "$root/Cargo.toml" --bench implicit -- --noplot '/direct$' \
    >"$work/bench_$rep.log" 2>&1
  for est in "$root"/target/criterion/implicit_*_step2/direct/new/estimates.json; do
    name="$(basename "$(dirname "$(dirname "$(dirname "$est")")")")"
    name="${name#implicit_}"
    case "$name" in block2d_160x160_step2 | block3d_20x20x20_step2) ;; *) continue ;; esac
    python3 -c "import json,sys; e=json.load(open(sys.argv[1])); print(json.dumps({'name': sys.argv[2], 'seconds': e['median']['point_estimate']/1e9}))" "$est" "$name" >>"$work/ours.jsonl"
  done
  echo "repetition $rep/$reps: CHOLMOD"
  "$work/venv/bin/python" "$root/scripts/cholmod/cholmod_time.py" "$work/mtx" >>"$work/cholmod.jsonl"
done
python3 "$root/scripts/cholmod/table.py" "$work/ours.jsonl" "$work/cholmod.jsonl"
