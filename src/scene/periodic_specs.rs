//! `[periodic]`: the wrapping axes, checked against the grains' extent and the neighbour reach,
//! and where each grain came from (for errors that name its table).

use super::*;

pub(super) fn validate_periodic(c: &Complainer, f: &SceneFile) -> Result<[Option<[f64; 2]>; 3], SceneError> {
    let p = &f.periodic;
    let mut out = [None; 3];
    for (a, (name, v)) in [("x", p.x), ("y", p.y), ("z", p.z)].into_iter().enumerate() {
        if let Some([lo, hi]) = v {
            if !(lo.is_finite() && hi.is_finite() && hi > lo) {
                return Err(c.invalid(format!("periodic.{name}"), format!("[{lo}, {hi}]"), "must be [lo, hi] with hi > lo", "give the wrapping interval in metres"));
            }
            out[a] = Some([lo, hi]);
        }
    }
    Ok(out)
}

/// A periodic axis must hold its grains and be long enough that a pair within reach has one
/// image only: period > 2 (2 R_max + skin).
pub(super) fn check_periodic(c: &Complainer, origins: &Origins, grains: &Grains, periodic: &[Option<[f64; 2]>; 3], skin: Option<f64>) -> Result<(), SceneError> {
    let r_max = grains.radius.iter().copied().fold(0.0, f64::max);
    let d_mean = 2.0 * grains.radius.iter().sum::<f64>() / grains.len() as f64;
    let reach = 2.0 * r_max + skin.unwrap_or(0.1 * d_mean);
    for (a, name) in ["x", "y", "z"].into_iter().enumerate() {
        let Some([lo, hi]) = periodic[a] else { continue };
        if hi - lo <= 2.0 * reach {
            return Err(c.invalid(format!("periodic.{name}"), format!("[{lo}, {hi}]"), format!("a period of {:.4e} m is too short for contacts of reach {reach:.4e} m", hi - lo), format!("make the period longer than {:.4e} m", 2.0 * reach)));
        }
        if let Some(i) = (0..grains.len()).find(|&i| !(grains.position[i][a] >= lo && grains.position[i][a] < hi)) {
            return Err(c.invalid(origins.name(i), format!("{:?}", grains.position[i]), format!("lies outside periodic.{name} = [{lo}, {hi})"), "place grains inside the periodic interval"));
        }
    }
    Ok(())
}
