//! Exponential tails of a distribution by maximum likelihood: the decay rate `a` of
//! `P(x) ~ exp(-a |x|)` beyond a threshold, with its standard error, from the samples
//! themselves (the binned PDF is for pictures only). On a bounded side (the tensile forces
//! of a wet packing never exceed `f0`) the tail is a truncated exponential.

use serde::Serialize;

/// Fewer samples beyond the threshold than this give no fit.
pub const MIN_TAIL_SAMPLES: usize = 10;

/// One tail fit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TailFit {
    /// Decay rate `a` of `exp(-a |x|)` (per unit of the normalised variable; may be negative on
    /// a bounded side, where the density grows towards the bound).
    pub rate: f64,
    /// Its standard error, from the Fisher information at the estimate.
    pub error: f64,
    /// Samples beyond the threshold.
    pub samples: usize,
    /// Their fraction of all the samples (both sides).
    pub fraction: f64,
    /// `|x|` from which the tail is fitted.
    pub threshold: f64,
    /// Largest `|x|` the variable can take on this side, if bounded.
    pub bound: Option<f64>,
    /// The fit from other thresholds: `(threshold, rate, error)`, to show how much the
    /// estimate depends on where the tail is taken to start.
    pub sensitivity: Vec<(f64, f64, f64)>,
}

/// `a l` beyond which a truncated exponential is fitted as a plain one (its truncation then
/// moves the mean by less than `e^-700`), and the bracket of the truncated fit.
const STEEP_IN_LENGTHS: f64 = 700.0;

/// The rate and its standard error for the exceedances `y` (all >= 0) of an exponential, or of
/// one truncated at `length` (`y <= length`).
fn rate_of(y: &[f64], length: Option<f64>) -> Option<(f64, f64)> {
    let n = y.len();
    if n < MIN_TAIL_SAMPLES {
        return None;
    }
    let mean = y.iter().sum::<f64>() / n as f64;
    match length {
        None => (mean > 0.0).then(|| (1.0 / mean, 1.0 / (mean * (n as f64).sqrt()))),
        Some(l) => {
            // Mean of a truncated exponential over its length, in t = a l:
            // h(t) = 1/t - 1/(e^t - 1), falling from 1 (t -> -inf) through 1/2 (t = 0) to 0.
            let h = |t: f64| if t.abs() < 1e-4 { 0.5 - t / 12.0 } else { 1.0 / t - 1.0 / t.exp_m1() };
            let target = mean / l;
            if !(target > 0.0 && target < 1.0) {
                return None;
            }
            // A tail that falls off within a small part of its length does not feel the
            // bound: the plain exponential's estimate (h(t) -> 1/t).
            if target < 1.0 / STEEP_IN_LENGTHS {
                return rate_of(y, None);
            }
            let (mut lo, mut hi) = (-STEEP_IN_LENGTHS, STEEP_IN_LENGTHS);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if h(mid) > target { lo = mid } else { hi = mid }
            }
            let t = 0.5 * (lo + hi);
            // Fisher information per sample, Var(y) = l^2 (1/t^2 - e^t / (e^t - 1)^2).
            let var_t = if t.abs() < 1e-3 { 1.0 / 12.0 - t * t / 240.0 } else { 1.0 / (t * t) - t.exp() / t.exp_m1().powi(2) };
            Some((t / l, 1.0 / (l * (n as f64 * var_t).sqrt())))
        }
    }
}

/// The exponential tail of `values` on the side `sign` (+1 or -1) of zero, from `|x| >=
/// threshold` (up to `bound` when the side is bounded), with the fit from each of
/// `other_thresholds` for its sensitivity; `None` with fewer than [`MIN_TAIL_SAMPLES`] samples.
pub fn fit_tail(values: &[f64], sign: f64, threshold: f64, bound: Option<f64>, other_thresholds: &[f64]) -> Option<TailFit> {
    let side: Vec<f64> = values.iter().filter(|x| x.signum() == sign && **x != 0.0).map(|x| x.abs()).collect();
    let fit = |u: f64| {
        let y: Vec<f64> = side.iter().filter(|x| **x >= u).map(|x| x - u).collect();
        rate_of(&y, bound.map(|b| b - u)).map(|(rate, error)| (rate, error, y.len()))
    };
    let (rate, error, samples) = fit(threshold)?;
    let sensitivity = other_thresholds.iter().filter_map(|&u| fit(u).map(|(r, e, _)| (u, r, e))).collect();
    Some(TailFit { rate, error, samples, fraction: samples as f64 / values.len() as f64, threshold, bound, sensitivity })
}

impl TailFit {
    /// The density (per unit of the normalised variable, over all the samples) that the fit
    /// gives at `|x| = x_abs` beyond the threshold: `fraction` times the exponential's (or
    /// truncated exponential's) density of the exceedance.
    pub fn density_at(&self, x_abs: f64) -> f64 {
        let y = x_abs - self.threshold;
        let mass = match self.bound {
            Some(b) if self.rate != 0.0 => 1.0 - (-self.rate * (b - self.threshold)).exp(),
            Some(b) => return self.fraction / (b - self.threshold),
            None => 1.0,
        };
        self.fraction * self.rate * (-self.rate * y).exp() / mass
    }
}
