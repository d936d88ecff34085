//! Snapshots of the engine: frames for the recording, and the whole state for checkpoints.

use super::*;
use crate::state::wall_contact_records;

impl<T: Real> CpuEngine<T> {
    /// The grain state in permanent-id order, and the touching pairs (canonical order) and
    /// wall contacts with their forces when `contacts`.
    pub(super) fn snapshot(&self, contacts: bool) -> Frame {
        let body = self.bodies();
        let prop = self.by_id(&self.prop);
        let mut frame = Frame {
            time: self.time,
            id: (0..self.id.len() as u32).collect(),
            position: self.positions(),
            radius: prop.iter().map(|p| p.radius.f64()).collect(),
            velocity: body.iter().map(|b| b.vel.f64()).collect(),
            angular_velocity: body.iter().map(|b| b.omega.f64()).collect(),
            orientation: self.orientation.as_ref().map(|q| self.by_id(q).iter().map(|q| glam::DQuat::from_xyzw(q[1].f64(), q[2].f64(), q[3].f64(), q[0].f64())).collect()),
            contacts: contacts.then(|| {
                self.pairs
                    .in_id_order(&self.slots())
                    .into_iter()
                    .filter_map(|(i, k)| {
                        let (i, k) = (i as usize, k as usize);
                        let j = self.pairs.partner[k] as usize;
                        let (h, _) = self.pair_overlap(i, j);
                        (h > T::ZERO || self.report.f_c(k) != T::ZERO).then(|| {
                            let springs = self.slots.load(&self.hist[k * self.slots.stride..]);
                            ContactRecord {
                                i: self.id[i],
                                j: self.id[j],
                                overlap: h.f64(),
                                normal_force: (self.report.f_n[k] + self.report.f_c(k)).f64(),
                                force: self.owner_force(k).f64(),
                                force_j: self.share[k].force.f64(),
                                tangential_spring: springs.tangential.f64(),
                                rolling_spring: springs.rolling.f64(),
                                bridge_volume: springs.bridge.f64(),
                            }
                        })
                    })
                    .collect()
            }),
            wall_contacts: contacts.then(|| {
                let ctx = ForceContext { model: &self.model, coeffs: &self.coeffs, n_materials: self.n_materials, slots: self.slots, elapsed: T::ZERO, window: T::ZERO, periodic: self.periodic, residual: &self.residual, material: &self.material, meshes: &self.meshes };
                wall_contact_records(&self.body, &self.prop, &self.id, &self.walls, &ctx, &self.wall_springs.dense(self.body.len(), walls_reals(&self.walls, self.slots.stride)))
            }),
            walls: self.walls.iter().map(|w| w.geom.f64()).collect(),
            walls_present: self.walls.iter().map(|w| w.present).collect(),
        };
        frame.retain_grains(|k| prop[k].in_play());
        frame
    }

