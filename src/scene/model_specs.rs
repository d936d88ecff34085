//! `[model]` and the method: the law per slot with its parameters checked against the materials,
//! the liquid bridges' limits, and contact dynamics' settings.

use super::*;
use crate::model::keys::{LawInput, MaterialUse};
use crate::model::MixedConstants;
use crate::model::registry::Slot;
use crate::model::{cohesion, damping, normal, rolling, tangential, twisting};

pub(super) fn validate_model(c: &Complainer, m: &ModelSpec, materials: &[Material], pairs: &[MaterialPair], grains: &Grains, walls: &[Wall]) -> Result<ContactModel<f64>, SceneError> {
    for (key, v, why) in [
        ("v_slip", m.v_slip, "Oquendo et al.'s contacts slide when their static spring fails its Coulomb test (mu_s), not above a speed"),
        ("v_roll", m.v_roll, "Oquendo et al.'s contacts roll when their rolling spring reaches the rolling friction, not above a speed"),
    ] {
        if let Some(v) = v {
            return Err(c.invalid(format!("model.{key}"), v, format!("is no longer used: {why}"), format!("remove `{key}` (docs/physics.md, \"Oquendo et al.'s contact law\")")));
        }
    }
    let used: Vec<u16> = grains.material.iter().copied().chain(walls.iter().map(|w| w.material)).collect();
    let uses: Vec<MaterialUse> =
        materials.iter().enumerate().map(|(i, mat)| MaterialUse { constants: mat.constants, restitution: mat.restitution, in_contact: used.contains(&(i as u16)) }).collect();
    let table = mixed_table(materials, pairs);
    let pair_uses: Vec<MixedConstants> = pairs.iter().map(|p| table[p.materials[0] as usize * materials.len() + p.materials[1] as usize]).collect();
    let mut input = LawInput { keys: m, materials: &uses, pairs: &pair_uses, normal: None };
    let normal = choose(c, &normal::SLOT, &m.normal, "hertz", &input)?;
    input.normal = Some(&normal);
    let damping = choose(c, &damping::SLOT, &m.damping, "none", &input)?;
    if matches!(damping, DampingLaw::None) && m.limit_damping.is_some() {
        return Err(c.invalid("model.limit_damping", "(set)", "is not used by the chosen laws (damping = \"none\": an elastic force never pulls)", "remove `limit_damping` or choose a damping law"));
    }
    Ok(ContactModel {
        normal,
        damping,
        tangential: choose(c, &tangential::SLOT, &m.tangential, "none", &input)?,
        rolling: choose(c, &rolling::SLOT, &m.rolling, "none", &input)?,
        twisting: choose(c, &twisting::SLOT, &m.twisting, "none", &input)?,
        cohesion: choose(c, &cohesion::SLOT, &m.cohesion, "none", &input)?,
        limit_damping: m.limit_damping.unwrap_or(true),
    })
}

/// The law a slot's key names (`default` when the scene leaves it out), read from its registry;
/// a law's refusal of a key becomes the scene's error.
fn choose<L>(c: &Complainer, slot: &Slot<L>, name: &Option<String>, default: &str, input: &LawInput) -> Result<L, SceneError> {
    let name = name.as_deref().unwrap_or(default);
    slot.parse(name, input).map_err(|problem| match problem {
        Some(p) => c.invalid(p.key, p.value, p.problem, p.fix),
        None => c.invalid(format!("model.{}", slot.name), format!("\"{name}\""), format!("unknown {} law", slot.name), format!("use {}", slot.names())),
    })
}

/// Sizes the largest bridge from the most liquid a stage adds: the mean bridge holds the
/// liquid over `BRIDGES_PER_GRAIN / 2` pairs per grain, and no bridge more than
/// `BRIDGE_CAP_IN_MEANS` of them.
pub(super) fn bridge_limits(c: &Complainer, model: &ContactModel<f64>, stages: &[Stage], grains: &Grains) -> Result<BridgeLimits, SceneError> {
    let wettest = stages.iter().filter_map(|s| s.wet_volume).fold(0.0, f64::max);
    match model.cohesion {
        CohesionLaw::None => {
            if wettest > 0.0 {
                return Err(c.invalid("stage.water_content", "(set)", "wets the sample, but the model has no cohesion", "set model.cohesion = \"capillary\" or remove water_content"));
            }
            Ok(BridgeLimits::default())
        }
        CohesionLaw::Capillary { theta, .. } => {
            if wettest == 0.0 {
                return Err(c.invalid("model.cohesion", "\"capillary\"", "no stage wets the sample", "give a stage `water_content`, e.g. 0.007"));
            }
            let mean = wettest / (0.5 * BRIDGES_PER_GRAIN * grains.len() as f64);
            let volume_cap = BRIDGE_CAP_IN_MEANS * mean;
            Ok(BridgeLimits { volume_cap, reach: crate::model::rupture_distance(theta, volume_cap) })
        }
    }
}

