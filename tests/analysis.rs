//! The force-transmission measures on configurations worked by hand: particle stresses of a
//! three-grain chain, bonds by sign, percolation of a spanning chain, the pressure scale; and
//! the maximum-likelihood tail estimator on samples of known tails.

use glam::DVec3;
use grains::analysis::contact_moments;
use grains::analysis::network::analyze;
use grains::engine::{ContactRecord, Frame};
use grains::periodic::Periodic;
use rand::{RngExt, SeedableRng};

/// Hand-worked values: round-off.
const HAND: f64 = 1e-12;

/// Three equal grains (R = 1 mm) in a row along x, 0-1-2, each pair overlapping by 1e-5 m:
/// bond 0-1 compressive (2 N), bond 1-2 tensile (-0.5 N, a capillary pull).
fn chain() -> Frame {
    let (r, h) = (1e-3, 1e-5);
    let x = |k: f64| DVec3::new(k * (2.0 * r - h), 0.0, 0.0);
    let rec = |i: u32, j: u32, f: f64| {
        // n from j to i; i is left of j, so n = -x; the force on i is f n.
        ContactRecord { i, j, overlap: h, normal_force: f, force: DVec3::new(-f, 0.0, 0.0), force_j: DVec3::new(f, 0.0, 0.0), tangential_spring: DVec3::ZERO, rolling_spring: DVec3::ZERO, bridge_volume: 0.0 }
    };
    Frame {
        time: 0.0,
        id: vec![0, 1, 2],
        position: vec![x(0.0), x(1.0), x(2.0)],
        radius: vec![r; 3],
        velocity: vec![DVec3::ZERO; 3],
        angular_velocity: vec![DVec3::ZERO; 3],
        orientation: None,
        contacts: Some(vec![rec(0, 1, 2.0), rec(1, 2, -0.5)]),
        wall_contacts: Some(vec![]),
        walls: Vec::new(),
        walls_present: Vec::new(),
    }
}

#[test]
fn particle_stresses_of_a_three_grain_chain() {
    let f = chain();
    let m = contact_moments(&f, &Periodic::default());
    let (r, h) = (1e-3, 1e-5);
    // Each contact point lies R' = R - h/2 from both centres. Bond 0-1 (n = -x from 1 to 0):
    // grain 0 is pushed by -2 N at +R', grain 1 by +2 N at -R'. Bond 1-2: grain 1 is pulled
    // by +0.5 N at +R', grain 2 by -0.5 N at -R'. So f (x) c along xx:
    let lever = r - h / 2.0;
    let m0 = -2.0 * lever;
    let m1 = 2.0 * -lever + 0.5 * lever;
    let m2 = -0.5 * -lever;
    println!("xx moments {:?}; by hand {m0:e} {m1:e} {m2:e}", m.iter().map(|t| t.x_axis.x).collect::<Vec<_>>());
    for (got, want) in m.iter().map(|t| t.x_axis.x).zip([m0, m1, m2]) {
        assert!((got - want).abs() <= HAND * want.abs().max(1e-12), "{got} vs {want}");
    }
    for t in &m {
        for b in 0..3 {
            for a in 0..3 {
                if (a, b) != (0, 0) {
                    assert_eq!(t.col(b)[a], 0.0, "a chain along x has only an xx moment");
                }
            }
        }
    }
    // Bonds by sign, pressures: grain 0 compressed (positive pressure), grain 2 in tension.
    let box_ = ([-1e-3, -1e-3, -1e-3], [5e-3, 1e-3, 1e-3]);
    let a = analyze(&f, &Periodic::default(), box_, None);
    assert_eq!((a.coordination.compressive, a.coordination.tensile), (2.0 / 3.0, 2.0 / 3.0));
    assert!(a.pressures[0] > 0.0 && a.pressures[2] < 0.0, "{:?}", a.pressures);
    // Particle pressure p_i = -tr(sigma_i)/3, sigma_i = moments / V_i, V_i = pi d^3 / (6 nu).
    let volume = 6e-3 * 2e-3 * 2e-3;
    let nu = 3.0 * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3) / volume;
    let v_i = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3) / nu;
    assert!((a.pressures[0] - (-m0 / (3.0 * v_i))).abs() <= HAND * a.pressures[0].abs());
    // The positive phase {0, 1} is linked by the compressive bond; no phase spans x (6 mm box).
    assert_eq!(a.positive_phase.clusters, 1);
    assert!(!a.positive_phase.spans[0]);
}