    /// The whole state, for a checkpoint.
    pub(super) fn save_state(&self) -> EngineState {
        let mut s = EngineState::default();
        let v3 = |v: &Vec3<T>| [v.x.f64(), v.y.f64(), v.z.f64()];
        // The arrays below are by slot; `id` says whose.
        s.put_ints("id", self.id.iter().map(|&x| x as u64));
        s.put_reals("body", self.body.iter().flat_map(|b| [v3(&b.pos), v3(&b.vel), v3(&b.omega)].concat()));
        s.put_reals("load", self.load.iter().flat_map(|l| [v3(&l.force), v3(&l.torque)].concat()));
        s.put_ints("wall_touch_ids", self.wall_touches.iter().flat_map(|t| [t.grain as u64, t.wall as u64, t.code() as u64]));
        s.put_reals("wall_touches", self.wall_touches.iter().flat_map(|t| [v3(&t.force).as_slice(), &[t.stiffness.f64(), t.damping.f64()]].concat()));
        s.put_reals("wall_touch_power", self.wall_touches.iter().map(|t| t.power.f64()));
        if T::COMPENSATED {
            s.put_reals("residual", self.residual.iter().flat_map(v3));
        }
        s.put_reals("built_at", self.built_at.iter().flat_map(|v| v.f64().to_array()));
        s.put_reals("built_margin", [self.built_margin.f64()]);
        // Three counts a grain where any axis wraps, as before they were kept for those alone.
        let with_images = if self.image.width() > 0 { self.body.len() } else { 0 };
        s.put_ints("image", (0..with_images).flat_map(|i| self.image.get(i).map(|x| x as i64 as u64)));
        if let Some(q) = &self.orientation {
            s.put_reals("orientation", q.iter().flat_map(|q| q.map(T::f64)));
        }
        // Dense, one block per grain and wall, as before the springs were kept for candidates only.
        s.put_reals("wall_hist", self.wall_springs.dense(self.body.len(), walls_reals(&self.walls, self.slots.stride)).iter().map(|x| x.f64()));
        s.put_reals("wall_reaction", self.wall_reaction.iter().flat_map(v3));
        s.put_ints("wall_count", self.wall_count.iter().copied());
        let piston = self.piston.map_or(Vec::new(), |p| {
            let z = match self.walls[p.wall].geom {
                WallGeom::Piston { z } => z.f64(),
                _ => unreachable!("the piston's wall is a piston"),
            };
            vec![z, self.walls[p.wall].velocity.z.f64(), p.pressure.f64()]
        });
        s.put_reals("piston", piston);
        let servo = self.servo.map_or(Vec::new(), |sv| {
            let mut v: Vec<f64> = sv.walls.iter().flat_map(|&w| [v3(&self.plane(w).0), v3(&self.walls[w].velocity)].concat()).collect();
            v.extend([sv.pressure.f64(), sv.strain_rate.map_or(f64::NAN, |r| r.f64())]);
            v
        });
        s.put_reals("servo", servo);
        // Where each wall a prescribed motion may move stands (its centre), its velocity and
        // spin; and the spins' power.
        s.put_reals("driven_walls", self.drivable.iter().flat_map(|&w| [v3(&self.walls[w].geom.centre()), v3(&self.walls[w].velocity), v3(&self.walls[w].spin)].concat()));
        // Where a wall turns: 1, then a plane's normal (and 0) or a mesh's rotation; 0 and four
        // zeros where it does not.
        if self.walls.iter().any(|w| w.turns) {
            s.put_reals("wall_turns", self.walls.iter().flat_map(|w| turned_state(w)));
        }
        s.put_reals("wall_power", self.wall_power.iter().map(|x| x.f64()));
        s.put_ints("wall_present", self.walls.iter().map(|w| w.present as u64));
        let l = &self.pairs;
        for (name, v) in [("owner_start", &l.owner_start), ("partner", &l.partner), ("rev_start", &l.rev_start), ("rev_pair", &l.rev_pair)] {
            s.put_ints(name, v.iter().map(|&x| x as u64));
        }
        s.put_reals("hist", self.hist.iter().map(|x| x.f64()));
        s.put_reals("liquid", self.liquid.iter().map(|x| x.f64()));
        s.put_reals("share", self.share.iter().flat_map(|l| [v3(&l.force), v3(&l.torque)].concat()));
        s.put_reals("f_n", self.report.f_n.iter().map(|x| x.f64()));
        s.put_reals("f_c", self.report.f_c.iter().map(|x| x.f64()));
        s.put_ints("pair_flags", self.report.flags.iter().map(|&x| x as u64));
        s.put_reals("force_i", self.force_i.iter().flat_map(v3));
        // By slot, where a grain is out of play (an inlet's or an outlet's scene).
        if !self.prop.iter().all(Props::in_play) {
            s.put_ints("in_play", self.prop.iter().map(|p| p.in_play() as u64));
        }
        s.put_reals("clock", [self.max_moved2.f64(), self.time, self.external_work]);
        s.put_ints("counters", [self.step, self.rebuilds, self.forces_valid as u64]);
        s
    }

