//! One run over several processes (feature `mpi`): `mpirun -np K grains run SCENE`.
//!
//! The domain is cut into boxes ([`Grid`]: slabs along one axis, or a grid of them along two
//! or three), one per process. Each process runs the CPU engine over the grains it owns and,
//! as ghosts, the grains of the boxes around it within the neighbour reach of its box. A pair
//! with a ghost is computed by both processes with the same operations on the same bits, and
//! every sum a grain's load takes runs in permanent-id order whatever the numbering (see
//! `cpu`), so each owned grain's load, and so its motion, is the one process's to the bit.
//! Between the operations of a step ([`super::CpuEngine::step_with`]):
//! - after each drift, each process sends its neighbours the motion of the grains they hold
//!   as ghosts, and the largest displacement since the last rebuild is the maximum over all;
//! - when that calls for a rebuild, every process rebuilds at once: the cuts move to the
//!   quantiles of the grains' positions if one process owns too many, each grain goes to the
//!   process that owns it now, with its walls' history, and each pair's history goes from a
//!   process that owned one of its grains (and so computed it every step) to every process
//!   that holds both, before the local neighbour list is built and the history carried over;
//! - before each force evaluation of a capillary scene, the bridge events (ruptures, touches)
//!   each process finds on the pairs of its own grains are gathered and replayed by every
//!   process in canonical order, so liquid moves between grains of different processes as on
//!   one;
//! - after each force evaluation, the walls' sums (piston, servo walls) are taken over every
//!   process's wall contacts in permanent-id order, so every process moves its walls alike.
//!
//! After each `advance` rank 0 gathers the whole state (grains by permanent id, each pair
//! once), and statistics, frames and checkpoints are the one-process engine's, computed from
//! it there: rank 0 writes the outputs and sends the statistics to the others, so the host
//! loop takes the same decisions everywhere (the piston's place too). The other processes hold
//! their box alone. A checkpoint is a one-process checkpoint and resumes on any number of
//! processes; a restore and a wetting stage gather or spread the whole state on every process
//! for a moment.
//!
//! Limits of this version: every process reads the whole scene (its grains' starting values,
//! O(N)); rank 0 holds the whole state (O(N)); the grid's cuts along an axis are the same
//! for every box (a tensor grid: a packing denser in one corner balances poorly); contact
//! dynamics is refused.

mod grid;
mod slabs;

pub use grid::Grid;
pub use slabs::Slabs;

use super::step::StepHooks;
use super::{touch_of_row, touches_state, CpuEngine, RowWidths, Rows, WallContact, BRIDGE_ROW, TOUCH_ROW};
use crate::engine::{Engine, EngineState, Frame, SimError, Stats};
use crate::real::Real;
use crate::scene::{Method, Scene};
use mpi::collective::SystemOperation;
use mpi::datatype::{Partition, PartitionMut};
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use std::sync::OnceLock;

/// This process's rank and the number of processes, once MPI has started.
static WORLD: OnceLock<(usize, usize)> = OnceLock::new();

/// Starts MPI, when the run command begins; `None` when it was started already. Holding the
/// universe keeps MPI up; dropping it finalises it. Calls from any thread, one at a time:
/// the run happens on a worker of the thread pool.
pub fn init() -> Option<mpi::environment::Universe> {
    let (universe, _) = mpi::initialize_with_threading(mpi::Threading::Serialized)?;
    let world = universe.world();
    WORLD.get_or_init(|| (world.rank() as usize, world.size() as usize));
    Some(universe)
}

/// Processes in the run (1 when MPI was not started).
pub fn size() -> usize {
    WORLD.get().map_or(1, |w| w.1)
}

/// True on the process that writes outputs and prints: rank 0, or the only one.
pub fn is_root() -> bool {
    WORLD.get().is_none_or(|w| w.0 == 0)
}

/// The CPU engine over several processes.
pub struct Distributed<T: Real> {
    /// The grains this process owns and its ghosts, numbered in ascending permanent id.
    local: CpuEngine<T>,
    net: Net<T>,
    /// On rank 0, the whole state, gathered there after each `advance`: statistics, frames
    /// and checkpoints. None on the other processes, which hold their box alone.
    whole: Option<CpuEngine<T>>,
}

