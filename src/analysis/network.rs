//! Force transmission in a packing (Richefeu et al. (2009)): normal-force statistics with their exponential
//! tails, bonds counted by sign, particle stresses and pressures, the macroscopic stress, the
//! bi-percolation of the positive- and negative-pressure phases, and the fabric anisotropy.

use super::tail::{fit_tail, TailFit};
use super::{contact_moments, outer, trace, Tensor};
use glam::DMat3;
use crate::engine::Frame;
use crate::periodic::Periodic;
use serde::Serialize;

/// Histogram bins of the force and pressure PDFs.
pub const PDF_BINS: usize = 40;
/// Where the dry force tail starts (over the mean force), and the other starts its
/// sensitivity is reported at.
pub const DRY_TAIL_FROM: (f64, [f64; 3]) = (1.0, [0.5, 1.5, 2.0]);
/// Where the wet force tails start (over f0, on each side of zero), and the other starts.
pub const WET_TAIL_FROM: (f64, [f64; 3]) = (0.0, [0.1, 0.2, 0.3]);

/// A probability density on regular bins.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Pdf {
    /// Bin centres (in the normalised variable).
    pub x: Vec<f64>,
    /// Density per unit of the variable.
    pub p: Vec<f64>,
}

impl Pdf {
    /// The density of `values` on `bins` bins over `[lo, hi]`.
    pub fn of(values: &[f64], lo: f64, hi: f64, bins: usize) -> Self {
        let w = (hi - lo) / bins as f64;
        let mut counts = vec![0usize; bins];
        for &v in values {
            if v >= lo && v <= hi {
                counts[(((v - lo) / w) as usize).min(bins - 1)] += 1;
            }
        }
        let n = values.len().max(1) as f64;
        Pdf { x: (0..bins).map(|k| lo + (k as f64 + 0.5) * w).collect(), p: counts.iter().map(|&c| c as f64 / (n * w)).collect() }
    }
}

/// Bonds (pairs exerting a force) per grain.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Coordination {
    /// All bonds: `2 bonds / N`.
    pub all: f64,
    /// Compressive bonds (total normal force > 0).
    pub compressive: f64,
    /// Tensile bonds (total normal force < 0).
    pub tensile: f64,
    /// All bonds per grain among grains with at least 2 bonds (rattlers left out).
    pub without_rattlers: f64,
    /// Fraction of grains with fewer than 2 bonds.
    pub rattlers: f64,
}

/// Whether a phase spans the sample along each axis.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Percolation {
    /// Grains in the phase.
    pub grains: usize,
    /// Clusters of the phase over the bond network.
    pub clusters: usize,
    /// Grains in its largest cluster.
    pub largest: usize,
    /// Whether some cluster touches both faces of the sample along x, y, z.
    pub spans: [bool; 3],
}

/// Everything `grains analyze` reports on a packing.
#[derive(Clone, Debug, Serialize)]
pub struct NetworkAnalysis {
    /// Simulated time of the frame (s).
    pub time: f64,
    /// The force scale: the mean compressive force (dry) or `f0 = kappa R_max` (wet) (N).
    pub force_scale: f64,
    /// "mean force" or "f0 = kappa R_max".
    pub force_scale_is: String,
    /// PDF of the normal forces over the force scale.
    pub force_pdf: Pdf,
    /// Dry: `beta` of `exp(-beta f/<f>)` above the mean. Wet: `alpha_w` of the compressive side
    /// from zero. Maximum likelihood, with its error.
    pub tail_compressive: Option<TailFit>,
    /// Wet: `alpha_w` of the tensile side (bounded by f0).
    pub tail_tensile: Option<TailFit>,
    /// Fraction of compressive forces below their mean.
    pub below_mean: f64,
    /// Bonds per grain.
    pub coordination: Coordination,
    /// Solid fraction of the sample.
    pub solid_fraction: f64,
    /// Volume-weighted particle stress over the sample (Pa, compression positive).
    #[serde(with = "super::tensor_rows")]
    pub macroscopic_stress: Tensor,
    /// Mean particle pressure over the sample (Pa, compression positive).
    pub mean_pressure: f64,
    /// The pressure scale `p0 = f0 / <d>^2` (wet; the force scale over `<d>^2` when dry) (Pa).
    pub pressure_scale: f64,
    /// PDF of the particle pressures over `p0`.
    pub pressure_pdf: Pdf,
    /// PDF of the particle pressures over their mean absolute value (the earlier view).
    pub pressure_pdf_mean_abs: Pdf,
    /// Exponential tails of the pressures over `p0`, from zero: positive side.
    pub pressure_tail_positive: Option<TailFit>,
    /// Negative side.
    pub pressure_tail_negative: Option<TailFit>,
    /// Grains of positive and of negative pressure as two phases over the bond network.
    pub positive_phase: Percolation,
    /// The negative-pressure phase.
    pub negative_phase: Percolation,
    /// Fabric tensor `<n (x) n>` over the bonds.
    #[serde(with = "super::tensor_rows")]
    pub fabric: Tensor,
    /// Axisymmetric fabric anisotropy about z, `5 (F_zz - (F_xx + F_yy)/2)`.
    pub fabric_anisotropy: f64,
    /// Particle pressure of each grain (Pa, compression positive), by slot.
    #[serde(skip)]
    pub pressures: Vec<f64>,
}

