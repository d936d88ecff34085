//! VTK XML output for ParaView: under `DIR/vtk/`, three files per frame and a `.pvd`
//! collection of each, so that ParaView plays the run and each kind is its own source:
//! * `grains_NNNNNN.vtp` / `grains.pvd`: the grains as points (one vertex cell each) with
//!   `id`, `radius` (m), `material` (index into the scene's `[[material]]` list), `velocity`
//!   (m/s), `angular_velocity` (rad/s), `force` (N, the sum of the contact forces on the
//!   grain from grains and walls; gravity not included), `coordination` (touching grains),
//!   `particle_pressure` (Pa, compression positive; with `output.analysis`) and `orientation`
//!   (quaternion, scalar first; when tracked).
//! * `contacts_NNNNNN.vtp` / `contacts.pvd`: every pair that touches or holds a liquid bridge
//!   as a line from grain i's centre towards grain j's (across a periodic boundary, to j's
//!   nearest image), with `id_i`, `id_j`, `normal_force` (N, compressive positive, capillary
//!   pull included), `tangential_force` (N, on i, the force's part across the line),
//!   `overlap` (m, negative across a gap) and `bridge_volume` (m^3).
//! * `walls_NNNNNN.vtp` / `walls.pvd`: the walls where they stand at that instant (planes and
//!   the piston as quads over the domain, the cylinder as a 64-sided mesh) with `wall` (index)
//!   and `force` (N, exerted by the grains on the wall) per polygon.
//!
//! Every real array is Float32; for exact values use `grains export` (LAMMPS files, full
//! precision). Each collection is rewritten whole after every frame, so a run that stops
//! leaves a collection of the frames it wrote.

mod walls;
pub mod xml;

pub use walls::domain;

use crate::analysis::network::particle_stresses;
use crate::analysis::sample_bounds;
use crate::engine::{Frame, Stats};
use crate::periodic::Periodic;
use crate::real::Vec3;
use crate::scene::Scene;
use anyhow::Context;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use xml::{Array, PolyData};

/// The folder of a run's output that holds the VTK files.
pub const DIR: &str = "vtk";
/// The kinds of file each frame writes, in the order of [`VtkRecorder::write`].
const KINDS: [&str; 3] = ["grains", "contacts", "walls"];

/// Writes a run's frames as VTK files.
pub struct VtkRecorder {
    dir: PathBuf,
    scene: Scene,
    /// Simulated time (s) and file number of every frame written, in order.
    written: Vec<(f64, usize)>,
    /// The last statistics read: where the servo walls stand, for particle pressures.
    stats: Stats,
    /// Bytes of the last frame's grain file, for the bytes-per-grain figure of docs/outputs.md.
    last_grain_bytes: u64,
    /// The lowest number the next file may take (after every file on disk when resumed).
    floor: usize,
}

impl VtkRecorder {
    /// Starts a run's VTK output in `out/vtk`.
    pub fn create(out: &Path, scene: &Scene) -> anyhow::Result<Self> {
        let dir = out.join(DIR);
        std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
        Ok(VtkRecorder { dir, scene: scene.clone(), written: Vec::new(), stats: Stats::default(), last_grain_bytes: 0, floor: 0 })
    }

    /// Continues the VTK output of a run resumed at simulated time `time` (s): the frames
    /// written up to then stay in the collections, the later ones (which the resumed run
    /// writes again) leave them, and file numbers go on after the highest one on disk.
    pub fn resume(out: &Path, scene: &Scene, time: f64) -> anyhow::Result<Self> {
        let mut r = Self::create(out, scene)?;
        let pvd = r.dir.join("grains.pvd");
        if pvd.exists() {
            let text = std::fs::read_to_string(&pvd).with_context(|| format!("cannot read {}", pvd.display()))?;
            let all = read_collection(&text).with_context(|| format!("{}: not a collection grains wrote", pvd.display()))?;
            r.floor = all.iter().map(|e| e.1 + 1).max().unwrap_or(0);
            r.written = all.into_iter().filter(|e| e.0 <= time).collect();
        }
        Ok(r)
    }

    /// Keeps the latest statistics (servo wall positions for the sample's box).
    pub fn stats(&mut self, s: &Stats) {
        self.stats = s.clone();
    }

    /// Writes one frame (taken with contacts) and rewrites the collections.
    pub fn write(&mut self, f: &Frame) -> anyhow::Result<()> {
        let number = self.written.last().map_or(self.floor, |e| (e.1 + 1).max(self.floor));
        let pieces = [self.grains(f), self.contacts(f), walls::piece(&self.scene, f)];
        for (kind, piece) in KINDS.iter().zip(&pieces) {
            let bytes = xml::write(&self.dir.join(file_name(kind, number)), piece)?;
            if *kind == "grains" {
                self.last_grain_bytes = bytes;
            }
        }
        self.written.push((f.time, number));
        for kind in KINDS {
            let path = self.dir.join(format!("{kind}.pvd"));
            let temp = self.dir.join(format!(".{kind}.pvd.tmp"));
            std::fs::write(&temp, collection(kind, &self.written)).with_context(|| format!("cannot write {}", temp.display()))?;
            std::fs::rename(&temp, &path).with_context(|| format!("cannot write {}", path.display()))?;
        }
        Ok(())
    }

