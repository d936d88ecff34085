//! The host's work on state read back: frames, checkpoints and wetting.

use super::*;

/// The GPU's history (one vec4 per block and contact: tangential with the sliding flag in w,
/// rolling, bridge volume in x) in the CPU engine's packed slots.
fn cpu_history(blocks: &[[f32; 4]], slots: &crate::state::HistorySlots) -> Vec<f32> {
    use layout::normal_slot;
    let layout = slots.layout;
    let per_contact = (layout::history_blocks(layout) as usize).max(1);
    let normal = layout::normal_slot(layout);
    let mut out = Vec::with_capacity(blocks.len() / per_contact * slots.stride);
    for contact in blocks.chunks_exact(per_contact) {
        let mut s = vec![0.0f32; slots.stride];
        let mut b = contact.iter();
        if layout.tangential {
            let t = b.next().expect("a tangential block");
            s[slots.tangential..slots.tangential + 3].copy_from_slice(&t[..3]);
            if layout.sliding {
                s[slots.sliding] = t[3];
            }
            if normal == normal_slot::TANGENTIAL_W {
                s[slots.normal] = t[3];
            }
        }
        if layout.rolling {
            let r = b.next().expect("a rolling block");
            s[slots.rolling..slots.rolling + 3].copy_from_slice(&r[..3]);
            if normal == normal_slot::ROLLING_W {
                s[slots.normal] = r[3];
            }
        }
        if layout.bridge {
            let v = b.next().expect("a bridge block");
            s[slots.bridge] = v[0];
            if normal == normal_slot::BRIDGE_Y {
                s[slots.normal] = v[1];
            }
        }
        if normal == normal_slot::OWN {
            s[slots.normal] = b.next().expect("a normal block")[0];
        }
        out.extend(s);
    }
    out
}

/// A checkpoint's walls buffer (`bytes`, `n` walls) in today's layout: one written before
/// walls could turn lacks each wall's `turn`, which is then the identity.
fn walls_turning(bytes: Vec<u8>, n: usize) -> Vec<u8> {
    let before = std::mem::offset_of!(layout::Wall, turn);
    if bytes.len() != n * before {
        return bytes;
    }
    let identity = glam::Vec4::X;
    bytes.chunks_exact(before).flat_map(|w| w.iter().copied().chain(bytemuck::bytes_of(&identity).iter().copied())).collect()
}

/// A wall's surface as the GPU holds it.
fn wall_geom(w: &layout::Wall) -> crate::walls::WallGeom<f32> {
    let v3 = |a: glam::Vec4| crate::real::Vec3::new(a.x, a.y, a.z);
    match w.kind {
        layout::wall_kind::PLANE => crate::walls::WallGeom::Plane { point: v3(w.point), normal: v3(w.normal) },
        layout::wall_kind::CYLINDER => crate::walls::WallGeom::Cylinder { cx: w.point[0], cy: w.point[1], radius: w.normal[3] },
        layout::wall_kind::MESH => {
            let turn = (w.flags & layout::wall_flags::TURNS != 0).then_some(w.turn.to_array());
            crate::walls::WallGeom::Mesh { mesh: w.normal[0].to_bits(), pose: crate::walls::MeshPose { shift: v3(w.point), pivot: crate::real::Vec3::new(w.normal.y, w.normal.z, w.normal.w), turn } }
        }
        _ => crate::walls::WallGeom::Piston { z: w.point[2] },
    }
}

/// The GPU's wall history (per grain, each wall's blocks from its `hist_at`) in the CPU
/// engine's layout ([`crate::state::walls_reals`]): a wall's contact, or a mesh's slots of a
/// contact and its normal.
fn cpu_wall_history(blocks: &[[f32; 4]], walls: &[layout::Wall], hist_blocks: usize, slots: &crate::state::HistorySlots) -> Vec<f32> {
    let mut out = Vec::new();
    let mut at = 0;
    while at < blocks.len() {
        for w in walls {
            let slots_of_wall = if w.kind == layout::wall_kind::MESH { crate::mesh::MESH_CONTACTS } else { 1 };
            for _ in 0..slots_of_wall {
                out.extend(cpu_history(&blocks[at..at + hist_blocks], slots));
                at += hist_blocks;
                if w.kind == layout::wall_kind::MESH {
                    out.extend(&blocks[at][..3]);
                    at += 1;
                }
            }
        }
    }
    out
}

