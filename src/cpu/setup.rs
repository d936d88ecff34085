//! Setting the engine up for a scene: the grains' arrays in permanent-id order, the walls and
//! their controllers, the pair coefficients, and the first neighbour list.

use super::*;

impl<T: Real> CpuEngine<T> {
    /// Sets up the engine for a scene and builds the first neighbour list.
    pub fn new(scene: &Scene) -> Result<Self, SimError> {
        let n_materials = scene.materials.len();
        let coeffs = scene.pair_coeffs();
        let g = &scene.grains;
        let n = g.len();
        let (positions, residual): (Vec<Vec3<T>>, Vec<Vec3<T>>) = g.position.iter().map(|&x| position::split(x)).unzip();
        let body: Vec<Body<T>> = (0..n).map(|i| Body { pos: positions[i], vel: Vec3::of(g.velocity[i]), omega: Vec3::of(g.angular_velocity[i]) }).collect();
        let residual = if T::COMPENSATED { residual } else { Vec::new() };
        let prop: Vec<Props<T>> = (0..n)
            .map(|i| Props::sphere(g.radius[i], g.mass[i]).with_play(g.starts_in_play(i)))
            .collect();
        let r_max = g.radius.iter().copied().fold(0.0, f64::max);
        let model = scene.model.cast::<T>();
        let slots = HistorySlots::new(model.history_layout());
        let mut piston = None;
        let walls: Vec<WallState<T>> = scene
            .walls
            .iter()
            .enumerate()
            .map(|(w, wall)| {
                if let WallShape::Piston { pressure, mass, area, .. } = wall.shape {
                    piston = Some(Piston { wall: w, mass: T::of(mass), area: T::of(area), pressure: T::of(pressure) });
                }
                let mut state = WallState { geom: WallGeom::of(&wall.shape), velocity: Vec3::ZERO, spin: Vec3::ZERO, turns: false, material: wall.material as u32, present: wall.present };
                state.drive(Vec3::of(wall.drive.velocity), Vec3::of(wall.drive.angular_velocity), wall.drive.turns);
                state
            })
            .collect();
        let n_walls = walls.len();
        let mut engine = CpuEngine {
            model,
            slots,
            coeffs,
            n_materials,
            gravity: Vec3::of(scene.gravity),
            dt: T::of(scene.time_step.dt),
            suggested_dt: scene.time_step.suggested_after_instability(),
            schedule: Schedule::new(scene.integrator, scene.time_step.dt),
            trace: Trace::default(),
            skin: T::of(scene.skin),
            detect_reach: T::of(scene.skin + scene.bridges.reach),
            cutoff: T::of(2.0 * r_max + scene.skin + scene.bridges.reach),
            capacity: scene.max_neighbours,
            r_min: scene.grains.radius.iter().copied().fold(f64::INFINITY, f64::min) as f32,
            bridge_cap: T::of(scene.bridges.volume_cap),
            liquid: if slots.layout.bridge { vec![T::ZERO; n] } else { Vec::new() },
            periodic: Periodic::of(&scene.periodic),
            reorder_every: scene.reorder_every,
            id: (0..n as u32).collect(),
            slot: Vec::new(),
            built_at: body.iter().map(|b| built_at::record(b.pos)).collect(),
            image: Images::new([0, 1, 2].map(|a| scene.periodic[a].is_some()), n),
            body,
            residual,
            prop,
            material: if n_materials > 1 { g.material.iter().map(|&m| m as u32).collect() } else { Vec::new() },
            load: vec![Load::default(); n],
            orientation: scene.track_orientation.then(|| vec![[T::ONE, T::ZERO, T::ZERO, T::ZERO]; n]),
            wall_names: scene.walls.iter().map(|w| w.name.clone()).collect(),
            walls,
            meshes: scene.mesh_surfaces(),
            mesh_overflow: None,
            piston,
            servo: scene.servo.map(|s| Servo { walls: s.walls, pressure: T::of(s.pressure), gain: T::of(s.gain), max_speed: T::of(s.max_speed), strain_rate: None }),
            wall_springs: WallSprings::default(),
            wall_touches: Vec::new(),
            wall_reaction: vec![Vec3::ZERO; n_walls],
            wall_count: vec![0; n_walls],
            wall_regimes: RegimeCounts::default(),
            wall_response: vec![(T::ZERO, T::ZERO); n_walls],
            wall_power: vec![T::ZERO; n_walls],
            drivable: (0..n_walls).filter(|&k| !matches!(scene.walls[k].shape, WallShape::Piston { .. }) && !scene.servo.is_some_and(|s| s.walls.contains(&k))).collect(),
            pairs: PairList::default(),
            hist: Vec::new(),
            share: Vec::new(),
            report: PairReports::default(),
            force_i: Vec::new(),
            max_moved2: T::ZERO,
            carried: false,
            built_margin: T::ZERO,
            forces_valid: false,
            step: 0,
            time: 0.0,
            rebuilds: 0,
            renumberings: 0,
            external_work: 0.0,
            clock: PhaseClock::default(),
            crew: Crew::default(),
        };
        engine.rebuild()?;
        Ok(engine)
    }

    /// Chooses the grains whose wall springs are kept ([`WallSprings::choose`]), from the
    /// positions of the last rebuild and the walls now.
    pub(super) fn choose_wall_springs(&mut self) {
        let per_grain = walls_reals(&self.walls, self.slots.stride);
        self.wall_springs = WallSprings::choose(&self.built_at, &self.prop, &self.walls, &self.meshes, self.skin, per_grain, &self.wall_springs);
    }

    /// The error for a grain that touched a mesh at more places than it keeps.
    pub(super) fn mesh_overflow_error(&self, grain: u32) -> SimError {
        let i = self.id.iter().position(|&g| g == grain).unwrap_or(0);
        let (b, p) = (&self.body[i], &self.prop[i]);
        let wall = self
            .walls
            .iter()
            .zip(&self.wall_names)
            .find(|(w, _)| crate::state::wall_overlaps(w, &self.meshes, b.pos, position::residual_at(&self.residual, i), p.radius * T::of(1.0 + 1e-6)).1 > 0 && matches!(w.geom, WallGeom::Mesh { .. }))
            .map_or_else(|| "(a mesh)".to_string(), |(_, n)| n.clone());
        SimError::MeshContacts { step: self.step, grain, wall, max: crate::mesh::MESH_CONTACTS, raw: crate::mesh::RAW_CONTACTS }
    }
}
