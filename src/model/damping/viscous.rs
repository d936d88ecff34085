//! A constant viscous dashpot `-c_n v_n`, `c_n` (N s/m) from the scene. Scene:
//! `damping = "viscous"`, `c_n` required.

use super::DampingLaw;
use crate::model::keys::{required_positive, LawInput};
use crate::model::registry::Entry;

/// The registry's row.
pub(super) const ENTRY: Entry<DampingLaw<f64>> = Entry {
    name: "viscous",
    keys: &["c_n"],
    parse: |input: &LawInput| Ok(DampingLaw::Viscous { c_n: required_positive(input.keys, "c_n", "give the dashpot coefficient c_n in N s/m")? }),
};
