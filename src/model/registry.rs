//! A slot's registry (after LAMMPS' `gran_sub_mod_register.cpp`): one row per law, naming it
//! as scenes write it, the `[model]` keys it owns and how it reads them. Every slot (normal,
//! damping, tangential, rolling, twisting, cohesion) keeps one in its `mod.rs`; a law's WGSL
//! code is its row's index, written into the kernels' prelude from [`Slot::codes`]
//! (`crate::model::wgsl_codes`), so that the Rust and WGSL codes cannot drift.

use super::keys::{KeyProblem, LawInput};

/// A registry row: the law's name in scenes, the `[model]` keys it owns, and how it reads them.
pub struct Entry<L> {
    /// `<slot> = "<name>"`.
    pub name: &'static str,
    /// The `[model]` keys the law reads; setting one under another law of the slot is an error.
    pub keys: &'static [&'static str],
    /// The law from the scene's keys (and, for laws that need them, its materials).
    pub parse: fn(&LawInput) -> Result<L, KeyProblem>,
}

/// One slot's registry: its name as a `[model]` key and its rows, in the order of their WGSL
/// codes.
pub struct Slot<L: 'static> {
    /// The slot's key under `[model]`, lower case; its WGSL constants are `<SLOT>_<LAW>`.
    pub name: &'static str,
    /// The laws, a law's WGSL code being its index.
    pub laws: &'static [Entry<L>],
}

impl<L> Slot<L> {
    /// The law `name` reads from `input`, refusing a key that only another law of the slot
    /// reads. `Err(None)`: no law has that name ([`Slot::names`] lists them).
    pub fn parse(&self, name: &str, input: &LawInput) -> Result<L, Option<KeyProblem>> {
        let chosen = self.laws.iter().find(|e| e.name == name).ok_or(None)?;
        for other in self.laws.iter().filter(|e| e.name != name) {
            for &key in other.keys.iter().filter(|k| !chosen.keys.contains(k)) {
                if input.keys.is_set(key) {
                    return Err(Some(KeyProblem {
                        key: format!("model.{key}"),
                        value: "(set)".to_string(),
                        problem: format!("is not used by the chosen laws ({} = \"{name}\")", self.name),
                        fix: format!("remove `{key}` or choose the law that uses it ({} = \"{}\")", self.name, other.name),
                    }));
                }
            }
        }
        (chosen.parse)(input).map_err(Some)
    }

    /// The laws' names, quoted, as a scene's error lists them: `"none", "papers" or "viscous"`.
    pub fn names(&self) -> String {
        let quoted: Vec<String> = self.laws.iter().map(|e| format!("\"{}\"", e.name)).collect();
        match quoted.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
            _ => quoted.concat(),
        }
    }

    /// The WGSL code of the law named `name`: its row's index.
    pub fn code(&self, name: &str) -> u32 {
        match self.laws.iter().position(|e| e.name == name) {
            Some(i) => i as u32,
            None => unreachable!("the {} law \"{name}\" has no registry row", self.name),
        }
    }

    /// Each law's WGSL constant and code, `(<SLOT>_<LAW>, row)`.
    pub fn codes(&self) -> impl Iterator<Item = (String, u32)> + '_ {
        self.laws.iter().enumerate().map(|(i, e)| (format!("{}_{}", self.name.to_uppercase(), e.name.to_uppercase()), i as u32))
    }
}
