//! Scene errors: one line naming the file, the key, the value and the fix.

use std::path::{Path, PathBuf};

/// Why a scene file was refused.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{file}: cannot read the scene: {reason}; fix: check the path")]
    Read {
        /// Scene file.
        file: PathBuf,
        /// The I/O error.
        reason: std::io::Error,
    },
    /// The TOML is malformed or has an unknown key or a value of the wrong type.
    #[error("{file} line {line}: {message}; fix: {fix}")]
    Syntax {
        /// Scene file.
        file: PathBuf,
        /// 1-based line of the offending key or value.
        line: usize,
        /// What the parser said.
        message: String,
        /// How to fix it.
        fix: String,
    },
    /// A grain file named by `[[read]]` was refused.
    #[error("{file}: {key}: {source}")]
    GrainFile {
        /// Scene file.
        file: PathBuf,
        /// The `[[read]]` table, e.g. `read[0].file`.
        key: String,
        /// What is wrong in the grain file.
        source: Box<crate::lammps::FileError>,
    },
    /// A value is out of range or inconsistent with the rest of the scene.
    #[error("{file}: {key} = {value}: {problem}; fix: {fix}")]
    Invalid {
        /// Scene file.
        file: PathBuf,
        /// Dotted path of the key, e.g. `grain[2].radius`.
        key: String,
        /// The value as given.
        value: String,
        /// What is wrong with it.
        problem: String,
        /// How to fix it.
        fix: String,
    },
}

impl SceneError {
    /// A TOML parse error, located by line.
    pub fn syntax(file: &Path, text: &str, err: &toml::de::Error) -> Self {
        let line = err.span().map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1).unwrap_or(0);
        // Name the table the key sits in: the last header above the offending line.
        let table = text.lines().take(line).filter(|l| l.trim_start().starts_with('[')).last().map(|h| format!(" in {}", h.trim()));
        let key = text.lines().nth(line.saturating_sub(1)).and_then(|l| l.split_once('=')).map(|(k, _)| format!("key `{}`: ", k.trim()));
        let message = format!("{}{}{}", key.unwrap_or_default(), err.message().replace('\n', " ").trim(), table.unwrap_or_default());
        let fix = if message.contains("unknown field") {
            "correct the key's spelling or remove it (docs/scene-reference.md lists every key)"
        } else if message.contains("missing field") {
            "add the key (docs/scene-reference.md gives its unit and meaning)"
        } else {
            "correct the value to the type docs/scene-reference.md gives"
        };
        SceneError::Syntax { file: file.to_path_buf(), line, message, fix: fix.to_string() }
    }
}

/// Builds [`SceneError::Invalid`] values for one file.
pub struct Complainer<'a> {
    /// The scene file being validated.
    pub file: &'a Path,
}

impl Complainer<'_> {
    /// An invalid value of `key`.
    pub fn invalid(&self, key: impl Into<String>, value: impl std::fmt::Display, problem: impl Into<String>, fix: impl Into<String>) -> SceneError {
        SceneError::Invalid {
            file: self.file.to_path_buf(),
            key: key.into(),
            value: value.to_string(),
            problem: problem.into(),
            fix: fix.into(),
        }
    }
}
