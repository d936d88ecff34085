//! This machine's memory bandwidth, probed as STREAM does: the triad `a = b + s c` over three
//! f64 arrays far larger than the caches, on a given number of threads, the best of a few
//! repeats. Counted as STREAM counts it (three arrays' bytes per pass; the write-allocate read
//! of `a` not counted).

use rayon::prelude::*;
use std::time::Instant;

/// Values per array: 3 x 32 MiB, well past the 32 MiB third-level caches seen here.
const LEN: usize = 1 << 22;
/// Timed passes; the fastest is reported.
const PASSES: usize = 6;
/// Values per parallel task.
const CHUNK: usize = 1 << 16;

/// The triad's bandwidth (bytes/s) on the current thread pool.
pub fn triad() -> f64 {
    let b = vec![1.0f64; LEN];
    let c = vec![2.0f64; LEN];
    let mut a = vec![0.0f64; LEN];
    let s = std::hint::black_box(3.0f64);
    let mut best = f64::INFINITY;
    for _ in 0..PASSES {
        let started = Instant::now();
        a.par_chunks_mut(CHUNK).zip(b.par_chunks(CHUNK)).zip(c.par_chunks(CHUNK)).for_each(|((a, b), c)| {
            for ((a, b), c) in a.iter_mut().zip(b).zip(c) {
                *a = b + s * c;
            }
        });
        best = best.min(started.elapsed().as_secs_f64());
        std::hint::black_box(&a);
    }
    (3 * LEN * std::mem::size_of::<f64>()) as f64 / best
}
