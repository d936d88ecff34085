//! Bauer's law fitted by Levenberg-Marquardt (Oquendo et al. eq. 19): synthetic data with known
//! parameters and noise, the paper's experimental parameters over an oedometer's pressure
//! range, and the power law across runs.

use grains::analysis::fit::{fit_bauer, fit_power_law};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A fitted parameter must lie within this many standard errors of the truth: the 99%
/// two-sided quantile of Student's t with 9 - 3 = 6 degrees of freedom (the standard errors
/// come from the residuals of 9 points).
const SIGMAS: f64 = 3.707;
/// Without noise, the fit returns the truth to this relative precision.
const EXACT: f64 = 1e-7;

/// Pressures of an oedometer run: 12.5 kPa doubled 8 times (to 3.2 MPa).
fn pressures() -> Vec<f64> {
    (0..9).map(|k| 12.5e3 * 2f64.powi(k)).collect()
}

/// Box-Muller normal deviate.
fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let (u, v): (f64, f64) = (rng.random_range(1e-12..1.0), rng.random_range(0.0..1.0));
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

fn curve(e0: f64, h_s: f64, eta: f64, noise: f64, seed: u64) -> Vec<(f64, f64)> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    pressures().into_iter().map(|p| (p, e0 * (-(p / h_s).powf(eta)).exp() + noise * normal(&mut rng))).collect()
}

#[test]
fn noise_free_data_give_back_the_parameters() {
    let fit = fit_bauer(&curve(0.72, 19.1e6, 0.57, 0.0, 0), None, 1.0).unwrap();
    println!("{}", fit.line());
    assert!((fit.h_s.value / 19.1e6 - 1.0).abs() < EXACT);
    assert!((fit.eta.value / 0.57 - 1.0).abs() < EXACT);
    assert!((fit.e0.value / 0.72 - 1.0).abs() < EXACT);
}

#[test]
fn noisy_data_are_recovered_within_their_errors() {
    // The paper's Guamo sand (h_s = 19.1 MPa, eta = 0.57) and a stiff simulated sand of
    // Table 2 (h_s ~ 1 GPa, eta ~ 0.3), with void-ratio noise of 1e-3.
    let mut within = 0;
    let mut total = 0;
    for (e0, h_s, eta) in [(0.72, 19.1e6, 0.57), (0.65, 1.0e9, 0.30)] {
        for seed in 1..=20 {
            let fit = fit_bauer(&curve(e0, h_s, eta, 1e-3, seed), None, 1.0).unwrap();
            // h_s is fitted as ln h_s, whose error is h_s's relative error.
            let deviations = [(fit.h_s.value / h_s).ln().abs() / (fit.h_s.error / fit.h_s.value), (fit.eta.value - eta).abs() / fit.eta.error, (fit.e0.value - e0).abs() / fit.e0.error];
            for d in deviations {
                total += 1;
                if d <= SIGMAS {
                    within += 1;
                } else {
                    println!("seed {seed}: {d:.2} standard errors off ({})", fit.line());
                }
            }
            if seed == 1 {
                println!("truth h_s = {:.3e}, eta = {eta}, e0 = {e0}: {}", h_s, fit.line());
            }
        }
    }
    println!("{within} of {total} estimates within {SIGMAS} standard errors");
    // 99% expected; the 120 estimates come from 40 fits, so allow a few more misses.
    assert!(within as f64 >= 0.95 * total as f64);
}

#[test]
fn fixing_e0_fits_two_parameters_and_the_mean_stress_form_scales_h_s_by_three() {
    let data = curve(0.72, 19.1e6, 0.57, 0.0, 0);
    let fixed = fit_bauer(&data, Some(0.72), 1.0).unwrap();
    assert!((fixed.h_s.value / 19.1e6 - 1.0).abs() < EXACT);
    let mean = fit_bauer(&data, None, 3.0).unwrap();
    println!("mean-stress form: {}", mean.line());
    assert!((mean.h_s.value / (3.0 * 19.1e6) - 1.0).abs() < EXACT);
    assert!((mean.eta.value / 0.57 - 1.0).abs() < EXACT);
}

#[test]
fn too_few_or_bad_points_are_errors() {
    assert!(fit_bauer(&[(1e4, 0.7), (2e4, 0.69)], None, 1.0).is_err());
    assert!(fit_bauer(&[(1e4, 0.7), (2e4, -0.1), (4e4, 0.6), (8e4, 0.5)], None, 1.0).is_err());
}

