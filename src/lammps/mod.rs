//! LAMMPS and LIGGGHTS files of spherical grains, read and written: data files of
//! `atom_style sphere` ([`data`]) and text dumps of `dump custom` ([`dump`]).
//!
//! Units: SI (LAMMPS' `units si`: m, kg, s, rad/s) in and out; a file in other units must be
//! converted first. Numbers are written in the shortest form that reads back to the same
//! `f64`, so a file read back by LAMMPS or by grains holds the same bits.

pub mod data;
pub mod dump;

use std::path::{Path, PathBuf};

/// Spherical atoms as LAMMPS files hold them, in file order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Atoms {
    /// Atom ids (LAMMPS' are 1-based).
    pub id: Vec<u64>,
    /// Atom types (1-based).
    pub kind: Vec<u32>,
    /// Radii (m).
    pub radius: Vec<f64>,
    /// Mass densities (kg/m^3), when the file gives them.
    pub density: Option<Vec<f64>>,
    /// Masses (kg), when the file gives them.
    pub mass: Option<Vec<f64>>,
    /// Centres (m).
    pub position: Vec<[f64; 3]>,
    /// Velocities (m/s); zero where the file gives none.
    pub velocity: Vec<[f64; 3]>,
    /// Angular velocities (rad/s); zero where the file gives none.
    pub angular_velocity: Vec<[f64; 3]>,
    /// The box's `[lo, hi]` along x, y and z (m).
    pub bounds: [[f64; 2]; 3],
    /// Whether each axis is periodic (dumps say so; data files do not, and read as false).
    pub periodic: [bool; 3],
    /// The time step number the file was written at (0 when it gives none).
    pub timestep: u64,
}

impl Atoms {
    /// Number of atoms.
    pub fn len(&self) -> usize {
        self.id.len()
    }
    /// True without atoms.
    pub fn is_empty(&self) -> bool {
        self.id.is_empty()
    }
}

/// Why a LAMMPS file was refused: one line naming the file, the line, the column and the fix.
#[derive(Debug, thiserror::Error)]
#[error("{}{}{}: {problem}; fix: {fix}", file.display(), line.map_or(String::new(), |l| format!(" line {l}")), column.as_ref().map_or(String::new(), |(c, name)| format!(", column {c} ({name})")))]
pub struct FileError {
    /// The file.
    pub file: PathBuf,
    /// 1-based line, when the problem has one.
    pub line: Option<usize>,
    /// 1-based column and its name, when the problem is one value.
    pub column: Option<(usize, String)>,
    /// What is wrong.
    pub problem: String,
    /// How to fix it.
    pub fix: String,
}

/// Locates problems in one file.
struct Reader<'a> {
    file: &'a Path,
}

impl Reader<'_> {
    fn error(&self, line: Option<usize>, problem: impl Into<String>, fix: impl Into<String>) -> FileError {
        FileError { file: self.file.to_path_buf(), line, column: None, problem: problem.into(), fix: fix.into() }
    }

    /// Value `column` (0-based) of `words` on 1-based line `line`, named `name`.
    fn number<T: std::str::FromStr>(&self, line: usize, words: &[&str], column: usize, name: &str) -> Result<T, FileError> {
        let at = Some((column + 1, name.to_string()));
        let Some(word) = words.get(column) else {
            return Err(FileError { file: self.file.to_path_buf(), line: Some(line), column: at, problem: format!("the line has {} values, this column is missing", words.len()), fix: "give every column the section or ITEM line names".into() });
        };
        word.parse().map_err(|_| FileError { file: self.file.to_path_buf(), line: Some(line), column: at, problem: format!("`{word}` is not a number"), fix: "correct the value".into() })
    }

    /// Three values from `first`, named `names`.
    fn triple(&self, line: usize, words: &[&str], first: usize, names: [&str; 3]) -> Result<[f64; 3], FileError> {
        Ok([self.number(line, words, first, names[0])?, self.number(line, words, first + 1, names[1])?, self.number(line, words, first + 2, names[2])?])
    }
}

/// Reads `path` to text.
fn read_text(path: &Path) -> Result<String, FileError> {
    std::fs::read_to_string(path).map_err(|e| FileError { file: path.to_path_buf(), line: None, column: None, problem: format!("cannot read it: {e}"), fix: "check the path (relative paths start at the scene file's folder)".into() })
}
