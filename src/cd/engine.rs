//! Contact dynamics behind the host loop's [`Engine`]: statistics, frames and checkpoints of
//! rigid grains, whose contact forces are the step's impulses over the step.

use super::warm::WarmStart;
use super::{ContactDynamics, Partner};
use crate::engine::{ContactRecord, Engine, EngineState, Frame, SimError, Stats, WallContactRecord, WallStats, RATTLER_CONTACTS};
use crate::real::{Real, Vec3};
use crate::walls::WallGeom;

impl<T: Real> ContactDynamics<T> {
    /// Force on `b` (N; `-force` on `a`) and normal force (N) of a contact at the last step.
    fn forces(&self, r: Vec3<T>, n: Vec3<T>) -> ([f64; 3], f64) {
        let h = self.h.f64();
        let f = r.f64();
        ([f[0] / h, f[1] / h, f[2] / h], r.dot(n).f64() / h)
    }

    /// The first grain whose state is not finite.
    fn first_non_finite(&self) -> Option<u32> {
        self.body.iter().position(|b| !(b.pos.is_finite() && b.vel.is_finite() && b.omega.is_finite())).map(|i| self.id[i])
    }
}

impl<T: Real> Engine for ContactDynamics<T> {
    fn backend(&self) -> &'static str {
        self.sweeps.backend()
    }
    fn precision(&self) -> &'static str {
        T::NAME
    }
    fn grain_count(&self) -> usize {
        self.body.len()
    }
    fn steps(&self) -> u64 {
        self.steps
    }
    fn time(&self) -> f64 {
        self.steps as f64 * self.h.f64()
    }

    fn set_profiling(&mut self, on: bool) {
        self.clock.enable(on);
    }

    fn phase_seconds(&self) -> Vec<(&'static str, f64)> {
        self.clock.totals()
    }

    fn advance(&mut self, n: u64) -> Result<(), SimError> {
        for _ in 0..n {
            self.step()?;
        }
        match self.first_non_finite() {
            Some(grain) => Err(SimError::Unstable { step: self.steps, time: self.time(), what: "the state is not finite".into(), grain, suggested_dt: 0.5 * self.h.f64(), also: ", or raise contact_dynamics.max_iterations" }),
            None => Ok(()),
        }
    }

    fn stats(&mut self) -> Result<Stats, SimError> {
        let n = self.body.len();
        let g = self.gravity.f64();
        let mut s = Stats { step: self.steps, time: self.time(), rebuilds: self.near.searches, external_work: self.external_work, grains: self.grain_count() as u64, ..Default::default() };
        for (b, p) in self.body.iter().zip(&self.prop) {
            let (m, v, w) = (p.mass.f64(), b.vel.f64(), b.omega.f64());
            s.ke_translational += 0.5 * m * b.vel.norm2().f64();
            s.ke_rotational += 0.5 * p.inertia.f64() * b.omega.norm2().f64();
            s.gravity_energy -= m * (g[0] * b.pos.x.f64() + g[1] * b.pos.y.f64() + g[2] * b.pos.z.f64());
            let x = b.pos.f64();
            let mv = [m * v[0], m * v[1], m * v[2]];
            for a in 0..3 {
                s.momentum[a] += mv[a];
                s.angular_momentum[a] += x[(a + 1) % 3] * mv[(a + 2) % 3] - x[(a + 2) % 3] * mv[(a + 1) % 3] + p.inertia.f64() * w[a];
            }
        }
        let mut touching = vec![0u64; n];
        s.walls = self.wall_names.iter().map(|name| WallStats { name: name.clone(), ..Default::default() }).collect();
        let (mut most, mut most_grain) = (0.0f64, 0);
        for c in &self.contacts {
            let r_n = c.r.dot(c.n);
            if r_n <= T::ZERO {
                continue;
            }
            touching[c.a as usize] += 1;
            let r_t = c.r - c.n * r_n;
            s.sliding += u64::from(r_t.norm2() >= c.mu * r_n * c.mu * r_n * T::of(1.0 - 1e-9));
            let overlap = (-c.gap).f64().max(0.0);
            match c.b {
                Partner::Grain(j) => {
                    s.contacts += 1;
                    touching[j as usize] += 1;
                    let r_min = self.prop[c.a as usize].radius.min(self.prop[j as usize].radius).f64();
                    // Ties go to the lower id, whatever the solve's order.
                    let (ratio, grain) = (overlap / r_min, self.id[c.a as usize]);
                    if ratio > most || (ratio == most && ratio > 0.0 && grain < most_grain) {
                        (most, most_grain) = (ratio, grain);
                    }
                }
                Partner::Wall(w) => {
                    s.wall_contacts += 1;
                    let (f, _) = self.forces(c.r, c.n);
                    let wall = &mut s.walls[w as usize];
                    wall.contacts += 1;
                    for (sum, f) in wall.force.iter_mut().zip(f) {
                        *sum += f;
                    }
                }
            }
        }
        self.servo_stats(&mut s.walls);
        s.pairs = self.contacts.iter().filter(|c| matches!(c.b, Partner::Grain(_))).count() as u64;
        s.coordination = 2.0 * s.contacts as f64 / n as f64;
        (s.max_overlap, s.max_overlap_grain) = (most, most_grain);
        s.unbalanced_force = self.report.unbalanced;
        s.unbalanced_force_loaded = self.report.unbalanced;
        s.rattlers = touching.iter().filter(|&&k| k < RATTLER_CONTACTS).count() as u64;
        s.ke_rattlers = touching.iter().zip(self.body.iter().zip(&self.prop)).filter(|(k, _)| **k < RATTLER_CONTACTS).map(|(_, (b, p))| 0.5 * p.mass.f64() * b.vel.norm2().f64()).sum();
        s.non_finite_grain = self.first_non_finite();
        let read = std::mem::take(&mut self.since_read);
        // The run's totals carry on past the read.
        (self.since_read.steps_total, self.since_read.unconverged_total) = (read.steps_total, read.unconverged_total);
        s.solver = Some(read);
        Ok(s)
    }

    fn frame(&self, contacts: bool) -> Result<Frame, SimError> {
        let mut f = Frame {
            time: self.time(),
            id: self.id.clone(),
            position: (0..self.body.len()).map(|i| self.position(i)).collect(),
            radius: self.prop.iter().map(|p| p.radius.f64()).collect(),
            velocity: self.body.iter().map(|b| b.vel.f64()).collect(),
            angular_velocity: self.body.iter().map(|b| b.omega.f64()).collect(),
            walls: self.walls.iter().map(|(geom, _)| geom.f64()).collect(),
            walls_present: vec![true; self.walls.len()],
            ..Default::default()
        };
        if contacts {
            let loaded = self.contacts.iter().filter(|c| c.r.dot(c.n) > T::ZERO);
            let (mut pairs, mut walls) = (Vec::new(), Vec::new());
            for c in loaded {
                let (force_b, normal_force) = self.forces(c.r, c.n);
                let on_a = glam::DVec3::new(-force_b[0], -force_b[1], -force_b[2]);
                let overlap = (-c.gap).f64().max(0.0);
                match c.b {
                    Partner::Grain(j) => pairs.push(ContactRecord { i: self.id[c.a as usize], j: self.id[j as usize], overlap, normal_force, force: on_a, force_j: force_b.into(), ..Default::default() }),
                    Partner::Wall(w) => {
                        let n = (-c.n).f64();
                        walls.push(WallContactRecord { grain: self.id[c.a as usize], wall: w, overlap, normal: n, lever: self.prop[c.a as usize].radius.f64(), force: on_a });
                    }
                }
            }
            // Canonical order (the solve's is by colour).
            pairs.sort_by_key(|p| (p.i, p.j));
            f.contacts = Some(pairs);
            f.wall_contacts = Some(walls);
        }
        Ok(f)
    }

    fn set_piston_pressure(&mut self, _pressure: f64) {
        // Contact-dynamics scenes have no piston (refused at `ContactDynamics::new`).
    }

    fn save(&self) -> Result<EngineState, SimError> {
        let mut s = EngineState::default();
        let v3 = |v: Vec3<T>| [v.x.f64(), v.y.f64(), v.z.f64()];
        s.put_reals("position", self.body.iter().flat_map(|b| v3(b.pos)));
        s.put_reals("residual", self.residual.iter().flat_map(|&r| v3(r)));
        s.put_reals("velocity", self.body.iter().flat_map(|b| v3(b.vel)));
        s.put_reals("omega", self.body.iter().flat_map(|b| v3(b.omega)));
        // The warm start, in detection order; a partner as a grain's slot or a wall's tagged index.
        let warm = self.warm.entries();
        s.put_ints("warm_a", warm.iter().map(|&(a, _, _)| a as u64));
        s.put_ints("warm_b", warm.iter().map(|&(_, b, _)| b));
        s.put_reals("warm_r", warm.iter().flat_map(|&(_, _, r)| v3(r)));
        s.put_ints("steps", [self.steps]);
        // Where the pairs were last searched, so that a resumed run searches when this one would.
        let (found_at, skin, searches) = self.near.saved();
        s.put_reals("near_found_at", found_at.iter().flat_map(|&p| v3(p)));
        s.put_reals("near_skin", [skin.f64()]);
        s.put_ints("near_searches", [searches]);
        // The walls that move: planes' points and every wall's velocity; the servo's targets.
        s.put_reals("wall_points", self.walls.iter().flat_map(|(g, _)| match g {
            WallGeom::Plane { point, .. } => v3(*point),
            _ => [0.0; 3],
        }));
        s.put_reals("wall_velocities", self.wall_motion.iter().flat_map(|m| v3(m.vel)));
        s.put_reals("external_work", [self.external_work]);
        s.put_reals("servo", self.servo.map_or(Vec::new(), |sv| vec![sv.pressure.f64(), sv.strain_rate.map_or(f64::NAN, |r| r.f64())]));
        // The solver's record since the last statistics read, so that a resumed run's
        // statistics are the uninterrupted run's.
        let r = &self.since_read;
        s.put_ints("solver_counts", [r.steps, r.unconverged_steps, r.max_iterations as u64, r.steps_total, r.unconverged_total, r.contact_updates]);
        s.put_reals("solver_reals", [r.mean_iterations, r.sweep_norm, r.unbalanced, self.report.unbalanced]);
        let q = &r.residuals;
        s.put_reals("solver_residuals", [q.normal, q.tangential, q.quadratic, q.maximum]);
        Ok(s)
    }

    fn restore(&mut self, s: &EngineState) -> anyhow::Result<()> {
        let n = self.body.len();
        let of = |x: &[f64]| Vec3::<T>::new(T::of(x[0]), T::of(x[1]), T::of(x[2]));
        let (pos, vel, omega) = (s.reals("position", 3 * n)?, s.reals("velocity", 3 * n)?, s.reals("omega", 3 * n)?);
        for (i, b) in self.body.iter_mut().enumerate() {
            let k = 3 * i..3 * i + 3;
            (b.pos, b.vel, b.omega) = (of(&pos[k.clone()]), of(&vel[k.clone()]), of(&omega[k]));
        }
        if T::COMPENSATED {
            self.residual = s.reals("residual", 3 * n)?.chunks_exact(3).map(of).collect();
        }
        let (a, b) = (s.ints("warm_a", None)?, s.ints("warm_b", None)?);
        let r = s.reals("warm_r", 3 * a.len())?;
        self.warm = WarmStart::of(a.iter().zip(b).zip(r.chunks_exact(3)).map(|((&a, &b), r)| (a as u32, b, of(r))).collect());
        self.steps = s.ints("steps", Some(1))?[0];
        // Checkpoints from before the pairs were kept between searches: searched at the first step.
        self.near = match s.reals.get("near_found_at") {
            Some(v) => {
                // Empty when saved before the first step.
                let found_at: Vec<Vec3<T>> = s.reals("near_found_at", if v.is_empty() { 0 } else { 3 * n })?.chunks_exact(3).map(of).collect();
                let (skin, searches) = (T::of(s.reals("near_skin", 1)?[0]), s.ints("near_searches", Some(1))?[0]);
                super::near::Near::resumed(found_at, skin, searches, &self.body, &self.residual, &self.prop, &self.id, self.r_max, T::of(self.params.gap_allowance))
            }
            None => Default::default(),
        };
        let walls = self.walls.len();
        let (points, velocities) = (s.reals("wall_points", 3 * walls)?, s.reals("wall_velocities", 3 * walls)?);
        for (w, ((geom, _), motion)) in self.walls.iter_mut().zip(&mut self.wall_motion).enumerate() {
            if let WallGeom::Plane { point, .. } = geom {
                *point = of(&points[3 * w..3 * w + 3]);
            }
            motion.vel = of(&velocities[3 * w..3 * w + 3]);
        }
        self.external_work = s.reals("external_work", 1)?[0];
        if let Some(sv) = &mut self.servo {
            let v = s.reals("servo", 2)?;
            sv.pressure = T::of(v[0]);
            sv.strain_rate = (!v[1].is_nan()).then(|| T::of(v[1]));
        }
        // Five counts in checkpoints from before the contact updates were counted.
        let (counts, reals) = (s.ints("solver_counts", None)?, s.reals("solver_reals", 4)?);
        if counts.len() < 5 {
            anyhow::bail!("the checkpoint's solver record holds {} counts, not 5 or 6; fix: resume with the grains that wrote it", counts.len());
        }
        self.since_read = crate::engine::SolverStats {
            steps: counts[0],
            unconverged_steps: counts[1],
            max_iterations: counts[2] as u32,
            steps_total: counts[3],
            unconverged_total: counts[4],
            contact_updates: counts.get(5).copied().unwrap_or(0),
            mean_iterations: reals[0],
            sweep_norm: reals[1],
            unbalanced: reals[2],
            // Checkpoints from before the residuals were measured resume with none recorded.
            residuals: match s.reals.get("solver_residuals") {
                Some(_) => {
                    let q = s.reals("solver_residuals", 4)?;
                    crate::engine::Residuals { normal: q[0], tangential: q[1], quadratic: q[2], maximum: q[3] }
                }
                None => Default::default(),
            },
        };
        self.report.unbalanced = reals[3];
        Ok(())
    }

    fn set_wall_drive(&mut self, _wall: usize, _drive: &crate::scene::WallDrive) {
        // Contact-dynamics scenes have no moving walls (refused at `ContactDynamics::new`).
    }

    fn set_wall_present(&mut self, _wall: usize, _present: bool) {
        // Contact-dynamics scenes keep their walls (stages that add or remove one are refused
        // at `ContactDynamics::new`).
    }

    fn remove_grains(&mut self, _ids: &[u32]) -> anyhow::Result<()> {
        anyhow::bail!("contact dynamics keeps every grain in play: it takes no outlet yet; fix: run the scene with simulation.method = \"dem\"")
    }

    fn insert_grains(&mut self, _grains: &[crate::engine::Insertion]) -> anyhow::Result<()> {
        anyhow::bail!("contact dynamics keeps every grain in play: it takes no inlet yet; fix: run the scene with simulation.method = \"dem\"")
    }

    fn set_servo(&mut self, pressure: Option<f64>, axial_strain_rate: Option<f64>) {
        if let Some(s) = &mut self.servo {
            if let Some(p) = pressure {
                s.pressure = T::of(p);
            }
            s.strain_rate = axial_strain_rate.map(T::of);
        }
    }

    fn wet(&mut self, _volume: f64) -> anyhow::Result<()> {
        anyhow::bail!("contact dynamics models no liquid bridges; fix: run wet stages with simulation.method = \"dem\"")
    }

    fn place_piston(&mut self, _z: f64) {
        // No piston: nothing to place.
    }

    fn memory_bytes(&self) -> u64 {
        use crate::state::allocated;
        allocated(&self.id) + allocated(&self.body) + allocated(&self.residual) + allocated(&self.prop) + allocated(&self.contacts) + self.near.bytes() + self.warm.bytes()
    }
}

