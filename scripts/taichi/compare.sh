#!/usr/bin/env bash
# Explicit throughput of `mpm` beside Taichi's CPU MLS-MPM on equal 2D scenes
# (issue 13; docs/performance.md, "Explicit step"). Runs the peer programs of
# ../shared/peers/taichi (gen_scenes.py, mls_mpm_bench.py, bench.py, analyze.py):
# the same elastic block, grid, lattice, Δt and step count in both programs.
#
#   scripts/taichi/compare.sh [ROUNDS] [n:steps ...]   (default 3 rounds; 128:400 256:200 512:100)
#
# Environment: THREADS (default 2, both programs), MPM (default: this tree's release
# build), TAICHI_PEER (default ../shared/peers/taichi beside the repository), JOBS
# (bench.py's job list; default all of mpm USL/USF/MUSL and Taichi f64/f32).
# Installs Taichi 1.7.4 into target/taichi/venv the first time (not needed by the
# default build or tests). Runs alternate between the programs (reversed order in
# odd rounds) so that a noisy machine weighs on both; the table gives medians,
# the ratio mpm / Taichi and the peak resident memory of every run.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
rounds="${1:-3}"
shift || true
peer="${TAICHI_PEER:-$root/../shared/peers/taichi}"
work="$root/target/taichi"
[ -f "$peer/bench.py" ] || { echo "no peer scripts at $peer (set TAICHI_PEER)" >&2; exit 1; }
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
out="$work/run_$(date +%Y%m%d_%H%M%S)"
export THREADS="${THREADS:-2}"
export JOBS="${JOBS:-mpm:usl,taichi:f64,mpm:usf,taichi:f32,mpm:musl}"
"$work/venv/bin/python" "$peer/bench.py" "$MPM" "$out" "$rounds" "$@"
"$work/venv/bin/python" "$peer/analyze.py" "$out" | tee "$out/table.md"
echo "results: $out"
