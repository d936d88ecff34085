//! How a law reads its scene keys: each law's module names the keys it owns and checks their
//! values; the scene layer supplies the values (and, for laws that check them, the materials)
//! and turns a [`KeyProblem`] into its error, which names the file, the key, the value and the
//! fix.

use super::{MaterialConstants, MixedConstants, NormalLaw};

/// The keys of a scene's `[model]` table, by name.
pub trait LawKeys {
    /// The value of a numeric `key`, if the scene sets it.
    fn number(&self, key: &str) -> Option<f64>;
    /// The value of a text `key`, if the scene sets it.
    fn text(&self, _key: &str) -> Option<&str> {
        None
    }
    /// Whether the scene sets `key`, of either kind.
    fn is_set(&self, key: &str) -> bool {
        self.number(key).is_some() || self.text(key).is_some()
    }
}

/// A material as a law's checks see it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialUse {
    /// Its elastic and frictional constants.
    pub constants: MaterialConstants,
    /// Its restitution coefficient as the scene gives it (`None` when not given).
    pub restitution: Option<f64>,
    /// Whether a grain or a wall is made of it.
    pub in_contact: bool,
}

/// What a law reads as it is chosen: the `[model]` keys, the materials (indexed as the scene's
/// `[[material]]` tables), and the normal law where the slot is chosen after it.
pub struct LawInput<'a> {
    /// The `[model]` keys.
    pub keys: &'a dyn LawKeys,
    /// The scene's materials, in order.
    pub materials: &'a [MaterialUse],
    /// Each `[[pair]]` table's constants, in the scene's order (`pair[k]`): the mixing rule's
    /// with the table's values in place.
    pub pairs: &'a [MixedConstants],
    /// The normal law, for the slots chosen after it (`None` while the normal law is chosen).
    pub normal: Option<&'a NormalLaw<f64>>,
}

/// A key whose value a law refuses.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyProblem {
    /// The key's path in the scene, e.g. `model.k_n` or `material[1].restitution`.
    pub key: String,
    /// The value as the scene gives it ("(missing)" when it is not set).
    pub value: String,
    /// What is wrong with it.
    pub problem: String,
    /// How to mend it.
    pub fix: String,
}

impl KeyProblem {
    /// A problem with `value` of the scene key `key` (its full path).
    pub fn new(key: impl Into<String>, value: impl std::fmt::Display, problem: impl Into<String>, fix: impl Into<String>) -> Self {
        KeyProblem { key: key.into(), value: value.to_string(), problem: problem.into(), fix: fix.into() }
    }
}

/// A `[model]` key the law needs, greater than zero and finite; `fix` says what to give.
pub fn required_positive(keys: &dyn LawKeys, key: &str, fix: &str) -> Result<f64, KeyProblem> {
    match keys.number(key) {
        Some(v) => positive(key, v, fix),
        None => Err(KeyProblem::new(format!("model.{key}"), "(missing)", "is required by the chosen law", fix)),
    }
}

/// A `[model]` key the law reads with a default, greater than zero and finite.
pub fn positive_or(keys: &dyn LawKeys, key: &str, default: f64, fix: &str) -> Result<f64, KeyProblem> {
    positive(key, keys.number(key).unwrap_or(default), fix)
}

/// A `[model]` key the law reads with a default, zero or more and finite.
pub fn non_negative_or(keys: &dyn LawKeys, key: &str, default: f64, fix: &str) -> Result<f64, KeyProblem> {
    match keys.number(key).unwrap_or(default) {
        v if v >= 0.0 && v.is_finite() => Ok(v),
        v => Err(KeyProblem::new(format!("model.{key}"), v, "must be zero or positive", fix)),
    }
}

fn positive(key: &str, v: f64, fix: &str) -> Result<f64, KeyProblem> {
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(KeyProblem::new(format!("model.{key}"), v, "must be a positive number", fix))
    }
}
