//! The force-transmission report of a packing: `analysis.json` and its pictures.

use crate::analysis::network::{analyze, NetworkAnalysis};
use crate::analysis::sample_bounds;
use crate::engine::{Frame, Stats};
use crate::model::CohesionLaw;
use crate::periodic::Periodic;
use crate::scene::Scene;
use anyhow::Context;
use std::path::Path;

/// Analyses `frame` (taken with contacts) and writes `analysis.json`, `force_pdf`,
/// `pressure_pdf`, `force_network` and `pressure_map` (PNG and SVG) into `dir`. Plots that
/// cannot be drawn (no font) give a warning, not an error.
pub fn write(scene: &Scene, frame: &Frame, stats: &Stats, dir: &Path) -> anyhow::Result<NetworkAnalysis> {
    let f0 = match scene.model.cohesion {
        CohesionLaw::Capillary { kappa, .. } => Some(kappa * scene.grains.radius.iter().copied().fold(0.0, f64::max)),
        CohesionLaw::None => None,
    };
    let a = analyze(frame, &Periodic::of(&scene.periodic), sample_bounds(scene, stats, frame), f0);
    let path = dir.join("analysis.json");
    std::fs::write(&path, serde_json::to_string_pretty(&a)?).with_context(|| format!("cannot write {}", path.display()))?;
    let x_label = format!("normal force / ({})", a.force_scale_is);
    // Tails drawn through the density at their start.
    let density_at = |x: f64| a.force_pdf.x.iter().zip(&a.force_pdf.p).min_by(|p, q| (p.0 - x).abs().total_cmp(&(q.0 - x).abs())).map_or(1.0, |(_, p)| *p);
    let mut tails = Vec::new();
    let start = if f0.is_some() { 0.0 } else { 1.0 };
    if let Some(t) = &a.tail_compressive {
        tails.push((start, t.rate, density_at(start) * (t.rate * start).exp()));
    }
    if let Some(t) = &a.tail_tensile {
        tails.push((-0.0, t.rate, density_at(-0.01)));
    }
    let drawn = [
        crate::output::plot::pdf(&dir.join("force_pdf"), &format!("{}: normal forces", scene.name), &x_label, &a.force_pdf, &tails),
        crate::output::plot::pdf(&dir.join("pressure_pdf"), &format!("{}: particle pressures", scene.name), "particle pressure / p0 = f0 / <d>^2", &a.pressure_pdf, &[]),
        crate::output::plot::slices(&dir.join("force_network"), &dir.join("pressure_map"), &scene.name, frame, &a.pressures),
    ];
    for e in drawn.into_iter().filter_map(Result::err) {
        eprintln!("warning: {e:#}");
    }
    Ok(a)
}

/// A few lines for a person.
pub fn human(a: &NetworkAnalysis) -> String {
    let tail = |t: &Option<crate::analysis::tail::TailFit>| t.as_ref().map_or("n/a".to_string(), |t| format!("{:.2}({:.2}) from {} over {} samples", t.rate, t.error, t.threshold, t.samples));
    let span = |s: [bool; 3]| format!("x {} y {} z {}", s[0], s[1], s[2]);
    format!(
        "  forces over {} ({:.3e} N): tail compressive {}, tensile {}; {:.0}% of compressive forces below their mean\n  bonds per grain {:.2} ({:.2} compressive, {:.2} tensile); {:.2} without rattlers ({:.0}% rattlers); solid fraction {:.4}\n  mean particle pressure {:.4e} Pa (p0 = {:.4e} Pa); pressure tails over p0 {} / {}; stress diagonal {:.4e} {:.4e} {:.4e} Pa; fabric anisotropy {:.3}\n  positive-pressure phase: {} grains, {} clusters, largest {}, spans {}\n  negative-pressure phase: {} grains, {} clusters, largest {}, spans {}\n",
        a.force_scale_is,
        a.force_scale,
        tail(&a.tail_compressive),
        tail(&a.tail_tensile),
        100.0 * a.below_mean,
        a.coordination.all,
        a.coordination.compressive,
        a.coordination.tensile,
        a.coordination.without_rattlers,
        100.0 * a.coordination.rattlers,
        a.solid_fraction,
        a.mean_pressure,
        a.pressure_scale,
        tail(&a.pressure_tail_positive),
        tail(&a.pressure_tail_negative),
        a.macroscopic_stress[0][0],
        a.macroscopic_stress[1][1],
        a.macroscopic_stress[2][2],
        a.fabric_anisotropy,
        a.positive_phase.grains,
        a.positive_phase.clusters,
        a.positive_phase.largest,
        span(a.positive_phase.spans),
        a.negative_phase.grains,
        a.negative_phase.clusters,
        a.negative_phase.largest,
        span(a.negative_phase.spans),
    )
}
