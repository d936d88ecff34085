//! Bauer's compression law (Oquendo et al. eq. 19) fitted by Levenberg-Marquardt, the power law
//! across a sweep, and the concise `value(uncertainty)` notation the paper prints.
//!
//! A three-parameter least-squares problem needs a 3x3 solve and nothing more, so the
//! damped Gauss-Newton iteration is written here rather than pulled in with a linear-algebra
//! crate.

use serde::Serialize;

/// A fitted parameter and its standard error.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Estimate {
    /// Best value.
    pub value: f64,
    /// Standard error from the covariance `s^2 (J^T J)^-1`.
    pub error: f64,
}

impl Estimate {
    /// `19.1(1.1)`, `0.57(1)`: the value to the last digit the error reaches, the error in
    /// parentheses (two significant digits when it starts with 1 and the second is not 0,
    /// else one).
    pub fn concise(&self) -> String {
        concise(self.value, self.error)
    }
}

/// See [`Estimate::concise`].
pub fn concise(value: f64, error: f64) -> String {
    if !(error.is_finite() && error > 0.0) {
        // No error to go by: six significant digits.
        return format!("{}", format!("{value:.5e}").parse::<f64>().unwrap_or(value));
    }
    let exp = error.log10().floor() as i32;
    // Two digits when the error starts with 1 (1.1, 0.14), one otherwise; an error that
    // rounds to 10, 20... in two digits is written with one.
    let two = (error / 10f64.powi(exp - 1)).round() as i64;
    let sig = if two < 20 && two % 10 != 0 { 2 } else { 1 };
    let decimals = -(exp - (sig - 1));
    let scale = 10f64.powi(decimals);
    let err = (error * scale).round() / scale;
    if decimals > 0 {
        let v = format!("{value:.prec$}", prec = decimals as usize);
        if err >= 1.0 {
            format!("{v}({err:.prec$})", prec = decimals as usize)
        } else {
            format!("{v}({})", (error * scale).round() as i64)
        }
    } else {
        let v = (value / 10f64.powi(-decimals)).round() * 10f64.powi(-decimals);
        format!("{v:.0}({err:.0})")
    }
}

/// Bauer's law `e = e0 exp(-(s p / h_s)^eta)`, `s` = 1 (vertical stress, Oquendo et al. eq. 19) or 3
/// (the abstract's mean-stress form).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct BauerFit {
    /// Void ratio at zero pressure (fitted, or given).
    pub e0: Estimate,
    /// True when e0 was fitted, false when it was given (measured).
    pub e0_fitted: bool,
    /// Granular hardness h_s (Pa).
    pub h_s: Estimate,
    /// Exponent eta.
    pub eta: Estimate,
    /// Pressure multiplier: 1 or 3.
    pub stress_factor: f64,
    /// Root-mean-square residual in e.
    pub rms: f64,
    /// Points fitted.
    pub points: usize,
    /// Correlations of the fitted parameters, from the covariance.
    pub correlations: Correlations,
}

/// Correlation coefficients (-1..1) of the fitted parameters: `ln h_s` with `eta`, and with
/// `e0` when e0 was fitted.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Correlations {
    /// `ln h_s` with `eta`.
    pub ln_h_s_eta: f64,
    /// `ln h_s` with `e0`.
    pub ln_h_s_e0: Option<f64>,
    /// `eta` with `e0`.
    pub eta_e0: Option<f64>,
}

impl BauerFit {
    /// The law at pressure `p` (Pa).
    pub fn void_ratio(&self, p: f64) -> f64 {
        bauer(self.e0.value, self.h_s.value, self.eta.value, self.stress_factor * p)
    }

    /// The paper's line: `h_s = 19.1(1.1) MPa, eta = 0.57(1), e0 = 0.712(3)` (e0 without an
    /// error when it was measured, not fitted).
    pub fn line(&self) -> String {
        let mpa = Estimate { value: self.h_s.value / 1e6, error: self.h_s.error / 1e6 };
        let e0 = if self.e0_fitted { self.e0.concise() } else { format!("{:.4} (measured)", self.e0.value) };
        format!("h_s = {} MPa, eta = {}, e0 = {e0}", mpa.concise(), self.eta.concise())
    }
}

fn bauer(e0: f64, h_s: f64, eta: f64, p: f64) -> f64 {
    e0 * (-(p / h_s).powf(eta)).exp()
}

