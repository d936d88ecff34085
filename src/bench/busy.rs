//! Busy programs beside a measurement (`grains bench --busy`): threads that compute until
//! dropped, at the bench's own priority. The kernel schedules threads, not processes, so each
//! competes for the cores as another program's busy loop in the same session would (one run of
//! `--busy 0,1` gave two threads 7.5e6 particle-steps/s beside one busy thread, where
//! `sh -c 'while :; do :; done'` beside the bench gave 7.8e6; see docs/performance.md).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;

/// Busy threads, stopped when dropped.
pub struct Busy {
    stop: Arc<AtomicBool>,
    threads: Vec<JoinHandle<()>>,
}

impl Busy {
    /// Starts `n` busy threads.
    pub fn start(n: usize) -> Busy {
        let stop = Arc::new(AtomicBool::new(false));
        let threads = (0..n)
            .map(|_| {
                let stop = stop.clone();
                std::thread::spawn(move || spin(&stop))
            })
            .collect();
        Busy { stop, threads }
    }
}

/// Integer arithmetic until `stop` (no pause instruction, which a hypervisor may take as a
/// spin-wait and deschedule).
fn spin(stop: &AtomicBool) {
    let mut x = 1u64;
    while !stop.load(Ordering::Relaxed) {
        for _ in 0..4096 {
            x = std::hint::black_box(x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1));
        }
    }
}

impl Drop for Busy {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        for t in self.threads.drain(..) {
            // A busy thread cannot panic; nothing to report if it did.
            let _ = t.join();
        }
    }
}
