//! How a law reads its scene keys: each law's module names the keys it owns and checks their
//! values; the scene layer supplies the values and turns a [`KeyProblem`] into its error, which
//! names the file, the key, the value and the fix.

/// The numeric keys of a scene's `[model]` table, by name.
pub trait LawKeys {
    /// The value of `key`, if the scene sets it.
    fn number(&self, key: &str) -> Option<f64>;
}

/// A key whose value a law refuses.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyProblem {
    /// The key, as written under `[model]`.
    pub key: &'static str,
    /// The value as the scene gives it ("(missing)" when it is not set).
    pub value: String,
    /// What is wrong with it.
    pub problem: String,
    /// How to mend it.
    pub fix: String,
}

/// A key the law needs, greater than zero and finite; `fix` says what to give.
pub fn required_positive(keys: &dyn LawKeys, key: &'static str, fix: &str) -> Result<f64, KeyProblem> {
    match keys.number(key) {
        Some(v) if v > 0.0 && v.is_finite() => Ok(v),
        Some(v) => Err(KeyProblem { key, value: v.to_string(), problem: "must be a positive number".to_string(), fix: fix.to_string() }),
        None => Err(KeyProblem { key, value: "(missing)".to_string(), problem: "is required by the chosen law".to_string(), fix: fix.to_string() }),
    }
}
