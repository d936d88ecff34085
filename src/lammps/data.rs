//! LAMMPS data files of `atom_style sphere`: the header's atom count, type count and box, the
//! `Atoms # sphere` section (`id type diameter density x y z`, image flags optional) and the
//! `Velocities` section (`id vx vy vz wx wy wz`). Other sections (Masses, coefficients) are
//! skipped.

use super::{read_text, Atoms, FileError, Reader};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

/// Reads a data file.
pub fn read(path: &Path) -> Result<Atoms, FileError> {
    parse(path, &read_text(path)?)
}

/// Parses data-file text as if read from `path`.
pub fn parse(path: &Path, text: &str) -> Result<Atoms, FileError> {
    let r = Reader { file: path };
    let mut atoms = Atoms::default();
    let mut count: Option<usize> = None;
    let mut bounds: [Option<[f64; 2]>; 3] = [None; 3];
    let mut section: Option<String> = None;
    let mut index_of: HashMap<u64, usize> = HashMap::new();
    let mut velocities = 0usize;
    let mut density = Vec::new();
    // The first line is the title.
    for (k, raw) in text.lines().enumerate().skip(1) {
        let line = k + 1;
        let (body, comment) = raw.split_once('#').map_or((raw, ""), |(b, c)| (b, c.trim()));
        let words: Vec<&str> = body.split_whitespace().collect();
        let Some(first) = words.first() else { continue };
        if first.chars().next().is_some_and(|c| c.is_ascii_alphabetic()) {
            let name = words.join(" ");
            if name == "Atoms" && !comment.is_empty() && comment != "sphere" {
                return Err(r.error(Some(line), format!("the Atoms section is of atom_style {comment}, not sphere"), "write the file from a run with atom_style sphere"));
            }
            if name == "Atoms" && count.is_none() {
                return Err(r.error(Some(line), "the Atoms section comes before the header's atom count", "give `N atoms` in the header"));
            }
            section = Some(name);
            continue;
        }
        match section.as_deref() {
            // The header: counts and the box.
            None => {
                let keyword: Vec<&str> = words.iter().copied().filter(|w| w.starts_with(|c: char| c.is_ascii_alphabetic())).collect();
                match keyword.join(" ").as_str() {
                    "atoms" => count = Some(r.number(line, &words, 0, "atoms")?),
                    "xy xz yz" => return Err(r.error(Some(line), "a triclinic box", "write the packing in an orthogonal box")),
                    axes => {
                        for (a, axis) in ["x", "y", "z"].iter().enumerate() {
                            if axes == format!("{axis}lo {axis}hi") {
                                bounds[a] = Some([r.number(line, &words, 0, &format!("{axis}lo"))?, r.number(line, &words, 1, &format!("{axis}hi"))?]);
                            }
                        }
                    }
                }
            }
            Some("Atoms") => {
                let id: u64 = r.number(line, &words, 0, "atom-ID")?;
                let diameter: f64 = r.number(line, &words, 2, "diameter")?;
                if !(diameter > 0.0) {
                    return Err(FileError { file: path.to_path_buf(), line: Some(line), column: Some((3, "diameter".into())), problem: format!("diameter {diameter} is not positive (a point particle)"), fix: "give every atom its sphere's diameter in metres".into() });
                }
                let rho: f64 = r.number(line, &words, 3, "density")?;
                if !(rho > 0.0) {
                    return Err(FileError { file: path.to_path_buf(), line: Some(line), column: Some((4, "density".into())), problem: format!("density {rho} is not positive"), fix: "give the mass density in kg/m^3".into() });
                }
                if index_of.insert(id, atoms.len()).is_some() {
                    return Err(FileError { file: path.to_path_buf(), line: Some(line), column: Some((1, "atom-ID".into())), problem: format!("atom {id} appears twice"), fix: "give every atom its own id".into() });
                }
                atoms.id.push(id);
                atoms.kind.push(r.number(line, &words, 1, "atom-type")?);
                atoms.radius.push(0.5 * diameter);
                density.push(rho);
                atoms.position.push(r.triple(line, &words, 4, ["x", "y", "z"])?);
                atoms.velocity.push([0.0; 3]);
                atoms.angular_velocity.push([0.0; 3]);
            }
            Some("Velocities") => {
                let id: u64 = r.number(line, &words, 0, "atom-ID")?;
                let Some(&i) = index_of.get(&id) else {
                    return Err(FileError { file: path.to_path_buf(), line: Some(line), column: Some((1, "atom-ID".into())), problem: format!("atom {id} has a velocity but is not in the Atoms section"), fix: "put the Atoms section first and give velocities of its atoms only".into() });
                };
                atoms.velocity[i] = r.triple(line, &words, 1, ["vx", "vy", "vz"])?;
                atoms.angular_velocity[i] = r.triple(line, &words, 4, ["wx", "wy", "wz"])?;
                velocities += 1;
            }
            Some(_) => {}
        }
    }
    let count = count.ok_or_else(|| r.error(None, "the header gives no `N atoms`", "write the file with LAMMPS' write_data"))?;
    if atoms.len() != count {
        return Err(r.error(None, format!("the header gives {count} atoms, the Atoms section holds {}", atoms.len()), "give one Atoms line per atom"));
    }
    if velocities != 0 && velocities != count {
        return Err(r.error(None, format!("the Velocities section holds {velocities} of the {count} atoms"), "give one Velocities line per atom, or none"));
    }
    for (a, axis) in ["x", "y", "z"].iter().enumerate() {
        atoms.bounds[a] = bounds[a].ok_or_else(|| r.error(None, format!("the header gives no `{axis}lo {axis}hi`"), "give the box in the header"))?;
    }
    atoms.density = Some(density);
    Ok(atoms)
}

/// The data file of `atoms` (which need densities), titled `title`.
pub fn write(atoms: &Atoms, title: &str) -> String {
    let types = atoms.kind.iter().copied().max().unwrap_or(1);
    let mut s = format!("LAMMPS data file (atom_style sphere, units si): {title}\n\n{} atoms\n{types} atom types\n\n", atoms.len());
    for (b, axis) in atoms.bounds.iter().zip(["x", "y", "z"]) {
        let _ = writeln!(s, "{:e} {:e} {axis}lo {axis}hi", b[0], b[1]);
    }
    s.push_str("\nAtoms # sphere\n\n");
    let density = atoms.density.as_deref().unwrap_or(&[]);
    for (i, rho) in density.iter().enumerate() {
        let p = atoms.position[i];
        let _ = writeln!(s, "{} {} {:e} {:e} {:e} {:e} {:e}", atoms.id[i], atoms.kind[i], 2.0 * atoms.radius[i], rho, p[0], p[1], p[2]);
    }
    s.push_str("\nVelocities\n\n");
    for i in 0..atoms.len() {
        let (v, w) = (atoms.velocity[i], atoms.angular_velocity[i]);
        let _ = writeln!(s, "{} {:e} {:e} {:e} {:e} {:e} {:e}", atoms.id[i], v[0], v[1], v[2], w[0], w[1], w[2]);
    }
    s
}