/// What the hooks between a step's operations need: everything but the local engine.
struct Net<T: Real> {
    world: SimpleCommunicator,
    rank: usize,
    grid: Grid,
    /// The scene with no grains: the local engines are made from it and their grains.
    template: Scene,
    /// The scene's grains, by permanent id.
    grains: crate::scene::Grains,
    widths: RowWidths,
    /// The permanent id of each local grain (ascending).
    gid: Vec<u32>,
    /// Whether this process owns each local grain.
    owned: Vec<bool>,
    /// The processes this one exchanges ghosts with.
    links: Vec<Link>,
    /// Every process's wall contacts at the last force evaluation, by permanent id.
    touches: Vec<WallContact<T>>,
}

/// The ghosts one process and a neighbour exchange after each drift (local numbers, each
/// list ascending, so that both ends agree on the order).
struct Link {
    rank: usize,
    /// Grains this process owns and the neighbour holds as ghosts.
    send: Vec<u32>,
    /// Ghosts here that the neighbour owns.
    recv: Vec<u32>,
}

impl<T: Real> Distributed<T> {
    /// Sets the scene up over every process of MPI's world (each process calls this alike).
    pub fn new(scene: &Scene) -> anyhow::Result<Self> {
        let file = scene.path.display();
        if !matches!(scene.method, Method::Dem) {
            anyhow::bail!("{file}: simulation.method = \"contact_dynamics\" runs on one process; fix: run it without mpirun");
        }
        if scene.walls.iter().any(|w| matches!(w.shape, crate::scene::WallShape::Mesh { .. })) {
            anyhow::bail!("{file}: mesh walls run on one process so far; fix: run it without mpirun");
        }
        if scene.has_flow() {
            anyhow::bail!("{file}: [[inlet]] and [[outlet]] run on one process so far; fix: run it without mpirun");
        }
        if scene.walls.iter().map(|w| &w.drive).chain(scene.stages.iter().flat_map(|s| s.walls.iter().map(|(_, d)| d))).any(|d| d.turns) {
            anyhow::bail!("{file}: walls that turn (a spin off a plane's normal) run on one process so far; fix: run it without mpirun");
        }
        let world = SimpleCommunicator::world();
        let grid = Grid::new(scene, world.size() as usize)?;
        let mut whole = CpuEngine::<T>::new(scene)?;
        whole.keep_slots();
        let template = Scene { grains: Default::default(), ..scene.clone() };
        let mut net = Net {
            rank: world.rank() as usize,
            world,
            grid,
            template,
            grains: scene.grains.clone(),
            widths: whole.row_widths(),
            gid: Vec::new(),
            owned: Vec::new(),
            links: Vec::new(),
            touches: Vec::new(),
        };
        let local = net.scatter(&mut whole)?;
        let whole = (net.rank == 0).then_some(whole);
        Ok(Distributed { local, net, whole })
    }

    /// Gathers the whole state from every process into `whole` on rank 0, or, when
    /// `everywhere`, on every process (made on those that hold none).
    fn gather_whole(&mut self, everywhere: bool) -> Result<(), SimError> {
        let state = self.local.save()?;
        let net = &self.net;
        let mut rows = Rows::of_state(&state, &net.widths, |l| net.owned[l as usize], |a, _| net.owned[a as usize]);
        rows.renumber(&net.widths, |l| net.gid[l as usize]);
        let (grains, pairs) = if everywhere { (Some(net.all_gather(&rows.grains)), Some(net.all_gather(&rows.pairs))) } else { (net.gather_to_root(&rows.grains), net.gather_to_root(&rows.pairs)) };
        let (Some(grains), Some(pairs)) = (grains, pairs) else { return Ok(()) };
        let (whole_state, _) = super::state_of_rows(&Rows { grains, pairs }, &net.widths, &state, &touches_state(&net.touches));
        let whole = match &mut self.whole {
            Some(w) => w,
            None => self.whole.insert(net.whole_engine().map_err(|e| net.internal(&self.local, &format!("{e:#}")))?),
        };
        whole.restore(&whole_state).map_err(|e| net.internal(&self.local, &format!("cannot gather the whole state: {e:#}")))?;
        // The walls' counts of sliding and rolling contacts are not in a state: from the contacts.
        whole.set_wall_sums(&net.touches, net.grains.len());
        Ok(())
    }

