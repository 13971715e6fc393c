//! Parallel loops whose results do not depend on the number of threads.
//!
//! Particle-to-grid transfers are gathers (each node sums its particles in
//! increasing order, `physics::transfer::NodeMap::gather`) or, in the explicit
//! step on a box of nodes, scatters coloured so that every node sums in one
//! fixed order (`solver::explicit::node_box`); sorts are stable (`bucket_sort`); sums over
//! particles use a fixed chunking (`deterministic_sum`). Loops over fewer items
//! than `MIN_PARALLEL_LEN` run serially.

use rayon::prelude::*;

/// Smallest number of items a parallel loop hands to one task: below it, the
/// cost of waking threads exceeds the work (small scenes run serially).
pub const MIN_PARALLEL_LEN: usize = 512;

/// Items per chunk of `deterministic_sum` (and of loops that sum as it does).
pub const SUM_CHUNK: usize = 4096;

/// Sum of `f(i)` for i in 0..n, in parallel but with a fixed chunking so that the
/// floating-point result does not depend on the number of threads.
pub fn deterministic_sum(n: usize, f: impl Fn(usize) -> f64 + Sync) -> f64 {
    let partial: Vec<f64> = (0..n.div_ceil(SUM_CHUNK))
        .into_par_iter()
        .map(|c| (c * SUM_CHUNK..((c + 1) * SUM_CHUNK).min(n)).map(&f).sum())
        .collect();
    partial.iter().sum()
}

/// A mutable slice that parallel tasks write through a shared copy, each task to
/// elements that no other task touches at the same time: the placements of
/// `bucket_sort` and `NodeMap::build`, the colour-by-colour scatter of
/// `solver::explicit::node_box`. (Atomics would do it safely, at the price of a second
/// array and a copy, or of compare-and-swap loops for floating-point sums.)
pub struct DisjointSlice<'a, T> {
    ptr: *mut T,
    len: usize,
    _slice: std::marker::PhantomData<&'a mut [T]>,
}

impl<T> Clone for DisjointSlice<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for DisjointSlice<'_, T> {}

// SAFETY: elements are reached only through `at`, whose callers keep the
// elements of different tasks disjoint (below).
unsafe impl<T: Send> Send for DisjointSlice<'_, T> {}
unsafe impl<T: Send> Sync for DisjointSlice<'_, T> {}

impl<'a, T> DisjointSlice<'a, T> {
    pub fn new(slice: &'a mut [T]) -> Self {
        DisjointSlice {
            ptr: slice.as_mut_ptr(),
            len: slice.len(),
            _slice: std::marker::PhantomData,
        }
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Element `i`.
    ///
    /// # Safety
    /// No other task may read or write element `i` while the returned
    /// reference lives. (`i` < len is checked.)
    #[inline(always)]
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn at(&self, i: usize) -> &mut T {
        assert!(i < self.len, "index {i} outside a slice of {}", self.len);
        // SAFETY: in bounds (checked); exclusive by the caller's contract.
        unsafe { &mut *self.ptr.add(i) }
    }
}

/// `f` on a pool of `threads` threads of its own (every parallel loop inside it
/// runs there): the thread-independence tests run the same work on 1, 2 or 3
/// threads and compare the bits.
pub fn on_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
        .install(f)
}

/// Items without a bucket in `bucket_sort`.
pub const NO_BUCKET: u32 = u32::MAX;

/// A stable counting sort of the items 0..keys.len() by key (each key below
/// `buckets`, or `NO_BUCKET` to leave the item out): bucket b holds the items
/// `order[start[b]..start[b + 1]]` in increasing order. In parallel over chunks
/// of items; each chunk writes only the positions its counts reserve, so the
/// result, the one stable order, is the same on any number of threads.
pub fn bucket_sort(keys: &[u32], buckets: usize, start: &mut Vec<u32>, order: &mut Vec<u32>) {
    let n = keys.len();
    let chunk = n
        .div_ceil(rayon::current_num_threads())
        .max(MIN_PARALLEL_LEN);
    let chunks = n.div_ceil(chunk).max(1);
    let items = |c: usize| c * chunk..((c + 1) * chunk).min(n);
    let width = buckets.max(1);
    // counts[c · buckets + b]: the items of chunk c in bucket b.
    let mut counts = vec![0u32; chunks * width];
    counts
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(c, count)| {
            for q in items(c) {
                if keys[q] != NO_BUCKET {
                    count[keys[q] as usize] += 1;
                }
            }
        });
    start.clear();
    start.push(0);
    for b in 0..buckets {
        let total: u32 = (0..chunks).map(|c| counts[c * width + b]).sum();
        start.push(start[b] + total);
    }
    // Chunk c's items of bucket b go from start[b] + Σ_{c' < c} counts[c'][b] on.
    for b in 0..buckets {
        let mut at = start[b];
        for c in 0..chunks {
            let count = counts[c * width + b];
            counts[c * width + b] = at;
            at += count;
        }
    }
    order.resize(start[buckets] as usize, 0);
    let out = DisjointSlice::new(order);
    counts
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(c, next)| {
            for q in items(c) {
                if keys[q] != NO_BUCKET {
                    let at = &mut next[keys[q] as usize];
                    // SAFETY: position `at` was reserved for this chunk's item q alone.
                    unsafe { *out.at(*at as usize) = q as u32 };
                    *at += 1;
                }
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sort by the definition: items grouped by key, each group ascending,
    /// on 1, 2 and 3 threads.
    #[test]
    fn bucket_sort_is_the_stable_sort_by_key() {
        let n = 5000;
        let keys: Vec<u32> = (0..n as u64)
            .map(|q| match q % 11 {
                3 => NO_BUCKET,
                _ => ((q * 2654435761) % 37) as u32,
            })
            .collect();
        let mut expected: Vec<(u32, u32)> = (0..n as u32)
            .filter(|&q| keys[q as usize] != NO_BUCKET)
            .map(|q| (keys[q as usize], q))
            .collect();
        expected.sort();
        for threads in 1..=3 {
            let (mut start, mut order) = (vec![7], vec![1, 2, 3]);
            on_threads(threads, || bucket_sort(&keys, 40, &mut start, &mut order));
            assert_eq!(start.len(), 41);
            let got: Vec<(u32, u32)> = (0..40)
                .flat_map(|b| {
                    order[start[b] as usize..start[b + 1] as usize]
                        .iter()
                        .map(move |&q| (b as u32, q))
                })
                .collect();
            assert_eq!(got, expected, "{threads} threads");
        }
    }
}