impl GpuEngine {
    /// Grain-wall contacts re-evaluated on the host from the GPU's state (the CPU twin's
    /// function in f32), given the grain arrays `[pos, vel, omega, residual, ..]` already read.
    pub(super) fn wall_contact_records(&self, arrays: &[Vec<[f32; 4]>]) -> Result<Vec<crate::engine::WallContactRecord>, SimError> {
        use crate::state::{wall_contact_records, Body, ForceContext, HistorySlots, Props, WallState};
        use crate::real::Vec3;
        let n_walls = self.wall_names.len();
        let blocks = self.params.hist_blocks as usize;
        let parts = self.read(&[
            (Buf::Material, 0, 4 * self.n as u64),
            (Buf::Walls, 0, (n_walls * std::mem::size_of::<layout::Wall>()) as u64),
            (Buf::WallHist, 0, 16 * self.n as u64 * self.params.wall_blocks as u64),
        ])?;
        // Copied out: a wall's vectors are 16-byte aligned, the words read back 4.
        let walls: Vec<layout::Wall> = bytemuck::pod_collect_to_vec(&parts[1]);
        let gpu_hist: &[[f32; 4]] = bytemuck::cast_slice(&parts[2]);
        let v3 = |a: [f32; 4]| Vec3::new(a[0], a[1], a[2]);
        let body: Vec<Body<f32>> = (0..self.n as usize).map(|i| Body { pos: v3(arrays[0][i]), vel: v3(arrays[1][i]), omega: v3(arrays[2][i]) }).collect();
        let prop: Vec<Props<f32>> = (0..self.n as usize).map(|i| Props { radius: arrays[0][i][3], mass: arrays[1][i][3], inertia: arrays[2][i][3] }).collect();
        let material: &[u32] = bytemuck::cast_slice(&parts[0]);
        let residual: Vec<Vec3<f32>> = arrays[3].iter().map(|&r| v3(r)).collect();
        let states: Vec<WallState<f32>> = walls
            .iter()
            .map(|w| WallState {
                geom: wall_geom(w),
                velocity: Vec3::new(w.velocity.x, w.velocity.y, w.velocity.z),
                spin: if w.flags & layout::wall_flags::DRIVEN != 0 { Vec3::new(w.drive.x, w.drive.y, w.drive.z) } else { Vec3::ZERO },
                material: w.material,
                present: w.flags & layout::wall_flags::ABSENT == 0,
                turns: w.flags & layout::wall_flags::TURNS != 0,
            })
            .collect();
        let slots = HistorySlots::new(self.history);
        let hist = cpu_wall_history(gpu_hist, &walls, blocks, &slots);
        let ctx = ForceContext {
            model: &self.model,
            coeffs: &self.coeffs,
            n_materials: self.n_materials,
            slots,
            elapsed: 0.0,
            window: 0.0,
            periodic: crate::periodic::Periodic::default(),
            residual: &residual,
            material,
            meshes: &self.meshes,
        };
        Ok(wall_contact_records(&body, &prop, &(0..self.n).collect::<Vec<u32>>(), &states, &ctx, &hist))
    }

