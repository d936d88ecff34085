//! MCAP recording of frames, readable by Foxglove.
//!
//! Two channels, both JSON-encoded with a JSON Schema:
//! * `/grains`, schema `grains.Frame`: the [`Frame`] as serialised by serde (time in s, ids,
//!   positions, radii, velocities, angular velocities in SI units; orientation quaternions
//!   scalar first when tracked; contact records when asked for).
//! * `/scene`, schema `foxglove.SceneUpdate`: one sphere primitive per grain, so that
//!   Foxglove's 3D panel draws the grains with no set-up (frame id `world`, metres).
//!
//! Message log times are simulated times in nanoseconds.

use crate::engine::Frame;
use anyhow::Context;
use serde_json::json;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

const FRAME_SCHEMA: &str = r#"{"type":"object","title":"grains.Frame","properties":{"time":{"type":"number","description":"simulated time (s)"},"id":{"type":"array","items":{"type":"integer"}},"position":{"type":"array","description":"centres (m)","items":{"type":"array","items":{"type":"number"}}},"radius":{"type":"array","description":"radii (m)","items":{"type":"number"}},"velocity":{"type":"array","description":"m/s","items":{"type":"array","items":{"type":"number"}}},"angular_velocity":{"type":"array","description":"rad/s","items":{"type":"array","items":{"type":"number"}}},"orientation":{"type":["array","null"],"description":"quaternions, scalar first"},"contacts":{"type":["array","null"],"description":"touching pairs: i, j, overlap (m), normal_force (N), force on i (N), tangential_spring (m), rolling_spring (m)"}}}"#;

const SCENE_SCHEMA: &str = r#"{"type":"object","title":"foxglove.SceneUpdate","properties":{"deletions":{"type":"array"},"entities":{"type":"array"}}}"#;

/// Writes frames to an MCAP file.
pub struct McapRecorder {
    writer: mcap::Writer<BufWriter<File>>,
    frames: u16,
    scene: u16,
    sequence: u32,
}

impl McapRecorder {
    /// Creates `path` and declares the channels.
    pub fn create(path: &Path) -> anyhow::Result<Self> {
        let file = File::create(path).with_context(|| format!("cannot create {}", path.display()))?;
        let mut writer = mcap::WriteOptions::new().profile("").library("grains").create(BufWriter::new(file))?;
        let no_meta = BTreeMap::new();
        let fs = writer.add_schema("grains.Frame", "jsonschema", FRAME_SCHEMA.as_bytes())?;
        let frames = writer.add_channel(fs, "/grains", "json", &no_meta)?;
        let ss = writer.add_schema("foxglove.SceneUpdate", "jsonschema", SCENE_SCHEMA.as_bytes())?;
        let scene = writer.add_channel(ss, "/scene", "json", &no_meta)?;
        Ok(McapRecorder { writer, frames, scene, sequence: 0 })
    }

    /// Appends one frame to both channels.
    pub fn write(&mut self, f: &Frame) -> anyhow::Result<()> {
        let t = (f.time * 1e9).round() as u64;
        let header = |channel_id, sequence| mcap::records::MessageHeader { channel_id, sequence, log_time: t, publish_time: t };
        self.writer.write_to_known_channel(&header(self.frames, self.sequence), &serde_json::to_vec(f)?)?;
        self.writer.write_to_known_channel(&header(self.scene, self.sequence), &serde_json::to_vec(&scene_update(f))?)?;
        self.sequence += 1;
        Ok(())
    }

    /// Writes the summary section and closes the file.
    pub fn finish(mut self) -> anyhow::Result<()> {
        self.writer.finish()?;
        Ok(())
    }
}

/// A `foxglove.SceneUpdate` with one sphere per grain, coloured by speed (blue at rest, red
/// at the frame's fastest).
fn scene_update(f: &Frame) -> serde_json::Value {
    let speed = |v: &glam::DVec3| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let v_max = f.velocity.iter().map(speed).fold(0.0, f64::max).max(1e-30);
    let spheres: Vec<_> = (0..f.position.len())
        .map(|i| {
            let p = f.position[i];
            let d = 2.0 * f.radius[i];
            let s = speed(&f.velocity[i]) / v_max;
            json!({
                "pose": {"position": {"x": p[0], "y": p[1], "z": p[2]}, "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}},
                "size": {"x": d, "y": d, "z": d},
                "color": {"r": s, "g": 0.3, "b": 1.0 - s, "a": 1.0}
            })
        })
        .collect();
    let sec = f.time.floor();
    json!({
        "deletions": [],
        "entities": [{
            "timestamp": {"sec": sec as u64, "nsec": ((f.time - sec) * 1e9) as u32},
            "frame_id": "world",
            "id": "grains",
            "lifetime": {"sec": 0, "nsec": 0},
            "frame_locked": false,
            "metadata": [],
            "arrows": [], "cubes": [], "spheres": spheres, "cylinders": [], "lines": [], "triangles": [], "texts": [], "models": []
        }]
    })
}

/// The last `/grains` frame of a recording.
pub fn last_frame(path: &Path) -> anyhow::Result<Frame> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut last = None;
    for m in ::mcap::MessageStream::new(&bytes).with_context(|| format!("{}: not an MCAP file", path.display()))? {
        let m = m.with_context(|| format!("{}: damaged", path.display()))?;
        if m.channel.topic == "/grains" {
            last = Some(m.data.into_owned());
        }
    }
    let data = last.with_context(|| format!("{}: no /grains frame", path.display()))?;
    Ok(serde_json::from_slice(&data)?)
}
