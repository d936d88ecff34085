//! Throughput where grain sizes differ, beside the bench bed: two beds poured by the bench
//! bed's recipe (10^4 grains poured onto a floor, periodic in x-y, the peers' step and skin),
//! one with a few grains ten times the others' diameter among the bed's grains, one with
//! diameters spread evenly over a factor of ten. Each bed, the bench bed included, runs as
//! poured (static: the list is hardly ever rebuilt) and stirred (every grain given 1 m/s in a
//! random direction, so that the list is rebuilt every few dozen steps): particle-steps per
//! second, and what each rebuild costs per grain.

use super::bed::{self, BedInfo, BED_SCENE};
use super::throughput::Throughput;
use super::{measure_scene, pool, BenchOptions, Config};
use crate::scene::Scene;
use anyhow::Context;
use rand::SeedableRng;
use std::path::Path;

/// One mixed bed: its name, footprint (m, square, periodic), insertion column's height (m),
/// pour duration (s) and `[[generate]]` blocks (count and diameters of each).
struct Mixed {
    name: &'static str,
    footprint: f64,
    column: f64,
    duration: f64,
    grains: &'static [(u64, f64, f64)],
}

/// The mixed beds: 5 grains of 10 mm among 9,995 of the bed's 0.85-1.15 mm, and 10,000
/// diameters uniform over 0.85-8.5 mm (the bed's smallest, so that the peers' step stays
/// stable). Random insertion fills their columns to 28% and 19% of their volume (the bench
/// bed's, 28%; a wide spread jams sooner); the spread's column is low and wide, because its
/// 8.5 mm grains falling from 0.3 m pressed 0.85 mm ones past the overlap limit.
const MIXED: [Mixed; 2] = [
    Mixed { name: "large_among_small", footprint: 25.0e-3, column: 46.0e-3, duration: 0.3, grains: &[(5, 10.0e-3, 10.0e-3), (9995, 0.85e-3, 1.15e-3)] },
    Mixed { name: "ratio_10_spread", footprint: 240.0e-3, column: 80.0e-3, duration: 0.3, grains: &[(10_000, 0.85e-3, 8.5e-3)] },
];

/// Speed of the stirred runs' grains (m/s).
const STIR_SPEED: f64 = 1.0;
/// Seed of the stirred runs' directions.
const STIR_SEED: u64 = 46;
/// What a stirred bed's name ends with.
pub const STIRRED: &str = ", stirred";

/// The scene text of a mixed bed: the bench bed's, with its name, footprint, grains and pour
/// duration.
fn scene_text(m: &Mixed) -> anyhow::Result<String> {
    let mut doc: toml::Table = toml::from_str(BED_SCENE).context("the bench bed's scene")?;
    doc.insert("name".into(), m.name.into());
    doc.insert("description".into(), format!("{} (grains bench, mixed sizes)", m.name).into());
    let axis = || toml::Value::Array(vec![0.0.into(), m.footprint.into()]);
    doc.insert("periodic".into(), toml::Value::Table(toml::Table::from_iter([("x".to_string(), axis()), ("y".to_string(), axis())])));
    let generate: Vec<toml::Value> = m
        .grains
        .iter()
        .map(|&(count, lo, hi)| {
            toml::Value::Table(
                toml::from_str(&format!(
                    "material = \"sand\"\ncount = {count}\ndiameter = {{ min = {lo:e}, max = {hi:e} }}\nregion = {{ shape = \"box\", min = [0.0, 0.0, 0.6e-3], max = [{f:e}, {f:e}, {c:e}] }}\n",
                    f = m.footprint,
                    c = m.column
                ))
                .expect("a generate block"),
            )
        })
        .collect();
    doc.insert("generate".into(), toml::Value::Array(generate));
    let stages = doc.get_mut("stage").and_then(|s| s.as_array_mut()).context("the bench bed's scene has a stage")?;
    stages[0].as_table_mut().context("a stage")?.insert("duration".into(), m.duration.into());
    Ok(toml::to_string(&doc)?)
}