    /// Makes the local engine anew from the whole state `whole`, which every process holds,
    /// and keeps `whole` on rank 0 alone.
    fn scatter_from(&mut self, mut whole: CpuEngine<T>) -> anyhow::Result<()> {
        self.local = self.net.scatter(&mut whole)?;
        self.whole = (self.net.rank == 0).then_some(whole);
        Ok(())
    }
}

impl<T: Real> Net<T> {
    /// Makes the local engine from the whole state, which every process holds: this process
    /// owns the grains in its box and holds as ghosts their partners in the current list.
    fn scatter(&mut self, whole: &mut CpuEngine<T>) -> anyhow::Result<CpuEngine<T>> {
        let state = whole.save()?;
        let n = self.grains.len();
        let owner: Vec<usize> = (0..n as u32).map(|i| self.grid.owner(whole.position(i))).collect();
        let me = self.rank;
        // Each grain's holders: its owner and the owners of its partners.
        let mut held: Vec<Vec<usize>> = owner.iter().map(|&o| vec![o]).collect();
        let ids = &state.ints["id"];
        let (starts, p) = (&state.ints["owner_start"], &state.ints["partner"]);
        for (slot, k) in crate::state::owned_pairs(starts) {
            let (a, b) = (ids[slot] as usize, ids[p[k] as usize] as usize);
            if owner[a] != owner[b] {
                held[a].push(owner[b]);
                held[b].push(owner[a]);
            }
        }
        for h in &mut held {
            h.sort_unstable();
            h.dedup();
        }
        let local = |i: u32| held[i as usize].contains(&me);
        let rows = Rows::of_state(&state, &self.widths, local, |a, b| local(a) && local(b));
        self.touches = whole.touch_rows(|_| true, |i| i).chunks_exact(TOUCH_ROW).map(touch_of_row).collect();
        let engine = self.make_local(&rows, &state)?;
        let gid = &self.gid;
        self.owned = gid.iter().map(|&i| owner[i as usize] == me).collect();
        let mut links = Vec::new();
        for r in (0..self.world.size() as usize).filter(|&r| r != me) {
            let send = (0..gid.len() as u32).filter(|&l| self.owned[l as usize] && held[gid[l as usize] as usize].contains(&r)).collect();
            let recv = (0..gid.len() as u32).filter(|&l| owner[gid[l as usize] as usize] == r).collect();
            links.push(Link { rank: r, send, recv });
        }
        links.retain(|l: &Link| !l.send.is_empty() || !l.recv.is_empty());
        self.links = links;
        Ok(engine)
    }

    /// A local engine holding the grains of `rows` (by permanent id), with the whole-engine
    /// values of `template`; notes their permanent ids.
    fn make_local(&mut self, rows: &Rows, template: &EngineState) -> anyhow::Result<CpuEngine<T>> {
        let (state, gid) = super::state_of_rows(rows, &self.widths, template, &touches_state::<T>(&[]));
        let order: Vec<usize> = gid.iter().map(|&i| i as usize).collect();
        let mut grains = self.grains.permuted(&order);
        // Where the grains are now, for the list the new engine builds before the restore.
        for (p, b) in grains.position.iter_mut().zip(state.reals["body"].chunks_exact(9)) {
            *p = glam::DVec3::new(b[0], b[1], b[2]);
        }
        let scene = Scene { grains, ..self.template.clone() };
        let mut local = CpuEngine::<T>::new(&scene)?;
        local.keep_slots();
        local.restore(&state)?;
        self.gid = gid;
        Ok(local)
    }

    /// An engine over every grain of the scene (its state to be restored).
    fn whole_engine(&self) -> anyhow::Result<CpuEngine<T>> {
        let mut whole = CpuEngine::new(&Scene { grains: self.grains.clone(), ..self.template.clone() })?;
        whole.keep_slots();
        Ok(whole)
    }

