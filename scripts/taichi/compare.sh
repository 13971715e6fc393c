#!/usr/bin/env bash
# Explicit throughput of `mpm` beside Taichi's CPU MLS-MPM on equal 2D scenes
# (issue 13; docs/performance.md, "Explicit step"). Runs the peer programs of
# ../shared/peers/taichi (gen_scenes.py, mls_mpm_bench.py, bench.py, analyze.py):
# the same elastic block, grid, lattice, Δt and step count in both programs.
#
#   scripts/taichi/compare.sh [ROUNDS] [n:steps ...]   (default 3 rounds; 128:400 256:200 512:100)
#   DIM=3 scripts/taichi/compare.sh [ROUNDS] [n:steps ...]   (3D; default 32:100 64:40 100:10)
#
# DIM=3 runs the 3D variants in this folder instead (gen_scenes_3d.py,
# mls_mpm_bench_3d.py, bench_3d.py, analyze_3d.py, compare_motion_3d.py): the same
# block as a cube [0.25,0.75] x [y_f, y_f+0.5] x [0.25,0.75], n^3 particles; the peer
# folder is not needed then (docs/performance_explicit.md, "3D").
# Environment: THREADS (default 2, both programs), MPM (default: this tree's release
# build), TAICHI_PEER (default ../shared/peers/taichi beside the repository), JOBS
# (bench.py's job list; default all of mpm USL/USF/MUSL and Taichi f64/f32).
# Installs Taichi 1.7.4 into target/taichi/venv the first time (not needed by the
# default build or tests). Runs alternate between the programs (reversed order in
# odd rounds) so that a noisy machine weighs on both; the table gives medians,
# the ratio mpm / Taichi and the peak resident memory of every run, and ratios.py
# the ratio of every round (mpm / Taichi f64) with its median.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
rounds="${1:-3}"
shift || true
peer="${TAICHI_PEER:-$root/../shared/peers/taichi}"
work="$root/target/taichi"
dim="${DIM:-2}"
case "$dim" in
  2) [ -f "$peer/bench.py" ] || { echo "no peer scripts at $peer (set TAICHI_PEER)" >&2; exit 1; }
     bench="$peer/bench.py"; analyze="$peer/analyze.py"; tag="run" ;;
  3) bench="$root/scripts/taichi/bench_3d.py"; analyze="$root/scripts/taichi/analyze_3d.py"; tag="run3d" ;;
  *) echo "DIM must be 2 or 3" >&2; exit 1 ;;
esac
mkdir -p "$work"
if [ ! -x "$work/venv/bin/python" ] || ! "$work/venv/bin/python" -c "import taichi" 2>/dev/null; then
  echo "installing taichi 1.7.4 into $work/venv"
  python3 -m venv "$work/venv"
  "$work/venv/bin/pip" install --quiet taichi==1.7.4
fi
if [ -z "${MPM:-}" ]; then
  cargo build --release --quiet --manifest-path "$root/Cargo.toml" --bin mpm
  MPM="$root/target/release/mpm"
fi
out="$work/${tag}_$(date +%Y%m%d_%H%M%S)"
export THREADS="${THREADS:-2}"
export JOBS="${JOBS:-mpm:usl,taichi:f64,mpm:usf,taichi:f32,mpm:musl}"
"$work/venv/bin/python" "$bench" "$MPM" "$out" "$rounds" "$@"
# The full table (the peer's analyze.py) wants both Taichi runs, f64 and f32.
if [ "$dim" = 3 ] || [[ ",$JOBS," == *",taichi:f32,"* ]]; then
  "$work/venv/bin/python" "$analyze" "$out" | tee "$out/table.md"
fi
# Per round mpm / Taichi f64 and their medians: what the targets are read against.
"$work/venv/bin/python" "$root/scripts/taichi/ratios.py" "$out/results.jsonl" | tee "$out/ratios.md"
echo "results: $out"
