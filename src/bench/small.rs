//! Small scenes: steps per second of the shipped oedometers (280 and 1200 grains) and the
//! 10^4-grain bed, where a GPU step is bound by the number of dispatches it records rather
//! than by arithmetic. Each runs from its initial state (the oedometers' grains falling into
//! the cylinder, the bed settled).

use crate::engine::Engine;
use serde::Serialize;
use std::time::Instant;

/// One small-scene measurement.
#[derive(Clone, Debug, Serialize)]
pub struct SmallScene {
    /// The scene.
    pub scene: String,
    /// Grains.
    pub grains: usize,
    /// "cpu" or "gpu".
    pub backend: String,
    /// "f32" or "f64".
    pub precision: String,
    /// Steps per wall second, median over the repeats.
    pub steps_per_second: f64,
    /// Steps per second of every repeat, in order.
    pub repeats: Vec<f64>,
    /// GPU: compute dispatches recorded per step (rebuild kernels included, which run with
    /// zero workgroups on steps that keep the list).
    pub dispatches_per_step: Option<f64>,
}

/// The oedometer scenes, embedded so that the bench runs from any directory.
pub fn oedometer_scenes() -> anyhow::Result<Vec<crate::scene::Scene>> {
    [("oedometer.toml", include_str!("../../scenes/oedometer.toml")), ("oedometer_1200.toml", include_str!("../../scenes/oedometer_1200.toml"))]
        .into_iter()
        .map(|(name, text)| Ok(crate::scene::parse(std::path::Path::new(name), text)?))
        .collect()
}

/// Times `repeats` runs of `steps` steps of `engine` after `warmup` untimed ones.
pub fn measure(engine: &mut dyn Engine, scene: &str, warmup: u64, steps: u64, repeats: usize, dispatches: &dyn Fn(&dyn Engine) -> Option<u64>) -> anyhow::Result<SmallScene> {
    engine.advance(warmup)?;
    engine.stats()?;
    let mut rates = Vec::with_capacity(repeats);
    let mut per_step = None;
    for _ in 0..repeats {
        let before = dispatches(engine);
        let t = Instant::now();
        engine.advance(steps)?;
        engine.stats()?;
        rates.push(steps as f64 / t.elapsed().as_secs_f64());
        per_step = before.zip(dispatches(engine)).map(|(a, b)| (b - a) as f64 / steps as f64);
    }
    let mut sorted = rates.clone();
    sorted.sort_by(f64::total_cmp);
    Ok(SmallScene {
        scene: scene.to_string(),
        grains: engine.grain_count(),
        backend: engine.backend().to_string(),
        precision: engine.precision().to_string(),
        steps_per_second: sorted[sorted.len() / 2],
        repeats: rates,
        dispatches_per_step: per_step,
    })
}