    /// Every process's `mine`, concatenated in rank order, on rank 0; None elsewhere.
    fn gather_to_root(&self, mine: &[f64]) -> Option<Vec<f64>> {
        let root = self.world.process_at_rank(0);
        if self.rank != 0 {
            root.gather_into(&(mine.len() as i32));
            root.gather_varcount_into(mine);
            return None;
        }
        let mut counts = vec![0i32; self.world.size() as usize];
        root.gather_into_root(&(mine.len() as i32), &mut counts[..]);
        let displs = offsets(&counts);
        let mut all = vec![0.0; counts.iter().map(|&c| c as usize).sum()];
        root.gather_varcount_into_root(mine, &mut PartitionMut::new(&mut all[..], &counts[..], &displs[..]));
        Some(all)
    }

    /// Rank 0's `bytes`, on every process.
    fn broadcast_bytes(&self, bytes: &mut Vec<u8>) {
        let root = self.world.process_at_rank(0);
        let mut len = bytes.len() as u64;
        root.broadcast_into(&mut len);
        bytes.resize(len as usize, 0);
        root.broadcast_into(&mut bytes[..]);
    }

    /// Every process's `mine`, concatenated in rank order.
    fn all_gather(&self, mine: &[f64]) -> Vec<f64> {
        let size = self.world.size() as usize;
        let mut counts = vec![0i32; size];
        self.world.all_gather_into(&(mine.len() as i32), &mut counts[..]);
        let displs = offsets(&counts);
        let mut all = vec![0.0; counts.iter().map(|&c| c as usize).sum()];
        self.world.all_gather_varcount_into(mine, &mut PartitionMut::new(&mut all[..], &counts[..], &displs[..]));
        all
    }

    /// Sends `out[k]` to `ranks[k]` and returns what each of them sent back, in that order.
    fn exchange(&self, ranks: &[usize], out: &[Vec<f64>]) -> Vec<Vec<f64>> {
        mpi::request::scope(|scope| {
            let sends: Vec<_> = ranks.iter().zip(out).map(|(&r, buf)| self.world.process_at_rank(r as i32).immediate_send(scope, &buf[..])).collect();
            let got = ranks.iter().map(|&r| self.world.process_at_rank(r as i32).receive_vec::<f64>().0).collect();
            for s in sends {
                s.wait();
            }
            got
        })
    }

    /// Sends `out[r]` to each process `r` and returns what each sent this one, by rank.
    fn all_to_all(&self, out: &[Vec<f64>]) -> Vec<Vec<f64>> {
        let size = self.world.size() as usize;
        let send_counts: Vec<i32> = out.iter().map(|b| b.len() as i32).collect();
        let mut recv_counts = vec![0i32; size];
        self.world.all_to_all_into(&send_counts[..], &mut recv_counts[..]);
        let (send_displs, recv_displs) = (offsets(&send_counts), offsets(&recv_counts));
        let send: Vec<f64> = out.concat();
        let mut recv = vec![0.0; recv_counts.iter().map(|&c| c as usize).sum()];
        self.world.all_to_all_varcount_into(&Partition::new(&send[..], &send_counts[..], &send_displs[..]), &mut PartitionMut::new(&mut recv[..], &recv_counts[..], &recv_displs[..]));
        recv_displs.iter().zip(&recv_counts).map(|(&d, &c)| recv[d as usize..(d + c) as usize].to_vec()).collect()
    }

    /// The same error on every process: of the errors the processes met (`mine` here), the one
    /// about the lowest permanent id.
    fn agree(&self, e: &CpuEngine<T>, mine: Option<SimError>) -> Result<(), SimError> {
        // [kind (0: none, 1: capacity, 2: non-finite, 3: internal), grain, count]
        let code = match &mine {
            None => [0, u32::MAX as u64, 0],
            Some(SimError::Capacity { grain, count, .. }) => [1, self.gid[*grain as usize] as u64, *count as u64],
            Some(SimError::Unstable { grain, .. }) => [2, self.gid.get(*grain as usize).copied().unwrap_or(*grain) as u64, 0],
            Some(SimError::Device { .. }) => [2, 0, 0],
            // The GPU's pair buffers: no process of a distributed CPU run has them; nor mesh
            // walls, which it refuses.
            Some(SimError::Internal { .. } | SimError::PairBuffers { .. } | SimError::DeviceMemory { .. } | SimError::MeshContacts { .. }) => [3, 0, 0],
        };
        let mut all = vec![0u64; 3 * self.world.size() as usize];
        self.world.all_gather_into(&code[..], &mut all[..]);
        let Some(c) = all.chunks_exact(3).filter(|c| c[0] != 0).min_by_key(|c| (c[1], c[0])) else { return Ok(()) };
        let (step, time, suggested_dt) = e.error_context();
        let grain = c[1] as u32;
        Err(match c[0] {
            1 => SimError::Capacity { step, grain, count: c[2] as usize, capacity: self.template.max_neighbours },
            3 => SimError::Internal { step, what: format!("process {} met an internal error", all.chunks_exact(3).position(|c| c[0] == 3).unwrap_or(0)) },
            _ => SimError::Unstable { step, time, what: "non-finite position or velocity".into(), grain, suggested_dt, also: "" },
        })
    }