#[test]
fn the_power_law_across_runs_recovers_the_papers_figure_5() {
    // h_s = 0.068 eta^-9.88 (MPa), the paper's fit, sampled at its eta range with 5% scatter.
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let pts: Vec<(f64, f64)> = [0.19, 0.2, 0.23, 0.24, 0.26, 0.27, 0.29, 0.3, 0.32, 0.4].iter().map(|&eta: &f64| (eta, 0.068 * eta.powf(-9.88) * (1.0 + 0.05 * normal(&mut rng)))).collect();
    let law = fit_power_law(&pts).unwrap();
    println!("a = {} MPa, b = {}", law.a.concise(), law.b.concise());
    // Ten points, two parameters: 8 degrees of freedom, 99% t quantile 3.355.
    assert!((law.b.value - -9.88).abs() <= 3.355 * law.b.error);
    assert!((law.a.value / 0.068).ln().abs() <= 3.355 * law.a.error / law.a.value);
}

#[test]
fn an_e0_profile_passes_through_the_truth_and_trades_h_s_against_eta() {
    use grains::analysis::fit::{e0_profile, profile_e0s};
    let data = curve(0.72, 19.1e6, 0.57, 0.0, 0);
    let mut e0s = profile_e0s(&data, 0.8, 12);
    e0s.push(0.72);
    e0s.sort_by(f64::total_cmp);
    let profile = e0_profile(&data, &e0s, 1.0);
    assert_eq!(profile.points.len(), e0s.len(), "every e0 above the largest e fits");
    let truth = profile.points.iter().find(|p| p.e0 == 0.72).unwrap();
    assert!((truth.h_s / 19.1e6 - 1.0).abs() < EXACT && (truth.eta / 0.57 - 1.0).abs() < EXACT, "{truth:?}");
    // A larger e0 reads the same curve as a harder, flatter law.
    for w in profile.points.windows(2) {
        assert!(w[1].h_s > w[0].h_s && w[1].eta < w[0].eta, "{w:?}");
    }
    let law = profile.power_law.unwrap();
    println!("along the profile: h_s = {} eta^{} MPa", law.a.concise(), law.b.concise());
    assert!(law.b.value < -1.0);
}

#[test]
fn the_free_fit_reports_how_its_parameters_are_correlated() {
    let fit = fit_bauer(&curve(0.72, 19.1e6, 0.57, 1e-4, 3), None, 1.0).unwrap();
    let c = fit.correlations;
    println!("ln h_s-eta {:.3}, ln h_s-e0 {:?}, eta-e0 {:?}", c.ln_h_s_eta, c.ln_h_s_e0, c.eta_e0);
    for r in [c.ln_h_s_eta, c.ln_h_s_e0.unwrap(), c.eta_e0.unwrap()] {
        assert!(r.abs() <= 1.0 + 1e-12);
    }
    // A harder sample (larger h_s) fits the same points with a smaller eta.
    assert!(c.ln_h_s_eta < -0.5);
    assert!(fit_bauer(&curve(0.72, 19.1e6, 0.57, 1e-4, 3), Some(0.72), 1.0).unwrap().correlations.ln_h_s_e0.is_none());
}

/// `grains fit bauer` on a compression CSV: e0 free or held, and the mean-stress form taking
/// 3p from the measured trace of the stress, not three times the vertical stress.
#[test]
fn fit_bauer_holds_or_frees_e0_and_takes_the_mean_stress_from_the_trace() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("compression.csv");
    let mut csv = String::from("pressure_Pa,stress_trace_Pa,void_ratio\n");
    for p in pressures() {
        // A settled oedometer: the trace of the stress is about twice the vertical stress.
        let trace = 2.0 * p;
        csv.push_str(&format!("{p},{trace},{}\n", 0.72 * (-(trace / 19.1e6f64).powf(0.57)).exp()));
    }
    std::fs::write(&path, csv).unwrap();
    let run = |args: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_grains")).args(["fit", "bauer", path.to_str().unwrap()]).args(args).output().unwrap();
        (o.status.code(), String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
    };
    let (code, out, err) = run(&["--mean-stress"]);
    println!("{out}{err}");
    assert_eq!(code, Some(0), "{err}");
    assert!(out.starts_with("h_s = 19.1") && out.contains("eta = 0.57"), "the trace is 3p: {out}");
    let (_, out, _) = run(&["--e0", "0.72"]);
    assert!(out.contains("e0 = 0.7200 (measured)"), "{out}");
    let (_, out, _) = run(&["--e0", "free", "--profile"]);
    assert!(out.contains("e0 held at") && out.contains("along the profile"), "{out}");
    let (code, _, err) = run(&["--e0", "loose"]);
    assert_eq!(code, Some(2), "clap refuses the value");
    assert!(err.contains("`loose`") && err.contains("fix:"), "{err}");
}
