//! The force-transmission report of a packing: `analysis.json` and its pictures.

use crate::analysis::network::{analyze, force_density, forces_over, mean_compressive_force, NetworkAnalysis};
use crate::analysis::richefeu;
use crate::analysis::tail::TailFit;
use crate::analysis::sample_bounds;
use crate::engine::{Frame, Stats};
use crate::model::CohesionLaw;
use crate::output::plot::{self, Density, Tail};
use crate::periodic::Periodic;
use crate::scene::Scene;
use anyhow::Context;
use std::path::Path;

/// The force-transmission analysis of `frame` (taken with contacts) of `scene`, over the
/// sample the scene's walls bound (what `analysis.json` holds).
pub fn analyze_scene(scene: &Scene, frame: &Frame, stats: &Stats) -> NetworkAnalysis {
    analyze(frame, &Periodic::of(&scene.periodic), sample_bounds(scene, stats, frame), capillary_scale(scene))
}

/// The capillary force scale `f0 = kappa R_max` (N) of a wet scene, the forces' unit there.
fn capillary_scale(scene: &Scene) -> Option<f64> {
    match scene.model.cohesion {
        CohesionLaw::Capillary { kappa, .. } => Some(kappa * scene.grains.radius.iter().copied().fold(0.0, f64::max)),
        CohesionLaw::None => None,
    }
}

/// Analyses `frame` (taken with contacts) and writes `analysis.json`, `force_pdf`,
/// `pressure_pdf`, `force_network` and `pressure_map` (PNG and SVG) into `dir`. Plots that
/// cannot be drawn (no font) give a warning, not an error.
pub fn write(scene: &Scene, frame: &Frame, stats: &Stats, dir: &Path) -> anyhow::Result<NetworkAnalysis> {
    let a = analyze_scene(scene, frame, stats);
    let f0 = capillary_scale(scene);
    let path = dir.join("analysis.json");
    std::fs::write(&path, serde_json::to_string_pretty(&a)?).with_context(|| format!("cannot write {}", path.display()))?;
    let x_label = format!("normal force / ({})", a.force_scale_is);
    let tails = force_tails(&a, f0.is_some());
    let densities = [Density { label: format!("{} (ours)", scene.name), pdf: &a.force_pdf }];
    let pressures = [Density { label: format!("{} (ours)", scene.name), pdf: &a.pressure_pdf }];
    let drawn = [
        plot::pdf(&dir.join("force_pdf"), &format!("{}: normal forces", scene.name), &x_label, &densities, &tails),
        plot::pdf(&dir.join("pressure_pdf"), &format!("{}: particle pressures", scene.name), "particle pressure / p0 = f0 / <d>^2", &pressures, &[]),
        plot::slices(&dir.join("force_network"), &dir.join("pressure_map"), &scene.name, frame, &a.pressures),
    ];
    for e in drawn.into_iter().filter_map(Result::err) {
        eprintln!("warning: {e:#}");
    }
    Ok(a)
}

/// The fitted tails of a force PDF at the densities their fits give, and the paper's (seed
/// 001: `beta` above the mean when dry, `alpha_w` on both sides of zero when wet) through the
/// same points at the thresholds.
fn force_tails(a: &NetworkAnalysis, wet: bool) -> Vec<Tail> {
    let mut tails = Vec::new();
    let sides: [(&Option<TailFit>, f64, &str); 2] = [(&a.tail_compressive, 1.0, "f > 0"), (&a.tail_tensile, -1.0, "f < 0")];
    for (k, (fit, sign, side)) in sides.into_iter().enumerate() {
        let Some(t) = fit else { continue };
        let start = sign * t.threshold;
        tails.push(Tail { start, rate: t.rate, amplitude: t.density_at(0.0), label: Some(format!("{side}: exp(-{:.2} |x|), fitted", t.rate)), published: false });
        let rate = if wet { richefeu::ALPHA_W } else { richefeu::BETA };
        // One legend entry for the paper's lines.
        let label = (k == 0).then(|| format!("exp(-{rate} |x|), Richefeu et al. (2009)"));
        tails.push(Tail { start, rate, amplitude: t.density_at(t.threshold) * (rate * t.threshold).exp(), label, published: true });
    }
    tails
}

/// This run's force PDF beside `other`'s (its scene and frame, taken with contacts), as
/// `force_pdf_beside.png` and `.svg` in `dir`. Two dry packings (Richefeu et al.'s Figs. 2-3: MD
/// beside CD, isotropic beside anisotropic) are each over their own mean force, which compares
/// the shapes; otherwise both are over this run's force scale (Fig. 7: wet and dry over the
/// wet run's `f0`).
pub fn write_beside(scene: &Scene, a: &NetworkAnalysis, other_scene: &Scene, other: &Frame, dir: &Path) -> anyhow::Result<()> {
    let wet = scene.model.cohesion != CohesionLaw::None;
    let each_own = !wet && other_scene.model.cohesion == CohesionLaw::None;
    let other_scale = if each_own { mean_compressive_force(other) } else { a.force_scale };
    let theirs = force_density(&forces_over(other, other_scale));
    let densities = [Density { label: scene.name.clone(), pdf: &a.force_pdf }, Density { label: other_scene.name.clone(), pdf: &theirs }];
    let tails: Vec<Tail> = force_tails(a, wet).into_iter().filter(|t| !t.published).collect();
    let axis = if each_own { "normal force / (mean force of each)".to_string() } else { format!("normal force / ({} of {})", a.force_scale_is, scene.name) };
    plot::pdf(&dir.join("force_pdf_beside"), &format!("{} and {}: normal forces", scene.name, other_scene.name), &axis, &densities, &tails)
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
        a.macroscopic_stress.x_axis.x,
        a.macroscopic_stress.y_axis.y,
        a.macroscopic_stress.z_axis.z,
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