/// `simulation.method` and, for contact dynamics, its `[contact_dynamics]` settings.
pub(super) fn validate_method(c: &Complainer, sim: &SimulationSpec, spec: Option<&ContactDynamicsSpec>, d_mean: f64) -> Result<Method, SceneError> {
    match sim.method.as_deref().unwrap_or("dem") {
        "dem" => {
            if spec.is_some() {
                return Err(c.invalid("contact_dynamics", "(set)", "is read only by contact dynamics", "set simulation.method = \"contact_dynamics\" or remove [contact_dynamics]"));
            }
            Ok(Method::Dem)
        }
        "contact_dynamics" => {
            let given = spec.copied().unwrap_or_default();
            let theta = given.theta.unwrap_or(CdParams::default().theta);
            if !(0.5..=1.0).contains(&theta) {
                return Err(c.invalid("contact_dynamics.theta", theta, "must lie in [0.5, 1]", "use 0.5 (the midpoint rule) to 1 (implicit Euler)"));
            }
            let tolerance = given.tolerance.unwrap_or(CdParams::default().tolerance);
            if !(tolerance > 0.0 && tolerance < 1.0) {
                return Err(c.invalid("contact_dynamics.tolerance", tolerance, "must lie in (0, 1)", "give a quadratic norm such as 1e-3 (the default)"));
            }
            let max_iterations = given.max_iterations.unwrap_or(CdParams::default().max_iterations);
            if max_iterations == 0 {
                return Err(c.invalid("contact_dynamics.max_iterations", 0, "must be at least 1", "give a number of sweeps, e.g. 1000"));
            }
            let relaxation = given.relaxation.unwrap_or(CdParams::default().relaxation);
            if !(relaxation > 0.0 && relaxation < 2.0) {
                return Err(c.invalid("contact_dynamics.relaxation", relaxation, "must lie in (0, 2)", "use 1 (plain Gauss-Seidel) or an over-relaxation such as 1.5"));
            }
            let gap_allowance = match given.gap_allowance {
                Some(v) => non_negative(c, "contact_dynamics.gap_allowance", v, "give a length in metres, e.g. 0.1 x the mean diameter")?,
                None => 0.1 * d_mean,
            };
            let wall_mass = given.wall_mass.map(|m| positive(c, "contact_dynamics.wall_mass", m, "give a mass in kg, or leave it out for the grains' total mass")).transpose()?;
            Ok(Method::ContactDynamics(CdParams { theta, tolerance, max_iterations, relaxation, gap_allowance, wall_mass }))
        }
        other => Err(c.invalid("simulation.method", format!("\"{other}\""), "unknown method", "use \"dem\" or \"contact_dynamics\"")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::keys::LawKeys;

    /// Every `[model]` key a registry row names, with its slot.
    fn registry_keys() -> Vec<(&'static str, &'static str)> {
        let mut keys = Vec::new();
        let mut add = |slot: &'static str, rows: Vec<&'static [&'static str]>| keys.extend(rows.into_iter().flatten().map(|k| (slot, *k)));
        add(normal::SLOT.name, normal::SLOT.laws.iter().map(|e| e.keys).collect());
        add(damping::SLOT.name, damping::SLOT.laws.iter().map(|e| e.keys).collect());
        add(tangential::SLOT.name, tangential::SLOT.laws.iter().map(|e| e.keys).collect());
        add(rolling::SLOT.name, rolling::SLOT.laws.iter().map(|e| e.keys).collect());
        add(twisting::SLOT.name, twisting::SLOT.laws.iter().map(|e| e.keys).collect());
        add(cohesion::SLOT.name, cohesion::SLOT.laws.iter().map(|e| e.keys).collect());
        keys
    }

    /// A key a law owns but `ModelSpec` does not hand it would read as never set: the law
    /// would take its default and the key would be silently ignored.
    #[test]
    fn every_key_a_law_owns_reaches_it_from_the_scene() {
        let keys = registry_keys();
        assert!(keys.len() >= 12, "{keys:?}");
        for (slot, key) in keys {
            let spec: ModelSpec = toml::from_str(&format!("{key} = 0.25")).or_else(|_| toml::from_str(&format!("{key} = \"as_written\""))).unwrap_or_else(|e| panic!("{slot} key {key}: {e}"));
            assert!(spec.is_set(key), "the {slot} slot's key `{key}` is accepted under [model] but not handed to its law");
        }
    }
}
