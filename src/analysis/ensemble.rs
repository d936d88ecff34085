//! Figures over independent samples of one scene (the same protocol from different seeds):
//! each figure's values, mean and spread, so that a reported number says how much it moves
//! from one packing to the next.

use serde::Serialize;
use serde_json::Value;

/// One figure across the samples.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Figure {
    /// What it is.
    pub name: &'static str,
    /// Its value in each sample that has it, in sample order.
    pub values: Vec<f64>,
    /// Mean over the samples.
    pub mean: f64,
    /// Sample standard deviation (0 with one sample).
    pub spread: f64,
    /// Standard error of the mean, `spread / sqrt(n)`.
    pub error: f64,
}

impl Figure {
    /// The figure of `values` (at least one).
    pub fn of(name: &'static str, values: Vec<f64>) -> Self {
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let spread = if values.len() > 1 { (values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0)).sqrt() } else { 0.0 };
        Figure { name, values, mean, spread, error: spread / n.sqrt() }
    }
}

/// How one figure is read from a finished run: its `summary.json` and `analysis.json`.
type Reader = fn(&Value, &Value) -> Option<f64>;

/// Whether a phase's largest cluster touches both faces along every axis (1) or not (0).
fn percolates(phase: &Value) -> Option<f64> {
    let spans = phase["spans"].as_array()?;
    Some(if !spans.is_empty() && spans.iter().all(|s| s.as_bool() == Some(true)) { 1.0 } else { 0.0 })
}

/// The figures gathered, in report order.
pub const FIGURES: &[(&str, Reader)] = &[
    ("bonds per grain Z", |_, a| a["coordination"]["all"].as_f64()),
    ("compressive bonds per grain", |_, a| a["coordination"]["compressive"].as_f64()),
    ("tensile bonds per grain", |_, a| a["coordination"]["tensile"].as_f64()),
    ("Z without rattlers", |_, a| a["coordination"]["without_rattlers"].as_f64()),
    ("rattler fraction", |_, a| a["coordination"]["rattlers"].as_f64()),
    ("solid fraction", |_, a| a["solid_fraction"].as_f64()),
    ("liquid bridges per grain", |s, _| Some(last_stage(s)?["stats"]["bridges"].as_f64()? / s["grains"].as_f64()?)),
    ("compressive forces below their mean", |_, a| a["below_mean"].as_f64()),
    ("compressive tail rate (beta or alpha_w)", |_, a| a["tail_compressive"]["rate"].as_f64()),
    ("its maximum-likelihood standard error", |_, a| a["tail_compressive"]["error"].as_f64()),
    ("tensile tail rate alpha_w", |_, a| a["tail_tensile"]["rate"].as_f64()),
    ("its maximum-likelihood standard error (tensile)", |_, a| a["tail_tensile"]["error"].as_f64()),
    ("positive pressure tail rate", |_, a| a["pressure_tail_positive"]["rate"].as_f64()),
    ("negative pressure tail rate", |_, a| a["pressure_tail_negative"]["rate"].as_f64()),
    ("mean pressure over p0", |_, a| Some(a["mean_pressure"].as_f64()? / a["pressure_scale"].as_f64()?)),
    ("positive phase percolates (x, y and z)", |_, a| percolates(&a["positive_phase"])),
    ("negative phase percolates (x, y and z)", |_, a| percolates(&a["negative_phase"])),
    ("fabric anisotropy", |_, a| a["fabric_anisotropy"].as_f64()),
    ("last stage settled", |s, _| Some(if last_stage(s)?["settled"].as_bool()? { 1.0 } else { 0.0 })),
    ("wall time (s)", |s, _| s["wall_seconds"].as_f64()),
];

/// The last stage's record in a summary.
fn last_stage(summary: &Value) -> Option<&Value> {
    summary["stages"].as_array()?.last()
}

/// The figures of the samples whose runs are given as `(summary, analysis)`; a figure no
/// sample has is left out.
pub fn gather(runs: &[(Value, Value)]) -> Vec<Figure> {
    FIGURES
        .iter()
        .filter_map(|&(name, read)| {
            let values: Vec<f64> = runs.iter().filter_map(|(s, a)| read(s, a)).filter(|v| v.is_finite()).collect();
            (!values.is_empty()).then(|| Figure::of(name, values))
        })
        .collect()
}

/// The figures as CSV: name, samples, mean, spread, error, then the values.
pub fn csv(figures: &[Figure]) -> String {
    let mut s = String::from("figure,samples,mean,spread,error,values\n");
    for f in figures {
        let values: Vec<String> = f.values.iter().map(|v| v.to_string()).collect();
        s.push_str(&format!("\"{}\",{},{},{},{},{}\n", f.name, f.values.len(), f.mean, f.spread, f.error, values.join(" ")));
    }
    s
}

/// A line per figure for a person: `mean +- spread (n samples)`.
pub fn human(figures: &[Figure]) -> String {
    figures.iter().map(|f| format!("  {}: {:.4} +- {:.4} over {} samples\n", f.name, f.mean, f.spread, f.values.len())).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mean, sample standard deviation and standard error against the numbers worked by hand,
    /// and figures read from two runs' reports (one without a tensile tail).
    #[test]
    fn figures_over_samples_match_the_hand_worked_numbers() {
        let f = Figure::of("x", vec![1.0, 2.0, 3.0, 4.0]);
        // Squared deviations 2.25 + 0.25 + 0.25 + 2.25 = 5, over n - 1 = 3.
        assert_eq!(f.mean, 2.5);
        assert!((f.spread - (5.0f64 / 3.0).sqrt()).abs() < 1e-15 && (f.error - f.spread / 2.0).abs() < 1e-15);
        assert_eq!(Figure::of("one", vec![7.0]).spread, 0.0);
        let run = |z: f64, tensile: Option<f64>, spans: [bool; 3]| {
            let analysis = serde_json::json!({
                "coordination": { "all": z },
                "tail_tensile": tensile.map(|r| serde_json::json!({ "rate": r })),
                "mean_pressure": 50.0, "pressure_scale": 200.0,
                "positive_phase": { "spans": spans },
            });
            (serde_json::json!({ "wall_seconds": 10.0 * z, "grains": 100, "stages": [{ "settled": true, "stats": { "bridges": 150 } }] }), analysis)
        };
        let figures = gather(&[run(4.0, Some(2.0), [true; 3]), run(6.0, None, [true, false, true])]);
        let get = |name: &str| figures.iter().find(|f| f.name.starts_with(name)).unwrap_or_else(|| panic!("{name} gathered"));
        assert_eq!(get("bonds per grain Z").values, vec![4.0, 6.0]);
        assert_eq!(get("tensile tail rate").values, vec![2.0]);
        assert_eq!(get("mean pressure over p0").mean, 0.25);
        assert_eq!(get("positive phase percolates").values, vec![1.0, 0.0]);
        assert_eq!(get("wall time").mean, 50.0);
        assert_eq!(get("liquid bridges per grain").values, vec![1.5, 1.5]);
        assert_eq!(get("last stage settled").mean, 1.0);
        assert!(figures.iter().all(|f| !f.name.starts_with("negative phase")), "a figure no sample has is left out");
    }
}