    /// An error for a state the processes disagree on (a bug, not the scene's doing).
    fn internal(&self, e: &CpuEngine<T>, what: &str) -> SimError {
        SimError::Internal { step: e.steps(), what: format!("process {}: {what}", self.rank) }
    }

    /// Local numbers of the grains this process owns.
    fn owned_numbers(&self) -> impl Iterator<Item = u32> + '_ {
        self.owned.iter().enumerate().filter(|(_, o)| **o).map(|(l, _)| l as u32)
    }

    /// Cuts the grid anew at the quantiles of the owned grains' positions when a process owns
    /// more than [`grid::REBALANCE_ABOVE`] times the mean (the same decision and cuts on every
    /// process: from the gathered counts and positions).
    fn rebalance(&mut self, e: &CpuEngine<T>) {
        let owned = self.owned_numbers().count() as u64;
        let size = self.world.size() as usize;
        let mut counts = vec![0u64; size];
        self.world.all_gather_into(&owned, &mut counts[..]);
        let mean = self.grains.len() as f64 / size as f64;
        if (*counts.iter().max().unwrap_or(&0) as f64) <= grid::REBALANCE_ABOVE * mean {
            return;
        }
        let mine: Vec<f64> = self.owned_numbers().flat_map(|l| e.position(l)).collect();
        let all: Vec<[f64; 3]> = self.all_gather(&mine).chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
        self.grid.recut(&all);
    }

    /// Rebuilds on every process: grains to their owners, pairs' history to the processes
    /// holding both grains, then the local list (see the module's doc).
    fn redistribute(&mut self, e: &mut CpuEngine<T>) -> Result<(), SimError> {
        let bad = self.owned_numbers().find(|&l| !e.is_finite(l));
        self.agree(e, bad.map(|l| SimError::Unstable { step: 0, time: 0.0, what: String::new(), grain: l, suggested_dt: 0.0, also: "" }))?;
        self.rebalance(e);
        let state = e.save()?;
        let holders: Vec<Vec<usize>> = (0..self.gid.len() as u32).map(|l| self.grid.holders(e.position(l))).collect();
        let me = self.rank;
        // The rows each process gets from this one: the grains it will hold that this one
        // owns, and the pairs between two grains it will hold of which this one owns one.
        let rows_for = |r: usize| {
            let held = |l: u32| holders[l as usize].contains(&r);
            let mut rows = Rows::of_state(&state, &self.widths, |l| self.owned[l as usize] && held(l), |a, b| (self.owned[a as usize] || self.owned[b as usize]) && held(a) && held(b));
            rows.renumber(&self.widths, |l| self.gid[l as usize]);
            rows
        };
        // Only the processes that hold one of this one's grains get rows (the boxes' neighbours):
        // the others get no rows, without a pass over the state.
        let mut dest = vec![false; self.world.size() as usize];
        for l in self.owned_numbers() {
            for &r in &holders[l as usize] {
                dest[r] = true;
            }
        }
        let out: Vec<Vec<f64>> = dest.iter().enumerate().map(|(r, &d)| (if d && r != me { rows_for(r) } else { Rows::default() }).to_message()).collect();
        let mut rows = rows_for(me);
        for (r, got) in self.all_to_all(&out).iter().enumerate() {
            if r != me {
                rows.append(&Rows::from_message(got));
            }
        }
        let mut local = self.make_local(&rows, &state).map_err(|err| self.internal(e, &format!("{err:#}")))?;
        let built = local.rebuild();
        self.agree(&local, built.err())?;
        let x: Vec<[f64; 3]> = (0..self.gid.len() as u32).map(|l| local.position(l)).collect();
        let owner: Vec<usize> = x.iter().map(|&p| self.grid.owner(p)).collect();
        self.owned = owner.iter().map(|&o| o == me).collect();
        self.links = (0..self.world.size() as usize)
            .filter(|&r| r != me)
            .map(|r| Link {
                rank: r,
                send: (0..x.len() as u32).filter(|&l| owner[l as usize] == me && self.grid.near(x[l as usize], r)).collect(),
                recv: (0..x.len() as u32).filter(|&l| owner[l as usize] == r).collect(),
            })
            .filter(|l| !l.send.is_empty() || !l.recv.is_empty())
            .collect();
        *e = local;
        Ok(())
    }
}