/// Why a fit failed.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// Too few points for the parameters.
    #[error("{points} points cannot fit {params} parameters; fix: record more pressure stages")]
    TooFew {
        /// Points given.
        points: usize,
        /// Parameters fitted.
        params: usize,
    },
    /// A point is unusable.
    #[error("point {index} (p = {p}, e = {e}) is not positive and finite; fix: check the data")]
    BadPoint {
        /// Its index.
        index: usize,
        /// Pressure.
        p: f64,
        /// Void ratio.
        e: f64,
    },
    /// The iteration did not settle.
    #[error("the fit did not converge in {0} iterations; fix: check that e falls with p")]
    NoConvergence(usize),
}

/// Largest number of Levenberg-Marquardt iterations.
pub const MAX_ITERATIONS: usize = 200;

/// Fits Bauer's law to `(p, e)` points (Pa, -). With `e0 = Some(v)` the initial void ratio is
/// held at `v` and only `h_s` and `eta` are fitted; otherwise all three.
pub fn fit_bauer(points: &[(f64, f64)], e0: Option<f64>, stress_factor: f64) -> Result<BauerFit, FitError> {
    for (index, &(p, e)) in points.iter().enumerate() {
        if !(p.is_finite() && p > 0.0 && e.is_finite() && e > 0.0) {
            return Err(FitError::BadPoint { index, p, e });
        }
    }
    let n_params = if e0.is_some() { 2 } else { 3 };
    if points.len() <= n_params {
        return Err(FitError::TooFew { points: points.len(), params: n_params });
    }
    // Parameters: ln h_s, eta, and (when free) e0. Start from a log-log line through
    // ln(-ln(e/e0)) = eta ln(p) - eta ln(h_s), with e0 a little above the largest e.
    let e_max = points.iter().map(|q| q.1).fold(0.0, f64::max);
    let e0_start = e0.unwrap_or(1.02 * e_max);
    let xs: Vec<(f64, f64)> = points
        .iter()
        .filter(|q| q.1 < e0_start)
        .map(|&(p, e)| ((stress_factor * p).ln(), (-(e / e0_start).ln()).ln()))
        .collect();
    let (eta0, ln_h0) = if xs.len() >= 2 {
        let n = xs.len() as f64;
        let (mx, my) = (xs.iter().map(|x| x.0).sum::<f64>() / n, xs.iter().map(|x| x.1).sum::<f64>() / n);
        let sxx: f64 = xs.iter().map(|x| (x.0 - mx).powi(2)).sum();
        let sxy: f64 = xs.iter().map(|x| (x.0 - mx) * (x.1 - my)).sum();
        let eta = (sxy / sxx).clamp(0.05, 3.0);
        (eta, mx - my / eta)
    } else {
        (0.5, (stress_factor * points.iter().map(|q| q.0).fold(0.0, f64::max)).ln() + 3.0)
    };
    let mut theta = vec![ln_h0, eta0];
    if e0.is_none() {
        theta.push(e0_start);
    }
    let model = |t: &[f64], p: f64| bauer(if t.len() == 3 { t[2] } else { e0.unwrap_or(1.0) }, t[0].exp(), t[1], stress_factor * p);
    let ssr = |t: &[f64]| points.iter().map(|&(p, e)| (e - model(t, p)).powi(2)).sum::<f64>();
    let jacobian = |t: &[f64]| -> Vec<Vec<f64>> {
        points
            .iter()
            .map(|&(p, _)| {
                let e0v = if t.len() == 3 { t[2] } else { e0.unwrap_or(1.0) };
                let x = stress_factor * p / t[0].exp();
                let u = x.powf(t[1]);
                let f = e0v * (-u).exp();
                // d f / d ln h_s = f u eta; d f / d eta = -f u ln x; d f / d e0 = f / e0.
                let mut row = vec![f * u * t[1], -f * u * x.ln()];
                if t.len() == 3 {
                    row.push(f / e0v);
                }
                row
            })
            .collect()
    };
    let normal = |t: &[f64]| {
        let j = jacobian(t);
        let k = t.len();
        let mut a = vec![vec![0.0; k]; k];
        let mut g = vec![0.0; k];
        for (row, &(p, e)) in j.iter().zip(points) {
            let r = e - model(t, p);
            for a_i in 0..k {
                g[a_i] += row[a_i] * r;
                for b in 0..k {
                    a[a_i][b] += row[a_i] * row[b];
                }
            }
        }
        (a, g)
    };
    let mut lambda = 1e-3;
    let mut cost = ssr(&theta);
    let mut converged = false;
    for _ in 0..MAX_ITERATIONS {
        let (a, g) = normal(&theta);
        let mut damped = a.clone();
        for (i, row) in damped.iter_mut().enumerate() {
            row[i] += lambda * a[i][i].max(1e-300);
        }
        let Some(step) = solve(&damped, &g) else {
            lambda *= 10.0;
            continue;
        };
        let trial: Vec<f64> = theta.iter().zip(&step).map(|(t, s)| t + s).collect();
        let trial_cost = ssr(&trial);
        if trial_cost.is_finite() && trial_cost <= cost {
            let small = step.iter().zip(&theta).all(|(s, t)| s.abs() <= 1e-12 * (1.0 + t.abs()));
            let flat = cost - trial_cost <= 1e-15 * cost.max(1e-300);
            theta = trial;
            cost = trial_cost;
            lambda = (lambda / 10.0).max(1e-12);
            if small || flat {
                converged = true;
                break;
            }
        } else {
            lambda *= 10.0;
            if lambda > 1e12 {
                converged = true;
                break;
            }
        }
    }
    if !converged {
        return Err(FitError::NoConvergence(MAX_ITERATIONS));
    }
    let dof = (points.len() - theta.len()) as f64;
    let s2 = cost / dof;
    let (a, _) = normal(&theta);
    let cov = invert(&a).ok_or(FitError::NoConvergence(MAX_ITERATIONS))?;
    let err = |i: usize| (s2 * cov[i][i]).max(0.0).sqrt();
    let corr = |i: usize, j: usize| cov[i][j] / (cov[i][i] * cov[j][j]).sqrt();
    let free = theta.len() == 3;
    let h_s = theta[0].exp();
    Ok(BauerFit {
        e0: if theta.len() == 3 { Estimate { value: theta[2], error: err(2) } } else { Estimate { value: e0.unwrap_or(1.0), error: 0.0 } },
        e0_fitted: theta.len() == 3,
        h_s: Estimate { value: h_s, error: h_s * err(0) },
        eta: Estimate { value: theta[1], error: err(1) },
        stress_factor,
        rms: (cost / points.len() as f64).sqrt(),
        points: points.len(),
        correlations: Correlations { ln_h_s_eta: corr(0, 1), ln_h_s_e0: free.then(|| corr(0, 2)), eta_e0: free.then(|| corr(1, 2)) },
    })
}

