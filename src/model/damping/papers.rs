//! The papers' nonlinear damping `-m_eff gamma_n sqrt(h) v_n` (Oquendo et al. eq. 1), its
//! `gamma_n` (s^-1 m^-1/2) the materials'. Scene: `damping = "papers"`, no keys of its own.

use super::DampingLaw;
use crate::model::keys::{KeyProblem, LawInput};
use crate::model::registry::Entry;

/// The registry's row: refuses a scene where no material or pair sets `gamma_n`, which would not damp.
pub(super) const ENTRY: Entry<DampingLaw<f64>> = Entry {
    name: "papers",
    keys: &[],
    parse: |input: &LawInput| {
        if input.materials.iter().all(|m| m.constants.gamma_n == 0.0) && input.pairs.iter().all(|p| p.gamma_n == 0.0) {
            return Err(KeyProblem::new("model.damping", "\"papers\"", "no material or pair sets gamma_n, so it would not damp", "set `gamma_n` (s^-1 m^-1/2) in the [[material]] tables or use damping = \"none\""));
        }
        Ok(DampingLaw::Papers)
    },
};
