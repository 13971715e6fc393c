#!/bin/sh
# Regenerates bench.csv and the plots of this folder (a few minutes on one core).
set -e
cd "$(dirname "$0")/../.."
cargo build --release
./target/release/mpm bench problems/column.toml --config papers/column_accuracy/bench.toml \
    --out out/column_accuracy --threads 1
cp out/column_accuracy/bench.csv out/column_accuracy/error_vs_wall.png papers/column_accuracy/
