//! `[[inlet]]` and `[[outlet]]` validated into [`Inlet`] and [`Outlet`] ([`crate::flow`]):
//! each inlet's reservoir, the grains it will put into play, is drawn at load and appended to
//! the scene's grains out of play, so that every engine holds them from the start.

use super::error::Complainer;
use super::schema::{InletSpec, OutletSpec, RegionSpec, SceneFile, DEFAULT_FLOW_INTERVAL};
use super::{positive, sphere_mass, Grains, Inlet, Outlet, SceneError};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::ops::Range;

/// The most grains an inlet's reservoir may hold.
const MAX_RESERVOIR: usize = 10_000_000;

/// Draws each inlet's reservoir (diameters uniform in its range, until the next grain would
/// take the mass past the inlet's `mass`) and appends it to `grains`, out of play, at the
/// centre of the inlet's region. Returns each inlet's ids.
pub(super) fn reservoirs(c: &Complainer, f: &SceneFile, material_of: &dyn Fn(String, &str) -> Result<u16, SceneError>, density_of: &dyn Fn(String, u16) -> Result<f64, SceneError>, seed: u64, grains: &mut Grains) -> Result<Vec<Range<u32>>, SceneError> {
    let mut out = Vec::new();
    for (k, spec) in f.inlets.iter().enumerate() {
        let key = |s: &str| format!("inlet[{k}].{s}");
        check_name(c, f, &key("name"), &spec.name, k, true)?;
        let m = material_of(key("material"), &spec.material)?;
        let rho = density_of(key("material"), m)?;
        let d = &spec.diameter;
        super::generate::check_diameters(c, &format!("inlet[{k}]"), d)?;
        if let Err((what, size)) = spec.region.sample(0.5 * d.max, &mut ChaCha8Rng::seed_from_u64(0)) {
            return Err(c.invalid(key("region"), format!("{what} {size:e} m"), format!("cannot hold a grain of diameter {:e} m", d.max), "enlarge the region"));
        }
        positive(c, &key("mass_rate"), spec.mass_rate, "give the mass put into play per second in kg/s, e.g. 0.05")?;
        positive(c, &key("mass"), spec.mass, "give the mass to put into play in all in kg, e.g. 0.1")?;
        if !(spec.velocity.is_finite()) {
            return Err(c.invalid(key("velocity"), format!("{:?}", spec.velocity.to_array()), "must be three finite numbers", "give the grains' velocity in m/s"));
        }
        let first = grains.len();
        let mut rng = ChaCha8Rng::seed_from_u64(reservoir_seed(seed, k));
        let mut total = 0.0;
        loop {
            let r = 0.5 * if d.max > d.min { rng.random_range(d.min..d.max) } else { d.min };
            let mass = sphere_mass(r, rho);
            if total + mass > spec.mass {
                break;
            }
            if grains.len() - first == MAX_RESERVOIR {
                return Err(c.invalid(key("mass"), spec.mass, format!("is more than {MAX_RESERVOIR} grains of these diameters"), "lower the mass, or give larger grains"));
            }
            total += mass;
            grains.push_waiting(r, mass, spec.region.centre(), m);
        }
        if grains.len() == first {
            return Err(c.invalid(key("mass"), spec.mass, "is less than one grain of these diameters", "give a mass of at least one grain"));
        }
        out.push(first as u32..grains.len() as u32);
    }
    Ok(out)
}

/// The inlets (reservoirs `ids`, from [`reservoirs`]) and the outlets of `f`, their times in
/// steps of `dt` (s).
pub(super) fn inlets_and_outlets(c: &Complainer, f: &SceneFile, ids: Vec<Range<u32>>, dt: f64, seed: u64) -> Result<(Vec<Inlet>, Vec<Outlet>), SceneError> {
    let steps = |key: String, interval: Option<f64>| -> Result<u64, SceneError> {
        let t = interval.unwrap_or(DEFAULT_FLOW_INTERVAL);
        positive(c, &key, t, "give the simulated time between events in s, e.g. 0.005")?;
        Ok((t / dt).round().max(1.0) as u64)
    };
    let mut inlets = Vec::new();
    for (k, (spec, grains)) in f.inlets.iter().zip(ids).enumerate() {
        let InletSpec { name, region, mass_rate, velocity, start, interval, .. } = spec;
        if !(start.is_finite() && *start >= 0.0) {
            return Err(c.invalid(format!("inlet[{k}].start"), start, "must be zero or positive", "give the time it opens in s"));
        }
        inlets.push(Inlet {
            name: name.clone(),
            region: *region,
            mass_rate: *mass_rate,
            velocity: *velocity,
            start_step: (start / dt).round() as u64,
            every: steps(format!("inlet[{k}].interval"), *interval)?,
            grains,
            seed: reservoir_seed(seed, k) ^ 0x5851_F42D_4C95_7F2D,
        });
    }
    let mut outlets = Vec::new();
    for (k, OutletSpec { name, region, interval }) in f.outlets.iter().enumerate() {
        check_name(c, f, &format!("outlet[{k}].name"), name, k, false)?;
        check_region(c, &format!("outlet[{k}].region"), region)?;
        outlets.push(Outlet { name: name.clone(), region: *region, every: steps(format!("outlet[{k}].interval"), *interval)? });
    }
    Ok((inlets, outlets))
}

/// The seed of inlet `k`'s draws: one stream per inlet.
fn reservoir_seed(seed: u64, k: usize) -> u64 {
    seed ^ 0xD1B5_4A32_D192_ED03u64.wrapping_mul(k as u64 + 1)
}

/// A region of positive extent along each axis.
fn check_region(c: &Complainer, key: &str, region: &RegionSpec) -> Result<(), SceneError> {
    let [lo, hi] = region.bounds();
    if (0..3).all(|a| lo[a].is_finite() && hi[a].is_finite() && hi[a] > lo[a]) {
        Ok(())
    } else {
        Err(c.invalid(key, format!("{region:?}"), "must be finite and of positive size along each axis", "give min below max (a box) or a positive radius and z_min below z_max (a cylinder)"))
    }
}

/// An inlet's or outlet's name: not empty, and no other inlet or outlet's (their columns in
/// `stats.csv`).
fn check_name(c: &Complainer, f: &SceneFile, key: &str, name: &str, k: usize, inlet: bool) -> Result<(), SceneError> {
    if name.is_empty() || name.contains([',', '"', '\n']) {
        return Err(c.invalid(key, format!("\"{name}\""), "must be a name without commas or quotes", "name it, e.g. \"feed\""));
    }
    let earlier = f.inlets.iter().take(if inlet { k } else { f.inlets.len() }).map(|i| &i.name).chain(f.outlets.iter().take(if inlet { 0 } else { k }).map(|o| &o.name));
    if earlier.into_iter().any(|n| n == name) {
        return Err(c.invalid(key, format!("\"{name}\""), "is the name of an earlier inlet or outlet", "give each inlet and outlet its own name"));
    }
    Ok(())
}