/// The beds, poured once and cached in `cache` ([`bed::settled`]): the bench bed first (the
/// others are compared with it), then the mixed ones.
pub fn beds(cache: &Path, progress: bool) -> anyhow::Result<Vec<(Scene, BedInfo)>> {
    let mut beds = vec![bed::settled_bed(cache, progress)?];
    for m in &MIXED {
        beds.push(bed::settled(Path::new(&format!("bench/mixed/{}.toml", m.name)), &scene_text(m)?, cache, progress)?);
    }
    Ok(beds)
}

/// `scene` with every grain moving at [`STIR_SPEED`] in a random direction (seeded).
pub fn stirred(scene: &Scene) -> Scene {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(STIR_SEED);
    let mut out = scene.clone();
    for v in &mut out.grains.velocity {
        *v = glam::DVec3::from(crate::scene::random_direction(&mut rng)) * STIR_SPEED;
    }
    out.name = format!("{}{STIRRED}", scene.name);
    out
}

/// Throughput on each bed, poured and stirred, for every backend, CPU precision and thread
/// count of `opts` (the CPU renumbering in cell order at the scene's default).
pub fn run(opts: &BenchOptions, cpu: &str, say: &dyn Fn(&str)) -> anyhow::Result<Vec<Throughput>> {
    let mut rows = Vec::new();
    for (poured, _) in pool(0)?.install(|| beds(&opts.cache, opts.progress))? {
        let steps = ((opts.work / poured.grains.len() as f64).round() as u64).max(20);
        let warmup = (steps / 5).max(10);
        for scene in [poured.clone(), stirred(&poured)] {
            for backend in &opts.backends {
                let configs: Vec<Config> = if backend == "gpu" {
                    vec![Config::gpu()]
                } else {
                    opts.precisions.iter().flat_map(|p| opts.threads.iter().map(move |&t| Config { backend: "cpu".into(), precision: p.clone(), threads: t, busy: 0 })).collect()
                };
                for config in configs {
                    say(&format!("mixed sizes: {} on {backend} {}, {} thread(s): {warmup} + {} x {steps} steps", scene.name, config.precision, config.threads, opts.repeats));
                    let row = measure_scene(opts, cpu, &scene, &config, warmup, steps)?;
                    let rebuild = row.rebuild_ns_per_grain.map_or(String::new(), |ns| format!(", rebuild {ns:.0} ns a grain"));
                    say(&format!("  {:.3e} particle-steps/s, Z = {:.2}, {} rebuilds{rebuild}", row.particle_steps_per_second, row.contacts_per_grain, row.rebuilds));
                    rows.push(Throughput { scene: scene.name.clone(), ..row });
                }
            }
        }
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mixed beds are what their names say before the pour: 10,000 grains each, five of
    /// them ten times the others' mean diameter in one, and diameters covering a factor of ten
    /// (within 5%) with as many below the middle diameter as above it (within 5%) in the
    /// other; the bench bed's step and skin.
    #[test]
    fn the_mixed_beds_hold_what_they_are_named_for() {
        let scenes: Vec<Scene> = MIXED.iter().map(|m| crate::scene::parse(Path::new(m.name), &scene_text(m).unwrap()).unwrap()).collect();
        for s in &scenes {
            assert_eq!(s.grains.len(), 10_000, "{}", s.name);
            assert_eq!(s.skin, 1.0e-4, "{}", s.name);
        }
        let d = |s: &Scene| s.grains.radius.iter().map(|r| 2.0 * r).collect::<Vec<f64>>();
        let large = d(&scenes[0]).iter().filter(|&&x| x == 10.0e-3).count();
        assert_eq!(large, 5);
        let spread = d(&scenes[1]);
        let (lo, hi) = spread.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &x| (lo.min(x), hi.max(x)));
        assert!((hi / lo / 10.0 - 1.0).abs() < 0.05, "{}", hi / lo);
        let below = spread.iter().filter(|&&x| x < 0.5 * (0.85e-3 + 8.5e-3)).count() as f64;
        assert!((below / 1e4 - 0.5).abs() < 0.05, "{below}");
    }
}
