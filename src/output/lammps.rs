//! `grains export`: a frame as LAMMPS / LIGGGHTS files (SI units), for `read_data` and
//! `read_dump`: atom id = permanent grain id + 1, atom type = material index + 1.

use crate::engine::Frame;
use crate::lammps::Atoms;
use crate::scene::Scene;

/// The atoms of frame `f` of a run of `scene`: masses and densities from the scene's grains,
/// the box over the periodic intervals and elsewhere over the grains and the walls
/// (`output::vtk`'s domain), the time step number `time / dt`.
pub fn atoms(scene: &Scene, f: &Frame) -> Atoms {
    let g = &scene.grains;
    let ids: Vec<usize> = f.id.iter().map(|&i| i as usize).collect();
    let volume = |r: f64| 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let (lo, hi) = super::vtk::domain(scene, f);
    Atoms {
        id: ids.iter().map(|&i| i as u64 + 1).collect(),
        kind: ids.iter().map(|&i| u32::from(g.material[i]) + 1).collect(),
        radius: f.radius.clone(),
        density: Some(ids.iter().map(|&i| g.mass[i] / volume(g.radius[i])).collect()),
        mass: Some(ids.iter().map(|&i| g.mass[i]).collect()),
        position: f.position.iter().map(|p| p.to_array()).collect(),
        velocity: f.velocity.iter().map(|v| v.to_array()).collect(),
        angular_velocity: f.angular_velocity.iter().map(|w| w.to_array()).collect(),
        bounds: [0, 1, 2].map(|a| scene.periodic[a].unwrap_or([lo[a], hi[a]])),
        periodic: scene.periodic.map(|p| p.is_some()),
        timestep: (f.time / scene.time_step.dt).round() as u64,
    }
}
