//! `[[stage]]` tables into the host loop's program: each kind's keys, settle criteria and
//! targets checked against the scene's walls and gravity.

use super::*;
use super::wall_specs::stage_drives;

#[allow(clippy::too_many_arguments)]
pub(super) fn validate_stages(
    c: &Complainer,
    specs: &[StageSpec],
    presence: &[Vec<(usize, bool)>],
    grains: &Grains,
    gravity: glam::DVec3,
    d_mean: f64,
    walls: &[Wall],
    servo: Option<ServoBox>,
    liquid_density: f64,
) -> Result<Vec<Stage>, SceneError> {
    let has_servo = servo.is_some();
    let g = (gravity[0] * gravity[0] + gravity[1] * gravity[1] + gravity[2] * gravity[2]).sqrt();
    let m_mean = grains.mass.iter().sum::<f64>() / grains.len() as f64;
    let has_piston = walls.iter().any(|w| matches!(w.shape, WallShape::Piston { .. }));
    let mut out = Vec::new();
    for (i, s) in specs.iter().enumerate() {
        let key = |k: &str| format!("stage[{i}].{k}");
        let oedometer = s.kind == "oedometer";
        let kind = match s.kind.as_str() {
            "fill" => StageKind::Fill,
            "settle" | "oedometer" => StageKind::Settle,
            "run" => StageKind::Run,
            other => return Err(c.invalid(key("kind"), format!("\"{other}\""), "unknown stage kind", "use \"fill\", \"settle\", \"run\" or \"oedometer\"")),
        };
        let duration = positive(c, &key("duration"), s.duration, "give the (longest) stage time in seconds")?;
        if kind == StageKind::Fill && g == 0.0 {
            return Err(c.invalid(key("kind"), "\"fill\"", "deposition needs gravity", "set simulation.gravity or use kind = \"settle\""));
        }
        if kind == StageKind::Run {
            for (k, set) in [("ke_per_grain", s.ke_per_grain.is_some()), ("ke_ratio", s.ke_ratio.is_some()), ("unbalanced_force", s.unbalanced_force.is_some()), ("pressure_tolerance", s.pressure_tolerance.is_some())] {
                if set {
                    return Err(c.invalid(key(k), "(set)", "is a settle criterion; a \"run\" stage ends after its duration", format!("remove `{k}` or use kind = \"settle\"")));
                }
            }
        }
        if !oedometer {
            for (k, set) in [("p0", s.p0.is_some()), ("p_max", s.p_max.is_some()), ("factor", s.factor.is_some()), ("seating_pressure", s.seating_pressure.is_some())] {
                if set {
                    return Err(c.invalid(key(k), "(set)", "belongs to kind = \"oedometer\"", format!("remove `{k}` or use kind = \"oedometer\"")));
                }
            }
        }
        if s.ke_per_grain.is_some() && s.ke_ratio.is_some() {
            return Err(c.invalid(key("ke_ratio"), "(set)", "replaces ke_per_grain, which is set too", "keep one of `ke_per_grain` (J per grain) and `ke_ratio` (kinetic over elastic energy)"));
        }
        let ke_ratio = s.ke_ratio.map(|r| positive(c, &key("ke_ratio"), r, "give a ratio such as 1e-4")).transpose()?;
        let ke_per_grain = match s.ke_per_grain {
            Some(v) => positive(c, &key("ke_per_grain"), v, "give an energy in J")?,
            None if kind == StageKind::Run || ke_ratio.is_some() => 0.0,
            None if g > 0.0 => {
                let v = DEFAULT_SETTLE_SPEED_FRACTION * (g * d_mean).sqrt();
                0.5 * m_mean * v * v
            }
            None => return Err(c.invalid(key("ke_per_grain"), "(missing)", "has no default without gravity", "give the settled kinetic energy per grain in J")),
        };
        let unbalanced_force = match s.unbalanced_force {
            Some(v) => positive(c, &key("unbalanced_force"), v, "give a ratio such as 0.01")?,
            None => DEFAULT_UNBALANCED_FORCE,
        };
        let pressure_tolerance = positive(c, &key("pressure_tolerance"), s.pressure_tolerance.unwrap_or(DEFAULT_PRESSURE_TOLERANCE), "give a fraction such as 0.01")?;
        if (s.piston_pressure.is_some() || oedometer) && !has_piston {
            let k = if oedometer { "kind" } else { "piston_pressure" };
            return Err(c.invalid(key(k), "(set)", "the scene has no piston", "add a [[wall]] with type = \"piston\""));
        }
        let base = Stage {
            name: s.name.clone().unwrap_or_else(|| format!("{}{}", s.kind, i)),
            kind,
            duration,
            ke_per_grain,
            ke_ratio,
            unbalanced_force,
            piston_pressure: s.piston_pressure.map(|p| non_negative(c, &key("piston_pressure"), p, "give the pressure in Pa")).transpose()?,
            pressure_tolerance,
            lower_piston: false,
            records_compression: false,
            seating: false,
            servo_pressure: match s.servo_pressure {
                Some(_) if !has_servo => return Err(c.invalid(key("servo_pressure"), "(set)", "the scene has no servo box", "add a [[wall]] with type = \"servo_box\" or remove the key")),
                Some(p) => Some(non_negative(c, &key("servo_pressure"), p, "give the pressure in Pa")?),
                None => None,
            },
            axial_strain_rate: match s.axial_strain_rate {
                Some(_) if !has_servo => return Err(c.invalid(key("axial_strain_rate"), "(set)", "the scene has no servo box", "add a [[wall]] with type = \"servo_box\" or remove the key")),
                Some(r) if !r.is_finite() => return Err(c.invalid(key("axial_strain_rate"), r, "must be finite", "give a strain rate in 1/s, positive to compress")),
                other => other,
            },
            walls: stage_drives(c, i, &s.walls, walls, servo)?,
            presence: presence[i].clone(),
            wet_volume: match s.water_content {
                Some(w) => Some(positive(c, &key("water_content"), w, "give the gravimetric water content, e.g. 0.007")? * grains.mass.iter().sum::<f64>() / liquid_density),
                None => None,
            },
        };
        if !oedometer {
            out.push(base);
            continue;
        }
        if s.piston_pressure.is_some() {
            return Err(c.invalid(key("piston_pressure"), "(set)", "an oedometer sets the pressure itself from p0 to p_max", "remove `piston_pressure`"));
        }
        let need = |k: &str, v: Option<f64>| match v {
            Some(x) => positive(c, &key(k), x, "give a pressure in Pa"),
            None => Err(c.invalid(key(k), "(missing)", "is required by kind = \"oedometer\"", "give a pressure in Pa, e.g. p0 = 1e4 and p_max = 1.28e6")),
        };
        let (p0, p_max) = (need("p0", s.p0)?, need("p_max", s.p_max)?);
        if p_max < p0 {
            return Err(c.invalid(key("p_max"), p_max, format!("is below p0 = {p0}"), "give p_max >= p0"));
        }
        let factor = s.factor.unwrap_or(DEFAULT_OEDOMETER_FACTOR);
        if !(factor > 1.0 && factor.is_finite()) {
            return Err(c.invalid(key("factor"), factor, "must exceed 1", "give a multiplier such as 2"));
        }
        let mut first = true;
        if let Some(seat) = s.seating_pressure {
            let seat = positive(c, &key("seating_pressure"), seat, "give a small pressure in Pa, below p0")?;
            if seat >= p0 {
                return Err(c.invalid(key("seating_pressure"), seat, format!("is not below p0 = {p0}"), "give a seating load below the first pressure, e.g. p0 / 10"));
            }
            out.push(Stage {
                name: format!("{}@seat {}", base.name, pressure_label(seat)),
                piston_pressure: Some(seat),
                lower_piston: true,
                records_compression: true,
                seating: true,
                presence: if first { base.presence.clone() } else { Vec::new() },
                ..base.clone()
            });
            first = false;
        }
        let mut p = p0;
        while p <= p_max * (1.0 + 1e-12) {
            out.push(Stage {
                name: format!("{}@{}", base.name, pressure_label(p)),
                piston_pressure: Some(p),
                lower_piston: first,
                records_compression: true,
                wet_volume: if first { base.wet_volume } else { None },
                presence: if first { base.presence.clone() } else { Vec::new() },
                ..base.clone()
            });
            first = false;
            p *= factor;
        }
    }
    if out.is_empty() {
        return Err(c.invalid("stage", "[]", "the scene has no [[stage]]", "add e.g. [[stage]] kind = \"run\" duration = 1e-3"));
    }
    Ok(out)
}

/// `10kPa`, `1.28MPa`: a pressure for stage names.
pub fn pressure_label(p: f64) -> String {
    if p >= 1e6 {
        format!("{}MPa", (p / 1e6 * 1000.0).round() / 1000.0)
    } else if p >= 1e3 {
        format!("{}kPa", (p / 1e3 * 1000.0).round() / 1000.0)
    } else {
        format!("{}Pa", (p * 1000.0).round() / 1000.0)
    }
}