    /// Restores what [`Self::save_state`] returned, for the same scene.
    pub(super) fn restore_state(&mut self, s: &EngineState) -> anyhow::Result<()> {
        let n = self.body.len();
        let id: Vec<u32> = s.ints("id", Some(n))?.iter().map(|&x| x as u32).collect();
        let mut seen = vec![false; n];
        for &i in &id {
            if (i as usize) >= n || std::mem::replace(&mut seen[i as usize], true) {
                anyhow::bail!("the checkpoint's `id` is not a numbering of the scene's {n} grains");
            }
        }
        // The grains' constant properties follow the checkpoint's numbering.
        let slot = self.slots();
        let r = Renumbering::new(id.iter().map(|&i| slot[i as usize]).collect());
        r.apply(&mut self.prop);
        r.apply(&mut self.material);
        // Every grain in play where the checkpoint does not say otherwise.
        let in_play = s.ints("in_play", Some(n)).ok();
        for (k, p) in self.prop.iter_mut().enumerate() {
            *p = p.with_play(in_play.is_none_or(|v| v[k] != 0));
        }
        self.id = id;
        self.refresh_slots();
        let v3 = |a: &[f64]| Vec3::new(T::of(a[0]), T::of(a[1]), T::of(a[2]));
        for (b, c) in self.body.iter_mut().zip(s.reals("body", 9 * n)?.chunks_exact(9)) {
            *b = Body { pos: v3(&c[0..3]), vel: v3(&c[3..6]), omega: v3(&c[6..9]) };
        }
        for (l, c) in self.load.iter_mut().zip(s.reals("load", 6 * n)?.chunks_exact(6)) {
            *l = Load { force: v3(&c[0..3]), torque: v3(&c[3..6]) };
        }
        let ids = s.ints("wall_touch_ids", None)?;
        let values = s.reals("wall_touches", 5 * ids.len() / 3)?;
        // Written before walls could spin: no power.
        let power = s.reals("wall_touch_power", ids.len() / 3).map(<[f64]>::to_vec).unwrap_or_else(|_| vec![0.0; ids.len() / 3]);
        self.wall_touches = ids
            .chunks_exact(3)
            .zip(values.chunks_exact(5))
            .zip(&power)
            .map(|((i, v), &power)| {
                let (regime, touching) = WallTouch::<T>::of_code(i[2] as u8);
                WallTouch { grain: i[0] as u32, wall: i[1] as u32, regime, touching, force: v3(&v[0..3]), stiffness: T::of(v[3]), damping: T::of(v[4]), power: T::of(power) }
            })
            .collect();
        // f64 keeps no residuals (and a checkpoint written before there were any still resumes).
        if T::COMPENSATED {
            self.residual = s.reals("residual", 3 * n)?.chunks_exact(3).map(v3).collect();
        }
        for (b, c) in self.built_at.iter_mut().zip(s.reals("built_at", 3 * n)?.chunks_exact(3)) {
            *b = Vec3::of([c[0], c[1], c[2]]);
        }
        // Where the state does not say (written before there was a margin, or put together
        // from several processes' rows), the margin from the kept positions alone.
        self.built_margin = match s.reals("built_margin", 1) {
            Ok(m) => T::of(m[0]),
            Err(_) => self.built_at.iter().map(|&at| super::built_at::bound::<T>(at)).fold(T::ZERO, T::max),
        };
        let with_images = if self.image.width() > 0 { n } else { 0 };
        for (i, c) in s.ints("image", Some(3 * with_images))?.chunks_exact(3).enumerate() {
            self.image.set(i, [c[0] as i64 as i32, c[1] as i64 as i32, c[2] as i64 as i32]);
        }
        if let Some(q) = &mut self.orientation {
            for (q, c) in q.iter_mut().zip(s.reals("orientation", 4 * n)?.chunks_exact(4)) {
                *q = [T::of(c[0]), T::of(c[1]), T::of(c[2]), T::of(c[3])];
            }
        }
        let per_grain = walls_reals(&self.walls, self.slots.stride);
        let wall_hist: Vec<T> = s.reals("wall_hist", if self.walls.is_empty() { 0 } else { n * per_grain })?.iter().map(|&x| T::of(x)).collect();
        self.wall_reaction = s.reals("wall_reaction", 3 * self.walls.len())?.chunks_exact(3).map(v3).collect();
        self.wall_count = s.ints("wall_count", Some(self.walls.len()))?.to_vec();
        if let Some(p) = &mut self.piston {
            let v = s.reals("piston", 3)?;
            self.walls[p.wall].geom = WallGeom::Piston { z: T::of(v[0]) };
            self.walls[p.wall].velocity.z = T::of(v[1]);
            p.pressure = T::of(v[2]);
        }
        if let Some(mut sv) = self.servo {
            let v = s.reals("servo", 6 * 6 + 2)?;
            for (k, &w) in sv.walls.iter().enumerate() {
                let (_, normal) = self.plane(w);
                self.walls[w].geom = WallGeom::Plane { point: v3(&v[6 * k..6 * k + 3]), normal };
                self.walls[w].velocity = v3(&v[6 * k + 3..6 * k + 6]);
            }
            sv.pressure = T::of(v[36]);
            sv.strain_rate = (!v[37].is_nan()).then(|| T::of(v[37]));
            self.servo = Some(sv);
        }
        // Written before walls could move: they stand where the scene put them.
        if s.reals.contains_key("driven_walls") {
            for (&w, c) in self.drivable.iter().zip(s.reals("driven_walls", 9 * self.drivable.len())?.chunks_exact(9)) {
                let wall = &mut self.walls[w];
                (wall.geom, wall.velocity, wall.spin) = (wall.geom.centred_at(v3(&c[0..3])), v3(&c[3..6]), v3(&c[6..9]));
            }
        }
        // Written while no wall turned: none has turned since the scene started.
        if s.reals.contains_key("wall_turns") {
            let turns = s.reals("wall_turns", 5 * self.walls.len())?;
            for (wall, t) in self.walls.iter_mut().zip(turns.chunks_exact(5)) {
                restore_turned(wall, t);
            }
        }
        // Written before stages could add and remove walls: as the scene starts.
        if s.ints.contains_key("wall_present") {
            let present = s.ints("wall_present", Some(self.walls.len()))?;
            for (wall, &p) in self.walls.iter_mut().zip(present) {
                wall.present = p != 0;
            }
        }
        // Written before walls could spin: no power.
        self.wall_power = match s.reals("wall_power", self.walls.len()) {
            Ok(p) => p.iter().map(|&x| T::of(x)).collect(),
            Err(_) => vec![T::ZERO; self.walls.len()],
        };
        self.wall_springs = WallSprings::from_dense(&wall_hist, &self.built_at, &self.prop, &self.walls, &self.meshes, self.skin, per_grain);
        let u32s = |name: &str, len: Option<usize>| -> anyhow::Result<Vec<u32>> { Ok(s.ints(name, len)?.iter().map(|&x| x as u32).collect()) };
        let partner = u32s("partner", None)?;
        let n_pairs = partner.len();
        self.pairs = PairList {
            owner_start: u32s("owner_start", Some(n + 1))?,
            partner,
            rev_start: u32s("rev_start", Some(n + 1))?,
            rev_pair: u32s("rev_pair", Some(n_pairs))?,
        };
        self.hist = s.reals("hist", n_pairs * self.slots.stride)?.iter().map(|&x| T::of(x)).collect();
        self.liquid = s.reals("liquid", self.liquid.len())?.iter().map(|&x| T::of(x)).collect();
        self.share = s.reals("share", 6 * n_pairs)?.chunks_exact(6).map(|c| Load { force: v3(&c[0..3]), torque: v3(&c[3..6]) }).collect();
        let capillary = if self.slots.layout.bridge { n_pairs } else { 0 };
        self.report = PairReports {
            f_n: s.reals("f_n", n_pairs)?.iter().map(|&x| T::of(x)).collect(),
            f_c: s.reals("f_c", capillary)?.iter().map(|&x| T::of(x)).collect(),
            flags: s.ints("pair_flags", Some(n_pairs))?.iter().map(|&x| x as u8).collect(),
        };
        let kept = if self.model.keeps_both_forces() { n_pairs } else { 0 };
        self.force_i = s.reals("force_i", 3 * kept)?.chunks_exact(3).map(v3).collect();
        let clock = s.reals("clock", 3)?;
        (self.max_moved2, self.time, self.external_work) = (T::of(clock[0]), clock[1], clock[2]);
        let counters = s.ints("counters", Some(3))?;
        (self.step, self.rebuilds, self.forces_valid) = (counters[0], counters[1], counters[2] != 0);
        Ok(())
    }
}

