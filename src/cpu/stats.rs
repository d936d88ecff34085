//! Statistics: sums over grains and over pairs in fixed chunks, combined in order, grains in
//! permanent-id order and pairs in canonical order (the same bits on any thread count and
//! however the slots are numbered).

use super::*;
use crate::model::NormalModel;
use crate::state::coeffs_of;

/// Per-chunk partial sums of the statistics over grains.
#[derive(Clone, Copy, Default)]
struct GrainSums {
    ke_t: f64,
    ke_r: f64,
    pe_g: f64,
    momentum: [f64; 3],
    angular: [f64; 3],
    net_force: f64,
    net_force_loaded: f64,
    rattlers: u64,
    ke_rattlers: f64,
    wall_force: f64,
    wall_contacts: u64,
    wall_elastic: f64,
    max_wall_overlap: (f64, u32),
}

/// Per-chunk partial sums of the statistics over pairs.
#[derive(Clone, Copy, Default)]
struct PairSums {
    contacts: u64,
    clamped: u64,
    regimes: RegimeCounts,
    elastic: f64,
    force: f64,
    max_overlap: (f64, u32),
}

/// The larger value, and of equal values the lower grain id.
fn max_by_first(a: (f64, u32), b: (f64, u32)) -> (f64, u32) {
    if b.0 > a.0 || (b.0 == a.0 && b.1 < a.1) { b } else { a }
}

impl<T: Real> CpuEngine<T> {
    /// Per fixed chunk of grain ids, the sum over its grains (in id order) of the magnitude of
    /// the force the walls exert on each (N).
    fn wall_force_by_chunk(&self) -> Vec<f64> {
        let mut sums = vec![0.0; self.body.len().div_ceil(CHUNK)];
        for grain in self.wall_touches.chunk_by(|a, b| a.grain == b.grain) {
            let force = grain.iter().fold(Vec3::ZERO, |f, t| f + t.force);
            sums[grain[0].grain as usize / CHUNK] += force.norm().f64();
        }
        sums
    }

