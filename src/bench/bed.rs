//! The benchmark bed: the peers' dense, settled, polydisperse packing (`scenes/bench_bed.toml`,
//! 10^4 grains poured onto a floor, periodic in x-y), poured once and cached on disk, and tiled
//! in x-y for larger sizes. Tiling is instant, so a 10^6-grain dense start costs only the
//! one-off pour of the 10^4-grain bed.

use glam::DVec3;
use crate::checkpoint::{self, EngineState};
use crate::cpu::CpuEngine;
use crate::output::RunRecorder;
use crate::periodic::Periodic;
use crate::protocol::StageResult;
use crate::scene::{self, Grains, Scene};
use anyhow::Context;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The bed's scene file, bundled so that `grains bench` runs from anywhere.
pub const BED_SCENE: &str = include_str!("../../scenes/bench_bed.toml");
/// The name the bundled scene reports under.
const BED_PATH: &str = "scenes/bench_bed.toml";
/// The revision of the pour's physics, part of the cache file's name with the scene's text, so
/// that a bed poured under an older contact law is poured again rather than read: raised
/// whenever a change moves the pour (2: the restitution dashpot sized for the clamped law, and
/// springs counted from the instant of touch; 3: the damped normal force taken over each
/// evaluation's window).
const POUR_REVISION: u32 = 3;

/// What the cache file's header records about the pour.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BedInfo {
    /// [`checkpoint::fnv1a`] of the scene text the bed was poured from.
    pub scene_hash: u64,
    /// Simulated time of the pour (s).
    pub time: f64,
    /// Whether the pour met its settle criteria before its duration ran out.
    pub settled: bool,
    /// Translational kinetic energy per grain at the end (J).
    pub ke_per_grain: f64,
    /// Contacts per grain at the end.
    pub coordination: f64,
    /// Wall seconds the pour took.
    pub wall_seconds: f64,
    /// The scene file the bed was read from (`grains bench --bed`), or empty for the pour.
    #[serde(default)]
    pub source: String,
}

/// The default cache folder: `$XDG_CACHE_HOME/grains`, else `$HOME/.cache/grains`, else
/// `./.grains-cache`.
pub fn default_cache() -> PathBuf {
    let base = std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")));
    base.map_or_else(|| PathBuf::from(".grains-cache"), |b| b.join("grains"))
}

/// The settled 10^4-grain bed: read from `cache`, or poured (f64, on the current thread pool)
/// and written there. Returns the scene with the settled grains and what the pour gave.
pub fn settled_bed(cache: &Path, progress: bool) -> anyhow::Result<(Scene, BedInfo)> {
    settled(Path::new(BED_PATH), BED_SCENE, cache, progress)
}

/// The grains of the scene `text` (named `path`) at the end of its stages: read from `cache`
/// (a file named after the scene and a hash of its text and [`POUR_REVISION`]), or run (f64,
/// on the current thread pool) and written there. Returns the scene with those grains and what
/// the run gave.
pub fn settled(path: &Path, text: &str, cache: &Path, progress: bool) -> anyhow::Result<(Scene, BedInfo)> {
    let mut scene = scene::parse(path, text)?;
    let hash = checkpoint::fnv1a(format!("{text}\npour revision {POUR_REVISION}").as_bytes());
    let path = cache.join(format!("{}-{hash:016x}.grains", scene.name.replace('_', "-")));
    if path.exists() {
        let (info, state): (BedInfo, EngineState) = checkpoint::read(&path)?;
        let n = scene.grains.len();
        let triples = |name: &str| -> anyhow::Result<Vec<DVec3>> { Ok(state.reals(name, 3 * n)?.chunks_exact(3).map(DVec3::from_slice).collect()) };
        scene.grains.position = triples("position").with_context(|| format!("{}: a damaged bed; fix: delete it and run again", path.display()))?;
        scene.grains.velocity = triples("velocity")?;
        scene.grains.angular_velocity = triples("angular_velocity")?;
        return Ok((scene, info));
    }
    if progress {
        eprintln!("pouring the {}-grain bed {} once; it is cached in {}", scene.grains.len(), scene.name, cache.display());
    }
    let started = std::time::Instant::now();
    let mut engine = CpuEngine::<f64>::new(&scene)?;
    let mut rec = RunRecorder::new(None, progress)?;
    let stages = crate::protocol::run(&scene, &mut engine, &mut rec);
    rec.finish()?;
    let stages: Vec<StageResult> = stages?;
    let last = stages.last().with_context(|| format!("{}: the bed's scene has no stage", scene.path.display()))?;
    let info = BedInfo {
        scene_hash: hash,
        time: last.time_end,
        settled: last.settled.unwrap_or(false),
        ke_per_grain: last.ke_per_grain,
        coordination: last.stats.coordination,
        wall_seconds: started.elapsed().as_secs_f64(),
        source: String::new(),
    };
    let periodic = Periodic::<f64>::of(&scene.periodic);
    let body = engine.bodies();
    scene.grains.position = body.iter().map(|b| periodic.wrap(b.pos).0.f64()).collect();
    scene.grains.velocity = body.iter().map(|b| b.vel.f64()).collect();
    scene.grains.angular_velocity = body.iter().map(|b| b.omega.f64()).collect();
    let mut state = EngineState::default();
    let flat = |v: &[DVec3]| v.iter().flat_map(|p| p.to_array()).collect::<Vec<f64>>();
    state.put_reals("position", flat(&scene.grains.position));
    state.put_reals("velocity", flat(&scene.grains.velocity));
    state.put_reals("angular_velocity", flat(&scene.grains.angular_velocity));
    std::fs::create_dir_all(cache).with_context(|| format!("cannot create the cache folder {}", cache.display()))?;
    checkpoint::write(&path, &info, &state)?;
    Ok((scene, info))
}

