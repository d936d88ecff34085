//! The force-transmission measures on configurations worked by hand: particle stresses of a
//! three-grain chain, bonds by sign, percolation of a spanning chain, and the exponential tail
//! of a sampled distribution.

use grains::analysis::contact_moments;
use grains::analysis::network::{analyze, Pdf};
use grains::engine::{ContactRecord, Frame};
use grains::periodic::Periodic;
use rand::{RngExt, SeedableRng};

/// Hand-worked values: round-off.
const HAND: f64 = 1e-12;

/// Three equal grains (R = 1 mm) in a row along x, 0-1-2, each pair overlapping by 1e-5 m:
/// bond 0-1 compressive (2 N), bond 1-2 tensile (-0.5 N, a capillary pull).
fn chain() -> Frame {
    let (r, h) = (1e-3, 1e-5);
    let x = |k: f64| [k * (2.0 * r - h), 0.0, 0.0];
    let rec = |i: u32, j: u32, f: f64| {
        // n from j to i; i is left of j, so n = -x; the force on i is f n.
        ContactRecord { i, j, overlap: h, normal_force: f, force: [-f, 0.0, 0.0], force_j: [f, 0.0, 0.0], tangential_spring: [0.0; 3], rolling_spring: [0.0; 3] }
    };
    Frame {
        time: 0.0,
        id: vec![0, 1, 2],
        position: vec![x(0.0), x(1.0), x(2.0)],
        radius: vec![r; 3],
        velocity: vec![[0.0; 3]; 3],
        angular_velocity: vec![[0.0; 3]; 3],
        orientation: None,
        contacts: Some(vec![rec(0, 1, 2.0), rec(1, 2, -0.5)]),
        wall_contacts: Some(vec![]),
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
    println!("xx moments {:?}; by hand {m0:e} {m1:e} {m2:e}", m.iter().map(|t| t[0][0]).collect::<Vec<_>>());
    for (got, want) in m.iter().map(|t| t[0][0]).zip([m0, m1, m2]) {
        assert!((got - want).abs() <= HAND * want.abs().max(1e-12), "{got} vs {want}");
    }
    for t in &m {
        for (a, row) in t.iter().enumerate() {
            for (b, x) in row.iter().enumerate() {
                if (a, b) != (0, 0) {
                    assert_eq!(*x, 0.0, "a chain along x has only an xx moment");
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

#[test]
fn the_exponential_tail_of_a_sampled_distribution_is_recovered() {
    // Forces drawn from P(f) = beta exp(-beta f / <f>) / <f> with beta = 1.4 above the mean.
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let samples: Vec<f64> = (0..200_000).map(|_| -rng.random_range(1e-12..1.0f64).ln() / 1.4).collect();
    let pdf = Pdf::of(&samples, 0.0, 5.0, 40);
    let beta = pdf.exponential_tail(1.0, 1.0).unwrap();
    println!("beta recovered {beta:.4} (1.4)");
    assert!((beta - 1.4).abs() < 0.05);
}