/// The nonzero normal forces of a frame's bonds over `scale` (N).
pub fn forces_over(frame: &Frame, scale: f64) -> Vec<f64> {
    frame.contacts.as_deref().unwrap_or(&[]).iter().map(|c| c.normal_force).filter(|f| *f != 0.0).map(|f| f / scale.max(1e-300)).collect()
}

/// The mean of a frame's compressive normal forces (N; 0 without any).
pub fn mean_compressive_force(frame: &Frame) -> f64 {
    let compressive: Vec<f64> = forces_over(frame, 1.0).into_iter().filter(|f| *f > 0.0).collect();
    compressive.iter().sum::<f64>() / compressive.len().max(1) as f64
}

/// The PDF of normalised forces, on [`PDF_BINS`] bins from the most tensile (or 0) to the
/// largest (or 1).
pub fn force_density(normalised: &[f64]) -> Pdf {
    let hi = normalised.iter().copied().fold(0.0, f64::max).max(1.0);
    let lo = normalised.iter().copied().fold(0.0, f64::min);
    Pdf::of(normalised, lo, hi, PDF_BINS)
}

/// The sample's box: lower and upper corners (m).
pub type Bounds = ([f64; 3], [f64; 3]);

/// The grains' particle stresses in a sample.
pub struct ParticleStresses {
    /// Each grain's sum of force (x) contact vector over its contacts (N m).
    pub moments: Vec<Tensor>,
    /// The sample's volume (m^3).
    pub volume: f64,
    /// Solid fraction of the sample (-).
    pub solid_fraction: f64,
    /// Each grain's pressure (Pa, compression positive): `-tr(sigma_i) / 3`, with
    /// `sigma_i = moments_i / V_i` over the free volume `V_i = pi d^3 / (6 nu)`.
    pub pressures: Vec<f64>,
}

/// Particle stresses of a frame taken with contacts, in the sample box `bounds`.
pub fn particle_stresses(frame: &Frame, periodic: &Periodic<f64>, bounds: Bounds) -> ParticleStresses {
    let (lo, hi) = bounds;
    let volume: f64 = (0..3).map(|a| hi[a] - lo[a]).product();
    let ball = |r: f64| 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
    let solid_fraction = frame.radius.iter().map(|&r| ball(r)).sum::<f64>() / volume;
    let moments = contact_moments(frame, periodic);
    let pressures = moments.iter().zip(&frame.radius).map(|(m, &r)| -trace(m) / (3.0 * (ball(r) / solid_fraction))).collect();
    ParticleStresses { moments, volume, solid_fraction, pressures }
}