/// One point of a profile of Bauer's law over e0: the fit with e0 held at `e0`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ProfilePoint {
    /// The e0 held (-).
    pub e0: f64,
    /// Fitted h_s (Pa).
    pub h_s: f64,
    /// Fitted eta.
    pub eta: f64,
    /// Root-mean-square residual in e.
    pub rms: f64,
}

/// Bauer's law fitted with e0 held at each of a range of values: how much the fitted h_s and
/// eta depend on the e0 assumed, and the power law `h_s = a eta^b` they trace as e0 slides.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct E0Profile {
    /// The fits, by increasing e0 (those that converged).
    pub points: Vec<ProfilePoint>,
    /// `h_s = a eta^b` through the profile (h_s in MPa), when three or more fits converged.
    pub power_law: Option<PowerLaw>,
}

/// Values of e0 for [`e0_profile`]: from just above the largest measured void ratio (Bauer's
/// e0 must exceed every e) to `up_to`, or at least 0.1 above it, spaced evenly in the log of
/// the distance to the largest e, from 1e-3 of it.
pub fn profile_e0s(points: &[(f64, f64)], up_to: f64, count: usize) -> Vec<f64> {
    let e_max = points.iter().map(|q| q.1).fold(0.0, f64::max);
    let span = (up_to - e_max).max(0.1);
    let first = 1e-3 * span;
    (0..count).map(|k| e_max + first * (span / first).powf(k as f64 / (count - 1).max(1) as f64)).collect()
}

/// Bauer's law fitted with e0 held at each of `e0s`.
pub fn e0_profile(points: &[(f64, f64)], e0s: &[f64], stress_factor: f64) -> E0Profile {
    let fits: Vec<ProfilePoint> =
        e0s.iter().filter_map(|&e0| fit_bauer(points, Some(e0), stress_factor).ok().map(|f| ProfilePoint { e0, h_s: f.h_s.value, eta: f.eta.value, rms: f.rms })).collect();
    let power_law = if fits.len() >= 3 { fit_power_law(&fits.iter().map(|f| (f.eta, f.h_s / 1e6)).collect::<Vec<_>>()).ok() } else { None };
    E0Profile { points: fits, power_law }
}