/// A bed given as a scene file (e.g. one whose `[[read]]` takes LAMMPS' settled bed): its
/// contacts per grain at the start, from one statistics read of a CPU f64 engine.
pub fn given_bed(path: &Path) -> anyhow::Result<(Scene, BedInfo)> {
    let scene = scene::load(path)?;
    let stats = crate::engine::Engine::stats(&mut CpuEngine::<f64>::new(&scene)?)?;
    let n = scene.grains.len() as f64;
    let info = BedInfo {
        scene_hash: checkpoint::fnv1a(&std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?),
        time: 0.0,
        settled: true,
        ke_per_grain: stats.ke_translational / n,
        coordination: stats.coordination,
        wall_seconds: 0.0,
        source: path.display().to_string(),
    };
    Ok((scene, info))
}

/// `nx x ny` copies of a bed periodic in x and y, side by side in the x-y plane. Copy `c`
/// holds grains `c n .. (c + 1) n`, so that each copy stays together in memory.
pub fn tile(bed: &Scene, nx: usize, ny: usize) -> anyhow::Result<Scene> {
    let (Some([x0, x1]), Some([y0, y1])) = (bed.periodic[0], bed.periodic[1]) else {
        anyhow::bail!("{}: only a bed periodic in x and y can be tiled", bed.path.display());
    };
    let g = &bed.grains;
    let mut out = Grains::default();
    for cy in 0..ny {
        for cx in 0..nx {
            let shift = [cx as f64 * (x1 - x0), cy as f64 * (y1 - y0), 0.0];
            out.radius.extend_from_slice(&g.radius);
            out.mass.extend_from_slice(&g.mass);
            out.material.extend_from_slice(&g.material);
            out.velocity.extend_from_slice(&g.velocity);
            out.angular_velocity.extend_from_slice(&g.angular_velocity);
            out.position.extend(g.position.iter().map(|p| DVec3::new(p[0] + shift[0], p[1] + shift[1], p[2] + shift[2])));
        }
    }
    let mut scene = bed.clone();
    scene.name = format!("{}_{}x{}", bed.name, nx, ny);
    scene.periodic[0] = Some([x0, x0 + nx as f64 * (x1 - x0)]);
    scene.periodic[1] = Some([y0, y0 + ny as f64 * (y1 - y0)]);
    scene.grains = out;
    Ok(scene)
}

/// `bed` with its grains numbered at random (a fixed shuffle): the order of a pour whose
/// grains were inserted at random places, which the engine's renumbering in cell order
/// (`simulation.reorder_every`) must undo for the pair pass to find its partners in the cache.
pub fn shuffled(bed: &Scene) -> Scene {
    use rand::seq::SliceRandom;
    use rand::SeedableRng;
    let mut order: Vec<usize> = (0..bed.grains.len()).collect();
    order.shuffle(&mut rand_chacha::ChaCha8Rng::seed_from_u64(SHUFFLE_SEED));
    let mut scene = bed.clone();
    scene.grains = bed.grains.permuted(&order);
    scene
}

/// Seed of [`shuffled`]'s order.
const SHUFFLE_SEED: u64 = 14;

/// Tiles the 10^4-grain bed up to `n` grains (a multiple of 10^4 that is a product of two
/// tile counts no more than 4:1 apart, e.g. 10^5 = 5 x 2, 10^6 = 10 x 10).
pub fn bed_of(base: &Scene, n: usize) -> anyhow::Result<Scene> {
    let per = base.grains.len();
    if !n.is_multiple_of(per) {
        anyhow::bail!("bench size {n}: the bed is tiled from {per} grains; fix: give a multiple of {per}");
    }
    let copies = n / per;
    let ny = (1..=copies).filter(|d| copies.is_multiple_of(*d) && d * d <= copies).max().unwrap_or(1);
    let nx = copies / ny;
    if nx > 4 * ny.max(1) && copies > 1 {
        anyhow::bail!("bench size {n}: {copies} copies tile only as {nx} x {ny}; fix: give a size whose number of copies is close to a square (e.g. 10^5, 4 x 10^5, 10^6)");
    }
    if copies == 1 { Ok(base.clone()) } else { tile(base, nx, ny) }
}
