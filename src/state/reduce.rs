//! Deterministic parallel reductions: work is cut into fixed chunks whose partial results are
//! combined in chunk order, so sums are bitwise identical on any number of threads.

use rayon::prelude::*;
use std::ops::Range;

/// Items per chunk of a reduction.
pub const CHUNK: usize = 2048;

/// Maps `f` over fixed chunks of `0..n` in parallel and returns the results in chunk order.
pub fn chunked<R: Send, F: Fn(Range<usize>) -> R + Sync + Send>(n: usize, f: F) -> Vec<R> {
    (0..n.div_ceil(CHUNK)).into_par_iter().with_min_len(PAR_MIN_CHUNKS).map(|c| f(c * CHUNK..((c + 1) * CHUNK).min(n))).collect()
}

/// Fewest items a parallel loop hands to one task: below this, waking another thread costs
/// more than the work (measured on the 3000-grain pour: 2 threads were slower than 1 with 512).
pub const PAR_MIN_ITEMS: usize = 4096;

/// Fewest pairs a task of the pair pass takes: a pair of Oquendo et al.'s law costs several times
/// a per-grain pass's item (the 1200-grain oedometer, about 3600 pairs, ran in 185 s on 2
/// threads with this against 234 s with [`PAR_MIN_ITEMS`], which kept it on one).
pub const PAR_MIN_PAIRS: usize = 1024;

/// [`PAR_MIN_ITEMS`] in chunks.
pub const PAR_MIN_CHUNKS: usize = PAR_MIN_ITEMS / CHUNK;