/// The power law `h_s = a eta^b` fitted as a straight line in log-log, with standard errors.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PowerLaw {
    /// Prefactor a (in the units of the h_s given).
    pub a: Estimate,
    /// Exponent b.
    pub b: Estimate,
}

impl PowerLaw {
    /// `h_s = 0.068(4) eta^-9.88(3) MPa`, for a law fitted to h_s in MPa.
    pub fn line(&self) -> String {
        format!("h_s = {} eta^{} MPa", self.a.concise(), self.b.concise())
    }
}

/// Fits `y = a x^b` to positive points by least squares on `ln y = ln a + b ln x`.
pub fn fit_power_law(points: &[(f64, f64)]) -> Result<PowerLaw, FitError> {
    if points.len() < 3 {
        return Err(FitError::TooFew { points: points.len(), params: 2 });
    }
    for (index, &(x, y)) in points.iter().enumerate() {
        if !(x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite()) {
            return Err(FitError::BadPoint { index, p: x, e: y });
        }
    }
    let n = points.len() as f64;
    let l: Vec<(f64, f64)> = points.iter().map(|&(x, y)| (x.ln(), y.ln())).collect();
    let (mx, my) = (l.iter().map(|q| q.0).sum::<f64>() / n, l.iter().map(|q| q.1).sum::<f64>() / n);
    let sxx: f64 = l.iter().map(|q| (q.0 - mx).powi(2)).sum();
    let sxy: f64 = l.iter().map(|q| (q.0 - mx) * (q.1 - my)).sum();
    let b = sxy / sxx;
    let ln_a = my - b * mx;
    let s2 = l.iter().map(|q| (q.1 - ln_a - b * q.0).powi(2)).sum::<f64>() / (n - 2.0);
    let b_err = (s2 / sxx).sqrt();
    let ln_a_err = (s2 * (1.0 / n + mx * mx / sxx)).sqrt();
    let a = ln_a.exp();
    Ok(PowerLaw { a: Estimate { value: a, error: a * ln_a_err }, b: Estimate { value: b, error: b_err } })
}

/// Solves `a x = b` by Gaussian elimination with partial pivoting; `None` when singular.
fn solve(a: &[Vec<f64>], b: &[f64]) -> Option<Vec<f64>> {
    let n = b.len();
    let mut m: Vec<Vec<f64>> = a.iter().zip(b).map(|(row, &v)| row.iter().copied().chain([v]).collect()).collect();
    for c in 0..n {
        let pivot = (c..n).max_by(|&i, &j| m[i][c].abs().total_cmp(&m[j][c].abs()))?;
        if m[pivot][c].abs() < 1e-300 {
            return None;
        }
        m.swap(c, pivot);
        let pivot_row = m[c].clone();
        for (r, row) in m.iter_mut().enumerate() {
            if r != c {
                let f = row[c] / pivot_row[c];
                for (x, p) in row.iter_mut().zip(&pivot_row).skip(c) {
                    *x -= f * p;
                }
            }
        }
    }
    Some((0..n).map(|i| m[i][n] / m[i][i]).collect())
}

fn invert(a: &[Vec<f64>]) -> Option<Vec<Vec<f64>>> {
    let n = a.len();
    let cols: Option<Vec<Vec<f64>>> = (0..n).map(|c| solve(a, &(0..n).map(|r| if r == c { 1.0 } else { 0.0 }).collect::<Vec<_>>())).collect();
    let cols = cols?;
    Some((0..n).map(|r| (0..n).map(|c| cols[c][r]).collect()).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn concise_notation_prints_as_the_paper() {
        assert_eq!(concise(19.1, 1.1), "19.1(1.1)");
        assert_eq!(concise(0.57, 0.01), "0.57(1)");
        assert_eq!(concise(0.068, 0.004), "0.068(4)");
        assert_eq!(concise(-9.88, 0.03), "-9.88(3)");
        assert_eq!(concise(0.428, 0.007), "0.428(7)");
        assert_eq!(concise(1234.0, 56.0), "1230(60)");
    }
}
