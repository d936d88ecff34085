//! LAMMPS / LIGGGHTS text dumps of `dump custom`: snapshots of `ITEM: TIMESTEP`, `ITEM: NUMBER
//! OF ATOMS`, `ITEM: BOX BOUNDS` and `ITEM: ATOMS` with named columns. Read: `id`, `type`,
//! the centre (`x y z`, unwrapped `xu yu zu` or scaled `xs ys zs`), `radius` or `diameter`;
//! optional `vx vy vz`, `omegax omegay omegaz`, `mass`, `density`; other columns are skipped.

use super::{read_text, Atoms, FileError, Reader};
use std::fmt::Write as _;
use std::path::Path;

/// The columns [`write`] gives, in order.
pub const COLUMNS: &str = "id type x y z radius mass vx vy vz omegax omegay omegaz";

/// Reads the snapshot of time step `step` of a dump (the last one when `None`).
pub fn read(path: &Path, step: Option<u64>) -> Result<Atoms, FileError> {
    parse(path, &read_text(path)?, step)
}

/// Parses dump text as if read from `path`.
pub fn parse(path: &Path, text: &str, step: Option<u64>) -> Result<Atoms, FileError> {
    let r = Reader { file: path };
    let lines: Vec<&str> = text.lines().collect();
    let mut chosen = None;
    let mut steps = Vec::new();
    let mut k = 0;
    while k < lines.len() {
        if lines[k].trim().is_empty() {
            k += 1;
            continue;
        }
        let (atoms, next) = snapshot(&r, &lines, k)?;
        steps.push(atoms.timestep);
        if step.is_none_or(|s| s == atoms.timestep) {
            chosen = Some(atoms);
        }
        k = next;
    }
    chosen.ok_or_else(|| match step {
        Some(s) => r.error(None, format!("no snapshot of time step {s} (the file holds {steps:?})"), "give one of those steps"),
        None => r.error(None, "no snapshot", "give a dump custom file"),
    })
}

