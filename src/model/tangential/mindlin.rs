//! The standard Hertz-Mindlin tangential law with history and one Coulomb coefficient (LAMMPS
//! `tangential mindlin`, LIGGGHTS `tangential history`). Scene: `tangential = "mindlin"`, with
//! `tangential_damping_ratio` and `kt_ratio`; the materials' and pairs' `mu_k` must equal their `mu_s`.

use super::{contact_tangential_velocity, rotate_into_plane, stiffness_of, TangentialLaw};
use crate::model::keys::{non_negative_or, KeyProblem, LawInput};
use crate::model::registry::Entry;
use crate::model::{Geometry, Kinematics};
use crate::real::{Real, Vec3};

/// The registry's row.
pub(super) const ENTRY: Entry<TangentialLaw<f64>> = Entry {
    name: "mindlin",
    keys: &["tangential_damping_ratio", "kt_ratio"],
    parse: |input: &LawInput| {
        if let Some((i, m)) = input.materials.iter().enumerate().find(|(_, m)| m.constants.mu_k != m.constants.mu_s) {
            return Err(KeyProblem::new(format!("material[{i}].mu_k"), m.constants.mu_k, "the Hertz-Mindlin law has one friction coefficient (mu_s)", "remove mu_k or set it equal to mu_s"));
        }
        if let Some((k, p)) = input.pairs.iter().enumerate().find(|(_, p)| p.mu_k != p.mu_s) {
            return Err(KeyProblem::new(format!("pair[{k}].mu_k"), p.mu_k, "the Hertz-Mindlin law has one friction coefficient (mu_s)", "remove mu_k from the pair (and the materials) or set it equal to mu_s"));
        }
        Ok(TangentialLaw::Mindlin {
            damping_ratio: non_negative_or(input.keys, "tangential_damping_ratio", 0.0, "give a fraction such as 0.9075")?,
            stiffness: stiffness_of(input)?,
        })
    },
};

/// Hertz-Mindlin tangential force on i with history and one Coulomb coefficient `mu`:
/// `F_t = -k_t xi - eta_t v_t`, capped at `mu F_n`; on the cap the spring is set to
/// `-(F_t + eta_t v_t) / k_t` (LAMMPS `tangential mindlin`). Returns the force and whether
/// the contact slid (was on the cap).
#[inline(always)]
pub fn mindlin_tangential<T: Real>(
    mu: T,
    g: &Geometry<T>,
    k: &Kinematics<T>,
    f_n: T,
    k_t: T,
    eta_t: T,
    xi: &mut Vec3<T>,
    elapsed: T,
) -> (Vec3<T>, bool) {
    let v_t = contact_tangential_velocity(g, k);
    *xi = rotate_into_plane(*xi, g.n) + v_t * elapsed;
    let damp = v_t * eta_t;
    let mut f_t = -(*xi * k_t) - damp;
    let limit = mu * f_n;
    let mag2 = f_t.norm2();
    let slips = mag2 > limit * limit;
    if slips {
        f_t = f_t * (limit / mag2.sqrt());
        *xi = if k_t > T::ZERO { (f_t + damp) * (-T::ONE / k_t) } else { Vec3::ZERO };
    }
    (f_t, slips)
}