/// Where each of the blocks of `counts` values starts in their concatenation.
fn offsets(counts: &[i32]) -> Vec<i32> {
    counts.iter().scan(0, |at, &n| Some(std::mem::replace(at, *at + n))).collect()
}

impl<T: Real> StepHooks<T> for Net<T> {
    fn drifted(&mut self, e: &mut CpuEngine<T>) -> Result<(), SimError> {
        let ranks: Vec<usize> = self.links.iter().map(|l| l.rank).collect();
        let out: Vec<Vec<f64>> = self.links.iter().map(|l| {
            let mut buf = Vec::with_capacity(l.send.len() * e.motion_row());
            e.motion_rows(&l.send, &mut buf);
            buf
        }).collect();
        for (l, got) in self.links.iter().zip(self.exchange(&ranks, &out)) {
            if got.len() != l.recv.len() * e.motion_row() {
                return Err(self.internal(e, &format!("process {} sent {} values for {} ghosts", l.rank, got.len(), l.recv.len())));
            }
            e.set_motion_rows(&l.recv, &got);
        }
        let mine = e.moved2_of(self.owned_numbers());
        let mut max = 0.0;
        self.world.all_reduce_into(&mine, &mut max, SystemOperation::max());
        e.set_moved2(max);
        Ok(())
    }

    fn rebuild_if_needed(&mut self, e: &mut CpuEngine<T>) -> Result<(), SimError> {
        if e.needs_rebuild() {
            self.redistribute(e)?;
        }
        Ok(())
    }

    fn bridges(&mut self, e: &mut CpuEngine<T>) -> Result<(), SimError> {
        // Each pair's events come from the process that owns its owner grain (it lists every
        // pair of that grain); every process replays them all, in canonical order.
        let mine = e.bridge_rows(|l| self.owned[l as usize], |l| self.gid[l as usize]);
        let all = self.all_gather(&mine);
        let mut rows: Vec<&[f64]> = all.chunks_exact(BRIDGE_ROW).collect();
        rows.sort_by_key(|r| (r[0] as u32, r[1] as u32));
        let gid = &self.gid;
        e.replay_bridges(&rows.concat(), |g| gid.binary_search(&g).ok().map(|l| l as u32));
        Ok(())
    }

    fn forces_evaluated(&mut self, e: &mut CpuEngine<T>) -> Result<(), SimError> {
        if self.template.walls.is_empty() {
            return Ok(());
        }
        let mine = e.touch_rows(|l| self.owned[l as usize], |l| self.gid[l as usize]);
        let mut touches: Vec<WallContact<T>> = self.all_gather(&mine).chunks_exact(TOUCH_ROW).map(touch_of_row).collect();
        touches.sort_by_key(|t| (t.grain, t.wall));
        e.set_wall_sums(&touches, self.grains.len());
        self.touches = touches;
        Ok(())
    }
}