    /// Bytes of the last grain file written.
    pub fn last_grain_bytes(&self) -> u64 {
        self.last_grain_bytes
    }

    fn grains(&self, f: &Frame) -> PolyData {
        let n = f.position.len();
        let mut force = vec![[0.0f64; 3]; n];
        let mut coordination = vec![0i64; n];
        let add = |acc: &mut [f64; 3], v: [f64; 3]| (0..3).for_each(|a| acc[a] += v[a]);
        for c in f.contacts.as_deref().unwrap_or(&[]) {
            add(&mut force[c.i as usize], c.force.to_array());
            add(&mut force[c.j as usize], c.force_j.to_array());
            if c.overlap > 0.0 {
                coordination[c.i as usize] += 1;
                coordination[c.j as usize] += 1;
            }
        }
        for w in f.wall_contacts.as_deref().unwrap_or(&[]) {
            add(&mut force[w.grain as usize], w.force.to_array());
        }
        let mut piece = PolyData { points: f.position.iter().map(|p| p.to_array()).collect(), ..PolyData::default() };
        for i in 0..n {
            piece.verts.push([i]);
        }
        let material = |id: u32| self.scene.grains.material.get(id as usize).copied().unwrap_or(0) as i64;
        let mut data = vec![
            Array::integers("id", f.id.iter().map(|&i| i as i64)),
            Array::scalars("radius", f.radius.iter().copied()),
            Array::integers("material", f.id.iter().map(|&i| material(i))),
            Array::vectors("velocity", f.velocity.iter().map(|v| v.to_array())),
            Array::vectors("angular_velocity", f.angular_velocity.iter().map(|w| w.to_array())),
            Array::vectors("force", force),
            Array::integers("coordination", coordination),
        ];
        // The servo box's walls bound the sample once a statistics read has said where.
        if self.scene.output.analysis && (self.scene.servo.is_none() || !self.stats.walls.is_empty()) {
            let p = particle_stresses(f, &Periodic::of(&self.scene.periodic), sample_bounds(&self.scene, &self.stats, f));
            data.push(Array::scalars("particle_pressure", p.pressures));
        }
        if let Some(q) = &f.orientation {
            data.push(Array::vectors("orientation", q.iter().map(|q| [q.w, q.x, q.y, q.z])));
        }
        piece.point_data = data;
        piece
    }

    fn contacts(&self, f: &Frame) -> PolyData {
        let periodic = Periodic::<f64>::of(&self.scene.periodic);
        let contacts = f.contacts.as_deref().unwrap_or(&[]);
        let mut piece = PolyData::default();
        let mut tangential = Vec::with_capacity(contacts.len());
        for c in contacts {
            let (pi, pj) = (Vec3::of(f.position[c.i as usize]), Vec3::of(f.position[c.j as usize]));
            let branch = periodic.min_image(pj - pi);
            let k = piece.points.len();
            piece.points.extend([pi.f64().to_array(), (pi + branch).f64().to_array()]);
            piece.lines.push([k, k + 1]);
            let n = branch * (1.0 / branch.norm());
            let fi = Vec3::of(c.force);
            tangential.push((fi - n * fi.dot(n)).f64().to_array());
        }
        piece.cell_data = vec![
            Array::integers("id_i", contacts.iter().map(|c| c.i as i64)),
            Array::integers("id_j", contacts.iter().map(|c| c.j as i64)),
            Array::scalars("normal_force", contacts.iter().map(|c| c.normal_force)),
            Array::vectors("tangential_force", tangential),
            Array::scalars("overlap", contacts.iter().map(|c| c.overlap)),
            Array::scalars("bridge_volume", contacts.iter().map(|c| c.bridge_volume)),
        ];
        piece
    }
}

/// `grains_000012.vtp`.
pub fn file_name(kind: &str, number: usize) -> String {
    format!("{kind}_{number:06}.vtp")
}

/// A `.pvd` collection of `kind`'s files at their simulated times.
fn collection(kind: &str, written: &[(f64, usize)]) -> String {
    let mut s = String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n");
    for &(time, number) in written {
        let _ = writeln!(s, "    <DataSet timestep=\"{time:e}\" group=\"\" part=\"0\" file=\"{}\"/>", file_name(kind, number));
    }
    s.push_str("  </Collection>\n</VTKFile>\n");
    s
}

/// The (time, file number) entries of a collection [`collection`] wrote.
fn read_collection(text: &str) -> anyhow::Result<Vec<(f64, usize)>> {
    let attribute = |line: &str, key: &str| -> Option<String> {
        let start = line.find(&format!("{key}=\""))? + key.len() + 2;
        Some(line[start..].split('"').next()?.to_string())
    };
    text.lines()
        .filter(|l| l.trim_start().starts_with("<DataSet"))
        .map(|l| {
            let time: f64 = attribute(l, "timestep").context("a DataSet without a timestep")?.parse()?;
            let file = attribute(l, "file").context("a DataSet without a file")?;
            let number = file.trim_end_matches(".vtp").rsplit('_').next().context("a file name without a number")?.parse()?;
            Ok((time, number))
        })
        .collect()
}