/// A wall's turning state as checkpoints keep it: 1, then a plane's normal and 0, or a mesh's
/// rotation; five zeros for a wall that does not turn.
fn turned_state<T: Real>(wall: &WallState<T>) -> [f64; 5] {
    match (wall.turns, wall.geom) {
        (true, WallGeom::Plane { normal, .. }) => [1.0, normal.x.f64(), normal.y.f64(), normal.z.f64(), 0.0],
        (true, WallGeom::Mesh { pose, .. }) => {
            let q = pose.turn.unwrap_or_else(crate::turn::identity);
            [1.0, q[0].f64(), q[1].f64(), q[2].f64(), q[3].f64()]
        }
        _ => [0.0; 5],
    }
}

/// Sets a wall's turning state from [`turned_state`]'s five values `t`.
fn restore_turned<T: Real>(wall: &mut WallState<T>, t: &[f64]) {
    if t[0] == 0.0 {
        return;
    }
    wall.turns = true;
    match &mut wall.geom {
        WallGeom::Plane { normal, .. } => *normal = Vec3::new(T::of(t[1]), T::of(t[2]), T::of(t[3])),
        WallGeom::Mesh { pose, .. } => pose.turn = Some([t[1], t[2], t[3], t[4]].map(T::of)),
        _ => {}
    }
}
