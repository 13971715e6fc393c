//! Parallel loops whose results do not depend on the number of threads.
//!
//! Particle-to-grid transfers are gathers (each node sums its particles in
//! increasing order, `physics::transfer::NodeMap::gather`); sums over particles
//! use a fixed chunking (`deterministic_sum`). Loops over fewer items than
//! `MIN_PARALLEL_LEN` run serially.

use rayon::prelude::*;

/// Smallest number of items a parallel loop hands to one task: below it, the
/// cost of waking threads exceeds the work (small scenes run serially).
pub const MIN_PARALLEL_LEN: usize = 512;

/// Sum of `f(i)` for i in 0..n, in parallel but with a fixed chunking so that the
/// floating-point result does not depend on the number of threads.
pub fn deterministic_sum(n: usize, f: impl Fn(usize) -> f64 + Sync) -> f64 {
    const CHUNK: usize = 4096;
    let partial: Vec<f64> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| (c * CHUNK..((c + 1) * CHUNK).min(n)).map(&f).sum())
        .collect();
    partial.iter().sum()
}
