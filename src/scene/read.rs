//! `[[read]]`: grains from LAMMPS / LIGGGHTS files, in the order of their atom ids, each atom
//! type mapped to a material by the table's `types`.

use super::error::Complainer;
use super::schema::ReadSpec;
use super::{sphere_mass, Grains, Material, SceneError};
use crate::lammps::{self, Atoms};
use std::path::PathBuf;

/// Relative difference between a file's density and its material's above which a warning
/// says the masses follow the file.
const DENSITY_MISMATCH: f64 = 1e-6;

/// The file of `spec`, relative to the scene file's folder.
pub(super) fn path(c: &Complainer, spec: &ReadSpec) -> PathBuf {
    c.file.parent().unwrap_or(std::path::Path::new("")).join(&spec.file)
}

/// Reads the grains of `read[k]` and appends them to `grains`. Masses come from the file's
/// densities (data files) or masses (dumps with a `mass` column), else from the material's
/// density.
pub(super) fn grains(
    c: &Complainer,
    k: usize,
    spec: &ReadSpec,
    materials: &[Material],
    material_of: &dyn Fn(String, &str) -> Result<u16, SceneError>,
    grains: &mut Grains,
    warnings: &mut Vec<String>,
) -> Result<usize, SceneError> {
    let key = |s: &str| format!("read[{k}].{s}");
    let file = path(c, spec);
    let atoms: Atoms = match spec.format.as_str() {
        "lammps-data" => {
            if spec.step.is_some() {
                return Err(c.invalid(key("step"), spec.step.unwrap_or(0), "a data file holds one snapshot", "remove `step`"));
            }
            lammps::data::read(&file)
        }
        "lammps-dump" => lammps::dump::read(&file, spec.step),
        other => return Err(c.invalid(key("format"), format!("\"{other}\""), "unknown grain file format", "use \"lammps-data\" or \"lammps-dump\"")),
    }
    .map_err(|source| SceneError::GrainFile { file: c.file.to_path_buf(), key: key("file"), source: Box::new(source) })?;
    let mut material_of_type = std::collections::HashMap::new();
    for (t, name) in &spec.types {
        let number: u32 = t.parse().map_err(|_| c.invalid(key("types"), format!("\"{t}\""), "is not an atom type number", "key the table by type numbers, e.g. { 1 = \"sand\" }"))?;
        material_of_type.insert(number, material_of(key(&format!("types.{t}")), name)?);
    }
    let mut order: Vec<usize> = (0..atoms.len()).collect();
    order.sort_by_key(|&i| atoms.id[i]);
    let mut mismatch = None;
    for &i in &order {
        let t = atoms.kind[i];
        let m = *material_of_type.get(&t).ok_or_else(|| {
            c.invalid(key("types"), format!("{:?}", spec.types.keys().collect::<Vec<_>>()), format!("maps no material to atom type {t} of {} (atom {})", file.display(), atoms.id[i]), format!("add `{t} = \"MATERIAL\"` to read[{k}].types"))
        })?;
        let r = atoms.radius[i];
        let material_density = materials[m as usize].density;
        let mass = match (&atoms.mass, &atoms.density, material_density) {
            (Some(mass), _, _) => mass[i],
            (None, Some(rho), own) => {
                if own.is_some_and(|d| ((rho[i] - d) / d).abs() > DENSITY_MISMATCH) {
                    mismatch.get_or_insert((rho[i], own.unwrap_or(0.0), materials[m as usize].name.clone()));
                }
                sphere_mass(r, rho[i])
            }
            (None, None, Some(d)) => sphere_mass(r, d),
            (None, None, None) => {
                return Err(c.invalid(key("types"), format!("\"{}\"", materials[m as usize].name), "the file gives no masses and the material no density", "add `density` (kg/m^3) to that [[material]]"));
            }
        };
        grains.push(r, mass, atoms.position[i].into(), atoms.velocity[i].into(), atoms.angular_velocity[i].into(), m);
    }
    if let Some((file_rho, own, name)) = mismatch {
        warnings.push(format!("{}: read[{k}]: the file's density {file_rho} kg/m^3 differs from material \"{name}\"'s {own} kg/m^3; the masses follow the file", c.file.display()));
    }
    Ok(atoms.len())
}
