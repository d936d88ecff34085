//! `[model]` and the method: the law per slot with its parameters checked against the materials,
//! the liquid bridges' limits, and contact dynamics' settings.

use super::*;

pub(super) fn validate_model(c: &Complainer, m: &ModelSpec, materials: &[Material], grains: &Grains, walls: &[Wall]) -> Result<ContactModel<f64>, SceneError> {
    let law = |v: &Option<String>, default: &str| v.clone().unwrap_or_else(|| default.to_string());
    let unused = |key: &str, set: bool, law: &str| -> Result<(), SceneError> {
        if set {
            Err(c.invalid(format!("model.{key}"), "(set)", format!("is not used by the chosen laws ({law})"), format!("remove `{key}` or choose the law that uses it")))
        } else {
            Ok(())
        }
    };
    let need = |key: &str, v: Option<f64>, why: &str| -> Result<f64, SceneError> {
        match v {
            Some(x) => positive(c, &format!("model.{key}"), x, why),
            None => Err(c.invalid(format!("model.{key}"), "(missing)", "is required by the chosen law", why.to_string())),
        }
    };
    let normal_name = law(&m.normal, "hertz");
    let normal = crate::model::normal::parse(&normal_name, m).map_err(|problem| match problem {
        Some(p) => c.invalid(format!("model.{}", p.key), p.value, p.problem, p.fix),
        None => c.invalid("model.normal", format!("\"{normal_name}\""), "unknown normal law", format!("use {}", crate::model::normal::names())),
    })?;
    let damping_name = law(&m.damping, "none");
    let damping = match damping_name.as_str() {
        "none" => DampingLaw::None,
        "papers" => DampingLaw::Papers,
        "restitution" => {
            // Every material in contact needs its restitution coefficient.
            let used: Vec<u16> = grains.material.iter().copied().chain(walls.iter().map(|w| w.material)).collect();
            if let Some((i, _)) = materials.iter().enumerate().find(|(i, mat)| used.contains(&(*i as u16)) && mat.restitution.is_none()) {
                return Err(c.invalid(format!("material[{i}].restitution"), "(missing)", "damping = \"restitution\" needs it", "add `restitution` in (0, 1] to the material"));
            }
            // Every material, used or not: the dashpot is sized for each pair of them.
            if let Some((i, e)) = materials.iter().enumerate().find_map(|(i, mat)| mat.restitution.filter(|&e| e < MIN_RESTITUTION).map(|e| (i, e))) {
                return Err(c.invalid(
                    format!("material[{i}].restitution"),
                    e,
                    format!("is below {MIN_RESTITUTION}, where the dashpot would set the contact's time scale and the time step, picked from the elastic contact time, would not resolve it"),
                    format!("give a restitution of at least {MIN_RESTITUTION}"),
                ));
            }
            DampingLaw::Restitution
        }
        "viscous" => DampingLaw::Viscous { c_n: need("c_n", m.c_n, "give the dashpot coefficient c_n in N s/m")? },
        other => return Err(c.invalid("model.damping", format!("\"{other}\""), "unknown damping law", "use \"none\", \"papers\", \"restitution\" or \"viscous\"")),
    };
    if !matches!(damping, DampingLaw::Viscous { .. }) {
        unused("c_n", m.c_n.is_some(), &format!("damping = \"{damping_name}\""))?;
    }
    if matches!(damping, DampingLaw::None) {
        unused("limit_damping", m.limit_damping.is_some(), "damping = \"none\" (an elastic force never pulls)")?;
    }
    if matches!(damping, DampingLaw::Papers) && materials.iter().all(|x| x.constants.gamma_n == 0.0) {
        return Err(c.invalid("model.damping", "\"papers\"", "no material sets gamma_n, so it would not damp", "set `gamma_n` (s^-1 m^-1/2) in the [[material]] tables or use damping = \"none\""));
    }
    let stiffness = |kt: Option<f64>| -> Result<TangentialStiffness<f64>, SceneError> {
        match kt {
            Some(r) => Ok(TangentialStiffness::RatioToNormal(positive(c, "model.kt_ratio", r, "give a ratio such as 2/7")?)),
            None => Ok(normal.default_tangential_stiffness()),
        }
    };
    for (key, v, why) in [
        ("v_slip", m.v_slip, "Oquendo et al.'s contacts slide when their static spring fails its Coulomb test (mu_s), not above a speed"),
        ("v_roll", m.v_roll, "Oquendo et al.'s contacts roll when their rolling spring reaches the rolling friction, not above a speed"),
    ] {
        if let Some(v) = v {
            return Err(c.invalid(format!("model.{key}"), v, format!("is no longer used: {why}"), format!("remove `{key}` (docs/physics.md, \"Oquendo et al.'s contact law\")")));
        }
    }
    let tangential_name = law(&m.tangential, "none");
    let tangential = match tangential_name.as_str() {
        "none" => {
            for (k, set) in [("static_damping", m.static_damping.is_some()), ("rolling_friction", m.rolling_friction.is_some()), ("kt_ratio", m.kt_ratio.is_some()), ("tangential_damping_ratio", m.tangential_damping_ratio.is_some())] {
                unused(k, set, "tangential = \"none\"")?;
            }
            TangentialLaw::None
        }
        "oquendo" => {
            unused("tangential_damping_ratio", m.tangential_damping_ratio.is_some(), "tangential = \"oquendo\" (its static spring is damped by static_damping)")?;
            TangentialLaw::Oquendo(OquendoLaw {
                static_damping: non_negative(c, "model.static_damping", m.static_damping.unwrap_or(DEFAULT_STATIC_DAMPING), "give a fraction of critical damping such as 0.3")?,
                stiffness: stiffness(m.kt_ratio)?,
                rolling_friction: match m.rolling_friction.as_deref().unwrap_or("torque") {
                    "torque" => RollingFriction::Torque,
                    "as_written" => RollingFriction::AsWritten,
                    other => return Err(c.invalid("model.rolling_friction", format!("\"{other}\""), "unknown rolling friction", "use \"torque\" (momentum-conserving) or \"as_written\" (eqs. 8-9 on each grain)")),
                },
            })
        }
        "mindlin" => {
            unused("static_damping", m.static_damping.is_some(), "tangential = \"mindlin\"")?;
            unused("rolling_friction", m.rolling_friction.is_some(), "tangential = \"mindlin\"")?;
            for (i, mat) in materials.iter().enumerate() {
                if mat.constants.mu_k != mat.constants.mu_s {
                    return Err(c.invalid(format!("material[{i}].mu_k"), mat.constants.mu_k, "the Hertz-Mindlin law has one friction coefficient (mu_s)", "remove mu_k or set it equal to mu_s"));
                }
            }
            TangentialLaw::Mindlin {
                damping_ratio: non_negative(c, "model.tangential_damping_ratio", m.tangential_damping_ratio.unwrap_or(0.0), "give a fraction such as 0.9075")?,
                stiffness: stiffness(m.kt_ratio)?,
            }
        }
        other => return Err(c.invalid("model.tangential", format!("\"{other}\""), "unknown tangential law", "use \"none\", \"oquendo\" or \"mindlin\"")),
    };
    let rolling_name = law(&m.rolling, "none");
    let rolling = match rolling_name.as_str() {
        "none" => {
            for (k, set) in [("rolling_k", m.rolling_k.is_some()), ("rolling_gamma", m.rolling_gamma.is_some()), ("rolling_mu", m.rolling_mu.is_some())] {
                unused(k, set, "rolling = \"none\"")?;
            }
            RollingLaw::None
        }
        "sds" => RollingLaw::Sds {
            k_r: need("rolling_k", m.rolling_k, "give the rolling stiffness in N/m")?,
            gamma_r: non_negative(c, "model.rolling_gamma", m.rolling_gamma.unwrap_or(0.0), "give the rolling damping in N s/m")?,
            mu_r: need("rolling_mu", m.rolling_mu, "give the rolling friction coefficient, e.g. 0.05")?,
        },
        other => return Err(c.invalid("model.rolling", format!("\"{other}\""), "unknown rolling law", "use \"none\" or \"sds\"")),
    };
    let twisting_name = law(&m.twisting, "none");
    let twisting = match twisting_name.as_str() {
        "none" => TwistingLaw::None,
        "oquendo" => TwistingLaw::Oquendo,
        other => return Err(c.invalid("model.twisting", format!("\"{other}\""), "unknown twisting law", "use \"none\" or \"oquendo\"")),
    };
    let cohesion_name = law(&m.cohesion, "none");
    let cohesion = match cohesion_name.as_str() {
        "none" => {
            for (k, set) in [("surface_tension", m.surface_tension.is_some()), ("contact_angle", m.contact_angle.is_some()), ("liquid_density", m.liquid_density.is_some())] {
                unused(k, set, "cohesion = \"none\"")?;
            }
            CohesionLaw::None
        }
        "capillary" => {
            let gamma_s = positive(c, "model.surface_tension", m.surface_tension.unwrap_or(DEFAULT_SURFACE_TENSION), "give the surface tension in N/m, e.g. 0.0728 for water")?;
            let theta = m.contact_angle.unwrap_or(0.0);
            if !(0.0..90.0).contains(&theta) {
                return Err(c.invalid("model.contact_angle", theta, "must lie in [0, 90) degrees for an attractive bridge", "give the contact angle in degrees, e.g. 0"));
            }
            let theta = theta.to_radians();
            CohesionLaw::Capillary { kappa: 2.0 * std::f64::consts::PI * gamma_s * theta.cos(), theta, c: CAPILLARY_C }
        }
        other => return Err(c.invalid("model.cohesion", format!("\"{other}\""), "unknown cohesion law", "use \"none\" or \"capillary\"")),
    };
    Ok(ContactModel { normal, damping, tangential, rolling, twisting, cohesion, limit_damping: m.limit_damping.unwrap_or(true) })
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
                return Err(c.invalid("contact_dynamics.tolerance", tolerance, "must lie in (0, 1)", "give a relative change such as 1e-6"));
            }
            let max_iterations = given.max_iterations.unwrap_or(CdParams::default().max_iterations);
            if max_iterations == 0 {
                return Err(c.invalid("contact_dynamics.max_iterations", 0, "must be at least 1", "give a number of sweeps, e.g. 1000"));
            }
            let gap_allowance = match given.gap_allowance {
                Some(v) => non_negative(c, "contact_dynamics.gap_allowance", v, "give a length in metres, e.g. 0.1 x the mean diameter")?,
                None => 0.1 * d_mean,
            };
            let wall_mass = given.wall_mass.map(|m| positive(c, "contact_dynamics.wall_mass", m, "give a mass in kg, or leave it out for the grains' total mass")).transpose()?;
            Ok(Method::ContactDynamics(CdParams { theta, tolerance, max_iterations, gap_allowance, wall_mass }))
        }
        other => Err(c.invalid("simulation.method", format!("\"{other}\""), "unknown method", "use \"dem\" or \"contact_dynamics\"")),
    }
}