/// Reads the snapshot that starts at 0-based line `k`; returns it and the line after it.
fn snapshot(r: &Reader, lines: &[&str], mut k: usize) -> Result<(Atoms, usize), FileError> {
    let item = |k: usize, want: &str| -> Result<(), FileError> {
        if lines.get(k).is_some_and(|l| l.trim_start().starts_with(want)) {
            Ok(())
        } else {
            Err(r.error(Some(k + 1), format!("expected `{want}`, found `{}`", lines.get(k).map_or("the end of the file", |l| l.trim())), "give the snapshot's ITEM lines in dump custom's order"))
        }
    };
    let words = |k: usize| -> Vec<&str> { lines.get(k).map_or(Vec::new(), |l| l.split_whitespace().collect()) };
    let mut atoms = Atoms::default();
    item(k, "ITEM: TIMESTEP")?;
    atoms.timestep = r.number(k + 2, &words(k + 1), 0, "timestep")?;
    item(k + 2, "ITEM: NUMBER OF ATOMS")?;
    let n: usize = r.number(k + 4, &words(k + 3), 0, "number of atoms")?;
    item(k + 4, "ITEM: BOX BOUNDS")?;
    let flags: Vec<&str> = words(k + 4).into_iter().skip(3).collect();
    if flags.iter().any(|f| ["xy", "xz", "yz"].contains(f)) {
        return Err(r.error(Some(k + 5), "a triclinic box", "dump the packing in an orthogonal box"));
    }
    for a in 0..3 {
        atoms.periodic[a] = flags.get(a).is_some_and(|f| *f == "pp");
        atoms.bounds[a] = [r.number(k + 6 + a, &words(k + 5 + a), 0, "lo")?, r.number(k + 6 + a, &words(k + 5 + a), 1, "hi")?];
    }
    k += 8;
    item(k, "ITEM: ATOMS")?;
    let names: Vec<&str> = words(k).into_iter().skip(2).collect();
    let column = |name: &str| names.iter().position(|c| *c == name);
    let need = |options: &[&str]| -> Result<(usize, String), FileError> {
        options.iter().find_map(|o| column(o).map(|c| (c, o.to_string()))).ok_or_else(|| r.error(Some(k + 1), format!("no `{}` column (the columns: {})", options.join("` or `"), names.join(" ")), format!("dump with `{}` among the columns", options[0])))
    };
    let id = need(&["id"])?.0;
    let kind = need(&["type"])?.0;
    let centre: Vec<(usize, String)> = ["x", "y", "z"].iter().map(|a| need(&[a, &format!("{a}u"), &format!("{a}s")])).collect::<Result<_, _>>()?;
    let (size, size_name) = need(&["radius", "diameter"])?;
    let optional3 = |names: [&str; 3]| names.map(column);
    let (vel, omega) = (optional3(["vx", "vy", "vz"]), optional3(["omegax", "omegay", "omegaz"]));
    let (mass, density) = (column("mass"), column("density"));
    let mut masses = Vec::new();
    let mut densities = Vec::new();
    for line in k + 1..k + 1 + n {
        let w = words(line);
        if w.is_empty() || w[0] == "ITEM:" {
            return Err(r.error(Some(line + 1), format!("the snapshot holds fewer than its {n} atoms"), "give one line per atom"));
        }
        let at = line + 1;
        atoms.id.push(r.number(at, &w, id, "id")?);
        atoms.kind.push(r.number(at, &w, kind, "type")?);
        let s: f64 = r.number(at, &w, size, &size_name)?;
        if !(s > 0.0) {
            return Err(FileError { file: r.file.to_path_buf(), line: Some(at), column: Some((size + 1, size_name)), problem: format!("{s} is not a positive size"), fix: "give every atom its sphere's size in metres".into() });
        }
        atoms.radius.push(if size_name == "diameter" { 0.5 * s } else { s });
        let mut p = [0.0; 3];
        for a in 0..3 {
            let (c, name) = &centre[a];
            let x: f64 = r.number(at, &w, *c, name)?;
            let [lo, hi] = atoms.bounds[a];
            p[a] = if name.ends_with('s') { lo + x * (hi - lo) } else { x };
        }
        atoms.position.push(p);
        let read3 = |cols: [Option<usize>; 3], names: [&str; 3]| -> Result<[f64; 3], FileError> {
            let mut v = [0.0; 3];
            for a in 0..3 {
                if let Some(c) = cols[a] {
                    v[a] = r.number(at, &w, c, names[a])?;
                }
            }
            Ok(v)
        };
        atoms.velocity.push(read3(vel, ["vx", "vy", "vz"])?);
        atoms.angular_velocity.push(read3(omega, ["omegax", "omegay", "omegaz"])?);
        if let Some(c) = mass {
            masses.push(r.number(at, &w, c, "mass")?);
        }
        if let Some(c) = density {
            densities.push(r.number(at, &w, c, "density")?);
        }
    }
    atoms.mass = mass.map(|_| masses);
    atoms.density = density.map(|_| densities);
    Ok((atoms, k + 1 + n))
}

/// One snapshot of `atoms` (which need masses) at time step `atoms.timestep`, with the
/// columns [`COLUMNS`].
pub fn write(atoms: &Atoms) -> String {
    let flags: Vec<&str> = atoms.periodic.iter().map(|&p| if p { "pp" } else { "ff" }).collect();
    let mut s = format!("ITEM: TIMESTEP\n{}\nITEM: NUMBER OF ATOMS\n{}\nITEM: BOX BOUNDS {}\n", atoms.timestep, atoms.len(), flags.join(" "));
    for b in &atoms.bounds {
        let _ = writeln!(s, "{:e} {:e}", b[0], b[1]);
    }
    let _ = writeln!(s, "ITEM: ATOMS {COLUMNS}");
    let mass = atoms.mass.as_deref().unwrap_or(&[]);
    for (i, m) in mass.iter().enumerate() {
        let (p, v, w) = (atoms.position[i], atoms.velocity[i], atoms.angular_velocity[i]);
        let _ = writeln!(
            s,
            "{} {} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e}",
            atoms.id[i], atoms.kind[i], p[0], p[1], p[2], atoms.radius[i], m, v[0], v[1], v[2], w[0], w[1], w[2]
        );
    }
    s
}