/// Analyses a frame taken with contacts. `f0` is the largest capillary force `kappa R_max` of
/// a wet packing (forces are then normalised by it), `None` for a dry one; `bounds` is the
/// sample's box.
pub fn analyze(frame: &Frame, periodic: &Periodic<f64>, bounds: Bounds, f0: Option<f64>) -> NetworkAnalysis {
    let n = frame.radius.len();
    let contacts = frame.contacts.as_deref().unwrap_or(&[]);
    let forces = forces_over(frame, 1.0);
    let compressive: Vec<f64> = forces.iter().copied().filter(|f| *f > 0.0).collect();
    let mean_c = mean_compressive_force(frame);
    let (scale, scale_is) = match f0 {
        Some(f0) => (f0, "f0 = kappa R_max"),
        None => (mean_c, "mean force"),
    };
    let normalised = forces_over(frame, scale);
    let force_pdf = force_density(&normalised);
    let (tail_compressive, tail_tensile) = match f0 {
        // Tensile forces never exceed f0: that side is bounded at 1.
        Some(_) => (fit_tail(&normalised, 1.0, WET_TAIL_FROM.0, None, &WET_TAIL_FROM.1), fit_tail(&normalised, -1.0, WET_TAIL_FROM.0, Some(1.0), &WET_TAIL_FROM.1)),
        None => (fit_tail(&normalised, 1.0, DRY_TAIL_FROM.0, None, &DRY_TAIL_FROM.1), None),
    };
    let below_mean = compressive.iter().filter(|f| **f < mean_c).count() as f64 / compressive.len().max(1) as f64;

    // Bonds per grain, by sign.
    let mut bonds = vec![0usize; n];
    let (mut n_comp, mut n_tens) = (0usize, 0usize);
    for c in contacts.iter().filter(|c| c.normal_force != 0.0) {
        bonds[c.i as usize] += 1;
        bonds[c.j as usize] += 1;
        if c.normal_force > 0.0 { n_comp += 1 } else { n_tens += 1 }
    }
    let rattlers = bonds.iter().filter(|b| **b < 2).count();
    let kept: usize = bonds.iter().filter(|b| **b >= 2).sum();
    let coordination = Coordination {
        all: 2.0 * (n_comp + n_tens) as f64 / n as f64,
        compressive: 2.0 * n_comp as f64 / n as f64,
        tensile: 2.0 * n_tens as f64 / n as f64,
        without_rattlers: kept as f64 / (n - rattlers).max(1) as f64,
        rattlers: rattlers as f64 / n as f64,
    };

    let ParticleStresses { moments, volume, solid_fraction: nu, pressures } = particle_stresses(frame, periodic, bounds);
    let mut macro_stress = DMat3::ZERO;
    for m in &moments {
        macro_stress -= *m / volume;
    }
    let mean_pressure = trace(&macro_stress) / 3.0;
    let d_mean = 2.0 * frame.radius.iter().sum::<f64>() / n.max(1) as f64;
    let pressure_scale = scale / (d_mean * d_mean);
    let pdf_over = |s: f64| {
        let x: Vec<f64> = pressures.iter().map(|p| p / s.max(1e-300)).collect();
        (Pdf::of(&x, x.iter().copied().fold(0.0, f64::min), x.iter().copied().fold(0.0, f64::max).max(1e-12), PDF_BINS), x)
    };
    let (pressure_pdf, p_norm) = pdf_over(pressure_scale);
    let (pressure_pdf_mean_abs, _) = pdf_over(pressures.iter().map(|p| p.abs()).sum::<f64>() / n.max(1) as f64);
    let pressure_tail = |sign: f64| fit_tail(&p_norm, sign, 0.0, None, &[]);

    // Fabric over the bonds.
    let mut fabric = DMat3::ZERO;
    let mut n_bonds = 0.0f64;
    for c in contacts.iter().filter(|c| c.normal_force != 0.0) {
        let u = super::contact_normal(frame, periodic, c).f64();
        fabric += outer(u, u);
        n_bonds += 1.0;
    }
    fabric /= n_bonds.max(1.0);
    let phase = |positive: bool| percolation(frame, contacts, &pressures, positive, bounds, d_mean);
    NetworkAnalysis {
        time: frame.time,
        force_scale: scale,
        force_scale_is: scale_is.to_string(),
        force_pdf,
        tail_compressive,
        tail_tensile,
        below_mean,
        coordination,
        solid_fraction: nu,
        macroscopic_stress: macro_stress,
        mean_pressure,
        pressure_scale,
        pressure_pdf,
        pressure_pdf_mean_abs,
        pressure_tail_positive: pressure_tail(1.0),
        pressure_tail_negative: pressure_tail(-1.0),
        positive_phase: phase(true),
        negative_phase: phase(false),
        fabric_anisotropy: 5.0 * (fabric.z_axis.z - 0.5 * (fabric.x_axis.x + fabric.y_axis.y)),
        fabric,
        pressures,
    }
}

/// Clusters of the grains of one pressure sign linked by bonds; a cluster spans an axis when
/// it holds grains within a mean diameter of both faces of the sample.
fn percolation(frame: &Frame, contacts: &[crate::engine::ContactRecord], pressures: &[f64], positive: bool, bounds: Bounds, d_mean: f64) -> Percolation {
    let n = pressures.len();
    let member: Vec<bool> = pressures.iter().map(|p| if positive { *p > 0.0 } else { *p < 0.0 }).collect();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for c in contacts.iter().filter(|c| c.normal_force != 0.0) {
        let (i, j) = (c.i as usize, c.j as usize);
        if member[i] && member[j] {
            let (a, b) = (root(&mut parent, i), root(&mut parent, j));
            if a != b {
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    let mut size = vec![0usize; n];
    let mut lo = vec![[f64::INFINITY; 3]; n];
    let mut hi = vec![[f64::NEG_INFINITY; 3]; n];
    for i in (0..n).filter(|&i| member[i]) {
        let r = root(&mut parent, i);
        size[r] += 1;
        for a in 0..3 {
            lo[r][a] = lo[r][a].min(frame.position[i][a] - frame.radius[i]);
            hi[r][a] = hi[r][a].max(frame.position[i][a] + frame.radius[i]);
        }
    }
    let roots: Vec<usize> = (0..n).filter(|&r| size[r] > 0).collect();
    let mut spans = [false; 3];
    for &r in &roots {
        for a in 0..3 {
            spans[a] |= lo[r][a] <= bounds.0[a] + d_mean && hi[r][a] >= bounds.1[a] - d_mean;
        }
    }
    Percolation { grains: member.iter().filter(|m| **m).count(), clusters: roots.len(), largest: roots.iter().map(|&r| size[r]).max().unwrap_or(0), spans }
}