    /// The statistics of the current state (loads evaluated first if nothing has).
    pub(super) fn statistics(&mut self) -> Stats {
        // A rebuild that fails here (a non-finite grain) leaves the loads as they were: the
        // statistics name the grain and the next step returns the error.
        self.ensure_loads().ok();
        let g = self.gravity;
        let wall_force = self.wall_force_by_chunk();
        let slot = self.slots();
        let grain_sums = chunked(self.body.len(), |r| {
            let mut s = GrainSums { wall_force: wall_force[r.start / CHUNK], ..Default::default() };
            for i in r.map(|id| slot[id] as usize) {
                let (b, p, l) = (&self.body[i], &self.prop[i], &self.load[i]);
                if !p.in_play() {
                    continue;
                }
                let m = p.mass.f64();
                let v = b.vel.f64();
                let pos = self.periodic.unwrap(b.pos, self.image.get(i));
                let x = pos.f64();
                s.ke_t += 0.5 * m * b.vel.norm2().f64();
                s.ke_r += 0.5 * p.inertia.f64() * b.omega.norm2().f64();
                s.pe_g -= m * g.dot(pos).f64();
                let w = b.omega.f64();
                let ii = p.inertia.f64();
                let mv = [m * v[0], m * v[1], m * v[2]];
                for (p, q) in s.momentum.iter_mut().zip(mv) {
                    *p += q;
                }
                s.angular[0] += x[1] * mv[2] - x[2] * mv[1] + ii * w[0];
                s.angular[1] += x[2] * mv[0] - x[0] * mv[2] + ii * w[1];
                s.angular[2] += x[0] * mv[1] - x[1] * mv[0] + ii * w[2];
                let pushes = |k: u32| (self.report.f_n[k as usize] > T::ZERO) as u64;
                let pl = &self.pairs;
                let mut contacts: u64 = (pl.owner_start[i]..pl.owner_start[i + 1]).map(pushes).sum::<u64>() + pl.rev_pair[pl.rev_start[i] as usize..pl.rev_start[i + 1] as usize].iter().map(|&k| pushes(k)).sum::<u64>();
                for wall in &self.walls {
                    let (overlaps, touching) = crate::state::wall_overlaps(wall, &self.meshes, b.pos, crate::position::residual_at(&self.residual, i), p.radius);
                    for &h in &overlaps[..touching] {
                        contacts += 1;
                        let c = coeffs_of(&self.coeffs, self.n_materials, wall.material as usize, crate::state::material_at(&self.material, i));
                        s.wall_contacts += 1;
                        s.wall_elastic += self.model.normal.potential(c, p.radius, h).f64();
                        s.max_wall_overlap = max_by_first(s.max_wall_overlap, ((h / p.radius).f64(), self.id[i]));
                    }
                }
                let net = l.force.norm().f64();
                s.net_force += net;
                if contacts < RATTLER_CONTACTS {
                    s.rattlers += 1;
                    s.ke_rattlers += 0.5 * m * b.vel.norm2().f64();
                } else {
                    s.net_force_loaded += net;
                }
            }
            s
        });
        let canonical = self.pairs.in_id_order(&slot);
        let pair_sums = chunked(canonical.len(), |r| {
            let mut s = PairSums::default();
            for (i, k) in r.map(|c| canonical[c]) {
                let (i, k) = (i as usize, k as usize);
                let j = self.pairs.partner[k] as usize;
                let (h, r_min) = self.pair_overlap(i, j);
                if h <= T::ZERO {
                    continue;
                }
                let (pi, pj) = (&self.prop[i], &self.prop[j]);
                let c = coeffs_of(&self.coeffs, self.n_materials, crate::state::material_at(&self.material, i), crate::state::material_at(&self.material, j));
                let r_eff = pi.radius * pj.radius / (pi.radius + pj.radius);
                s.contacts += 1;
                s.clamped += self.report.clamped(k) as u64;
                s.regimes.count(self.report.regime(k));
                s.elastic += self.model.normal.potential(c, r_eff, h).f64();
                s.force += 2.0 * self.owner_force(k).norm().f64();
                s.max_overlap = max_by_first(s.max_overlap, ((h / r_min).f64(), self.id[i]));
            }
            s
        });
        let mut gs = GrainSums::default();
        for s in grain_sums {
            gs.ke_t += s.ke_t;
            gs.ke_r += s.ke_r;
            gs.pe_g += s.pe_g;
            for a in 0..3 {
                gs.momentum[a] += s.momentum[a];
                gs.angular[a] += s.angular[a];
            }
            gs.net_force += s.net_force;
            gs.net_force_loaded += s.net_force_loaded;
            gs.rattlers += s.rattlers;
            gs.ke_rattlers += s.ke_rattlers;
            gs.wall_force += s.wall_force;
            gs.wall_contacts += s.wall_contacts;
            gs.wall_elastic += s.wall_elastic;
            gs.max_wall_overlap = max_by_first(gs.max_wall_overlap, s.max_wall_overlap);
        }
        let mut ps = PairSums::default();
        for s in pair_sums {
            ps.contacts += s.contacts;
            ps.clamped += s.clamped;
            ps.regimes.add(s.regimes);
            ps.elastic += s.elastic;
            ps.force += s.force;
            ps.max_overlap = max_by_first(ps.max_overlap, s.max_overlap);
        }
        let n = self.grains_in_play() as f64;
        // Each touching pair counts once per grain; each wall contact once.
        let contact_ends = 2 * ps.contacts + gs.wall_contacts;
        let unbalanced_force = crate::engine::unbalanced(gs.net_force, n, ps.force + gs.wall_force, contact_ends);
        let unbalanced_force_loaded = crate::engine::unbalanced(gs.net_force_loaded, n - gs.rattlers as f64, ps.force + gs.wall_force, contact_ends);
        let (max_overlap, max_overlap_grain) = max_by_first(ps.max_overlap, gs.max_wall_overlap);
        let walls = (0..self.walls.len())
            .map(|w| {
                let servo = self.servo.and_then(|s| s.walls.iter().position(|&x| x == w).map(|k| (s, k)));
                WallStats {
                    name: self.wall_names[w].clone(),
                    force: self.wall_reaction[w].f64().to_array(),
                    contacts: self.wall_count[w],
                    position: servo.map(|(_, k)| {
                        let p = self.plane(w).0;
                        [p.x, p.y, p.z][k / 2].f64()
                    }),
                    pressure: servo.map(|(s, k)| self.servo_pressure(&s, k).f64()),
                }
            })
            .collect();
        let piston = self.piston.map(|p| {
            let wall = &self.walls[p.wall];
            let z = match wall.geom {
                WallGeom::Piston { z } => z.f64(),
                _ => unreachable!("the piston's wall is a piston"),
            };
            PistonStats {
                z,
                velocity: wall.velocity.z.f64(),
                target_pressure: p.pressure.f64(),
                pressure: self.wall_reaction[p.wall].z.f64() / p.area.f64(),
            }
        });
        let piston_ke = self.piston.map_or(0.0, |p| 0.5 * p.mass.f64() * self.walls[p.wall].velocity.z.f64().powi(2));
        let (bridges, liquid_in_bridges, capillary_energy) = match self.model.cohesion {
            CohesionLaw::Capillary { kappa, theta, c } => {
                let (stride, b) = (self.slots.stride, self.slots.bridge);
                let bridge = |(i, k): (u32, u32)| {
                    let (i, k) = (i as usize, k as usize);
                    let (v, j) = (self.hist[k * stride + b], self.pairs.partner[k] as usize);
                    (v, capillary_potential(kappa, theta, c, self.prop[i].radius, self.prop[j].radius, v, self.gap(i, j)))
                };
                chunked(canonical.len(), |r| r.map(|c| bridge(canonical[c])).filter(|(v, _)| *v > T::ZERO).fold((0u64, 0.0, 0.0), |(n, s, u), (v, e)| (n + 1, s + v.f64(), u + e.f64())))
                    .into_iter()
                    .fold((0, 0.0, 0.0), |(n, s, u), (m, t, e)| (n + m, s + t, u + e))
            }
            CohesionLaw::None => (0, 0.0, 0.0),
        };
        let liquid_on_grains: f64 = chunked(self.liquid.len(), |r| r.map(|id| self.liquid[slot[id] as usize].f64()).sum::<f64>()).into_iter().sum();
        Stats {
            step: self.step,
            time: self.time,
            ke_translational: gs.ke_t,
            ke_rotational: gs.ke_r,
            elastic_energy: ps.elastic + gs.wall_elastic,
            capillary_energy,
            gravity_energy: gs.pe_g,
            piston_ke,
            external_work: self.external_work,
            momentum: gs.momentum,
            angular_momentum: gs.angular,
            pairs: self.pairs.len() as u64,
            contacts: ps.contacts,
            wall_contacts: gs.wall_contacts,
            clamped: ps.clamped,
            sliding: ps.regimes.sliding + self.wall_regimes.sliding,
            rolling: ps.regimes.rolling + self.wall_regimes.rolling,
            coordination: crate::engine::coordination(ps.contacts, n),
            grains: n as u64,
            max_overlap,
            max_overlap_grain,
            unbalanced_force,
            unbalanced_force_loaded,
            rattlers: gs.rattlers,
            ke_rattlers: gs.ke_rattlers,
            non_finite_grain: self.first_non_finite(),
            rebuilds: self.rebuilds,
            bridges,
            liquid_in_bridges,
            liquid_on_grains,
            walls,
            piston,
            solver: None,
            flow: Vec::new(),
        }
    }
}