impl<T: Real> Engine for Distributed<T> {
    fn backend(&self) -> &'static str {
        "cpu"
    }
    fn precision(&self) -> &'static str {
        T::NAME
    }
    fn grain_count(&self) -> usize {
        self.net.grains.len()
    }
    fn steps(&self) -> u64 {
        self.local.steps()
    }
    fn time(&self) -> f64 {
        self.local.time()
    }
    fn advance(&mut self, n: u64) -> Result<(), SimError> {
        for _ in 0..n {
            // Processes exchange ghosts after each drift and sum the walls after each
            // evaluation: no step carries the next one's first sweep.
            self.local.step_with(&mut self.net, false)?;
        }
        self.gather_whole(false)
    }
    /// Rank 0's statistics of the whole state, on every process (so that each takes the same
    /// decisions), carried as the JSON a checkpoint carries them in.
    fn stats(&mut self) -> Result<Stats, SimError> {
        let mut bytes = match &mut self.whole {
            Some(w) => serde_json::to_vec(&w.stats()?).map_err(|e| self.net.internal(&self.local, &format!("{e}")))?,
            None => Vec::new(),
        };
        self.net.broadcast_bytes(&mut bytes);
        serde_json::from_slice(&bytes).map_err(|e| self.net.internal(&self.local, &format!("cannot read rank 0's statistics: {e}")))
    }
    /// The whole state's frame on rank 0; an empty one on the other processes, which write no
    /// outputs (what a frame decides, the piston's place, comes from rank 0).
    fn frame(&self, contacts: bool) -> Result<Frame, SimError> {
        self.whole.as_ref().map_or(Ok(Frame::default()), |w| w.frame(contacts))
    }
    fn set_piston_pressure(&mut self, pressure: f64) {
        self.local.set_piston_pressure(pressure);
        if let Some(w) = &mut self.whole {
            w.set_piston_pressure(pressure);
        }
    }
    /// The whole state, on rank 0, which alone writes checkpoints.
    fn save(&self) -> Result<EngineState, SimError> {
        match &self.whole {
            Some(w) => w.save(),
            None => Err(self.net.internal(&self.local, "only rank 0 holds the whole state to save")),
        }
    }
    fn restore(&mut self, state: &EngineState) -> anyhow::Result<()> {
        let mut whole = match self.whole.take() {
            Some(w) => w,
            None => self.net.whole_engine()?,
        };
        whole.restore(state)?;
        self.scatter_from(whole)
    }
    fn set_wall_drive(&mut self, wall: usize, drive: &crate::scene::WallDrive) {
        self.local.set_wall_drive(wall, drive);
        if let Some(w) = &mut self.whole {
            w.set_wall_drive(wall, drive);
        }
    }
    fn set_wall_present(&mut self, wall: usize, present: bool) {
        self.local.set_wall_present(wall, present);
        if let Some(w) = &mut self.whole {
            w.set_wall_present(wall, present);
        }
    }
    fn remove_grains(&mut self, _ids: &[u32]) -> anyhow::Result<()> {
        anyhow::bail!("a run over several processes keeps every grain in play: it takes no outlet yet; fix: run it without mpirun")
    }
    fn insert_grains(&mut self, _grains: &[crate::engine::Insertion]) -> anyhow::Result<()> {
        anyhow::bail!("a run over several processes keeps every grain in play: it takes no inlet yet; fix: run it without mpirun")
    }
    fn set_servo(&mut self, pressure: Option<f64>, axial_strain_rate: Option<f64>) {
        self.local.set_servo(pressure, axial_strain_rate);
        if let Some(w) = &mut self.whole {
            w.set_servo(pressure, axial_strain_rate);
        }
    }
    fn wet(&mut self, volume: f64) -> anyhow::Result<()> {
        // Shared over every pair in canonical order: on the whole state, gathered on every
        // process, then scattered anew.
        self.gather_whole(true)?;
        let Some(mut whole) = self.whole.take() else { anyhow::bail!(self.net.internal(&self.local, "the whole state was gathered on every process, yet is missing here")) };
        whole.wet(volume)?;
        self.scatter_from(whole)
    }
    fn place_piston(&mut self, z: f64) {
        // Rank 0's place: the others' frames are empty.
        let mut z = z;
        self.net.world.process_at_rank(0).broadcast_into(&mut z);
        self.local.place_piston(z);
        if let Some(w) = &mut self.whole {
            w.place_piston(z);
        }
    }
    fn memory_bytes(&self) -> u64 {
        self.local.memory_bytes() + self.whole.as_ref().map_or(0, |w| w.memory_bytes())
    }
    fn set_profiling(&mut self, on: bool) {
        self.local.set_profiling(on);
    }
    fn phase_seconds(&self) -> Vec<(&'static str, f64)> {
        self.local.phase_seconds()
    }
}