/// The maximum-likelihood tail is an estimate with an honest error: over many independent
/// samples drawn from a known exponential tail (unbounded, as compressive forces above the
/// mean; truncated at a bound, as tensile forces below f0, also one so steep that the bound
/// does not matter), the true rate lies within one
/// standard error of the estimate in about 68% of them and within two in about 95%; the
/// density the fit draws holds the tail's share of the samples.
#[test]
fn the_tail_estimator_recovers_a_known_rate_within_its_own_error() {
    /// Binomial spread of the coverage over 400 draws is about 2.3% (one error) and 1.1%
    /// (two); allow three times that.
    const COVERAGE: [(f64, f64); 2] = [(0.6827, 0.07), (0.9545, 0.035)];
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    for (rate, bound, threshold) in [(1.4f64, None, 1.0f64), (2.6, Some(1.0f64), 0.0), (-0.8, Some(1.0), 0.0), (1500.0, Some(1.0), 0.0)] {
        let draws = 400;
        let mut inside = [0usize; 2];
        let mut mean_error = 0.0;
        for _ in 0..draws {
            // 300 samples beyond the threshold, and as many below it that the fit must ignore.
            let values: Vec<f64> = (0..600)
                .map(|k| {
                    let u: f64 = rng.random_range(1e-12..1.0f64);
                    if k % 2 == 0 {
                        return threshold * u;
                    }
                    let y = match bound {
                        None => -u.ln() / rate,
                        // Inverse CDF of exp(-rate y) on [0, l].
                        Some(b) => {
                            let l = b - threshold;
                            -(1.0 - u * (1.0 - (-rate * l).exp())).ln() / rate
                        }
                    };
                    threshold + y
                })
                .collect();
            let fit = grains::analysis::tail::fit_tail(&values, 1.0, threshold, bound, &[]).unwrap();
            assert_eq!(fit.samples, 300);
            // The density the fit draws holds the tail's share of the samples.
            let (end, steps) = (bound.unwrap_or(f64::INFINITY).min(threshold + 40.0 / rate.abs()), 20_000);
            let h = (end - threshold) / steps as f64;
            let held: f64 = (0..steps).map(|k| fit.density_at(threshold + (k as f64 + 0.5) * h) * h).sum();
            assert!((held / fit.fraction - 1.0).abs() < 1e-6 && (fit.fraction - 0.5).abs() < 1e-12, "the fitted density holds {held} of a fraction {}", fit.fraction);
            mean_error += fit.error / draws as f64;
            for (k, n) in inside.iter_mut().enumerate() {
                *n += ((fit.rate - rate).abs() <= (k + 1) as f64 * fit.error) as usize;
            }
        }
        let coverage = inside.map(|n| n as f64 / draws as f64);
        println!("rate {rate} (bound {bound:?}): mean error {mean_error:.3}; true rate within 1 / 2 errors in {:.3} / {:.3} of {draws} draws", coverage[0], coverage[1]);
        for (c, (expect, tol)) in coverage.iter().zip(COVERAGE) {
            assert!((c - expect).abs() < tol, "coverage {c} against {expect}");
        }
    }
}

/// The particle pressures are normalised by the paper's p0 = f0 / <d>^2 (the mean-|p| view
/// kept beside it): on the three-grain chain, the PDF's variable is p / p0 exactly.
#[test]
fn pressures_are_normalised_by_f0_over_the_mean_diameter_squared() {
    let f = chain();
    let box_ = ([-1e-3, -1e-3, -1e-3], [5e-3, 1e-3, 1e-3]);
    let f0 = 0.75;
    let a = analyze(&f, &Periodic::default(), box_, Some(f0));
    let d = 2e-3;
    assert!((a.pressure_scale - f0 / (d * d)).abs() <= HAND * a.pressure_scale, "p0 = {} against f0 / d^2 = {}", a.pressure_scale, f0 / (d * d));
    let largest = a.pressures.iter().copied().fold(f64::MIN, f64::max) / a.pressure_scale;
    let top_bin = a.pressure_pdf.x.last().unwrap() + 0.5 * (a.pressure_pdf.x[1] - a.pressure_pdf.x[0]);
    assert!((top_bin - largest).abs() <= HAND * largest.abs(), "the PDF spans the pressures over p0: {top_bin} vs {largest}");
}

#[test]
fn a_tensor_is_written_and_read_as_its_rows() {
    // f (x) c has rows f[a] c: the files hold [[xx, xy, xz], ..] whatever the matrix type's
    // own order (glam's DMat3 is column-major).
    #[derive(serde::Serialize, serde::Deserialize)]
    struct Holder {
        #[serde(with = "grains::analysis::tensor_rows")]
        t: grains::analysis::Tensor,
    }
    let t = grains::analysis::outer(glam::DVec3::new(1.0, 2.0, 3.0), glam::DVec3::new(4.0, 5.0, 6.0));
    let json = serde_json::to_string(&Holder { t }).unwrap();
    assert_eq!(json, r#"{"t":[[4.0,5.0,6.0],[8.0,10.0,12.0],[12.0,15.0,18.0]]}"#);
    assert_eq!(serde_json::from_str::<Holder>(&json).unwrap().t, t);
    assert_eq!(grains::analysis::trace(&t), 4.0 + 10.0 + 18.0);
}
