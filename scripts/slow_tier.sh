#!/usr/bin/env bash
# The slow tier: the verification tests kept out of `cargo test --release` (the
# README's command, what CI runs) for their length, `#[ignore = "slow tier, ..."]`
# in tests/verification/ with their last measured time alone on the 2-core machine.
# The fine resolutions (`#[ignore = "about ..."]`) and the fuzz campaign
# (scripts/fuzz_campaign.sh) are not in it. docs/verification.md lists both.
#
#   scripts/slow_tier.sh [FILTER]     179 s of tests on 2 cores, 2026-12-04 (10 tests)
set -euo pipefail
cd "$(dirname "$0")/.."
mapfile -t tests < <(grep -h -A1 '#\[ignore = "slow tier' tests/verification/*.rs \
  | sed -n 's/^fn \([a-z0-9_]*\)(.*/\1/p' | grep -e "${1:-}")
echo "slow tier: ${#tests[@]} tests"
cargo test --release --test verification -- --ignored --exact \
  $(for t in "${tests[@]}"; do grep -l "fn $t(" tests/verification/*.rs \
    | sed "s|tests/verification/\(.*\)\.rs|\1::$t|"; done)
