//! Checkpoints: an engine's whole state and the host loop's progress, written at stage
//! boundaries so that `grains run --resume DIR` continues a run and ends where an
//! uninterrupted run ends (bitwise on the CPU backend).
//!
//! File format (`checkpoint.grains`): the line `grains-checkpoint 1`, one line of JSON (the
//! header: scene identity, the host loop's progress, and the list of arrays with their kind
//! and length), then the arrays' raw little-endian bytes in that order. Reals are stored as
//! f64, which holds f32 exactly. A checkpoint is written to a temporary file and renamed, so
//! the file on disk is always a whole one.

pub use crate::engine::EngineState;
use anyhow::{bail, Context};
use serde::{Deserialize, Serialize};
use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;

/// The first line of a checkpoint file.
pub const MAGIC: &str = "grains-checkpoint 1";
/// The checkpoint's file name inside a run directory.
pub const FILE: &str = "checkpoint.grains";

/// What a checkpoint belongs to: resuming refuses another scene, backend or precision.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunIdentity {
    /// The scene file as given.
    pub scene_file: String,
    /// [`fnv1a`] of the scene file's text.
    pub scene_hash: u64,
    /// "cpu" or "gpu".
    pub backend: String,
    /// "f32" or "f64".
    pub precision: String,
}

/// A checkpoint's header.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CheckpointHeader {
    /// What the checkpoint belongs to.
    pub identity: RunIdentity,
    /// Where the run stands.
    pub progress: crate::protocol::Progress,
    /// The output files a resumed run continues, by name in the run directory, with their
    /// length in bytes at the checkpoint: what was written after it is cut off on resuming.
    #[serde(default)]
    pub files: Vec<(String, u64)>,
}

#[derive(Serialize, Deserialize)]
struct ArrayEntry {
    name: String,
    kind: String,
    len: usize,
}

#[derive(Serialize, Deserialize)]
struct Header<H> {
    #[serde(flatten)]
    header: H,
    arrays: Vec<ArrayEntry>,
}

/// Writes `header` and `state` to `path` (through a temporary file renamed into place).
pub fn write<H: Serialize>(path: &Path, header: &H, state: &EngineState) -> anyhow::Result<()> {
    let mut arrays: Vec<ArrayEntry> = state.reals.iter().map(|(n, v)| ArrayEntry { name: n.clone(), kind: "f64".into(), len: v.len() }).collect();
    arrays.extend(state.ints.iter().map(|(n, v)| ArrayEntry { name: n.clone(), kind: "u64".into(), len: v.len() }));
    let tmp = path.with_extension("tmp");
    let file = std::fs::File::create(&tmp).with_context(|| format!("cannot create {}", tmp.display()))?;
    let mut w = std::io::BufWriter::new(file);
    writeln!(w, "{MAGIC}")?;
    serde_json::to_writer(&mut w, &Header { header, arrays })?;
    writeln!(w)?;
    for v in state.reals.values() {
        for x in v {
            w.write_all(&x.to_le_bytes())?;
        }
    }
    for v in state.ints.values() {
        for x in v {
            w.write_all(&x.to_le_bytes())?;
        }
    }
    let file = w.into_inner().map_err(|e| e.into_error())?;
    file.sync_all()?;
    std::fs::rename(&tmp, path).with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

/// Reads a checkpoint written by [`write()`].
pub fn read<H: for<'de> Deserialize<'de>>(path: &Path) -> anyhow::Result<(H, EngineState)> {
    let file = std::fs::File::open(path).with_context(|| format!("cannot open {}; fix: give the --out directory of a run that wrote a checkpoint", path.display()))?;
    let mut r = BufReader::new(file);
    let mut line = String::new();
    r.read_line(&mut line)?;
    if line.trim_end() != MAGIC {
        bail!("{} is not a grains checkpoint (it starts with {:?})", path.display(), line.trim_end());
    }
    line.clear();
    r.read_line(&mut line)?;
    let header: Header<H> = serde_json::from_str(&line).with_context(|| format!("{}: unreadable header", path.display()))?;
    let mut state = EngineState::default();
    for a in &header.arrays {
        let mut bytes = vec![0u8; 8 * a.len];
        r.read_exact(&mut bytes).with_context(|| format!("{}: `{}` is cut short; the file is damaged", path.display(), a.name))?;
        let words = bytes.chunks_exact(8).map(|c| u64::from_le_bytes(c.try_into().expect("8 bytes")));
        match a.kind.as_str() {
            "f64" => state.put_reals(&a.name, words.map(f64::from_bits)),
            "u64" => state.put_ints(&a.name, words),
            other => bail!("{}: unknown array kind {other}", path.display()),
        }
    }
    Ok((header.header, state))
}

/// A stable 64-bit FNV-1a hash, to recognise the scene a checkpoint belongs to.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_checkpoint_reads_back_what_was_written() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(FILE);
        let mut s = EngineState::default();
        s.put_reals("x", [1.0, -0.0, f64::MIN_POSITIVE, (0.1f32) as f64]);
        s.put_ints("i", [0, u64::MAX, (-3i64) as u64]);
        write(&path, &serde_json::json!({"scene": "t"}), &s).unwrap();
        let (h, back): (serde_json::Value, EngineState) = read(&path).unwrap();
        assert_eq!(h["scene"], "t");
        assert_eq!(back.reals["x"].iter().map(|x| x.to_bits()).collect::<Vec<_>>(), s.reals["x"].iter().map(|x| x.to_bits()).collect::<Vec<_>>());
        assert_eq!(back.ints, s.ints);
    }
}