    /// The grain state, and the touching pairs and wall contacts with their forces when
    /// `contacts`.
    pub(super) fn snapshot(&self, contacts: bool) -> Result<Frame, SimError> {
        let mut names = vec![Buf::Pos, Buf::Vel, Buf::Omega, Buf::Residual];
        if self.track_orientation {
            names.push(Buf::Quat);
        }
        let arrays = self.read_vec4s(&names)?;
        let (pos, residual) = (&arrays[0], &arrays[3]);
        let v3 = |p: &[f32; 4]| crate::real::Vec3::new(p[0], p[1], p[2]);
        let xyz = |v: &[f32; 4]| glam::DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
        let contact_records = contacts.then(|| -> Result<Vec<ContactRecord>, SimError> {
            let np = self.control.n_pairs as u64;
            let blocks = self.params.hist_blocks as u64;
            let rolling_block = self.history.tangential as usize;
            let both = self.model.keeps_both_forces();
            let parts = self.read(&[(Buf::PairI, 0, 4 * np), (Buf::PairJ, 0, 4 * np), (Buf::OutFi, 0, 16 * np), (Buf::OutFj, 0, if both { 16 * np } else { 0 }), (Buf::Hist, 0, 16 * np * blocks), (Buf::OutTj, 0, 16 * np)])?;
            let (pi, pj): (&[u32], &[u32]) = (&parts[0], &parts[1]);
            let fi: &[[f32; 4]] = bytemuck::cast_slice(&parts[2]);
            let fj: &[[f32; 4]] = bytemuck::cast_slice(&parts[3]);
            let hist: &[[f32; 4]] = bytemuck::cast_slice(&parts[4]);
            // out_tj.w: the capillary force.
            let f_c: Vec<f32> = bytemuck::cast_slice::<u32, [f32; 4]>(&parts[5]).iter().map(|t| t[3]).collect();
            Ok((0..np as usize)
                .filter_map(|k| {
                    let (i, j) = (pi[k] as usize, pj[k] as usize);
                    let (a, b) = (&pos[i], &pos[j]);
                    // The compensated positions' separation, as the kernels have it.
                    let d = crate::position::separation(&self.periodic, v3(a), v3(&residual[i]), v3(b), v3(&residual[j])).f64();
                    let h = (a[3] + b[3]) as f64 - (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                    (h > 0.0 || f_c[k] != 0.0).then(|| ContactRecord {
                        i: pi[k],
                        j: pj[k],
                        overlap: h,
                        normal_force: (fi[k][3] + f_c[k]) as f64,
                        force: xyz(&fi[k]),
                        force_j: if both { xyz(&fj[k]) } else { -xyz(&fi[k]) },
                        tangential_spring: if self.history.tangential { xyz(&hist[k * blocks as usize]) } else { glam::DVec3::ZERO },
                        rolling_spring: if self.history.rolling { xyz(&hist[k * blocks as usize + rolling_block]) } else { glam::DVec3::ZERO },
                        bridge_volume: if self.history.bridge { hist[k * blocks as usize + blocks as usize - 1][0] as f64 } else { 0.0 },
                    })
                })
                .collect())
        });
        let contact_records = contact_records.transpose()?;
        let wall_records = if !contacts {
            None
        } else if self.has_walls {
            Some(self.wall_contact_records(&arrays)?)
        } else {
            Some(Vec::new())
        };
        let mut frame = Frame {
            time: self.time,
            id: (0..self.n).collect(),
            position: pos.iter().zip(residual).map(|(p, r)| crate::position::absolute(v3(p), v3(r))).collect(),
            radius: arrays[0].iter().map(|v| v[3] as f64).collect(),
            velocity: arrays[1].iter().map(xyz).collect(),
            angular_velocity: arrays[2].iter().map(xyz).collect(),
            orientation: self.track_orientation.then(|| arrays[4].iter().map(|q| glam::DQuat::from_xyzw(q[1] as f64, q[2] as f64, q[3] as f64, q[0] as f64)).collect()),
            contacts: contact_records,
            wall_contacts: wall_records,
            walls: self.walls_now()?,
            walls_present: self.wall_flags.iter().map(|f| f & layout::wall_flags::ABSENT == 0).collect(),
        };
        frame.retain_grains(|k| self.in_play[k]);
        Ok(frame)
    }

    /// Every wall's surface where it stands now.
    fn walls_now(&self) -> Result<Vec<crate::walls::WallGeom<f64>>, SimError> {
        let n_walls = self.wall_names.len();
        if n_walls == 0 {
            return Ok(Vec::new());
        }
        let parts = self.read(&[(Buf::Walls, 0, (n_walls * std::mem::size_of::<layout::Wall>()) as u64)])?;
        Ok(bytemuck::pod_collect_to_vec::<u32, layout::Wall>(&parts[0]).iter().map(|w| wall_geom(w).f64()).collect())
    }

    /// Wets the sample with `volume` (m^3) of liquid, as the CPU twin does.
    pub(super) fn wet_pairs(&mut self, volume: f64) -> anyhow::Result<()> {
        use crate::real::Vec3;
        let crate::model::CohesionLaw::Capillary { theta, .. } = self.model.cohesion else {
            anyhow::bail!("the scene wets the sample but has no capillary cohesion; fix: set model.cohesion = \"capillary\"");
        };
        // The liquid goes to the pairs of the current list.
        self.ensure_loads()?;
        let (n, np, blocks) = (self.n as u64, self.read_control()?.n_pairs as u64, self.params.hist_blocks as u64);
        let parts = self.read(&[(Buf::Pos, 0, 16 * n), (Buf::PairI, 0, 4 * np), (Buf::PairJ, 0, 4 * np), (Buf::Hist, 0, 16 * np * blocks), (Buf::Liquid, 0, 4 * n), (Buf::Residual, 0, 16 * n)])?;
        let pos: &[[f32; 4]] = bytemuck::cast_slice(&parts[0]);
        let residual: &[[f32; 4]] = bytemuck::cast_slice(&parts[5]);
        let (pi, pj) = (&parts[1], &parts[2]);
        let mut hist: Vec<[f32; 4]> = bytemuck::cast_slice(&parts[3]).to_vec();
        let mut liquid: Vec<f32> = bytemuck::cast_slice(&parts[4]).to_vec();
        // The CPU twin's radii and gaps (in f32, as its f32 engine has them).
        let v3 = |p: &[f32; 4]| Vec3::new(p[0], p[1], p[2]);
        let pairs: Vec<(f64, f64, f64)> = (0..np as usize)
            .map(|k| {
                let (i, j) = (pi[k] as usize, pj[k] as usize);
                let (a, b) = (&pos[i], &pos[j]);
                (a[3] as f64, b[3] as f64, (crate::position::separation(&self.periodic, v3(a), v3(&residual[i]), v3(b), v3(&residual[j])).norm() - a[3] - b[3]) as f64)
            })
            .collect();
        let (shares, rest) = crate::model::share_liquid(volume, &pairs, self.params.cohesion[3] as f64, theta as f64);
        let last = blocks as usize - 1;
        for (k, v) in shares {
            hist[k * blocks as usize + last][0] += v as f32;
        }
        let rest = (rest / n as f64) as f32;
        for l in &mut liquid {
            *l += rest;
        }
        self.gpu.queue.write_buffer(&self.buffers[Buf::Hist], 0, bytemuck::cast_slice(&hist));
        self.gpu.queue.write_buffer(&self.buffers[Buf::Liquid], 0, bytemuck::cast_slice(&liquid));
        self.forces_valid = false;
        Ok(())
    }

    /// The whole state, for a checkpoint: every buffer but constants and scratch, bit for bit.
    pub(super) fn save_state(&self) -> Result<crate::engine::EngineState, SimError> {
        let mut s = crate::engine::EngineState::default();
        let n_pairs = self.control.n_pairs as u64;
        let per_pair: HashMap<Buf, u64> = self.pair_buffers().into_iter().collect();
        // In the order of their names, as checkpoints have always listed them.
        let mut names: Vec<Buf> = self.buffers.iter().map(|(name, _)| name).filter(|name| !NOT_STATE.contains(name)).collect();
        names.sort_unstable_by_key(|name| name.name());
        let parts: Vec<(Buf, u64, u64)> = names.iter().map(|&name| (name, 0, per_pair.get(&name).map_or(self.buffers[name].size(), |b| b * n_pairs))).collect();
        for (name, words) in names.iter().map(|name| name.name()).zip(self.read(&parts)?) {
            // Two 4-byte words per stored integer, the first in the low half.
            s.put_ints(&format!("gpu:{name}"), words.chunks(2).map(|c| c[0] as u64 | (c.get(1).copied().unwrap_or(0) as u64) << 32));
        }
        s.put_ints("counters", [self.step, self.forces_valid as u64, self.params.pair_capacity as u64]);
        s.put_reals("time", [self.time]);
        Ok(s)
    }

    /// Restores what [`Self::save_state`] returned, for the same scene.
    pub(super) fn restore_state(&mut self, s: &crate::engine::EngineState) -> anyhow::Result<()> {
        let counters = s.ints("counters", Some(3))?;
        if counters[2] != self.params.pair_capacity as u64 {
            self.allocate_pairs(counters[2]).map_err(|reason| anyhow::anyhow!("the GPU could not allocate the checkpoint's {} pairs of buffers: {reason}; fix: resume on a device with more memory, or with --backend cpu", counters[2]))?;
            self.build_bind_groups();
        }
        for (key, words) in &s.ints {
            let Some(name) = key.strip_prefix("gpu:") else { continue };
            let buffer = Buf::of_name(name).and_then(|b| self.buffers.get(b)).ok_or_else(|| anyhow::anyhow!("the checkpoint holds a GPU buffer `{name}` this engine lacks; fix: resume with the grains version that wrote it"))?;
            let mut bytes: Vec<u8> = words.iter().flat_map(|&w| w.to_le_bytes()).collect();
            if name == Buf::Walls.name() {
                bytes = walls_turning(bytes, self.wall_flags.len().max(1));
            }
            // A list of an odd number of words was padded with one (beyond the live pairs).
            if bytes.len() as u64 > buffer.size() + 4 {
                anyhow::bail!("the checkpoint's GPU buffer `{name}` holds {} bytes, this scene's {}; fix: resume with the scene the checkpoint was written for", bytes.len(), buffer.size());
            }
            self.gpu.queue.write_buffer(buffer, 0, &bytes[..bytes.len().min(buffer.size() as usize)]);
            let walls_bytes = self.wall_flags.len() * std::mem::size_of::<layout::Wall>();
            if name == Buf::Walls.name() && bytes.len() >= walls_bytes {
                let walls: Vec<layout::Wall> = bytemuck::pod_collect_to_vec(&bytes[..walls_bytes]);
                self.wall_flags = walls.iter().map(|w| w.flags).collect();
            }
        }
        (self.step, self.forces_valid) = (counters[0], counters[1] != 0);
        self.time = s.reals("time", 1)?[0];
        self.marks.clear();
        self.marks_base = self.read_control()?.rebuild_checks;
        self.read_in_play()?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A walls buffer written before walls could turn (each wall's bytes up to `turn`) comes
    /// back whole, each wall's rotation the identity; one of today's is kept as it is.
    #[test]
    fn old_walls_buffers_gain_the_identity_rotation() {
        let walls: Vec<layout::Wall> = (0..3u32)
            .map(|k| layout::Wall { kind: k, material: k + 1, flags: 1, hist_at: 4 * k, point: glam::Vec4::splat(k as f32), normal: glam::Vec4::Z, velocity: glam::Vec4::W, drive: glam::Vec4::ONE, turn: glam::Vec4::X })
            .collect();
        let now: Vec<u8> = bytemuck::cast_slice(&walls).to_vec();
        let before = std::mem::offset_of!(layout::Wall, turn);
        let old: Vec<u8> = now.chunks_exact(std::mem::size_of::<layout::Wall>()).flat_map(|w| w[..before].to_vec()).collect();
        assert_eq!(walls_turning(old, 3), now);
        assert_eq!(walls_turning(now.clone(), 3), now);
    }
}
