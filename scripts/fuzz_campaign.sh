#!/usr/bin/env bash
# A longer run of the scene fuzzer of tests/input/fuzz.rs: mutants of problems/*.toml
# (types changed, keys removed, extreme and scaled values, resized arrays, deeply
# nested expressions, unknown keys, malformed --set overrides) through `mpm check`,
# and short `mpm run`s of mutants of the small scenes. Fails on a panic, an abort,
# a timeout, or an error that names no key; prints every failing mutant.
#
#   scripts/fuzz_campaign.sh [SEED [CHECKS [RUNS]]]   defaults: a seed from the clock, 5000, 300
#
# The suite runs one fixed seed (400 checks, 120 runs, a few seconds); this takes
# about a minute per thousand checks on 2 cores. Re-run a failing seed to reproduce.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seed="${1:-$(date +%s)}"
checks="${2:-5000}"
runs="${3:-300}"
cd "$root"
echo "fuzz campaign: seed $seed, $checks checks, $runs runs"
MPM_FUZZ_SEED="$seed" MPM_FUZZ_CHECKS="$checks" MPM_FUZZ_RUNS="$runs" \
  cargo test --release --test input fuzz_campaign -- --ignored --nocapture
