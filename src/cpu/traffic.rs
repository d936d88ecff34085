//! The bytes a step moves to and from memory, counted from the arrays each pass reads and
//! writes (each array streamed once per pass, a read and a write counted apart; the random
//! reads of a partner's grain counted as if its record were streamed once): the traffic a
//! step could not do with less, which `grains bench` sets beside the time to show how close
//! to the memory's bandwidth the step runs.

use super::*;

/// Bytes of a slice.
fn bytes<X>(v: &[X]) -> u64 {
    std::mem::size_of_val(v) as u64
}

impl<T: Real> CpuEngine<T> {
    /// Bytes each phase of a step that keeps its neighbour list moves (`kick`, `drift`,
    /// `force`, `walls`, `gather`), in the order of the schedule's later steps, as the engine's
    /// sweeps run them ([`Sweep`]: a kick merged into a sweep reads the grains' load
    /// and properties there, while the sweep has the bodies in hand).
    pub(super) fn traffic(&self) -> Vec<(&'static str, u64)> {
        let l = &self.pairs;
        let (body, prop) = (bytes(&self.body), bytes(&self.prop));
        // Compensated positions' residuals (empty in f64): read by every separation and every
        // wall distance, read and written by a drift.
        let residual = bytes(&self.residual);
        let orientation = self.orientation.as_deref().map_or(0, bytes);
        let kick = 2 * body + bytes(&self.load) + prop;
        let drift = 2 * body + 2 * residual + bytes(&self.built_at) + 2 * orientation;
        let r = &self.report;
        // A pair open since the last evaluation ([`PairFlags::OPEN`], as many as now) has its
        // flags read and nothing else: its springs and records keep their zeros.
        let n_pairs = l.len().max(1) as u64;
        let open = r.flags.iter().filter(|&&f| f == PairFlags::OPEN.0).count() as u64;
        let live = |b: u64| b / n_pairs * (n_pairs - open);
        let pair_out = bytes(&self.share) + bytes(&r.f_n) + bytes(&r.f_c) + bytes(&self.force_i);
        let force = bytes(&l.partner) + body + residual + prop + bytes(&r.flags) + live(2 * bytes(&self.hist) + pair_out) + bytes(&self.load);
        // The wall contacts run in the gather's sweep, on the loads it has in hand.
        // Only the candidates ([`super::wall_springs`]) are visited: their grains' state and their
        // springs, read and written; every grain's candidate bit is read.
        let ws = &self.wall_springs;
        let candidates_of = |b: u64| b / self.body.len().max(1) as u64 * ws.candidates() as u64;
        let walls = if self.walls.is_empty() { 0 } else { bytes(&ws.candidate) + candidates_of(body + residual + prop) + 2 * bytes(&ws.springs) };
        let gather = bytes(&self.share) + bytes(&l.rev_start) + bytes(&l.rev_pair) + 2 * bytes(&self.load);
        let mut out: Vec<(&'static str, u64)> = Vec::new();
        let mut add = |name: &'static str, b: u64| match out.iter_mut().find(|e| e.0 == name) {
            Some(e) => e.1 += b,
            None => out.push((name, b)),
        };
        let merged_kick = bytes(&self.load) + prop;
        // Inside a run of steps a step's first sweep, a kick and a drift, rides in the step
        // before's gather sweep ([`CpuEngine::step_in_run`]), which has the bodies, loads
        // and properties in hand: the residuals, the build positions and the orientations
        // are what it adds.
        let sweeps = self.schedule.sweeps(1);
        let carried = matches!((sweeps.first(), sweeps.last()), (Some(Sweep::KickDrift { .. }), Some(Sweep::ForcesKick { .. })));
        for &sweep in sweeps {
            match sweep {
                Sweep::Op(Op::Kick { .. }) => add("kick", kick),
                Sweep::Op(Op::Drift { .. }) => add("drift", drift),
                Sweep::Op(Op::RebuildIfNeeded) => {}
                Sweep::Op(Op::Forces { .. }) => {
                    add("force", force);
                    add("gather", gather);
                    add("walls", walls);
                }
                Sweep::KickDrift { .. } if carried => add("drift", 2 * residual + bytes(&self.built_at) + 2 * orientation),
                Sweep::KickDrift { .. } => {
                    add("kick", merged_kick);
                    add("drift", drift);
                }
                Sweep::ForcesKick { .. } => {
                    add("force", force);
                    // The gather's sweep reads and writes the bodies to kick them; the load it
                    // has just written is in hand.
                    add("gather", gather + 2 * body + prop);
                    add("walls", walls);
                }
            }
        }
        out.retain(|e| e.1 > 0);
        out
    }
}
